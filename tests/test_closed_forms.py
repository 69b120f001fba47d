"""Every closed form used numerically agrees with the symbolic derivation (docs/theory.md).

`pfm_stability.analysis.derivation` derives KB's eq (5)–(25) with sympy; here each
numeric shortcut (the models' NV* and ω*, `force_law`, `criteria`) is checked
against it:

* exactly, where the function is plain arithmetic and accepts sympy symbols
  (`criteria.kb_critical_L`);
* otherwise against the derivation lambdified to Python floats, at
  ``POINTS`` = 50 seeded random points of the physical domain, with
  ``RTOL`` = 1e-10. Why 1e-10: the two sides are the same quantity evaluated
  in double precision by different routes — closed forms with powers up to
  n + 1 ≤ 5 (a few ulps each, ~1e-15), polynomial roots for the models'
  boundaries (~1e-13 on these well-separated crossings) and bisection to
  rtol 1e-13…1e-14 for the non-power-law solvers. 1e-10 leaves three orders
  of magnitude of margin over that round-off, while any algebraic slip (a
  wrong exponent, τ for τ + T, a missing factor 2) is an O(1) error.

Then the facts KB's paper must reproduce with the CARMEL preset (KB §4–5.4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import sympy as sp

from pfm_stability.analysis import criteria
from pfm_stability.analysis import derivation as D
from pfm_stability.analysis.derivation import F_a, L, NV_star, T, V, W, alpha, d, f, k, n, tau
from pfm_stability.laws.force_law import ForceLaw, PowerLaw, corridor_gain, wall_equilibrium, wall_gain
from pfm_stability.models import Continuous, KBFirstOrder, Loop
from pfm_stability.parameters import CARMEL

pytestmark = pytest.mark.xdist_group("derivation")  # the derivation's sympy steps once per suite (tests/conftest.py)

POINTS = 50
RTOL = 1e-10
SEED = 19910409  # KB was presented at ICRA, April 1991


def points(**ranges):
    """POINTS seeded uniform samples, one dict per point, name → float."""
    rng = np.random.default_rng(SEED)
    columns = {name: rng.uniform(low, high, POINTS) for name, (low, high) in ranges.items()}
    return [{name: float(col[i]) for name, col in columns.items()} for i in range(POINTS)]


def numeric(expr, symbols):
    """The derived expression as a float function of `symbols` (math module, no numpy)."""
    return sp.lambdify(symbols, expr, "math")


# physical ranges: τ, T in s; k in 1/s; V in m/s; W, L in m; α in rad; NV* in 1/s
LOOP = {"tau": (0.05, 2.0), "T": (0.0, 0.5), "k": (0.2, 20.0)}
LAW = {"f": (0.1, 5.0), "n": (0.5, 4.0), "W": (0.2, 2.0)}
WALL = {"alpha": (math.radians(5), math.radians(85)), "V": (0.1, 3.0), "NV": (0.5, 10.0)}


# ------------------------------------------------------------------ loop models
@pytest.mark.parametrize(
    "model, kind",
    [(Continuous(), "continuous"), (KBFirstOrder(), "kb_first_order")],
    ids=["continuous", "kb_first_order"],
)
def test_model_boundary_matches_routh(model, kind):
    """`continuous`: NV* = 1/τ, ω* = √(k/τ) (Routh on KB 17); `kb_first_order`:
    NV* = 1/(τ + T), ω* = √(k/(τ + T)) (Routh on KB 19, eq 20). K* = k·NV*."""
    crit = D.routh_criterion(kind)
    NV_c = numeric(crit.NV_critical, (tau, T, k))
    omega_c = numeric(crit.omega_critical, (tau, T, k))
    for p in points(**LOOP):
        b = model.boundary(Loop(p["tau"], p["T"], p["k"]))
        expected = NV_c(p["tau"], p["T"], p["k"])
        assert b.NV_critical == pytest.approx(expected, rel=RTOL)
        assert b.omega_critical == pytest.approx(omega_c(p["tau"], p["T"], p["k"]), rel=RTOL)
        assert b.K_critical == pytest.approx(p["k"] * expected, rel=RTOL)


def test_kb_first_order_critical_delay():
    """`KBFirstOrder.critical_delay`: T* = 1/NV − τ, the T solving (20)'s boundary."""
    crit = D.routh_criterion("kb_first_order")
    T_star = sp.solve(crit.condition.lhs, T)[0]
    NV_symbol = sp.Symbol("NV", positive=True)
    T_c = numeric(T_star.subs(D.N, NV_symbol / V), (NV_symbol, tau))
    for p in points(tau=(0.05, 2.0), k=(0.2, 20.0), NV=(0.1, 5.0)):
        expected = max(T_c(p["NV"], p["tau"]), 0.0)
        got = KBFirstOrder().critical_delay(p["NV"], Loop(p["tau"], 0.1, p["k"]))
        assert got == pytest.approx(expected, rel=RTOL, abs=1e-15)


