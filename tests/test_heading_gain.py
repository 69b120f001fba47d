"""The heading gain c in every loop model (docs/models.md, "The heading gain").

A field that depends on the robot's heading adds c·θ to the linearized reference,
δ ≈ −N·(x − x0) − c·θ, and KB eq (18) becomes τs³ + s² + ks + k(cs + NV)·e^(−sT) = 0.
What is checked here, and against what:

* c = 0 is KB's loop: one loop however c = 0 is spelled (the answers the code gave before
  the heading gain existed are kept in tests/test_c_zero_reference.py);
* the closed forms: `continuous` NV* = (1 + c)/τ, `kb_first_order`'s Routh bound
  derived with sympy here;
* `exact_delay` against two independent root finders (qpmr: QPmR spectral mapping;
  cxroots: argument principle), `sampled` against a closed-loop matrix built here
  with scipy's `expm`, on random and extreme parameters with c < 0 and c > 0;
* N < 0 (NV < 0) in every model: unstable, with the divergent real root, no NaN.
"""

import math
import warnings

import numpy as np
import pytest
import sympy as sp
from scipy.linalg import expm
from scipy.optimize import brentq

from pfm_stability.numerics.delay import DelayLoop, delay_verdicts_from_gain, kb_critical_gain
from pfm_stability.models import MODEL_NAMES, Continuous, ExactDelay, KBFirstOrder, Loop, Pade, Sampled, gain_margin, make_model, verdict_label
from pfm_stability.models.verdicts import DIVERGENT_REASON, divergent_reason
from pfm_stability.models.heading import kb_heading_interval

STRUCTURES = [(h, d) for h in ("command", "reference") for d in (0, 1)]
ALL_MODELS = [("continuous", {}), ("kb_first_order", {}), ("pade", {"pade_order": 4}), ("exact_delay", {})] + [
    ("sampled", {"hold": h, "compute_delay": d}) for h, d in STRUCTURES
]


