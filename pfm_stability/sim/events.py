"""Events that end a run: collision, target reached, trapped (docs/simulator.md).

Events are checked at every sample instant t_k, before the controller senses:

* ``collision`` — the robot disc (diameter W) touches an occupied cell's
  square or an analytic wall segment. The reported time is refined by linear
  interpolation of the clearance between the last two samples, so it is
  accurate to O(T²) rather than T; a graze that starts and ends between two
  samples (depth < ~V²T²/(8 × turn radius), well under 1 mm for CARMEL) is
  not seen.
* ``target_reached`` — within the target radius of a point target, or past
  the finish distance of a direction target.
* ``trapped`` — no progress of `trap_distance` towards the target within
  `trap_time` (KB §5.1's trap situations, or a robot stopped by the speed law).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EVENT_TYPES", "Event"]

EVENT_TYPES = ("collision", "target_reached", "trapped")


@dataclass(frozen=True)
class Event:
    """Something that ended a run.

    Attributes
    ----------
    type : {"collision", "target_reached", "trapped"}
    t : float
        Time, s.
    x, y : float
        Robot centre at the sample that detected it, m.
    """

    type: str
    t: float
    x: float
    y: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {"type": self.type, "t": self.t, "x": self.x, "y": self.y}
