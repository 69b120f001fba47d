"""The holonomic loop family s² + (c_h s + κ)e^(−sT) and the kinematic steering loop (docs/models.md).

Oracles: the closed forms of docs/models.md ("Robot loop families"), the
published numbers of Ge & Cui 2002's loops worked out there, cxroots and qpmr
(independent quasi-polynomial root finders) for the exact delay, and
eigenvalues of the sampled loop's transition matrix built here with scipy's
expm for the sampled model.
"""

import math
import warnings

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

from pfm_stability.models import Continuous, ExactDelay, KBFirstOrder, Loop, Pade, Sampled, make_model
from pfm_stability.models.holonomic import BEST_CURVATURE_PRODUCT, HOLONOMIC, HolonomicLoop, kinematic_loop

cxroots = pytest.importorskip("cxroots")

EXACT = ExactDelay()
ZOH = Sampled("command", 0)
ZOH1 = Sampled("command", 1)
ALL = [Continuous(), KBFirstOrder(), Pade(4), EXACT, ZOH, ZOH1]


def _pure_delay_T_star(c, kappa):
    w = math.sqrt((c * c + math.sqrt(c**4 + 4 * kappa * kappa)) / 2)
    return math.atan2(c * w, kappa) / w, w


def _random_points(count, seed):
    """Seeded (c_h, κ) spread over six decades each, far from any published case."""
    rng = np.random.default_rng(seed)
    return [(float(10 ** rng.uniform(-3, 2)), float(10 ** rng.uniform(-4, 3))) for _ in range(count)]


# --------------------------------------------------------------- published numbers
def _printed(text):
    """A published number and half a unit of its last printed digit (the rounding it carries)."""
    decimals = len(text.split(".")[1]) if "." in text else 0
    return pytest.approx(float(text), abs=0.5 * 10.0**-decimals * (1 + 1e-9))


@pytest.mark.parametrize(
    "c_h, kappa, pure, omega, zoh, zoh1",
    [(0.2, 0.01, "6.474", "0.2058", "10", "4.26"), (0.08, 0.0016, "16.19", None, "25", "10.65"), (0.2, 24.0, "8.33", "4.901", "16.7", "5.55")],
)
def test_published_critical_delays(c_h, kappa, pure, omega, zoh, zoh1):
    """T* of the tracking gains and of a Khatib corridor (docs/models.md table): pure delay, ZOH, ZOH + 1 sample.

    Each value must round to the published digits (tolerance: half a unit of the
    last printed digit); κ = 24 is published in ms."""
    unit = 1e3 if kappa > 1 else 1.0
    loop = HolonomicLoop(0.1, c_h)
    assert unit * EXACT.critical_delay(kappa, loop) == _printed(pure)
    assert unit * ZOH.critical_delay(kappa, loop) == _printed(zoh)
    assert unit * ZOH1.critical_delay(kappa, loop) == _printed(zoh1)
    if omega is not None:
        assert _pure_delay_T_star(c_h, kappa)[1] == _printed(omega)
        T_star = EXACT.critical_delay(kappa, loop)
        b = EXACT.boundary(HolonomicLoop(T_star, c_h))
        assert b.kappa_critical == pytest.approx(kappa, rel=1e-6)  # at T*, κ is on the boundary
        assert b.omega_critical == _printed(omega)


@pytest.mark.parametrize("c_h, expected", [(0.0, 1.044 + 4.531j), (0.2, 0.978 + 4.583j)])
def test_published_rightmost_roots(c_h, expected):
    """κ = 24, T = 0.1 s: the undamped loop and the corridor with α_v = 0.1 are unstable; roots to the
    published 4 digits (absolute 1e-3)."""
    root = EXACT.rightmost_root(24.0, HolonomicLoop(0.1, c_h))
    assert abs(root.real - expected.real) < 1e-3 and abs(root.imag - expected.imag) < 1e-3
    assert not EXACT.is_stable(24.0, HolonomicLoop(0.1, c_h))


