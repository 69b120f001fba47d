"""`exact_delay` (KB eq 18) against independent root finders and its own identities.

Oracles: cxroots (BSD; argument principle + Newton in a rectangle) always, and
qpmr (GPL; Vyhlídal & Zítek's QPmR) when the test-only extra is installed.
"""

import math
import warnings

import numpy as np
import pytest

from conftest import random_loops
from pfm_stability.numerics.delay import DelayLoop
from pfm_stability.models import Continuous, ExactDelay, KBFirstOrder, Loop

cxroots = pytest.importorskip("cxroots")

ORACLE_SETS = random_loops(50, seed=11)


def _rhp_radius(tau, k, K):
    """Every root with Re s >= 0 has |a(s)| = K|e^(−sT)| <= K, so |s| < R with τR³ − R² − kR > K."""
    R = 1.0
    while tau * R**3 - R**2 - k * R <= K:
        R *= 1.5
    return R


def _cx_roots(tau, T, k, K, box):
    f = lambda s: tau * s**3 + s**2 + k * s + K * np.exp(-s * T)  # noqa: E731
    df = lambda s: 3 * tau * s**2 + 2 * s + k - K * T * np.exp(-s * T)  # noqa: E731
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.array(cxroots.Rectangle(*box).roots(f, df).roots)


@pytest.mark.parametrize("tau, T, k, K", ORACLE_SETS)
def test_rightmost_root_and_verdict_against_cxroots(tau, T, k, K):
    """Rightmost root to 1e-6 and verdict agreement on 50 random sets.

    cxroots searches a rectangle around our rightmost root that also contains
    the whole right half-plane disc |s| < R (so a missed unstable root would
    show); its Newton polishing is good to ~1e-10, hence 1e-6 absolute.
    """
    loop = DelayLoop([tau, 1.0, k, 0.0], T)
    ours = loop.rightmost_roots(K, count=1)[0]
    R = max(_rhp_radius(tau, k, K), abs(ours.imag) + 1.0)
    roots = _cx_roots(tau, T, k, K, ([ours.real - 1.0, R], [-R, R]))
    theirs = roots[np.argmax(roots.real)]
    assert abs(ours.real - theirs.real) < 1e-6
    assert abs(abs(ours.imag) - abs(theirs.imag)) < 1e-6
    assert loop.is_stable(K) == bool(np.all(roots.real < 0))
    assert loop.unstable_root_count(K) == int(np.sum(roots.real > 0))


