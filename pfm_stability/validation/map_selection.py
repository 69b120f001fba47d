"""Which segments of a map to simulate: the cases with a prediction, the length a measurement needs, a seeded spread.

Part of the map validation (`validation.maps`, docs/validation.md, docs/maps.md).
**Selection** (`select_segments`, deterministic given the seed): segments with
a prediction, in three tiers taken in order until `count` are chosen: long
enough with |margin| > `CLEAR_MARGIN`; long enough with a smaller margin; too
short (reported as not measurable, not counted). In a tier the stable and
unstable segments share the draw in proportion (each at least one when both
exist), each group cut into margin-quantile bins, one segment drawn per bin.
Long enough (`required_length`): length − 2·end_margin covers `min_periods`
periods 2π/ω at V, ω from the `sampled` model's dominant root at NV = N·V (the
boundary's ω* when that root is real or far slower: then also
`min_periods`/|σ|, a weak field's slow drift, whose sign turning points cannot show).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..analysis.criteria import loop_of
from ..models import Loop, Sampled
from ..parameters import Controller, Robot

__all__ = ["CLEAR_MARGIN", "MIN_PERIODS", "predicted", "periods_omega", "required_length", "select_segments", "number"]

CLEAR_MARGIN = 0.10
"""|margin| above which a prediction is clear (preferred in the selection; the bar of the agreement)."""

MIN_PERIODS = 3.0
"""Periods a run must cover: σ by peaks needs >= 4 turning points, the first swing left out (`sim.metrics`).
Shorter records (1–1.5 periods) read σ's sign right on the synthetic corridors through the linear-prediction fit
(`validation.maps.short_record_fit`), but on the shipped maps they added disagreements (docs/maps.md, "Validation")."""


# ---------------------------------------------------------------- segments
def number(value):
    """A real number as float, or None (None, NaN, bool or not a number).

    Parameters
    ----------
    value : object
        Anything.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return None
    value = float(value)
    return None if math.isnan(value) else value


def predicted(segment) -> bool:
    """True if the segment carries a verdict to check (finite geometry, margin and a bool `stable`).

    Parameters
    ----------
    segment : MapSegment
        A segment of a map's analysis.
    """
    geometry = [number(getattr(segment, k, None)) for k in ("x0", "y0", "x1", "y1", "length")]
    margin = number(getattr(segment, "margin", None))
    stable = getattr(segment, "stable", None)
    return (
        all(v is not None and math.isfinite(v) for v in geometry)
        and margin is not None
        and isinstance(stable, (bool, np.bool_))
        and number(getattr(segment, "N", None)) is not None
    )


def periods_omega(segment, robot: Robot, controller: Controller, model: Sampled) -> tuple:
    """(ω for the period in rad/s, σ of the dominant root at N·V or None, True if that root oscillates).

    Parameters
    ----------
    segment : MapSegment
        The segment (N, c).
    robot, controller : Robot, Controller
        The robot and its controller.
    model : Sampled
        The sampled model.
    """
    N = number(segment.N)
    c = number(getattr(segment, "c", 0.0)) or 0.0
    try:
        loop = Loop.of(robot, controller, c=c)
    except ValueError:
        loop = loop_of(robot, controller)
    omega_star, sigma, omega = model.boundary(loop).omega_critical or 0.0, None, 0.0
    if N not in (None, 0.0) and math.isfinite(N):
        root = model.rightmost_root(N * robot.V, loop)
        sigma, omega = float(root.real), abs(float(root.imag))
    oscillates = omega >= 0.2 * omega_star and omega > 0
    if not oscillates:  # a real (or far slower) dominant root: the loop's own time scale
        omega = omega_star if omega_star > 0 else robot.k
    return omega, sigma, oscillates


def required_length(omega: float, V: float, end_margin: float, min_periods: float = MIN_PERIODS, sigma: float | None = None) -> float:
    """Segment length a measurement needs, m: 2·end_margin + V·(`min_periods` periods 2π/ω, rad/s), and,
    given the σ (1/s) of a non-oscillating dominant root, at least `min_periods`/|σ| (its sign shows only in a slow drift).

    Parameters
    ----------
    omega : float
        Oscillation frequency, rad/s.
    V : float
        Speed, m/s.
    end_margin : float
        Length left out at each end, m.
    min_periods : float
        Periods the measurement needs.
    sigma : float, optional
        σ of a non-oscillating dominant root, 1/s.
    """
    duration = min_periods * 2 * math.pi / omega
    if sigma:
        duration = max(duration, min_periods / abs(sigma))
    return 2 * end_margin + V * duration


def _stratified(indices, margins, k: int, rng) -> list:
    """`k` of `indices`: one drawn from each of k margin-quantile bins (sorted by margin, then index)."""
    if k <= 0:
        return []
    order = sorted(indices, key=lambda i: (margins[i], i))
    return [int(b[rng.integers(b.size)]) for b in np.array_split(np.array(order), k) if b.size]


def _split(count: int, sizes: tuple) -> tuple:
    """Allocate `count` (<= sum of `sizes`) between two groups: proportional, >= 1 each when both exist and count >= 2."""
    a, b = sizes
    if a == 0 or b == 0:
        return min(count, a), min(count, b)
    ka = min(max(round(count * a / (a + b)), 1), count - 1) if count >= 2 else int(a >= b)
    ka = max(min(ka, a), count - b)
    return ka, count - ka


def select_segments(margins, stable, long_enough, count: int, *, seed: int = 0) -> list:
    """Indices of `count` segments spread over the predicted margins (deterministic given `seed`).

    Tiers, taken in order until `count` are chosen: long enough with
    |margin| > `CLEAR_MARGIN`; long enough with a smaller margin; too short.
    Within a tier the stable and the unstable segments share the draw in
    proportion (each at least one when both exist), and each group is cut
    into margin-quantile bins, one segment drawn per bin.

    Parameters
    ----------
    margins : sequence of float
        Predicted margins (NV*/NV − 1; ``inf`` allowed).
    stable : sequence of bool
        Predicted verdicts.
    long_enough : sequence of bool
        Segment long enough to measure.
    count : int
        Segments wanted (fewer if fewer exist).
    seed : int

    Returns
    -------
    list of int
        Chosen indices, sorted by margin.
    """
    rng = np.random.default_rng(seed)
    n = len(margins)
    tiers = (
        [i for i in range(n) if long_enough[i] and abs(margins[i]) > CLEAR_MARGIN],
        [i for i in range(n) if long_enough[i] and not abs(margins[i]) > CLEAR_MARGIN],
        [i for i in range(n) if not long_enough[i]],
    )
    chosen = []
    for tier in tiers:
        take = min(count - len(chosen), len(tier))
        if take <= 0:
            continue
        groups = ([i for i in tier if stable[i]], [i for i in tier if not stable[i]])
        for group, k in zip(groups, _split(take, tuple(len(g) for g in groups))):
            chosen += _stratified(group, margins, k, rng)
    return sorted(chosen, key=lambda i: (margins[i], i))