def test_zoh_damping_window_for_the_corridor():
    """ZOH at T = 0.1 s stabilises κ = 24 exactly for c_h in (κT/2, 2/T) = (1.2, 20) (Jury); relative 1e-9."""
    (lo, hi), = ZOH.damping_range(24.0, HolonomicLoop(0.1, 0.2))
    assert lo == pytest.approx(1.2, rel=1e-9) and hi == pytest.approx(20.0, rel=1e-9)


# --------------------------------------------------------------- closed forms, random
@pytest.mark.parametrize("c_h, kappa", _random_points(20, seed=3))
def test_closed_forms_of_T_star(c_h, kappa):
    """Pure delay T* = atan2(c_hω, κ)/ω (exact route: relative 1e-9); ZOH T* = min(2/c_h, 2c_h/κ) (Jury),
    first order T* = min(1/c_h, c_h/κ) (Routh): searched by bisection to 1e-9, so relative 1e-7. Padé(8) tends
    to the exact delay (relative 1e-4: Padé's error at ωT <= π/2 is far below that at order 8)."""
    loop = HolonomicLoop(0.01, c_h)
    assert EXACT.critical_delay(kappa, loop) == pytest.approx(_pure_delay_T_star(c_h, kappa)[0], rel=1e-9)
    assert ZOH.critical_delay(kappa, loop) == pytest.approx(min(2 / c_h, 2 * c_h / kappa), rel=1e-7)
    assert KBFirstOrder().critical_delay(kappa, loop) == pytest.approx(min(1 / c_h, c_h / kappa), rel=1e-7)
    assert Pade(8).critical_delay(kappa, loop) == pytest.approx(_pure_delay_T_star(c_h, kappa)[0], rel=1e-4)


@pytest.mark.parametrize("c_h, kappa", _random_points(12, seed=4))
def test_T_star_is_where_stability_ends(c_h, kappa):
    """Each model's T* separates stable (T*·(1 − 1e-4)) from unstable (T*·(1 + 1e-4)); 1e-4 is far above the
    searches' 1e-9 and far below any second crossing."""
    for model in ALL[1:]:
        T_star = model.critical_delay(kappa, HolonomicLoop(0.0, c_h))
        if math.isinf(T_star) or T_star * 1.0001 > 100:
            continue
        assert model.is_stable(kappa, HolonomicLoop(T_star * 0.9999, c_h)), model
        assert not model.is_stable(kappa, HolonomicLoop(T_star * 1.0001, c_h)), model


def test_continuous_stable_iff_positive_damping_and_stiffness():
    """Continuous loop s² + c_h s + κ: stable ⇔ c_h > 0 and κ > 0, on random signs and sizes; T* inf or 0."""
    rng = np.random.default_rng(5)
    model = Continuous()
    for _ in range(200):
        c_h = float(rng.choice([-1, 0, 1]) * 10 ** rng.uniform(-3, 3))
        kappa = float(rng.choice([-1, 1]) * 10 ** rng.uniform(-3, 3))
        expected = c_h > 0 and kappa > 0
        loop = HolonomicLoop(0.5, c_h)
        assert model.is_stable(kappa, loop) == expected
        assert model.critical_delay(kappa, loop) == (math.inf if expected else 0.0)


@pytest.mark.parametrize("model", ALL[1:], ids=lambda m: repr(m))
def test_undamped_and_negative_edge_cases(model):
    """c_h = 0: any delay destabilises (T* = 0, unstable at T > 0); κ < 0 or c_h < 0: unstable, T* = 0,
    no damping range for κ < 0. Exact comparisons: these are decided by signs, not searches."""
    for c_h, kappa in [(0.0, 24.0), (0.0, 1e-3), (-0.2, 24.0), (0.2, -24.0)]:
        assert model.critical_delay(kappa, HolonomicLoop(0.1, c_h)) == 0.0
        assert not model.is_stable(kappa, HolonomicLoop(0.1, c_h))
    assert model.damping_range(-1.0, HolonomicLoop(0.1, 0.2)) == ()
    assert model.boundary(HolonomicLoop(0.1, 0.0)).kappa_critical == 0.0