def _heading_loops(count, seed, *, tau=(0.02, 1.5), T=(0.005, 0.5), k=(0.3, 10.0)):
    """Seeded (τ, T, k, c): every other c negative (down to −0.99), the rest positive up to 20 (log-uniform)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        t = 0.0 if i % 5 == 4 else float(np.exp(rng.uniform(np.log(tau[0]), np.log(tau[1]))))
        d = float(np.exp(rng.uniform(np.log(T[0]), np.log(T[1]))))
        g = float(np.exp(rng.uniform(np.log(k[0]), np.log(k[1]))))
        c = float(rng.uniform(-0.99, -0.01)) if i % 2 else float(np.exp(rng.uniform(np.log(0.01), np.log(20.0))))
        out.append((t, d, g, c))
    return out


# ---------------------------------------------------------------------------------------------
# c = 0 spelled any way (the answers of the code before c: tests/test_c_zero_reference.py)
# ---------------------------------------------------------------------------------------------
def test_c_zero_spelled_any_way_is_one_loop():
    """Loop(τ, T, k), c=0, c=0.0, c=-0.0 and c=np.float64(0) are one loop (equal, one hash, one
    cache entry), c is keyword-only, and the models give identical answers for them."""
    loops = [Loop(0.3, 0.065, 2.0), Loop(0.3, 0.065, 2.0, c=0), Loop(0.3, 0.065, 2.0, c=-0.0), Loop(0.3, 0.065, 2.0, c=np.float64(0.0))]
    assert all(loop == loops[0] and hash(loop) == hash(loops[0]) for loop in loops)
    assert all(type(loop.c) is float for loop in loops)
    with pytest.raises(TypeError):
        Loop(0.3, 0.065, 2.0, 0.5)
    for name, options in ALL_MODELS:
        model = make_model(name, **options)
        answers = {(model.boundary(loop).NV_critical, model.rightmost_root(2.0, loop), model.critical_delay(2.0, loop)) for loop in loops}
        assert len(answers) == 1


@pytest.mark.parametrize(
    "c, message",
    [
        (-1.0, r"c must be a finite number in \[-0.99, 100\]; got -1.0 \(c <= -1 removes the heading feedback: unstable at any NV\)"),
        (100.5, r"c must be a finite number in \[-0.99, 100\]; got 100.5"),
        (float("nan"), "c must be a finite number"),
        (True, "c must be a finite number"),
        ("0.5", "c must be a finite number"),
    ],
)
def test_heading_gain_range_is_checked(c, message):
    """The documented range [−0.99, 100]: c <= −1 leaves no heading feedback (the continuous loop
    τs³ + s² + k(1 + c)s + kNV then has a non-positive s coefficient), refused with that reason."""
    with pytest.raises(ValueError, match=message):
        Loop(0.3, 0.065, 2.0, c=c)


# ---------------------------------------------------------------------------------------------
# closed forms
# ---------------------------------------------------------------------------------------------
def _routh_bound():
    """Routh on the heading loop with e^(−sT) ≈ 1 − sT, derived here from scratch with sympy.

    Returns the cubic's coefficients, the Hurwitz condition a2·a1 − a3·a0 and the symbols.
    """
    s, tau, T, k, NV = sp.symbols("s tau T k NV", positive=True)
    c = sp.Symbol("c", real=True)
    cubic = sp.Poly(sp.expand(tau * s**3 + s**2 + k * s + k * (c * s + NV) * (1 - s * T)), s)
    a3, a2, a1, a0 = (cubic.coeff_monomial(s**i) for i in (3, 2, 1, 0))
    return (a3, a2, a1, a0), sp.expand(a2 * a1 - a3 * a0), (tau, T, k, c, NV)


def test_kb_first_order_routh_bound_derived_with_sympy():
    """Symbolically: (19) with the heading term is τs³ + (1 − kcT)s² + k(1 + c − NVT)s + kNV, and the
    Hurwitz condition a2a1 = a3a0 gives NV* = (1 − kcT)(1 + c)/(τ + T(1 − kcT)); without delay
    (T = 0) it is the continuous NV* = (1 + c)/τ."""
    (a3, a2, a1, a0), hurwitz, (tau, T, k, c, NV) = _routh_bound()
    assert sp.simplify(a2 - (1 - k * c * T)) == 0
    assert sp.simplify(a1 - k * (1 + c - NV * T)) == 0
    (NV_star,) = sp.solve(sp.Eq(hurwitz, 0), NV)
    assert sp.simplify(NV_star - (1 - k * c * T) * (1 + c) / (tau + T * (1 - k * c * T))) == 0
    assert sp.simplify(NV_star.subs(T, 0) - (1 + c) / tau) == 0


@pytest.mark.parametrize("tau, T, k, c", _heading_loops(40, seed=1))
def test_continuous_and_kb_closed_forms(tau, T, k, c):
    """The generic crossing route of both models equals the closed forms (1e-12 relative: two
    floating-point routes to one number): continuous NV* = (1 + c)/τ, ω*² = k(1 + c)/τ;
    kb_first_order NV* and ω*² = kNV*/(1 − kcT) from the sympy bound, 0 when kcT >= 1 (τ > 0:
    the s² coefficient is not positive). T* and k* of kb_first_order are the roots of the same
    sympy condition in T and in k (smallest positive), k* = inf above the largest k (10⁴)."""
    loop = Loop(tau, T, k, c=c)
    continuous = Continuous().boundary(loop)
    if tau > 0:
        assert continuous.NV_critical == pytest.approx((1 + c) / tau, rel=1e-12)
        assert continuous.omega_critical == pytest.approx(math.sqrt(k * (1 + c) / tau), rel=1e-12)
    else:
        assert continuous.NV_critical == math.inf
    (_, a2, _, a0), hurwitz, (tau_s, T_s, k_s, c_s, NV_s) = _routh_bound()
    values = {tau_s: tau, T_s: T, k_s: k, c_s: c}
    kb = KBFirstOrder().boundary(loop)
    if 1 - k * c * T <= 0:
        assert kb.NV_critical == 0.0 and tau > 0
        return
    (NV_star,) = sp.solve(sp.Eq(hurwitz, 0), NV_s)
    expected = float(NV_star.subs(values))
    assert kb.NV_critical == pytest.approx(expected, rel=1e-12)
    assert kb.omega_critical**2 == pytest.approx(float((a0 / a2).subs(values).subs(NV_s, expected)), rel=1e-12)
    NV = 0.6 * expected
    in_T = sp.Poly(hurwitz.subs({tau_s: tau, k_s: k, c_s: c, NV_s: NV}), T_s)
    T_roots = [float(sp.re(r)) for r in in_T.nroots(n=30) if abs(sp.im(r)) < 1e-20 and sp.re(r) > 0]
    assert KBFirstOrder().critical_delay(NV, loop) == pytest.approx(min(T_roots), rel=1e-12)
    in_k = sp.solve(sp.cancel(hurwitz.subs({tau_s: tau, T_s: T, c_s: c, NV_s: NV}) / k_s), k_s)
    k_roots = [float(r) for r in in_k if r.is_real and r > 0]
    expected_k = min(k_roots) if k_roots and min(k_roots) <= 1e4 else math.inf
    assert KBFirstOrder().critical_gain_k(NV, loop) == pytest.approx(expected_k, rel=1e-12)


# ---------------------------------------------------------------------------------------------
# exact_delay against independent root finders
# ---------------------------------------------------------------------------------------------
def _rhp_radius(tau, k, c, K):
    """Every root with Re s >= 0 has |a(s)| = |kcs + K|·|e^(−sT)| <= |kc||s| + |K|, so |s| < R."""
    R, slope = 1.0, k + abs(k * c)
    while (tau * R**3 - R**2 - slope * R if tau > 0 else R**2 - slope * R) <= abs(K):
        R *= 1.5
    return R


def _qpmr_roots(tau, T, k, c, K, left, R):
    """QPmR's roots in [left, R] × [−R, R]: grid step R/200 (0.05 at most), Newton-polished to 1e-10."""
    qpmr = pytest.importorskip("qpmr")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        roots, _ = qpmr.qpmr(np.array([[0.0, k, 1.0, tau], [K, k * c, 0.0, 0.0]]), np.array([0.0, T]), region=[left, R, -R, R], e=1e-10, ds=min(0.05, R / 200) if R < 50 else R / 200)
    return roots


