"""Oscillation episodes of a lateral motion: where a robot weaves (docs/maps.md, "Validation by driving").

One definition serves the map's prediction (`maps.deciding.paths`: the linear loop driven along a route) and its judge
(`validation.map_drives`: the simulator's drives). The lateral oscillation is the motion minus its own average
over one period P = 2π/ω* (the loop's oscillation at the boundary; `scipy.ndimage.uniform_filter1d`), smoothed
over P/8 (the cell ripple, at c/V, is faster). Its turning points give amplitudes; an **episode** is
`EPISODE_PERIODS` periods — 2·`EPISODE_PERIODS` turning points alternating in side, consecutive ones P/4 to P
apart (an oscillation, not a bend of the path) — whose amplitudes grow (a least-squares fit of log amplitude
against time rises by at least `GROWTH_EFOLDS` e-fold over them, and each side's amplitude rises period after period:
a swerve after a quiet stretch is no growth) or all stay above `AMPLITUDE_THRESHOLD`.
Amplitudes below `NOISE_FLOOR` are no oscillation. The first and last half period are not judged (the average is
not centred there), and the samples where the judged part is cut are no turning points (the motion is cut there,
not turning).

Every number above is a field of one table, `maps.judging.judge_thresholds.JudgeThresholds` (the package's: `JUDGE`; the
names here are its fields' aliases), with its unit, justification and measured sensitivity in docs/judge.md; every
function takes ``thresholds=JUDGE``, so that an experiment re-judges with another table.
"""

from __future__ import annotations

import math

import numpy as np

from .judge_thresholds import JUDGE, JudgeThresholds

__all__ = ["AMPLITUDE_THRESHOLD", "EPISODE_PERIODS", "GROWTH_EFOLDS", "NOISE_FLOOR", "episodes", "lateral_episodes", "lateral_extent",
           "oscillation", "swing"]

EPISODE_PERIODS = JUDGE.episode_periods
"""Periods of an episode: `JudgeThresholds.episode_periods` of `JUDGE` (docs/judge.md)."""
GROWTH_EFOLDS = JUDGE.growth_efolds
"""e-folds the fitted amplitude must gain over an episode's periods to count as growing: `JudgeThresholds.growth_efolds`
of `JUDGE`."""
AMPLITUDE_THRESHOLD = JUDGE.amplitude_threshold
"""Lateral amplitude (m) that, held over `EPISODE_PERIODS` periods, is an episode whether or not it grows:
`JudgeThresholds.amplitude_threshold` of `JUDGE` (its justification there and in docs/judge.md)."""
NOISE_FLOOR = JUDGE.noise_floor
"""Amplitudes below this (m) are no oscillation: `JudgeThresholds.noise_floor` of `JUDGE`."""


def lateral_episodes(t, lateral, period: float, thresholds: JudgeThresholds = JUDGE) -> tuple:
    """(episodes, max_amplitude) of a lateral signal: the (t_start, t_end) of each episode (s) and the largest
    amplitude of its oscillation about its one-period average (m) (module docstring).

    Parameters
    ----------
    t : ndarray
        Times, s (uniform step).
    lateral : ndarray
        Lateral position, m.
    period : float
        The oscillation period P, s.
    thresholds : JudgeThresholds
        The judge's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; docs/judge.md).
    """
    t = np.asarray(t, dtype=float)
    r, n = _about_average(t, lateral, period, thresholds)
    return ((), 0.0) if r is None else _episodes(t, r, period, n, thresholds)


def lateral_extent(t, lateral, period: float, thresholds: JudgeThresholds = JUDGE) -> tuple:
    """(swing, excursion) per sample of a lateral signal, m: the amplitude of the oscillation about its one-period
    average it is part of, held for at least one period (`swing`, for a lateral position), and the farthest it strays
    from that average within half a period either side — however irregular its turning points (a swing needs three
    alternating ones, P/4 to P apart); zeros for a signal shorter than two periods.

    Parameters
    ----------
    t : ndarray
        Times, s (uniform step).
    lateral : ndarray
        Lateral position, m.
    period : float
        The oscillation period P, s.
    thresholds : JudgeThresholds
        The judge's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; docs/judge.md).
    """
    from scipy.ndimage import maximum_filter1d

    t = np.asarray(t, dtype=float)
    r, n = _about_average(t, lateral, period, thresholds)
    if r is None:
        return np.zeros(t.size), np.zeros(t.size)
    return _held(t, _smoothed(r, n, thresholds), period, n, thresholds), maximum_filter1d(np.abs(r), n, mode="nearest")