def test_T_zero_is_the_continuous_loop():
    """T = 0: every model gives the continuous loop's verdict, its boundary (κ* = inf) and its roots (1e-12)."""
    rng = np.random.default_rng(6)
    for _ in range(20):
        c_h, kappa = float(10 ** rng.uniform(-2, 2)), float(rng.choice([-1, 1]) * 10 ** rng.uniform(-2, 2))
        loop = HolonomicLoop(0.0, c_h)
        reference = np.roots([1.0, c_h, kappa])
        for model in ALL:
            assert model.is_stable(kappa, loop) == (kappa > 0)
            assert math.isinf(model.boundary(loop).kappa_critical)
            root = model.rightmost_root(kappa, loop)
            assert abs(root.real - reference.real.max()) <= 1e-12 * max(1.0, abs(kappa), c_h)


# ------------------------------------------------------ boundaries against verdicts
@pytest.mark.parametrize("seed", range(6))
def test_boundaries_and_damping_ranges_agree_with_verdicts(seed):
    """Random (T, c_h, κ) far from CARMEL: κ inside `boundary().stable_set` ⇔ `is_stable`, c_h inside
    `damping_range` ⇔ `is_stable` (points within 1e-6 relative of an edge skipped: the undecided band)."""
    rng = np.random.default_rng(100 + seed)
    T, c_h = float(10 ** rng.uniform(-3, 0.5)), float(10 ** rng.uniform(-2, 2))
    loop = HolonomicLoop(T, c_h)
    for model in ALL:
        b = model.boundary(loop)
        edges = [x for pair in b.stable_set for x in pair if math.isfinite(x)]
        for kappa in 10 ** rng.uniform(-4, 4, 12):
            if any(abs(kappa / e - 1) < 1e-6 for e in edges if e > 0):
                continue
            assert b.contains(kappa) == model.is_stable(kappa, loop), (model, T, c_h, kappa)
        kappa = float(10 ** rng.uniform(-3, 1)) / T**2
        ranges = model.damping_range(kappa, loop)
        edges = [x for pair in ranges for x in pair if math.isfinite(x)]
        for c in 10 ** rng.uniform(-3, 3, 12):
            if any(abs(c / e - 1) < 1e-6 for e in edges if e > 0):
                continue
            inside = any(lo < c < hi for lo, hi in ranges)
            assert inside == model.is_stable(kappa, HolonomicLoop(T, float(c))), (model, T, kappa, c)


def test_exact_delay_damping_range_closed_form():
    """The exact-delay c_h range: empty iff κT² >= max x² cos x ≈ 0.5498 (scipy's bounded
    minimiser as the oracle, 1e-9: a maximum is flat, its value is found to ~xatol²); its ends have
    T*(κ, c_h) = T by the closed form (relative 1e-9)."""
    peak = scipy.optimize.minimize_scalar(lambda x: -x * x * math.cos(x), bounds=(0.0, math.pi / 2), method="bounded", options={"xatol": 1e-10})
    assert BEST_CURVATURE_PRODUCT == pytest.approx(-peak.fun, rel=1e-9)
    T = 0.1
    assert EXACT.damping_range(0.5498 * 1.0001 / T**2, HolonomicLoop(T, 1.0)) == ()
    for kappa in (0.01, 1.0, 24.0, 54.0):
        (lo, hi), = EXACT.damping_range(kappa, HolonomicLoop(T, 1.0))
        assert _pure_delay_T_star(lo, kappa)[0] == pytest.approx(T, rel=1e-9)
        assert _pure_delay_T_star(hi, kappa)[0] == pytest.approx(T, rel=1e-9)


# ----------------------------------------------------------- independent oracles
def _cx_roots(kappa, c_h, T, box):
    f = lambda s: s**2 + (c_h * s + kappa) * np.exp(-s * T)
    df = lambda s: 2 * s + (c_h - T * (c_h * s + kappa)) * np.exp(-s * T)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.array(cxroots.Rectangle(*box).roots(f, df).roots)


