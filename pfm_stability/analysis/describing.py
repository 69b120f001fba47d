"""Describing functions and harmonic balance: limit cycles of a linear loop closed through a nonlinearity (docs/wobble.md).

A loop G(s) closed through a static (or amplitude-dependent) nonlinearity whose
input is A·sin ωt is replaced by its first harmonic: the describing function

    N(A) = (b₁ + j·a₁)/A,   b₁ = (1/π)∫₀^{2π} F(A sin θ) sin θ dθ,   a₁ = (1/π)∫₀^{2π} F(A sin θ) cos θ dθ,

and a limit cycle of amplitude A and frequency ω solves the harmonic balance
G(jω)·N(A) = −1 (Slotine & Li, Applied Nonlinear Control, §5.4). This module is
general — any loop transfer, any describing function:

* `describing_function(F, A)`: N(A) of a static nonlinearity F by quadrature on θ
  (the trapezoidal rule on the circle: exact for a trigonometric polynomial of the
  odd part up to the node count, spectrally accurate for a smooth F);
* `saturation_df(A, M)`, `sine_df(A)`: the closed forms of two nonlinearities the
  robot's loop needs (a unit-slope saturation at ±M; sin x);
* `rate_limit_df(A, ω, R, T)`: a rate (slew) limiter's, amplitude- and
  frequency-dependent (ρ = Aω/R) with a phase lag — in closed form for a
  continuous limiter, and for one that acts once per period T on a sequence
  (a velocity smoother at the controller's rate) the closed form times a
  tabulated correction (`rate_limit_correction`); `rate_limit_waveform`, its
  output over a period;
* `harmonic_balance(G, N, amplitudes, frequencies)`: every (A, ω) with
  G(jω)N(A) = −1, found where the Nyquist curve G(jω) crosses the curve −1/N(A) and
  polished by Newton on the two real equations; each cycle carries Loeb's
  stability test (a small increase of A must decay).

**The rate limiter** (docs/wobble.md, "The drive's rate limit"). Its output y follows
the input x = A sin θ (θ = ωt) while |ẋ| <= R and ramps at ±R otherwise. With r = 1/ρ and
a = arccos r, for 1 < ρ < ρ_t = √(4 + π²)/2 it follows x over [θ₁, π − a] around each peak
(it leaves where ẋ = −R) and ramps down until it meets x again at θ₁ + π, so θ₁ solves
r(θ₁ + a) = √(1 − r²) + sin θ₁ (increasing in θ₁ on (a, π − a): one root), and b₁, a₁
are the integrals of sin θ and of the ramp in closed form. For ρ >= ρ_t the follow
segment has shrunk to a point: a triangle of slope R and amplitude πR/(2ω), its peak
where it touches x, sin θ_p = πr/2, so N = (4/(πρ))·e^(−j·arccos(π/(2ρ))); ρ <= 1: N = 1.

Loeb's test (stated for any characteristic function Δ(s, A) whose zero at s = jω is
the cycle): the perturbed root moves by δs = −(Δ_A/Δ_s)·δA, and the cycle is stable
when a larger amplitude makes the loop decay, Re(δs)/δA < 0, i.e.
Re(j·Δ_A/Δ_ω) > 0 (Δ_s = −j·Δ_ω by analyticity). 1 + G(jω)N(A) is Δ divided by the
loop's denominator, which changes neither the zero nor the sign of the test there.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from ..numerics.solve import newton_increasing

__all__ = [
    "Cycle",
    "describing_function",
    "harmonic_content",
    "saturation_df",
    "saturation_df_for_output",
    "sine_df",
    "J1_PEAK",
    "rate_limit_df",
    "rate_limit_waveform",
    "rate_limit_correction",
    "RATE_LIMIT_TRIANGLE",
    "harmonic_balance",
    "loeb_stable",
]

_NODES = 256
"""Quadrature nodes on the circle (`describing_function`): the fundamental of an odd F is exact for harmonics below 255."""


@dataclass(frozen=True)
class Cycle:
    """One solution of the harmonic balance G(jω)·N(A) = −1.

    Attributes
    ----------
    amplitude : float
        A, the amplitude at the nonlinearity's input (its unit).
    omega : float
        ω, rad/s.
    stable : bool
        Loeb's test: True when a slightly larger amplitude decays (an attracting cycle).
    residual : float
        |1 + G(jω)N(A)| at the solution.
    """

    amplitude: float
    omega: float
    stable: bool
    residual: float


def _circle(nodes: int) -> np.ndarray:
    return 2.0 * math.pi * (np.arange(nodes) + 0.5) / nodes


def describing_function(F, A, *, nodes: int = _NODES):
    """N(A) = (b₁ + j·a₁)/A of a static nonlinearity F for input amplitudes A (module docstring).

    Parameters
    ----------
    F : callable
        y = F(x), vectorized over numpy arrays (x in the input's unit).
    A : float or array_like
        Input amplitudes, > 0 (the input's unit).
    nodes : int
        Points of the trapezoidal rule on [0, 2π) (default 256): exact for the
        first harmonic of any trigonometric polynomial F(A sin θ) of degree < nodes − 1.

    Returns
    -------
    complex or ndarray of complex
        The describing function (output unit per input unit); real for a single-valued F.

    Raises
    ------
    ValueError
        For an amplitude that is not finite and > 0.
    """
    amplitudes = np.asarray(A, dtype=float)
    if not np.all(np.isfinite(amplitudes) & (amplitudes > 0)):
        raise ValueError(f"describing_function needs amplitudes A > 0 and finite; got {A!r}")
    theta = _circle(int(nodes))
    s, c = np.sin(theta), np.cos(theta)
    y = np.asarray(F(amplitudes[..., None] * s), dtype=float)
    b1 = 2.0 * np.mean(y * s, axis=-1)
    a1 = 2.0 * np.mean(y * c, axis=-1)
    N = (b1 + 1j * a1) / amplitudes
    return complex(N) if np.ndim(N) == 0 else N


def harmonic_content(F, A, harmonic: int = 3, *, nodes: int = _NODES):
    """|h-th harmonic| / |fundamental| of F(A sin θ): how far the output is from a sinusoid (a DF's trust measure).

    Parameters
    ----------
    F : callable
        y = F(x), vectorized.
    A : float or array_like
        Input amplitudes, > 0.
    harmonic : int
        Which harmonic (3 for an odd F, whose even harmonics vanish).
    nodes : int
        Points of the trapezoidal rule on [0, 2π).

    Returns
    -------
    float or ndarray
        The ratio (0 for a linear F; 1/3 for an ideal relay's third harmonic).
    """
    amplitudes = np.asarray(A, dtype=float)
    theta = _circle(int(nodes))
    y = np.asarray(F(amplitudes[..., None] * np.sin(theta)), dtype=float)
    spectrum = np.abs(np.mean(y[..., None, :] * np.exp(-1j * np.outer([1, harmonic], theta)), axis=-1))
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(spectrum[..., 0] > 0, spectrum[..., 1] / spectrum[..., 0], 0.0)
    return float(ratio) if np.ndim(ratio) == 0 else ratio


def saturation_df(A, M: float):
    """N(A) of a unit-slope saturation at ±M: 1 for A <= M, (2/π)(asin r + r√(1 − r²)) with r = M/A above.

    Parameters
    ----------
    A : float or array_like
        Input amplitudes, >= 0.
    M : float
        Saturation level, > 0 (the input's unit).

    Returns
    -------
    float or ndarray
        Dimensionless, in (0, 1].
    """
    amplitudes = np.asarray(A, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.clip(M / amplitudes, 0.0, 1.0)
    N = np.where(amplitudes <= M, 1.0, (2.0 / math.pi) * (np.arcsin(r) + r * np.sqrt(1.0 - r * r)))
    return float(N) if np.ndim(N) == 0 else N


def saturation_df_for_output(U, M: float):
    """The saturation's N at the input amplitude E whose output fundamental E·N(E) is U: 1 for U <= M, 0 for U >= 4M/π.

    E·N(E) rises from M (at E = M) to 4M/π (E → ∞); with r = M/E it is
    (2M/π)(asin r/r + √(1 − r²)), decreasing in r with slope (2M/(πr²))(r√(1 − r²) − asin r), inverted
    elementwise by safeguarded Newton (`numerics.solve.newton_increasing`), and N = r·U/M.

    Parameters
    ----------
    U : float or array_like
        Output fundamentals, >= 0 (the output's unit).
    M : float
        Saturation level, > 0.

    Returns
    -------
    float or ndarray
        Dimensionless, in [0, 1]; E = U/N.
    """
    U = np.asarray(U, dtype=float)
    ratio = U / M
    inside = (ratio > 1.0) & (ratio < 4.0 / math.pi)

    target = np.where(inside, ratio, 1.1)

    def excess(r):  # target − h(r): increasing in r
        root = np.sqrt(1.0 - r * r)
        return target - (2.0 / math.pi) * (np.arcsin(r) / r + root), -(2.0 / (math.pi * r * r)) * (r * root - np.arcsin(r))

    r = newton_increasing(excess, np.full(target.shape, 1e-12), np.ones(target.shape), rtol=1e-15) if np.any(inside) else np.ones_like(ratio)
    N = np.where(ratio <= 1.0, 1.0, np.where(inside, r * ratio, 0.0))
    return float(N) if np.ndim(N) == 0 else N


J1_PEAK = 1.8411837813406593
"""Θ where 2J₁(Θ), the fundamental of sin(Θ sin ωt), peaks (the first zero of J₁′): a larger heading swing makes less
lateral motion."""


def sine_df(A):
    """N(A) of sin x: 2·J₁(A)/A (1 at A = 0), dimensionless.

    Parameters
    ----------
    A : float or array_like
        Input amplitudes, rad, >= 0.
    """
    amplitudes = np.asarray(A, dtype=float)
    safe = np.where(amplitudes > 0, amplitudes, 1.0)
    N = np.where(amplitudes > 1e-8, 2.0 * special.j1(safe) / safe, 1.0 - amplitudes**2 / 8.0)
    return float(N) if np.ndim(N) == 0 else N


RATE_LIMIT_TRIANGLE = math.sqrt(4.0 + math.pi**2) / 2.0
"""ρ_t = √(4 + π²)/2 ≈ 1.862: from this ρ = Aω/R on a rate limiter's output is a triangle (module docstring)."""


def _follow_start(r):
    """θ₁ of the mixed regime (module docstring) for r = 1/ρ in (1/ρ_t, 1), rad: the root of f(θ) = r(θ + a) − √(1 − r²) − sin θ.

    f increases on (a, π − a) and is convex there (f″ = sin θ > 0), with f(π − a) >= 0: Newton from π − a falls onto the
    root monotonically, no step leaving the bracket; it converges quadratically, linearly only as ρ → 1 (f′ → 0 at the
    root), where `numerics.solve.newton_increasing` finishes what 40 steps leave.
    """
    a = np.arccos(r)
    root = np.sqrt(1.0 - r * r)
    t = math.pi - a
    for _ in range(40):
        step = (r * (t + a) - root - np.sin(t)) / (r - np.cos(t))
        t = t - step
        if np.all(np.abs(step) <= 1e-15 * t):
            return t
    return newton_increasing(lambda t: (r * (t + a) - root - np.sin(t), r - np.cos(t)), a, math.pi - a, rtol=1e-15)


def rate_limit_df(A, omega, R: float, T: float = 0.0):
    """N of a rate (slew) limiter for the input A·sin ωt: complex, |N| <= 1, a phase lag (module docstring).

    Continuous (T = 0): a function of ρ = Aω/R alone, 1 for ρ <= 1, the mixed regime's closed form up to
    `RATE_LIMIT_TRIANGLE`, (4/(πρ))·e^(−j·arccos(π/(2ρ))) beyond. Sampled (T > 0): a limiter that moves once per
    period T by at most R·T (`sim.robot.slew_limit`) on the samples A·sin(ωkT), its N the fundamental (DTFT at ω)
    of its output sequence over the input's: 1 while the largest step 2A·sin(ωT/2) is within R·T, and
    N_c(s)·`rate_limit_correction`(s, ωT) above, with s = 2A·sin(ωT/2)/(R·T) = ρ·sin(ωT/2)/(ωT/2) (→ ρ as ωT → 0).

    Parameters
    ----------
    A : float or array_like
        Input amplitude, >= 0 (the input's unit, e.g. rad/s).
    omega : float or array_like
        Angular frequency, rad/s, > 0 (broadcast with A).
    R : float
        The limit on the input's rate of change, > 0 (unit of A per second; inf: none).
    T : float
        0 for a continuous limiter; else the period at which it acts, s (ωT in [0, `_CORRECTION_OMEGA_T`]: the
        correction's table; beyond, its edge).

    Returns
    -------
    complex or ndarray of complex
    """
    if not R > 0:
        raise ValueError(f"rate_limit_df needs a rate limit R > 0; got {R!r}")
    if np.ndim(A) == 0 and np.ndim(omega) == 0:  # one value (a harmonic balance's Newton step): no masks
        A, omega = float(A), float(omega)
        if not T > 0:
            return complex(_continuous_rate_df(A * omega / R))
        s = 2.0 * A * math.sin(0.5 * omega * T) / (R * T)
        return complex(_continuous_rate_df(s) * rate_limit_correction(s, omega * T)) if s > 1.0 else 1.0 + 0j
    A, omega = np.broadcast_arrays(np.asarray(A, dtype=float), np.asarray(omega, dtype=float))
    if T > 0:
        wT = omega * T
        s = 2.0 * A * np.sin(0.5 * wT) / (R * T)
        return np.where(s > 1.0, _continuous_rate_df(s) * rate_limit_correction(s, wT), 1.0 + 0j)
    return _continuous_rate_df(A * omega / R)


def _continuous_rate_df(rho):
    """N(ρ) of the continuous rate limiter (module docstring), complex (an array for an array ρ)."""
    if np.ndim(rho) == 0:  # one value: its regime's formula alone (the same formulas, no masks)
        rho = float(rho)
        return 1.0 + 0j if rho <= 1.0 else complex(_triangle_df(1.0 / rho) if rho >= RATE_LIMIT_TRIANGLE else _mixed_df(1.0 / rho))
    rho = np.asarray(rho, dtype=float)
    N = np.ones(rho.shape, dtype=complex)
    triangle = rho >= RATE_LIMIT_TRIANGLE
    N[triangle] = _triangle_df(1.0 / rho[triangle])
    mixed = (rho > 1.0) & ~triangle
    if np.any(mixed):
        N[mixed] = _mixed_df(1.0 / rho[mixed])
    return N


def _triangle_df(r):
    """(4r/π)·e^(−j·arccos(πr/2)): the triangle's N for r = 1/ρ <= 1/ρ_t."""
    return (4.0 * r / math.pi) * np.exp(-1j * np.arccos(0.5 * math.pi * r))


def _mixed_df(r):
    """b₁ + j·a₁ of the follow-and-ramp output for r = 1/ρ in (1/ρ_t, 1) (module docstring), in closed form given θ₁."""
    t1, t2 = _follow_start(r), math.pi - np.arccos(r)
    t3, top = t1 + math.pi, np.sqrt(1.0 - r * r)
    ramp = lambda t: top - r * (t - t2)
    sin_part = (0.5 * (t2 - t1) - 0.25 * (np.sin(2 * t2) - np.sin(2 * t1))
                + (-ramp(t3) * np.cos(t3) - r * np.sin(t3)) - (-ramp(t2) * np.cos(t2) - r * np.sin(t2)))
    cos_part = (0.5 * (np.sin(t2) ** 2 - np.sin(t1) ** 2)
                + (ramp(t3) * np.sin(t3) - r * np.cos(t3)) - (ramp(t2) * np.sin(t2) - r * np.cos(t2)))
    return (2.0 / math.pi) * (sin_part + 1j * cos_part)


def rate_limit_waveform(rho: float, theta):
    """The continuous rate limiter's steady output for the input sin θ at ρ = Aω/R, in units of A (module docstring).

    Parameters
    ----------
    rho : float
        Aω/R, > 0.
    theta : array_like
        Phases ωt, rad.
    """
    theta = np.asarray(theta, dtype=float)
    if rho <= 1.0:
        return np.sin(theta)
    r = 1.0 / rho
    if rho >= RATE_LIMIT_TRIANGLE:
        start = end = math.pi - math.asin(0.5 * math.pi * r)
        top = 0.5 * math.pi * r
    else:
        start, end = float(_follow_start(np.array([r]))[0]), math.pi - math.acos(r)
        top = math.sqrt(1.0 - r * r)
    phase = np.mod(theta - start, 2.0 * math.pi)  # from the start of a follow segment (or the triangle's peak)
    sign = np.where(phase < math.pi, 1.0, -1.0)  # half-wave symmetry: y(θ + π) = −y(θ)
    local = np.mod(phase, math.pi) + start
    return sign * np.where(local <= end, np.sin(local), top - r * (local - end))


_CORRECTION_S = np.geomspace(1.0, 400.0, 40)
"""s = ρ·sin(ωT/2)/(ωT/2) of the sampled limiter's correction (above 400: its value there, the triangle's limit)."""

_CORRECTION_OMEGA_T = 2.5
"""The largest ωT the correction is fitted to (2.5 samples per input period); beyond, its value there."""

_CORRECTION_DEGREE = 3
"""log Q is fitted by ωT times a polynomial of this degree − 1 in ωT (Q = 1 at ωT = 0)."""


@functools.lru_cache(maxsize=1)
def _correction_table():
    """The coefficients c_i(log s) of log Q = ωT·(c₁ + c₂ωT + c₃ωT²), each a cubic spline in log s (`rate_limit_correction`).

    The sampled limiter is simulated on sinusoids: v_k = v_(k−1) + clip(u_k − v_(k−1), ±1), u_k = U·sin(ωTk + φ) with
    U = s/(2 sin(ωT/2)) (R·T = 1), from v = 0, on a grid of s and of ωT in [0.05, 2.5] every 0.025 and two phases φ,
    twenty periods at the smallest ωT (more at the others); the fundamental is the Hann-windowed DTFT over the last
    80 % (the first fifth is the transient: the limiter forgets its start within a period or two). The sampled
    limiter's N is not smooth in ωT: where ωT is near 2π·p/q its steady state locks onto the q sample phases, and N
    moves by ±1° (ωT ≈ 0.2) to ±3° (ωT ≈ 0.5) around its trend from one ωT to the next (measured on runs of 300
    periods and 8 phases); the least-squares fit over the whole ωT range is that trend, the mean describing function.
    """
    from scipy.interpolate import CubicSpline

    wT = np.arange(0.05, _CORRECTION_OMEGA_T + 1e-9, 0.025)
    S, Y, P = np.meshgrid(_CORRECTION_S, wT, (0.0, 0.25 * math.pi), indexing="ij")
    U = S / (2.0 * np.sin(0.5 * Y))
    n = int(math.ceil(20 * 2.0 * math.pi / wT[0]))
    start = n // 5
    window = 0.5 - 0.5 * np.cos(2.0 * math.pi * np.arange(n - start) / (n - start))
    rotation, z = np.exp(1j * Y), np.exp(1j * P)
    v, out, into = np.zeros(S.shape), np.zeros(S.shape, dtype=complex), np.zeros(S.shape, dtype=complex)
    for k in range(n):
        u = U * z.imag
        v += np.clip(u - v, -1.0, 1.0)
        if k >= start:
            weight = window[k - start] * np.conj(z)
            out += v * weight
            into += u * weight
        z *= rotation
    log_Q = np.log(np.mean(out / into, axis=2) / _continuous_rate_df(S[:, :, 0]))  # (s, ωT)
    basis = wT[:, None] ** np.arange(1, _CORRECTION_DEGREE + 1)[None, :]
    coefficients = np.linalg.lstsq(basis, log_Q.T, rcond=None)[0]  # (degree, s)
    x = np.log(_CORRECTION_S)
    return tuple(CubicSpline(x, c) for c in coefficients)


def rate_limit_correction(s, omega_T):
    """Q = N_sampled/N_c(s): how a limiter acting once per period T differs from the continuous one (`rate_limit_df`).

    Fitted once per process to simulations of the sampled limiter on sinusoids (`_correction_table`, ~0.3 s):
    log Q = ωT·(c₁(s) + c₂(s)·ωT + c₃(s)·ωT²), s in [1, 400] and ωT in [0, 2.5] (outside, the edge). Q = 1 at ωT = 0;
    at large s it tends to e^(jωT/2)/sinc(ωT/2): a ramping sequence leads the continuous triangle by half a period.

    Parameters
    ----------
    s : array_like
        2A·sin(ωT/2)/(R·T), >= 1.
    omega_T : array_like
        ωT, rad, >= 0.
    """
    splines = _correction_table()
    x = np.log(np.clip(np.asarray(s, dtype=float), _CORRECTION_S[0], _CORRECTION_S[-1]))
    y = np.clip(np.asarray(omega_T, dtype=float), 0.0, _CORRECTION_OMEGA_T)
    exponent = sum(spline(x) * y ** (i + 1) for i, spline in enumerate(splines))
    return complex(np.exp(exponent)) if np.ndim(exponent) == 0 else np.exp(exponent)


def loeb_stable(delta, A: float, omega: float, *, step: float = 1e-6) -> bool:
    """Loeb's test at a cycle (A, ω) of a characteristic function Δ(A, ω) (module docstring): Re(j·Δ_A/Δ_ω) > 0.

    Parameters
    ----------
    delta : callable
        Δ(A, ω) -> complex, zero at the cycle (e.g. 1 + G(jω)N(A)).
    A : float
        The cycle's amplitude, > 0.
    omega : float
        Its frequency, rad/s, > 0.
    step : float
        Relative step of the central differences.

    Returns
    -------
    bool
        True for a stable (attracting) cycle.
    """
    hA, hw = step * A, step * omega
    dA = (delta(A + hA, omega) - delta(A - hA, omega)) / (2 * hA)
    dw = (delta(A, omega + hw) - delta(A, omega - hw)) / (2 * hw)
    return bool((1j * dA / dw).real > 0)


def _segment_crossings(p, q):
    """Index pairs (i, j) and parameters (t, u) where segment p[i]p[i+1] crosses q[j]q[j+1] (complex polylines)."""
    a, b = p[:-1, None], p[1:, None]
    c, d = q[None, :-1], q[None, 1:]
    r, s = b - a, d - c
    denominator = (r.conjugate() * s).imag
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((c - a).conjugate() * s).imag / denominator
        u = ((c - a).conjugate() * r).imag / denominator
    hit = np.isfinite(t) & np.isfinite(u) & (t >= 0) & (t < 1) & (u >= 0) & (u < 1)
    i, j = np.nonzero(hit)
    return i, j, t[i, j], u[i, j]


def _cells_with_zero(D):
    """(i, j) of the grid cells [A_i, A_i+1] × [ω_j, ω_j+1] whose four corners give Re D and Im D both signs."""
    corners = np.stack([D[:-1, :-1], D[1:, :-1], D[:-1, 1:], D[1:, 1:]])
    both = lambda part: (part.min(axis=0) <= 0) & (part.max(axis=0) >= 0)
    ok = np.all(np.isfinite(corners), axis=0)
    return np.nonzero(ok & both(corners.real) & both(corners.imag))


def harmonic_balance(G, N, amplitudes, frequencies, *, tol: float = 1e-10, frequency_dependent: bool = False) -> tuple:
    """Every limit cycle (A, ω) with G(jω)·N(A) = −1 on the given ranges (module docstring).

    The Nyquist polyline G(jω) over `frequencies` and the polyline −1/N(A) over
    `amplitudes` are intersected segment by segment; each intersection starts a
    Newton solve (`scipy.optimize.root`) of Re and Im of 1 + G(jω)N(A) in
    (log A, log ω). The grids only need to resolve the two curves (a crossing
    between grid points is found; two crossings inside one pair of segments are not).
    A describing function of A and ω (a rate limiter's, `rate_limit_df`:
    ``frequency_dependent=True``) has no single curve −1/N: every cell of the grid
    A × ω whose corners give 1 + G·N real and imaginary parts of both signs starts
    the solve instead.

    Parameters
    ----------
    G : callable
        G(s) -> complex for complex s (vectorized over arrays), the linear loop's transfer.
    N : callable
        N(A) -> complex (vectorized), the describing function; N(A, ω) with ``frequency_dependent``.
    amplitudes : array_like
        Increasing amplitudes > 0 where cycles are sought (the input's unit).
    frequencies : array_like
        Increasing frequencies > 0, rad/s.
    tol : float
        Largest |1 + G(jω)N(A)| accepted at a solution.
    frequency_dependent : bool
        N takes (A, ω) (broadcast arrays).

    Returns
    -------
    tuple of Cycle
        Sorted by amplitude; duplicates (the same cycle found from two crossings) merged.
    """
    A = np.asarray(amplitudes, dtype=float)
    w = np.asarray(frequencies, dtype=float)
    if A.ndim != 1 or w.ndim != 1 or A.size < 2 or w.size < 2 or np.any(A <= 0) or np.any(w <= 0):
        raise ValueError("harmonic_balance needs 1-D grids of at least two amplitudes > 0 and two frequencies > 0")
    nyquist = np.asarray(G(1j * w), dtype=complex)
    describe = (lambda a, omega: N(a, omega)) if frequency_dependent else (lambda a, omega: N(a))
    if frequency_dependent:
        i, j = _cells_with_zero(1.0 + nyquist[None, :] * np.asarray(N(A[:, None], w[None, :]), dtype=complex))
        starts = [(math.sqrt(A[a] * A[a + 1]), math.sqrt(w[f] * w[f + 1])) for a, f in zip(i, j)]
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            locus = -1.0 / np.asarray(N(A), dtype=complex)
        wi, ai, t, u = _segment_crossings(nyquist, locus)
        starts = [(math.exp(math.log(A[a]) + uu * (math.log(A[a + 1]) - math.log(A[a]))),
                   math.exp(math.log(w[f]) + tt * (math.log(w[f + 1]) - math.log(w[f])))) for f, a, tt, uu in zip(wi, ai, t, u)]

    def delta(a, omega):
        return 1.0 + complex(G(1j * omega)) * complex(describe(a, omega))

    def equations(x):
        d = delta(math.exp(x[0]), math.exp(x[1]))
        return [d.real, d.imag]

    cycles = []
    for a0, omega0 in starts:
        solution = optimize.root(equations, [math.log(a0), math.log(omega0)], method="hybr", options={"xtol": 1e-14})
        a, omega = (math.exp(v) for v in solution.x)
        residual = abs(delta(a, omega))
        if not residual <= tol:
            continue
        if any(abs(a - c.amplitude) <= 1e-8 * a and abs(omega - c.omega) <= 1e-8 * omega for c in cycles):
            continue
        cycles.append(Cycle(a, omega, loeb_stable(delta, a, omega), residual))
    return tuple(sorted(cycles, key=lambda c: c.amplitude))