def _about_average(t, lateral, period: float, thresholds: JudgeThresholds) -> tuple:
    """(r, n): `lateral` minus its average over `JudgeThresholds.average_periods` periods, n samples a period; (None, 0)
    for fewer than two periods."""
    from scipy.ndimage import uniform_filter1d

    t, lateral = np.asarray(t, dtype=float), np.asarray(lateral, dtype=float)
    n = _period_samples(t, period)
    if n is None:
        return None, 0
    return lateral - uniform_filter1d(lateral, _average_samples(t, period, thresholds), mode="nearest"), n


def _period_samples(t: np.ndarray, period: float):
    """Samples per period of the uniform times `t` (s; at least 3), or None when the run is shorter than two periods
    (or eight samples) or the period is not a positive number."""
    if t.size < 8 or not period > 0 or not math.isfinite(period):
        return None
    n = max(3, int(round(period / float(np.median(np.diff(t))))))
    return None if t.size < 2 * n else n


def _average_samples(t: np.ndarray, period: float, thresholds: JudgeThresholds) -> int:
    """Samples of the running average the oscillation is measured about: `JudgeThresholds.average_periods` periods of
    the uniform times `t` (s; at least 3)."""
    return max(3, int(round(thresholds.average_periods * period / float(np.median(np.diff(t))))))


def episodes(t, x, y, period: float, thresholds: JudgeThresholds = JUDGE) -> tuple:
    """(episodes, max_amplitude) of a trajectory in the plane: its lateral oscillation is its distance across its own
    path averaged over one period (module docstring).

    Parameters
    ----------
    t : ndarray
        Times, s (uniform step).
    x, y : ndarray
        Positions, m.
    period : float
        The oscillation period P, s.
    thresholds : JudgeThresholds
        The judge's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; docs/judge.md).
    """
    t = np.asarray(t, dtype=float)
    r, n = oscillation(t, x, y, period, thresholds)
    if r is None:
        return (), 0.0
    return _episodes(t, r, period, n, thresholds)


def oscillation(t, x, y, period: float, thresholds: JudgeThresholds = JUDGE) -> tuple:
    """(r, n): a trajectory's lateral oscillation r (m, per point: its distance across its own path averaged over one
    period, left positive) and the samples per period n; (None, 0) for a run shorter than two periods.

    Parameters
    ----------
    t : ndarray
        Times, s (uniform step).
    x, y : ndarray
        Positions, m.
    period : float
        The oscillation period P, s.
    thresholds : JudgeThresholds
        The judge's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; its `average_periods` the average's
        length).
    """
    from scipy.ndimage import uniform_filter1d

    t, x, y = (np.asarray(v, dtype=float) for v in (t, x, y))
    n = _period_samples(t, period)
    if n is None:
        return None, 0
    m = _average_samples(t, period, thresholds)
    sx, sy = uniform_filter1d(x, m, mode="nearest"), uniform_filter1d(y, m, mode="nearest")
    hx, hy = np.gradient(sx), np.gradient(sy)
    norm = np.hypot(hx, hy)
    norm[norm == 0] = 1.0
    return ((x - sx) * -hy + (y - sy) * hx) / norm, n


def swing(t, x, y, period: float, thresholds: JudgeThresholds = JUDGE) -> np.ndarray:
    """Per point, the amplitude (m) of the lateral oscillation it is part of, held for at least one period — three
    turning points alternating in side, P/4 to P apart, as the episodes' judge finds them (a bend of the path is no
    swing) — the smallest of those three (the largest such window's); 0 where there is none.

    Parameters
    ----------
    t : ndarray
        Times, s (uniform step).
    x, y : ndarray
        Positions, m.
    period : float
        The oscillation period P, s.
    thresholds : JudgeThresholds
        The judge's thresholds (`maps.judging.judge_thresholds.JUDGE`: the package's; its `swing_points` the turning points
        held).
    """
    t = np.asarray(t, dtype=float)
    r, n = oscillation(t, x, y, period, thresholds)
    return np.zeros(t.size) if r is None else _held(t, _smoothed(r, n, thresholds), period, n, thresholds)


