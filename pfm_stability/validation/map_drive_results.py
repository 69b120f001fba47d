"""What validation by driving answers (`validation.map_drives`; docs/maps.md, "Validation by driving"): the drives
as simulated (`SimulatedDrive`, `DriveRuns`: nothing judged yet), each drive judged (`Drive`), the stretches where
prediction and drives disagree (`Disagreement`), how big the predicted weave is against the simulated one
(`WobbleAgreement`, `wobble_agreement`) and the scored validation (`DriveValidation`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..io.serialize import json_number, json_ready
from ..maps.judging.judge_thresholds import JUDGE, JudgeThresholds

__all__ = ["Disagreement", "Drive", "DriveRuns", "DriveValidation", "SimulatedDrive", "WobbleAgreement", "wobble_agreement"]

@dataclass(frozen=True)
class SimulatedDrive:
    """One drive as the simulator ran it, before it is judged (`DriveRuns`).

    Attributes
    ----------
    index : int
    kind : str
        "route" or "waypoints" (`Drive`).
    ends : tuple of float
        (x0, y0, x1, y1): start and goal (or the piece's end), m.
    event : str or None
        What ended it (`Drive.event`).
    t, x, y : ndarray
        Its trajectory: times (s) and positions (m).
    path : int or None
        Its own path's index among `DriveRuns.drive_paths`' routes (None: it did not move).
    contact : tuple of float or None
        (x, y) of the robot's centre where a collision ended it, m (None: no collision).
    """

    index: int
    kind: str
    ends: tuple
    event: str | None
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    path: int | None = None
    contact: tuple | None = None

    @property
    def duration(self) -> float:
        """Its duration, s."""
        return float(self.t[-1] - self.t[0]) if self.t.size else 0.0


@dataclass(frozen=True)
class DriveRuns:
    """A map's drives simulated once, with the prediction along their own paths: what `judge_drives` scores, with
    any `JudgeThresholds` (`drive_map` is the two in one; experiments/judge_thresholds.py re-judges one `DriveRuns`).
    The prediction is the package's (made with `JUDGE`: `maps.judging.driven`'s loop is judged by the same rule); a re-judging
    moves the drives' side only.

    Attributes
    ----------
    analysis : MapAnalysis
        The grid-law analysis the drives were made on.
    count : int
        Drives asked for.
    seed : int
        Seed of their choice.
    period : float
        The episodes' period P = 2π/ω*, s (inf: no ω*).
    drives : tuple of SimulatedDrive
    skipped : int
        Drives that could not start (the start or goal touches an obstacle).
    drive_paths : PathVerdicts or None
        The verdicts along the drives' own paths (`maps.analysis.judge_routes`; None: no drive moved).
    seconds : float
        Wall-clock time of the simulation and the prediction along the paths, s.
    """

    analysis: object
    count: int
    seed: int
    period: float
    drives: tuple
    skipped: int
    drive_paths: object
    seconds: float


@dataclass(frozen=True)
class Drive:
    """One simulated drive.

    Attributes
    ----------
    index : int
    kind : str
        "route" (along a route piece, target at infinity) or "waypoints" (point to point).
    x0, y0, x1, y1 : float
        Start and goal (or the piece's end), m.
    event : str or None
        What ended it ("target_reached", "collision", "trapped"; None: its time ran out).
    duration : float
        s.
    episodes : tuple of tuple
        (t_start, t_end) of each oscillation episode, s.
    max_amplitude : float
        Largest lateral oscillation amplitude, m.
    contact : tuple of float or None
        (x, y) of the robot's centre where a collision ended it, m (None: no collision).
    """

    index: int
    kind: str
    x0: float
    y0: float
    x1: float
    y1: float
    event: str | None
    duration: float
    episodes: tuple = ()
    max_amplitude: float = 0.0
    contact: tuple | None = None

    def to_dict(self) -> dict:
        """JSON form."""
        return json_ready({**self.__dict__, "episodes": [list(e) for e in self.episodes]})


@dataclass(frozen=True)
class Disagreement:
    """A stretch of route where the map's verdict and the drives disagree.

    Attributes
    ----------
    kind : str
        "missed" (an episode where stable was predicted) or "false alarm" (predicted unstable, driven, no episode).
    route : int
    start, stop, length : float
        Arc positions along the route and length, m.
    x0, y0, x1, y1 : float
        Its ends, m.
    drives : tuple of int
        The drives that passed it.
    predicted_amplitude : float
        The largest lateral oscillation of the loop driven along it held for at least one period (`maps.deciding.paths`,
        `maps.judging.episodes.lateral_extent`), m.
    simulated_amplitude : float
        The same of the drives there (`maps.judging.episodes.swing`: three alternating turning points about their paths
        averaged over a period, as the episodes' judge finds them; a bend is none), m. Above `AMPLITUDE_THRESHOLD`
        on a false alarm: the robot did weave past it, for one period or more but fewer than `EPISODE_PERIODS`; on a
        missed episode, the predicted amplitude above it is the loop's weave that did not last.
    """

    kind: str
    route: int
    start: float
    stop: float
    length: float
    x0: float
    y0: float
    x1: float
    y1: float
    drives: tuple = ()
    predicted_amplitude: float = 0.0
    simulated_amplitude: float = 0.0

    def to_dict(self) -> dict:
        """JSON form."""
        return json_ready({**self.__dict__, "drives": list(self.drives)})


@dataclass(frozen=True)
class WobbleAgreement:
    """How big the predicted weave is against the simulated one, along the measured part of the drives' own paths
    (`wobble_agreement`): where either the prediction's loop or the drive wove past `AMPLITUDE_THRESHOLD` for at
    least one period, the ratio of the two weaves held there (`DriveValidation`'s per-sample amplitudes:
    `maps.judging.episodes.lateral_extent`'s swing of the loop, `maps.judging.episodes.swing` of the drive; 0 where one held none).
    Recall and precision judge each side against the threshold; this says how far apart the two are in size, which
    is what decides them near it.

    Attributes
    ----------
    length : float
        Measured length where either side wove past the threshold, m (the loop still in the corridor: where it left,
        its size is only "at least `maps.judging.driven.LEAVES`", and the length is counted as ``left`` instead).
    within : float or None
        Share of `length` where predicted / simulated lies within 1/`factor` .. `factor` (None: no
        length).
    ratio_quartiles : tuple of float or None
        The 25th, 50th and 75th percentiles of predicted / simulated by length (a value of the samples, not
        interpolated; 0 where the loop held no weave, inf where the drive held none).
    left : float
        Measured length where the prediction's loop left the corridor, m.
    factor : float
        The factor `within` allows (`JudgeThresholds.wobble_factor`).
    """

    length: float
    within: float | None
    ratio_quartiles: tuple | None
    left: float
    factor: float = JUDGE.wobble_factor

    def to_dict(self) -> dict:
        """JSON form."""
        return {"length": json_number(self.length), "within": json_number(self.within), "factor": self.factor,
                "ratio_quartiles": None if self.ratio_quartiles is None else [json_number(v) for v in self.ratio_quartiles],
                "left": json_number(self.left)}


def wobble_agreement(predicted, simulated, spacing, leaves: float, thresholds: JudgeThresholds = JUDGE) -> WobbleAgreement:
    """`WobbleAgreement` of measured samples.

    Parameters
    ----------
    predicted, simulated : ndarray
        The weave held at each sample by the prediction's loop and by the drive, m (>= 0).
    spacing : ndarray
        The samples' lengths, m.
    leaves : float
        A predicted weave this large or larger means the loop left the corridor, m.
    thresholds : JudgeThresholds
        Its `amplitude_threshold` and `wobble_factor` (`maps.judging.judge_thresholds.JUDGE`: the package's).
    """
    predicted, simulated, spacing = (np.asarray(v, dtype=float) for v in (predicted, simulated, spacing))
    factor = thresholds.wobble_factor
    left = predicted >= leaves
    either = ~left & (np.maximum(predicted, simulated) >= thresholds.amplitude_threshold)
    length = float(spacing[either].sum())
    if not length > 0:
        return WobbleAgreement(0.0, None, None, float(spacing[left].sum()), factor)
    ratio = np.divide(predicted[either], simulated[either], out=np.full(int(either.sum()), np.inf), where=simulated[either] > 0)
    weight = spacing[either]
    within = float(weight[(ratio >= 1 / factor) & (ratio <= factor)].sum()) / length
    order = np.argsort(ratio, kind="stable")
    cumulative = np.cumsum(weight[order]) / length
    quartiles = tuple(float(ratio[order][min(np.searchsorted(cumulative, q - 1e-12), ratio.size - 1)]) for q in (0.25, 0.5, 0.75))
    return WobbleAgreement(length, within, quartiles, float(spacing[left].sum()), factor)


@dataclass(frozen=True)
class DriveValidation:
    """Recall and precision of the map's unstable stretches against the drives' episodes, by route length.

    Attributes
    ----------
    recall, precision : float or None
        By route length (None: nothing to measure).
    drives : tuple of Drive
    disagreements : tuple of Disagreement
    lengths : dict
        Length (m): of the map's routes ``route``, ``driven`` (covered by a drive), ``not_driven``; of the drives' own
        paths ``drive_paths``, ``drive_paths_driven`` (measured), ``drive_paths_unmeasured`` (passed only in a drive's
        last three periods); ``episode``, ``episode_recalled``, ``episode_off_route`` (the drives' path length in
        episodes farther than the match distance from their own path: measured, not scored),
        ``predicted_unstable_driven``, ``predicted_unstable_matched``, ``predicted_unstable_unmeasured``,
        ``predicted_unstable_not_driven`` (on the map's routes, no drive near); of the disagreements,
        ``false_alarm_swinging`` (false alarms where a drive wove past `AMPLITUDE_THRESHOLD` for at least one period,
        not three) and ``missed_predicted_swinging`` (missed episodes where the loop wove past it, not for three).
    counts : dict
        Drives by how they ended, episodes found.
    inputs : dict
    seconds : float
    episode_points : ndarray, shape (n, 2)
        Robot positions during the episodes, m (for the picture).
    by_kind : dict
        ``route`` and ``waypoints``: the same recall, precision, specificity and lengths over that kind of drive only.
    drive_paths : PathVerdicts or None
        The verdicts along the paths the drives took (`maps.analysis.judge_routes`): the drives are scored
        against them (a disagreement's ``route`` >= the map's route count is drive path ``route`` − that count).
    recall_interval, precision_interval : tuple of float or None
        95 % intervals of recall and precision over the choice of drives (`_interval`: the drives resampled with
        replacement, `INTERVAL_RESAMPLES` times, seeded); None where the figure is None.
    specificity : float or None
        Of the length driven with a verdict and no episode within half a window (``lengths["quiet_driven"]``), the
        share predicted stable (``quiet_predicted_stable``); None when every such metre was near an episode. Where no
        drive oscillates, recall is undefined and precision rests on the few metres predicted unstable; this says how
        much of the calm driving the map also called calm.
    specificity_interval : tuple of float or None
        Its 95 % interval over the drives.
    wobble : WobbleAgreement or None
        How big the predicted weave is against the simulated one where either passed the threshold.
    collisions : CollisionSummary or None
        Where the drives collided and what the map predicted there (`validation.map_collisions`).
    """

    recall: float | None
    precision: float | None
    drives: tuple
    disagreements: tuple
    lengths: dict
    counts: dict
    inputs: dict = field(default_factory=dict)
    seconds: float = 0.0
    episode_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    by_kind: dict = field(default_factory=dict)
    drive_paths: object = None
    recall_interval: tuple | None = None
    precision_interval: tuple | None = None
    specificity: float | None = None
    specificity_interval: tuple | None = None
    wobble: WobbleAgreement | None = None
    collisions: object = None

    def to_dict(self) -> dict:
        """JSON form."""
        return {
            "wobble": self.wobble.to_dict() if self.wobble is not None else None,
            "collisions": self.collisions.to_dict() if self.collisions is not None else None,
            "drive_paths": self.drive_paths.to_dict() if self.drive_paths is not None else None,
            "recall": json_number(self.recall) if self.recall is not None else None,
            "precision": json_number(self.precision) if self.precision is not None else None,
            "recall_interval": json_ready(self.recall_interval),
            "precision_interval": json_ready(self.precision_interval),
            "specificity": json_number(self.specificity) if self.specificity is not None else None,
            "specificity_interval": json_ready(self.specificity_interval),
            "by_kind": json_ready(self.by_kind),
            "lengths": json_ready(self.lengths),
            "counts": json_ready(self.counts),
            "disagreements": [d.to_dict() for d in self.disagreements],
            "drives": [d.to_dict() for d in self.drives],
            "inputs": json_ready(self.inputs),
            "timing": {"seconds": json_number(self.seconds)},
        }
