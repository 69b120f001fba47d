"""The CARMEL robot between two samples: steering lag, heading, synchro-drive motion.

Steering motor (Koren & Borenstein 1991 eq 6) τω̇ + ω = u, heading θ̇ = ω,
synchro-drive motion ẋ = V sin θ, ẏ = V cos θ (eq 14; the travel direction is
the heading). Over one hold interval of length h the input is one of

* **constant** (``hold="command"``, and a saturated servo): u held, so
  ω(t) = u + (ω₀ − u)e^(−t/τ), θ(t) = θ₀ + a(t)ω₀ + (t − a(t))u with
  a(t) = τ(1 − e^(−t/τ)) (τ = 0: ω = u, θ = θ₀ + ut);
* **servo** (``hold="reference"``): δ̃ held and u = k(δ̃ − θ(t)) closed
  continuously, i.e. τθ̈ + θ̇ + kθ = kδ̃ (eq 7). With e = θ − δ̃,
  (e, ω)(t) = exp(A t)(e₀, ω₀), A = [[0, 1], [−k/τ, −1/τ]] (2 × 2 matrix
  exponential in closed form; τ = 0: e(t) = e₀e^(−kt), ω = −ke).

Both are exact: θ(t) and ω(t) are linear in (θ₀, ω₀, held value) with
coefficients that depend only on (τ, k, h), precomputed once per member.

Plant gain and dead time (docs/simulator.md, "Plant gain and dead time"). A
real motor is τω̇ + ω = g·u(t − D): the held command's solution above takes
v = g·u, and the servo's takes k → g·k (τθ̈ + θ̇ + gkθ = gkδ̃). A command
computed from the data of t_k is applied at t_k + d·T (compute delay d) and
reaches the motor D later, at t_k + m·T + ε with 0 <= ε < T (`delay_split`):
over [t_k, t_k+1) the motor sees g·u_(k−m−1) for the first ε and g·u_(k−m)
after, two constant inputs, so the engine splits the period at ε into two
intervals of this module's kind, each exact, each with its own graded rule
on its own length (ε and T − ε). A dead time in a continuous servo loop
(``hold="reference"``) is a delay differential equation, not a sequence of
such intervals: the simulator refuses it (`Scenario`).

The drive's velocity smoother (docs/simulator.md, "The drive's rate limit").
A limit R (rad/s², `Robot.yaw_accel_limit`) on the rate of change of the
commanded yaw rate acts as Nav2's ``velocity_smoother`` does with
``feedback: OPEN_LOOP`` at the controller's rate: each period its output
moves from its last output towards the new command by at most R·T
(`slew_limit`), starting from 0 (Nav2's first ``last_cmd_`` is a zero
twist). It sits on the command's way to the base — cmd_vel → smoother →
dead time → motor — after the steering-rate saturation, so the held values
above are its outputs; it is a discrete operator on the sequence of
commands, so it commutes with the compute delay and the dead time. With a
servo (``hold="reference"``) there is no sequence of commands to limit: the
simulator refuses it (`Scenario`).

Positions (eq 14). With θ(t) = θ₀ + Δ(t),

    ∫₀ʰ sin θ dt = sin θ₀ ∫cos Δ dt + cos θ₀ ∫sin Δ dt,
    ∫₀ʰ cos θ dt = cos θ₀ ∫cos Δ dt − sin θ₀ ∫sin Δ dt,
    ∫sin Δ dt = ∫Δ dt + ∫(sin Δ − Δ) dt,   ∫cos Δ dt = h + ∫(cos Δ − 1) dt.

Δ(t) is linear in (θ₀, ω₀, held value), and so is ∫₀ʰ Δ dt, with
closed-form coefficients (`constant_input`, `servo`): the motion's part
linear in the heading — all of it, to round-off, in the regime where the
growth rate σ is measured — is exact for any h/τ. Only the residuals
sin Δ − Δ = O(Δ³) and cos Δ − 1 = O(Δ²) are integrated numerically (in
practice the rule is applied to sin Δ and cos Δ and corrected by its exactly
known error on Δ, `Coefficients.maps`), by a composite Gauss–Legendre rule
with `NODES` nodes per panel on a mesh graded to the steering time scales
(`graded_rule`): when h ≫ τ (or ≫ 1/k, √(τ/k) for the servo) θ(t) turns
within a boundary layer of width ~τ at the start of each interval, which a
rule over the whole interval cannot resolve. The panels divide the phase

    Φ(t) = ∫₀ᵗ r dt′,   r(t) = ω_s + Σᵢ |λᵢ| e^(−dᵢt/(2·NODES + 1))   (rad)

into equal parts of at most `RESOLUTION` rad, where ω_s (rad/s) bounds |θ̇|
(`slow_rate`) and λᵢ are the eigenvalues of the steering solution (1/s,
dᵢ = −Re λᵢ; `constant_input_modes`, `servo_modes`). An n-node rule's error
on a mode e^(λt) over a panel of width w starting at t is ~e^(−dt)(w|λ|)^(2n+1),
hence the exponent: the panels are ~RESOLUTION·τ wide at the start and widen
as the modes decay, and no panel turns the slow motion by more than
RESOLUTION rad. A member's panel count is ⌈Φ(h)/RESOLUTION⌉ (at most
`MAX_PANELS`) and depends on its own (τ, k, h, ω_max) only; one panel, the
plain 4-node rule, at CARMEL's T = 0.065 s, τ = 0.3 s. A batch's rules are
padded with zero weights to its member with the most panels, and a step's
cost grows with that count (a 1000-member grid batch at T/τ = 4, 16 nodes,
steps ~1.3× slower than with 4 nodes).

Measured error of one step's position against adaptive quadrature (scipy
``quad``, tolerance 1e-13 relative), worst over 17 initial headings, for the
largest turns: a saturated reversal (held command, ω₀ = −120°/s,
u = +120°/s) or a held reference 0.99·ω_max/k ahead with ω₀ = −120°/s (the
largest unsaturated servo turn); V = 0.8 m/s:

==========  ======  ======  =======  ======  ============  ==================
hold        τ (s)   k (1/s) T (s)    T/τ     panels        error (m)
==========  ======  ======  =======  ======  ============  ==================
command     0.3     2       0.065    0.22    1             1.6e-13 (1.6e-13)
command     0.3     2       0.5      1.7     3             3.2e-10 (1.2e-6)
command     0.05    2       0.2      4       4             2.1e-11 (7.5e-7)
command     0.01    2       0.3      30      10            3.6e-13 (1.2e-4)
command     0.01    0.5     1.0      100     11            9.8e-10 (3.3e-4)
reference   0.3     2       0.065    0.22    1             1.1e-13 (1.1e-13)
reference   0.3     2       0.2      0.67    1             1.3e-9  (1.3e-9)
reference   0.05    6       0.2      4       3             1.8e-10 (6.8e-7)
reference   0.01    0.5     1.0      100     12            1.5e-10 (3.3e-4)
==========  ======  ======  =======  ======  ============  ==================

(in brackets: the former 4-node rule over the whole interval). At most
~1e-8 of the step's length V·T; `tests/test_sim_robot.py` re-measures these
figures. In the linear regime the simulated σ and ω equal the `sampled`
model's dominant pole to 5e-9 relative for T/τ from 1 to 100 and every
hold and compute delay (the former rule: up to 1.6e-3 at T/τ = 30;
`tests/test_sim_accuracy.py`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..numerics.solve import gauss_legendre as legendre_nodes
from ..parameters import dead_time_split

__all__ = [
    "NODES", "RESOLUTION", "MAX_PANELS", "delay_split", "gauss_legendre", "slow_rate", "constant_input_modes", "servo_modes",
    "panel_count", "graded_rule", "node_sum", "Rule", "Coefficients", "constant_input", "servo", "propagate",
    "advance_position", "advance_held", "DelayLine", "CommandPath", "slew_limit",
]

NODES = 4
"""Gauss–Legendre nodes per panel of the position quadrature."""

RESOLUTION = 1.0
"""Largest phase Φ per panel, rad (module docstring; the error falls roughly as RESOLUTION⁸)."""

MAX_PANELS = 64
"""Most panels per hold interval, to bound memory: Φ(h) <= 64 rad is divided as designed (each mode adds
at most 2·NODES + 1 = 9 rad, so any T/τ and |θ̇|·T up to ~45 rad); beyond, the panels widen."""


def delay_split(T, compute_delay, dead_time):
    """(m, ε) per member: `parameters.dead_time_split` (the one rule, shared with the `sampled` model) on arrays.

    Over [t_k, t_k+1) the motor sees u_(k−m−1) for the first ε seconds and
    u_(k−m) for the rest (module docstring).

    Parameters
    ----------
    T : ndarray, shape (B,)
        Sampling period, s (> 0).
    compute_delay : ndarray of int, shape (B,)
        d, samples (0 or 1).
    dead_time : ndarray, shape (B,)
        D, s (>= 0).

    Returns
    -------
    m : ndarray of int, shape (B,)
        Whole periods, d included.
    eps : ndarray, shape (B,)
        The fraction of a period, s, in [0, T).
    """
    pairs = [dead_time_split(float(t), int(d), float(D)) for t, d, D in
             zip(np.ravel(T), np.ravel(compute_delay), np.ravel(dead_time))]
    return np.array([m for m, _ in pairs], dtype=np.int64), np.array([e for _, e in pairs], dtype=float)


def gauss_legendre(nodes: int = NODES):
    """Nodes as fractions of an interval (0, 1) and weights summing to 1.

    Parameters
    ----------
    nodes : int
        Nodes of the rule.
    """
    x, w = legendre_nodes(nodes)
    return (x + 1) / 2, w / 2


def slow_rate(k, max_steering_rate, gain=1.0):
    """Bound ω_s on |θ̇|, rad/s: g·min(ω_max, kπ).

    A held command is k·wrap(δ − θ) clipped to ±ω_max, and a servo's command
    k(δ̃ − θ) starts within ±kπ; the motor turns at g times the command, and
    ω lags it (eq 6), so it stays within the same bound.

    Parameters
    ----------
    k : array_like
        Steering gain, 1/s.
    max_steering_rate : array_like
        Rate limit ω_max, rad/s (of the command, before the gain).
    gain : array_like
        Plant gain g (1: KB's motor).
    """
    bound = np.minimum(np.asarray(max_steering_rate, dtype=float), np.pi * np.asarray(k, dtype=float))
    return np.asarray(gain, dtype=float) * bound


def constant_input_modes(tau):
    """(|λ|, −Re λ) of the held-command solution, 1/s, shape (B, 1): λ = −1/τ (absent: |λ| = 0 for τ = 0).

    Parameters
    ----------
    tau : array_like, shape (B,)
        Steering lag τ per member, s.
    """
    tau = np.asarray(tau, dtype=float)
    lag = tau > 0
    rate = np.where(lag, 1.0 / np.where(lag, tau, 1.0), 0.0)
    return rate[:, None], np.where(lag, rate, 1.0)[:, None]


def servo_modes(tau, k):
    """(|λ|, −Re λ) of the servo's eigenvalues, 1/s, shape (B, 2).

    τ > 0: the roots of τλ² + λ + k, real (fast, slow; slow = k/(τ·fast)
    without cancellation) or a complex pair (counted once); τ = 0: λ = −k.
    Absent modes have |λ| = 0.

    Parameters
    ----------
    tau : array_like, shape (B,)
        Steering lag τ per member, s.
    k : array_like, shape (B,)
        Steering gain per member, 1/s.
    """
    tau = np.asarray(tau, dtype=float)
    k = np.asarray(k, dtype=float)
    lag = tau > 0
    safe_tau = np.where(lag, tau, 1.0)
    half = 0.5 / safe_tau
    q2 = half * half - k / safe_tau
    real = q2 >= 0
    fast = half + np.sqrt(np.where(real, q2, 0.0))
    rate1 = np.where(lag, np.where(real, fast, np.sqrt(k / safe_tau)), k)
    decay1 = np.where(lag, np.where(real, fast, half), k)
    slow = np.where(lag & real, k / (safe_tau * fast), 0.0)
    return np.stack([rate1, slow], axis=1), np.stack([decay1, np.where(slow > 0, slow, 1.0)], axis=1)


def _phase(t, rates, decays, slow):
    """Φ(t) = ω_s t + Σᵢ |λᵢ|(1 − e^(−μᵢt))/μᵢ, μᵢ = dᵢ/(2·NODES + 1), rad; t shape (B, P)."""
    mu = decays[:, None, :] / (2 * NODES + 1)
    modes = rates[:, None, :] * -np.expm1(-mu * t[:, :, None]) / mu
    return slow[:, None] * t + np.sum(modes, axis=2)


def panel_count(h, rates, decays, slow):
    """Panels per member: ⌈Φ(h)/RESOLUTION⌉, from 1 to `MAX_PANELS`.

    Parameters
    ----------
    h : ndarray, shape (B,)
        Interval length, s.
    rates, decays : ndarray, shape (B, M)
        |λᵢ| and −Re λᵢ of the solution's modes, 1/s (`constant_input_modes`, `servo_modes`).
    slow : ndarray, shape (B,)
        ω_s, rad/s (`slow_rate`).

    Returns
    -------
    ndarray of int, shape (B,)
    """
    need = _phase(np.asarray(h, dtype=float)[:, None], rates, decays, slow)[:, 0] / RESOLUTION
    return np.clip(np.ceil(need), 1, MAX_PANELS).astype(np.int64)


@dataclass(frozen=True)
class Rule:
    """A composite Gauss–Legendre rule per member on [0, h].

    Attributes
    ----------
    t : ndarray, shape (B, J)
        Node times, s. A member with fewer panels than the batch's most is
        padded with zero-weight nodes at t = h.
    w : ndarray, shape (B, J)
        Weights, s (each row sums to h).
    h : ndarray, shape (B,)
        Interval length, s.
    """

    t: np.ndarray
    w: np.ndarray
    h: np.ndarray

    def take(self, index) -> "Rule":
        """The rules of some members.

        Parameters
        ----------
        index : int, slice or ndarray
            Which members.
        """
        return Rule(self.t[index], self.w[index], self.h[index])


def graded_rule(h, rates, decays, slow, panels=None) -> Rule:
    """`panels` panels per member, each spanning an equal part of the phase Φ(h) (module docstring), `NODES` nodes each.

    The breakpoints solve Φ(t) = jΦ(h)/panels by bisection (Φ increases
    with t); one panel is the plain Gauss–Legendre rule on [0, h]. Every
    member's nodes and weights depend on its own parameters only.

    Parameters
    ----------
    h, rates, decays, slow
        As for `panel_count`.
    panels : ndarray of int, shape (B,), optional
        Panels per member; default `panel_count`.
    """
    h = np.asarray(h, dtype=float)
    panels = np.asarray(panel_count(h, rates, decays, slow) if panels is None else panels)
    j = np.arange(1, int(panels.max(initial=1)))[None, :]
    inside = j < panels[:, None]
    target = _phase(h[:, None], rates, decays, slow) * np.where(inside, j / panels[:, None], 1.0)
    lo, hi = np.zeros_like(target), np.broadcast_to(h[:, None], target.shape)
    for _ in range(60 if target.size else 0):  # one panel each: no inner breakpoint to place
        mid = 0.5 * (lo + hi)
        below = _phase(mid, rates, decays, slow) < target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    inner = np.where(inside, 0.5 * (lo + hi), h[:, None])
    breaks = np.concatenate([np.zeros((h.size, 1)), inner, h[:, None]], axis=1)
    start, width = breaks[:, :-1, None], np.diff(breaks, axis=1)[:, :, None]
    fractions, weights = gauss_legendre(NODES)
    J = NODES * (breaks.shape[1] - 1)
    t = (start + width * fractions).reshape(h.size, J)
    w = (width * weights).reshape(h.size, J)
    return Rule(t, w, h)


def node_sum(a):
    """Σ over the node axis (axis 1) of a (B, J, …) array, left to right.

    Sequential, so a member's zero-weight padding (trailing) leaves its sum
    unchanged bit for bit: the batch's widest rule adds nothing to a member's
    position (which still agrees with its run alone to round-off only, as
    numpy's SIMD sin/cos round arrays of other shapes differently;
    docs/simulator.md, "Batches").

    Parameters
    ----------
    a : ndarray, shape (B, J, …)
        Values at the nodes.
    """
    if a.shape[1] > 32:
        return np.cumsum(a, axis=1)[:, -1]
    total = a[:, 0].copy()  # the same additions in the same order as cumsum, a column at a time: for short rules
    for j in range(1, a.shape[1]):  # numpy's accumulate along a short inner axis costs ~15 ns per element, this ~1
        total += a[:, j]
    return total


@dataclass(frozen=True)
class Coefficients:
    """Linear maps of (θ₀, ω₀, held value v) over one interval, and its quadrature rule.

    Attributes
    ----------
    maps : ndarray, shape (B, J + 3, 3)
        Each row c gives c·(θ₀, ω₀, v): rows 0 … J − 1 are Δ = θ − θ₀ at
        the rule's nodes (rad); row J the correction ∫₀ʰ Δ dt − Σⱼ wⱼΔⱼ
        (∫Δ dt in closed form, minus the rule applied to Δ; rad·s); row
        J + 1 θ(h) (rad); row J + 2 ω(h) (rad/s).
    rule : Rule
    """

    maps: np.ndarray
    rule: Rule

    def take(self, index) -> "Coefficients":
        """The coefficients of some members.

        Parameters
        ----------
        index : int, slice or ndarray
            Which members.
        """
        return Coefficients(self.maps[index], self.rule.take(index))


def _coefficients(delta, integral, theta, omega, rule: Rule) -> Coefficients:
    """Stack the maps: delta (B, J, 3) at the nodes, integral, theta, omega (B, 3) (`Coefficients.maps`)."""
    correction = integral - node_sum(rule.w[:, :, None] * delta)
    return Coefficients(np.concatenate([delta, np.stack([correction, theta, omega], axis=1)], axis=1), rule)


def _with_end(rule: Rule):
    """Node times and the end, shape (B, J + 1), s."""
    return np.concatenate([rule.t, rule.h[:, None]], axis=1)


def constant_input(tau, rule: Rule) -> Coefficients:
    """Coefficients for a held steering-rate command u (v = u): KB eq 6 with constant input.

    Δ(t) = a(t)ω₀ + (t − a(t))u; ∫₀ʰ a dt = τ(h − a(h)), ∫₀ʰ t dt = h²/2.

    Parameters
    ----------
    tau : ndarray, shape (B,)
        Steering time constant, s (>= 0).
    rule : Rule
        Nodes and interval lengths (h > 0).
    """
    tau = np.asarray(tau, dtype=float)
    h = rule.h
    t = _with_end(rule)
    lag = tau[:, None] > 0
    safe_tau = np.where(lag, tau[:, None], 1.0)
    decay = np.where(lag, np.exp(-t / safe_tau), 0.0)
    a = np.where(lag, -safe_tau * np.expm1(-t / safe_tau), 0.0)
    zero = np.zeros_like(h)
    delta = np.stack([np.zeros_like(t), a, t - a], axis=-1)
    lagged = tau * (h - a[:, -1])
    integral = np.stack([zero, lagged, 0.5 * h * h - lagged], axis=-1)
    theta = np.stack([np.ones_like(h), a[:, -1], h - a[:, -1]], axis=-1)
    omega = np.stack([zero, decay[:, -1], 1.0 - decay[:, -1]], axis=-1)
    return _coefficients(delta[:, :-1], integral, theta, omega, rule)


def servo(tau, k, rule: Rule) -> Coefficients:
    """Coefficients for a held reference δ̃ (v = δ̃) with the servo u = k(δ̃ − θ) closed (KB eq 7).

    exp(A t) = [[P, Q], [R, S]] of the 2 × 2 matrix A = [[0, 1], [−k/τ, −1/τ]]
    in closed form: with s = −1/(2τ) (half the trace) and q² = s² − k/τ,
    exp(A t) = e^(st)[C·I + S·(A − sI)], C = cosh(qt), S = sinh(qt)/q
    (cos βt and sin(βt)/β when q² = −β² < 0; S → t as q → 0). Checked
    against scipy's `expm` in the tests (which costs milliseconds per matrix).
    Δ(t) = (P − 1)(θ₀ − δ̃) + Qω₀, and d/dt exp(At) = exp(At)A, i.e.
    Ṗ = −(k/τ)Q, Q̇ = P − Q/τ, gives ∫₀ʰ Q dt = τ(1 − P(h))/k and
    ∫₀ʰ P dt = Q(h) + (1 − P(h))/k (also for τ = 0).

    Parameters
    ----------
    tau, k : ndarray, shape (B,)
        s, 1/s.
    rule : Rule
        Nodes and interval lengths, s.
    """
    tau = np.asarray(tau, dtype=float)
    k = np.asarray(k, dtype=float)
    h = rule.h
    t = _with_end(rule)
    lag = (tau > 0)[:, None]
    safe_tau = np.where(lag, tau[:, None], 1.0)
    s = -0.5 / safe_tau
    q2 = s * s - k[:, None] / safe_tau
    z = np.sqrt(np.abs(q2)) * t
    small = z < 1e-8
    safe_z = np.where(small, 1.0, z)
    C = np.where(q2 >= 0, np.cosh(z), np.cos(z))
    S = t * np.where(small, 1.0, np.where(q2 >= 0, np.sinh(safe_z), np.sin(safe_z)) / safe_z)
    decay = np.exp(s * t)
    P = np.where(lag, decay * (C - s * S), np.exp(-k[:, None] * t))
    Q = np.where(lag, decay * S, 0.0)
    R = np.where(lag, -decay * S * k[:, None] / safe_tau, -k[:, None] * np.exp(-k[:, None] * t))
    S22 = np.where(lag, decay * (C - (1.0 / safe_tau + s) * S), 0.0)
    delta = np.stack([P - 1.0, Q, 1.0 - P], axis=-1)
    Ph, Qh = P[:, -1], Q[:, -1]
    P_minus_1 = Qh + (1.0 - Ph) / k - h
    integral = np.stack([P_minus_1, tau * (1.0 - Ph) / k, -P_minus_1], axis=-1)
    theta = np.stack([Ph, Qh, 1.0 - Ph], axis=-1)
    omega = np.stack([R[:, -1], S22[:, -1], -R[:, -1]], axis=-1)
    return _coefficients(delta[:, :-1], integral, theta, omega, rule)


def propagate(coef: Coefficients, theta0, omega0, v):
    """Over one interval: (Δ at the nodes (B, J), correction (B,), θ at the end (B,), ω at the end (B,)).

    The correction is ∫₀ʰ Δ dt − Σⱼ wⱼΔⱼ, rad·s (`Coefficients.maps`).

    Parameters
    ----------
    coef : Coefficients
        The interval's linear maps and rule.
    theta0, omega0 : ndarray, shape (B,)
        Heading (rad) and rate (rad/s) at the interval's start.
    v : ndarray, shape (B,)
        The held value: command (rad/s) or reference (rad).
    """
    c = coef.maps
    out = c[:, :, 0] * theta0[:, None] + c[:, :, 1] * omega0[:, None] + c[:, :, 2] * v[:, None]
    J = out.shape[1] - 3
    return out[:, :J], out[:, J], out[:, J + 1], out[:, J + 2]


def advance_position(x, y, V, rule: Rule, theta0, delta, correction):
    """x + V∫sin θ, y + V∫cos θ over one interval (KB eq 14).

    ∫sin Δ dt = Σⱼ wⱼ sin Δⱼ + correction (= ∫Δ dt + Σⱼ wⱼ(sin Δⱼ − Δⱼ):
    the linear part exact), ∫cos Δ dt = Σⱼ wⱼ cos Δⱼ, then the sum formulas
    for θ = θ₀ + Δ (module docstring).

    Parameters
    ----------
    x, y : ndarray, shape (B,)
        Position at the start, m.
    V : ndarray, shape (B,)
        Speed, m/s.
    rule : Rule
    theta0 : ndarray, shape (B,)
        Heading at the start, rad.
    delta, correction
        Δ at the nodes (B, J), rad, and ∫Δ dt − Σⱼ wⱼΔⱼ (B,), rad·s (`propagate`).
    """
    w = rule.w
    across = node_sum(w * np.sin(delta)) + correction
    along = node_sum(w * np.cos(delta))
    s0, c0 = np.sin(theta0), np.cos(theta0)
    return x + V * (s0 * along + c0 * across), y + V * (c0 * along - s0 * across)


def advance_held(coef: Coefficients, theta, omega, u, V, x, y):
    """One interval with a held motor input: (x, y, θ, ω) at its end (`propagate`, then `advance_position`).

    Parameters
    ----------
    coef : Coefficients
        The interval's linear maps and rule (`constant_input`).
    theta, omega : ndarray, shape (B,)
        Heading (rad) and rate (rad/s) at the start.
    u : ndarray, shape (B,)
        The motor's input over the interval, rad/s (g times the command).
    V : ndarray, shape (B,)
        Speed, m/s.
    x, y : ndarray, shape (B,)
        Position at the start, m.
    """
    delta, correction, theta_end, omega_end = propagate(coef, theta, omega, u)
    x, y = advance_position(x, y, V, coef.rule, theta, delta, correction)
    return x, y, theta_end, omega_end


class DelayLine:
    """The values computed at t_0 … t_k, as far back as the loop's delay reaches (`delay_split`).

    A ring of `length` rows of `size` members; a value asked for from before t_0 is u_0 (the robot starts as if
    it had been running). A lag shared by every member (an int: KB's robots, one compute delay) reads one row.

    Parameters
    ----------
    size : int
        Members.
    length : int
        Rows kept: the longest lag read plus two.
    """

    def __init__(self, size: int, length: int):
        self.ring = np.zeros((length, size))
        self.members = np.arange(size)
        self.first = None

    def push(self, k: int, value):
        """Store the values computed at t_k.

        Parameters
        ----------
        k : int
            The sample.
        value : ndarray, shape (size,)
            One value per member.
        """
        if self.first is None:
            self.first = value.copy()
        self.ring[k % self.ring.shape[0]] = value

    def back(self, k: int, lag):
        """The value computed at t_(k − lag) (per member; `lag` an int or an int array), u_0 before t_0.

        Parameters
        ----------
        k : int
            The current sample.
        lag : int or ndarray of int
            Samples back.
        """
        j = k - lag
        if isinstance(j, int):
            return self.ring[j % self.ring.shape[0]].copy() if j >= 0 else self.first.copy()
        return np.where(j >= 0, self.ring[j % self.ring.shape[0], self.members], self.first)


class CommandPath:
    """The command's way from the controller to the motor: the drive's velocity smoother, then the delay line.

    The members with a yaw acceleration limit (a finite `step`) pass each computed value through `slew_limit` (its
    state the last output, 0 at the start: Nav2's first output moves from a zero command); the others' values go to
    the `DelayLine` untouched, so a batch without a limit runs the code it ran before the smoother. Whatever computes
    a yaw-rate command (the VFF controller, a path tracker) hands it to `push`; the motor's inputs come from `back`.

    Parameters
    ----------
    size : int
        Members.
    length : int
        Rows of the delay line (`DelayLine`).
    step : ndarray or None
        The smoother's largest change per period, R·T (rad/s, ``inf`` for a member without a limit); None: no member has one.
    """

    def __init__(self, size: int, length: int, step=None):
        self.line = DelayLine(size, length)
        self.limited = None if step is None else np.isfinite(step)
        self.step = step
        self.last = np.zeros(size)

    def push(self, k: int, value):
        """Store the command computed at t_k (rad/s, per member; a servo's reference passes untouched).

        Parameters
        ----------
        k : int
            The sample.
        value : ndarray, shape (size,)
            One command per member.
        """
        if self.limited is not None:
            value = np.where(self.limited, slew_limit(self.last, value, self.step), value)
            self.last = value
        self.line.push(k, value)

    def back(self, k: int, lag):
        """The smoother's output for the command computed at t_(k − lag) (`DelayLine.back`).

        Parameters
        ----------
        k : int
            The current sample.
        lag : int or ndarray of int
            Samples back.
        """
        return self.line.back(k, lag)


def slew_limit(previous, command, step):
    """The velocity smoother's output: `previous` moved towards `command` by at most `step` (Nav2's ``applyConstraints``).

    v_k = v_(k−1) + clip(u_k − v_(k−1), −R·T, R·T) (module docstring): open loop, the
    same limit accelerating and decelerating.

    Parameters
    ----------
    previous : ndarray
        The smoother's last output, rad/s.
    command : ndarray
        The new command, rad/s.
    step : ndarray
        The largest change per period, R·T, rad/s (> 0; inf: none).
    """
    return previous + np.clip(command - previous, -step, step)
