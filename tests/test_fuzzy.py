"""The DFAPF fuzzy controllers (`fuzzy`) and the fuzzy-scheduled lateral law (`fuzzy_law`).

Reference values are the reconstruction's (docs/velocity_and_fuzzy.md, choices R1–R7):
they are compared to the digits printed there, so each tolerance is half a unit of the
last printed digit. Gains are also checked by an independent route: central differences
of the lateral force itself (N = −∂F_x/∂x / F_y, c = −∂F_x/∂ψ / F_y).
"""

import math

import numpy as np
import pytest

from pfm_stability.laws.fuzzy import FuzzySystem, FuzzyVariable, load_dfapf, symmetrized_rows
from pfm_stability.laws.fuzzy_law import FuzzyScheduledLaw

TABLE1 = {  # the paper's Table 1 as printed: rows θ, columns d = ZD SD MD FD
    "NH": "NA NA NA NA", "NB": "SA NA NA NA", "NM": "SA NA NA SA", "NS": "MA SA SA SA",
    "Z": "LA LA MA SA", "PS": "NA MA SA SA", "PM": "SA SA NA NA", "PB": "SA NA NA NA",
}
TABLE2 = {  # Table 2: rows θ, columns ΔV = NBV … PBV
    "NH": "LA MA SA NA NA NA NA", "NB": "MA SA NA NA NA NA NA", "NM": "SA NA NA NA NA NA NA",
    "NS": "NA NA NA NA SA SA MA", "Z": "NA NA NA NA SA MA LA", "PS": "NA NA NA NA SA SA MA",
    "PM": "SA SA NA NA NA NA NA", "PB": "MA SA NA NA NA NA NA",
}


@pytest.fixture(scope="module")
def fis():
    return load_dfapf()


@pytest.fixture(scope="module")
def law(fis):
    return FuzzyScheduledLaw(0.5, 100.0, controllers=fis)


def _table(system):
    return {r: " ".join(system.output.sets[k] for k in row) for r, row in zip(system.first.sets, system.table)}


def test_data_file_parses_to_the_printed_tables(fis):
    """The shipped YAML holds exactly the paper's sets, uniform centres and both rule tables (exact comparison)."""
    assert _table(fis.eta) == TABLE1
    assert _table(fis.K_V) == TABLE2
    theta, d, dv, out = fis.eta.first, fis.eta.second, fis.K_V.second, fis.eta.output
    assert theta.periodic and theta.sets == ("NH", "NB", "NM", "NS", "Z", "PS", "PM", "PB")
    assert theta.spacing == 45.0 and d.sets == ("ZD", "SD", "MD", "FD") and out.centres == (1.0, 34.0, 67.0, 100.0)
    np.testing.assert_allclose(d.centres, [0, 2 / 3, 4 / 3, 2], rtol=0, atol=1e-15)
    np.testing.assert_allclose(dv.centres, np.linspace(-1, 1, 7), rtol=0, atol=1e-15)
    # R2: FWHM = 0.8 spacing, so membership 1/2 at 0.4 spacing from a centre
    np.testing.assert_allclose(d.memberships(0.4 * d.spacing)[0], 0.5, rtol=1e-12)
    # R3: the bearing wraps: +180° is NH's centre, and 170° is as close to NH as -170°
    assert theta.memberships(180.0)[0] == pytest.approx(1.0)
    np.testing.assert_allclose(theta.memberships(170.0)[0], theta.memberships(-170.0)[0], rtol=1e-12)


@pytest.mark.parametrize("theta, row", [
    (0.0, [87.848, 87.631, 85.430, 86.990, 70.991, 62.410, 34.755]),
    (90.0, [34.755, 34.772, 35.005, 34.829, 30.009, 12.072, 11.228]),
    (-90.0, [34.755, 34.669, 33.193, 18.782, 14.926, 17.141, 34.058]),
    (180.0, [11.228, 11.410, 13.110, 11.926, 12.700, 10.504, 9.914]),
])
def test_eta_table(fis, theta, row):
    """η(θ, d) of controller 1 at d = 0 … 2 m, to the three printed decimals (tolerance 5e-4)."""
    got = fis.eta.evaluate(theta, np.array([0.0, 0.1, 0.25, 0.5, 1.0, 1.5, 2.0]))
    np.testing.assert_allclose(got, row, rtol=0, atol=5e-4)