def _cxroots_roots(tau, T, k, c, K, box):
    cxroots = pytest.importorskip("cxroots")
    kc = k * c

    def f(s):
        return tau * s**3 + s**2 + k * s + (kc * s + K) * np.exp(-s * T)

    def df(s):
        return 3 * tau * s**2 + 2 * s + k + (kc - T * (kc * s + K)) * np.exp(-s * T)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.array(cxroots.Rectangle(*box).roots(f, df).roots)


def _delay_loop(tau, T, k, c):
    return DelayLoop([tau, 1.0, k, 0.0] if tau > 0 else [1.0, k, 0.0], T, delayed=[k * c, 0.0])


def _count(tau, T, k, c, K):
    return int(delay_verdicts_from_gain(*(np.array([x], dtype=float) for x in (tau, T, k, K, c)))[1][0])


@pytest.mark.parametrize("tau, T, k, c", _heading_loops(24, seed=5, tau=(0.1, 1.5), T=(0.005, 1.0)))
def test_exact_delay_against_qpmr(tau, T, k, c):
    """24 random loops (c in [−0.99, 20], τ = 0 on every fifth; τ >= 0.1 s keeps QPmR's rectangle,
    and its time, small; small τ and large k are among the extremes below): at a random gain and on both sides
    (±1e-6 relative) of every finite edge of the stable set, QPmR's roots in a rectangle holding
    the whole right half-plane disc give the crossing count (equal, an integer) and the stable-set
    membership; the rightmost root agrees to 1e-6 (QPmR polishes to ~1e-10; 1e-6 as for c = 0)."""
    interval = kb_heading_interval(tau, T, k, c)
    rng = np.random.default_rng(int(1e6 * T))
    gains = [k * float(rng.uniform(0.2, 3.0)) / (tau + T)]
    gains += [e * f for lo, hi in interval.intervals for e in (lo, hi) if 0 < e < math.inf for f in (1 - 1e-6, 1 + 1e-6)]
    q = _delay_loop(tau, T, k, c)
    for K in gains:
        ours = q.rightmost_roots(K, count=1)
        R = max(_rhp_radius(tau, k, c, K), abs(ours[0].imag) + 1.0)
        roots = _qpmr_roots(tau, T, k, c, K, min(ours[0].real - 1.0, -0.5), R)
        theirs = roots[np.argmax(roots.real)]
        assert abs(ours[0].real - theirs.real) < 1e-6 and abs(abs(ours[0].imag) - abs(theirs.imag)) < 1e-6
        unstable = int(np.sum(roots.real > 0))
        assert _count(tau, T, k, c, K) == q.unstable_root_count(K) == unstable
        assert any(lo < K < hi for lo, hi in interval.intervals) == (unstable == 0)


