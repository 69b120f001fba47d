"""Events that end a run: collision, target reached, trapped (docs/simulator.md).

Events are checked at every sample instant t_k, before the controller senses:

* ``collision`` — the robot disc (diameter W) touches an occupied cell's
  square or an analytic wall segment anywhere on its exact path from t_k−1
  to t_k (`pfm_stability.sim.contact`: a robot that moves V·T = 80 m per
  period at T = 100 s cannot pass through a wall between two samples). The
  time is the first touch, to 1e-12 of the period, and (x, y) the robot
  centre there; the run ends at t_k, the first sample after it (whose
  position may lie past the contact). A graze shallower than ~1e-8 m may
  count or not.
* ``target_reached`` — within the target radius of a point target, or past
  the finish distance of a direction target.
* ``trapped`` — no progress of `trap_distance` towards the target within
  `trap_time` (KB §5.1's trap situations, or a robot stopped by the speed law).
* ``no_valid_control`` — a Nav2 controller driven by `pfm_stability.sim.tracking` found no command (Nav2's
  ``NoValidControl``: every trajectory it tried collides) or lost its plan (the closest pose off its costmap).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EVENT_TYPES", "Event"]

EVENT_TYPES = ("collision", "target_reached", "trapped", "no_valid_control")


@dataclass(frozen=True)
class Event:
    """Something that ended a run.

    Attributes
    ----------
    type : {"collision", "target_reached", "trapped", "no_valid_control"}
    t : float
        Time, s: a collision's first touch (between samples), else the sample's.
    x, y : float
        Robot centre at that time, m.
    """

    type: str
    t: float
    x: float
    y: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {"type": self.type, "t": self.t, "x": self.x, "y": self.y}
