"""The window-edge relay's limit cycle (`maps.deciding.relay`) against the sampled loop simulated with the relay, and against
the VFF simulator beside a rack (docs/maps.md, "Verdicts along every route").

Independent route: the loop is discretized here (expm of the augmented plant matrix, KB's τ, k, T, V, both holds,
compute delay 0/1), its critical gain N* and phase crossover ω* come from its own frequency response, and the
relay (± |J|/2 about a boundary, a smooth slope beside it, or a staircase of jumps) is applied to the samples of the
lateral position, as the controller does. The settled cycle's first harmonic and half-period are measured from the
samples.

**Tolerance** (`_band`). The describing function (DF) is exact for a sinusoid at the relay's input; two things move
the true cycle off it:

* the sampled relay switches at the first sample past the zero crossing, up to half a sample early or late
  relative to its first harmonic (a ±1 sequence of m samples each way is centred on its block): a phase of
  ±ωT/2. The cycle's ω therefore lies where the phase of −1/H(e^{jωT}) (H the loop with the smooth slope closed)
  is within ωT/2 of 0, and its half-period is a whole number of samples; its amplitude is 2|J|/(π·|−1/H|)
  somewhere over that band;
* the relay's odd harmonics (1/n of the fundamental for a square wave) through the loop's low-pass: the third,
  r3 = |H(3jω*)|/(3|H(jω*)|), shifts the zero crossings (and so the switching phase and the amplitude) by about
  r3; 3·r3 bounds the sum over the odd harmonics for the loop's third-order roll-off.

So the DF's amplitude must lie within (the band's relative spread + 3·r3) of the measured first harmonic. At
CARMEL (21 samples a half-period) that is 3–8 %; at a coarse random robot (7 samples) up to ~50 %.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq

from pfm_stability.maps.deciding.relay import profile_cycle, relay_amplitude, window_cycle, window_relay
from pfm_stability.models import make_model
from pfm_stability.models.loop import Loop
from pfm_stability.parameters import CARMEL, HOLDS


def _loop(tau, k, T, V, hold, delay):
    """(A_d, B_d): state_{k+1} = A_d·state_k + B_d·δ_k of the sampled loop, δ the heading reference (rad) the
    computer computes at t_k from the lateral position; states (ω, θ, x[, held command]). Command hold: the computer
    holds u = k(δ − θ); reference hold: it holds δ and the servo closes u = k(δ − θ(t)). A compute delay applies
    the command computed at t_k over [t_k+1, t_k+2)."""
    if hold == "command":
        A = np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, V, 0]])
        B = np.array([1 / tau, 0, 0])
    else:
        A = np.array([[-1 / tau, -k / tau, 0], [1, 0, 0], [0, V, 0]])
        B = np.array([k / tau, 0, 0])
    M = np.zeros((4, 4))
    M[:3, :3], M[:3, 3] = A, B
    E = expm(M * T)
    Phi, Gam = E[:3, :3], E[:3, 3]
    theta = np.array([0.0, k, 0.0]) if hold == "command" else np.zeros(3)  # the held input's θ feedback
    gain = k if hold == "command" else 1.0  # the held input per unit δ
    if not delay:
        return Phi - np.outer(Gam, theta), gain * Gam
    Ad = np.zeros((4, 4))
    Ad[:3, :3], Ad[:3, 3], Ad[3, :3] = Phi, Gam, -theta
    return Ad, np.r_[0.0, 0.0, 0.0, gain]


def _G(w, loop, T):
    """x/δ of the sampled loop at e^{jωT} (the loop closes δ = −N·x: 1 + N·G = 0)."""
    Ad, Bd = loop
    return np.linalg.solve(np.exp(1j * w * T) * np.eye(Ad.shape[0]) - Ad, Bd)[2]


def _crossover(loop, T):
    """(ω*, N*): the first frequency where G(e^{jωT}) is real and negative, and N* = −1/G there."""
    ws = np.linspace(1e-3, 0.999 * math.pi / T, 3000)
    g = np.array([_G(w, loop, T) for w in ws])
    i = np.flatnonzero((g.imag[:-1] < 0) & (g.imag[1:] >= 0) & (g.real[1:] < 0))[0]
    w = brentq(lambda w: _G(w, loop, T).imag, ws[i], ws[i + 1], xtol=1e-14)
    return w, -1.0 / _G(w, loop, T).real


def _simulate(loop, force, x0, steps):
    """Lateral positions x_k of the loop with δ_k = force(x_k)."""
    Ad, Bd = loop
    z = np.zeros(Ad.shape[0])
    z[2] = x0
    out = np.empty(steps)
    for i in range(steps):
        out[i] = z[2]
        z = Ad @ z + Bd * force(z[2])
    return out


def _cycle(x, boundary=0.0):
    """(first-harmonic amplitude, half-period in samples, mean) of the settled samples (the last half of the run):
    the period from the relay's upward switches (x crossing `boundary`), the harmonic over the whole periods between
    the first and the last of them."""
    x = x[x.size // 2:]
    side = x > boundary
    up = np.flatnonzero(~side[:-1] & side[1:]) + 1
    period = (up[-1] - up[0]) / (up.size - 1)
    seg = x[up[0]:up[-1]]
    a1 = 2 * abs(np.mean(seg * np.exp(-2j * math.pi * np.arange(seg.size) / period)))
    return float(a1), float(period / 2), float(seg.mean())


def _harmonic(t, x):
    """First-harmonic amplitude of a settled oscillation x(t) over the whole periods between its first and last
    upward crossings of its mean."""
    r = x - x.mean()
    up = np.flatnonzero((r[:-1] < 0) & (r[1:] >= 0))
    period = (t[up[-1]] - t[up[0]]) / (up.size - 1)
    seg, ts = r[up[0]:up[-1]], t[up[0]:up[-1]]
    return float(2 * abs(np.mean(seg * np.exp(-2j * math.pi * ts / period))))


def _band(loop, T, w0, N_smooth):
    """(spread, r3, (ω_lo, ω_hi)): the frequencies whose −1/H phase is within ±ωT/2 of 0 (H the loop with N_smooth
    closed), the largest relative difference of 2|J|/(π·|−1/H|) over them from its value at ω*, and
    r3 = |H(3ω*)|/(3|H(ω*)|) (module docstring)."""
    ws = np.linspace(0.5 * w0, 1.5 * w0, 1001)
    inv = np.array([-1 / _G(w, loop, T) for w in ws]) - N_smooth
    inside = np.abs(np.angle(inv)) <= ws * T / 2
    i0 = int(np.argmin(abs(ws - w0)))
    lo = hi = i0
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    while hi < ws.size - 1 and inside[hi + 1]:
        hi += 1
    ratio = abs(inv[i0]) / np.abs(inv[lo:hi + 1])
    H = lambda w: _G(w, loop, T) / (1 + N_smooth * _G(w, loop, T))  # noqa: E731
    return float(np.max(np.abs(ratio - 1))), float(abs(H(3 * w0)) / (3 * abs(H(w0)))), (ws[lo], ws[hi])


def _check_relay(tau, k, T, V, hold, delay, fraction, J=0.1):
    """Simulate the relay ±|J|/2 beside the smooth slope fraction·N*: (first harmonic, relay_amplitude, tolerance,
    measured ω, the band of ω) (module docstring)."""
    loop = _loop(tau, k, T, V, hold, delay)
    w0, N0 = _crossover(loop, T)
    Ns = fraction * N0
    A = float(relay_amplitude(J, N0, Ns))
    x = _simulate(loop, lambda x: -Ns * x - 0.5 * J * np.sign(x), 1.2 * A, int(60 * 2 * math.pi / w0 / T))
    a1, half, _ = _cycle(x)
    spread, r3, band = _band(loop, T, w0, Ns)
    return a1, A, spread + 3 * r3, math.pi / (half * T), band


@pytest.mark.parametrize("hold", HOLDS)
@pytest.mark.parametrize("delay", (0, 1))
def test_relay_cycle_at_carmel(hold, delay):
    """CARMEL (τ 0.3 s, k 2 1/s, T 65 ms, V 0.8 m/s), each hold and compute delay: the loop discretized here has the
    sampled model's N* = NV*/V and ω* (`Sampled.boundary`, another computation: to 1e-9), and the relay ±|J|/2 on
    its samples — alone and beside a smooth restoring slope 0.6·N* — settles in a cycle whose first harmonic is
    `relay_amplitude(J, N*, N_smooth)` = 2|J|/(π(N* − N_s)) within the module docstring's tolerance (7–14 % here;
    measured 3–8 %), at a frequency inside the half-sample phase band (0.5 % slack: the band's grid), its
    half-period within one sample of π/(ω*T)."""
    tau, k, T, V = CARMEL.robot.tau, CARMEL.robot.k, CARMEL.controller.T, CARMEL.robot.V
    w0, N0 = _crossover(_loop(tau, k, T, V, hold, delay), T)
    boundary = make_model("sampled", hold=hold, compute_delay=delay).boundary(Loop(tau, T, k))
    assert w0 == pytest.approx(boundary.omega_critical, rel=1e-9)
    assert N0 == pytest.approx(boundary.NV_critical / V, rel=1e-9)
    for fraction in (0.0, 0.6):
        a1, A, tol, w, (lo, hi) = _check_relay(tau, k, T, V, hold, delay, fraction)
        assert tol < 0.15
        assert a1 == pytest.approx(A, rel=tol), (fraction, a1, A, tol)
        assert 0.995 * lo <= w <= 1.005 * hi and abs(math.pi / (w * T) - math.pi / (w0 * T)) <= 1.0


def test_relay_cycle_at_random_robots():
    """Eight random robots (seeded: τ 0.05–0.5 s, k 1–5 1/s, T 20–150 ms, V 0.3–1.5 m/s, the four sampled
    structures in turn), the relay alone and beside a smooth slope 0.6·N*: the first harmonic is relay_amplitude's
    within each case's tolerance (module docstring: the half-sample phase band and the third harmonic), and the
    frequency inside that band."""
    rng = np.random.default_rng(2031)
    for i in range(8):
        tau, k, T, V = rng.uniform(0.05, 0.5), rng.uniform(1, 5), rng.uniform(0.02, 0.15), rng.uniform(0.3, 1.5)
        hold, delay = HOLDS[i % 2], (i // 2) % 2
        for fraction in (0.0, 0.6):
            a1, A, tol, w, (lo, hi) = _check_relay(tau, k, T, V, hold, delay, fraction)
            assert a1 == pytest.approx(A, rel=tol), (i, fraction, a1, A, tol)
            assert 0.995 * lo <= w <= 1.005 * hi, (i, fraction, w, lo, hi)


def test_the_smooth_slope_enlarges_the_cycle():
    """Beside a smooth restoring slope N_s = 0.6·N* the cycle is 1/(1 − 0.6) = 2.5 times the relay alone's (the
    relay need supply only N* − N_s of the loop's gain): at CARMEL the simulated first harmonic is more than twice
    2|J|/(πN*) (the formula without the slope) and within tolerance of 2|J|/(π(N* − N_s)). N_s >= N* (the smooth
    loop unstable by itself) has no relay cycle: inf."""
    tau, k, T, V = CARMEL.robot.tau, CARMEL.robot.k, CARMEL.controller.T, CARMEL.robot.V
    loop = _loop(tau, k, T, V, "command", 1)
    w0, N0 = _crossover(loop, T)
    a1, A, tol, _, _ = _check_relay(tau, k, T, V, "command", 1, 0.6)
    assert a1 > 2 * float(relay_amplitude(0.1, N0))
    assert a1 == pytest.approx(A, rel=tol)
    assert A == pytest.approx(2.5 * float(relay_amplitude(0.1, N0)), rel=1e-12)
    assert np.isinf(relay_amplitude(0.1, N0, N0)) and np.isinf(relay_amplitude(0.1, N0, 2 * N0))


def test_an_asymmetric_relay_is_smaller():
    """A pull P towards the jump (levels +P and −(|J| − P), P = |J|/4; CARMEL, command hold, compute delay 1): the
    loop's integrator makes the mean output zero, so the relay is on the +P side a fraction 1 − P/|J| of the time and
    its fundamental is (2|J|/π)·sin(πP/|J|): the cycle is smaller than the symmetric relay's (simulated both) and
    near relay_amplitude × sin(π/4), to 25 % (the asymmetric wave's second harmonic, sin(2πd)/(2 sin πd) = 0.71 of
    its fundamental, through the loop's low-pass: ~10 % of x, twice the symmetric relay's third)."""
    tau, k, T, V = CARMEL.robot.tau, CARMEL.robot.k, CARMEL.controller.T, CARMEL.robot.V
    loop = _loop(tau, k, T, V, "command", 1)
    w0, N0 = _crossover(loop, T)
    J = 0.1
    x = _simulate(loop, lambda x: J / 4 if x < 0 else -0.75 * J, 0.02, int(60 * 2 * math.pi / w0 / T))
    a1, _, _ = _cycle(x)
    symmetric, _, _, _, _ = _check_relay(tau, k, T, V, "command", 1, 0.0, J)
    assert a1 < 0.9 * symmetric
    assert a1 == pytest.approx(float(relay_amplitude(J, N0)) * math.sin(math.pi / 4), rel=0.25)


def _staircase(J0, J1, c, Ns):
    """A relay J0 at 0, then a jump J1 at every cell boundary c, 2c, … on the + side only (a rack's columns entering
    the window one by one), beside a smooth slope Ns: the restoring force (heading reference)."""
    return lambda x: -Ns * x - 0.5 * J0 * np.sign(x) - J1 * np.floor(np.maximum(x, 0.0) / c)


def test_profile_cycle_matches_the_loop_with_a_staircase():
    """`profile_cycle` on the force profile of a staircase (relay 0.5 at the path, 0.25 at each further cell
    boundary on one side, 0.1 m cells, smooth slope 0.23 1/m: the aisle beside a rack, CARMEL's loop): the cycle
    crosses several boundaries, its centre moves off the rack; the simulated first harmonic and mean position are
    the describing function's within the relay tolerance plus 5 % (the profile's steps smear each jump over c/16;
    the staircase's own harmonics). And on a lone relay beside a slope it gives relay_amplitude's closed form
    within 1 % (the same smearing, a saturation of half-width c/16 for a relay: O((step/A)²), 0.2 % measured)."""
    tau, k, T, V = CARMEL.robot.tau, CARMEL.robot.k, CARMEL.controller.T, CARMEL.robot.V
    loop = _loop(tau, k, T, V, "command", 1)
    w0, N0 = _crossover(loop, T)
    force = _staircase(0.5, 0.25, 0.1, 0.23)
    offsets = np.arange(-96, 97) * 0.00625
    amplitude, centre = profile_cycle(offsets, force(offsets)[None, :], N0)
    x = _simulate(loop, force, 0.05, int(60 * 2 * math.pi / w0 / T))
    a1, _, mean = _cycle(x)
    spread, r3, _ = _band(loop, T, w0, 0.23)
    assert amplitude[0] > 0.1  # past the first neighbouring boundary: the one-jump formula does not apply
    assert a1 == pytest.approx(amplitude[0], rel=spread + 3 * r3 + 0.05)
    assert mean == pytest.approx(centre[0], abs=0.1 * amplitude[0])
    lone = lambda s: -0.23 * s - 0.05 * np.sign(s)  # noqa: E731
    amplitude, centre = profile_cycle(offsets, lone(offsets)[None, :], N0)
    assert amplitude[0] == pytest.approx(float(relay_amplitude(0.1, N0, 0.23)), rel=0.01)
    assert centre[0] == pytest.approx(0.0, abs=1e-3)


def test_profile_cycle_no_cycle_and_leaving():
    """A profile whose describing function stays under N* (a smooth slope 0.5·N*, no jump) has no cycle (0); one
    whose gain stays above N* to the profile's reach (slope 2·N*) leaves it (inf)."""
    offsets = np.arange(-96, 97) * 0.00625
    amplitude, _ = profile_cycle(offsets, np.stack([-1.0 * offsets, -4.0 * offsets]), 2.0)
    assert amplitude[0] == 0.0 and np.isinf(amplitude[1])


def _aisle(law, gap: int, length: int = 400):
    """A histogram grid: a one-cell wall at column 0, free columns 1 … gap, a solid rack from column gap + 1 (the
    aisle of tests/test_map_paths.py's rack, with a wall on the other side)."""
    from pfm_stability.maps.reading.field import HistogramMap

    cv = np.zeros((gap + 12, length), dtype=np.int16)
    cv[0, :] = law.cv
    cv[gap + 1:, :] = law.cv
    return HistogramMap(0.0, 0.0, law.cell_size, cv)


def test_a_split_jump_is_one_jump():
    """`window_relay` at a point on the cell boundary where a rack's column enters the window, the route tilted by
    0.1 rad so that the average over the robot's position along it puts F_n(s0) half-way up the jump: the jump found
    is the whole column's force (`tests/test_map_paths.py`'s hand sum, within 10 %), not the half either quarter-cell
    interval holds."""
    from pfm_stability.laws.fields import make_law

    law = make_law("grid", CARMEL.robot, CARMEL.controller)
    h, c = law.window_cells // 2, law.cell_size
    from pfm_stability.maps.reading.field import HistogramMap

    cv = np.zeros((60, 200), dtype=np.int16)
    cv[40:, :] = law.cv
    grid = HistogramMap(0.0, 0.0, c, cv)
    phi = 0.1
    x = np.array([(40 - h) * c])  # the boundary: moving towards +x the window gains column 40
    relay, jump = window_relay(grid, law, x, np.array([10.05]), np.array([math.sin(phi)]), np.array([math.cos(phi)]), np.zeros(1))
    dx, dy = (h + 0.5) * c, np.arange(-h, h + 1) * c
    column = float(law.ratio * law.W**law.n * law.cv * np.sum(dx / (dx * dx + dy * dy) ** ((law.n + 1) / 2)))
    # the normal is tilted by phi: the column's force projects on it by cos(phi)
    assert relay[0] and jump[0] == pytest.approx(column * math.cos(phi), rel=0.1)


@pytest.mark.slow
def test_rack_aisle_cycle_matches_the_simulator():
    """Map level: CARMEL in a 3.3 m aisle between a thin wall and a solid rack (`_aisle`, gap 32 cells): at 1.7 m
    from the wall the window loses the wall's column and gains the rack's at one cell boundary, a relay of ~0.51 F_ct
    beside a smooth slope 0.23 1/m, and the rack's further columns enter one a cell beyond it. The VFF simulator
    (the grid law, target straight along the aisle, started 3 cm off) settles in a cycle of first harmonic ~0.17 m;
    `window_cycle` (the describing function of the window's whole profile) predicts it within 10 % (CARMEL's band
    ±3.5 %, the third harmonic ~1 %, the simulator's robot at a point where the profile averages over its cell
    along the path, the small-angle steering). The one-jump formula is less than 85 % of it (the staircase)."""
    from pfm_stability.laws.fields import make_law
    from pfm_stability.sim.engine import run_batch
    from pfm_stability.sim.scenario import Pose, Scenario, Target
    from pfm_stability.validation.maps import simulator_grid

    robot, controller = CARMEL.robot, CARMEL.controller
    law = make_law("grid", robot, controller)
    grid = _aisle(law, 32)
    boundary = make_model("sampled", hold=controller.hold, compute_delay=controller.compute_delay).boundary(Loop.of(robot, controller))
    N0 = boundary.NV_critical / robot.V
    p = (np.array([1.7]), np.array([20.05]), np.zeros(1), np.ones(1), np.zeros(1))
    relay, jump = window_relay(grid, law, *p)
    predicted = float(window_cycle(grid, law, *p, N0)[0])
    scenario = Scenario(name="aisle", robot=robot, controller=controller, environment=simulator_grid(grid), start=Pose(1.73, 2.0, 0.0),
                        target=Target.direction(0.0), duration=40.0, cell_ratio=law.ratio, window_cells=law.window_cells)
    tr = run_batch([scenario], record="trajectory", metrics=False).runs[0].trajectory
    settled = tr.t > 15.0
    a1 = _harmonic(tr.t[settled], tr.x[settled])
    assert relay[0] and jump[0] == pytest.approx(0.51, rel=0.05)
    assert a1 == pytest.approx(predicted, rel=0.10)
    assert float(relay_amplitude(jump[0], N0, 0.23)) < 0.85 * a1
