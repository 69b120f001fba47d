"""`sampled`: the discrete-time loop a real VFF controller closes (docs/models.md).

Linearized loop (Koren & Borenstein 1991 eq 6, 7, 10, 14): steering motor
τω̇ + ω = u, heading θ̇ = ω, lateral offset ẋ = Vθ, and the reference
δ = −N·x. With y = x/V the loop gain appears as K = kNV only:

    ω̇ = (u − ω)/τ,   θ̇ = ω,   ẏ = θ,   δ = −(K/k)·y.

(τ = 0: ω = u and the state is (θ, y).) Two structures (``hold``):

* ``"command"``: the computer samples θ_k and δ_k and holds
  u_k = k(δ_k − θ_k) = −kθ_k − K·y_k over [t_k, t_k+1) (CARMEL's case);
* ``"reference"``: the computer samples δ_k and holds it; the steering servo
  closes u = k(δ_k − θ(t)) continuously.

A heading gain c (`Loop.c`, docs/models.md) makes the computer's reference
δ_k = −(K/k)·y_k − c·θ_k (θ is sampled with x): the held command becomes
u_k = −k(1 + c)θ_k − K·y_k, the held reference feeds k·δ_k = −kcθ_k − K·y_k
to the servo. Only F0 changes (F0 = k(1 + c) or kc on θ), so the
characteristic polynomial stays affine in K and everything below applies.

``compute_delay`` = 1 applies the value computed at t_k over [t_k+1, t_k+2)
(one more state: the stored command). The plant is discretized with a
zero-order hold, Φ = e^(AT), Γ = ∫₀ᵀ e^(As) ds·B (module
`matrix_exponential`; python-control's ``sample_system`` is the test
oracle), and closed with the sampled feedback
v_k = −(F0 + K·F1)·x_k.

Numerics: the δ (delta-operator) form
-------------------------------------
As T → 0 the poles z crowd at 1 and a polynomial in z loses every digit
that matters (its coefficients tend to binomial coefficients). Everything
here is therefore computed in the δ form z = 1 + T·w (Middleton & Goodwin,
*Digital Control and Estimation: A Unified Approach*, 1990):
Φ = I + TΨ and Γ = TG with Ψ = (e^(AT) − I)/T and G = Γ/T taken from the
exponential of [[A, I], [0, 0]]·T without forming Φ − I. The characteristic
polynomial becomes, with F = F0 + K·F1 (rank one, so it is affine in K),

    P(w) = (1 + Tw)^c·det(wI − Ψ) + F·adj(wI − Ψ)·G,   c = compute_delay,

whose coefficients stay O(1) as T → 0 and tend to the continuous loop's.
The unit circle |z| = 1 is mapped to the imaginary axis by the bilinear
substitution z = (1 + Tμ/2)/(1 − Tμ/2) (Tustin's w-plane), so
Q(μ) = (1 − Tμ/2)^d·P(μ/(1 − Tμ/2)) is Hurwitz exactly when the sampled
loop is stable, and the crossing gains are those of `pfm_stability.numerics.crossings`
in the s domain, plus the gain at which the degree of Q drops (a pole
passing through z = −1, where Ω → ∞). A crossing at Ω maps back to the
frequency ω = 2·atan(ΩT/2)/T. Verdicts come from the eigenvalues λ of the
δ-form closed-loop matrix (|1 + Tλ| < 1 ⇔ 2 Re λ + T|λ|² < 0), an
independent route; the dominant pole is σ = ln|1 + Tλ|/T (log1p),
ω = arg(1 + Tλ)/T (atan2: π/T for a real negative z).

T = 0 is the continuous loop of KB eq (17) (`continuous`).

Any family's loop: the model takes the continuous part from the loop
(`family.Characteristic.state_space`), so the holonomic robot's double
integrator with its acceleration held (`models.holonomic`) runs the same code —
it is KB's loop with τ = 0 and the command held, its heading feedback k(1 + c)
replaced by c_h and K by κ.

Plant gain and dead time (docs/models.md, "Plant gain and dead time"). The
motor is τω̇ + ω = g·u(t − D): g enters through the loop's steering gain g·k
(`Loop.steering_gain`, in `Characteristic.state_space`). A command computed
at t_k reaches the motor at t_k + d·T + D = t_k + m·T + ε, 0 <= ε < T
(`parameters.dead_time_split`, the simulator's rule), so over [t_k, t_k+1)
the motor holds v_(k−m−1) for the first ε and v_(k−m) after — the modified
z-transform. The state is augmented with the commands still on their way,
s_j = v_(k−j), j = 1 … m + (ε > 0), and

    x_(k+1) = Φ(T)x_k + Γ(T − ε)·v_(k−m) + (Γ(T) − Γ(T − ε))·v_(k−m−1),

Γ(h) = ∫₀ʰ e^(As) ds·B (Φ(T − ε)Γ(ε) = Γ(T) − Γ(T − ε)). In the δ form the
closed-loop matrix is Ψ_a − G_a·(F0 + K·F1, 0 …), still rank one in K, so the
polynomials, crossings and verdicts below run unchanged on the augmented
blocks (`dead_time_plant`). D = 0 runs exactly the code it always ran; D a
whole number of periods is a compute delay of m samples. A dead time inside
the continuous servo (``hold="reference"``) is a delay differential equation,
no sampled loop: refused with one line, as the simulator refuses it. At
T = 0 the loop is the exact delay loop with delay D (`exact_delay`).

NV = 0 (N = 0, `models.base.neutral_reason`): y feeds nothing back, so the
closed-loop matrix's y column is zero and z = 1 (λ = 0) is a pole at every T,
k and c. The verdict and the dominant pole are those of the matrix without
y's row and column, the heading loop (`_judged_eigenvalues`): with the whole
command k(δ − θ) held it can be unstable on its own, even with c = 0.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..checks import check_choice, check_integer
from ..numerics.matrix_exponential import zoh_blocks
from ..parameters import HOLDS, RANGES, dead_time_split
from ..numerics.crossings import StabilityInterval, walk_stable_set
from ..numerics.quasi import sign_change_roots
from ..numerics.routh import schur_cohn_stable
from .base import AffineGainModel, LoopModel, checked
from .continuous import Continuous
from .family import Characteristic

__all__ = ["command_form", "Sampled", "continuous_plant", "discretize", "closed_loop_matrix", "delta_plant", "dead_time_plant", "bilinear_polynomial",
           "MAX_DELAY_STATES", "MAX_EIGEN_STATES", "DelayLine"]


def continuous_plant(loop: Characteristic, hold: str):
    """Continuous part of the sampled loop: (A, B, F0, F1) (`Characteristic.state_space`).

    The held input is v_k = −(F0 + K·F1)·state_k, and ẋ = A x + B v between
    samples, the lateral state last. Steering: states (ω, θ, y) for τ > 0,
    (θ, y) for τ = 0; y = x/V (s); the heading gain c adds kc to F0's θ entry.
    Holonomic: states (v, x), the acceleration held.

    Parameters
    ----------
    loop : Loop or HolonomicLoop
    hold : {"command", "reference"}
        ``"command"`` only for a holonomic loop.

    Returns
    -------
    A, B, F0, F1 : ndarray
    """
    hold = check_choice("hold", hold, HOLDS)
    if loop.dead_time > 0 and hold == "reference":
        raise ValueError(f"dead_time must be 0 with hold=reference for the sampled model (a dead time inside the continuous "
                         f"steering servo makes a delay differential equation between samples, no finite sampled loop; "
                         f"kb_first_order, pade and exact_delay take it, and hold=command with it: docs/models.md); got {loop.dead_time}")
    return loop._state_space(hold)


def discretize(A, B, T: float):
    """Zero-order-hold discretization: Φ = e^(AT), Γ = ∫₀ᵀ e^(As) ds B (`matrix_exponential.zoh_blocks`).

    Parameters
    ----------
    A, B : ndarray
        The continuous-time plant ẋ = Ax + Bu.
    T : float
        Sampling period, s.
    """
    Phi, integral = zoh_blocks(A, T)
    return Phi, integral @ B


@lru_cache(maxsize=4096)
def delta_plant(loop: Characteristic, hold: str):
    """(Ψ, G, F0, F1) with Φ = I + TΨ and Γ = TG, accurate as T → 0.

    Ψ = (e^(AT) − I)/T is formed as (∫₀ᵀ e^(As) ds)·A/T when ‖A‖T <= 1 (no
    cancellation against I), and from Φ directly otherwise; G = (∫₀ᵀ e^(As) ds)·B/T.
    T = 0 gives Ψ = A, G = B (the continuous loop).
    """
    A, B, F0, F1 = continuous_plant(loop, hold)
    if loop.T == 0:
        Psi, G = A.copy(), B.copy()
    else:
        Phi, integral = zoh_blocks(A, loop.T)
        small = np.linalg.norm(A, 1) * loop.T <= 1.0
        Psi = integral @ A / loop.T if small else (Phi - np.eye(A.shape[0])) / loop.T
        G = integral @ B / loop.T
    for array in (Psi, G, F0, F1):
        array.setflags(write=False)
    return Psi, G, F0, F1


MAX_DELAY_STATES = 100_000
"""The most commands on their way (m + (ε > 0), `dead_time_plant`) the sampled model carries: its crossings and verdicts
come from the delay line's structured characteristic (`DelayLine`, work in proportion to the periods in flight); past
this a dead time is a delay loop (`exact_delay`, whose T → 0 limit the sampled loop is)."""

MAX_EIGEN_STATES = 400
"""The most commands on their way for which the dominant pole comes from the eigenvalues of the closed-loop matrix
(`Sampled.rightmost_root`; ~0.1 s at 400): the shift register is a Jordan block at z = 0, whose computed eigenvalues
scatter on a circle of radius ε^(1/m) (0.91 at m = 400), well inside the loop's own poles z = e^(sT) at these periods.
Beyond it the rightmost root is not reported (None) and the searches for T* and D* read the verdict's sign."""

