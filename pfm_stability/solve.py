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

__all__ = ["bisect_root", "expand_bracket"]


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
