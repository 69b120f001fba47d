"""The oscillation judge's thresholds: one named, documented table (docs/judge.md).

Every number the oscillation judge (`maps.judging.episodes`: what an episode is, how large a swing is) and the drives'
scoring (`validation.map_drives`: which samples are measured, what matches what) compare against lives in
`JudgeThresholds`, with its unit, where its value comes from and what moving it does; `JUDGE` is the table the
package uses. Both the map's prediction (`maps.judging.driven`, `maps.deciding.decide`: the loop driven along a route is judged by the
same rule, and the window-edge relay is unstable when its cycle reaches `amplitude_threshold`) and the validation read
it, so a change to it moves both sides. The judge functions take ``thresholds=JUDGE``: an experiment re-judges the
same drives with another table (experiments/judge_thresholds.py, whose measured sensitivity is docs/judge.md's
table) without touching the package's.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

__all__ = ["JUDGE", "JudgeThresholds"]


@dataclass(frozen=True)
class JudgeThresholds:
    """Every threshold of the oscillation judge and of the drives' scoring (docs/judge.md: each value's measured
    sensitivity). P is the oscillation period 2π/ω* (the loop's at the boundary), Λ the verdicts' window.

    Attributes
    ----------
    episode_periods : int
        Periods an episode lasts: 2·episode_periods turning points alternating in side. *Definition*: "a lateral
        deviation that grows over at least three periods, or stays above a threshold". Fewer finds shorter weaves
        (a swing round a corner lasts one or two periods); more needs longer drives and loses weaves cut short.
    growth_efolds : float
        e-folds (dimensionless) the least-squares fit of log amplitude against time must rise over an episode's
        span for it to count as growing (each side's amplitude also rising period after period). *A chosen scale*:
        a factor e in amplitude over three periods, σ/ω* ≥ 1/(6π), well clear of a steady weave's scatter of
        turning-point amplitudes; a stable loop's decaying start transient falls instead. Lower counts slowly growing
        (or noisily steady) weaves; higher leaves growing weaves to `amplitude_threshold`.
    amplitude_threshold : float
        Lateral amplitude, m, that, held by every turning point of an episode, makes it an episode whether or not it
        grows. *Measured*: an unstable loop's oscillation grows until the steering-rate limit holds it in a limit
        cycle, ±2 cm on the straight test corridor at 1.4 V* (W 0.4 m, k 20 1/s, 120 deg/s; tests/test_map_paths.py),
        reached within two periods, too soon for the growth to count; a stable loop's forced ripple on the same grid,
        and its decaying start transient after the first period, stay below 1.3 cm. Also the relay's test on the
        prediction side (`maps.deciding.decide`: a window-edge relay is unstable when its cycle reaches it) and the size above
        which a false alarm or a missed episode counts as "swinging" and a weave is compared (`WobbleAgreement`).
        Lower calls ripple an episode; higher misses rate-limited cycles.
    noise_floor : float
        Amplitude, m, below which a turning point is no oscillation. *Physical scale*: the histogram grid's
        quantization ripple is ~mm. Higher drops small turning points and with them the growth from a small start
        (a growing weave is found later); lower lets ripple break the alternation of turning points.
    average_periods : float
        Length of the running average the lateral oscillation is measured about, periods. *Definition*: an average
        over exactly one period P removes a sinusoid at ω* from the average (its zero) and keeps a bend of the path
        slower than P. It also defines a drive's own path (`validation.map_drives._taken_path`, the path the
        prediction is made along); a re-judging with another value moves only the judge. Shorter takes part of the
        oscillation into the path; longer takes slow bends into the oscillation.
    smoothing_periods : float
        Running-mean smoothing of the oscillation before its turning points are found, periods. *Physical scale*: the
        cell ripple, at c/V, is faster; a mean over P/8 passes the oscillation at ω* at 97 % (sinc(π/8)). Longer
        flattens the weave; shorter lets the ripple's turning points through (merged by `min_gap_periods`).
    edge_periods : float
        Length, periods, at each end of a run not judged, and whose cut samples are no turning points.
        *Definition*: within half a period of an end the one-period average is not centred.
    min_gap_periods : float
        Least spacing, periods, of consecutive turning points of an oscillation; two closer are ripple and the larger
        is kept. *Definition*: a sinusoid's turning points are P/2 apart; a quarter period is half that.
    max_gap_periods : float
        Largest spacing, periods, of consecutive turning points of an oscillation. *Definition*: twice a sinusoid's
        P/2; a slower swing is a bend of the path. Lower misses weaves slower than ω* (a loop's large weave beside a
        rack); higher takes bends for oscillations.
    lead_periods : float
        An episode (and a swing) begins this many periods before its first turning point. *Definition*: a sinusoid's
        zero crossing lies a quarter period before its extreme.
    swing_points : int
        Turning points, alternating and spaced as above, a swing is held for (`maps.judging.episodes.swing`, the weave the
        disagreements and `WobbleAgreement` report). *Definition*: three turning points are one period.
    match_distance : float
        Largest distance, m, from a drive's trajectory point to the sample of its own path (or of the map's routes)
        it marks; at least the robot's width W. *A chosen scale*: a drive's own path is its trajectory averaged over
        a period, so the robot's points lie within its weave of it; farther is a spin off the path (measured, not
        scored). Lower leaves a large weave's extremes unscored; higher lets a point mark a neighbouring stretch.
    start_periods : float
        A drive's first this many periods are not measured (its start's transient), periods. *Definition*: the
        response to the start (δ off the route, or towards its carrot) is over within about one period.
    start_share : float
        ... or its first this share of its duration, if that is shorter (dimensionless). *A chosen scale*: a drive
        shorter than four periods keeps three quarters of its length.
    end_periods : float or None
        Samples a drive passed only in its last this many periods are not measured, periods (and a
        predicted-unstable stretch reaching them is cut back by as many periods' travel less half a window,
        `_cut_short`). None: `episode_periods`. *Definition*: an episode needs that long after a sample to be found.
        Fewer scores samples no episode could have shown (missed weaves cut short); more measures less.
    match_window : float
        A predicted-unstable sample matches an episode sample within this share of the verdicts' window Λ along the
        same path, and an episode sample is recalled by one so near (dimensionless). *Definition*: a point's verdict is
        the growth over the window Λ centred there, so Λ/2 either side. Lower demands the weave where the window
        put it; higher forgives it being a window away.
    wobble_factor : float
        A predicted weave agrees in size with the simulated one when their ratio lies within 1/this .. this
        (dimensionless; `WobbleAgreement`, reported, not scored). *A chosen scale*: a factor 2 either way.
    """

    episode_periods: int = 3
    growth_efolds: float = 1.0
    amplitude_threshold: float = 0.015
    noise_floor: float = 0.005
    average_periods: float = 1.0
    smoothing_periods: float = 0.125
    edge_periods: float = 0.5
    min_gap_periods: float = 0.25
    max_gap_periods: float = 1.0
    lead_periods: float = 0.25
    swing_points: int = 3
    match_distance: float = 0.5
    start_periods: float = 1.0
    start_share: float = 0.25
    end_periods: float | None = None
    match_window: float = 0.5
    wobble_factor: float = 2.0

    def __post_init__(self):
        for name in ("episode_periods", "swing_points"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise ValueError(f"{name} must be an integer >= 1; got {value!r}")
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name in ("episode_periods", "swing_points") or value is None:
                continue
            if not isinstance(value, (int, float)) or not value >= 0 or value == float("inf"):
                raise ValueError(f"{f.name} must be a finite number >= 0; got {value!r}")
        if self.max_gap_periods < self.min_gap_periods:
            raise ValueError(f"max_gap_periods ({self.max_gap_periods}) must be >= min_gap_periods ({self.min_gap_periods})")

    @property
    def end_exclusion(self) -> float:
        """Periods at a drive's end whose samples are not measured: `end_periods`, or `episode_periods` when None."""
        return float(self.episode_periods) if self.end_periods is None else float(self.end_periods)

    def replace(self, **changes) -> "JudgeThresholds":
        """A copy with `changes` (field names and values).

        Parameters
        ----------
        **changes
            Field names and their new values.
        """
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """JSON form: every field by name."""
        return dataclasses.asdict(self)


JUDGE = JudgeThresholds()
"""The thresholds the package judges with (docs/judge.md)."""
