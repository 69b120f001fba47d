"""MPPI and DWB as Nav2's sources compute them (docs/controllers.md): pieces checked against independent oracles
(scipy's Savitzky–Golay coefficients, Nav2's loops written out here in plain Python), the rules the sources state
(acceleration limits, the model delay's shift, the period refused, every-trajectory-collides), and the linearisation's
sampling uncertainty. Small batches keep the tests cheap (64 samples; the defaults are 1000)."""

import math

import numpy as np
import pytest
from scipy.signal import savgol_coeffs

from pfm_stability.controllers.costmap import CorridorCostmap

from pfm_stability.controllers.base import NoValidControl, RobotState

from pfm_stability.controllers.linearize import linearize

from pfm_stability.controllers.plan import straight_plan
from pfm_stability.controllers import dwb, mppi
from pfm_stability.controllers.mppi import _reset, _rollout_velocities
from pfm_stability.controllers.mppi_critics import F, closest_path_points

PLAN = straight_plan(12.0, 0.05, x0=-1.0)
SMALL = mppi.MPPIParams(batch_size=64)


def test_savitzky_golay_taps_are_scipys_and_keep_quadratics():
    """savitskyGolayFilter's nine taps (−21 … 59 … −21)/231 are scipy's savgol_coeffs(9, 2); a quadratic sequence (with
    its own past as history) comes back unchanged but for the unfiltered last element (float32: 1e-5 of its size)."""
    taps = np.array([-21, 14, 39, 54, 59, 54, 39, 14, -21]) / 231.0
    assert np.allclose(savgol_coeffs(9, 2), taps, atol=1e-15)
    k = np.arange(-4, 56)
    q = (0.3 + 0.01 * k - 0.0004 * k * k).astype(F)
    out = mppi.savitzky_golay(q[4:].copy(), q[:4], 2)
    assert np.allclose(out[:-4], q[4:-4], rtol=0, atol=1e-5 * np.abs(q).max())


def test_the_rollout_keeps_the_accelerations_and_the_model_delay_shifts_as_nav2_does():
    """MotionModel::predict: each step within ax·dt (vx) and az·dt (wz) of the previous; applyDelayShift with a delay of
    d model steps shifts the velocities by d − 1 and fills steps 1 … d − 1 with the commands in flight (so d = 1 does
    nothing)."""
    rng = np.random.default_rng(1)
    memory = _reset(SMALL, rng)
    cvx = (0.5 + 0.5 * rng.standard_normal((56, 64))).astype(F)
    cwz = (2.0 * rng.standard_normal((56, 64))).astype(F)
    vx, wz = _rollout_velocities(SMALL, (F(0.4), F(0.1)), cvx, cwz, memory)
    assert np.all(np.abs(np.diff(vx, axis=0)) <= 3.0 * 0.05 + 1e-6) and np.all(np.abs(np.diff(wz, axis=0)) <= 3.5 * 0.05 + 1e-6)
    # exact is legitimate below: the rate limits are the same arithmetic on the same inputs, and the delay shift only
    # copies values (d = 1: none; d = 3: rows moved and the commands in flight written in), no arithmetic
    one = _reset(SMALL.replace(model_delay_wz=0.05), rng)
    assert np.array_equal(_rollout_velocities(SMALL, (F(0.4), F(0.1)), cvx, cwz, one)[1], wz)
    three = _reset(SMALL.replace(model_delay_wz=0.15), rng)
    three = type(three)(**{**three.__dict__, "delay_wz": np.array([0.7, 0.8, 0.9], dtype=F)})
    shifted = _rollout_velocities(SMALL, (F(0.4), F(0.1)), cvx, cwz, three)[1]
    assert np.all(shifted[1] == F(0.8)) and np.all(shifted[2] == F(0.9)) and np.array_equal(shifted[3:], wz[1:-2])


def _find_closest_path_pt(vec, dist, init):
    """utils::findClosestPathPt, line by line."""
    distim1 = vec[init] if init != 0 else 0.0
    for i in range(init + 1, len(vec)):
        disti = vec[i]
        if disti > dist:
            if i > 0 and dist - distim1 < disti - dist:
                return i - 1
            return i
        distim1 = disti
    return len(vec) - 1


def test_path_align_matches_plan_points_as_nav2s_loop_does():
    """The vectorised matching of trajectory points to plan points by integrated distance equals Nav2's loop, each
    search starting at the previous match, on random monotone distances (exact: integers)."""
    r = np.random.default_rng(2)
    dists = np.concatenate([[0.0], np.cumsum(r.uniform(0.01, 0.1, 30))]).astype(F)
    traj = np.cumsum(r.uniform(0.0, 0.2, (13, 50)), axis=0).astype(F)
    matched = closest_path_points(dists, traj)
    for t in range(50):
        init = 0
        for p in range(13):
            init = _find_closest_path_pt(dists, traj[p, t], init)
            assert matched[p, t] == init


