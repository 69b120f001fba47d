"""Target tracking (Ge & Cui 2002 eq 33–36) and the gradient-step planner (docs/models.md, "Robot loop families").

Oracles: Ge & Cui's published gains (ζ, ω_n), scipy's ODE solver for the
tracking error, and iterating the planner's nonlinear map x_{k+1} = x_k + h sin δ_k
with KB's wall and corridor laws for the planner's regimes.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pfm_stability.laws.force_law import PowerLaw, corridor_gain, wall_gain
from pfm_stability.models.planner import gradient_step
from pfm_stability.models.tracking import tracking_dynamics


@pytest.mark.parametrize("alpha_v, zeta, regime", [(0.0, 0.0, "undamped"), (0.02, 0.2, "underdamped"), (0.1, 1.0, "critically damped"), (0.2, 2.0, "overdamped")])
def test_published_tracking_gains(alpha_v, zeta, regime):
    """Ge & Cui 2002 Fig 8: α_p = 0.005, m = 1 → ω_n = 0.1 and ζ as listed (relative 1e-12: closed forms)."""
    d = tracking_dynamics(0.005, alpha_v, 1.0)
    assert d.natural_frequency == pytest.approx(0.1, rel=1e-12)
    assert d.damping_ratio == pytest.approx(zeta, rel=1e-12, abs=1e-15)
    assert d.regime == regime


def test_conference_gains_and_mass_scaling():
    """The conference form's α_p = 0.0008, α_v = 0.04 gives ζ = 1, ω_n = 0.04; gains and mass enter as α/m only."""
    d = tracking_dynamics(0.0008, 0.04)
    assert d.natural_frequency == pytest.approx(0.04, rel=1e-12) and d.regime == "critically damped"
    e = tracking_dynamics(0.0016, 0.08, 2.0)
    assert (e.damping_ratio, e.natural_frequency) == pytest.approx((d.damping_ratio, d.natural_frequency), rel=1e-12)


@pytest.mark.parametrize("seed", range(8))
def test_closed_form_error_against_ode(seed):
    """e(t) in closed form against scipy's DOP853 on ë + 2α′_v ė + 2α′_p e = 0 at random gains (ζ from 0 to
    ~30, one case within 1e-7 of ζ = 1 where the closed form must not cancel); DOP853 at rtol 1e-11 is good to
    ~1e-9 of the initial size, hence 1e-8 absolute on e0, ė0 of order 1."""
    rng = np.random.default_rng(seed)
    mass = float(10 ** rng.uniform(-1, 1))
    alpha_p = float(10 ** rng.uniform(-3, 1))
    wn = math.sqrt(2 * alpha_p / mass)
    zeta = [0.0, 0.3, 1.0 + 1e-8, 2.5, 30.0, float(rng.uniform(0, 3)), 0.999, float(rng.uniform(1, 5))][seed]
    d = tracking_dynamics(alpha_p, zeta * wn * mass, mass)
    e0, de0 = rng.normal(size=2)
    t = np.linspace(0, 8 / wn, 50)
    sol = solve_ivp(lambda _, y: [y[1], -2 * d.damping_ratio * wn * y[1] - wn * wn * y[0]], (0, t[-1]), [e0, de0], t_eval=t, rtol=1e-11, atol=1e-13, method="DOP853")
    assert np.max(np.abs(d.error(t, e0, de0) - sol.y[0])) < 1e-8


def test_tracking_bad_input():
    """Bad gains or times raise ValueError naming the parameter."""
    for call, name in [(lambda: tracking_dynamics(0.0, 0.1), "alpha_p"), (lambda: tracking_dynamics(0.005, -1.0), "alpha_v"), (lambda: tracking_dynamics(0.005, 0.1, 0.0), "mass"), (lambda: tracking_dynamics(0.005, 0.1).error([-1.0], 1.0, 0.0), "t")]:
        with pytest.raises(ValueError, match=f"^{name} "):
            call()


