"""The potentials of Ge & Cui 2000 and their bounds on ξ/η (`pfm_stability.laws.potentials`).

S.S. Ge and Y.J. Cui, IEEE T-RA 16(5), 2000 ("GC2000"; docs/traps.md). Three
kinds of checks:

* the paper's numbers (docs/traps.md, "Reproduced numbers"), each with the
  equation or figure it comes from and why its tolerance is what it is;
* independent routes: every force and second derivative against finite
  differences of the potential itself; k_n against a brute-force dense sup of
  eq (28); eq (29) as printed against its compact form; k_n as the threshold
  where stationary points on the goal–obstacle ray appear (the meaning of the
  bound), on random (r, ρ0, n) far from the paper's values;
* k′_n >= k_n (eq 31) on random (r, ρ0, n), and bad input → ValueError naming the argument.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.laws import potentials as P

RNG_SEED = 20000501


# ------------------------------------------------------------------ the paper's numbers
@pytest.mark.parametrize(
    "n, rho_m, k, kc",
    [(0.5, 0.605551, 1.86357, 13.6402), (1.0, 0.732051, 0.288953, 1.39952), (3.0, 1.215250, 0.0335084, 0.181618), (4.0, None, 0.0303375, 0.195793)],
)
def test_bounds_at_r_half_rho0_two(n, rho_m, k, kc):
    """GC2000 eq (27), (28), (34)/(37) at r = 0.5, ρ0 = 2: the values quoted with 6 significant digits,
    so a relative tolerance of 6e-6 (half a unit of the last digit of the smallest, 0.0303375)."""
    if rho_m is not None:
        assert P.rho_m(0.5, 2.0, n) == pytest.approx(rho_m, rel=2e-6)
    assert P.k_exact(0.5, 2.0, n) == pytest.approx(k, rel=6e-6)
    assert P.k_conservative(0.5, 2.0, n) == pytest.approx(kc, rel=6e-6)
    assert P.k_conservative(0.5, 2.0, n) >= P.k_exact(0.5, 2.0, n)


def test_k2_closed_form_eq29():
    """GC2000 eq (29), r = 0.5, ρ0 = 2: k₂ = 0.0549637342 (10 digits quoted: abs 1e-10), attained at
    ρ* = 3ρ0/(1 + s) = 1.30278 (6 digits: 5e-6); η* = 1/k₂ = 18.1938. Also Sec VI.B: k₂(0.2, 0.8) = 0.343523."""
    k2 = P.k2_closed_form(0.5, 2.0)
    assert k2 == pytest.approx(0.0549637342, abs=1e-10)
    s = math.sqrt(1 + 3 * 2.0 / 0.5)
    rho_star = 3 * 2.0 / (1 + s)
    assert rho_star == pytest.approx(1.30278, abs=5e-6)
    assert P.bound_integrand(rho_star, 0.5, 2.0, 2.0) == pytest.approx(k2, rel=1e-13)
    assert 1 / k2 == pytest.approx(18.1938, abs=5e-5)
    assert P.k_exact(0.5, 2.0, 2.0) == k2
    assert P.k2_closed_form(0.2, 0.8) == pytest.approx(0.343523, abs=5e-7)


def test_eq29_as_printed_equals_the_compact_form():
    """Eq (29) as the paper prints it, [2/(9ρ0²) + 2r/(27ρ0³)]√(1 + 3ρ0/r) − 2/(3ρ0²) + 2r/(27ρ0³), on random (r, ρ0): rounding only (1e-9)."""
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(50):
        rho0 = 10 ** rng.uniform(-2, 2)
        r = rho0 * rng.uniform(0.01, 0.99)
        printed = (2 / (9 * rho0**2) + 2 * r / (27 * rho0**3)) * math.sqrt(1 + 3 * rho0 / r) - 2 / (3 * rho0**2) + 2 * r / (27 * rho0**3)
        assert P.k2_closed_form(r, rho0) == pytest.approx(printed, rel=1e-9)


def test_fig2_one_dimensional_trap():
    """GC2000 Fig 2 (eq 6–7): ξ = η = 1, point obstacle at 0.5, ρ0 = 2, Khatib's law: trapped at x = −0.5
    exactly (force −0.5 + (1 − 0.5)/1 = 0; bisection to 1e-15: tolerance 1e-12); U_min = 0.25, U(goal) = 1.125."""
    [(rg, kind)] = P.ray_stationary_points(0.5, 1.0, 1.0, 2.0, 0.0)
    assert kind == "minimum" and rg == pytest.approx(0.5, abs=1e-12)
    u = lambda x: P.attraction_potential(abs(x), 1.0) + P.khatib_potential(0.5 - x, 1.0, 2.0)
    assert u(-0.5) == pytest.approx(0.25, abs=1e-15) and u(0.0) == pytest.approx(1.125, abs=1e-15)


def test_fig6_one_dimensional_goal_aware():
    """GC2000 Fig 6: ξ = η = 1, ρ0 = 2, obstacle at 0.5. n = 0.5: a minimum at −0.356648 and a maximum at
    −0.122035 (6 digits: 1e-6; the paper's −0.355 is within 0.5 %); n = 1, 2, 3: no stationary point."""
    points = P.ray_stationary_points(0.5, 1.0, 1.0, 2.0, 0.5)
    assert [k for _, k in points] == ["maximum", "minimum"]
    assert -points[1][0] == pytest.approx(-0.356648, abs=1e-6) and -points[0][0] == pytest.approx(-0.122035, abs=1e-6)
    assert abs(-points[1][0] + 0.355) / 0.355 < 0.005
    for n in (1.0, 2.0, 3.0):
        assert P.ray_stationary_points(0.5, 1.0, 1.0, 2.0, n) == []


def test_sharpness_of_k2():
    """GC2000 Sec IV ("accurate lower bound"): ξ/η = 0.999 k₂ gives a maximum–minimum pair on the ray at
    ρ_g ≈ 0.790 / 0.816 (3 digits quoted: 5e-4); 1.001 k₂ gives none."""
    k2 = P.k2_closed_form(0.5, 2.0)
    below = P.ray_stationary_points(0.5, 0.999 * k2, 1.0, 2.0, 2.0)
    assert [k for _, k in below] == ["maximum", "minimum"]
    assert below[0][0] == pytest.approx(0.790, abs=5e-4) and below[1][0] == pytest.approx(0.816, abs=5e-4)
    assert P.ray_stationary_points(0.5, 1.001 * k2, 1.0, 2.0, 2.0) == []


def test_sec6b_vertical_model():
    """GC2000 Sec VI.B: goal 8.7, obstacle edge at 8.5 (r = 0.2), ξ = 1, η = 0.1, ρ0 = 0.8. Khatib's law traps
    at ρ_g = 0.3 (0.3 = 0.1·(1/0.5 − 1/0.8)/0.5²), y = 9.0000 (bisection: 1e-12); the goal-aware law (n = 2) has none."""
    [(rg, kind)] = P.ray_stationary_points(0.2, 1.0, 0.1, 0.8, 0.0)
    assert kind == "minimum" and 8.7 + rg == pytest.approx(9.0, abs=1e-12)
    assert P.ray_stationary_points(0.2, 1.0, 0.1, 0.8, 2.0) == []


def test_goal_hessian_sec6():
    """Sec 1 of docs/traps.md: at the goal (m = n = 2) ∇²U = [ξ + η(1/r − 1/ρ0)²]·I = 2.40625·I for ξ = 1, η = 0.1,
    r = 0.2, ρ0 = 0.8: the radial second derivative of the ray potential at ρ_g → 0 by a one-sided difference,
    whose error is h times the third derivative (3η d(c²)/dρ at r ≈ −56): h = 1e-6 → 6e-5, tolerance 1e-4 relative."""
    h = 1e-6
    u = lambda rg: P.attraction_potential(rg, 1.0) + P.gnron_potential(rg + 0.2, rg, 0.1, 0.8, 2.0)
    second = (u(2 * h) - 2 * u(h) + u(0.0)) / h**2
    assert second == pytest.approx(2.40625, rel=1e-4)
    assert P.repulsion_derivatives(0.2, 0.0, 0.1, 0.8, 2.0)[5] == pytest.approx(0.1 * (1 / 0.2 - 1 / 0.8) ** 2, rel=1e-14)


# ------------------------------------------------------------------ independent routes
def _random_laws(count):
    rng = np.random.default_rng(RNG_SEED + 1)
    for _ in range(count):
        yield dict(eta=10 ** rng.uniform(-2, 2), rho0=10 ** rng.uniform(-1, 1), n=float(rng.choice([0.0, 0.3, 1.0, 1.7, 2.0, 3.5])),
                   delta=float(rng.choice([0.0, 10 ** rng.uniform(-3, -1)])))


def test_forces_and_second_derivatives_against_finite_differences():
    """F_rep1 = −∂U/∂ρ (eq 10), F_rep2 = ∂U/∂ρ_g (eq 11) and the second derivatives, against central differences
    of the potential (eq 8, 40) itself at random points inside the influence region: step 1e-6·ρ, relative error
    of a central difference ~1e-9 + rounding 1e-16/1e-12 → tolerance 1e-6."""
    rng = np.random.default_rng(RNG_SEED + 2)
    for law in _random_laws(40):
        rho = law["rho0"] * rng.uniform(0.05, 0.95, 20)
        rg = 10 ** rng.uniform(-1, 1, 20)
        d = P.repulsion_derivatives(rho, rg, **law)
        f1, f2 = P.gnron_forces(rho, rg, **law)
        u = lambda a, b: P.gnron_potential(a, b, **law)
        h1, h2 = 1e-6 * rho, 1e-6 * rg
        du_r = (u(rho + h1, rg) - u(rho - h1, rg)) / (2 * h1)
        du_g = (u(rho, rg + h2) - u(rho, rg - h2)) / (2 * h2)
        scale = np.abs(du_r) + np.abs(du_g) + 1e-300
        assert np.all(np.abs(-f1 - du_r) <= 1e-6 * scale) and np.all(np.abs(f2 - du_g) <= 1e-6 * scale + 1e-300)
        for i, (a, b) in enumerate([(1, 0), (0, 1)]):  # second derivatives from differences of the first
            first = lambda x, y: P.repulsion_derivatives(x, y, **law)[1 + i]
            fd_r = (first(rho + h1, rg) - first(rho - h1, rg)) / (2 * h1)
            fd_g = (first(rho, rg + h2) - first(rho, rg - h2)) / (2 * h2)
            exact_r, exact_g = (d[3], d[4]) if i == 0 else (d[4], d[5])
            s2 = np.abs(exact_r) + np.abs(exact_g) + np.abs(fd_r) + 1e-300
            assert np.all(np.abs(fd_r - exact_r) <= 1e-5 * s2) and np.all(np.abs(fd_g - exact_g) <= 1e-5 * s2)


def test_attraction_force_and_khatib_force():
    """|F_att| = (m/2)ξρ_g^(m−1) (eq 1–2; m = 1: ξ/2) and Khatib's η(1/ρ − 1/ρ0)/ρ² (eq 4), 0 beyond ρ0."""
    rg = np.array([0.1, 1.0, 7.0])
    assert np.allclose(P.attraction_force(rg, 3.0, 2), 3.0 * rg) and np.allclose(P.attraction_force(rg, 3.0, 1), 1.5)
    assert np.allclose(P.attraction_potential(rg, 3.0, 1), 1.5 * rg)
    rho = np.array([0.5, 1.0, 2.0, 3.0])
    assert np.allclose(P.khatib_force(rho, 2.0, 2.0), [2.0 * (2 - 0.5) / 0.25, 2.0 * 0.5, 0.0, 0.0])
    assert np.allclose(P.khatib_potential(rho, 2.0, 2.0), [0.5 * 2.0 * 1.5**2, 0.25, 0.0, 0.0])


def test_delta_keeps_the_potential_continuous_and_bounded():
    """Eq (40) with ρ0 + δ: U(ρ0) = 0 and the force is finite at the surface ρ = 0."""
    u0 = P.gnron_potential(np.array([2.0 - 1e-12, 2.0, 2.0 + 1e-12]), 1.0, 1.0, 2.0, 2.0, delta=0.1)
    assert np.all(np.abs(u0) < 1e-20)
    f1, f2 = P.gnron_forces(0.0, 1.0, 1.0, 2.0, 2.0, delta=0.1)
    assert math.isfinite(float(f1)) and float(f1) == pytest.approx((1 / 0.1 - 1 / 2.1) / 0.01)


def test_k_exact_against_a_brute_force_sup():
    """k_n (eq 28) against the maximum of the integrand on 10⁶ points of (ρ_m, ρ0) for random (r, ρ0, n, m):
    the grid misses the peak by O(h²) relative (h ~ 1e-6 of the span) → 1e-7 (and never exceeds k_n by more)."""
    rng = np.random.default_rng(RNG_SEED + 3)
    for _ in range(25):
        rho0 = 10 ** rng.uniform(-1.5, 1.5)
        r = rho0 * rng.uniform(0.02, 0.95)
        n, m = rng.uniform(0.2, 6.0), float(rng.choice([1.0, 2.0]))
        lo = P.rho_m(r, rho0, n)
        t = np.concatenate([np.linspace(0, 1, 1_000_001), np.geomspace(1e-12, 1e-3, 2000)])
        rho = lo + (rho0 - lo) * t
        rho = rho[(rho > lo) & (rho < rho0)]
        brute = float(np.max(P.bound_integrand(rho, r, rho0, n, m)))
        k = P.k_exact(r, rho0, n, m)
        assert brute <= k * (1 + 1e-12) and brute == pytest.approx(k, rel=1e-7), (r, rho0, n, m)


def test_k_exact_is_where_stationary_points_appear_on_the_ray():
    """The meaning of k_n: on random (r, ρ0, n, m, δ) far from the paper's, ξ/η = 1.001 k_n leaves the
    goal–obstacle ray free of stationary points, ξ/η = 0.99 k_n does not (a pair appears). 0.99, not 0.999:
    the pair's separation grows like √(1 − ξ/ηk_n), and 0.99 keeps it well above the scan's spacing."""
    rng = np.random.default_rng(RNG_SEED + 4)
    for _ in range(30):
        rho0 = 10 ** rng.uniform(-1, 1)
        r = rho0 * rng.uniform(0.05, 0.9)
        n, m = rng.uniform(0.3, 5.0), float(rng.choice([1.0, 2.0]))
        delta = float(rng.choice([0.0, 0.05 * r]))
        k = P.k_exact(r, rho0, n, m, delta)
        eta = 10 ** rng.uniform(-1, 1)
        assert P.ray_stationary_points(r, 1.001 * k * eta, eta, rho0, n, m, delta) == [], (r, rho0, n, m, delta)
        assert len(P.ray_stationary_points(r, 0.99 * k * eta, eta, rho0, n, m, delta)) >= 2, (r, rho0, n, m, delta)


def test_conservative_bound_is_never_below_the_exact_one():
    """Eq (31): k′_n >= k_n, on random (r, ρ0, n) covering n < 2, n = 2, n > 2 and both cases of (33), m = 1 and 2."""
    rng = np.random.default_rng(RNG_SEED + 5)
    cases = 0
    for _ in range(300):
        rho0 = 10 ** rng.uniform(-2, 2)
        r = rho0 * rng.uniform(0.01, 0.99)
        n = float(rng.choice([2.0, rng.uniform(0.05, 2.0), rng.uniform(2.0, 8.0)]))
        m = float(rng.choice([1.0, 2.0]))
        k, kc = P.k_exact(r, rho0, n, m), P.k_conservative(r, rho0, n, m)
        assert kc >= k * (1 - 1e-12), (r, rho0, n, m, k, kc)
        cases += n < 2 and r / rho0 <= 0.5 - n / 4
    assert cases > 20  # the first case of eq (33) was exercised


def test_rho_m_is_the_root_of_phi():
    """Eq (26)–(27): φ(ρ_m) = 0 and ρ_m > r (n > 0); ρ_m = √(rρ0) for n = 2; ρ_m = r for n = 0."""
    rng = np.random.default_rng(RNG_SEED + 6)
    for _ in range(100):
        rho0 = 10 ** rng.uniform(-2, 2)
        r, n = rho0 * rng.uniform(0.01, 0.99), rng.uniform(0.01, 10.0)
        rm = P.rho_m(r, rho0, n)
        phi = (1 - n / 2) / rm - r / rm**2 + n / (2 * rho0)
        assert rm > r and abs(phi) <= 1e-12 * (abs(1 - n / 2) / rm + r / rm**2 + n / (2 * rho0))
    assert P.rho_m(0.5, 2.0, 2.0) == pytest.approx(1.0, rel=1e-15) and P.rho_m(0.5, 2.0, 0.0) == 0.5


def test_khatib_law_has_no_finite_bound_for_a_spring():
    """n = 0, m = 2: the integrand grows like 1/(ρ − r): k = inf (a trap exists for every ξ/η). With m = 1 the sup
    is its limit 2(1/r − 1/ρ0)/r² at ρ → r: the goal stays a minimum iff the constant pull ξ/2 beats the repulsion there."""
    assert P.k_exact(0.5, 2.0, 0.0) == math.inf and P.k_conservative(0.5, 2.0, 0.0) == math.inf
    assert P.k_exact(0.5, 2.0, 0.0, m=1) == pytest.approx(2 * (1 / 0.5 - 1 / 2.0) / 0.25)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: P.gnron_potential(-1.0, 1.0, 1.0, 2.0, 2.0), "rho"),
        (lambda: P.gnron_potential(np.array([1.0, np.nan]), 1.0, 1.0, 2.0, 2.0), "rho"),
        (lambda: P.gnron_potential(1.0, "x", 1.0, 2.0, 2.0), "rho_g"),
        (lambda: P.gnron_potential(1.0, 1.0, 0.0, 2.0, 2.0), "eta"),
        (lambda: P.gnron_potential(1.0, 1.0, 1.0, math.inf, 2.0), "rho0"),
        (lambda: P.gnron_potential(1.0, 1.0, 1.0, 2.0, -1.0), "n"),
        (lambda: P.gnron_potential(1.0, 1.0, 1.0, 2.0, 2.0, delta=-0.1), "delta"),
        (lambda: P.attraction_potential(1.0, -1.0), "xi"),
        (lambda: P.attraction_potential(1.0, 1.0, m=0.5), "m"),
        (lambda: P.k_exact(2.0, 2.0, 2.0), "r"),
        (lambda: P.k_exact(0.5, 2.0, 11.0), "n"),
        (lambda: P.k_conservative(0.5, None, 2.0), "rho0"),
        (lambda: P.rho_m(0.5, 2.0, True), "n"),
        (lambda: P.ray_stationary_points(-0.5, 1.0, 1.0, 2.0), "r"),
    ],
)
def test_bad_input_names_the_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        call()