POLYNOMIAL_STATES = 64
"""The most commands on their way for which the characteristic polynomial in z is formed (`Sampled.polynomials`,
`jury_stable`): one of degree ~67 no longer resolves its coefficients."""


@lru_cache(maxsize=4096)
def dead_time_plant(loop: Characteristic, hold: str, compute_delay: int):
    """(Ψ_a, G_a, F0_a, F1_a): the δ-form blocks of the sampled loop whose commands reach the motor d·T + D late.

    The state is (x, v_(k−1), …, v_(k−L)), L = m + (ε > 0) with d·T + D = m·T + ε
    (`parameters.dead_time_split`), and (Φ_cl − I)/T = Ψ_a − G_a·(F0_a + K·F1_a)
    (module docstring). Ψ_a's plant block is `delta_plant`'s Ψ; the commands'
    columns are Γ(T − ε)/T (v_(k−m)) and (Γ(T) − Γ(T − ε))/T (v_(k−m−1)); the
    line shifts by one each period. G_a feeds the new command v_k to the line
    (1/T) and, when m = 0, to the plant after ε (Γ(T − ε)/T).

    Parameters
    ----------
    loop : Loop
        T > 0 and D = `dead_time`, s.
    hold : {"command"}
        ``"reference"`` with D > 0 is refused (`continuous_plant`).
    compute_delay : {0, 1}
        d, samples.
    """
    m, eps, after, before = _delay_split_blocks(loop, hold, compute_delay, MAX_EIGEN_STATES)
    Psi, G = delta_plant(loop, hold)[:2]
    F0, F1 = delta_plant(loop, hold)[2:]
    T = loop.T
    lines = m + (eps > 0)
    n = Psi.shape[0]
    size = n + lines
    Psi_a = np.zeros((size, size))
    Psi_a[:n, :n] = Psi
    if m >= 1:
        Psi_a[:n, n + m - 1] = after[:, 0]
    if eps > 0:
        Psi_a[:n, n + m] = before[:, 0]
    for j in range(1, lines):
        Psi_a[n + j, n + j - 1] = 1.0 / T
    Psi_a[n:, n:] -= np.eye(lines) / T
    G_a = np.zeros((size, 1))
    G_a[n, 0] = 1.0 / T
    if m == 0:
        G_a[:n, 0] = after[:, 0]
    F0_a, F1_a = (np.concatenate([F, np.zeros(lines)]) for F in (F0, F1))
    for array in (Psi_a, G_a, F0_a, F1_a):
        array.setflags(write=False)
    return Psi_a, G_a, F0_a, F1_a