# ------------------------------------------------------------------ force law
def test_power_law_force_and_slope():
    """`PowerLaw.force` = F_r/F_a of KB (8, 13); `slope` = its d-derivative; `local_exponent`
    = −dF′/F = n and `equivalent_f` (KB §4 f_av) = f for the power law itself."""
    law_expr = D.force_law("power")(d) / F_a
    assert sp.simplify(-d * sp.diff(law_expr, d) / law_expr - n) == 0
    force = numeric(law_expr, (d, f, n, W))
    slope = numeric(sp.diff(law_expr, d), (d, f, n, W))
    for p in points(d=(0.1, 5.0), **LAW):
        law = PowerLaw(p["f"], p["n"], p["W"])
        assert float(law.force(p["d"])) == pytest.approx(force(p["d"], p["f"], p["n"], p["W"]), rel=RTOL)
        assert float(law.slope(p["d"])) == pytest.approx(slope(p["d"], p["f"], p["n"], p["W"]), rel=RTOL)
        assert float(law.local_exponent(p["d"])) == pytest.approx(p["n"], rel=RTOL)
        assert float(law.equivalent_f(p["d"], p["n"], p["W"])) == pytest.approx(p["f"], rel=RTOL)


def test_power_law_wall_equilibrium_and_gain():
    """`wall_equilibrium` = d0 of KB (23); `wall_gain` = (d0, N) with N of (11) at δ = 0, d = d0."""
    d0 = numeric(D.wall_equilibrium("power"), (alpha, f, n, W))
    N_eq = numeric(D.wall_equilibrium_gain("power"), (alpha, f, n, W))
    N_d = numeric(D.wall_gain("power"), (d, alpha, f, n, W))
    for p in points(**WALL, **LAW):
        law = PowerLaw(p["f"], p["n"], p["W"])
        args = (p["alpha"], p["f"], p["n"], p["W"])
        assert wall_equilibrium(law, p["alpha"]) == pytest.approx(d0(*args), rel=RTOL)
        got_d0, got_N = wall_gain(law, p["alpha"])
        assert got_d0 == pytest.approx(d0(*args), rel=RTOL)
        assert got_N == pytest.approx(N_eq(*args), rel=RTOL)
        assert got_N == pytest.approx(N_d(d0(*args), *args), rel=RTOL)


def test_power_law_corridor_gain():
    """`corridor_gain` = 2nfWⁿ/L^(n+1) (KB §5.4, from the linearized lateral force)."""
    N_c = numeric(D.corridor_gain("power"), (L, f, n, W))
    for p in points(L=(0.5, 5.0), **LAW):
        law = PowerLaw(p["f"], p["n"], p["W"])
        assert corridor_gain(law, p["L"]) == pytest.approx(N_c(p["L"], p["f"], p["n"], p["W"]), rel=RTOL)


# ------------------------------------------------------------------ criteria (power law)
def test_kb_critical_L_is_eq25_exactly():
    """`kb_critical_L` is plain arithmetic: with symbols it is L* of KB (25) exactly."""
    derived = D.corridor_condition("power").rhs ** (1 / (n + 1))
    assert sp.simplify(criteria.kb_critical_L(n, W, V, tau + T, f) - derived) == 0


def test_kb_critical_f_wall_is_eq24():
    """`kb_critical_f_wall` = the boundary of KB (24)."""
    f_c = numeric(D.wall_f_condition().rhs, (alpha, V, tau, T, n, W))
    for p in points(alpha=WALL["alpha"], V=WALL["V"], **LOOP, **LAW):
        got = criteria.kb_critical_f_wall(p["alpha"], p["V"], p["tau"] + p["T"], p["n"], p["W"])
        assert got == pytest.approx(f_c(p["alpha"], p["V"], p["tau"], p["T"], p["n"], p["W"]), rel=RTOL)