def test_mppi_is_seeded_and_refuses_a_period_longer_than_model_dt():
    """The same Generator seed gives the same command, another seed another; Optimizer::setOffset throws for a
    controller period beyond model_dt (ValueError here), and a shorter one runs without shifting the sequence."""
    cm = CorridorCostmap(half_width=0.8)
    state = RobotState(0.0, 0.05, 0.0, 0.5, 0.0)
    a, b, c = (mppi.command(state, PLAN, cm, SMALL, rng=np.random.default_rng(s)) for s in (3, 3, 4))
    assert (a.v, a.w) == (b.v, b.w) != (c.v, c.w)
    with pytest.raises(ValueError, match="model_dt"):
        SMALL.replace(controller_frequency=10.0)
    assert not SMALL.replace(controller_frequency=40.0).shift_control_sequence and SMALL.shift_control_sequence


def test_mppi_fails_when_every_trajectory_collides():
    """A corridor narrower than the inscribed radius: every point is inscribed (a collision for a point cost), the
    optimizer resets and retries once, then NoValidControl (Optimizer::fallback)."""
    with pytest.raises(NoValidControl):
        mppi.command(RobotState(0.0, 0.0, 0.0, 0.5, 0.0), PLAN, CorridorCostmap(half_width=0.2, exact=True), SMALL,
                     rng=np.random.default_rng(0))


def test_mppi_linearisation_is_restoring_with_its_sampling_error():
    """About a corridor's centre MPPI steers back (k_y, k_θ > 0) and cruises near vx_max; the standard error over four
    noise draws is stated and smaller than the gains (batch 64: a noisy optimizer, still well determined)."""
    g = linearize("mppi", SMALL.replace(batch_size=128), CorridorCostmap(half_width=0.6, exact=True), draws=4)
    assert g.k_y > 3 * g.k_y_se > 0 and g.k_theta > 3 * g.k_theta_se > 0
    assert 0.3 < g.V <= 0.5 and g.k_w == 0.0 and g.draws == 4


def test_dwb_samples_the_window_as_the_iterator_does():
    """OneDVelocityIterator: 20 values evenly over [−1, 1] rad/s with 0 inserted where they cross it, 20 over
    [0, 0.26] m/s; (0, 0) invalid; the limited-acceleration generator's window is ±acc·T around the measured rate."""
    p = dwb.DWBParams()
    vx, wz = dwb.velocity_samples(p, 0.26, 0.0)
    thetas = np.unique(np.round(wz, 12))
    assert vx.size == 20 * 21 - 1 and thetas.size == 21 and 0.0 in thetas
    assert np.allclose(np.delete(thetas, 10), np.linspace(-1.0, 1.0, 20), atol=1e-12)
    lim = p.replace(trajectory_generator_name="LimitedAccelGenerator")
    w = np.unique(np.round(dwb.velocity_samples(lim, 0.26, 0.3)[1], 12))
    assert w.min() == pytest.approx(0.3 - 3.2 * 0.05) and w.max() == pytest.approx(0.3 + 3.2 * 0.05)


def test_dwb_chooses_a_sample_that_steers_back_at_full_speed():
    """Off the centre line DWB picks a sampled yaw rate of the opposite sign and the largest speed (GoalDist rewards
    progress); on it (lattice centred) ω = 0."""
    p, cm = dwb.DWBParams(), CorridorCostmap(half_width=0.6)
    vx, wz = dwb.velocity_samples(p, 0.26, 0.0)
    for ey in (0.05, -0.05):
        cmd = dwb.command(RobotState(0.0, ey, 0.0, 0.26, 0.0), PLAN, cm, p)
        assert np.any(np.isclose(wz, cmd.w, atol=1e-12)) and math.copysign(1, cmd.w) == -math.copysign(1, ey)
        assert cmd.v == pytest.approx(0.26)
    assert dwb.command(RobotState(0.0, 0.0, 0.0, 0.26, 0.0), PLAN, cm, p).w == 0.0


def test_dwb_grid_distance_is_the_costmap_queues_on_a_straight_plan():
    """The map grid's propagation (costmap_queue: Euclidean order from the sources, each cell the Manhattan distance to
    the source that reached it), run here as Nav2's queue on a 21 × 21 grid, equals the Euclidean-nearest source's
    Manhattan distance for a plan along a grid row, everywhere (exact: integers)."""
    import heapq

    n = 21
    sources = [(i, 10) for i in range(3, 15)]
    value = {}
    heap = [(0.0, k, s, s) for k, s in enumerate(sources)]
    seen = set(sources)
    counter = len(heap)
    while heap:
        _, _, (x, y), (sx, sy) = heapq.heappop(heap)
        value[(x, y)] = abs(x - sx) + abs(y - sy)
        for nx, ny in ((x - 1, y), (x, y - 1), (x + 1, y), (x, y + 1)):
            if 0 <= nx < n and 0 <= ny < n and (nx, ny) not in seen:
                seen.add((nx, ny))
                counter += 1
                heapq.heappush(heap, (math.hypot(nx - sx, ny - sy), counter, (nx, ny), (sx, sy)))
    cm = CorridorCostmap()
    r = cm.resolution
    sx, sy = np.array([s[0] for s in sources]) * r, np.array([s[1] for s in sources]) * r
    qx, qy = np.meshgrid(np.arange(n) * r, np.arange(n) * r, indexing="ij")
    got = dwb._manhattan(cm, cm.window(0.5, 0.5), sx, sy, qx.ravel(), qy.ravel()).reshape(n, n)
    assert all(got[i, j] == value[(i, j)] for i in range(n) for j in range(n))
