"""The symbolic derivation reproduces Koren & Borenstein 1991 (KB), eq (5)–(25).

Every derived result is compared *exactly* with the paper's printed formula —
corrected where docs/theory.md says it is misprinted — by ``simplify(a − b) == 0``
(or `simplify_physical`, the same on 0 < α < π/2, where powers of sin α,
cos α must combine: sympy cannot be told α < π/2). The only floating-point
comparisons are the Padé coefficients against the numeric implementations,
which are float by construction (rtol 1e-12: a handful of ulps of factorial
ratios up to (2m)! with m ≤ 4).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

from pfm_stability.analysis import derivation as D
from pfm_stability.analysis.derivation import (
    F_a,
    F_r,
    M,
    N,
    NV_star,
    T,
    V,
    W,
    L,
    alpha,
    d,
    d_t,
    alpha_t,
    delta,
    delta_t,
    f,
    k,
    n,
    s,
    t,
    tau,
    theta,
)

pytestmark = pytest.mark.xdist_group("derivation")  # the derivation's sympy steps once per suite (tests/conftest.py)


def same(a, b) -> bool:
    """Exact symbolic identity a ≡ b."""
    return sp.simplify(a - b) == 0


def same_physical(a, b) -> bool:
    """Exact identity on the physical domain 0 < α < π/2."""
    return D.simplify_physical(a - b) == 0


def dot(q):
    return sp.Derivative(q(t), t)


# ------------------------------------------------------------------ (5)–(7)
def test_steering_equation_eq7():
    """KB (7): τθ̈ + θ̇ + kθ = kδ follows from (5), (6) and ω = θ̇."""
    eq = D.steering_equation()
    expected = tau * theta(t).diff(t, 2) + theta(t).diff(t) + k * theta(t) - k * delta_t(t)
    assert same(eq.lhs - eq.rhs, expected)


# ------------------------------------------------------------------ (8)–(13)
def test_power_law_eq8_eq13():
    """KB (8) with (13): F_r = F_cr Wⁿ/dⁿ = f F_a Wⁿ/dⁿ."""
    assert same(D.force_law("power")(d), f * F_a * W**n / d**n)


def test_force_balance_eq9():
    """KB (9): tan δ = (F_r − F_a cos α)/(F_a sin α), from the resultant's direction."""
    eq = D.force_balance("power")
    assert eq.lhs == sp.tan(delta)
    assert same(eq.rhs, (f * F_a * W**n / d**n - F_a * sp.cos(alpha)) / (F_a * sp.sin(alpha)))


def test_N_eq11():
    """KB (11): N = nWⁿf cos²δ/(d^(n+1) sin α), by implicit differentiation of (9)."""
    assert same(D.linearization_gains("power").N, n * W**n * f * sp.cos(delta) ** 2 / (d ** (n + 1) * sp.sin(alpha)))


def test_M_eq12():
    """KB (12): M = (1 − tan δ/tan α)cos²δ, the same for every force law."""
    expected = (1 - sp.tan(delta) / sp.tan(alpha)) * sp.cos(delta) ** 2
    assert same(D.linearization_gains("power").M, expected)
    assert same(D.linearization_gains("general").M, expected)


def test_small_delta_after_eq13():
    """KB after (13): for small δ, N is independent of δ and M = 1 (first order in δ)."""
    lin = D.linearization_gains("power")
    assert lin.M.subs(delta, 0) == 1
    assert sp.diff(lin.N, delta).subs(delta, 0) == 0


def test_rate_eq10():
    """KB (10), OCR-corrected: δ̇ = −N ḋ + M α̇ (the first term is ḋ, not α̇)."""
    lin = D.linearization_gains("power")
    assert same(lin.rate.rhs, -lin.N * dot(d_t) + lin.M * dot(alpha_t))
    assert lin.rate.lhs == dot(delta_t)


def test_general_law_gains():
    """docs/theory.md, "Any force law": N = −F_r′(d)cos²δ/(F_a sin α); the power law substituted gives (11)."""
    general = D.linearization_gains("general").N
    assert same(general, -sp.Derivative(F_r(d), d) * sp.cos(delta) ** 2 / (F_a * sp.sin(alpha)))
    powered = general.subs(F_r, D.force_law("power")).doit()
    assert same(powered, D.linearization_gains("power").N)


def test_kinematics_eq14():
    """KB (14): ḋ = V sin θ."""
    assert D.kinematics() == sp.Eq(dot(d_t), V * sp.sin(theta(t)))