def _check_periods_in_flight(loop: Characteristic, compute_delay: int, most: int, what: str) -> tuple:
    """(m, ε) of the loop (`parameters.dead_time_split`), or ValueError when more than `most` commands are on their way."""
    T = loop.T
    m, eps = dead_time_split(T, compute_delay, loop.dead_time)
    if m + (eps > 0) > most:
        longest = (most - compute_delay) * T
        raise ValueError(f"dead_time must be at most {most - compute_delay} sampling periods, {longest:g} s with T = {T:g} s and "
                         f"compute_delay {compute_delay}, for {what} (exact_delay takes a longer one: the sampled loop's "
                         f"limit as T -> 0; docs/models.md); got {loop.dead_time}")
    return m, eps


def _delay_split_blocks(loop: Characteristic, hold: str, compute_delay: int, most: int) -> tuple:
    """(m, ε, Γ(T − ε)/T, (Γ(T) − Γ(T − ε))/T): the whole periods a command waits (compute delay included), the
    fraction ε, and the δ-form input columns of the command that arrives after ε and of the one before it."""
    m, eps = _check_periods_in_flight(loop, compute_delay, most, "the sampled model's closed-loop matrix" if most == MAX_EIGEN_STATES else "the sampled model")
    A, B = continuous_plant(loop, hold)[:2]
    G = delta_plant(loop, hold)[1]
    after = zoh_blocks(A, loop.T - eps)[1] @ B / loop.T if eps > 0 else G  # Γ(T − ε)/T
    return m, eps, after, G - after  # (Γ(T) − Γ(T − ε))/T = Φ(T − ε)Γ(ε)/T


