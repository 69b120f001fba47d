"""Regulated Pure Pursuit and the Graceful controller (docs/controllers.md): their decisions as Nav2's sources compute
them, and their numeric linearisation against closed forms derived independently.

* RPP on a straight plan: the carrot at arc L is at y = −(e_y + L·e_θ) to first order, x² + y² = L², so
  ω = v·2y/L² gives k_θ = 2V/L, k_y = 2V/L² (pure pursuit's lateral loop); `controllers.linearize` must reproduce it.
* Graceful: the closed form is derived here with sympy from the control law written out in this file (Park &
  Kuipers' curvature as ``smooth_control_law.cpp`` and ``ego_polar_coords.hpp`` state it), independently of the
  module's own ``closed_form_gains``.
"""

import math

import numpy as np
import pytest
import sympy as sp

from pfm_stability.controllers.costmap import CorridorCostmap

from pfm_stability.controllers.base import RobotState

from pfm_stability.controllers.linearize import linearize

from pfm_stability.controllers.plan import straight_plan
from pfm_stability.controllers import graceful, rpp

FREE = CorridorCostmap(width=6.0, height=6.0)  # 3 m of plan ahead: the lookaheads drawn (<= 2 m) fit
PLAN = straight_plan(12.0, 0.05, x0=-1.0)


@pytest.mark.parametrize("seed", range(4))
def test_rpp_linearisation_reproduces_the_pure_pursuit_closed_form(seed):
    """k_θ = 2V/L, k_y = 2V/L² for random V and fixed L, and with the velocity-scaled lookahead L = clamp(V·t) (the
    measured speed's fixed point). Tolerance 1e-6 relative: the central differences' truncation (h/L)² <= 1e-7 at
    h = 1e-4 m, L >= 0.3 m."""
    r = np.random.default_rng(seed)
    V, L, t = r.uniform(0.3, 2.0), r.uniform(0.3, 2.0), r.uniform(0.5, 2.5)
    for params, lookahead in ((rpp.RPPParams(max_linear_vel=V, lookahead_dist=L), L),
                              (rpp.RPPParams(max_linear_vel=V, use_velocity_scaled_lookahead_dist=True, lookahead_time=t,
                                             min_lookahead_dist=0.3, max_lookahead_dist=2.0), min(max(V * t, 0.3), 2.0))):
        params = params.replace(use_regulated_linear_velocity_scaling=False)
        g = linearize("rpp", params, FREE)
        k_theta, k_y = rpp.closed_form_gains(V, lookahead)
        assert g.V == pytest.approx(V, rel=1e-12)
        assert g.k_theta == pytest.approx(k_theta, rel=1e-6) and g.k_y == pytest.approx(k_y, rel=1e-6)
        assert g.NV == pytest.approx(V / lookahead, rel=1e-6) and g.w0 == 0.0


def test_rpp_regulates_its_speed_by_curvature_and_by_the_costmap():
    """applyConstraints: the curvature heuristic v·(1 − |R − R_min|/R_min) below R_min; the cost heuristic from the
    robot's cell cost c, d = (f·r − ln c + ln 253)/f, v·gain·d/cost_scaling_dist below it; the floor min_speed."""
    p = rpp.RPPParams(max_linear_vel=0.8)
    assert rpp.regulated_speed(p, 1 / 0.6, 0.0, 0.22, 5.0, 5.0) == pytest.approx(0.8 * (1 - 0.3 / 0.9))
    cm = CorridorCostmap(half_width=0.5)
    c = float(cm.cost(0.0, 0.0))
    d = (3.0 * 0.22 - math.log(c) + math.log(253.0)) / 3.0
    assert d < 0.6
    cmd = rpp.command(RobotState(0.0, 0.0, 0.0, 0.8, 0.0), PLAN, cm, p)
    assert cmd.v == pytest.approx(0.8 * d / 0.6, rel=1e-12) and cmd.w == 0.0
    assert rpp.regulated_speed(p, 1 / 0.05, 0.0, 0.22, 5.0, 5.0) == 0.25  # R = 0.05 m: floored at the min speed


def test_rpp_rotates_in_place_when_the_carrot_is_far_off_its_heading():
    """shouldRotateToPath: bearing > 0.785 rad → v = 0, ω towards it at 1.8 rad/s clamped to ω_m ± 3.2·0.05."""
    cmd = rpp.command(RobotState(0.0, 0.0, 1.2, 0.3, 0.5), PLAN, FREE, rpp.RPPParams())
    assert cmd.v == 0.0 and cmd.w == pytest.approx(-(3.2 * 0.05 - 0.5))


def test_rpp_steers_with_the_exact_curvature_of_its_carrot():
    """Robot at e_y = 0.1 m, heading 0.05 rad, on a pose: the carrot at arc 0.6 from the closest pose (x = 0.6, y = 0),
    in the robot's frame (x, y); ω = v·2y/(x² + y²) exactly (1e-12)."""
    ey, et, L = 0.1, 0.05, 0.6
    cmd = rpp.command(RobotState(0.0, ey, et, 0.5, 0.0), PLAN, FREE, rpp.RPPParams(use_regulated_linear_velocity_scaling=False))
    x = math.cos(et) * L + math.sin(et) * (-ey)
    y = -math.sin(et) * L + math.cos(et) * (-ey)
    assert cmd.w == pytest.approx(0.5 * 2 * y / (x * x + y * y), rel=1e-12)


