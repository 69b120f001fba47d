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
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = ["Bracket", "bisect_batched", "bisect_root", "expand_bracket", "first_crossing", "gauss_legendre", "invert_decreasing", "newton_increasing", "refine_sign_change", "spread_values"]


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


def newton_increasing(func, lo, hi, *, rtol: float = 4e-16, atol: float = 0.0, iterations: int = 200, moving: bool = False):
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
    rtol, atol : float
        Stop when every step is below rtol·|x| + atol (or the bracket is that narrow); atol (units of x) for roots
        at or near 0, where rtol·|x| is below f's round-off.
    iterations : int
        At most this many steps.
    moving : bool
        Call ``func(x, index)`` with the roots still moving alone (1-D brackets; `index` into them): a converged
        root stays where it is (its step is 0 and its f the same), so it is not evaluated again — the same roots,
        for an expensive `func`.

    Returns
    -------
    ndarray
        The roots.
    """
    lo = np.array(lo, dtype=float)
    hi = np.array(hi, dtype=float)
    x = 0.5 * (lo + hi)
    previous = hi - lo
    index = np.arange(x.size)
    for _ in range(iterations):
        f, slope = func(x[index], index) if moving else func(x)
        xi, lo_i, hi_i = (x[index], lo[index], hi[index]) if moving else (x, lo, hi)
        lo_i = np.where(f < 0, xi, lo_i)
        hi_i = np.where(f > 0, xi, hi_i)
        with np.errstate(divide="ignore", invalid="ignore"):
            correction = f / slope
        newton = xi - correction
        converged = (f == 0) | (np.abs(correction) <= rtol * np.abs(xi) + atol)
        good = np.isfinite(newton) & (newton > lo_i) & (newton < hi_i) & (np.abs(correction) < 0.5 * previous)
        step_to = np.where(converged, xi, np.where(good, newton, 0.5 * (lo_i + hi_i)))
        previous = np.abs(step_to - xi)
        done = np.all(converged | (hi_i - lo_i <= rtol * np.abs(step_to) + atol))
        if moving:
            x[index], lo[index], hi[index] = step_to, lo_i, hi_i
            index, previous = index[~converged], previous[~converged]
        else:
            x, lo, hi = step_to, lo_i, hi_i
        if done:
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

    `bisect_batched` on the label measure >= 0; returns the upper end of the
    final bracket (hi − lo <= max(rtol·hi, atol)).

    Parameters
    ----------
    measure : callable
        ``measure(x)`` for an array of x, returns an array of floats.
    lo, hi : float
        The bracket: measure(lo) < 0 <= measure(hi).
    members : int
        Values evaluated per round.
    rtol, atol : float
        Stop when hi − lo <= max(rtol·hi, atol).
    """
    return bisect_batched(lambda x: np.asarray(measure(x), dtype=float) >= 0, lo, hi, members=members, rtol=rtol, atol=atol, ends=(False, True)).hi


@dataclass(frozen=True)
class Bracket:
    """Where a batched bisection left the change of label.

    Attributes
    ----------
    lo, hi : float
        The final bracket: the labels at its ends differ.
    low_label, high_label : object
        The labels at lo and hi.
    rounds : int
        Rounds run (batches of evaluations).
    evaluations : int
        Values classified.
    most_changes : int
        The largest number of label changes seen inside one round's values
        (> 1: the label is not monotone there; the change nearest lo was kept).
    """

    lo: float
    hi: float
    low_label: object
    high_label: object
    rounds: int
    evaluations: int
    most_changes: int