class DelayLine:
    """The characteristic of the sampled loop whose commands reach the motor m·T + ε late, in structured form.

    With x_(k+1) = Φx_k + Γ_a·v_(k−m) + Γ_b·v_(k−m−1), v_k = −(F0 + K·F1)·x_k (`dead_time_plant`) and the δ form
    Φ = I + TΨ, Γ = T·G, w = (z − 1)/T, the closed-loop poles are the roots of the polynomial of degree N = m + 1 + n

        χ(z) = z^(m+1)·p(w) + z·(r0a + K·r1a)(w) + (r0b + K·r1b)(w),   p = det(wI − Ψ),  r_i· = F_i·adj(wI − Ψ)·G_·,

    (the rank-one terms of `_rank_one`), evaluated without forming its m + n + 2 coefficients: work in proportion to the
    periods in flight, accurate however many (`MAX_DELAY_STATES`). Its crossings of the unit circle are the angles
    θ where K(θ) = −(z^(m+1)p + z·r0a + r0b)/(z·r1a + r1b) is real at z = e^(jθ) (a pole passes outwards as K grows where
    arg K rises with θ, as in s); its poles outside the circle are N less the winding number of χ round it (the
    argument principle, χ having real coefficients: twice the turn over 0 <= θ <= π).

    Parameters
    ----------
    loop : Characteristic
        T > 0 and a dead time D > 0.
    hold : {"command"}
    compute_delay : {0, 1}
    """

    def __init__(self, loop: Characteristic, hold: str, compute_delay: int):
        self.T = loop.T
        m, eps, after, before = _delay_split_blocks(loop, hold, compute_delay, MAX_DELAY_STATES)
        Psi, _, F0, F1 = delta_plant(loop, hold)
        self.m = m
        self.degree = m + 1 + Psi.shape[0]
        self.p = np.poly(Psi)
        self.r0a, self.r1a = (_rank_one(Psi, after, F) for F in (F0, F1))
        self.r0b, self.r1b = (_rank_one(Psi, before, F) if np.any(before) else np.zeros(1) for F in (F0, F1))

    def _parts(self, theta):
        """(lead, gain): χ = lead + K·gain at z = e^(jθ)."""
        z = np.exp(1j * theta)
        w = np.expm1(1j * theta) / self.T
        lead = np.exp(1j * (self.m + 1) * theta) * np.polyval(self.p, w) + z * np.polyval(self.r0a, w) + np.polyval(self.r0b, w)
        return lead, z * np.polyval(self.r1a, w) + np.polyval(self.r1b, w)

    def gain(self, theta):
        """K(θ): the gain that puts a pole at e^(jθ) (real there).

        Parameters
        ----------
        theta : float or ndarray
            Angle on the unit circle, rad (ω = θ/T).
        """
        lead, gain = self._parts(theta)
        return -lead / gain

    def grid(self) -> np.ndarray:
        """Angles in (0, π]: logarithmic near 0, then a step over which z^(m+1) turns by at most π/4 (π/(4·N)); a faster
        turn of χ (a root near the circle) is resolved by `_refine_turns`, a sign change of Im K by the step."""
        uniform = np.linspace(0.0, math.pi, 4 * self.degree + 2)[1:]  # z^(m+1) turns by at most π/4 a step
        return np.unique(np.concatenate([np.geomspace(1e-9 * math.pi, math.pi, 512), uniform]))

    def crossings(self) -> list:
        """Every gain K > 0 at which a pole crosses the unit circle: (K, ω = θ/T rad/s, change of the poles outside as K
        grows: ±2 for a pair, ±1 for a real pole through z = −1, 0 for a touch), sorted by gain."""
        theta = self.grid()
        roots = sign_change_roots(lambda x: np.imag(self.gain(x)), theta)
        gains, slopes = np.real(self.gain(roots)), self._phase_slope(roots)
        out = [(float(K), float(x) / self.T, 2 * _sign(slope)) for K, x, slope in zip(gains, roots, slopes) if K > 0]
        K_pi = float(np.real(self.gain(math.pi)))  # z = −1: K is real there; one real pole passes
        if K_pi > 0:
            out.append((K_pi, math.pi / self.T, _sign(float(self._phase_slope(np.array([math.pi]))[0]))))
        return sorted(out)

    def _phase_slope(self, theta):
        """d arg K/dθ: positive where a pole crossing at e^(jθ) moves outwards as K grows (Re(z̄·dz/dK) ∝ it)."""
        z, w = np.exp(1j * theta), np.expm1(1j * theta) / self.T
        m, T = self.m, self.T
        der = lambda p: np.polyval(np.polyder(p), w) if len(p) > 1 else 0.0 * w  # noqa: E731
        L = np.exp(1j * (m + 1) * theta) * np.polyval(self.p, w) + z * np.polyval(self.r0a, w) + np.polyval(self.r0b, w)
        dL = ((m + 1) * np.exp(1j * m * theta) * np.polyval(self.p, w) + np.exp(1j * (m + 1) * theta) * der(self.p) / T
              + np.polyval(self.r0a, w) + z * der(self.r0a) / T + der(self.r0b) / T)
        M = z * np.polyval(self.r1a, w) + np.polyval(self.r1b, w)
        dM = np.polyval(self.r1a, w) + z * der(self.r1a) / T + der(self.r1b) / T
        dK_dz = -(dL * M - L * dM) / (M * M)
        return np.imag(dK_dz * 1j * z / (-L / M))

    def stable_gains(self) -> StabilityInterval:
        """Every stable gain K: the poles outside at K → 0+ (the heading loop's: the neutral pole z = 1 moves in), moved by
        each crossing's change (`numerics.crossings.walk_stable_set`; the crossings on 0 < θ <= π are all of them)."""
        base = self.outside(0.0, neutral=True)
        if base is None:
            return StabilityInterval(0.0, None, (), ())
        return walk_stable_set(base, self.crossings())

    def outside(self, K: float, neutral: bool = False) -> int | None:
        """Poles with |z| > 1 at gain K (argument principle); None when one is on the circle (a phase jump unresolved).

        Parameters
        ----------
        K : float
            Loop gain, 1/s².
        neutral : bool
            At K = 0 (NV = 0): count without the neutral pole z = 1 (the heading loop's poles: χ/(z − 1), of degree N − 1).
        """
        theta = self.grid()
        f = (lambda x: self._characteristic(x, K) / np.expm1(1j * x)) if neutral else (lambda x: self._characteristic(x, K))
        values = f(theta)
        start = np.real(values[0]) if neutral else f(0.0)  # χ/(z − 1) at z → 1: its real limit (real coefficients)
        theta, values = np.concatenate([[0.0], theta]), np.concatenate([[start], values])
        theta, values = _refine_turns(theta, values, f)
        if theta is None:
            return None
        turn = float(np.sum((np.diff(np.angle(values)) + math.pi) % (2 * math.pi) - math.pi))
        winding = turn / math.pi
        inside = round(winding)
        return None if abs(winding - inside) > 0.25 else self.degree - int(neutral) - int(inside)

    def _characteristic(self, theta, K: float):
        lead, gain = self._parts(theta)
        return lead + K * gain


def _sign(x: float) -> int:
    """+1, −1, or 0 for a slope within round-off of 0 (a pole touching the circle and returning)."""
    return 0 if abs(x) <= 1e-12 else (1 if x > 0 else -1)


def _refine_turns(theta, values, f, step: float = math.pi / 4, rounds: int = 60):
    """Grid points added where the phase of f turns by more than `step` between neighbours (a root near the circle),
    until none does; (None, None) when an interval shrinks to round-off with the jump left (a root on it)."""
    for _ in range(rounds):
        jumps = np.flatnonzero(np.abs((np.diff(np.angle(values)) + math.pi) % (2 * math.pi) - math.pi) > step)
        if jumps.size == 0:
            return theta, values
        lo, hi = theta[jumps], theta[jumps + 1]
        if np.any(hi - lo <= 4e-16 * np.maximum(hi, 1e-300)):
            return None, None
        middle = 0.5 * (lo + hi)
        theta, values = np.concatenate([theta, middle]), np.concatenate([values, f(middle)])
        order = np.argsort(theta, kind="stable")
        theta, values = theta[order], values[order]
    return None, None