EXTREMES = [
    (0.3, 0.065, 2.0, -0.99, 1.0, "cxroots"),  # the smallest c: almost no heading feedback
    (0.3, 0.065, 2.0, 100.0, 5.0, "cxroots"),  # the largest c: the steering loop itself oscillates
    (0.0, 0.4, 3.0, 4.0, 2.0, "cxroots"),  # τ = 0, c > 1: crossing frequencies start above ω = 0
    (1.0, 0.4, 6.0, 0.5, 10.0, "cxroots"),  # kτ = 6 > 2 + √3: the steering loop resonates
    (0.2, 0.5, 10.0, 5.0, 30.0, "qpmr"),  # four roots in the right half-plane
    (0.01, 0.02, 50.0, -0.9, 1e3, "qpmr"),  # small τ, large k, c near −1
]


@pytest.mark.parametrize("tau, T, k, c, K, finder", EXTREMES)
def test_exact_delay_extremes_against_root_finders(tau, T, k, c, K, finder):
    """Extreme parameters: the argument principle (cxroots) or QPmR in a rectangle holding every
    root with Re s >= 0 counts the same right-half-plane roots as the crossing count (both routes:
    arrays and `DelayLoop`), and its rightmost root is ours to 1e-6 (their polishing is ~1e-10)."""
    q = _delay_loop(tau, T, k, c)
    ours = q.rightmost_roots(K, count=1)[0]
    R = max(_rhp_radius(tau, k, c, K), abs(ours.imag) + 1.0)
    left = min(ours.real - 1.0, -0.3)
    roots = _cxroots_roots(tau, T, k, c, K, ([left, R], [-R, R])) if finder == "cxroots" else _qpmr_roots(tau, T, k, c, K, left, R)
    assert _count(tau, T, k, c, K) == q.unstable_root_count(K) == int(np.sum(roots.real > 0))
    theirs = roots[np.argmax(roots.real)]
    assert abs(ours.real - theirs.real) < 1e-6 and abs(abs(ours.imag) - abs(theirs.imag)) < 1e-6


def test_a_stable_band_that_does_not_start_at_zero():
    """c < 0 with a long delay: the steering loop with its delayed heading term is unstable alone
    (small NV), stable in a band, unstable above: the stable set is one interval away from 0, so
    NV* = 0 ("unstable at any speed" near NV = 0). QPmR confirms the count on both sides of both
    edges (±1e-3)."""
    tau, T, k, c = 3.6211123971040755, 1.0527124359998534, 29.44461390105401, -0.393489281511628
    boundary = ExactDelay().boundary(Loop(tau, T, k, c=c))
    ((lo, hi),) = boundary.stable_set
    assert boundary.NV_critical == 0.0 and 0.1 < lo < hi < 1.0
    for NV, expected in ((lo * 0.999, 2), (lo * 1.001, 0), (hi * 0.999, 0), (hi * 1.001, 2)):
        roots = _qpmr_roots(tau, T, k, c, k * NV, -0.5, 5.0)
        assert int(np.sum(roots.real > 0)) == expected == _count(tau, T, k, c, k * NV)