def test_kv_values_and_output_range(fis):
    """K_V at the three printed points (2 decimals, tolerance 5e-3) and the centroid's compressed range [9.914, 87.848]."""
    assert fis.K_V_of(1.0, 0.0) == pytest.approx(87.85, abs=5e-3)
    assert fis.K_V_of(-1.0, math.pi) == pytest.approx(87.85, abs=5e-3)
    assert fis.K_V_of(0.5, math.pi / 2) == pytest.approx(14.93, abs=5e-3)
    lo, hi = fis.eta.output_range()
    assert lo == pytest.approx(9.914, abs=5e-4) and hi == pytest.approx(87.848, abs=5e-4)
    # the centroid of NA alone (LA alone) on [1, 100] bounds any output from below (above):
    # other sets firing can only pull the centroid inwards
    y = np.linspace(1, 100, 1001)
    mu = fis.eta.output.memberships(y)
    na, la = ((mu[:, k] * y).sum() / mu[:, k].sum() for k in (0, 3))
    assert na <= lo < na + 1e-3 and hi < la


def test_gradients_match_finite_differences(fis):
    """The forward-mode derivatives of the discretised centroid against central differences (h = 1e-7).

    The output has kinks wherever an active min/max switches; between them it is smooth,
    so at seeded random points the two agree to FD truncation/rounding (~1e-6 relative to the
    1..100 scale): tolerance 1e-4 absolute per unit of input.
    """
    rng = np.random.default_rng(7)
    th = rng.uniform(-179.0, 179.0, 25)
    d = rng.uniform(0.05, 1.95, 25)
    _, g_th, g_d = fis.eta.evaluate_with_gradient(th, d)
    h = 1e-7
    fd_th = (fis.eta.evaluate(th + h, d) - fis.eta.evaluate(th - h, d)) / (2 * h)
    fd_d = (fis.eta.evaluate(th, d + h) - fis.eta.evaluate(th, d - h)) / (2 * h)
    np.testing.assert_allclose(g_th, fd_th, rtol=0, atol=1e-4)
    np.testing.assert_allclose(g_d, fd_d, rtol=0, atol=1e-4)
    assert np.abs(g_d).max() > 1.0  # the check is not vacuous


def test_symmetrize(fis):
    """symmetrize=True copies the N-rows (obstacle on the right) onto the P-rows; "positive" the reverse; exact equalities."""
    sym = load_dfapf(symmetrize=True)
    pos = load_dfapf(symmetrize="positive")
    d = np.linspace(0, 2, 9)
    for th in (30.0, 90.0, 135.0, 160.0):
        np.testing.assert_allclose(sym.eta.evaluate(th, d), sym.eta.evaluate(-th, d), rtol=1e-12)
        np.testing.assert_allclose(pos.K_V.evaluate(th, d - 1), pos.K_V.evaluate(-th, d - 1), rtol=1e-12)
    np.testing.assert_allclose(sym.eta.evaluate(90.0, d), fis.eta.evaluate(-90.0, d), rtol=1e-12)
    np.testing.assert_allclose(pos.eta.evaluate(-90.0, d), fis.eta.evaluate(90.0, d), rtol=1e-12)
    rows = symmetrized_rows({k: k for k in TABLE1}, "negative")
    assert rows["PM"] == "NM" and rows["Z"] == "Z" and rows["NH"] == "NH"


def test_bad_inputs(tmp_path):
    """Malformed data and options raise a ValueError naming what is wrong."""
    with pytest.raises(ValueError, match="symmetrize"):
        load_dfapf(symmetrize="left")
    bad = tmp_path / "bad.yaml"
    bad.write_text("variables: {}\n")
    with pytest.raises(ValueError, match="controllers"):
        load_dfapf(path=bad)
    with pytest.raises(ValueError, match="uniformly spaced"):
        FuzzyVariable("d", 0.0, 2.0, ("A", "B", "C"), (0.0, 0.5, 2.0))
    v = FuzzyVariable("d", 0.0, 1.0, ("A", "B"), (0.0, 1.0))
    with pytest.raises(ValueError, match="rule table"):
        FuzzySystem("x", v, v, v, ((0,),))
    with pytest.raises(ValueError, match="rho0"):
        FuzzyScheduledLaw(-1.0, 100.0)
    with pytest.raises(ValueError, match="side"):
        FuzzyScheduledLaw(0.5, 100.0).wall_equilibria(1.0, "up")