def bisect_batched(
    classify,
    lo: float,
    hi: float,
    *,
    members: int = 9,
    rtol: float = 1e-7,
    atol: float = 0.0,
    quantum: float | None = None,
    geometric: bool = False,
    max_rounds: int = 60,
    ends=None,
    on_round=None,
) -> Bracket:
    """Narrow [lo, hi] around the value where a label changes, many values per round.

    The one batched bisection of the package: every caller whose evaluations
    are cheaper together than apart (a vectorized growth rate, a batch of
    simulations) uses it. Each round classifies `members` values spread over
    the bracket in one call and keeps the cell before the first value whose
    label differs from the label at lo, so a round divides the bracket by
    members − 1 (the ends are not classified again).

    Parameters
    ----------
    classify : callable
        ndarray of values → sequence of labels (bools, strings …), one per value.
    lo, hi : float
        The bracket; the labels at its ends must differ.
    members : int
        Values per round, >= 3 (ends included in the first round).
    rtol, atol : float
        Stop when hi − lo <= max(rtol·|hi|, atol).
    quantum : float, optional
        Only multiples of `quantum` are valid values (e.g. corridor widths on a
        cell grid); stop when the bracket holds no further multiple.
    geometric : bool
        Spread values geometrically (lo > 0), for brackets over decades.
    max_rounds : int
        Stop after this many rounds.
    ends : (label, label), optional
        The labels at lo and hi when already known (not classified again).
    on_round : callable, optional
        ``on_round(bracket)`` after each round (progress).

    Raises
    ------
    ValueError
        If the labels at the two ends are the same.
    """
    members = max(3, int(members))
    evaluations = rounds = most = 0
    if ends is None:
        values = spread_values(lo, hi, members, quantum, geometric)
        labels = list(classify(values))
        evaluations, rounds = len(values), 1
        lo_label, hi_label = labels[0], labels[-1]
        lo, hi = float(values[0]), float(values[-1])
        if lo_label == hi_label:
            raise ValueError(f"the label is {lo_label!r} at both ends of [{lo:g}, {hi:g}]; no change to bisect")
        lo, hi, most = _first_change(values, labels, lo_label, lo, hi)
    else:
        lo_label, hi_label = ends
    bracket = Bracket(lo, hi, lo_label, hi_label, rounds, evaluations, most)
    while rounds < max_rounds and hi - lo > max(rtol * abs(hi), atol):
        inner = spread_values(lo, hi, members, quantum, geometric)[1:-1]
        if inner.size == 0:
            break
        labels = list(classify(inner))
        evaluations += len(inner)
        rounds += 1
        lo, hi, changes = _first_change(np.concatenate([[lo], inner, [hi]]), [lo_label] + labels + [hi_label], lo_label, lo, hi)
        most = max(most, changes)
        bracket = Bracket(lo, hi, lo_label, hi_label, rounds, evaluations, most)
        if on_round is not None:
            on_round(bracket)
    return bracket


def spread_values(lo, hi, members, quantum, geometric):
    """`members` values over [lo, hi] (ends included): evenly, geometrically, or on multiples of `quantum`.

    Parameters
    ----------
    lo, hi : float
        The ends of the interval (both included).
    members : int
        How many values.
    quantum : float or None
        If given, the values are multiples of it (duplicates removed: maybe fewer than `members`).
    geometric : bool
        Geometric spacing (lo > 0) rather than even spacing; ignored when `quantum` is given.
    """
    if quantum is not None:
        k0, k1 = math.ceil(lo / quantum - 1e-9), math.floor(hi / quantum + 1e-9)
        k = np.unique(np.round(np.linspace(k0, k1, members))) if k1 >= k0 else np.array([])
        return k * quantum
    return np.geomspace(lo, hi, members) if geometric else np.linspace(lo, hi, members)


def _first_change(values, labels, lo_label, lo, hi):
    """(lo, hi) of the cell before the first label that differs from lo_label, and how many changes the sequence has."""
    changes = sum(a != b for a, b in zip(labels[:-1], labels[1:]))
    first = next((i for i, label in enumerate(labels) if label != lo_label), None)
    if first is None or first == 0:
        return lo, hi, changes
    return float(values[first - 1]), float(values[first]), changes


def invert_decreasing(g, targets, lo: float, hi: float, iterations: int = 200):
    """x in [lo, hi] with g(x) = target for many targets at once, g vectorized and decreasing in x > 0.

    Elementwise bisection on log x (to round-off): each target has its own
    bracket, all narrowed together (`bisect_batched` narrows one bracket with
    many evaluations per round instead). Used for boundary curves in the
    equilibrium distance (`pfm_stability.analysis.curves`).

    Parameters
    ----------
    g : callable
        ndarray → ndarray, decreasing.
    targets : array_like
        Values of g to reach.
    lo, hi : float
        Initial bracket, 0 < lo < hi; hi is doubled (up to 100 times) until g(hi) <= min(targets).
    iterations : int
        Bisection steps at most.

    Returns
    -------
    ndarray
        Shaped like `targets`: ``nan`` for targets above g(lo), ``inf`` for targets below g(hi).
    """
    targets = np.asarray(targets, dtype=float)
    for _ in range(100):
        if g(np.array([hi]))[0] <= np.min(targets):
            break
        hi *= 2.0
    a = np.full(targets.shape, math.log(lo))
    b = np.full(targets.shape, math.log(hi))
    for _ in range(iterations):
        m = 0.5 * (a + b)
        above = g(np.exp(m)) > targets
        a = np.where(above, m, a)
        b = np.where(above, b, m)
        if np.all(b - a <= 4e-16 * np.maximum(1.0, np.abs(a))):
            break
    x = np.exp(0.5 * (a + b))
    x = np.where(targets > g(np.array([lo]))[0], np.nan, x)
    return np.where(targets < g(np.array([hi]))[0], np.inf, x)


@lru_cache(maxsize=32)
def gauss_legendre(points: int):
    """Gauss–Legendre nodes and weights on [−1, 1], cached and read-only (numpy solves an eigenproblem each time)."""
    x, w = np.polynomial.legendre.leggauss(points)
    x.flags.writeable = w.flags.writeable = False
    return x, w


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