def test_the_printed_band_example_holds_for_its_printed_values():
    """docs/models.md ("The heading gain") prints a loop with a stable band away from 0, to 3 digits. Recomputed from
    the printed, rounded inputs, each edge of the stable set must round to the printed digits (half a unit of the last
    one), and QPmR's root count (independent of the model) must be 0 one unit inside each printed edge and 2 one unit
    outside it. The example once printed the band of the unrounded inputs (0.120 < NV < 0.790)."""
    import re
    from pathlib import Path

    text = " ".join((Path(__file__).resolve().parents[1] / "docs" / "models.md").read_text().split())
    found = re.search(r"tested: τ = ([\d.]+) s, T = ([\d.]+) s, k = ([\d.]+) 1/s, c = −([\d.]+): stable for ([\d.]+) < NV < ([\d.]+) only, "
                      r"NV\\\* = 0", text)
    assert found, "the example's sentence changed: update this test with it"
    tau, T, k, c = (float(x) for x in found.groups()[:4])
    c = -c
    printed = found.groups()[4:]
    boundary = ExactDelay().boundary(Loop(tau, T, k, c=c))
    ((lo, hi),) = boundary.stable_set
    assert boundary.NV_critical == 0.0
    for value, shown, below, above in ((lo, printed[0], 2, 0), (hi, printed[1], 0, 2)):  # unstable roots one unit below / above
        unit = 10.0 ** -len(shown.split(".")[1])
        assert abs(value - float(shown)) <= 0.5 * unit * (1 + 1e-9), (value, shown)
        for NV, expected in ((float(shown) - unit, below), (float(shown) + unit, above)):
            roots = _qpmr_roots(tau, T, k, c, k * NV, -0.5, 5.0)
            assert int(np.sum(roots.real > 0)) == expected, (NV, expected)


def test_heading_route_with_c_zero_equals_kb_critical_gain():
    """The heading machinery (polynomial split points, level equation, crossing count) run at c = 0
    reproduces the c = 0 route's K* (three phase levels) on 150 random loops, resonant ones
    included (1e-12 relative: both solve the same level equation by Newton), as one interval."""
    rng = np.random.default_rng(1)
    for i in range(150):
        tau = float(rng.uniform(0.0, 4.0)) if i % 7 else 0.0
        k = float(np.exp(rng.uniform(np.log(0.05), np.log(400.0)))) / max(tau, 0.05)
        T = float(np.exp(rng.uniform(np.log(0.001), np.log(50.0))))
        interval = kb_heading_interval(tau, T, k, 0.0)
        assert interval.gain == pytest.approx(float(kb_critical_gain(tau, T, k)[0]), rel=1e-12)
        assert interval.intervals == ((0.0, interval.gain),)


def test_reference_roots_with_and_without_a_heading_term():
    """Values computed independently for the issue, 4 decimals: CARMEL (τ = 0.3 s, T = 0.065 s,
    k = 2 1/s) with N_KB·V = 2.6 1/s, without the heading term (c = 0, NV = 2.6) and with
    q = 0.5 of the force along the velocity (c = q/(1 − q) = 1, NV = 2.6/(1 − q) = 5.2): rightmost
    roots −0.0413 ± 2.2959j (stable) and +0.0512 ± 3.3545j (unstable). Tolerance: half a unit in
    the 4th decimal. Without delay both are stable (τN_KB·V < 1: (1 + c)/τ scales with NV)."""
    model = ExactDelay()
    without = model.rightmost_root(2.6, Loop(0.3, 0.065, 2.0))
    with_term = model.rightmost_root(5.2, Loop(0.3, 0.065, 2.0, c=1.0))
    assert abs(without - complex(-0.0413, 2.2959)) < 5e-5
    assert abs(with_term - complex(0.0512, 3.3545)) < 5e-5
    assert model.is_stable(2.6, Loop(0.3, 0.065, 2.0)) and not model.is_stable(5.2, Loop(0.3, 0.065, 2.0, c=1.0))
    assert Continuous().is_stable(5.2, Loop(0.3, 0.065, 2.0, c=1.0))


@pytest.mark.parametrize("tau, T, k, c", _heading_loops(6, seed=8))
def test_pade_converges_to_exact_delay_with_heading(tau, T, k, c):
    """Padé(m, m) of e^(−sT) in k(cs + NV)e^(−sT): NV* → exact_delay's as m grows (1e-8 at m = 10,
    Padé's error is O((sT)^(2m+1)))."""
    loop = Loop(tau, T, k, c=c)
    exact = ExactDelay().boundary(loop).NV_critical
    if exact == 0:
        assert Pade(10).boundary(loop).NV_critical == 0
        return
    assert Pade(10).boundary(loop).NV_critical == pytest.approx(exact, rel=1e-8)