def _oracle_sets(count, seed):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        T = float(10 ** rng.uniform(-2, 0))
        kappa = float(10 ** rng.uniform(-1, 1.5)) / T**0.5
        c_h = float(10 ** rng.uniform(-1.5, 0.5)) * math.sqrt(kappa)
        out.append((T, c_h, kappa))
    return out


@pytest.mark.parametrize("T, c_h, kappa", _oracle_sets(10, seed=21))
def test_exact_delay_roots_against_cxroots(T, c_h, kappa):
    """Rightmost root to 1e-6 and the verdict against cxroots (argument principle + Newton, polished to
    ~1e-10). Every root with Re s >= 0 has |s|² = |c_h s + κ||e^(−sT)| <= c_h|s| + κ, so |s| < R =
    c_h + √κ + 1 and the rectangle also holds every unstable root."""
    loop = HolonomicLoop(T, c_h)
    ours = EXACT.rightmost_root(kappa, loop)
    R = max(c_h + math.sqrt(kappa) + 1.0, abs(ours.imag) + 1.0)
    roots = _cx_roots(kappa, c_h, T, ([ours.real - 1.0, R], [-R, R]))
    theirs = roots[np.argmax(roots.real)]
    assert abs(ours.real - theirs.real) < 1e-6 and abs(ours.imag - abs(theirs.imag)) < 1e-6
    assert EXACT.is_stable(kappa, loop) == bool(np.all(roots.real < 0))


@pytest.mark.parametrize("T, c_h, kappa", _oracle_sets(4, seed=22))
def test_exact_delay_boundary_root_on_axis_by_qpmr(T, c_h, kappa):
    """At T = T*(κ, c_h) qpmr (Vyhlídal & Zítek's QPmR) finds the rightmost root on the imaginary axis at
    the closed form's ω (absolute 1e-6: its polishing tolerance is 1e-10)."""
    qpmr = pytest.importorskip("qpmr")
    T_star = EXACT.critical_delay(kappa, HolonomicLoop(T, c_h))
    w = _pure_delay_T_star(c_h, kappa)[1]
    R = c_h + math.sqrt(kappa) + 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        roots, _ = qpmr.qpmr(np.array([[0.0, 0.0, 1.0], [kappa, c_h, 0.0]]), np.array([0.0, T_star]), region=[-1.0, 1.0, -R, R], e=1e-10, ds=min(0.02, R / 200))
    top = roots[np.argmax(roots.real)]
    assert abs(top.real) < 1e-6 and abs(abs(top.imag) - w) < 1e-6


def _sampled_poles(kappa, c_h, T, compute_delay):
    """Poles of the double integrator with a ZOH of u = −κx − c_h v, built independently (scipy expm)."""
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    B = np.array([[0.0], [1.0]])
    M = scipy.linalg.expm(np.block([[A, B], [np.zeros((1, 3))]]) * T)
    Phi, Gamma = M[:2, :2], M[:2, 2:]
    F = np.array([[kappa, c_h]])
    if compute_delay == 0:
        return np.linalg.eigvals(Phi - Gamma @ F)
    return np.linalg.eigvals(np.block([[Phi, Gamma], [-F, np.zeros((1, 1))]]))


@pytest.mark.parametrize("compute_delay", [0, 1])
def test_sampled_verdict_against_scipy_poles(compute_delay):
    """120 random (T, c_h, κ): the sampled verdict, the Jury test and the boundary's stable set agree with
    |z| < 1 of poles from scipy's expm (points with ||z| − 1| < 1e-9 skipped: round-off decides those);
    the dominant pole's ln|z|/T to 1e-9 relative."""
    rng = np.random.default_rng(30 + compute_delay)
    model = Sampled("command", compute_delay)
    for _ in range(120):
        T = float(10 ** rng.uniform(-3, 1))
        c_h = float(10 ** rng.uniform(-1, 1)) / T * rng.uniform(0, 2.5)
        kappa = float(10 ** rng.uniform(-2, 1.5)) / T**2
        z = _sampled_poles(kappa, c_h, T, compute_delay)
        radius = np.abs(z).max()
        if abs(radius - 1) < 1e-9:
            continue
        loop = HolonomicLoop(T, c_h)
        assert model.is_stable(kappa, loop) == (radius < 1)
        assert model.jury_stable(kappa, loop) == (radius < 1)
        assert model.boundary(loop).contains(kappa) == (radius < 1)
        if radius > 1e-6:
            assert model.rightmost_root(kappa, loop).real == pytest.approx(math.log(radius) / T, rel=1e-9, abs=1e-9 / T)