def test_critical_f_wall_power_law():
    """`critical_f_wall` (power law) = (24) with 1/NV* for τ + T."""
    f_c = numeric(D.wall_f_condition(NV_star).rhs, (alpha, V, NV_star, n, W))
    for p in points(**WALL, **LAW):
        law = PowerLaw(p["f"], p["n"], p["W"])
        got = criteria.critical_f_wall(law, p["alpha"], p["V"], p["NV"])
        assert got == pytest.approx(f_c(p["alpha"], p["V"], p["NV"], p["n"], p["W"]), rel=RTOL)


def test_critical_alpha_power_law():
    """`critical_alpha`: N(α*)V = NV* with N(α) of (11) at the equilibrium (23)."""
    N_eq = numeric(D.wall_equilibrium_gain("power"), (alpha, f, n, W))
    for p in points(**WALL, **LAW):
        law = PowerLaw(p["f"], p["n"], p["W"])
        a = criteria.critical_alpha(law, p["V"], p["NV"])
        assert 0 < a < math.pi / 2
        assert N_eq(a, p["f"], p["n"], p["W"]) * p["V"] == pytest.approx(p["NV"], rel=RTOL)


def test_critical_L_and_f_corridor_power_law():
    """`critical_L` = (25) with 1/NV* for τ + T; `critical_f_corridor` = (25) solved for f."""
    boundary = D.corridor_condition("power", NV_star)
    L_c = numeric(boundary.rhs ** (1 / (n + 1)), (V, NV_star, f, n, W))
    f_c = numeric(sp.solve(sp.Eq(boundary.lhs, boundary.rhs), f)[0], (L, V, NV_star, n, W))
    for p in points(L=(0.5, 5.0), V=WALL["V"], NV=WALL["NV"], **LAW):
        law = PowerLaw(p["f"], p["n"], p["W"])
        assert criteria.critical_L(law, p["V"], p["NV"]) == pytest.approx(L_c(p["V"], p["NV"], p["f"], p["n"], p["W"]), rel=RTOL)
        got = criteria.critical_f_corridor(law, p["L"], p["V"], p["NV"])
        assert got == pytest.approx(f_c(p["L"], p["V"], p["NV"], p["n"], p["W"]), rel=RTOL)


# ------------------------------------------------------------------ a non-power law
@dataclass(frozen=True)
class ShiftedPowerLaw(ForceLaw):
    """F_r/F_a = c (W/(d + a))^m: a law the numeric (non-closed-form) paths must handle."""

    c: float
    m: float
    W: float
    a: float
    name = "shifted power law (test)"

    @property
    def scale(self) -> float:
        return self.c

    def force(self, d):
        return self.c * (self.W / (np.asarray(d, dtype=float) + self.a)) ** self.m

    def slope(self, d):
        return -self.m * self.force(d) / (np.asarray(d, dtype=float) + self.a)

    def with_scale(self, scale: float) -> "ShiftedPowerLaw":
        return ShiftedPowerLaw(scale, self.m, self.W, self.a)


c_, m_, a_ = sp.symbols("c m a", positive=True)
SHIFTED = sp.Lambda(d, F_a * c_ * (W / (d + a_)) ** m_)
# ranges keep the equilibrium and the critical values at d, L > 0 (d0 + a >= W > a)
SHIFTED_LAW = {"c": (1.0, 3.0), "m": (1.0, 3.0), "W": (0.2, 2.0), "a_frac": (0.0, 0.005)}
SHIFTED_WALL = {"alpha": (math.radians(20), math.radians(70)), "V": (0.3, 2.0), "NV": (1.0, 5.0)}


def _shifted(p):
    return ShiftedPowerLaw(p["c"], p["m"], p["W"], p["a_frac"] * p["W"]), (p["c"], p["m"], p["W"], p["a_frac"] * p["W"])


def test_general_law_wall_and_corridor_gains():
    """Numeric equilibrium (bisection) and gains for a non-power law = the general derivation
    (docs/theory.md, "Any force law": F_r(d0) = F_a cos α, N = −F_r′(d0)/(F_a sin α), corridor N = −2F_r′(L)/F_a)."""
    d0 = numeric(D.wall_equilibrium(SHIFTED), (alpha, c_, m_, W, a_))
    N_eq = numeric(D.wall_equilibrium_gain(SHIFTED), (alpha, c_, m_, W, a_))
    N_c = numeric(D.corridor_gain(SHIFTED), (L, c_, m_, W, a_))
    for p in points(L=(0.5, 5.0), **SHIFTED_WALL, **SHIFTED_LAW):
        law, args = _shifted(p)
        got_d0, got_N = wall_gain(law, p["alpha"])
        assert got_d0 == pytest.approx(d0(p["alpha"], *args), rel=RTOL)
        assert got_N == pytest.approx(N_eq(p["alpha"], *args), rel=RTOL)
        assert corridor_gain(law, p["L"]) == pytest.approx(N_c(p["L"], *args), rel=RTOL)


