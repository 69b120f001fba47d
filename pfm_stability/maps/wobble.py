"""The speed mask by wobble tolerance: each straight segment's V_tolerance (``map --wobble TOL``; docs/maps.md).

Past V* a supercritical corridor settles on a small limit cycle whose amplitude grows from 0
(docs/wobble.md). A user who accepts a wobble of TOL metres may drive a segment up to
V_tolerance, the fastest speed whose cycle stays under TOL (`analysis.wobble.corridor_branch`,
`WobbleBranch.tolerance_speed`), instead of V*. Each segment is read as the straight corridor
of the map's law (`MapAnalysis.law`) whose half-width L is measured across the segment's judged
part: from each of its samples with an equilibrium a ray along the segment's normal, either way,
finds the first occupied cell — its centre for the ``grid`` law (the law's walls are rows of
cells, `laws.effective_force.GridWallLaw`), the point where the ray enters it for the ``power``
law (whose L runs to the wall's face, as in `equilibria.power_equilibria`, there on the map's pixels); a straight line fitted to each side's hits is the
wall, and L is half the distance between the two lines at the judged part's middle (exact for
straight parallel walls, also when the segment lies at a small angle to them).

The speed written in the mask (`SegmentWobble.V_limit`) is V_tolerance only where the method
can be trusted: a supercritical branch whose cycle at V_tolerance passes the describing
function's trust test (`analysis.wobble.trusted_cycle`), and whose V* agrees with the segment's
own to `V_CRITICAL_AGREEMENT` (otherwise the segment is not the straight corridor the wobble
models: walls thicker than a cell, one-sided, bent). Everywhere else the mask keeps V*, and
`SegmentWobble.reason` says why. Route stretches (`MapAnalysis.paths`) keep their V*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..analysis.wobble import WOBBLE_MODELS, corridor_branch, trusted_cycle
from ..io.serialize import json_number
from ..laws.effective_force import GridWallLaw
from ..checks import check_number
from .equilibria import RAY_LENGTH

__all__ = ["V_CRITICAL_AGREEMENT", "SegmentWobble", "segment_half_width", "with_wobble"]

V_CRITICAL_AGREEMENT = 0.02
"""Largest |V*_wobble/V*_segment − 1| for which a segment counts as the straight corridor the wobble models (the
map's straight corridors agree with the grid law's to 0.7 %, tests/test_map_corridors.py)."""
_RAY_STEP = 0.125
"""Step of a ray across the segment, histogram cells."""


@dataclass(frozen=True)
class SegmentWobble:
    """One segment's speed limit by wobble tolerance (module docstring; JSON ``segments[i].wobble``).

    Attributes
    ----------
    tolerance : float
        The largest acceptable lateral amplitude, m.
    L : float or None
        Half-width of the straight corridor the segment is read as, m (None: not measured, see `reason`).
    V_tolerance : float or None
        The fastest speed whose wobble stays under `tolerance`, m/s (`WobbleBranch.tolerance_speed`; None: no branch).
    criticality : str or None
        ``"supercritical"`` or ``"subcritical"`` (None: no branch).
    V_limit : float or None
        The speed the mask uses, m/s: `V_tolerance` when trusted, else the segment's V* (None: no verdict).
    reason : str or None
        Why `V_limit` is V* rather than `V_tolerance` (None when it is `V_tolerance`).
    """

    tolerance: float
    L: float | None
    V_tolerance: float | None
    criticality: str | None
    V_limit: float | None
    reason: str | None = None

    def to_dict(self) -> dict:
        """JSON: every field (infinities as "inf", undefined as null)."""
        number = lambda x: None if x is None or (isinstance(x, float) and math.isnan(x)) else json_number(x)
        return {"tolerance": self.tolerance, "L": number(self.L), "V_tolerance": number(self.V_tolerance),
                "criticality": self.criticality, "V_limit": number(self.V_limit), "reason": self.reason}


def segment_half_width(analysis, index: int) -> float | None:
    """Half-width L of the straight corridor segment `index` is read as, m (module docstring; None: no sample with an
    equilibrium in its judged part, or a side with no wall within `equilibria.RAY_LENGTH`).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (its grid, samples and segments).
    index : int
        The segment's index in `analysis.segments`.
    """
    s = analysis.segments[index]
    samples, grid = analysis.samples, analysis.grid
    if s.judged_from is None:
        return None
    tx, ty = (s.x1 - s.x0) / s.length, (s.y1 - s.y0) / s.length
    mine = np.flatnonzero((samples.segment == index) & np.isfinite(samples.N))
    at = (samples.x[mine] - s.x0) * tx + (samples.y[mine] - s.y0) * ty
    mine = mine[(at >= s.judged_from) & (at <= s.judged_to)]
    if mine.size == 0:
        return None
    x, y = samples.x[mine], samples.y[mine]
    centre = isinstance(analysis.law, GridWallLaw)
    nx_, ny_ = -ty, tx
    lines = []
    for sign in (1.0, -1.0):
        hx, hy = _wall_hits(grid, x, y, sign * nx_, sign * ny_, centre)
        if not np.isfinite(hx).all():
            return None
        # the wall a straight line in the segment's frame (the segment may lie at a small angle to its walls)
        along, across = (hx - s.x0) * tx + (hy - s.y0) * ty, (hx - s.x0) * nx_ + (hy - s.y0) * ny_
        lines.append(np.polyfit(along, across, 1) if np.ptp(along) > 0 else np.array([0.0, float(np.mean(across))]))
    (b_left, a_left), (b_right, a_right) = lines
    middle = (s.judged_from + s.judged_to) / 2
    gap = (a_left + b_left * middle) - (a_right + b_right * middle)
    return float(gap / 2 * math.cos(math.atan((b_left + b_right) / 2)))


def _wall_hits(grid, x, y, nx_, ny_, centre: bool) -> tuple:
    """(x, y) where a ray from each point along the unit vector (nx_, ny_) meets the first occupied histogram cell, m:
    that cell's centre (`centre`) or where the ray enters it (to half a step); nan if none within `RAY_LENGTH`."""
    c = grid.cell_size
    step = c * _RAY_STEP
    occupied = grid.occupied
    cells_x, cells_y = occupied.shape
    hx, hy = np.full(x.shape, np.nan), np.full(x.shape, np.nan)
    todo = np.arange(x.size)
    for k in range(1, int(math.ceil(RAY_LENGTH / step)) + 1):
        if todo.size == 0:
            break
        d = k * step
        i = np.floor((x[todo] + d * nx_ - grid.x_min) / c).astype(np.int64)
        j = np.floor((y[todo] + d * ny_ - grid.y_min) / c).astype(np.int64)
        inside = (i >= 0) & (i < cells_x) & (j >= 0) & (j < cells_y)
        hit = np.zeros(todo.size, dtype=bool)
        hit[inside] = occupied[i[inside], j[inside]]
        done = todo[hit]
        if centre:
            hx[done], hy[done] = grid.x_min + (i[hit] + 0.5) * c, grid.y_min + (j[hit] + 0.5) * c
        else:
            hx[done], hy[done] = x[done] + (d - step / 2) * nx_, y[done] + (d - step / 2) * ny_
        todo = todo[~hit & inside]
    return hx, hy