def _held(t, r, period, n: int, thresholds: JudgeThresholds) -> np.ndarray:
    """Per sample, the smallest amplitude (m) of the `JudgeThresholds.swing_points` turning points of the smoothed
    oscillation `r` (`n` samples a period) that hold it for a period around it, the largest such (0: none)."""
    out = np.zeros(t.size)
    kept, amplitude = _turning_points(t, r, period, n, thresholds)
    for sel, a in _oscillating(t, r, kept, amplitude, period, thresholds.swing_points, thresholds):
        inside = (t >= t[sel[0]] - thresholds.lead_periods * period) & (t <= t[sel[-1]])
        out[inside] = np.maximum(out[inside], a.min())
    return out


def _smoothed(r, n: int, thresholds: JudgeThresholds) -> np.ndarray:
    """The oscillation `r` (m) smoothed over `JudgeThresholds.smoothing_periods` of its `n` samples a period (the cell
    ripple is faster), its first and last `edge_periods` 0 (the averaged path is not centred at the ends)."""
    from scipy.ndimage import uniform_filter1d

    edge = _edge(n, thresholds)
    r = uniform_filter1d(r, max(1, int(n * thresholds.smoothing_periods)), mode="nearest")
    r[:edge] = 0.0
    if edge:
        r[-edge:] = 0.0
    return r


def _edge(n: int, thresholds: JudgeThresholds) -> int:
    """Samples not judged at each end of a run of `n` samples a period (`JudgeThresholds.edge_periods`)."""
    return int(n * thresholds.edge_periods)


def _episodes(t, r, period, n, thresholds: JudgeThresholds) -> tuple:
    """The episodes of the oscillation `r` (m) about the average path (`n` samples a period)."""
    r = _smoothed(r, n, thresholds)
    kept, amplitude = _turning_points(t, r, period, n, thresholds)
    found = []
    for sel, a in _oscillating(t, r, kept, amplitude, period, 2 * thresholds.episode_periods, thresholds):
        span = t[sel[-1]] - t[sel[0]]
        slope = np.polyfit(t[sel], np.log(a), 1)[0]
        grows = slope * span >= thresholds.growth_efolds and np.all(a[2:] >= a[:-2])  # and on each side, period after period
        if grows or a.min() >= thresholds.amplitude_threshold:
            lo, hi = t[sel[0]] - thresholds.lead_periods * period, t[sel[-1]]
            if found and lo <= found[-1][1]:
                found[-1] = (found[-1][0], float(hi))
            else:
                found.append((float(lo), float(hi)))
    return tuple(found), float(amplitude.max()) if amplitude.size else 0.0


def _turning_points(t, r, period, n: int, thresholds: JudgeThresholds) -> tuple:
    """(indices, amplitudes (m)) of the turning points of the smoothed oscillation `r` (`n` samples a period, its first
    and last `edge_periods` zeroed by `_smoothed`) above `noise_floor`; of two closer than `min_gap_periods` (ripple),
    the larger. The first and last samples judged are none: the oscillation is cut there, not turning (a weave still
    rising where the judged part ends would count its value at the cut as an extreme)."""
    dr = np.diff(r)
    edge = _edge(n, thresholds)
    turn = np.flatnonzero((dr[:-1] > 0) & (dr[1:] <= 0) | (dr[:-1] < 0) & (dr[1:] >= 0)) + 1
    turn = turn[(np.abs(r[turn]) > thresholds.noise_floor) & (turn > edge) & (turn < r.size - edge - 1)]
    kept = []
    for k in turn:
        if kept and t[k] - t[kept[-1]] < thresholds.min_gap_periods * period:
            if abs(r[k]) > abs(r[kept[-1]]):
                kept[-1] = k
            continue
        kept.append(k)
    kept = np.array(kept, dtype=int)
    return kept, (np.abs(r[kept]) if kept.size else np.zeros(0))


def _oscillating(t, r, kept, amplitude, period, count: int, thresholds: JudgeThresholds):
    """The runs of `count` consecutive turning points that oscillate — alternating in side, consecutive ones
    `min_gap_periods` to `max_gap_periods` apart (not a bend of the path) — as (indices, amplitudes)."""
    low, high = thresholds.min_gap_periods * period, thresholds.max_gap_periods * period
    for i in range(0, max(0, kept.size - count + 1)):
        sel = kept[i:i + count]
        gaps = np.diff(t[sel])
        if np.any(np.sign(r[sel][1:]) == np.sign(r[sel][:-1])) or gaps.min() < low or gaps.max() > high:
            continue
        yield sel, amplitude[i:i + count]