# ---------------------------------------------------------------------------------------------
# sampled against a closed-loop matrix built here
# ---------------------------------------------------------------------------------------------
def _independent_poles(tau, T, k, c, NV, hold, delay):
    """Poles of the sampled loop from its physics, with scipy's expm: steering motor τω̇ + ω = u,
    θ̇ = ω, ẏ = θ (y = x/V); the computer samples θ and y and computes δ_k = −NV/k·... i.e.
    δ_k = −(K/k)y_k − cθ_k; `command` holds u_k = k(δ_k − θ_k), `reference` holds δ_k and the
    servo closes u = k(δ_k − θ(t)); a compute delay stores the value one period."""
    K = k * NV
    if tau > 0:
        A = np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, 1, 0]]) if hold == "command" else np.array([[-1 / tau, -k / tau, 0], [1, 0, 0], [0, 1, 0]])
        B = np.array([1 / tau, 0, 0]) if hold == "command" else np.array([k / tau, 0, 0])
    else:
        A = np.array([[0.0, 0], [1, 0]]) if hold == "command" else np.array([[-k, 0.0], [1, 0]])
        B = np.array([1.0, 0]) if hold == "command" else np.array([k, 0.0])
    theta, y = len(B) - 2, len(B) - 1
    law = np.zeros(len(B))
    if hold == "command":
        law[theta], law[y] = -k * (1 + c), -K
    else:
        law[theta], law[y] = -c, -K / k
    n = len(B)
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, B
    E = expm(M * T)
    Phi, Gamma = E[:n, :n], E[:n, n]
    if delay == 0:
        return np.linalg.eigvals(Phi + np.outer(Gamma, law))
    return np.linalg.eigvals(np.block([[Phi, Gamma[:, None]], [law[None, :], np.zeros((1, 1))]]))


SAMPLED_SETS = _heading_loops(10, seed=12) + [(0.3, 1e-4, 2.0, 0.5), (0.3, 5.0, 0.5, -0.99), (0.3, 0.065, 2.0, 100.0), (0.0, 0.1, 2.0, -0.5)]


@pytest.mark.parametrize("hold, delay", STRUCTURES)
def test_sampled_against_an_independent_closed_loop_matrix(hold, delay):
    """14 loops (c < 0 and c > 0, T from 1e-4 to 5 s, c = −0.99 and 100) × 4 structures:
    * verdicts: the model's (δ-form eigenvalues) = spectral radius < 1 of the matrix built here
      (points with |ρ − 1| < 1e-9 skipped: rounding decides there);
    * every finite edge of the stable set: ρ = 1 there to 1e-9 and ρ < 1 / > 1 on the stable /
      unstable side (±1e-6 relative): the unit-circle crossings are where the poles are;
    * the rightmost root σ + jω = ln z/T of the dominant pole, to 1e-7·max(1, |s|) (ln of poles
      from two different exponentials; T = 1e-4 amplifies their 1e-12 by 1/T)."""
    model = Sampled(hold, delay)
    rng = np.random.default_rng(3)
    for tau, T, k, c in SAMPLED_SETS:
        loop = Loop(tau, T, k, c=c)
        boundary = model.boundary(loop)
        for NV in rng.uniform(0.05, 3.0, 3) * (1 + abs(c)) / (tau + T + 0.05):
            poles = _independent_poles(loop.tau, T, k, c, NV, hold, delay)
            rho = np.max(np.abs(poles))
            if abs(rho - 1) > 1e-9:
                assert model.is_stable(NV, loop) == (rho < 1)
            z = poles[np.argmax(np.abs(poles))]
            s = model.rightmost_root(NV, loop)
            assert abs(s - complex(math.log(abs(z)) / T, abs(np.angle(z)) / T)) < 1e-7 * max(1.0, abs(s))
        for lo, hi in boundary.stable_set:
            for edge, inside in ((lo, 1 + 1e-6), (hi, 1 - 1e-6)):
                if 0 < edge < math.inf:
                    assert np.max(np.abs(_independent_poles(loop.tau, T, k, c, edge, hold, delay))) == pytest.approx(1.0, abs=1e-9)
                    assert np.max(np.abs(_independent_poles(loop.tau, T, k, c, edge * inside, hold, delay))) < 1
                    assert np.max(np.abs(_independent_poles(loop.tau, T, k, c, edge * (2 - inside), hold, delay))) > 1


