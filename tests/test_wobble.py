"""The corridor's wobble by harmonic balance (analysis.wobble): the field's describing function, criticality, the branch."""

import math

import numpy as np
import pytest
import sympy as sp
from scipy import integrate

from pfm_stability.analysis.wobble import (
    DEFAULT_TOLERANCE_FRACTION,
    corridor_branch,
    corridor_steering,
    corridor_wobble,
    field_cubic,
    field_df,
)
from pfm_stability.laws.force_law import PowerLaw, corridor_gain, law_in_force
from pfm_stability.models import make_model
from pfm_stability.models.loop import Loop
from pfm_stability.parameters import CARMEL, Controller, Robot


def _sympy_beta_f(f, n, W, L):
    """β_f from sympy: δ(y) = atan(P(L + y) − P(L − y)), P = f(W/d)ⁿ, δ = −N·y + δ₃y³ + …; the DF of δ₃y³ is (3/4)δ₃A²,
    so N_f/N = 1 − (3/4)(δ₃/N)A²."""
    y, fs, ns, Ws, Ls = sp.symbols("y f n W L", positive=True)
    P = lambda d: fs * (Ws / d) ** ns
    delta = sp.atan(P(Ls + y) - P(Ls - y))
    values = {fs: f, ns: n, Ws: W, Ls: L, y: 0}
    N = -float(sp.diff(delta, y).subs(values))
    d3 = float(sp.diff(delta, y, 3).subs(values)) / 6
    return N, -0.75 * d3 / N


@pytest.mark.parametrize("seed", range(4))
def test_field_cubic_against_sympy(seed):
    """`field_cubic` (Richardson on the quadrature) equals the sympy series' coefficient on random power laws, to 1e-6
    relative (the Richardson remainder is O(A⁴) at A = min(L, 1/N)/200); N_f(A) = N(1 + β_f A²) (N: KB eq 25) at A = 1e-5·L to 1e-9."""
    rng = np.random.default_rng(seed)
    f, n, W = rng.uniform(0.2, 3.0), rng.uniform(0.5, 4.0), rng.uniform(0.3, 1.0)
    L = W / 2 + rng.uniform(0.1, 1.0)
    law = PowerLaw(f, n, W)
    N, beta_f = _sympy_beta_f(f, n, W, L)
    assert corridor_gain(law, L) == pytest.approx(N, rel=1e-12)
    assert field_cubic(law, L) == pytest.approx(beta_f, rel=1e-6, abs=1e-9 * N**2)
    A = 1e-5 * L
    assert field_df(law, L, A) == pytest.approx(N * (1 + beta_f * A**2), rel=1e-9)


def test_field_describing_function_against_adaptive_quadrature():
    """N_f(A) = −(1/(πA))∫δ(A sin θ) sin θ dθ by scipy's adaptive quad, up to 0.95 of the corridor (a steep integrand near the
    wall), at CARMEL's law and at the grid's averaged law; to 1e-8 relative (the grid's law ends at the window's reach,
    1.65 m for CARMEL: a kink in F once L + A passes it, where the trapezoid on 256 nodes errs by ~3e-10)."""
    from pfm_stability.sim.scenario import scenario_law

    for law, L in ((law_in_force(CARMEL.robot, CARMEL.controller), 0.9), (scenario_law("grid", CARMEL.robot, CARMEL.controller), 1.0)):
        delta = corridor_steering(law, L)
        for A in (0.01, 0.3 * L, 0.8 * L, 0.95 * L):
            b1 = integrate.quad(lambda t: float(delta(A * math.sin(t))) * math.sin(t), 0, 2 * math.pi, epsabs=0, epsrel=1e-13, limit=200)[0]
            assert field_df(law, L, A) == pytest.approx(-b1 / (math.pi * A), rel=1e-8)


@pytest.fixture(scope="module")
def carmel_branch():
    r, c = CARMEL.robot, CARMEL.controller
    return corridor_branch(r, c, law_in_force(r, c), 0.9)


def test_carmel_against_independent_simulator(carmel_branch):
    """CARMEL at 0.8 m/s in the 0.9 m corridor (command hold, one sample of compute delay, 120°/s): an independent simulator
    measured a cycle of about 0.21 m at 2.27 rad/s; the sampled loop's harmonic balance gives it within 15 % and 5 %
    (the accuracy the describing function is held to); V = 1.06·V* as stated."""
    (cycle,) = [c for c in carmel_branch.cycles_at(0.8) if c.stable]
    assert cycle.amplitude == pytest.approx(0.21, rel=0.15)
    assert cycle.omega == pytest.approx(2.27, rel=0.05)
    assert 0.8 / carmel_branch.V_critical == pytest.approx(1.06, abs=0.005)
    assert carmel_branch.criticality == "supercritical"


