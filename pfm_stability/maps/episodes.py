"""Oscillation episodes of a lateral motion: where a robot weaves (docs/maps.md, "Validation by driving").

One definition serves the map's prediction (`maps.paths`: the linear loop driven along a route) and its judge
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
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["AMPLITUDE_THRESHOLD", "EPISODE_PERIODS", "GROWTH_EFOLDS", "NOISE_FLOOR", "episodes", "lateral_episodes", "lateral_extent",
           "oscillation", "swing"]

EPISODE_PERIODS = 3
"""Periods of an episode ("a lateral deviation that grows over at least three periods, or stays above a threshold")."""
GROWTH_EFOLDS = 1.0
"""e-folds the fitted amplitude must gain over an episode's periods to count as growing."""
AMPLITUDE_THRESHOLD = 0.015
"""Lateral amplitude (m) that, held over `EPISODE_PERIODS` periods, is an episode whether or not it grows. An unstable
loop's oscillation grows until the steering-rate limit holds it in a limit cycle: ±2 cm on the straight test corridor
at 1.4 V* (W 0.4 m, k 20 1/s, 120 deg/s; tests/test_map_paths.py), reached within two periods, too soon for the
growth to count; a stable loop's forced ripple on the same grid, and its decaying start transient after the first
period, stay below 1.3 cm."""
NOISE_FLOOR = 0.005
"""Amplitudes below this (m) are no oscillation (the grid's quantization ripple is ~mm)."""


def lateral_episodes(t, lateral, period: float) -> tuple:
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
    """
    t = np.asarray(t, dtype=float)
    r, n = _about_average(t, lateral, period)
    return ((), 0.0) if r is None else _episodes(t, r, period, n)


def lateral_extent(t, lateral, period: float) -> tuple:
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
    """
    from scipy.ndimage import maximum_filter1d

    t = np.asarray(t, dtype=float)
    r, n = _about_average(t, lateral, period)
    if r is None:
        return np.zeros(t.size), np.zeros(t.size)
    return _held(t, _smoothed(r, n), period, n), maximum_filter1d(np.abs(r), n, mode="nearest")


def _about_average(t, lateral, period: float) -> tuple:
    """(r, n): `lateral` minus its average over one period of n samples; (None, 0) for fewer than two periods."""
    from scipy.ndimage import uniform_filter1d

    t, lateral = np.asarray(t, dtype=float), np.asarray(lateral, dtype=float)
    n = _period_samples(t, period)
    return (None, 0) if n is None else (lateral - uniform_filter1d(lateral, n, mode="nearest"), n)


def _period_samples(t: np.ndarray, period: float):
    """Samples per period of the uniform times `t` (s; at least 3), or None when the run is shorter than two periods
    (or eight samples) or the period is not a positive number."""
    if t.size < 8 or not period > 0 or not math.isfinite(period):
        return None
    n = max(3, int(round(period / float(np.median(np.diff(t))))))
    return None if t.size < 2 * n else n


def episodes(t, x, y, period: float) -> tuple:
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
    """
    t = np.asarray(t, dtype=float)
    r, n = oscillation(t, x, y, period)
    if r is None:
        return (), 0.0
    return _episodes(t, r, period, n)


def oscillation(t, x, y, period: float) -> tuple:
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
    """
    from scipy.ndimage import uniform_filter1d

    t, x, y = (np.asarray(v, dtype=float) for v in (t, x, y))
    n = _period_samples(t, period)
    if n is None:
        return None, 0
    sx, sy = uniform_filter1d(x, n, mode="nearest"), uniform_filter1d(y, n, mode="nearest")
    hx, hy = np.gradient(sx), np.gradient(sy)
    norm = np.hypot(hx, hy)
    norm[norm == 0] = 1.0
    return ((x - sx) * -hy + (y - sy) * hx) / norm, n