# ---------------------------------------------------------------- kinematic steering
def test_kinematic_steering_published_example():
    """Ge & Cui 2002 §7, c = 0, K_s = 2, NV = 2: T* = 0.575307 s, ω = 1.57230 (published to 6 digits: 1e-6
    relative), through the existing steering model with τ = 0, and the closed form
    T* = atan2(K_s, ω)/ω, ω² = (−K_s² + √(K_s⁴ + 4K_s²N²V²))/2."""
    T_star = ExactDelay().critical_delay(2.0, kinematic_loop(2.0, 0.1))
    assert T_star == pytest.approx(0.575307, rel=1e-6)
    b = ExactDelay().boundary(kinematic_loop(2.0, T_star))
    assert b.NV_critical == pytest.approx(2.0, rel=1e-6)
    assert b.omega_critical == pytest.approx(1.57230, rel=1e-5)


@pytest.mark.parametrize("seed", range(3))
def test_kinematic_closed_form_random(seed):
    """The kinematic T* closed form on random K_s, NV (relative 1e-9: both are exact routes)."""
    rng = np.random.default_rng(40 + seed)
    for _ in range(10):
        K_s, NV = float(10 ** rng.uniform(-2, 2)), float(10 ** rng.uniform(-2, 2))
        w = math.sqrt((-K_s**2 + math.sqrt(K_s**4 + 4 * K_s**2 * NV**2)) / 2)
        assert ExactDelay().critical_delay(NV, kinematic_loop(K_s, 0.0)) == pytest.approx(math.atan2(K_s, w) / w, rel=1e-9)


@pytest.mark.parametrize("c, expected", [(0.0, 2.76787), (0.1, 3.01188), (0.25, 3.36649), (0.5, 3.92682), (1.0, 4.93063)])
def test_steering_heading_gain_table(c, expected):
    """CARMEL τ = 0.3 s, k = 2, T = 0.065 s, exact delay: NV*(c) as published (6 digits: relative 2e-6)."""
    assert ExactDelay().boundary(Loop(0.3, 0.065, 2.0, c=c)).NV_critical == pytest.approx(expected, rel=2e-6)


@pytest.mark.parametrize("q, expected", [(0.0, 2.76787), (0.1, 2.73476), (0.2, 2.69319), (0.5, 2.46532)])
def test_steering_velocity_attraction_in_kb_normalisation(q, expected):
    """The same loop with q = 2α_vV/(F_a sin α): c = q/(1 − q), N = N_KB/(1 − q), so N_KB V* = (1 − q)·NV*(c)."""
    c = q / (1 - q)
    assert (1 - q) * ExactDelay().boundary(Loop(0.3, 0.065, 2.0, c=c)).NV_critical == pytest.approx(expected, rel=2e-6)