def test_branch_leaves_v_star_with_the_normal_form_slope(carmel_branch):
    """V(A) = V*(1 − βA²) + O(A⁴) with β = β_f − ω*²/(8V*²): β_f from sympy, V* and ω* from the sampled model's boundary
    (`Sampled.boundary`, NV*/N). Checked at the branch's smallest amplitudes, where the A⁴ term is below 1e-4 of βA²."""
    r, c = CARMEL.robot, CARMEL.controller
    boundary = make_model("sampled", hold=c.hold, compute_delay=c.compute_delay).boundary(Loop(r.tau, c.T, r.k))
    N, beta_f = _sympy_beta_f(c.f, c.n, r.W, 0.9)
    V_star = boundary.NV_critical / N
    beta = beta_f - boundary.omega_critical**2 / (8 * V_star**2)
    A = carmel_branch.amplitudes[:5]
    assert carmel_branch.V_critical == pytest.approx(V_star, rel=1e-12)
    assert carmel_branch.beta == pytest.approx(beta, rel=1e-6)
    assert np.allclose((carmel_branch.speeds[:5] / V_star - 1) / A**2, -beta, rtol=1e-3)
    assert carmel_branch.dA2_dV > 0


def test_below_v_star_no_wobble_and_tolerance_speed():
    """Below V* a supercritical robot settles (amplitude 0); V_tolerance for the default tolerance (a tenth of L − W/2)
    is the speed whose branch amplitude equals it: between V* and CARMEL's 0.8 m/s, and the branch read there gives back
    the tolerance to 1e-3 (linear interpolation between branch points)."""
    r, c = CARMEL.robot, CARMEL.controller
    law = law_in_force(r, c)
    slow = corridor_wobble(r.replace(V=0.7), c, law, 0.9)
    assert slow.amplitude == 0.0 and not slow.reaches_wall
    assert slow.tolerance == pytest.approx(DEFAULT_TOLERANCE_FRACTION * (0.9 - r.W / 2))
    assert slow.V_critical < slow.V_tolerance < 0.8
    branch = corridor_branch(r, c, law, 0.9)
    (cycle,) = [x for x in branch.cycles_at(slow.V_tolerance) if x.stable]
    assert cycle.amplitude == pytest.approx(slow.tolerance, rel=1e-3)


def test_past_the_wall_and_exact_delay():
    """Far past V* no cycle fits in the corridor: amplitude None, reaches_wall, a reason. The exact-delay loop (KB eq 18,
    no compute delay) has its own V* = NV*/N from `ExactDelay.boundary`."""
    r, c = CARMEL.robot, CARMEL.controller
    law = law_in_force(r, c)
    fast = corridor_wobble(r.replace(V=1.3), c, law, 0.9)
    assert fast.amplitude is None and fast.reaches_wall and "wall" in fast.reason
    exact = corridor_wobble(r, c, law, 0.9, model="exact_delay")
    expected = make_model("exact_delay").boundary(Loop(r.tau, c.T, r.k)).NV_critical / corridor_gain(law, 0.9)
    assert exact.V_critical == pytest.approx(expected, rel=1e-12)


SUBCRITICAL = dict(robot=Robot(V=1.0, tau=0.2, k=2.0, W=0.6, max_steering_rate=math.radians(180)),
                   controller=Controller(f=0.1, n=3.0, T=0.05, hold="command", compute_delay=0), L=0.6)


def test_subcritical_case():
    """A weak, steep law (n = 3, f = 0.1) in a narrow corridor stiffens faster than its direction saturates: β > 0
    (sympy's β_f outweighs ω*²/(8V*²)), a cycle exists below V* (the fold is slower than V*) and it is unstable; the report
    prints no amplitude between the fold and V*, with the reason."""
    s = SUBCRITICAL
    law = law_in_force(s["robot"], s["controller"])
    branch = corridor_branch(s["robot"], s["controller"], law, s["L"])
    N, beta_f = _sympy_beta_f(0.1, 3.0, 0.6, 0.6)
    assert beta_f > branch.omega_critical**2 / (8 * branch.V_critical**2)
    assert branch.criticality == "subcritical"
    assert branch.fold_speed < branch.V_critical
    V = 0.5 * (branch.fold_speed + branch.V_critical)
    cycles = branch.cycles_at(V)
    assert cycles and not cycles[0].stable
    answer = corridor_wobble(s["robot"].replace(V=V), s["controller"], law, s["L"])
    assert answer.amplitude is None and "subcritical" in answer.reason


def test_refusals():
    """A corridor the robot does not fit, or an unknown model, is one ValueError line naming the input."""
    r, c = CARMEL.robot, CARMEL.controller
    with pytest.raises(ValueError, match="L must exceed W/2"):
        corridor_branch(r, c, law_in_force(r, c), 0.3)
    with pytest.raises(ValueError, match="model"):
        corridor_branch(r, c, law_in_force(r, c), 0.9, model="pade")
    with pytest.raises(ValueError, match="tolerance"):
        corridor_wobble(r, c, law_in_force(r, c), 0.9, tolerance=-1.0)
