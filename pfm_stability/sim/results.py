"""Results of simulated runs: one `RunResult` per member, a `BatchResult` for a batch.

JSON form (`to_dict`): ``events`` (list of {type, t, x, y}), ``metrics``
(`OscillationMetrics.to_dict`: growth_rate σ in 1/s, angular_frequency ω in
rad/s, oscillating, stable, …) and ``inputs`` (everything that defined the
run). Numbers are written by `pfm_stability.io.serialize.json_number`: infinite
ones as ``"inf"``/``"-inf"``, undefined ones as ``None`` (with a reason in
the metrics), never NaN. Wall-clock times are under ``timing`` only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_array, json_number, json_ready
from .events import Event
from .metrics import OscillationMetrics
from .scenario import Scenario

__all__ = ["Trajectory", "RunResult", "BatchResult"]


@dataclass(frozen=True)
class Trajectory:
    """Robot state at every sample instant.

    Attributes
    ----------
    t : ndarray
        s.
    x, y : ndarray
        Robot centre, m.
    theta : ndarray
        Heading, rad from +Y towards +X (not wrapped).
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray

    def at_times(self, times) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) linearly interpolated at `times` (s) inside the run.

        Parameters
        ----------
        times : array_like
            Times inside the run, s.
        """
        return np.interp(times, self.t, self.x), np.interp(times, self.t, self.y)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {key: json_array(getattr(self, key)) for key in ("t", "x", "y", "theta")}


@dataclass(frozen=True)
class RunResult:
    """One member's outcome.

    Attributes
    ----------
    scenario : Scenario
    events : tuple of Event
        At most one: the event that ended the run (none if it ran its duration).
    metrics : OscillationMetrics or None
        None when the batch ran with ``metrics=False``.
    t_end : float
        Last sample instant, s: the duration, or the sample of the event that
        stopped the run (a collision's first sample after the contact, whose
        time is the event's).
    steps : int
        Sampling periods simulated.
    offset_t, offset : ndarray
        Lateral offset (m) at the sample instants of the measurement window.
    min_clearance : float or None
        Smallest gap between the robot disc and an obstacle over the samples
        (and at a contact between them), m (<= 0 at a collision); None if no
        obstacle ever came within W/2 + V·T of the robot's cell (grid) — the
        gap is only computed near obstacles.
    trajectory : Trajectory or None
        Every sample, when recorded.
    """

    scenario: Scenario
    events: tuple
    metrics: OscillationMetrics
    t_end: float
    steps: int
    offset_t: np.ndarray
    offset: np.ndarray
    min_clearance: float | None = None
    trajectory: Trajectory | None = None

    def event(self, kind: str) -> Event | None:
        """The event of type `kind`, if it happened.

        Parameters
        ----------
        kind : str
            The event's type (`Event.type`).
        """
        return next((e for e in self.events if e.type == kind), None)

    @property
    def collided(self) -> bool:
        return self.event("collision") is not None

    def plot(self, ax=None, **kwargs):
        """`plots.trajectory.plot_trajectory` of this run (recorded with its trajectory); returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; None: a new figure.
        **kwargs
            Passed on to `plots.trajectory.plot_trajectory`.
        """
        from ..plots.trajectory import plot_trajectory

        return plot_trajectory(self, ax=ax, **kwargs)

    def to_dict(self, trajectory: bool = False) -> dict:
        """Events, metrics and inputs as a JSON-ready dict (SI units); the sampled trajectory too if asked.

        ``inputs.measure.along_from`` is ``"-inf"`` when the metrics use the
        whole run (a start that is infinitely far back, not an undefined one).

        Parameters
        ----------
        trajectory : bool
            Include the sampled trajectory.
        """
        inputs = json_ready(self.scenario.inputs())
        inputs["measure"]["along_from"] = json_number(self.scenario.measure.along_from)
        out = {
            "events": [json_ready(e.to_dict()) for e in self.events],
            "metrics": json_ready(self.metrics.to_dict()) if self.metrics is not None else None,
            "t_end": json_number(self.t_end),
            "steps": int(self.steps),
            "min_clearance": json_number(self.min_clearance),
            "inputs": inputs,
        }
        if trajectory and self.trajectory is not None:
            out["trajectory"] = self.trajectory.to_dict()
        return out


@dataclass(frozen=True)
class BatchResult:
    """Outcomes of a batch, in member order, with array views for sweeps and bisection.

    Attributes
    ----------
    runs : tuple of RunResult
    robot_steps : int
        Sampling periods simulated over all members.
    seconds : float
        Wall-clock time of the stepping (metrics excluded), s.
    """

    runs: tuple
    robot_steps: int
    seconds: float

    def __len__(self) -> int:
        return len(self.runs)

    def __getitem__(self, i) -> RunResult:
        return self.runs[i]

    def _metrics(self):
        if any(r.metrics is None for r in self.runs):
            raise ValueError("metrics were not computed (run_batch(..., metrics=False))")
        return [r.metrics for r in self.runs]

    def _bools(self, attr) -> np.ndarray:
        return np.array([getattr(m, attr) for m in self._metrics()], dtype=bool)

    @property
    def stable(self) -> np.ndarray:
        """bool per member: the run **settled** (`OscillationMetrics.stable`: no collision, no growing
        oscillation, no limit cycle, σ < 0 when defined).

        Not the linear-stability verdict the loop models predict (sign of σ):
        that is `pfm_stability.sim.verdict.linearly_stable` (a slow decay
        flagged as a limit cycle is linearly stable but has not settled).
        """
        return self._bools("stable")

    @property
    def oscillating(self) -> np.ndarray:
        """bool per member."""
        return self._bools("oscillating")

    @property
    def collided(self) -> np.ndarray:
        """bool per member."""
        return np.array([r.collided for r in self.runs], dtype=bool)

    def _masked(self, attr) -> np.ma.MaskedArray:
        values = [getattr(m, attr) for m in self._metrics()]
        return np.ma.masked_array([0.0 if v is None else v for v in values], mask=[v is None for v in values])

    @property
    def growth_rate(self) -> np.ma.MaskedArray:
        """σ per member, 1/s; masked where undefined (see each run's `metrics.reason`)."""
        return self._masked("growth_rate")

    @property
    def angular_frequency(self) -> np.ma.MaskedArray:
        """ω per member, rad/s; masked where undefined."""
        return self._masked("angular_frequency")

    @property
    def rate(self) -> float:
        """Robot-steps per second of the stepping."""
        return self.robot_steps / self.seconds if self.seconds > 0 else float("inf")

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units); wall-clock ``seconds`` and ``rate`` under ``timing``."""
        return {
            "members": [r.to_dict() for r in self.runs],
            "robot_steps": int(self.robot_steps),
            "timing": {"seconds": json_number(self.seconds), "rate": json_number(self.rate)},
        }