def test_rpp_refuses_what_it_does_not_model():
    with pytest.raises(ValueError, match="use_dynamic_window"):
        rpp.RPPParams(use_dynamic_window=True)
    with pytest.raises(ValueError, match="min_lookahead_dist"):
        rpp.RPPParams(min_lookahead_dist=1.0, max_lookahead_dist=0.5)


def _sympy_graceful_gains():
    """−∂κ/∂e_θ·L and −∂κ/∂e_y·L² at 0 from the control law written out symbolically (module docstring)."""
    ey, et = sp.symbols("e_y e_theta", real=True)
    L, kp, kd = sp.symbols("L k_phi k_delta", positive=True)
    dx = sp.cos(et) * L - sp.sin(et) * ey  # the target (L, 0) seen from the robot at (0, e_y), yaw e_θ
    dy = -sp.sin(et) * L - sp.cos(et) * ey
    sight = sp.atan2(-dy, dx)
    r = sp.sqrt(dx ** 2 + dy ** 2)
    phi, delta = -et + sight, sight  # target yaw −e_θ in the robot's frame; the robot's own yaw 0
    kappa = -1 / r * (kd * (delta - sp.atan(-kp * phi)) + (1 + kp / (1 + (kp * phi) ** 2)) * sp.sin(delta))
    at0 = {ey: 0, et: 0}
    return (sp.simplify(-sp.diff(kappa, et).subs(at0) * L), sp.simplify(-sp.diff(kappa, ey).subs(at0) * L ** 2)), (kp, kd)


def test_graceful_closed_form_is_the_control_laws_derivative():
    """sympy: −L·∂κ/∂e_θ = 1 + k_δ + k_φ and −L²·∂κ/∂e_y = (1 + k_δ)(1 + k_φ) exactly (simplify(a − b) == 0), and the
    module's closed_form_gains says the same at random gains (1e-12)."""
    (a, b), (kp, kd) = _sympy_graceful_gains()
    assert sp.simplify(a - (1 + kd + kp)) == 0 and sp.simplify(b - (1 + kd) * (1 + kp)) == 0
    r = np.random.default_rng(5)
    for _ in range(3):
        p = graceful.GracefulParams(k_phi=r.uniform(0.5, 4), k_delta=r.uniform(0.5, 4), max_lookahead=r.uniform(0.5, 2))
        V, L = graceful.cruise_speed(p), p.max_lookahead
        k_theta, k_y = graceful.closed_form_gains(p)
        assert k_theta == pytest.approx(V * float(a.subs({kp: p.k_phi, kd: p.k_delta})) / L, rel=1e-12)
        assert k_y == pytest.approx(V * float(b.subs({kp: p.k_phi, kd: p.k_delta})) / L ** 2, rel=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_graceful_linearisation_matches_the_closed_form(seed):
    """The numeric linearisation of the real algorithm (single-precision polar coordinates) against the closed form:
    5e-6 relative (float32 rounds φ and δ to 6e-8 of the 1e-4 perturbation, ~1e-7 of the difference, times the
    curvature's few terms; truncation (h/L)² <= 4e-8)."""
    r = np.random.default_rng(seed)
    p = graceful.GracefulParams(k_phi=r.uniform(0.5, 4), k_delta=r.uniform(0.5, 4), max_lookahead=r.uniform(0.5, 2),
                                v_linear_max=r.uniform(0.3, 1.5), v_angular_max=50.0)
    g = linearize("graceful", p, FREE)
    k_theta, k_y = graceful.closed_form_gains(p)
    assert g.V == pytest.approx(graceful.cruise_speed(p), rel=1e-6)
    assert g.k_theta == pytest.approx(k_theta, rel=5e-6) and g.k_y == pytest.approx(k_y, rel=5e-6)


def test_graceful_cruises_at_the_slowdown_speed_and_rotates_first_when_far_off():
    """v = v_max·min(1, r/slowdown_radius): with the defaults (1 m, 1.5 m) one third of a metre per second; a target
    bearing beyond initial_rotation_tolerance turns in place (rotation_scaling_factor·angle·v_angular_max, at least
    v_angular_min_in_place) and keeps the flag; inside it the flag clears."""
    p = graceful.GracefulParams()
    assert graceful.cruise_speed(p) == pytest.approx(0.5 / 1.5)
    cmd = graceful.command(RobotState(0.0, 0.0, 1.0), PLAN, FREE, p)
    bearing = -1.0 + math.atan2(0.0, 1.0)  # about −1 rad (the target at (1, 0), the robot turned +1)
    assert cmd.v == 0.0 and cmd.memory is True and cmd.w == pytest.approx(0.5 * bearing * 1.0, rel=0.02)
    assert graceful.command(RobotState(0.0, 0.0, 0.1), PLAN, FREE, p).memory is False