# ------------------------------------------------------------------ (15)–(16)
def test_ode_eq15_corrected():
    """KB (15), corrected (docs/theory.md, misprints): τθ⃛ + θ̈ + kθ̇ + kNV sin θ = kMα̇.

    KB print τθ̈ + θ̇ + kθ + … (second order); differentiating (7) gives the
    third-order form, whose characteristic equation is (17).
    """
    eq = D.robot_environment_ode()
    expected = tau * theta(t).diff(t, 3) + theta(t).diff(t, 2) + k * theta(t).diff(t) + k * N * V * sp.sin(theta(t))
    assert same(eq.lhs, expected)
    assert same(eq.rhs, k * M * dot(alpha_t))
    misprinted = tau * theta(t).diff(t, 2) + theta(t).diff(t) + k * theta(t) + k * N * V * sp.sin(theta(t))
    assert not same(eq.lhs, misprinted)


def test_linear_ode_eq16_corrected():
    """KB (16), corrected: τθ⃛ + θ̈ + kθ̇ + kNVθ = kα̇ (sin θ ≈ θ, M = 1)."""
    eq = D.linearized_ode()
    expected = tau * theta(t).diff(t, 3) + theta(t).diff(t, 2) + k * theta(t).diff(t) + k * N * V * theta(t)
    assert same(eq.lhs, expected)
    assert same(eq.rhs, k * dot(alpha_t))


# ------------------------------------------------------------------ (17)–(19)
def test_characteristic_eq17():
    """KB (17): τs³ + s² + ks + kNV (Laplace transform of (16), α̇ = 0)."""
    assert same(D.characteristic_polynomial("continuous"), tau * s**3 + s**2 + k * s + k * N * V)


def test_characteristic_eq18():
    """KB (18): τs³ + s² + ks + kNV e^(−sT)."""
    assert same(D.characteristic_polynomial("exact_delay"), tau * s**3 + s**2 + k * s + k * N * V * sp.exp(-s * T))


def test_characteristic_eq19():
    """KB (19): τs³ + s² + k(1 − NVT)s + kNV (e^(−sT) ≈ 1 − sT)."""
    assert same(D.characteristic_polynomial("kb_first_order"), tau * s**3 + s**2 + k * (1 - N * V * T) * s + k * N * V)


@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_pade_is_the_pade_approximant(m):
    """P_m/Q_m matches e^(−sT) to order (sT)^(2m) exactly, with deg P = deg Q = m."""
    P, Q = D.pade_approximant(m)
    assert sp.degree(P, s) == m and sp.degree(Q, s) == m
    z = sp.Symbol("z")
    error = sp.series((P / Q).subs(s * T, z).subs(s, z / T) - sp.exp(-z), z, 0, 2 * m + 1).removeO()
    assert sp.expand(error) == 0


def _normalized(poly, T_value=None):
    """Descending float coefficients in s, leading coefficient 1 (python-control's convention)."""
    if T_value is not None:
        poly = poly.subs(T, T_value)
    c = np.array([float(x) for x in sp.Poly(poly, s).all_coeffs()])
    return c / c[0]


@pytest.mark.parametrize("m", [1, 2, 3, 4])
@pytest.mark.parametrize("T_value", [0.065, 0.5, 2.0])
def test_pade_coefficients_match_numeric(m, T_value):
    """Derived Padé(m, m) = `pade_coefficients` = ``control.pade`` (rtol 1e-12, float round-off).

    Numerator and denominator are scaled by the same factor (den leading 1).
    """
    import control

    from pfm_stability.models.pade import pade_coefficients

    P, Q = D.pade_approximant(m)
    lead = float(sp.Poly(Q.subs(T, T_value), s).LC())
    num = np.array([float(x) for x in sp.Poly(P.subs(T, T_value), s).all_coeffs()]) / lead
    den = _normalized(Q, T_value)
    ours_num, ours_den = pade_coefficients(T_value, m)
    ctl_num, ctl_den = control.pade(T_value, m)
    for other_num, other_den in ((ours_num, ours_den), (ctl_num, ctl_den)):
        np.testing.assert_allclose(num, other_num, rtol=1e-12)
        np.testing.assert_allclose(den, other_den, rtol=1e-12)


@pytest.mark.parametrize("m", [1, 3])
def test_pade_characteristic_matches_model(m):
    """(18) with Padé(m, m): (τs³ + s² + ks)Q + kNV·P equals the `Pade` model's D + kNV·E (rtol 1e-12)."""
    from pfm_stability.models import Loop, Pade

    values = {tau: 0.3, T: 0.065, k: 2.0, N: 3.0, V: 0.8}
    loop = Loop(0.3, 0.065, 2.0)
    derived = _normalized(D.characteristic_polynomial("pade", m).subs(values))
    model = Pade(m).characteristic(3.0 * 0.8, loop)
    np.testing.assert_allclose(derived, model / model[0], rtol=1e-12)


