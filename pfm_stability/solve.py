"""Scalar roots of monotone functions on a bracket, for the fast (report) path.

Why not a library: `scipy.optimize.brentq` is the natural choice, but importing
``scipy.optimize`` takes ~0.4 s — more than half of the report's whole
cold-start budget (issue: ``report`` must run in half the time of
``import control``). mpmath ships with sympy and imports in 0.05 s, but its
bracketing solvers stop after a fixed number of steps and return a wrong root
without warning (Anderson–Björck on eˣ − 10⁶ over [0, 100] returns 49.98, not
13.8). Bisection needs no such care: it halves the bracket until the requested
relative width, so each call costs at most ~60 evaluations of functions that
here cost micro- to milliseconds. The tests check it against `brentq`.
Vectorized code (many points at once) uses `scipy.optimize.elementwise`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["bisect_root", "expand_bracket", "newton_increasing", "first_crossing", "refine_sign_change"]


def bisect_root(func, lo: float, hi: float, rtol: float = 1e-13) -> float:
    """Root of a continuous function with a sign change on [lo, hi], by bisection.

    Parameters
    ----------
    func : callable
        float → float.
    lo, hi : float
        Bracket; func(lo) and func(hi) must differ in sign (or one be 0).
    rtol : float
        Stop when hi − lo <= rtol·max(|lo|, |hi|) (or the floats are adjacent).

    Returns
    -------
    float
        The midpoint of the final bracket.

    Raises
    ------
    ValueError
        If the bracket has no sign change.
    """
    f_lo, f_hi = func(lo), func(hi)
    if f_lo == 0:
        return lo
    if f_hi == 0:
        return hi
    if (f_lo > 0) == (f_hi > 0):
        raise ValueError(f"no sign change on [{lo:g}, {hi:g}]: f = {f_lo:g}, {f_hi:g}")
    for _ in range(2100):  # enough to exhaust the doubles between any two floats
        mid = 0.5 * (lo + hi)
        if hi - lo <= rtol * max(abs(lo), abs(hi)) or mid in (lo, hi):
            return mid
        f_mid = func(mid)
        if f_mid == 0:
            return mid
        if (f_mid > 0) == (f_lo > 0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def expand_bracket(func, start: float, *, factor: float = 2.0, steps: int = 200, upward: bool = True):
    """Grow ``[start, start·factor^j]`` (or downward) until func changes sign.

    Parameters
    ----------
    func : callable
        float → float, evaluated at positive arguments.
    start : float
        First point, > 0.
    factor : float
        Growth factor per step.
    steps : int
        Largest number of steps.
    upward : bool
        Search towards +inf (True) or towards 0 (False).

    Returns
    -------
    (lo, hi) or None
        A bracket with a sign change, or None if none was found.
    """
    f_start = func(start)
    prev = start
    for _ in range(steps):
        nxt = prev * factor if upward else prev / factor
        if not math.isfinite(nxt) or nxt == 0:
            return None
        if (func(nxt) > 0) != (f_start > 0):
            return (prev, nxt) if upward else (nxt, prev)
        prev = nxt
    return None


def newton_increasing(func, lo, hi, *, rtol: float = 4e-16, iterations: int = 200):
    """Roots of strictly increasing functions, one per bracket, for arrays of brackets at once.

    Safeguarded Newton (Numerical Recipes' ``rtsafe``): a Newton step that
    leaves the current bracket, or does not halve it fast enough, is replaced
    by a bisection step, so convergence is guaranteed and quadratic near the
    root.

    Parameters
    ----------
    func : callable
        ``func(x) -> (f, f')`` on arrays shaped like `lo`; f increasing in x,
        f(lo) <= 0 <= f(hi).
    lo, hi : array_like
        Brackets (finite).
    rtol : float
        Stop when every step is below rtol·|x| (or the bracket is that narrow).

    Returns
    -------
    ndarray
        The roots.
    """
    lo = np.array(lo, dtype=float)
    hi = np.array(hi, dtype=float)
    x = 0.5 * (lo + hi)
    previous = hi - lo
    for _ in range(iterations):
        f, slope = func(x)
        lo = np.where(f < 0, x, lo)
        hi = np.where(f > 0, x, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            correction = f / slope
        newton = x - correction
        converged = (f == 0) | (np.abs(correction) <= rtol * np.abs(x))
        good = np.isfinite(newton) & (newton > lo) & (newton < hi) & (np.abs(correction) < 0.5 * previous)
        step_to = np.where(converged, x, np.where(good, newton, 0.5 * (lo + hi)))
        previous = np.abs(step_to - x)
        x = step_to
        if np.all(converged | (hi - lo <= rtol * np.abs(x))):
            break
    return x


def first_crossing(measure, lo: float, hi: float, *, start: float = 0.0, points_per_decade: int = 32, rtol: float = 1e-7, atol: float = 0.0) -> float:
    """Smallest x in (start, hi] with measure(x) >= 0, given measure(start) < 0; ``inf`` if none.

    `measure` is continuous (e.g. a loop's growth rate as a parameter grows)
    and vectorized. It is evaluated on a geometric grid; the grid-local maxima
    below 0 that come before the first sign change are refined together by a
    golden-section search (16 steps shrink each two-cell bracket 2000-fold,
    so a short excursion above 0 between grid points is found), and the first
    sign change is narrowed to `rtol` by `refine_sign_change`.

    Parameters
    ----------
    measure : callable
        ndarray → ndarray of the same shape.
    lo, hi : float
        The grid's ends, 0 < lo < hi (a crossing in (start, lo] is found too).
    start : float
        A point below lo where measure < 0 is known (e.g. T = 0).
    points_per_decade : int
        Grid density.
    rtol, atol : float
        Relative and absolute width of the final bracket (hi − lo <= max(rtol·hi, atol)).

    Returns
    -------
    float
    """
    count = max(8, int(math.ceil(points_per_decade * (math.log10(hi) - math.log10(lo)))) + 1)
    grid = np.geomspace(lo, hi, count)
    values = np.asarray(measure(grid), dtype=float)
    above = np.flatnonzero(values >= 0)
    first = int(above[0]) if above.size else count
    bracket = ((float(grid[first - 1]) if first else start), float(grid[first])) if above.size else None
    j = np.arange(1, min(first, count - 1))
    peaks = j[(values[j - 1] < values[j]) & (values[j] >= values[j + 1])]
    if peaks.size:
        x, top = _golden_maxima(measure, grid[peaks - 1], grid[peaks + 1])
        hit = np.flatnonzero(top >= 0)
        if hit.size:
            i = int(hit[0])
            bracket = (float(grid[peaks[i] - 1]), float(x[i]))
    if bracket is None:
        return math.inf
    return refine_sign_change(measure, *bracket, rtol=rtol, atol=atol)


def refine_sign_change(measure, lo: float, hi: float, *, members: int = 16, rtol: float = 1e-7, atol: float = 0.0) -> float:
    """The first x in (lo, hi] where measure(x) >= 0, given measure(lo) < 0 <= measure(hi).

    Batched bisection: each round evaluates `members` evenly spaced points
    of the bracket in one call and keeps the cell before the first point with
    measure >= 0, so one round divides the bracket by members + 1. Returns the
    upper end of the final bracket (hi − lo <= max(rtol·hi, atol)).
    """
    while hi - lo > max(rtol * abs(hi), atol):
        points = np.linspace(lo, hi, members + 2)[1:-1]
        values = np.asarray(measure(points), dtype=float)
        above = np.flatnonzero(values >= 0)
        if above.size:
            i = int(above[0])
            lo, hi = (float(points[i - 1]) if i else lo), float(points[i])
        else:
            lo = float(points[-1])
    return hi


def _golden_maxima(measure, a, b, iterations: int = 16):
    """Golden-section maxima of `measure` on the brackets [a_i, b_i], all at once: (x, measure(x)).

    A bracket stops early once its two interior values differ by less than 1 %
    of their distance below 0: the maximum is then settled well below 0.
    """
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    values = np.asarray(measure(np.concatenate([c, d])), dtype=float)
    fc, fd = values[: c.size], values[c.size:]
    for _ in range(iterations):
        top = np.maximum(fc, fd)
        active = (top < 0) & (np.abs(fc - fd) >= 0.01 * -top)
        if np.any(top >= 0) or not np.any(active):
            break
        left = fc > fd  # the maximum lies in [a, d]
        a, b = np.where(active & ~left, c, a), np.where(active & left, d, b)
        new_c, new_d = b - ratio * (b - a), a + ratio * (b - a)
        probe = np.where(left, new_c, new_d)[active]
        fp = np.full(a.shape, -np.inf)
        fp[active] = np.asarray(measure(probe), dtype=float)
        c, d = np.where(active, np.where(left, new_c, d), c), np.where(active, np.where(left, c, new_d), d)
        fc, fd = np.where(active, np.where(left, fp, fd), fc), np.where(active, np.where(left, fc, fp), fd)
    better = fc >= fd
    return np.where(better, c, d), np.where(better, fc, fd)
