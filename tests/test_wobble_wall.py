"""The wall's biased (dual-input) describing function (analysis.wobble.wall_df, wall_branch) against quadrature and the simulator."""

import math

import pytest
from scipy import integrate, optimize

from pfm_stability.analysis.wobble import wall_branch, wall_df, wall_steering
from pfm_stability.laws.force_law import law_in_force, wall_gain
from pfm_stability.parameters import CARMEL
from pfm_stability.validation.wobble import WobbleCase, simulate_wobbles

LAW = law_in_force(CARMEL.robot, CARMEL.controller)


@pytest.mark.parametrize("alpha_deg", [20.0, 45.0])
def test_bias_and_describing_function_against_adaptive_quadrature(alpha_deg):
    """B(A) solves mean δ(B + A sin θ) = 0 and N_f = −b₁/A: both recomputed with scipy's quad and brentq, to 1e-9;
    B > 0 (the law is steeper towards the wall: the cycle's centre moves out) and N_f → N (KB eq 11) as A → 0 (1e-6)."""
    alpha = math.radians(alpha_deg)
    delta = wall_steering(LAW, alpha)
    d0, N = wall_gain(LAW, alpha)
    for A in (0.05 * d0, 0.4 * d0):
        mean = lambda b: integrate.quad(lambda t: float(delta(b + A * math.sin(t))), 0, 2 * math.pi, epsrel=1e-13)[0]
        B = optimize.brentq(mean, -d0 + A + 1e-9, d0, xtol=1e-15)
        b1 = integrate.quad(lambda t: float(delta(B + A * math.sin(t))) * math.sin(t), 0, 2 * math.pi, epsrel=1e-13)[0] / math.pi
        (Nf,), (Bc,) = wall_df(LAW, alpha, [A])
        assert Bc == pytest.approx(B, rel=1e-9, abs=1e-12) and Bc > 0
        assert Nf == pytest.approx(-b1 / A, rel=1e-9)
    assert wall_df(LAW, alpha, [1e-4 * d0])[0][0] == pytest.approx(N, rel=1e-6)


def test_wall_cycles_against_simulation():
    """CARMEL beside a wall at 30 and 45 deg, 1.2·V*: the biased describing function's amplitude within 15 % and frequency within
    5 % of the simulator's settled cycle (continuous wall, power law, command hold, one sample of compute delay; 120 s runs
    started 2 cm out; measured 2.5 % and 5.1 % low, 0.3 % and 0.8 % high)."""
    cases, cycles = [], []
    for alpha_deg in (30.0, 45.0):
        alpha = math.radians(alpha_deg)
        branch = wall_branch(CARMEL.robot, CARMEL.controller, LAW, alpha)
        V = 1.2 * branch.V_critical
        (cycle,) = [c for c in branch.cycles_at(V) if c.stable]
        cycles.append(cycle)
        cases.append(WobbleCase(CARMEL.robot.replace(V=V), CARMEL.controller, 0.0, 0.02, 120.0, alpha=alpha))
    for cycle, m in zip(cycles, simulate_wobbles(cases)):
        assert not m.collided and m.steady
        assert cycle.amplitude == pytest.approx(m.amplitude, rel=0.15)
        assert cycle.omega == pytest.approx(m.omega, rel=0.05)
