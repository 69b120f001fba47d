"""N = 0, no restoring force: every loop model judges its heading loop (docs/models.md, "N = 0").

At N = 0 the characteristic function of every model is s·D1(s) (a pole at z = 1 for `sampled`):
the lateral root is neutral, and the verdict, the dominant root, T* and k* are those of D1, the
heading loop, which can be unstable by itself. Every expected value below comes from a route
written here, never from the code under test:

* `continuous`, `kb_first_order`, `pade`: numpy roots of D1 written out (the Padé coefficients
  from scipy's `pade` of the Taylor series of e^(−x));
* `exact_delay`: QPmR (spectral mapping) and cxroots (argument principle) on the quasi-polynomial
  τs² + s + k + kc·e^(−sT);
* `sampled`: the closed-loop matrix at K = 0 built from the loop's physics with scipy's `expm`:
  one eigenvalue is 1 (the lateral mode), the others decide;
* T* and k*: the oracle's verdict just below and above them, and on a scan below (the first loss).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from cli_helpers import report_json, run
from scipy.interpolate import pade as scipy_pade
from scipy.linalg import expm

from pfm_stability.maps.analysis import sample_verdict
from pfm_stability.maps.deciding.verdicts import GrowthRate
from pfm_stability.models import NEUTRAL_REASON, Loop, gain_margin, make_model, neutral_reason, verdict_label
from pfm_stability.vectorized import loop_verdicts

STRUCTURES = [(h, d) for h in ("command", "reference") for d in (0, 1)]
ALL_MODELS = [("continuous", {}), ("kb_first_order", {}), ("pade", {"pade_order": 3}), ("exact_delay", {})] + [
    ("sampled", {"hold": h, "compute_delay": d}) for h, d in STRUCTURES
]
ISSUE = (0.5, 0.09, 8.6)
"""τ (s), T (s), k (1/s) of the Khatib corridor beyond ρ0 (N = 0, c = 0) whose sampled loop, command held one
sample late, oscillates by itself: poles 1, −0.0608, 0.948 ± 0.343j at K = 0."""


def _loops(count, seed, *, tau=(0.05, 1.5), T=(0.005, 1.0), k=(0.3, 12.0), c=(-0.99, 20.0)):
    """Seeded random (τ, T, k, c): log-uniform τ, T, k; c uniform; τ = 0 on every fifth, c = 0 on every fourth."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        t = 0.0 if i % 5 == 4 else float(np.exp(rng.uniform(*np.log(tau))))
        c_i = 0.0 if i % 4 == 3 else float(rng.uniform(*c))
        out.append((t, float(np.exp(rng.uniform(*np.log(T)))), float(np.exp(rng.uniform(*np.log(k)))), c_i))
    return out


# ---------------------------------------------------------------------------------------------
# oracles
# ---------------------------------------------------------------------------------------------
def _closed_loop_poles(tau, T, k, c, hold, delay):
    """Every pole of the sampled loop at K = 0 from its physics, with scipy's expm: steering motor τω̇ + ω = u,
    θ̇ = ω, ẏ = θ; the computer samples θ and computes δ_k = −cθ_k (N = 0: no y term); `command` holds
    u_k = k(δ_k − θ_k), `reference` holds δ_k and the servo closes u = k(δ_k − θ(t)); a compute delay
    stores the value one period."""
    if tau > 0:
        A = np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, 1, 0]]) if hold == "command" else np.array([[-1 / tau, -k / tau, 0], [1, 0, 0], [0, 1, 0]])
        B = np.array([1 / tau, 0, 0]) if hold == "command" else np.array([k / tau, 0, 0])
    else:
        A = np.array([[0.0, 0], [1, 0]]) if hold == "command" else np.array([[-k, 0.0], [1, 0]])
        B = np.array([1.0, 0]) if hold == "command" else np.array([k, 0.0])
    n = len(B)
    law = np.zeros(n)
    law[n - 2] = -k * (1 + c) if hold == "command" else -c
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, B
    E = expm(M * T)
    Phi, Gamma = E[:n, :n], E[:n, n]
    if delay == 0:
        return np.linalg.eigvals(Phi + np.outer(Gamma, law))
    return np.linalg.eigvals(np.block([[Phi, Gamma[:, None]], [law[None, :], np.zeros((1, 1))]]))