def command_form(loop: Characteristic, hold: str, compute_delay: int) -> tuple:
    """(M, n, F0, F1): the sampled loop with its command apart, x_(k+1) = M·x_k + n·v_k, v_k = −(F0 + K·F1)·x_k, so that
    Φ_cl(K) = M − n·(F0 + K·F1) (`closed_loop_matrix`): a nonlinearity acting on the command (a rate limit) or on the
    lateral feedback (the force itself instead of its gradient) enters there.

    The state is `closed_loop_matrix`'s: the plant's, then with compute_delay = 1 the command waiting to be applied
    (v_k enters it and reaches the plant a period later), or with a dead time the commands on their way
    (`dead_time_plant`).

    Parameters
    ----------
    loop : Loop or HolonomicLoop
        T must be > 0.
    hold : {"command", "reference"}
    compute_delay : {0, 1}
    """
    T = loop.T
    if loop.dead_time > 0:
        Psi_a, G_a, F0_a, F1_a = dead_time_plant(loop, hold, compute_delay)
        return np.eye(Psi_a.shape[0]) + T * Psi_a, T * G_a[:, 0], np.array(F0_a), np.array(F1_a)
    Psi, G, F0, F1 = delta_plant(loop, hold)
    n = Psi.shape[0]
    Phi, Gamma = np.eye(n) + T * Psi, T * G[:, 0]
    if compute_delay == 0:
        return Phi, Gamma, np.array(F0), np.array(F1)
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = Phi, Gamma
    waiting = np.zeros(n + 1)
    waiting[n] = 1.0
    return M, waiting, np.concatenate([F0, [0.0]]), np.concatenate([F1, [0.0]])


def closed_loop_matrix(loop: Characteristic, K: float, hold: str, compute_delay: int) -> np.ndarray:
    """Φ_cl of the sampled loop for the loop gain K (kNV, κ; 1/s²).

    Parameters
    ----------
    loop : Loop or HolonomicLoop
        T must be > 0.
    K : float
        Loop gain, 1/s².
    hold : {"command", "reference"}
    compute_delay : {0, 1}

    Returns
    -------
    ndarray
        State transition matrix over one period; with compute_delay = 1 the
        last state is the command waiting to be applied.
    """
    if loop.dead_time > 0:
        return np.eye(dead_time_plant(loop, hold, compute_delay)[0].shape[0]) + loop.T * _delta_matrix(loop, K, hold, compute_delay)
    Psi, G, F0, F1 = delta_plant(loop, hold)
    n = Psi.shape[0]
    Phi, Gamma = np.eye(n) + loop.T * Psi, loop.T * G
    F = (F0 + K * F1)[None, :]
    if compute_delay == 0:
        return Phi - Gamma @ F
    return np.block([[Phi, Gamma], [-F, np.zeros((1, 1))]])


def _delta_matrix(loop: Characteristic, K: float, hold: str, compute_delay: int) -> np.ndarray:
    """(Φ_cl − I)/T without cancellation: its eigenvalues λ give the poles z = 1 + Tλ."""
    if loop.dead_time > 0 and loop.T > 0:
        Psi_a, G_a, F0_a, F1_a = dead_time_plant(loop, hold, compute_delay)
        return Psi_a - G_a @ (F0_a + K * F1_a)[None, :]
    Psi, G, F0, F1 = delta_plant(loop, hold)
    F = (F0 + K * F1)[None, :]
    if compute_delay == 0 or loop.T == 0:
        return Psi - G @ F
    return np.block([[Psi, G], [-F / loop.T, np.full((1, 1), -1.0 / loop.T)]])


def bilinear_polynomial(p_w, degree: int, T: float) -> np.ndarray:
    """Q(μ) = (1 − Tμ/2)^degree · P(μ/(1 − Tμ/2)) for P(w) given descending (degree >= deg P).

    Parameters
    ----------
    p_w : array_like
        P(w), descending coefficients.
    degree : int
        The power of (1 − Tμ/2), >= deg P.
    T : float
        Sampling period, s.
    """
    p = np.asarray(p_w, dtype=float)[::-1]  # ascending: p_i w^i
    factor = np.array([-T / 2, 1.0])  # 1 − Tμ/2, descending
    out = np.zeros(degree + 1)
    for i, coefficient in enumerate(p):
        if coefficient == 0.0:
            continue
        term = np.polymul(np.concatenate([[1.0], np.zeros(i)]), _power(factor, degree - i))
        out = np.polyadd(out, coefficient * term)
    return np.asarray(out[-(degree + 1):], dtype=float)


def _power(poly, m: int):
    out = np.array([1.0])
    for _ in range(m):
        out = np.polymul(out, poly)
    return out


