"""The plan as Nav2's controller server hands it, the lookahead point, and the inflation costmap (docs/controllers.md).

Each rule is checked against the Nav2 source's statement of it, computed here by hand on small cases: nav2_util's
``getLookAheadPoint`` (arc length from the first pose, linear interpolation), ``FeasiblePathHandler`` (the last of
equally close poses, never the last pose, the prune distance exclusive, the costmap window), and the inflation
layer's ``computeCost`` with its cost table and the cut at ⌈inflation_radius/resolution⌉ cells.
"""

import math

import numpy as np
import pytest

from pfm_stability.controllers.costmap import CorridorCostmap, Inflation

from pfm_stability.controllers.plan import Plan, local_plan, lookahead_point, straight_plan

from pfm_stability.controllers.base import RobotState
from pfm_stability.controllers.plan import closest_pose, prune


def test_lookahead_point_is_arc_length_along_the_plan_with_linear_interpolation():
    """getLookAheadPoint: the first pose with path_dist + d >= L, the point L − path_dist along its segment (exact to
    round-off: two divisions), heading the segment's; beyond the end the last pose and the shortened distance."""
    x, y = np.array([0.0, 0.3, 0.3, 1.0]), np.array([0.0, 0.4, 1.0, 1.0])  # segments of 0.5, 0.6, 0.7 m
    yaw = np.zeros(4)
    px, py, heading, used = lookahead_point(x, y, yaw, 0.8)
    assert (px, py) == pytest.approx((0.3, 0.4 + 0.3), abs=1e-15)
    assert heading == pytest.approx(math.pi / 2) and used == 0.8
    px, py, heading, used = lookahead_point(x, y, yaw, 0.5)  # exactly at a pose: that pose (d >= L)
    assert (px, py) == pytest.approx((0.3, 0.4), abs=1e-15)
    px, py, heading, used = lookahead_point(x, y, yaw + 0.25, 5.0)
    assert (px, py, heading, used) == pytest.approx((1.0, 1.0, 0.25, 1.8))
    px, py, heading, used = lookahead_point(x, y, yaw, 2.0, interpolate_after_goal=True)
    assert (px, py, heading, used) == pytest.approx((1.2, 1.0, 0.0, 2.0))


def test_the_local_plan_starts_at_the_last_closest_pose_and_keeps_the_prune_distance():
    """findPlanSegment: min_by keeps the last of equal minima; the pruned end is the first pose whose integrated
    distance exceeds prune_distance, excluded; never the last pose as the closest (two poses remain)."""
    plan = Plan([0.0, 1.0, 2.0, 3.0, 4.0, 5.0], [0.0] * 6, [0.0] * 6)
    part = local_plan(plan, RobotState(1.5, 0.0, 0.0), prune_distance=2.0)
    assert part.first == 2 and list(part.x) == [2.0, 3.0, 4.0]  # 1 and 2 tie: the later; 5 is 3 m on, beyond 2
    part = local_plan(plan, RobotState(9.0, 0.0, 0.0), prune_distance=2.0)
    assert part.first == 4 and list(part.x) == [4.0, 5.0]


def test_the_local_plan_ends_at_the_costmap_window_and_the_closest_pose_is_searched_near_the_plan_start():
    """transformLocalPlan stops at the first pose off the costmap; max_robot_pose_search_dist (half the window's larger
    side, 1.5 m for 3 m) bounds the search, which pruning (Plan.pruned) moves along with the robot."""
    cm = CorridorCostmap()
    plan = straight_plan(10.0, 0.05, x0=-1.0)
    state = RobotState(0.0, 0.0, 0.0)
    part = local_plan(plan, state, cm.window(0.0, 0.0))
    assert part.x[0] == pytest.approx(0.0, abs=1e-12) and part.x[-1] == pytest.approx(1.5) and part.x[-1] < cm.window(0, 0).x0 + 3.0
    far = RobotState(3.0, 0.0, 0.0)
    assert plan.x[closest_pose(plan, far, 1.5)] == pytest.approx(0.5)  # the search stops 1.5 m after the plan's start
    starts = []
    for _ in range(3):  # each cycle's pruning moves the search on by at most 1.5 m
        plan = prune(plan, far, cm.window(3.0, 0.0))
        starts.append(plan.x[0])
    assert starts == pytest.approx([0.5, 2.0, 3.0])