# ------------------------------------------------------------------ (20)
def test_routh_eq20():
    """KB (20): Routh on (19) gives 1 − NV(τ + T) > 0, NV* = 1/(τ + T), ω* = √(k/(τ + T)).

    The s¹ entry of the first column is k(1 − NV(τ + T)): k cancels from the
    condition only in this first-order approximation (docs/models.md: exact only as k → 0).
    """
    crit = D.routh_criterion("kb_first_order")
    assert isinstance(crit.condition, sp.StrictGreaterThan)
    assert same(crit.condition.lhs, 1 - N * V * (tau + T)) and crit.condition.rhs == 0
    assert D.routh_condition() == crit.condition
    assert same(crit.NV_critical, 1 / (tau + T))
    assert same(crit.omega_critical, sp.sqrt(k / (tau + T)))
    first = crit.first_column
    assert [same(a, b) for a, b in zip(first, (tau, 1, k * (1 - N * V * (tau + T)), k * N * V))] == [True] * 4


def test_routh_continuous():
    """Routh on (17): τNV < 1, so NV* = 1/τ and ω* = √(k/τ) (the `continuous` model)."""
    crit = D.routh_criterion("continuous")
    assert same(crit.condition.lhs, 1 - N * V * tau)
    assert same(crit.NV_critical, 1 / tau)
    assert same(crit.omega_critical, sp.sqrt(k / tau))


def test_routh_boundary_is_imaginary_pair():
    """At NV* of (20), ±jω* are roots of (19) (independent check of the Routh reading)."""
    crit = D.routh_criterion("kb_first_order")
    poly = D.characteristic_polynomial("kb_first_order").subs(N, crit.NV_critical / V)
    assert same(poly.subs(s, sp.I * crit.omega_critical), 0)


# ------------------------------------------------------------------ wall (21)–(24)
def test_wall_eq21():
    """KB (21): d^(n+1) > nV(τ + T)Wⁿf/sin α (KB print ≥; equality is marginal)."""
    cond = D.wall_condition("power")
    assert isinstance(cond, sp.StrictGreaterThan)
    assert cond.lhs == d ** (n + 1)
    assert same(cond.rhs, n * V * (tau + T) * W**n * f / sp.sin(alpha))


def test_wall_eq22_eq23():
    """KB (22): F_r = F_a cos α at δ = 0; (23) solved: d0 = W (f/cos α)^(1/n)."""
    balance = D.wall_balance("power")
    assert same(balance.lhs, f * F_a * W**n / d**n) and same(balance.rhs, F_a * sp.cos(alpha))
    assert same_physical(D.wall_equilibrium("power"), W * (f / sp.cos(alpha)) ** (1 / n))
    general = D.wall_balance("general")
    assert general.lhs == F_r(d) and same(general.rhs, F_a * sp.cos(alpha))


def test_wall_eq24():
    """KB (24): f > cos α [nV(τ + T)/(W tan α)]ⁿ, from d0 of (23) in (21)."""
    cond = D.wall_f_condition()
    assert isinstance(cond, sp.StrictGreaterThan) and cond.lhs == f
    assert same_physical(cond.rhs, sp.cos(alpha) * (n * V * (tau + T) / (W * sp.tan(alpha))) ** n)


def test_wall_gain_at_equilibrium():
    """N(α) at the equilibrium (criteria docstring): (n/W) f^(−1/n) cos^((n+1)/n)α / sin α."""
    expected = n / W * f ** (-1 / n) * sp.cos(alpha) ** ((n + 1) / n) / sp.sin(alpha)
    assert same_physical(D.wall_equilibrium_gain("power"), expected)


def test_wall_general_law():
    """docs/theory.md, "Any force law": N = −F_r′(d0)/(F_a sin α); with the power law the general (20) is (21)."""
    assert same(D.wall_gain("general"), -sp.Derivative(F_r(d), d) / (F_a * sp.sin(alpha)))
    general = D.wall_condition("general").lhs.subs(F_r, D.force_law("power")).doit()
    # 1 − N V (τ+T) = 1 − rhs(21)/d^(n+1): the same condition, since d^(n+1) > 0
    assert same(general, 1 - D.wall_condition("power").rhs / d ** (n + 1))


def test_generic_NV_critical_forms():
    """criteria's generalized forms: (24) and (25) with 1/NV* in place of τ + T."""
    assert same_physical(D.wall_f_condition(NV_star).rhs, sp.cos(alpha) * (n * V / (W * NV_star * sp.tan(alpha))) ** n)
    assert same(D.corridor_condition("power", NV_star).rhs, 2 * n * W**n * V * f / NV_star)
    assert same(D.wall_condition("power", NV_star).rhs, n * V * W**n * f / (NV_star * sp.sin(alpha)))