class Sampled(AffineGainModel):
    """The sampled-data loop with zero-order hold, for the loop of any family (`continuous_plant`).

    Parameters
    ----------
    hold : {"command", "reference"}
        What is held between samples (`parameters.HOLDS`, docs/models.md); a
        holonomic robot holds its acceleration command (``"command"``).
    compute_delay : {0, 1}
        Samples between measurement and actuation.
    """

    name = "sampled"
    domain = "z"

    def __init__(self, hold: str = "command", compute_delay: int = 0):
        self.hold = check_choice("hold", hold, HOLDS)
        self.compute_delay = check_integer("compute_delay", compute_delay, 0, 1)

    def options(self) -> dict:
        """``{"hold": …, "compute_delay": …}``: the sampled structure (docs/models.md)."""
        return {"hold": self.hold, "compute_delay": self.compute_delay}

    def __repr__(self) -> str:
        return f"Sampled(hold={self.hold!r}, compute_delay={self.compute_delay})"

    # ------------------------------------------------------------ polynomials
    def _lead(self, loop: Characteristic, Psi: np.ndarray) -> np.ndarray:
        """(1 + Tw)^c·det(wI − Ψ), descending in w (c = compute_delay)."""
        p = np.poly(Psi)
        return np.polymul([loop.T, 1.0], p) if self.compute_delay and loop.T > 0 else p

    def delta_polynomials(self, loop: Characteristic):
        """(D, E) in the δ variable w = (z − 1)/T: P(w) = D(w) + K·E(w), descending.

        D = (1 + Tw)^c det(wI − Ψ) + F0 adj(wI − Ψ) G and E = F1 adj(wI − Ψ) G,
        each rank-one term as det(wI − Ψ + G F) − det(wI − Ψ).

        Parameters
        ----------
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        if loop.dead_time > 0:  # the commands on their way are states (`dead_time_plant`): det(wI − Ψ_a) leads
            _check_periods_in_flight(loop, self.compute_delay, POLYNOMIAL_STATES, "the sampled model's characteristic polynomial")
            Psi, G, F0, F1 = dead_time_plant(loop, self.hold, self.compute_delay)
            lead = np.poly(Psi)
        else:
            Psi, G, F0, F1 = delta_plant(loop, self.hold)
            lead = self._lead(loop, Psi)
        e = _rank_one(Psi, G, F1)
        return np.polyadd(lead, _rank_one(Psi, G, F0)), np.trim_zeros(e, "f") if np.any(e) else np.zeros(1)

    def bilinear_polynomials(self, loop: Characteristic):
        """(D, E) in μ (z = (1 + Tμ/2)/(1 − Tμ/2)): stable ⇔ D + K·E is Hurwitz, descending, one length.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`); T > 0, s.
        """
        d, e = self.delta_polynomials(loop)
        degree = len(np.trim_zeros(d, "f")) - 1
        return bilinear_polynomial(d, degree, loop.T), bilinear_polynomial(e, degree, loop.T)

    def parts(self, loop: Characteristic):
        """(P0, P1, P2) in μ: the characteristic polynomial P0 + δ·P1 + K·P2 (Tustin's map of the δ form; T = 0: `continuous`'s).

        P1 is the rank-one term of the unit damping row (the family's F0 at δ = 1 less at δ = 0).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if loop.T == 0:
            return Continuous().parts(loop)
        Psi, G, F0, F1 = delta_plant(loop.with_damping(0.0), self.hold)
        unit = delta_plant(loop.with_damping(1.0), self.hold)[2] - F0
        lead = np.polyadd(self._lead(loop, Psi), _rank_one(Psi, G, F0))
        degree = len(np.trim_zeros(lead, "f")) - 1
        return tuple(bilinear_polynomial(p, degree, loop.T) for p in (lead, _rank_one(Psi, G, unit), _rank_one(Psi, G, F1)))

    def polynomials(self, loop: Characteristic):
        """(D(z), E(z)): det(zI − Φ_cl(K)) = D + K·E, descending in z (T > 0).

        Formed from the δ form, P_z(z) = Σ p_i T^(d−i) (z − 1)^i; a polynomial
        in z is ill-conditioned for T → 0 (use `bilinear_polynomials` there).

        Parameters
        ----------
        loop : Loop
            τ (s), T (s), k (1/s) and the heading gain c.
        """
        d, e = self.delta_polynomials(loop)
        degree = len(np.trim_zeros(d, "f")) - 1
        return _to_z(d, degree, loop.T), _to_z(e, degree, loop.T)

    # --------------------------------------------------------------- queries
    def stable_gains(self, loop: Characteristic):
        """Every stable loop gain K: the crossings of the bilinear polynomials, each stretch decided by the eigenvalues
        (T = 0: the continuous loop, KB eq 17 for the steering robot, exactly).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if loop.T == 0:
            return loop.delay_interval() if loop.dead_time > 0 else Continuous().stable_gains(loop)
        if loop.dead_time > 0:  # the delay line's crossings of the unit circle and the count they move (`DelayLine`)
            return DelayLine(loop, self.hold, self.compute_delay).stable_gains()
        d, e = self.bilinear_polynomials(loop)
        return self._interval(d, e, lambda K: self._stable(loop.gain_of(K), loop), loop)

    def _frequency(self, Omega: float, loop: Characteristic) -> float:
        """ω (rad/s) of the unit-circle point that μ = jΩ maps to."""
        return 2.0 * math.atan(Omega * loop.T / 2.0) / loop.T if loop.T > 0 else Omega

    def _infinite_frequency(self, loop: Characteristic) -> float:
        """A pole passing through z = −1 when Q's degree drops: ω = π/T."""
        return math.pi / loop.T

    def _delta_eigenvalues(self, gain: float, loop: Characteristic) -> np.ndarray:
        return np.linalg.eigvals(_delta_matrix(loop, loop.loop_gain(gain), self.hold, self.compute_delay))

    def _judged_eigenvalues(self, gain: float, loop: Characteristic) -> np.ndarray:
        """The λ the verdict judges: every one, or at gain 0 those of the heading loop (y's row and column removed)."""
        if gain != 0:
            return self._delta_eigenvalues(gain, loop)
        y = delta_plant(loop, self.hold)[0].shape[0] - 1  # the lateral state: the plant's last
        matrix = _delta_matrix(loop, 0.0, self.hold, self.compute_delay)
        return np.linalg.eigvals(np.delete(np.delete(matrix, y, axis=0), y, axis=1))

    @checked
    def eigenvalues(self, gain: float, loop: Characteristic) -> np.ndarray:
        """Closed-loop poles z (T > 0), as 1 + Tλ.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return 1.0 + loop.T * self._delta_eigenvalues(gain, loop)

    @checked
    def is_stable(self, gain: float, loop: Characteristic) -> bool:
        """Every pole strictly inside the unit circle: 2 Re λ + T|λ|² < 0 (T = 0: the continuous loop by Routh;
        NV = 0: every pole but the neutral z = 1, `_judged_eigenvalues`).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return self._stable(gain, loop)

    def _stable(self, gain: float, loop: Characteristic) -> bool:
        if loop.T == 0:
            return _limit(loop)._stable(gain, loop)
        if loop.dead_time > 0:  # the delay line's poles outside the circle (`DelayLine.outside`; NV = 0 without z = 1)
            return DelayLine(loop, self.hold, self.compute_delay).outside(loop.loop_gain(gain), neutral=gain == 0) == 0
        lam = self._judged_eigenvalues(gain, loop)
        size = np.abs(lam)
        return bool(np.all(2.0 * lam.real + (loop.T * size) * size < 0.0))  # T|λ|·|λ|: no overflow of |λ|² at tiny T

    @checked
    def jury_stable(self, gain: float, loop: Characteristic) -> bool:
        """Schur–Cohn (Jury) verdict on det(zI − Φ_cl), independent of the eigenvalues (T = 0: the continuous loop's).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if loop.T == 0:
            return self._stable(gain, loop)
        return schur_cohn_stable(self.characteristic(gain, loop))

    @checked
    def rightmost_root(self, gain: float, loop: Characteristic) -> complex:
        """Dominant pole as s = ln(z)/T: σ = ln|z|/T (1/s), ω = arg(z)/T in [0, π/T] (rad/s); NV = 0: the heading loop's.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if loop.T == 0:
            return _limit(loop).rightmost_root(gain, loop)
        if loop.dead_time > 0 and sum(dead_time_split(loop.T, self.compute_delay, loop.dead_time)) > MAX_EIGEN_STATES:
            return None  # more commands in flight than the eigenvalues resolve (`MAX_EIGEN_STATES`); the verdict does not need it
        lam = self._judged_eigenvalues(gain, loop)
        T = loop.T
        sigma = _log_radius(lam, T) / T
        omega = np.abs(np.arctan2(T * lam.imag, 1.0 + T * lam.real)) / T
        i = int(np.argmax(sigma))
        return complex(float(sigma[i]), float(omega[i]))

    @checked
    def roots(self, gain: float, loop: Characteristic) -> np.ndarray:
        """All closed-loop poles z (T > 0); the continuous roots s at T = 0.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return self._delta_eigenvalues(gain, loop) if loop.T == 0 else 1.0 + loop.T * self._delta_eigenvalues(gain, loop)

    @checked
    def critical_dead_time(self, gain: float, loop: Characteristic) -> float | None:
        """D*, s (`LoopModel.critical_dead_time`); None with ``hold="reference"``: the sampled model takes no dead time
        inside the continuous servo (`continuous_plant`), so it has no D* (the continuous-time models give theirs); None
        too when the loop is still stable at the longest dead time the delay line carries at this T
        ((`MAX_DELAY_STATES` − d − 1)·T, shorter than 10 s only for periods below 0.1 ms).

        Parameters
        ----------
        gain : float
            Loop gain NV, 1/s.
        loop : Loop
            τ, T, k, c and g (its own D is replaced).
        """
        if self.hold == "reference":
            return None
        from .dead_time import search_dead_time

        if loop.T == 0:  # the loop's own limit, the delay loop with delay D: its exact margin
            return _limit(loop).critical_dead_time(gain, loop)
        most = (MAX_DELAY_STATES - self.compute_delay - 1) * loop.T  # the longest dead time the delay line carries
        if most >= RANGES["dead_time"].high:
            return search_dead_time(self, gain, loop)
        found = search_dead_time(self, gain, loop, high=most)
        return None if math.isinf(found) else found  # stable as far as the model reaches: no D* it can give

    @checked
    def critical_delay(self, gain: float, loop: Characteristic) -> float:
        """T*, s (`LoopModel.critical_delay`); with a dead time D the periods searched are those whose delay line the
        model carries, T >= D/(`MAX_DELAY_STATES` − d − 1) (at T = 0 the loop's own limit, the delay loop with delay D,
        is judged first: T* = 0 when it is unstable).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged; its own T, s, is replaced by the searched ones.
        """
        if loop.dead_time <= 0:
            return LoopModel.critical_delay.__wrapped__(self, gain, loop)

        def search():
            start, rtol, atol = loop.delay_search(gain)
            return max(start, loop.dead_time / (MAX_DELAY_STATES - self.compute_delay - 1)), RANGES["T"].high, {"rtol": rtol, "atol": atol}

        return self.first_loss(gain, loop._with_delay, 0.0, search)

    def searched_growth_rates(self, gain: float, loops) -> np.ndarray:
        """The growth rates the searches for T*, k* and D* measure (`LoopModel.searched_growth_rates`): `growth_rates`,
        and for a loop with a dead time `_searched_growth`.

        T* with a dead time D (docs/models.md, "Plant gain and dead time"): at T = 0 the loop is its own limit, the exact
        delay loop with delay D (T* = 0 if that is unstable); at T > 0 the sampled loop itself, every probe.

        Parameters
        ----------
        gain : float
            The family's loop gain, already checked.
        loops : sequence of Characteristic
            The probed loops.
        """
        loops = list(loops)
        if not any(loop.dead_time > 0 for loop in loops):
            return self._growth_rates(gain, loops)
        return np.array([self._searched_growth(gain, loop) for loop in loops])

    def _searched_growth(self, gain: float, loop: Characteristic) -> float:
        """The growth rate (1/s) a search over T or D measures: the dominant pole's where the eigenvalues resolve it
        (`MAX_EIGEN_STATES`), else the verdict's sign (−1 stable, +1 not: the delay line's count, `DelayLine.outside`)."""
        root = self.rightmost_root(gain, loop)
        if root is not None:
            return root.real
        return -1.0 if self._stable(gain, loop) else 1.0

    def _growth_rates(self, NV: float, loops) -> np.ndarray:
        """σ = max ln|z|/T (1/s) at the gain for each loop, all exponentials and eigenvalues in one batch
        (loops with a dead time one by one, `rightmost_root`)."""
        loops = list(loops)
        late = [i for i, loop in enumerate(loops) if loop.dead_time > 0]
        if late:
            sigma = np.empty(len(loops))
            for i in late:
                root = self.rightmost_root(NV, loops[i])
                sigma[i] = root.real if root is not None else math.nan
            rest = [i for i in range(len(loops)) if i not in set(late)]
            if rest:
                sigma[rest] = self._growth_rates(NV, [loops[i] for i in rest])
            return sigma
        K = np.array([loop.loop_gain(NV) for loop in loops])
        T = np.array([loop.T for loop in loops])
        plants = [loop._state_space(self.hold) for loop in loops]
        A, B, F0, F1 = (np.stack([p[i] for p in plants]) for i in range(4))
        n = A.shape[-1]
        Psi, G = A.copy(), B.copy()
        sampled = T > 0
        if sampled.any():
            Phi, integral = zoh_blocks(A[sampled], T[sampled])
            t = T[sampled, None, None]
            small = (np.abs(A[sampled]).sum(axis=1).max(axis=1) * T[sampled] <= 1.0)[:, None, None]
            Psi[sampled] = np.where(small, integral @ A[sampled] / t, (Phi - np.eye(n)) / t)
            G[sampled] = integral @ B[sampled] / t
        F = (F0 + K[:, None] * F1)[:, None, :]
        closed = Psi - G @ F
        keep = np.arange(n + self.compute_delay)  # the states judged: at NV = 0 not y, the plant's last (`_judged_eigenvalues`)
        keep = keep[keep != n - 1] if NV == 0 else keep
        judged, plant = np.ix_(keep, keep), np.ix_(keep[keep < n], keep[keep < n])
        if self.compute_delay and sampled.any():
            t = T[sampled, None, None]
            top = np.concatenate([Psi[sampled], G[sampled]], axis=2)
            bottom = np.concatenate([-F[sampled] / t, -np.ones((int(sampled.sum()), 1, 1)) / t], axis=2)
            lam = np.linalg.eigvals(np.concatenate([top, bottom], axis=1)[(slice(None),) + judged])
        else:
            lam = np.linalg.eigvals(closed[sampled][(slice(None),) + plant]) if sampled.any() else np.empty((0, n))
        sigma = np.empty(len(loops))
        sigma[sampled] = np.max(_log_radius(lam, T[sampled, None]), axis=1) / T[sampled]
        if (~sampled).any():
            sigma[~sampled] = np.linalg.eigvals(closed[~sampled][(slice(None),) + plant]).real.max(axis=1)
        return sigma


def _limit(loop: Characteristic):
    """The model a sampled loop tends to as T → 0: `continuous`, or `exact_delay` with the delay D when D > 0."""
    if loop.dead_time > 0:
        from .exact_delay import ExactDelay  # imports `pade`, which imports nothing of this module

        return ExactDelay()
    return Continuous()


def _rank_one(Psi, G, F) -> np.ndarray:
    """F·adj(wI − Ψ)·G = det(wI − Ψ + G F) − det(wI − Ψ), descending in w (zero for F = 0)."""
    if not np.any(F):
        return np.zeros(1)
    return np.polysub(np.poly(Psi - G @ F[None, :]), np.poly(Psi))


def _log_radius(lam, T):
    """ln|1 + Tλ| without cancellation: log1p(2T Re λ + T²|λ|²)/2 while |Tλ| < 1/2, ln|1 + Tλ| beyond
    (−inf for a pole at z = 0, never NaN)."""
    lam = np.asarray(lam)
    T = np.asarray(T, dtype=float)
    near = np.abs(T * lam) < 0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        small = 0.5 * np.log1p(np.where(near, 2.0 * T * lam.real + T * T * np.abs(lam) ** 2, 0.0))
        large = np.log(np.abs(1.0 + T * lam))
    return np.where(near, small, large)


def _to_z(p_w, degree: int, T: float) -> np.ndarray:
    """P_z(z) = Σ p_i T^(degree − i) (z − 1)^i for P(w) = Σ p_i w^i (descending in and out)."""
    p = np.asarray(p_w, dtype=float)[::-1]
    out = np.zeros(degree + 1)
    for i, coefficient in enumerate(p):
        if coefficient != 0.0:
            out = np.polyadd(out, coefficient * T ** (degree - i) * _power(np.array([1.0, -1.0]), i))
    return np.asarray(out[-(degree + 1):], dtype=float)