def test_inflation_cost_follows_compute_cost():
    """computeCost: 254 at 0, 253 within the inscribed radius, ⌊252·exp(−f(d − r))⌋ beyond, 0 past the radius (float form
    untruncated; checked at hand-picked distances to 1e-12)."""
    inf = Inflation(inflation_radius=0.7, cost_scaling_factor=3.0, inscribed_radius=0.22)
    assert inf.cost(0.0) == 254 and inf.cost(0.22) == 253 and inf.cost(0.71) == 0
    assert inf.cost(0.5) == pytest.approx(252 * math.exp(-3.0 * 0.28), rel=1e-12)


def test_the_cell_table_truncates_and_cuts_at_whole_cells():
    """With nav2_bringup's 0.70 m / 3.0 at 0.05 m cells the cost at 14 cells is ⌊252·e^(−1.44)⌋ = 59 and at 15 cells 0 (the
    cut at ⌈0.7/0.05⌉ = 14 cells); 1.004 cells reads the table at 1.00 (rounded to 1/100 cell)."""
    inf = Inflation(0.70, 3.0, 0.22)
    costs = inf.cell_cost(np.array([0.0, 1.0, 4.0, 5.0, 14.0, 15.0, 1.004]), 0.05)
    assert list(costs[:4]) == [254, 253, 253, int(252 * math.exp(-3.0 * 0.03))]
    assert costs[4] == 59 == int(252 * math.exp(-3.0 * 0.48)) and costs[5] == 0 and costs[6] == costs[1]


def test_the_grid_corridor_is_its_rows_costs_and_the_exact_one_the_formula():
    """A corridor of half-width 0.6 m: row j costs the table at min(12 − j, j + 12) cells (walls on rows ±12), the
    exact costmap the float formula at the point; equal (to the truncation, < 1) at row centres."""
    grid, exact = CorridorCostmap(half_width=0.6), CorridorCostmap(half_width=0.6, exact=True)
    y = np.arange(-12, 13) * 0.05
    g, e = grid.cost(np.zeros_like(y), y), exact.cost(np.zeros_like(y), y)
    assert np.all((e - g >= 0) & (e - g < 1)) and g[0] == g[-1] == 254 and np.array_equal(g, g[::-1])
    assert grid.cost(0.0, 0.024) == grid.cost(0.0, 0.0) != grid.cost(0.0, 0.026)  # cell edges at ±0.025


def test_a_lattice_shift_moves_the_cells_and_walls():
    """lattice = (0, 0.02): row centres at 0.05·j + 0.02, the walls on the rows nearest ∓0.6 (−0.58 and 0.62); the
    window's origin on the shifted corners."""
    cm = CorridorCostmap(half_width=0.6, lattice=(0.0, 0.02))
    assert cm.walls == pytest.approx((-0.58, 0.62))
    assert cm.rows(np.array([0.02, 0.044, 0.046])).tolist() == [0, 0, 1]
    w = cm.window(0.0, 0.0)
    assert ((w.y0 - 0.02 + 0.025) / 0.05) == pytest.approx(round((w.y0 - 0.02 + 0.025) / 0.05))
    with pytest.raises(ValueError):
        CorridorCostmap(half_width=0.6, lattice=(0.0, 0.2))


def test_the_algorithms_defaults_are_the_registry_s():
    """One declaration of Nav2's defaults (`controllers.registry`, the sources' declare_parameter values): every field
    of RPP's, Graceful's, MPPI's and DWB's parameters that the registry declares has the registry's default, except the
    fields each module names in ``BRINGUP_DEFAULTS`` with its reason (MPPI's critics, DWB's limits and critics: the source
    declares none a controller can run with). A default that drifts from Nav2's source fails here."""
    from dataclasses import MISSING, fields

    from pfm_stability.controllers import dwb, graceful, mppi, rpp
    from pfm_stability.controllers.registry import get_controller

    for name, module, cls in (("rpp", rpp, rpp.RPPParams), ("graceful", graceful, graceful.GracefulParams),
                              ("mppi", mppi, mppi.MPPIParams), ("dwb", dwb, dwb.DWBParams)):
        declared = {p.name: p.default for p in get_controller(name).parameters}
        exceptions = set(getattr(module, "BRINGUP_DEFAULTS", ()))
        shared = [f for f in fields(cls) if f.name in declared and f.name not in exceptions]
        assert len(shared) >= 8, name
        for f in shared:
            default = f.default if f.default is not MISSING else f.default_factory()
            expected = declared[f.name]
            if f.name == "trajectory_generator_name":
                expected = expected.split("::")[-1]
            assert default == pytest.approx(expected) if isinstance(expected, float) else default == expected, (name, f.name)
        for field_name in exceptions:
            assert field_name in declared, (name, field_name)