def _heading_poles(tau, T, k, c, hold, delay):
    """The sampled poles without the lateral one: the pole nearest 1 is removed after checking it is 1 (to 1e-9)."""
    poles = _closed_loop_poles(tau, T, k, c, hold, delay)
    i = int(np.argmin(np.abs(poles - 1.0)))
    assert abs(poles[i] - 1.0) < 1e-9, poles
    return np.delete(poles, i)


def _pade(T, m):
    """Padé(m, m) of e^(−sT) by scipy's `pade` from the Taylor coefficients of e^(−x), x = sT: (num, den) in s, descending."""
    p, q = scipy_pade([(-1.0) ** j / math.factorial(j) for j in range(2 * m + 1)], m)
    scale = T ** np.arange(m, -1, -1)  # x^i = T^i s^i
    return np.asarray(p.coeffs) * scale, np.asarray(q.coeffs) * scale


def _heading_polynomial(name, tau, T, k, c, order=3):
    """D1 = D/s written out: the continuous, first-order and Padé heading loops (descending)."""
    if name == "continuous":
        return np.array([tau, 1.0, k * (1 + c)])
    if name == "kb_first_order":
        return np.array([tau, 1.0 - k * c * T, k * (1 + c)])
    num, den = _pade(T, order)
    return np.polyadd(np.polymul([tau, 1.0, k], den), k * c * num)


def _rhp_radius(tau, k, c):
    """Every root of τs² + s + k + kc·e^(−sT) with Re s >= 0 has |τs² + s + k| <= |kc|, so |s| < R."""
    return (1.0 + math.sqrt(1.0 + 4.0 * tau * k * (1 + abs(c)))) / (2.0 * tau) + 1.0 if tau > 0 else k * (1 + abs(c)) + 1.0