@pytest.mark.parametrize("tau, T, k, K", ORACLE_SETS[:50])
def test_rightmost_root_against_qpmr(tau, T, k, K):
    """Same check with qpmr (GPL, test-only extra): rightmost root to 1e-6, verdict agrees."""
    qpmr = pytest.importorskip("qpmr")
    loop = DelayLoop([tau, 1.0, k, 0.0], T)
    ours = loop.rightmost_roots(K, count=1)[0]
    R = max(_rhp_radius(tau, k, K), abs(ours.imag) + 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        roots, _ = qpmr.qpmr(np.array([[0.0, k, 1.0, tau], [K, 0.0, 0.0, 0.0]]), np.array([0.0, T]), region=[ours.real - 1.0, R, -R, R], e=1e-10, ds=min(0.05, R / 200))
    theirs = roots[np.argmax(roots.real)]
    assert abs(ours.real - theirs.real) < 1e-6
    assert abs(abs(ours.imag) - abs(theirs.imag)) < 1e-6
    assert loop.is_stable(K) == bool(np.all(roots.real < 0))


def test_carmel_boundary_above_kb_and_growing_with_k():
    """Must hold (docs/models.md: KB is exact only as k → 0): for τ = 0.3 s, T = 0.065 s the exact NV* lies above KB's
    1/(τ+T) and grows with k (KB eq 20 claims no k-dependence)."""
    values = [ExactDelay().boundary(Loop(0.3, 0.065, k)).NV_critical for k in (0.5, 1.0, 2.0, 4.0, 8.0)]
    assert all(v > 1 / 0.365 for v in values)
    assert all(b > a for a, b in zip(values, values[1:]))


@pytest.mark.parametrize("tau, T, k, K", ORACLE_SETS[:20])
def test_boundary_root_is_on_the_axis(tau, T, k, K):
    """At K* a root sits at jω* (residual of eq 18 at round-off level) and the
    crossing count flips from 0 to 2 across K* (±1e-6 relative)."""
    loop_params = Loop(tau, T, k)
    boundary = ExactDelay().boundary(loop_params)
    q = DelayLoop(loop_params.plant, T)
    K_star, w = boundary.K_critical, boundary.omega_critical
    assert abs(q.value(1j * w, K_star)) < 1e-9 * K_star
    assert q.unstable_root_count(K_star * (1 - 1e-6)) == 0
    assert q.unstable_root_count(K_star * (1 + 1e-6)) == 2
    rightmost = q.rightmost_roots(K_star, count=1)[0]
    assert abs(rightmost.real) < 1e-8 and abs(abs(rightmost.imag) - w) < 1e-8


@pytest.mark.parametrize("tau, T, k, K", ORACLE_SETS[:20])
def test_delay_margin_is_where_a_root_reaches_the_axis(tau, T, k, K):
    """Delay margin T̄(K): stable just below, unstable just above (1e-7 relative)."""
    a = [tau, 1.0, k, 0.0]
    margin = DelayLoop(a, T).delay_margin(K)
    if margin == 0.0:
        assert not DelayLoop(a, 0.0).is_stable(K)
        return
    assert DelayLoop(a, margin * (1 - 1e-7)).is_stable(K)
    assert not DelayLoop(a, margin * (1 + 1e-7)).is_stable(K)


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
def test_resonant_steering_loop_has_three_crossing_frequencies():
    """kτ > 2 + √3: |a(jω)| dips, so one K meets it at three frequencies, with
    crossing directions +, −, + (Cooke & van den Driessche); counts stay >= 0
    and agree with cxroots."""
    tau, k, T = 1.0, 6.0, 0.4
    q = DelayLoop([tau, 1.0, k, 0.0], T)
    w = np.linspace(0.01, 5, 4000)
    modulus = np.abs(np.polyval(q.a, 1j * w))
    local_max = modulus[np.argmax(np.diff(np.sign(np.diff(modulus))) < 0) + 1]
    K = 0.98 * local_max
    freqs = q.crossing_frequencies(K)
    assert [d for _, d in freqs] == [1, -1, 1]
    for T_test in (0.1, 0.4, 1.3, 3.0):
        loop = DelayLoop([tau, 1.0, k, 0.0], T_test)
        R = max(_rhp_radius(tau, k, K), 6.0)
        roots = _cx_roots(tau, T_test, k, K, ([-0.5, R], [-R, R]))
        assert loop.unstable_root_count(K) == int(np.sum(roots.real > 0))


def test_exact_delay_at_T0_is_continuous():
    """T = 0: eq (18) is eq (17); NV* = 1/τ and ω* = √(k/τ)."""
    loop = Loop(0.3, 0.0, 2.0)
    assert ExactDelay().boundary(loop).NV_critical == pytest.approx(Continuous().boundary(loop).NV_critical, rel=1e-12)
    assert ExactDelay().boundary(loop).omega_critical == pytest.approx(math.sqrt(2.0 / 0.3), rel=1e-12)


def test_second_order_plant_tau_zero():
    """τ = 0: s² + ks + K e^(−sT); the delay alone destabilizes. Check the root at jω*."""
    loop = Loop(0.0, 0.1, 2.0)
    b = ExactDelay().boundary(loop)
    q = DelayLoop(loop.plant, loop.T)
    assert math.isfinite(b.NV_critical) and b.NV_critical > 0
    assert abs(q.value(1j * b.omega_critical, b.K_critical)) < 1e-9 * b.K_critical
    assert KBFirstOrder().boundary(loop).NV_critical == pytest.approx(1 / 0.1)


def test_small_gain_is_stable_and_huge_delay_has_many_crossings():
    """K → 0: stable for any T (the zero root of a(s) moves left). Huge T: many
    crossing delays below T. The crossing count equals the argument principle
    (cxroots.count_roots) at T = 30 s and the number of pseudospectral
    eigenvalues with Re > 0 (polished) at T = 100 s."""
    tau, k, K = 0.3, 2.0, 1.0
    assert DelayLoop([tau, 1.0, k, 0.0], 100.0).is_stable(1e-9)
    for T in (30.0, 100.0):
        q = DelayLoop([tau, 1.0, k, 0.0], T)
        crossings = q.crossing_delays(K, T)
        ((w, _),) = q.crossing_frequencies(K)
        assert len(crossings) == math.floor((T - crossings[0].delay) * w / (2 * math.pi)) + 1
        assert q.unstable_root_count(K) == 2 * len(crossings)
        spectrum = q.rightmost_roots(K, count=4 * len(crossings) + 4, nodes=160)
        assert int(np.sum(spectrum.real > 0)) == 2 * len(crossings)
    f = lambda s: tau * s**3 + s**2 + k * s + K * np.exp(-30.0 * s)  # noqa: E731
    df = lambda s: 3 * tau * s**2 + 2 * s + k - 30.0 * K * np.exp(-30.0 * s)  # noqa: E731
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert cxroots.Rectangle([0.0, 3.0], [-3.0, 3.0]).count_roots(f, df) == DelayLoop([tau, 1.0, k, 0.0], 30.0).unstable_root_count(K)
    b = ExactDelay().boundary(Loop(tau, 100.0, k))
    assert 0 < b.K_critical < 0.05


def test_general_polynomial_form():
    """a(s) + K e^(−sT) for another a(s): (s + 1)² + K e^(−s): K* from the phase
    condition 2·atan(ω) + ω = π, K* = 1 + ω*² (textbook single-delay example)."""
    q = DelayLoop([1.0, 2.0, 1.0], 1.0)
    interval = q.critical_gain()
    w = interval.frequency
    assert 2 * math.atan(w) + w == pytest.approx(math.pi, rel=1e-12)
    assert interval.gain == pytest.approx(1 + w * w, rel=1e-12)


def test_critical_gain_when_the_first_level_is_not_the_lowest():
    """τ = 3 s, T = 3 s, k = 2 1/s (kτ = 6 > 2 + √3: the steering loop resonates): NV* = 0.3236174,
    not 0 (the old doubling search started too low and fell back to a fixed gain). Checked with
    cxroots (argument principle and Newton) in a rectangle that holds every root with Re s >= 0:
    none in the right half-plane at K*(1 − 1e-6), the pair at ±jω* (1e-6) in it at K*(1 + 1e-6)."""
    loop = Loop(3.0, 3.0, 2.0)
    b = ExactDelay().boundary(loop)
    assert b.NV_critical == pytest.approx(0.3236174, rel=1e-6)
    R = _rhp_radius(loop.tau, loop.k, 2 * b.K_critical)
    for factor, expected in ((1 - 1e-6, 0), (1 + 1e-6, 2)):
        roots = _cx_roots(loop.tau, loop.T, loop.k, b.K_critical * factor, ([-0.01, R], [-R, R]))
        right = roots[roots.real > 0]
        assert len(right) == expected
        assert np.all(np.abs(np.abs(right.imag) - b.omega_critical) < 1e-6)


@pytest.mark.parametrize("seed", range(6))
def test_resonant_critical_gain_by_two_routes_and_the_generic_count(seed):
    """Resonant loops (kτ from 4 to 400, T up to 50 s: up to ~10⁴ phase levels below the dip):
    the vectorized three-candidate K* equals the generic scalar `DelayLoop.critical_gain`
    (every stretch of |a(jω)|, 1e-12) and the generic crossing count says stable at
    K*(1 − 1e-9) and at 50 geometric gains below, unstable at K*(1 + 1e-9)."""
    from pfm_stability.numerics.delay import kb_critical_gain

    rng = np.random.default_rng(seed)
    tau = float(rng.uniform(0.05, 4.0))
    k = float(np.exp(rng.uniform(np.log(4.0), np.log(400.0)))) / tau
    T = float(np.exp(rng.uniform(np.log(0.01), np.log(50.0))))
    K, w = (float(x) for x in kb_critical_gain(tau, T, k))
    q = DelayLoop([tau, 1.0, k, 0.0], T)
    generic = q.critical_gain()
    assert generic.gain == pytest.approx(K, rel=1e-12)
    assert generic.frequency == pytest.approx(w, rel=1e-10)
    assert q.is_stable(K * (1 - 1e-9)) and not q.is_stable(K * (1 + 1e-9))
    assert all(q.is_stable(g) for g in np.geomspace(1e-6 * K, 0.999 * K, 50))