# ------------------------------------------------------------------ corridor (25)
def test_corridor_gain():
    """KB §5.4: lateral force F_r(L + x) − F_r(L − x) linearized at x = 0 gives N = 2nfWⁿ/L^(n+1)."""
    assert same(D.corridor_gain("power"), 2 * n * f * W**n / L ** (n + 1))
    assert same(D.corridor_gain("general"), -2 * sp.Derivative(F_r(L), L) / F_a)


def test_corridor_eq25():
    """KB (25), W* read as Wⁿ: L^(n+1) > 2nWⁿV(T + τ)f."""
    cond = D.corridor_condition("power")
    assert isinstance(cond, sp.StrictGreaterThan) and cond.lhs == L ** (n + 1)
    assert same(cond.rhs, 2 * n * W**n * V * (T + tau) * f)


def test_corridor_general_law():
    """The general corridor condition with the power law substituted is (25)."""
    general = D.corridor_condition("general").lhs.subs(F_r, D.force_law("power")).doit()
    assert same(general, 1 - D.corridor_condition("power").rhs / L ** (n + 1))


def test_custom_lambda_law():
    """A law given as a Lambda: F_r = F_a c e^(−d/λ) gives d0 = λ ln(c/cos α), N(α) = 1/(λ tan α)."""
    c, lam = sp.symbols("c lambda", positive=True)
    law = sp.Lambda(d, F_a * c * sp.exp(-d / lam))
    assert same_physical(D.wall_equilibrium(law), lam * sp.log(c / sp.cos(alpha)))
    assert same_physical(D.wall_equilibrium_gain(law), 1 / (lam * sp.tan(alpha)))
    assert same(D.corridor_gain(law), 2 * c * sp.exp(-L / lam) / lam)


def test_general_equilibrium_has_no_closed_form():
    """For an undefined F_r, (22) defines d0 only implicitly."""
    with pytest.raises(ValueError, match="d0 solves"):
        D.wall_equilibrium("general")


# ------------------------------------------------------------------ API
def test_derivation_steps_cover_kb_in_order():
    """`derivation()` lists frozen Steps from KB (5) to (25), equation numbers non-decreasing."""
    for law in ("power", "general"):
        steps = D.derivation(law)
        assert all(isinstance(step, D.Step) for step in steps)
        numbers = [int(step.equation.split(",")[0].split("-")[0].split(" ")[0]) for step in steps]
        assert numbers[0] == 5 and numbers[-1] == 25
        assert numbers == sorted(numbers)
        assert all(step.explanation and step.title for step in steps)
    with pytest.raises(AttributeError):
        steps[0].title = "x"
    assert steps[0].to_dict()["equation"] == "5"


def test_bad_arguments():
    """Unknown laws, kinds and Padé orders are rejected with a ValueError."""
    with pytest.raises(ValueError, match="law"):
        D.force_law("khatib")
    with pytest.raises(ValueError, match="kind"):
        D.characteristic_polynomial("sampled")
    with pytest.raises(ValueError, match="order"):
        D.pade_approximant(0)


# ------------------------------------------------------------------ CLI
@pytest.mark.parametrize("fmt", ["text", "latex"])
@pytest.mark.parametrize("law", ["power", "general"])
def test_derive_cli(capsys, fmt, law):
    """``pfm-stability derive`` prints every step in both formats and exits 0."""
    from pfm_stability.cli import main

    assert main(["derive", "--format", fmt, "--law", law]) == 0
    out = capsys.readouterr().out
    steps = D.derivation(law)
    if fmt == "latex":
        assert out.count(r"\begin{equation*}") == len(steps)
        assert r"\tag{20}" in out and r"\tag{25}" in out
    else:
        assert "KB (20)" in out and "KB (25)" in out
        assert out.count("KB (") == len(steps)


def test_derive_cli_law_choices_match_library():
    """The CLI's --law choices (kept sympy-free) are the library's LAWS."""
    from pfm_stability.cli import derive

    assert derive.LAWS == D.LAWS


def test_derive_cli_rejects_bad_order(capsys):
    """A bad --pade-order is a one-line user error, exit status 2."""
    from pfm_stability.cli import main

    assert main(["derive", "--pade-order", "0"]) == 2
    assert "pade_order" in capsys.readouterr().err


def test_cli_import_does_not_import_sympy():
    """Building the CLI parser (all subcommands) does not import sympy (start-up time)."""
    code = "import sys; from pfm_stability.cli import build_parser; build_parser(); print('sympy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