def _qpmr_heading_roots(tau, T, k, c, left, R):
    """QPmR's roots of τs² + s + k + kc·e^(−sT) in [left, R] × [−R, R] (grid step R/200 at most 0.05, polished to 1e-10)."""
    qpmr = pytest.importorskip("qpmr")
    coefficients = np.array([[k, 1.0, tau], [k * c, 0.0, 0.0]]) if tau > 0 else np.array([[k, 1.0], [k * c, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        roots, _ = qpmr.qpmr(coefficients, np.array([0.0, T]), region=[left, R, -R, R], e=1e-10, ds=min(0.05, R / 200))
    return roots


def _cxroots_heading_roots(tau, T, k, c, box):
    """The argument principle's roots of τs² + s + k + kc·e^(−sT) in a rectangle (cxroots)."""
    cxroots = pytest.importorskip("cxroots")

    def f(s):
        return tau * s**2 + s + k + k * c * np.exp(-s * T)

    def df(s):
        return 2 * tau * s + 1 - T * k * c * np.exp(-s * T)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.array(cxroots.Rectangle(*box).roots(f, df).roots)


def _exact_heading_unstable(tau, T, k, c):
    """Right-half-plane roots of τs² + s + k + kc·e^(−sT) by QPmR (the whole disc |s| < R holding them)."""
    R = _rhp_radius(tau, k, c)
    return int(np.sum(_qpmr_heading_roots(tau, T, k, c, -0.5, R).real > 0))


def _oracle_stable(name, options, tau, T, k, c):
    """The heading loop's verdict by this module's own route for `name`."""
    if name == "sampled":
        if T == 0:
            return bool(np.all(np.roots(_heading_polynomial("continuous", tau, T, k, c)).real < 0))
        return bool(np.max(np.abs(_heading_poles(tau, T, k, c, options["hold"], options["compute_delay"]))) < 1)
    if name == "exact_delay":
        return _exact_heading_unstable(tau, T, k, c) == 0
    p = np.trim_zeros(_heading_polynomial(name, tau, T, k, c, options.get("pade_order", 3)), "f")
    return bool(np.all(np.roots(p).real < 0))


# ---------------------------------------------------------------------------------------------
# the issue's point, the sampled loop and the polynomial models
# ---------------------------------------------------------------------------------------------
def test_issue_point_sampled_command_held_one_sample_late():
    """τ = 0.5 s, T = 0.09 s, k = 8.6 1/s, c = 0, command held, compute delay 1, N = 0: the closed-loop matrix
    built here has the poles the issue gives, 1, −0.0608, 0.948 ± 0.343j (3 digits, as quoted), |z| = 1.008;
    the model says unstable, its rightmost root is ln z/T of that pair (1e-9: two exponentials agree to
    round-off), its margin −1 and T*, k* are where the oracle's heading loop changes verdict (±1e-6)."""
    tau, T, k = ISSUE
    poles = _closed_loop_poles(tau, T, k, 0.0, "command", 1)
    expected = np.array([1.0, -0.0608, 0.948 + 0.343j, 0.948 - 0.343j])
    assert np.allclose(np.sort_complex(poles), np.sort_complex(expected), atol=5e-4)
    heading = _heading_poles(tau, T, k, 0.0, "command", 1)
    z = heading[np.argmax(np.abs(heading))]
    assert abs(z) == pytest.approx(1.008, abs=5e-4)
    model, loop = make_model("sampled", hold="command", compute_delay=1), Loop(tau, T, k)
    assert not model.is_stable(0.0, loop)
    root = model.rightmost_root(0.0, loop)
    assert root.real == pytest.approx(math.log(abs(z)) / T, rel=1e-9) and root.imag == pytest.approx(abs(np.angle(z)) / T, rel=1e-9)
    assert verdict_label(0.0, model.boundary(loop), False) == "unstable" and gain_margin(0.0, model.boundary(loop), False) == -1.0
    T_star, k_star = model.critical_delay(0.0, loop), model.critical_gain_k(0.0, loop)
    assert 0 < T_star < T and 0 < k_star < k
    heading_rho = lambda t, g: np.max(np.abs(_heading_poles(tau, t, g, 0.0, "command", 1)))  # noqa: E731
    assert heading_rho(T_star * (1 - 1e-6), k) < 1 < heading_rho(T_star * (1 + 1e-6), k)
    assert heading_rho(T, k_star * (1 - 1e-6)) < 1 < heading_rho(T, k_star * (1 + 1e-6))
    assert all(heading_rho(t, k) < 1 for t in np.linspace(1e-4, 1 - 1e-5, 60) * T_star)  # the first loss


@pytest.mark.parametrize("hold, delay", STRUCTURES)
def test_sampled_at_N0_against_an_independent_closed_loop_matrix(hold, delay):
    """16 seeded loops (τ = 0 on every fifth, c from −0.99 to 20, T from 5 ms to 1 s) plus extremes
    (T = 1e-4 s and 5 s, c = −0.99 and 100, k = 30): the matrix built here has a pole at 1 (to 1e-9) and the
    model's verdict at NV = 0 is that the other poles lie inside the unit circle (points with |ρ − 1| < 1e-9
    skipped: rounding decides); the rightmost root is ln z/T of the dominant one (1e-7·max(1, |s|), as for
    N ≠ 0: two exponentials, amplified by 1/T at T = 1e-4). Both verdicts occur over the set (command hold)."""
    model = make_model("sampled", hold=hold, compute_delay=delay)
    loops = _loops(16, seed=31) + [(0.3, 1e-4, 2.0, 0.5), (0.3, 5.0, 0.5, -0.99), (0.3, 0.065, 2.0, 100.0), (0.0, 0.1, 30.0, 0.0)]
    verdicts = set()
    for tau, T, k, c in loops:
        loop = Loop(tau, T, k, c=c)
        heading = _heading_poles(loop.tau, loop.T, k, c, hold, delay)
        rho = np.max(np.abs(heading))
        if abs(rho - 1) > 1e-9:
            assert model.is_stable(0.0, loop) == (rho < 1), (tau, T, k, c, rho)
            verdicts.add(bool(rho < 1))
        z = heading[np.argmax(np.abs(heading))]
        s = complex(math.log(abs(z)) / T, abs(np.angle(z)) / T)
        root = model.rightmost_root(0.0, loop)
        assert abs(root.real - s.real) <= 1e-7 * max(1.0, abs(s)), (tau, T, k, c)
    if hold == "command":
        assert verdicts == {True, False}


@pytest.mark.parametrize("name", ["continuous", "kb_first_order", "pade"])
def test_polynomial_models_at_N0_against_numpy_roots(name):
    """20 seeded loops plus extremes (c = −0.99 and 100, kcT = 1.7, τ = 0 with kcT = 1 exactly, T = 0): the
    verdict at NV = 0 is whether numpy's roots of D1 = D/s written out (Padé from scipy) lie in
    Re s < 0, and the rightmost root is theirs (1e-8·max(1, |s|): companion eigenvalues either way); a
    constant D1 (kcT = 1, τ = 0) has no root: stable, −inf. `continuous` is always stable (1 + c > 0)."""
    model = make_model(name)
    loops = _loops(20, seed=7) + [(0.3, 0.065, 2.0, -0.99), (0.3, 0.065, 2.0, 100.0), (0.3, 0.065, 2.0, 12.9), (0.0, 1.0, 2.0, 0.5), (0.4, 0.0, 3.0, 5.0)]
    verdicts = set()
    for tau, T, k, c in loops:
        loop = Loop(tau, T, k, c=c)
        roots = np.roots(np.trim_zeros(_heading_polynomial(name, tau, T, k, c), "f"))
        stable = bool(np.all(roots.real < 0))
        assert model.is_stable(0.0, loop) == stable, (tau, T, k, c)
        verdicts.add(stable)
        root = model.rightmost_root(0.0, loop)
        if roots.size == 0:
            assert root.real == -math.inf
        else:
            top = roots[np.argmax(roots.real)]
            assert abs(root.real - top.real) <= 1e-8 * max(1.0, abs(top))
    assert verdicts == ({True} if name == "continuous" else {True, False})


@pytest.mark.parametrize("name", ["kb_first_order", "pade", "sampled"])
def test_critical_delay_and_gain_at_N0_are_the_heading_loops(name):
    """T* and k* at NV = 0 (c = 5: the heading term destabilizes with delay; c = 0 and the command held for
    `sampled`): the oracle's heading loop (numpy roots of D1, or the expm matrix) is stable at T*(1 − 1e-6) and
    on a scan of 40 periods below, unstable at T*(1 + 1e-6); the same for k*. `kb_first_order` has the closed
    forms T* = 1/(kc), k* = 1/(cT) of its s¹ coefficient 1 − kcT (1e-12)."""
    tau, T, k, c = (0.3, 0.065, 2.0, 5.0) if name != "sampled" else (*ISSUE, 0.0)
    options = {"hold": "command", "compute_delay": 1} if name == "sampled" else {}
    model, loop = make_model(name, **options), Loop(tau, T, k, c=c)

    def stable(t, g):
        return _oracle_stable(name, options, tau, t, g, c)

    T_star, k_star = model.critical_delay(0.0, loop), model.critical_gain_k(0.0, loop)
    assert stable(T_star * (1 - 1e-6), k) and not stable(T_star * (1 + 1e-6), k)
    assert all(stable(t, k) for t in np.geomspace(1e-3, 1 - 1e-5, 40) * T_star)
    assert stable(T, k_star * (1 - 1e-6)) and not stable(T, k_star * (1 + 1e-6))
    if name == "kb_first_order":
        assert T_star == pytest.approx(1 / (k * c), rel=1e-12) and k_star == pytest.approx(1 / (c * T), rel=1e-12)


def test_a_stable_heading_loop_has_no_finite_T_or_k_where_it_stays_stable():
    """c = 0: `continuous`, `kb_first_order`, `pade` and `exact_delay` have the heading loop τs² + s + k (times
    the Padé denominator, Hurwitz), stable at every T and k: T* = k* = inf, verdict stable, margin inf. The
    oracle: numpy roots of τs² + s + k at the largest T and k allowed (100 s, 10⁴ 1/s) and QPmR's count there."""
    tau, T, k = 0.3, 0.065, 2.0
    assert np.all(np.roots([tau, 1.0, 1e4]).real < 0) and _exact_heading_unstable(tau, 100.0, k, 0.0) == 0
    for name in ("continuous", "kb_first_order", "pade", "exact_delay"):
        model, loop = make_model(name), Loop(tau, T, k)
        assert model.is_stable(0.0, loop)
        assert model.critical_delay(0.0, loop) == math.inf and model.critical_gain_k(0.0, loop) == math.inf
        assert gain_margin(0.0, model.boundary(loop), True) == math.inf


# ---------------------------------------------------------------------------------------------
# exact_delay against root finders
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("tau, T, k, c", _loops(12, seed=19, tau=(0.1, 1.5), c=(-0.99, 12.0)))
def test_exact_delay_at_N0_against_qpmr(tau, T, k, c):
    """12 seeded loops (τ = 0 on every fifth, c from −0.99 to 12): QPmR's roots of τs² + s + k + kc·e^(−sT) in a
    rectangle holding the disc |s| < R of every right-half-plane root give the verdict at NV = 0 and the
    crossing count (an integer: equal), and the rightmost root agrees to 1e-6 (QPmR polishes to ~1e-10;
    the pseudospectral roots are Newton-polished: 1e-6 as for N ≠ 0)."""
    model, loop = make_model("exact_delay"), Loop(tau, T, k, c=c)
    ours = model.rightmost_root(0.0, loop)
    R = max(_rhp_radius(tau, k, c), abs(ours.imag) + 1.0)
    roots = _qpmr_heading_roots(tau, T, k, c, min(ours.real - 1.0, -0.5), R)
    unstable = int(np.sum(roots.real > 0))
    assert model.unstable_root_count(0.0, loop) == unstable
    assert model.is_stable(0.0, loop) == (unstable == 0)
    theirs = roots[np.argmax(roots.real)]
    assert abs(ours.real - theirs.real) < 1e-6 and abs(abs(ours.imag) - abs(theirs.imag)) < 1e-6


EXTREMES = [
    (0.3, 0.065, 2.0, 12.9, "cxroots"),  # the velocity-attraction corridor: kcT = 1.68
    (0.3, 0.065, 2.0, 100.0, "qpmr"),  # the largest c
    (0.3, 5.0, 2.0, -0.99, "qpmr"),  # the smallest c, a long delay: eleven roots in view
    (0.0, 0.4, 3.0, 4.0, "cxroots"),  # τ = 0, c > 1
    (1.0, 0.4, 6.0, 0.5, "cxroots"),  # kτ = 6: the steering loop resonates
    (0.01, 0.02, 50.0, -0.9, "cxroots"),  # small τ, large k, c near −1
]


@pytest.mark.parametrize("tau, T, k, c, finder", EXTREMES)
def test_exact_delay_at_N0_extremes_against_root_finders(tau, T, k, c, finder):
    """Extremes: the argument principle (cxroots) or QPmR in a rectangle holding every right-half-plane root of
    τs² + s + k + kc·e^(−sT) counts what the model counts, decides its verdict at NV = 0, and has its rightmost
    root (1e-6); where the heading loop is unstable T* is below T and the count changes at T*(1 ± 1e-6)."""
    model, loop = make_model("exact_delay"), Loop(tau, T, k, c=c)
    ours = model.rightmost_root(0.0, loop)
    R = max(_rhp_radius(tau, k, c), abs(ours.imag) + 1.0)
    left = min(ours.real - 1.0, -0.3)
    roots = _cxroots_heading_roots(tau, T, k, c, ([left, R], [-R, R])) if finder == "cxroots" else _qpmr_heading_roots(tau, T, k, c, left, R)
    unstable = int(np.sum(roots.real > 0))
    assert model.unstable_root_count(0.0, loop) == unstable and model.is_stable(0.0, loop) == (unstable == 0)
    theirs = roots[np.argmax(roots.real)]
    assert abs(ours.real - theirs.real) < 1e-6
    T_star = model.critical_delay(0.0, loop)
    if unstable:
        assert _exact_heading_unstable(tau, T_star * (1 - 1e-6), k, c) == 0 < _exact_heading_unstable(tau, T_star * (1 + 1e-6), k, c)


def test_exact_delay_k_star_at_N0():
    """k* at NV = 0 with c = 12.9 (the velocity-attraction corridor): QPmR's heading loop is stable at k*(1 − 1e-6)
    and on a scan below, unstable at k*(1 + 1e-6)."""
    tau, T, c = 0.3, 0.065, 12.9
    k_star = make_model("exact_delay").critical_gain_k(0.0, Loop(tau, T, 2.0, c=c))
    assert _exact_heading_unstable(tau, T, k_star * (1 + 1e-6), c) > 0
    assert all(_exact_heading_unstable(tau, T, g, c) == 0 for g in [*np.geomspace(1e-3, 0.9, 4) * k_star, k_star * (1 - 1e-6)])


# ---------------------------------------------------------------------------------------------
# one rule: NV* and the vectorized verdicts agree with it
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, options", ALL_MODELS, ids=[f"{n}-{o}" for n, o in ALL_MODELS])
def test_vectorized_verdicts_at_N0_equal_the_scalar_models(name, options):
    """36 seeded loops (τ = 0, c = 0 among them): `loop_verdicts` at NV = 0, with every column and verdict-only,
    gives each point the scalar model's `is_stable(0, loop)`, "stable"/"unstable" and margin inf/−1; and the
    verdict agrees with NV* as docs/models.md says: stable at NV = 0 exactly when the stable set starts at 0
    with NV* > 0 and the model is stable at NV = 10⁻⁷·min(1, NV*) (the neutral root moves left as NV → 0+)."""
    loops = _loops(36, seed=23, T=(0.002, 0.6), k=(0.2, 30.0), c=(-0.99, 30.0))
    tau, T, k, c = (np.array(x) for x in zip(*loops))
    every = loop_verdicts(name, tau, T, k, 0.0, c=c, **options)
    fast = loop_verdicts(name, tau, T, k, np.zeros(tau.size), c=c, columns="verdict", **options)
    model = make_model(name, **options)
    for i, (t, d, g, h) in enumerate(loops):
        loop = Loop(t, d, g, c=h)
        stable = model.is_stable(0.0, loop)
        assert every.stable[i] == fast.stable[i] == stable, (i, loops[i])
        assert every.verdict[i] == fast.verdict[i] == ("stable" if stable else "unstable")
        assert every.margin[i] == (math.inf if stable else -1.0)
        b = model.boundary(loop)
        assert stable == (bool(b.stable_set) and b.stable_set[0][0] == 0 and b.NV_critical > 0) == model.is_stable(1e-7 * min(1.0, b.NV_critical or 1.0), loop)


def test_neutral_reason_names_the_heading_loop_only_at_N0():
    """The reason of each verdict at NV = 0, and none elsewhere (N < 0 has its own)."""
    assert neutral_reason(0.0, True).endswith("the heading loop is stable")
    assert neutral_reason(0.0, False).endswith("the heading loop is unstable by itself")
    assert neutral_reason(0.0) == NEUTRAL_REASON
    assert neutral_reason(1e-300, True) is None and neutral_reason(-1.0, False) is None


# ---------------------------------------------------------------------------------------------
# the report, a sweep row, a map sample
# ---------------------------------------------------------------------------------------------
KHATIB = ["--law", "khatib", "--goal-distance", "1", "--rho0", "0.8", "--L", "1.0", "--tau", "0.5", "--T", "0.09", "--k", "8.6",
          "--hold", "command", "--compute-delay", "1", "--model", "sampled"]
VELOCITY = ["--law", "velocity", "--alpha-v", "0.58", "--rho0", "0.8", "--L", "1.0"]


def test_report_khatib_corridor_beyond_rho0_text_and_json():
    """`report --law khatib --goal-distance 1 --rho0 0.8 --L 1.0 --tau 0.5 --T 0.09 --k 8.6 --hold command
    --compute-delay 1 --model sampled` (N = 0): JSON unstable, margin −1, V* = 0, the rightmost root ln z/T of the
    matrix built here (1e-9), the heading reason, remedies in T and k only; the text says UNSTABLE with the reason
    (it said "stable", margin inf, before)."""
    data = report_json(KHATIB)
    assert data["environment"]["corridor"]["N"] == 0.0
    v = data["corridor"]["sampled"]
    heading = _heading_poles(*ISSUE, 0.0, "command", 1)
    z = heading[np.argmax(np.abs(heading))]
    assert v["verdict"] == "unstable" and v["stable"] is False and v["margin"] == -1.0 and v["V_critical"] == 0.0
    assert v["rightmost_root"]["sigma"] == pytest.approx(math.log(abs(z)) / ISSUE[1], rel=1e-9)
    assert v["reason"] == neutral_reason(0.0, False) and set(v["to_stabilize"]) == {"T", "k"}
    code, out, err = run(["report", *KHATIB])
    assert code == 0, err
    row = next(line for line in out.splitlines() if line.split()[:1] == ["sampled"] and "%" in line)
    assert row.split()[1] == "UNSTABLE" and "-100.0%" in row
    assert f"every model: unstable ({neutral_reason(0.0, False)})" in out


def test_report_velocity_attraction_corridor_text_and_json():
    """`report --law velocity --alpha-v 0.58 --rho0 0.8 --L 1.0` (N = 0, the heading gain c of the JSON, ≈ 12.9):
    each model's verdict is the oracle's for its heading loop — numpy roots for continuous, kb_first_order and
    pade, QPmR for exact_delay, the expm matrix for sampled (the report's hold and compute delay) — so only
    continuous is stable; stable margin inf, unstable −1; the text lists both reasons."""
    data = report_json(VELOCITY)
    env = data["environment"]["corridor"]
    assert env["N"] == 0.0 and env["c"] == pytest.approx(12.9, rel=1e-2)
    inputs = {key: entry["value"] for key, entry in data["inputs"].items()}
    tau, T, k, c = inputs["tau"], inputs["T"], inputs["k"], env["c"]
    options = {"hold": inputs["hold"], "compute_delay": inputs["compute_delay"], "pade_order": data["models"]["pade"]["order"]}
    for name, v in data["corridor"].items():
        expected = _oracle_stable(name, options, tau, T, k, c)
        assert v["stable"] is expected and v["verdict"] == ("stable" if expected else "unstable"), name
        assert v["margin"] == ("inf" if expected else -1.0) and v["reason"] == neutral_reason(0.0, expected)
    assert [n for n, v in data["corridor"].items() if v["stable"]] == ["continuous"]
    code, out, err = run(["report", *VELOCITY])
    assert code == 0, err
    assert f"kb_first_order, pade, exact_delay, sampled: unstable ({neutral_reason(0.0, False)})" in out
    assert f"continuous: stable ({neutral_reason(0.0, True)})" in out


SWEEP = """\
preset: carmel
law: {name: khatib, goal_distance: 1.0, rho0: 0.8}
scenario: {corridor: {L: 1.0}}
models: [sampled, exact_delay]
hold: command
compute_delay: 1
grid:
  tau: {from: 0.5, to: 0.5, num: 1}
  k: {from: 8.6, to: 8.6, num: 1}
  T: {from: 0.05, to: 0.09, num: 2}
"""


def test_sweep_rows_at_N0_are_the_heading_loops(tmp_path, capsys):
    """A Khatib corridor beyond ρ0 (N = 0) swept in T (spec in tmp_path, `pfm-stability sweep`): `sampled` is stable
    at T = 0.05 s and unstable at 0.09 s as the expm matrix built here says (it wrote "stable" for both before),
    margin inf/−1; `exact_delay` (c = 0: τs² + s + k) stable; the reason is the heading loop's."""
    pq = pytest.importorskip("pyarrow.parquet")
    spec, out = tmp_path / "spec.yaml", tmp_path / "t.parquet"
    spec.write_text(SWEEP)
    code, _, err = run(["sweep", str(spec), "--out", str(out), "--quiet"])
    assert code == 0, err
    table = pq.read_table(out).to_pydict()
    tau, _, k = ISSUE
    assert table["N"] == [0.0, 0.0]
    for i, T in enumerate(table["T"]):
        expected = bool(np.max(np.abs(_heading_poles(tau, T, k, 0.0, "command", 1))) < 1)
        assert table["sampled_stable"][i] is expected and table["sampled_verdict"][i] == ("stable" if expected else "unstable")
        assert table["sampled_margin"][i] == (math.inf if expected else -1.0)
        assert table["exact_delay_verdict"][i] == "stable" and table["reason"][i] == NEUTRAL_REASON
    assert table["sampled_verdict"] == ["stable", "unstable"]


def test_map_sample_with_N0_is_the_models_verdict_at_zero():
    """A map sample with N = 0 (`maps.analysis.sample_verdict`) takes the model's verdict at NV = 0: for the issue's
    loop (the expm matrix: unstable) V* = 0, margin −1 and the reason; for CARMEL's reference hold (stable) V* = inf,
    margin inf. The growth rate the map averages is 0 at N = 0 for a stable heading loop (the neutral root) and the
    heading loop's own σ = ln|z|/T (1e-9) when that grows."""
    model = make_model("sampled", hold="command", compute_delay=1)
    loop = Loop(*ISSUE)
    heading = _heading_poles(*ISSUE, 0.0, "command", 1)
    assert np.max(np.abs(heading)) > 1
    j = sample_verdict(0.0, 0.8, model.boundary(loop), model.is_stable(0.0, loop))
    assert (j.V_critical, j.margin, j.stable, j.verdict, j.reason) == (0.0, -1.0, False, "unstable", neutral_reason(0.0, False))
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), model.boundary(loop).NV_critical)
    assert float(growth(0.0)) == pytest.approx(math.log(np.max(np.abs(heading))) / ISSUE[1], rel=1e-9)
    stable_model, stable_loop = make_model("sampled", hold="reference"), Loop(0.3, 0.065, 2.0)
    assert np.max(np.abs(_heading_poles(0.3, 0.065, 2.0, 0.0, "reference", 0))) < 1
    boundary = stable_model.boundary(stable_loop)
    j = sample_verdict(0.0, 0.8, boundary, stable_model.is_stable(0.0, stable_loop))
    assert (j.V_critical, j.margin, j.stable, j.verdict) == (math.inf, math.inf, True, "stable")
    assert float(GrowthRate(lambda NV: stable_model.rightmost_root(NV, stable_loop), boundary.NV_critical)(0.0)) == 0.0