# ---------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: HolonomicLoop(-1.0, 0.2), "T"),
        (lambda: HolonomicLoop(0.1, math.nan), "c_h"),
        (lambda: HolonomicLoop(0.1, "0.2"), "c_h"),
        (lambda: EXACT.is_stable(0.0, HolonomicLoop(0.1, 0.2)), "kappa"),
        (lambda: ZOH.critical_delay(math.inf, HolonomicLoop(0.1, 0.2)), "kappa"),
        (lambda: ZOH.rightmost_root(1.0, (0.1, 0.2)), "loop"),
        (lambda: Sampled("command", 2), "compute_delay"),
        (lambda: Pade(0), "pade_order"),
        (lambda: make_model("nope"), "model"),
        (lambda: Sampled("reference", 0).is_stable(1.0, HolonomicLoop(0.1, 0.2)), "hold"),
        (lambda: Continuous().critical_gain_k(1.0, HolonomicLoop(0.1, 0.2)), "loop"),
        (lambda: ZOH.damping_range(1.0, Loop(0.3, 0.1, 2.0)), "damping_range"),
        (lambda: kinematic_loop(0.0, 0.1), "K_s"),
        (lambda: EXACT.damping_range(True, HolonomicLoop(0.1, 0.2)), "kappa"),
    ],
)
def test_bad_input_names_the_parameter(call, name):
    """Bad input raises ValueError whose message starts with the parameter's name (one line)."""
    with pytest.raises(ValueError) as info:
        call()
    message = str(info.value)
    assert message.startswith(name + " ") and "\n" not in message


def test_factory_and_json():
    """Every name builds its model, which takes a holonomic loop; the holonomic family lists a model with its
    equation and options, the sampled one without a hold (the acceleration is held); a boundary serializes with
    "inf" for an unbounded set."""
    for name, cls in [("continuous", Continuous), ("kb_first_order", KBFirstOrder), ("pade", Pade), ("exact_delay", ExactDelay), ("sampled", Sampled)]:
        model = make_model(name)
        assert isinstance(model, cls) and model.boundary(HolonomicLoop(0.1, 0.2)).model == name
    assert HOLONOMIC.describe(make_model("sampled", compute_delay=1)) == {
        "equation": "det(zI - Phi_cl(kappa, c_h)) = 0, ZOH of the acceleration, period T", "compute_delay": 1}
    assert HOLONOMIC.describe(make_model("pade", pade_order=5)) == {"equation": "s^2 Q_m(s) + (c_h s + kappa) P_m(s) = 0  (Pade(m,m))", "order": 5}
    d = Continuous().boundary(HolonomicLoop(0.1, 0.2)).to_dict()
    assert d["kappa_critical"] == "inf" and d["stable_set"] == [[0.0, "inf"]]


# --------------------------------------------------------------- T* below a microsecond
SUB_MICROSECOND = [(1e3, 1e12), (1.0, 1e9), (0.1, 1e8), (0.0033677912440780674, 8364626.708573155), (50.0, 3e9)]
"""(c_h, κ) whose T* lies between 1e-10 and 1e-6 s; the light damping of the middle three (c_h ≪ √κ) left the old
absolute floor far above 1e-9·T* (the fourth was found 3e-7 relative off)."""


def _mp_first_loss(stable, T_hi):
    """The delay where `stable(T)` (mpmath, 30 digits) turns False, by bisection on [T_hi/64, T_hi], 1e-12 relative."""
    import mpmath as mp

    lo, hi = mp.mpf(T_hi) / 64, mp.mpf(T_hi)
    assert stable(lo) and not stable(hi)
    while hi - lo > mp.mpf("1e-12") * hi:
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return float(hi)


def _mp_zoh1_stable(kappa, c_h):
    """ZOH with one sample of delay, built here in mpmath: Φ = [[1, T], [0, 1]], Γ = [T²/2, T], the held command
    u_k = −κx_{k−1} − c_h v_{k−1}; stable iff every eigenvalue of [[Φ, Γ], [−F, 0]] has |z| < 1."""
    import mpmath as mp

    def stable(T):
        M = mp.matrix([[1, T, T * T / 2], [0, 1, T], [-kappa, -c_h, 0]])
        return max(abs(z) for z in mp.eig(M, left=False, right=False)) < 1

    return stable


def _routh_stable(descending) -> bool:
    """Every root in Re s < 0: the n + 1 entries of the first column of the Routh array are positive (any zero: not)."""
    n = len(descending) - 1
    width = n // 2 + 2
    rows = [list(descending[0::2]), list(descending[1::2])]
    rows = [r + [0] * (width - len(r)) for r in rows]
    for _ in range(n - 1):
        upper, lower = rows[-2], rows[-1]
        if lower[0] <= 0:
            return False
        rows.append([(lower[0] * upper[i + 1] - upper[0] * lower[i + 1]) / lower[0] for i in range(width - 1)] + [0])
    return all(row[0] > 0 for row in rows)