@pytest.mark.parametrize("hold, delay", STRUCTURES)
def test_sampled_with_heading_tends_to_continuous(hold, delay):
    """T → 0: every structure's NV* → (1 + c)/τ (0.1 % at T = 1e-5 s: the error is O(T/τ));
    T = 0 is the continuous loop exactly."""
    for c in (-0.5, 2.0):
        assert Sampled(hold, delay).boundary(Loop(0.3, 1e-5, 2.0, c=c)).NV_critical == pytest.approx((1 + c) / 0.3, rel=1e-3)
        assert Sampled(hold, delay).boundary(Loop(0.3, 0.0, 2.0, c=c)).NV_critical == Continuous().boundary(Loop(0.3, 0.0, 2.0, c=c)).NV_critical


# ---------------------------------------------------------------------------------------------
# every model: verdicts, margins, T* and k* with c
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, options", ALL_MODELS, ids=lambda x: x if isinstance(x, str) else "-".join(map(str, x.values())))
def test_every_model_flips_at_its_boundary_and_margins_hold(name, options):
    """4 loops with c in (−0.99, 3) (at least 3 with a finite NV* > 0 in each model): stable at
    0.999 NV*, unstable at 1.001 NV* (the model's own
    independent verdict), the rightmost root at NV* on the axis at ω* (1e-6); at 0.7 NV*, T* and k*
    as the definitions say: stable at (1 − 1e-5)·T*, unstable at (1 + 1e-5)·T* (the searches stop
    at 1e-7 relative), the same for k*."""
    model = make_model(name, **options)
    checked = 0
    for tau, T, k, c in [(0.3, 0.065, 2.0, 0.5), (0.87, 0.15, 2.5, 2.1), (0.05, 0.22, 1.6, -0.65), (0.49, 0.4, 0.6, -0.66)]:
        loop = Loop(tau, T, k, c=c)
        b = model.boundary(loop)
        if not 0 < b.NV_critical < math.inf:  # e.g. command hold, compute delay 1, kcT large: unstable at any NV
            assert not model.is_stable(1e-3, loop)
            continue
        checked += 1
        assert model.is_stable(0.999 * b.NV_critical, loop) and not model.is_stable(1.001 * b.NV_critical, loop)
        root = model.rightmost_root(b.NV_critical, loop)
        assert abs(root.real) < 1e-6 * max(1.0, abs(root.imag)) and abs(abs(root.imag) - b.omega_critical) < 1e-6 * b.omega_critical
        NV = 0.7 * b.NV_critical
        T_star, k_star = model.critical_delay(NV, loop), model.critical_gain_k(NV, loop)
        if name != "continuous":
            assert 0 < T_star < 100
            assert model.is_stable(NV, Loop(tau, T_star * (1 - 1e-5), k, c=c)) and not model.is_stable(NV, Loop(tau, T_star * (1 + 1e-5), k, c=c))
        if 0 < k_star < 1e4:
            assert model.is_stable(NV, Loop(tau, T, k_star * (1 - 1e-5), c=c)) and not model.is_stable(NV, Loop(tau, T, k_star * (1 + 1e-5), c=c))
        else:
            assert k_star == math.inf and all(model.is_stable(NV, Loop(tau, T, g, c=c)) for g in np.geomspace(k / 100, 1e4, 9))
    assert checked >= 3


# ---------------------------------------------------------------------------------------------
# N < 0
# ---------------------------------------------------------------------------------------------
NEGATIVE_LOOPS = [(0.3, 0.065, 2.0, 0.0), (0.3, 0.065, 2.0, 1.0), (0.0, 0.1, 2.0, -0.5), (0.3, 0.0, 2.0, 0.3), (1.2, 0.5, 6.0, 20.0)]
"""The last is unstable at every NV > 0 too (kcT = 60): there an oscillating pair is further right than the real root."""


def _real_root(tau, T, k, c, K):
    """The real root s > 0 of τs³ + s² + ks + (kcs + K)e^(−sT) for K < 0 (bracketed by brentq: the
    function is K < 0 at 0 and positive for large s)."""
    f = lambda s: tau * s**3 + s**2 + k * s + (k * c * s + K) * math.exp(-s * T)  # noqa: E731
    hi = 1.0
    while f(hi) <= 0:
        hi *= 2
    return brentq(f, 0.0, hi, xtol=1e-300, rtol=1e-13)