def with_wobble(analysis, tolerance: float):
    """The analysis with each segment's `SegmentWobble` for `tolerance` (``MapSegment.wobble``; module docstring).

    Parameters
    ----------
    analysis : MapAnalysis
        A map analysis (`analyze_map`).
    tolerance : float
        Largest acceptable lateral amplitude, m, > 0.

    Returns
    -------
    MapAnalysis
        The same analysis, its segments carrying their wobble; the verdicts, V* and route stretches unchanged.

    Raises
    ------
    ValueError
        For a tolerance that is not a number > 0.
    """
    tolerance = check_number("tolerance", tolerance, 0.0, math.inf, unit="m")
    segments = tuple(replace(s, wobble=_segment_wobble(analysis, k, tolerance)) for k, s in enumerate(analysis.segments))
    return replace(analysis, segments=segments)


def _segment_wobble(analysis, index: int, tolerance: float) -> SegmentWobble:
    s = analysis.segments[index]
    V_star = s.V_critical

    def keep(reason, L=None, V_tol=None, criticality=None):
        return SegmentWobble(tolerance, L, V_tol, criticality, V_star, reason)

    if V_star is None:
        return keep("no verdict: no speed limit")
    if not (0.0 < V_star < math.inf):
        return keep("unstable at any speed: no limit cycle to tolerate" if V_star == 0 else "stable at any speed: no wobble")
    model = analysis.model if analysis.model in WOBBLE_MODELS else "sampled"
    L = segment_half_width(analysis, index)
    if L is None:
        return keep("no corridor half-width: a side without a wall")
    try:
        branch = corridor_branch(analysis.robot, analysis.controller, analysis.law, L, model=model)
    except ValueError as error:
        return keep(f"no wobble branch: {error}", L)
    V_tol = branch.tolerance_speed(tolerance)
    common = dict(L=L, V_tol=V_tol, criticality=branch.criticality)
    if abs(branch.V_critical / V_star - 1.0) > V_CRITICAL_AGREEMENT:
        return keep(f"not the straight corridor of half-width {L:.3g} m the wobble models (its V* {branch.V_critical:.4g} m/s, "
                    f"the segment's {V_star:.4g} m/s): V* kept", **common)
    if branch.criticality != "supercritical":
        return keep("subcritical: past V* the wobble jumps to a large cycle; V* kept", **common)
    cycles = [c for c in branch.cycles_at(V_tol) if c.stable]
    if not math.isfinite(V_tol) or (V_tol > branch.V_critical and not (cycles and trusted_cycle(cycles[0]))):
        return keep("the describing function is not trusted at V_tolerance (strong harmonics or the steering-rate limit): "
                    "V* kept", **common)
    return SegmentWobble(tolerance, L, V_tol, branch.criticality, V_tol)
