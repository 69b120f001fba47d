"""The speed mask from the routes' stretches, and its upstream dilation (`maps.deciding.outputs.speed_limits`, docs/maps.md,
"The speed mask")."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from pfm_stability.maps.reading.occupancy import OccupancyMap
from pfm_stability.maps.deciding.outputs import route_piece, speed_limits, upstream_distance
from pfm_stability.maps.deciding.paths import PathStretch
from pfm_stability.maps.reading.routes import path_of

R = 0.05  # m per map cell
V, W = 1.0, 0.4  # m/s, m


def _analysis(points, stretch_arcs, V_star=0.4, horizontal=True):
    """A 20 m corridor's map (all free) with one route along it and one unstable stretch of V* = `V_star`."""
    shape = (40, 420) if horizontal else (420, 40)
    values = np.zeros(shape, dtype=np.int8)
    occupancy = OccupancyMap("corridor", R, (0.0, 0.0, 0.0), values, values != 0, values == 0)
    route = path_of(np.asarray(points, dtype=float), 0, "test")
    a, b = stretch_arcs
    stretch = PathStretch(0, a, b, 0, 0, 0, 0, b - a, "unstable", V_critical=V_star)
    paths = SimpleNamespace(paths=(route,), stretches=(stretch,))
    return SimpleNamespace(occupancy=occupancy, robot=SimpleNamespace(V=V, W=W), segments=(), paths=paths)


def _expected(shape, lo, hi, percent, horizontal=True):
    """Closed form: 100 everywhere except within W/2 of the straight piece from `lo` to `hi` (along the corridor's axis
    at 1 m from the map's edge)."""
    jj, ii = np.mgrid[0:shape[0], 0:shape[1]]
    x, y = (ii + 0.5) * R, (jj + 0.5) * R
    along, across = (x, y) if horizontal else (y, x)
    gap = np.maximum(np.maximum(lo - along, along - hi), 0.0)
    near = np.hypot(gap, across - 1.0) <= W / 2
    return np.where(near, percent, 100)


@pytest.mark.parametrize("horizontal", [True, False])
@pytest.mark.parametrize("reverse", [False, True])
def test_slow_zone_starts_the_braking_distance_earlier_both_ways(horizontal, reverse):
    """A straight 20 m route (two pieces, along x or along y, listed in either order) with one unstable stretch from
    8 m to 12 m at V* = 0.4 m/s, V = 1 m/s: without dilation the mask is 40 % within W/2 of that stretch; with
    a_max = 0.5 m/s² it reaches (V² − V*²)/(2 a_max) = 0.84 m further at both ends (a robot may come from either end),
    the closed form of the braking distance. Compared cell by cell with the distance to a straight piece (exact
    geometry: no tolerance except the cells' centres, none of which lies within 1e-6 m of the zone's edge)."""
    line = [(0.0, 1.0), (10.0, 1.0), (20.0, 1.0)]
    points = line if horizontal else [(y, x) for x, y in line]
    arcs = (8.0, 12.0)
    if reverse:
        points, arcs = points[::-1], (20.0 - arcs[1], 20.0 - arcs[0])
    analysis = _analysis(points, arcs, horizontal=horizontal)
    shape = analysis.occupancy.values.shape
    assert np.array_equal(speed_limits(analysis), _expected(shape, 8.0, 12.0, 40, horizontal))
    reach = (V**2 - 0.4**2) / (2 * 0.5)
    assert upstream_distance(V, 0.4, 0.5) == pytest.approx(0.84, rel=1e-12)
    assert np.array_equal(speed_limits(analysis, a_max=0.5), _expected(shape, 8.0 - reach, 12.0 + reach, 40, horizontal))


def test_dilation_is_clipped_at_the_route_ends_and_needs_a_positive_deceleration():
    """A stretch 0.5 m from the route's start dilated by 0.84 m reaches only the route's start (the route ends there);
    V* >= V needs no braking (0 m); a_max <= 0 is a one-line ValueError naming it."""
    analysis = _analysis([(0.0, 1.0), (20.0, 1.0)], (0.5, 3.0))
    shape = analysis.occupancy.values.shape
    assert np.array_equal(speed_limits(analysis, a_max=0.5), _expected(shape, 0.0, 3.0 + 0.84, 40))
    assert upstream_distance(1.0, 1.2, 0.5) == 0.0
    with pytest.raises(ValueError, match=r"a_max must be > 0"):
        upstream_distance(1.0, 0.5, 0.0)


def test_route_piece_follows_the_polyline():
    """The piece of an L-shaped route (3 m along x, then 4 m along y) between arcs 2 and 5 m: from (2, 0) through the
    corner (3, 0) to (3, 2), by hand; its length is 3 m."""
    piece = route_piece([(0, 0), (3, 0), (3, 4)], 2.0, 5.0)
    assert piece == pytest.approx(np.array([[2, 0], [3, 0], [3, 2]]), abs=1e-12)
    assert math.fsum(np.hypot(*np.diff(piece, axis=0).T)) == pytest.approx(3.0, rel=1e-12)


def test_a_zone_wherever_the_verdict_is_unstable():
    """A stable stretch gets no zone (100 %), whatever V* a hand-built one carries; an unstable stretch gets its zone
    at floor(100·V*/V) (exact integers: 40 % for V* = 0.4 V), and at the filter's 1 % floor when no speed on the ladder
    calms it (V* = 0): a zone wherever the verdict is unstable (docs/maps.md, "The speed mask")."""
    a = _analysis([(0.0, 1.0), (20.0, 1.0)], (5.0, 10.0), V_star=0.0)
    stable = PathStretch(0, 5.0, 10.0, 0, 0, 0, 0, 5.0, "stable", V_critical=0.0)
    a.paths = SimpleNamespace(paths=a.paths.paths, stretches=(stable,))
    assert np.all(speed_limits(a) == 100)
    a.paths = SimpleNamespace(paths=a.paths.paths, stretches=(replace(stable, verdict="unstable"),))
    assert speed_limits(a).min() == 1
    a.paths = SimpleNamespace(paths=a.paths.paths, stretches=(replace(stable, verdict="unstable", V_critical=0.4),))
    assert speed_limits(a).min() == 40