def swing(t, x, y, period: float) -> np.ndarray:
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
    """
    t = np.asarray(t, dtype=float)
    r, n = oscillation(t, x, y, period)
    return np.zeros(t.size) if r is None else _held(t, _smoothed(r, n), period, n)


def _held(t, r, period, n: int) -> np.ndarray:
    """Per sample, the smallest amplitude (m) of the three turning points of the smoothed oscillation `r` (`n` samples
    a period) that hold it for a period around it, the largest such (0: none)."""
    out = np.zeros(t.size)
    kept, amplitude = _turning_points(t, r, period, n)
    for sel, a in _oscillating(t, r, kept, amplitude, period, 3):
        inside = (t >= t[sel[0]] - period / 4) & (t <= t[sel[-1]])
        out[inside] = np.maximum(out[inside], a.min())
    return out


def _smoothed(r, n: int) -> np.ndarray:
    """The oscillation `r` (m) smoothed over an eighth of its `n` samples a period (the cell ripple is faster), its
    first and last half period 0 (the averaged path is not centred at the ends)."""
    from scipy.ndimage import uniform_filter1d

    r = uniform_filter1d(r, max(1, n // 8), mode="nearest")
    r[: n // 2], r[-(n // 2):] = 0.0, 0.0
    return r


def _episodes(t, r, period, n) -> tuple:
    """The episodes of the oscillation `r` (m) about the average path (`n` samples a period)."""
    r = _smoothed(r, n)
    kept, amplitude = _turning_points(t, r, period, n)
    found = []
    for sel, a in _oscillating(t, r, kept, amplitude, period, 2 * EPISODE_PERIODS):
        span = t[sel[-1]] - t[sel[0]]
        slope = np.polyfit(t[sel], np.log(a), 1)[0]
        grows = slope * span >= GROWTH_EFOLDS and np.all(a[2:] >= a[:-2])  # and on each side, period after period
        if grows or a.min() >= AMPLITUDE_THRESHOLD:
            lo, hi = t[sel[0]] - period / 4, t[sel[-1]]
            if found and lo <= found[-1][1]:
                found[-1] = (found[-1][0], float(hi))
            else:
                found.append((float(lo), float(hi)))
    return tuple(found), float(amplitude.max()) if amplitude.size else 0.0


def _turning_points(t, r, period, n: int) -> tuple:
    """(indices, amplitudes (m)) of the turning points of the smoothed oscillation `r` (`n` samples a period, its first
    and last half period zeroed by `_smoothed`) above `NOISE_FLOOR`; of two closer than a quarter period (ripple), the
    larger. The first and last samples judged are none: the oscillation is cut there, not turning (a weave still
    rising where the judged part ends would count its value at the cut as an extreme)."""
    dr = np.diff(r)
    turn = np.flatnonzero((dr[:-1] > 0) & (dr[1:] <= 0) | (dr[:-1] < 0) & (dr[1:] >= 0)) + 1
    turn = turn[(np.abs(r[turn]) > NOISE_FLOOR) & (turn > n // 2) & (turn < r.size - n // 2 - 1)]
    kept = []
    for k in turn:
        if kept and t[k] - t[kept[-1]] < period / 4:
            if abs(r[k]) > abs(r[kept[-1]]):
                kept[-1] = k
            continue
        kept.append(k)
    kept = np.array(kept, dtype=int)
    return kept, (np.abs(r[kept]) if kept.size else np.zeros(0))


def _oscillating(t, r, kept, amplitude, period, count: int):
    """The runs of `count` consecutive turning points that oscillate — alternating in side, consecutive ones P/4 to P
    apart (not a bend of the path) — as (indices, amplitudes)."""
    for i in range(0, max(0, kept.size - count + 1)):
        sel = kept[i:i + count]
        gaps = np.diff(t[sel])
        if np.any(np.sign(r[sel][1:]) == np.sign(r[sel][:-1])) or gaps.min() < period / 4 or gaps.max() > period:
            continue
        yield sel, amplitude[i:i + count]
