"""T* and k*: the operating point's first loss of stability as T or k grows, in every model.

Definition (the same in every model): T* is the smallest sampling period /
delay at which the operating point (τ, k, NV fixed) loses stability — it is
stable for every T in [0, T*); k* likewise for the steering gain (τ, T, NV
fixed). Each test checks the definition by a route that does not use the
search that computed the value: the model's own independent verdict on both
sides of the value, and a dense scan below it with an independent oracle
(scipy's matrix exponential and numpy eigenvalues for ``sampled``, numpy roots for ``pade``, the Cooke–van den Driessche crossing
count of `DelayLoop` for ``exact_delay``).
"""

import math

import numpy as np
import pytest
import scipy.linalg

from conftest import random_loops
from pfm_stability.numerics.delay import DelayLoop
from pfm_stability.models import Continuous, ExactDelay, KBFirstOrder, Loop, Pade, Sampled
from pfm_stability.models.sampled import continuous_plant

STRUCTURES = [(h, c) for h in ("command", "reference") for c in (0, 1)]


def _sampled_oracle_stable(loop, hold, delay, NV):
    """Spectral radius < 1 of the sampled loop discretized by scipy's expm (independent of the model's
    numpy exponential and δ form; python-control's ZOH is checked against the model in test_sampled)."""
    A, B, F0, F1 = continuous_plant(loop, hold)
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n:] = A, B
    E = scipy.linalg.expm(M * loop.T)
    Phi, Gamma = E[:n, :n], E[:n, n:]
    F = (F0 + loop.k * NV * F1)[None, :]
    if delay == 0:
        closed = Phi - Gamma @ F
    else:
        closed = np.block([[Phi, Gamma], [-F, np.zeros((1, 1))]])
    return bool(np.max(np.abs(np.linalg.eigvals(closed))) < 1.0)


def _pade_oracle_stable(loop, order, NV):
    d, e = Pade(order).polynomials(loop)
    n = max(len(d), len(e))
    p = np.trim_zeros(np.pad(d, (n - len(d), 0)) + loop.k * NV * np.pad(e, (n - len(e), 0)), "f")
    return bool(np.max(np.roots(p).real) < 0)


def _exact_oracle_stable(loop, NV):
    return DelayLoop(loop.plant, loop.T).is_stable(loop.k * NV)


def _operating_points(count, seed):
    """(τ, T, k, NV) with NV between 0.3 and 0.95 of the continuous limit 1/τ (stable at T = 0)."""
    rng = np.random.default_rng(seed)
    out = []
    for tau, T, k, _ in random_loops(count, seed, tau=(0.02, 1.0), T=(0.005, 0.3), k=(0.3, 12.0)):
        out.append((tau, T, k, rng.uniform(0.3, 0.95) / tau))
    return out


@pytest.mark.parametrize("hold, delay", STRUCTURES)
@pytest.mark.parametrize("tau, T, k, NV", _operating_points(3, seed=41))
def test_sampled_T_star_is_the_first_loss_of_stability(hold, delay, tau, T, k, NV):
    """Sampled: stable just below T* (1e-6 relative), unstable just above (1e-5), and stable at
    100 geometric T in [1e-4·T*, 0.999·T*] by scipy's ZOH eigenvalues."""
    loop = Loop(tau, T, k)
    model = Sampled(hold, delay)
    T_star = model.critical_delay(NV, loop)
    assert 0 < T_star < math.inf
    assert _sampled_oracle_stable(Loop(tau, T_star * (1 - 1e-6), k), hold, delay, NV)
    assert not _sampled_oracle_stable(Loop(tau, T_star * (1 + 1e-5), k), hold, delay, NV)
    for t in np.geomspace(1e-4 * T_star, 0.999 * T_star, 100):
        assert _sampled_oracle_stable(Loop(tau, float(t), k), hold, delay, NV)


@pytest.mark.parametrize("tau, T, k, NV", _operating_points(6, seed=43))
def test_pade_and_exact_T_star_are_the_first_loss_of_stability(tau, T, k, NV):
    """Padé(3): stable below T*, unstable above (numpy roots); exact delay: the delay
    margin, checked by the crossing count of the generic `DelayLoop` on both sides and on a
    200-point scan below it. Padé(3)'s T* approaches the exact one (2e-2 relative: the
    third-order approximant's phase error at the crossing frequency)."""
    loop = Loop(tau, T, k)
    T_pade = Pade(3).critical_delay(NV, loop)
    assert _pade_oracle_stable(Loop(tau, T_pade * (1 - 1e-6), k), 3, NV)
    assert not _pade_oracle_stable(Loop(tau, T_pade * (1 + 1e-5), k), 3, NV)
    T_exact = ExactDelay().critical_delay(NV, loop)
    assert _exact_oracle_stable(Loop(tau, T_exact * (1 - 1e-9), k), NV)
    assert not _exact_oracle_stable(Loop(tau, T_exact * (1 + 1e-9), k), NV)
    for t in np.geomspace(1e-4 * T_exact, 0.999 * T_exact, 200):
        assert _exact_oracle_stable(Loop(tau, float(t), k), NV)
    assert T_pade == pytest.approx(T_exact, rel=2e-2)


def test_closed_forms_of_T_star():
    """continuous: T does not enter (inf or 0); kb_first_order: KB eq (20) solved for T, 1/NV − τ."""
    loop = Loop(0.3, 0.065, 2.0)
    assert Continuous().critical_delay(2.0, loop) == math.inf
    assert Continuous().critical_delay(4.0, loop) == 0.0
    assert KBFirstOrder().critical_delay(2.0, loop) == pytest.approx(1 / 2.0 - 0.3, rel=1e-15)