def _divergent_rate(model, NV, loop):
    """Growth rate (1/s) of the model's largest real root s > 0 (sampled: real pole z > 1, ln z/T)."""
    if model.name == "exact_delay":
        return _real_root(loop.tau, loop.T, loop.k, loop.c, loop.k * NV)
    roots = model.roots(NV, loop)
    real = roots[np.abs(roots.imag) <= 1e-9 * np.maximum(1.0, np.abs(roots))].real
    if model.name == "sampled" and loop.T > 0:
        return float(np.log(real.max()) / loop.T)
    return float(real.max())


@pytest.mark.parametrize("name, options", ALL_MODELS, ids=lambda x: x if isinstance(x, str) else "-".join(map(str, x.values())))
@pytest.mark.parametrize("tau, T, k, c", NEGATIVE_LOOPS)
def test_negative_N_diverges_in_every_model(name, options, tau, T, k, c):
    """NV < 0 (N < 0: the field pushes away from the equilibrium), from −1e-6 to −1e6 1/s: every
    model has a real root s > 0 (z > 1: found here from its characteristic function, by
    bracketing for exact_delay), is unstable, reports a rightmost root at least that far right
    (1e-6·max(1, s): the roots' own polishing is ~1e-10) and real (|ω| < 1e-9) unless the loop also
    oscillates at every NV, T* = k* = 0, margin −1, verdict "unstable", the divergent reason;
    nothing is NaN."""
    model = make_model(name, **options)
    loop = Loop(tau, T, k, c=c)
    boundary = model.boundary(loop)
    for NV in (-1e-6, -0.7, -1e6):
        stable = model.is_stable(NV, loop)
        root = model.rightmost_root(NV, loop)
        rate = _divergent_rate(model, NV, loop)
        assert not stable and rate > 0 and root is not None and math.isfinite(root.real) and math.isfinite(root.imag)
        assert root.real >= rate - 1e-6 * max(1.0, rate)
        if boundary.stable_set:
            assert abs(root.imag) < 1e-9
        assert model.critical_delay(NV, loop) == 0.0 and model.critical_gain_k(NV, loop) == 0.0
        assert gain_margin(NV, boundary, stable) == -1.0 and verdict_label(NV, boundary, stable) == "unstable"
        assert divergent_reason(NV) == DIVERGENT_REASON and "N < 0" in DIVERGENT_REASON
    assert divergent_reason(0.7) is None


def test_negative_gain_in_the_vectorized_count_and_delay_loop():
    """K < 0 in the array count: Z odd (one real root plus crossing pairs), unstable, delay margin 0;
    the generic `DelayLoop` count agrees on 2000 random points with and without c, and cxroots counts
    the same right-half-plane roots on one."""
    rng = np.random.default_rng(4)
    n = 2000
    tau, T, k = rng.uniform(0, 2, n), rng.uniform(0, 2, n), rng.uniform(0.2, 10, n)
    K = -np.exp(rng.uniform(np.log(1e-3), np.log(1e3), n))
    c = np.where(np.arange(n) % 2, 0.0, rng.uniform(-0.99, 5, n))
    for heading in ((), (c,)):
        stable, Z, margin = delay_verdicts_from_gain(tau, T, k, K, *heading)
        assert not stable.any() and np.all(Z % 2 == 1) and np.all(margin == 0)
        cc = heading[0] if heading else np.zeros(n)
        assert all(_delay_loop(tau[i], T[i], k[i], cc[i]).unstable_root_count(K[i]) == Z[i] for i in range(0, n, 10))
    roots = _cxroots_roots(0.3, 0.5, 2.0, 1.0, -3.0, ([-0.3, 10.0], [-10.0, 10.0]))
    assert int(np.sum(roots.real > 0)) == _count(0.3, 0.5, 2.0, 1.0, -3.0)


def test_model_names_cover_every_model():
    """The models exercised above are all of them."""
    assert {name for name, _ in ALL_MODELS} == set(MODEL_NAMES)