# -------------------------------------------------------------------------- planner
def test_planner_regimes_and_boundaries():
    """hN < 1 monotone, = 1 deadbeat, (1, 2) zig-zag, = 2 neutral, > 2 divergent, N < 0 divergent; h* = 2/N.
    The boundaries hold at h = 1/N and 2/N computed in floating point (round-off tolerance 1e-12)."""
    N = 7.3
    cases = [(0.5 / N, "monotone"), (1 / N, "deadbeat"), (1.5 / N, "zig-zag"), (2 / N, "neutral"), (2.5 / N, "divergent")]
    for h, regime in cases:
        step = gradient_step(h, N)
        assert step.regime == regime and step.critical_step == pytest.approx(2 / N, rel=1e-15)
        assert step.factor == pytest.approx(1 - h * N, abs=1e-15)
    assert gradient_step(0.1, -2.0).regime == "divergent" and gradient_step(0.1, -2.0).critical_step == 0.0
    for call, name in [(lambda: gradient_step(0.0, 1.0), "step"), (lambda: gradient_step(0.1, 0.0), "N"), (lambda: gradient_step(0.1, math.nan), "N")]:
        with pytest.raises(ValueError, match=f"^{name} "):
            call()


def _iterate(x0, h, lateral, forward, equilibrium, steps=60):
    """x_{k+1} = x_k + h sin δ_k with δ_k = atan2(F_x, F_y): the nonlinear planner, stopped once the
    deviation from the equilibrium has grown 1000-fold (still in the linear region)."""
    xs = [x0]
    for _ in range(steps):
        xs.append(xs[-1] + h * math.sin(math.atan2(lateral(xs[-1]), forward)))
        if abs(xs[-1] - equilibrium) > 1e3 * abs(x0 - equilibrium):
            break
    return np.array(xs)


def _observed_regime(deviation):
    """The regime seen in a run, up to the step where it has shrunk 1000-fold (below that, round-off of the
    equilibrium distance would flip signs at random)."""
    small = np.flatnonzero(np.abs(deviation) < 1e-3 * abs(deviation[0]))
    run = deviation[: small[0] + 1] if small.size else deviation
    signs = np.sign(run[:-1] * run[1:])
    if not small.size:
        return "divergent" if abs(deviation[-1]) > abs(deviation[0]) else "neutral"
    return "zig-zag" if np.all(signs < 0) else "monotone" if np.all(signs > 0) else "mixed"


@pytest.mark.parametrize("hN", [0.4, 0.9, 1.3, 1.8, 2.2, 3.0])
@pytest.mark.parametrize("seed", range(3))
def test_planner_regime_against_nonlinear_wall_and_corridor(hN, seed):
    """Random KB power laws: iterating the nonlinear map from 1e-6 of the wall (or corridor) equilibrium shows the
    predicted regime (60 steps: |1 − hN|^60 <= 0.8^60 ≈ 2e-6, so a converging run shrinks 1000-fold and a
    diverging one grows 1000-fold within 60 steps (1.2^60 ≈ 6e4), where it is stopped; the start is small enough that the nonlinearity does not change the regime)."""
    rng = np.random.default_rng(seed)
    law = PowerLaw(float(rng.uniform(0.5, 5)), float(rng.uniform(1, 3)), float(rng.uniform(0.3, 1)))
    alpha = float(rng.uniform(0.3, 1.3))
    d0, N = wall_gain(law, alpha)
    expected = gradient_step(hN / N, N).regime
    xs = _iterate(d0 * (1 + 1e-6), hN / N, lambda d: float(law.force(d)) - math.cos(alpha), math.sin(alpha), d0)
    assert _observed_regime(xs - d0) == expected
    L = float(rng.uniform(1.0, 3.0)) * law.W  # half-width
    Nc = corridor_gain(law, L)  # the target straight down the corridor: F_y = F_a = 1
    lateral = lambda x: float(law.force(L + x) - law.force(L - x))
    xs = _iterate(1e-6 * L, hN / Nc, lateral, 1.0, 0.0)
    assert _observed_regime(xs) == gradient_step(hN / Nc, Nc).regime