def test_T_star_where_stability_in_NV_is_not_an_interval():
    """Command hold with kT near 2: the sampled loop is stable only for NV in a band that does not
    start at 0 (NV* = 0). T* of an operating point inside the band is still its first loss of
    stability from T = 0, found by the scan, and the point is stable at its own T; checked
    against scipy's ZOH on a 300-point scan below T*."""
    loop = Loop(0.009711634968144423, 0.17022748203838609, 13.877647289515428)
    model = Sampled("command", 0)
    b = model.boundary(loop)
    assert b.NV_critical == 0.0 and len(b.stable_set) == 1 and b.stable_set[0][0] > 0
    NV = 0.5 * sum(b.stable_set[0])
    assert model.is_stable(NV, loop) and _sampled_oracle_stable(loop, "command", 0, NV)
    T_star = model.critical_delay(NV, loop)
    assert T_star > loop.T  # stable at its own T, although NV*(T) = 0 there: the collapse of NV* is not T*
    assert not _sampled_oracle_stable(Loop(loop.tau, T_star * (1 + 1e-5), loop.k), "command", 0, NV)
    for t in np.geomspace(1e-5, 0.999 * T_star, 300):
        assert _sampled_oracle_stable(Loop(loop.tau, float(t), loop.k), "command", 0, NV)


@pytest.mark.parametrize("hold, delay", STRUCTURES)
@pytest.mark.parametrize("tau, T, k, NV", _operating_points(3, seed=47))
def test_k_star_is_the_first_loss_of_stability(hold, delay, tau, T, k, NV):
    """k*: stable for every k in (0, k*) (100 geometric values down to 1e-3·k*, scipy ZOH),
    unstable just above; for exact_delay k* = 0 exactly when NV(τ + T) >= 1 (KB's eq 20 is the
    k → 0 limit), else the same two-sided check by the generic crossing count."""
    loop = Loop(tau, T, k)
    k_star = Sampled(hold, delay).critical_gain_k(NV, loop)
    if k_star == 0:  # no gain is small enough: unstable at the bottom of the search range
        assert not _sampled_oracle_stable(Loop(tau, T, 1e-3 * k), hold, delay, NV)
        return
    if math.isfinite(k_star):
        assert not _sampled_oracle_stable(Loop(tau, T, k_star * (1 + 1e-5)), hold, delay, NV)
        top = 0.999 * k_star
    else:
        top = 1e4
    for g in np.geomspace(1e-3 * top, top, 100):
        assert _sampled_oracle_stable(Loop(tau, T, float(g)), hold, delay, NV)
    k_exact = ExactDelay().critical_gain_k(NV, loop)
    if NV * (tau + T) >= 1:
        assert k_exact == 0.0
    elif math.isfinite(k_exact):
        assert _exact_oracle_stable(Loop(tau, T, k_exact * (1 - 1e-6)), NV)
        assert not _exact_oracle_stable(Loop(tau, T, k_exact * (1 + 1e-6)), NV)


def test_k_star_closed_forms():
    """k cancels from Routh's conditions of (17) and (20): inf when stable, 0 otherwise."""
    loop = Loop(0.3, 0.065, 2.0)
    assert Continuous().critical_gain_k(3.0, loop) == math.inf and Continuous().critical_gain_k(3.5, loop) == 0.0
    assert KBFirstOrder().critical_gain_k(2.0, loop) == math.inf and KBFirstOrder().critical_gain_k(3.0, loop) == 0.0


@pytest.mark.parametrize("k", [1e-4, 5e-6, 1e-6])
def test_k_star_search_stays_inside_the_range_of_k(k):
    """A steering gain inside its documented range [1e-6, 1e4] 1/s but below 1e-3 (`report --k 1e-4`): the k* search
    once probed 1e-3·k, outside the range, and the report failed with "k must be ... got 1e-07", a value the user never
    typed. Now the search starts at the range's end: the report answers, and k* keeps its definition, checked by the
    independent oracles (scipy ZOH for sampled, numpy roots for pade, the crossing count for exact_delay): unstable
    just above a finite k* (1 + 1e-5: above the search's 1e-7), stable on a scan below it down to the range's end;
    k* = 0 only where the range's smallest k is already unstable."""
    from pfm_stability.parameters import CARMEL, RANGES
    from pfm_stability.report.stability import build_report

    robot, controller = CARMEL.robot.replace(k=k), CARMEL.controller
    report = build_report(robot, controller, L=0.9, alpha_deg=30.0)
    low = RANGES["k"].low
    oracles = {"sampled": lambda g, NV: _sampled_oracle_stable(Loop(robot.tau, controller.T, g), controller.hold, controller.compute_delay, NV),
               "pade": lambda g, NV: _pade_oracle_stable(Loop(robot.tau, controller.T, g), 3, NV),
               "exact_delay": lambda g, NV: _exact_oracle_stable(Loop(robot.tau, controller.T, g), NV)}
    for analysis in (report.wall, report.corridor):
        for name, oracle in oracles.items():
            v = analysis.models[name]
            k_star = v.critical["k_critical"]
            if k_star == 0:
                assert not oracle(low, v.NV)
                continue
            if math.isfinite(k_star):
                assert not oracle(k_star * (1 + 1e-5), v.NV)
            top = 0.999 * min(k_star, RANGES["k"].high)
            for g in np.geomspace(low, top, 25):
                assert oracle(float(g), v.NV), (name, g, k_star)