@pytest.mark.parametrize("side, d0, eta, eta_d, n_frozen, n_total, n_tol, c", [
    ("left", 0.43933, 34.94, -2.45, 13.459, 13.499, 5e-4, 0.168),
    # printed 13.257; ours 13.25646 = N_frozen − η_d p/F_y with the exact η_d = −73.1497.
    # It rounds to 13.256: the printed digit is one unit high (0.004 %), documented in
    # docs/velocity_and_fuzzy.md; tolerance one unit of the last digit instead of a half.
    ("right", 0.42194, 24.06, -73.15, 11.501, 13.257, 1e-3, 0.403),
])
def test_wall_table(law, side, d0, eta, eta_d, n_frozen, n_total, n_tol, c):
    """The wall table (ρ0 = 0.5, F_a = 100, α = 60°, n = 0) to the printed digits (half a unit of the last one).

    c is the central value; at θ_obs = ±90° (a set centre) η has a kink in θ and the two
    one-sided values bracket it.
    """
    (e,) = law.wall_equilibria(math.pi / 3, side)
    assert e.x0 == pytest.approx(d0, abs=5e-6)
    assert e.eta == pytest.approx(eta, abs=5e-3) and e.eta_d == pytest.approx(eta_d, abs=5e-3)
    assert e.N_frozen == pytest.approx(n_frozen, abs=5e-4) and e.N == pytest.approx(n_total, abs=n_tol)
    assert e.c == pytest.approx(c, abs=5e-4)
    assert min(e.c_plus, e.c_minus) < e.c < max(e.c_plus, e.c_minus)


def test_corridor_table_and_bracket(law):
    """Corridor x* (mm, 2 decimals: tolerance 5e-3 mm) and N with F_fwd = 100; the frozen-gain bracket."""
    rows = [(0.20, 0.65, 955.7), (0.30, 3.46, 154.1), (0.40, 8.24, 35.87), (0.45, 8.09, 17.54)]
    for L, x_mm, N in rows:
        (e,) = law.corridor_equilibria(L)
        assert 1000 * e.x0 == pytest.approx(x_mm, abs=5e-3)
        assert e.N == pytest.approx(N, abs=0.5 * 10 ** (-(len(str(N).split(".")[1]))))
    b = law.robust_bracket(math.pi / 3)
    assert b.eta == pytest.approx((9.914, 87.848), abs=5e-4)
    assert b.N == pytest.approx((9.147, 23.175), abs=5e-4)
    assert b.d0 == pytest.approx((0.371, 0.470), abs=5e-4)


def test_gains_by_finite_differences_random():
    """N (total and frozen) and c against central differences of the lateral force at random parameters.

    Far from the paper's case (ρ0 up to 3 m, F_a from 1 to 1000, α from 20° to 80°, n = 0 or 1).
    h = 1e-6 (m, rad) keeps the FD within one smooth piece of the centroid; the force scale is
    F_a, so relative tolerance 1e-4 leaves room for FD rounding (~1e-16·F/h). c is compared with
    the central difference in ψ, which is the mean of the two sides of the kink at θ_obs = ±90°.
    """
    rng = np.random.default_rng(3)
    fis = load_dfapf()
    checked = 0
    for _ in range(6):
        law = FuzzyScheduledLaw(rng.uniform(0.3, 3.0), 10 ** rng.uniform(0, 3), n=float(rng.integers(0, 2)),
                                rho_g=rng.uniform(0.5, 2.0), controllers=fis)
        alpha = math.radians(rng.uniform(20, 80))
        for side in ("left", "right"):
            for e in law.wall_equilibria(alpha, side):
                h = 1e-6
                Fy = law.attraction * math.sin(alpha)

                def fx(d, psi):
                    return float(law.wall_force(d, psi, alpha, side)[0])

                N_fd = -(fx(e.x0 + h, 0) - fx(e.x0 - h, 0)) / (2 * h) / Fy
                c_fd = -(fx(e.x0, h) - fx(e.x0, -h)) / (2 * h) / Fy
                scale = law.attraction / Fy
                assert e.N == pytest.approx(N_fd, abs=1e-4 * max(1.0, abs(N_fd)) * scale)
                assert e.c == pytest.approx(c_fd, abs=1e-4 * scale)
                p, dp = law.shape(e.x0)
                assert e.N_frozen == pytest.approx(-e.eta * dp * law.factor / Fy, rel=1e-12)
                checked += 1
    assert checked >= 6