def _mp_pade_stable(kappa, c_h, m):
    """s²·Q_m(sT) + (c_h s + κ)·P_m(sT) with Padé's textbook coefficients of e^(−x), P_m(x) = Σ_j (2m − j)! m! /
    ((2m)! j! (m − j)!) (−x)^j and Q_m(x) = P_m(−x); stable iff the first column of its Routh array (mpmath) is positive."""
    import mpmath as mp

    a = [mp.factorial(2 * m - j) * mp.factorial(m) / (mp.factorial(2 * m) * mp.factorial(j) * mp.factorial(m - j)) for j in range(m + 1)]

    def stable(T):
        P = [a[j] * (-T) ** j for j in range(m + 1)]  # ascending powers of s
        Q = [a[j] * T**j for j in range(m + 1)]
        coefficients = [mp.mpf(0)] * (m + 3)
        for j in range(m + 1):
            coefficients[j + 2] += Q[j]
            coefficients[j + 1] += c_h * P[j]
            coefficients[j] += kappa * P[j]
        return _routh_stable(coefficients[::-1])

    return stable


@pytest.mark.parametrize("c_h, kappa", SUB_MICROSECOND)
def test_T_star_below_a_microsecond_meets_its_promise(c_h, kappa):
    """`critical_delay` promises 1e-9 relative; where T* <= 1e-6 s its absolute floor (1e-12·min(1/c_h, 1/√κ)) used to
    stop the bisection first (2e-7 to 3e-6 relative off). Oracles at 1e-9 relative (plus round-off: 2e-9): Routh's
    min(1/c_h, c_h/κ) for kb_first_order, Jury's min(2/c_h, 2c_h/κ) for the ZOH; the exact delay's crossing solved
    here with mpmath (s = jω: −ω² + κ cos ωT + c_h ω sin ωT = 0 and c_h ω cos ωT − κ sin ωT = 0, 30 digits); the ZOH
    with one sample of delay and Padé(4) bisected here in mpmath on their own stability tests."""
    import mpmath as mp

    loop = HolonomicLoop(0.01, c_h)
    first_order = min(1 / c_h, c_h / kappa)
    assert 1e-10 < first_order <= 1e-6
    assert KBFirstOrder().critical_delay(kappa, loop) == pytest.approx(first_order, rel=2e-9, abs=0)
    assert ZOH.critical_delay(kappa, loop) == pytest.approx(min(2 / c_h, 2 * c_h / kappa), rel=2e-9, abs=0)
    with mp.workdps(30):  # abs=0 below: pytest.approx's default absolute 1e-12 would pass anything at T* ~ 1e-9 s
        w0, T0 = _pure_delay_T_star(c_h, kappa)[1], _pure_delay_T_star(c_h, kappa)[0]
        w, T = mp.findroot(lambda w, T: (-w * w + kappa * mp.cos(w * T) + c_h * w * mp.sin(w * T), c_h * w * mp.cos(w * T) - kappa * mp.sin(w * T)),
                           (mp.mpf(w0) * (1 + mp.mpf("1e-6")), mp.mpf(T0) * (1 - mp.mpf("1e-6"))))
        assert EXACT.critical_delay(kappa, loop) == pytest.approx(float(T), rel=2e-9, abs=0)
        T_zoh1 = _mp_first_loss(_mp_zoh1_stable(mp.mpf(kappa), mp.mpf(c_h)), 4 * first_order)
        T_pade = _mp_first_loss(_mp_pade_stable(mp.mpf(kappa), mp.mpf(c_h), 4), 4 * first_order)
    assert ZOH1.critical_delay(kappa, loop) == pytest.approx(T_zoh1, rel=2e-9, abs=0)
    assert Pade(4).critical_delay(kappa, loop) == pytest.approx(T_pade, rel=2e-9, abs=0)
