"""The frequency of an established oscillation and its 95 % interval, from the zero crossings of a record
(docs/diagnose.md, "The measured frequency").

A log's stretch is short (a corridor driven for 2–3 periods) and starts with a transient (the robot entered the
corridor off its centre line, the loop's faster modes have not died out). The turning points' mean spacing carries
that transient into ω: measured 16–18 % high on such runs. Here ω comes from the part of the record that oscillates:

1. **Centre.** The level c about which the record swings: the median of the record between its first and last
   established crossing (whole half-periods: a growing or decaying e^(σt)·cos(ωt) spends exactly half of every
   period above its centre, so the median over whole periods is the centre, whatever σ and the waveform's
   asymmetry). Found by iterating from the whole record's median (`CENTRE_PASSES` passes; a record with less than a
   whole established period keeps the whole record's median).
2. **Crossings.** A crossing is counted when the record passes from below c − h to above c + h or back
   (a Schmitt trigger, h = `HYSTERESIS` × the record's half range about c, so noise and a transient's small
   wiggles count none); its time is where the straight line fitted to the samples between the two thresholds
   meets c.
3. **Established.** The crossings of an established linear oscillation are equally spaced (by π/ω). Leading
   crossings are dropped while the period that starts at the first one (to the crossing after next: a whole
   period, so a centre error's alternation of long and short half-periods cancels) differs by more than
   `ESTABLISHED` from the median of the next `NEIGHBOURS` periods. What is dropped is the start transient.
4. **Fit.** The established crossing times c_i against their index i: a straight line c_i = a + b·i by least
   squares; b = π/ω is the half-period, with its standard error s_b from the residuals (n − 2 degrees of
   freedom). The 95 % interval of ω is π/(b ± t·s_b), t the Student t quantile with n − 2 degrees of freedom.
   (A spectral estimate was not chosen: its resolution, 2π over the record's length, is 30–50 % of ω on 2–3
   periods; the crossing times' scatter, a few milliseconds against a half-period of a second or more, resolves
   ω to a fraction of a percent.)

**Too few periods.** With fewer than `MIN_CROSSINGS` established crossings the fit has fewer than two degrees of
freedom and its interval says nothing (t = 12.7 with one): the estimate is then the mean spacing of the crossings
left (two or three), the interval null and `few_periods` true; with fewer than two crossings there is no estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_number

__all__ = ["FrequencyEstimate", "crossing_frequency", "zero_crossings", "MIN_CROSSINGS", "ESTABLISHED", "NEIGHBOURS", "HYSTERESIS",
           "CENTRE_PASSES"]

MIN_CROSSINGS = 4
"""Established crossings (one and a half periods) below which a run holds too few periods for an interval: a line
through n crossing times has n − 2 degrees of freedom; at 4 the 95 % t quantile is 4.30, at 3 it is 12.7 (an
interval of ±12.7 standard errors says nothing)."""
ESTABLISHED = 0.05
"""A leading crossing is part of the start transient while the period it starts differs by more than this fraction
from the median of the later periods. An established linear oscillation's periods are equal: over whole 20-s corridor
runs they vary by at most 0.6 % in MuJoCo (three speeds) and 4.3 % in the VFF simulator (eight random corridors, the
largest where a growing swing nears the walls at the run's end, which this rule does not touch); a transient that
moves the turning points' ω by 16–18 % moves the first periods by far more."""
NEIGHBOURS = 3
"""A leading period is compared with the median of the next this many (not of all later ones: an oscillation that grows
into the walls lengthens its periods steadily, by 2–4 % a period in the VFF simulator's corridors, and against all later
periods each leading one would look like a transient until only the large swings were left)."""
HYSTERESIS = 0.1
"""The Schmitt trigger's half-width h as a fraction of the record's half range about its centre (m for an offset):
wider than the odometry's noise (0.5 mm on a centimetre swing: 5 %) and the ripple of a grid's cells, narrower than
the smallest swing of a decaying oscillation worth timing (a swing below h is not counted)."""
CENTRE_PASSES = 3
"""Passes of centre → crossings → centre (the centre moves by less than the crossings' resolution after two)."""


@dataclass(frozen=True)
class FrequencyEstimate:
    """ω of the established part of a record and its 95 % interval (module docstring).

    Attributes
    ----------
    omega : float or None
        ω, rad/s (None: fewer than two crossings).
    low, high : float or None
        Its 95 % interval, rad/s (None when `few_periods`; ``inf`` for high when the interval reaches a zero
        half-period).
    crossings : int
        Established crossings used.
    dropped : int
        Leading crossings dropped as the start transient.
    established : float or None
        Time of the first crossing used, s.
    periods : float
        Established periods: (crossings − 1)/2.
    few_periods : bool
        Fewer than `MIN_CROSSINGS` established crossings: no interval.
    centre : float
        The level the record swings about (the record's unit).
    """

    omega: float | None
    low: float | None
    high: float | None
    crossings: int
    dropped: int
    established: float | None
    periods: float
    few_periods: bool
    centre: float

    def to_dict(self) -> dict:
        """``{omega, low, high, crossings, dropped, established, periods, few_periods}`` (SI units)."""
        return {"omega": json_number(self.omega), "low": json_number(self.low), "high": json_number(self.high),
                "crossings": self.crossings, "dropped": self.dropped, "established": json_number(self.established),
                "periods": self.periods, "few_periods": self.few_periods}


def zero_crossings(t: np.ndarray, x: np.ndarray, centre: float, h: float) -> np.ndarray:
    """The times (s) where `x` crosses `centre` from below centre − h to above centre + h or back (module docstring, 2).

    Parameters
    ----------
    t : numpy.ndarray
        Sample times, s, increasing.
    x : numpy.ndarray
        The record (any unit).
    centre : float
        The level crossed.
    h : float
        The trigger's half-width (x's unit), ≥ 0.

    Returns
    -------
    numpy.ndarray
        Crossing times, increasing.
    """
    state = np.where(x > centre + h, 1, np.where(x < centre - h, -1, 0))
    outside = np.flatnonzero(state != 0)
    if outside.size < 2:
        return np.zeros(0)
    s = state[outside]
    change = np.flatnonzero(s[1:] != s[:-1])
    times = []
    for k in change:
        i, j = outside[k], outside[k + 1]  # the last sample on one side, the first beyond the other threshold
        tt, xx = t[i:j + 1], x[i:j + 1] - centre
        if j - i == 1:
            times.append(tt[0] - xx[0] * (tt[1] - tt[0]) / (xx[1] - xx[0]))
        else:
            slope, intercept = np.polyfit(tt - tt[0], xx, 1)
            times.append(tt[0] - intercept / slope if slope != 0 else 0.5 * (tt[0] + tt[-1]))
    return np.clip(np.asarray(times), t[0], t[-1])


def _established(c: np.ndarray) -> int:
    """How many leading crossings belong to the start transient (module docstring, 3)."""
    first = 0
    while c.size - first >= 4:  # at least two whole periods to compare
        periods = c[first + 2:] - c[first:-2]
        if abs(periods[0] / np.median(periods[1:1 + NEIGHBOURS]) - 1.0) <= ESTABLISHED:
            break
        first += 1
    return first


def _student_t(dof: int) -> float:
    """The 97.5 % quantile of Student's t with `dof` degrees of freedom."""
    from scipy.special import stdtrit

    return float(stdtrit(dof, 0.975))


def crossing_frequency(t, x) -> FrequencyEstimate:
    """ω of the established oscillation of a record and its 95 % interval, from its zero crossings (module docstring).

    Parameters
    ----------
    t : array_like
        Sample times, s, increasing (need not be uniform).
    x : array_like
        The record (e.g. a lateral offset, m), finite.

    Returns
    -------
    FrequencyEstimate

    Raises
    ------
    ValueError
        t and x of different lengths, or non-finite.
    """
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    if t.shape != x.shape or t.ndim != 1:
        raise ValueError(f"t and x must be one-dimensional arrays of one length; got {t.shape} and {x.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
        raise ValueError("t and x must be finite")
    centre = float(np.median(x)) if x.size else 0.0
    c, first = np.zeros(0), 0
    for _ in range(CENTRE_PASSES):
        half_range = 0.5 * float(np.percentile(x, 99) - np.percentile(x, 1)) if x.size else 0.0
        c = zero_crossings(t, x, centre, HYSTERESIS * half_range) if half_range > 0 else np.zeros(0)
        first = _established(c)
        if c.size - first < 3:  # less than a whole period: the median cannot be taken over whole periods
            break
        last = first + 2 * ((c.size - first - 1) // 2)  # whole periods (an even number of half-periods)
        centre = float(np.median(x[(t >= c[first]) & (t <= c[last])]))
    used = c[first:]
    n = int(used.size)
    if n < 2:
        return FrequencyEstimate(None, None, None, n, first, None, 0.0, True, centre)
    periods = (n - 1) / 2.0
    if n < MIN_CROSSINGS:
        return FrequencyEstimate(math.pi * (n - 1) / float(used[-1] - used[0]), None, None, n, first, float(used[0]),
                                 periods, True, centre)
    i = np.arange(n, dtype=float)
    b, a = np.polyfit(i, used, 1)
    residual = used - (a + b * i)
    se = math.sqrt(float(residual @ residual) / (n - 2) / float(np.sum((i - i.mean()) ** 2)))
    half = _student_t(n - 2) * se
    high = math.pi / (b - half) if b - half > 0 else math.inf
    return FrequencyEstimate(math.pi / b, math.pi / (b + half), high, n, first, float(used[0]), periods, False, centre)
