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
* `harmonic_balance(G, N, amplitudes, frequencies)`: every (A, ω) with
  G(jω)N(A) = −1, found where the Nyquist curve G(jω) crosses the curve −1/N(A) and
  polished by Newton on the two real equations; each cycle carries Loeb's
  stability test (a small increase of A must decay).

Loeb's test (stated for any characteristic function Δ(s, A) whose zero at s = jω is
the cycle): the perturbed root moves by δs = −(Δ_A/Δ_s)·δA, and the cycle is stable
when a larger amplitude makes the loop decay, Re(δs)/δA < 0, i.e.
Re(j·Δ_A/Δ_ω) > 0 (Δ_s = −j·Δ_ω by analyticity). 1 + G(jω)N(A) is Δ divided by the
loop's denominator, which changes neither the zero nor the sign of the test there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from ..numerics.solve import invert_decreasing

__all__ = [
    "Cycle",
    "describing_function",
    "harmonic_content",
    "saturation_df",
    "saturation_df_for_output",
    "sine_df",
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
    (2M/π)(asin r/r + √(1 − r²)), inverted elementwise (`numerics.solve.invert_decreasing`), and N = r·U/M.

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

    def h(r):
        return (2.0 / math.pi) * (np.arcsin(r) / r + np.sqrt(1.0 - r * r))

    r = invert_decreasing(h, np.where(inside, ratio, 1.1), 1e-12, 1.0) if np.any(inside) else np.ones_like(ratio)
    N = np.where(ratio <= 1.0, 1.0, np.where(inside, r * ratio, 0.0))
    return float(N) if np.ndim(N) == 0 else N


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


def harmonic_balance(G, N, amplitudes, frequencies, *, tol: float = 1e-10) -> tuple:
    """Every limit cycle (A, ω) with G(jω)·N(A) = −1 on the given ranges (module docstring).

    The Nyquist polyline G(jω) over `frequencies` and the polyline −1/N(A) over
    `amplitudes` are intersected segment by segment; each intersection starts a
    Newton solve (`scipy.optimize.root`) of Re and Im of 1 + G(jω)N(A) in
    (log A, log ω). The grids only need to resolve the two curves (a crossing
    between grid points is found; two crossings inside one pair of segments are not).

    Parameters
    ----------
    G : callable
        G(s) -> complex for complex s (vectorized over arrays), the linear loop's transfer.
    N : callable
        N(A) -> complex (vectorized), the describing function.
    amplitudes : array_like
        Increasing amplitudes > 0 where cycles are sought (the input's unit).
    frequencies : array_like
        Increasing frequencies > 0, rad/s.
    tol : float
        Largest |1 + G(jω)N(A)| accepted at a solution.

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
    with np.errstate(divide="ignore", invalid="ignore"):
        locus = -1.0 / np.asarray(N(A), dtype=complex)
    i, j, t, u = _segment_crossings(nyquist, locus)

    def delta(a, omega):
        return 1.0 + complex(G(1j * omega)) * complex(N(a))

    def equations(x):
        d = delta(math.exp(x[0]), math.exp(x[1]))
        return [d.real, d.imag]

    cycles = []
    for wi, ai, ti, ui in zip(i, j, t, u):
        omega0 = math.exp(math.log(w[wi]) + ti * (math.log(w[wi + 1]) - math.log(w[wi])))
        a0 = math.exp(math.log(A[ai]) + ui * (math.log(A[ai + 1]) - math.log(A[ai])))
        solution = optimize.root(equations, [math.log(a0), math.log(omega0)], method="hybr", options={"xtol": 1e-14})
        a, omega = (math.exp(v) for v in solution.x)
        residual = abs(delta(a, omega))
        if not residual <= tol:
            continue
        if any(abs(a - c.amplitude) <= 1e-8 * a and abs(omega - c.omega) <= 1e-8 * omega for c in cycles):
            continue
        cycles.append(Cycle(a, omega, loeb_stable(delta, a, omega), residual))
    return tuple(sorted(cycles, key=lambda c: c.amplitude))