def test_general_law_critical_alpha_L_f_corridor():
    """`critical_alpha`, `critical_L`, `critical_f_corridor` for a non-power law solve the
    derivation's boundary N·V = NV* (residuals, and L* against sympy's solution)."""
    N_eq = numeric(D.wall_equilibrium_gain(SHIFTED), (alpha, c_, m_, W, a_))
    N_corridor = D.corridor_gain(SHIFTED)
    L_star = sp.solve(N_corridor * V - NV_star, L)
    assert len(L_star) == 1
    L_c = numeric(L_star[0], (V, NV_star, c_, m_, W, a_))
    N_c = numeric(N_corridor, (L, c_, m_, W, a_))
    for p in points(L=(0.5, 5.0), **SHIFTED_WALL, **SHIFTED_LAW):
        law, args = _shifted(p)
        a_star = criteria.critical_alpha(law, p["V"], p["NV"])
        assert N_eq(a_star, *args) * p["V"] == pytest.approx(p["NV"], rel=RTOL)
        assert criteria.critical_L(law, p["V"], p["NV"]) == pytest.approx(L_c(p["V"], p["NV"], *args), rel=RTOL)
        f_corr = criteria.critical_f_corridor(law, p["L"], p["V"], p["NV"])
        assert N_c(p["L"], f_corr, *args[1:]) * p["V"] == pytest.approx(p["NV"], rel=RTOL)


def test_general_law_critical_f_wall():
    """`critical_f_wall` for a non-power law: the strength c* with N(α; c*)·V = NV* (derivation's
    N at the equilibrium of (22)); the operating strength may lie on either side of c*."""
    N_eq = numeric(D.wall_equilibrium_gain(SHIFTED), (alpha, c_, m_, W, a_))
    for p in points(**SHIFTED_WALL, **SHIFTED_LAW):
        law, args = _shifted(p)
        f_star = criteria.critical_f_wall(law, p["alpha"], p["V"], p["NV"])
        assert N_eq(p["alpha"], f_star, *args[1:]) * p["V"] == pytest.approx(p["NV"], rel=RTOL)


# ------------------------------------------------------------------ KB must-hold facts (CARMEL)
def _carmel_values():
    r, c = CARMEL.robot, CARMEL.controller
    return {V: r.V, tau: r.tau, T: c.T, k: r.k, W: r.W, f: c.f, n: c.n}


def test_carmel_alpha_20_deg_is_unstable():
    """KB Fig 5: with CARMEL's parameters a wall seen at α = 20° violates (24) (oscillation)."""
    values = {**_carmel_values(), alpha: sp.rad(20)}
    condition = D.wall_f_condition().subs(values)
    assert condition == sp.false
    f_star = criteria.kb_critical_f_wall(math.radians(20), CARMEL.robot.V, CARMEL.robot.tau + CARMEL.controller.T, CARMEL.controller.n, CARMEL.robot.W)
    assert f_star > CARMEL.controller.f  # ≈ 3.8 > 0.8
    law = PowerLaw(CARMEL.controller.f, CARMEL.controller.n, CARMEL.robot.W)
    alpha_star = criteria.critical_alpha(law, CARMEL.robot.V, 1.0 / (CARMEL.robot.tau + CARMEL.controller.T))
    assert alpha_star > math.radians(20)


def test_carmel_critical_corridor_half_width():
    """KB (25): L* = (2nWⁿV(T + τ)f)^(1/(n+1)); for CARMEL (n = 2) ≈ 0.843 m."""
    values = _carmel_values()
    derived = float((D.corridor_condition("power").rhs ** (1 / (n + 1))).subs(values))
    r, c = CARMEL.robot, CARMEL.controller
    by_hand = (2 * c.n * r.W**c.n * r.V * (c.T + r.tau) * c.f) ** (1 / (c.n + 1))
    assert derived == pytest.approx(by_hand, rel=1e-15)
    assert criteria.kb_critical_L(c.n, r.W, r.V, r.tau + c.T, c.f) == pytest.approx(derived, rel=1e-15)
    assert derived == pytest.approx(0.8427, abs=5e-4)
