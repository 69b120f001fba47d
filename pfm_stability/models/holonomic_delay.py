"""The holonomic loop with its delay taken exactly: `exact_delay` and `sampled` (docs/models.md).

Both models of s² + (c_h·s + κ)·e^(−sT) = 0 (`models.holonomic`) that keep
the delay whole.

**exact_delay** is the quasi-polynomial a(s) + (d(s) + K)e^(−sT) of module
`pfm_stability.numerics.delay` with a(s) = s², d(s) = c_h·s and K = κ: verdicts by its
crossing count, T* by its delay margin, rightmost roots by its pseudospectral
method. The crossing polynomial F(y) = y² − c_h²y − κ² (y = ω²) has one
positive root, ω² = (c_h² + √(c_h⁴ + 4κ²))/2, where F′ > 0: every crossing
as T grows destabilises, so the loop is stable exactly when c_h > 0, κ > 0
and T < T* = atan2(c_h ω, κ)/ω. T* decreases strictly in κ (from π/(2c_h)
at κ → 0), so the stable set in κ is one interval (0, κ*): at κ* a root is at
jω with ω sin ωT = c_h and κ* = ω² cos ωT, ωT ∈ (0, π/2) (ω sin ωT increases
there; none when c_hT >= π/2). In c_h, T* rises from 0 and falls back to 0,
so the stable set is one interval whose ends solve ω² cos ωT = κ on either
side of the maximum of ω² cos ωT (x tan x = 2, x = ωT), c_h = ω sin ωT
there; empty when κT² exceeds that maximum, ≈ 0.5498. Every interval is checked
by the crossing count (`crossings.stable_set`).

**sampled** is the double integrator ẋ = v, v̇ = u with a zero-order hold of
the acceleration command u_k = −κx_k − c_h v_k, applied at once
(compute_delay = 0) or one period later (1). The δ form of `models.sampled`
is exact here (A² = 0): Ψ = [[0, 1], [0, 0]], G = [T/2, 1]ᵀ, and

    P(w) = (1 + Tw)^d·w² + c_h·w + κ·(1 + Tw/2),   z = 1 + Tw,

affine in κ and in c_h. Tustin's map z = (1 + Tμ/2)/(1 − Tμ/2) sends the unit
circle to the imaginary axis, where `crossings.affine_crossings` finds the
crossing gains (plus the gain at which a pole passes z = −1); verdicts come
from the eigenvalues of the δ-form closed-loop matrix (|1 + Tλ| < 1), and
`jury_stable` is the Schur–Cohn test on the polynomial in z. Jury's
conditions for d = 0 give T* = min(2/c_h, 2c_h/κ) (the tests' closed form).
T = 0 is `continuous`.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..checks import check_choice, check_integer
from ..numerics.crossings import Crossing, StabilityInterval, stable_interval, stable_set
from ..numerics.delay import DelayLoop
from ..parameters import MODEL_NAMES
from ..numerics.routh import schur_cohn_stable
from ..numerics.solve import bisect_root
from .holonomic import HolonomicBoundary, HolonomicContinuous, HolonomicFirstOrder, HolonomicLoop, HolonomicModel, HolonomicPade, PolynomialHolonomicModel, checked
from .sampled import bilinear_polynomial

__all__ = ["BEST_CURVATURE_PRODUCT", "HolonomicExactDelay", "HolonomicSampled", "make_holonomic_model"]


def _curvature_peak() -> float:
    """x0 with x·tan x = 2 on (0, π/2): where ω² cos ωT peaks (x = ωT)."""
    return bisect_root(lambda x: x * math.tan(x) - 2.0, 1e-9, math.pi / 2 - 1e-12, rtol=1e-15)


_X0 = _curvature_peak()
BEST_CURVATURE_PRODUCT = _X0 * _X0 * math.cos(_X0)
"""max over ω of ω²T²·cos ωT (≈ 0.5498): no damping stabilises κ with κT² at or above it (exact delay)."""


class HolonomicExactDelay(HolonomicModel):
    """s² + (c_h s + κ)e^(−sT) = 0, the delay taken exactly (module `delay`)."""

    name = "exact_delay"
    equation = "s^2 + (c_h s + kappa) exp(-s T) = 0"

    @staticmethod
    def quasi_polynomial(loop: HolonomicLoop) -> DelayLoop:
        """a(s) + (d(s) + κ)e^(−sT) with a(s) = s², d(s) = c_h·s."""
        return DelayLoop([1.0, 0.0, 0.0], loop.T, delayed=[loop.c_h, 0.0])

    def compute_boundary(self, loop: HolonomicLoop) -> HolonomicBoundary:
        if loop.T == 0:
            b = HolonomicContinuous().boundary(loop)
            return HolonomicBoundary(self.name, b.kappa_critical, b.omega_critical, b.stable_set)
        crossings = []
        if 0 < loop.c_h * loop.T < math.pi / 2:
            T, c = loop.T, loop.c_h
            w = bisect_root(lambda x: x * math.sin(x * T) - c, 0.0, math.pi / (2 * T), rtol=1e-15)
            crossings.append(Crossing(w * w * math.cos(w * T), w))
        interval = stable_interval(crossings, lambda g: self._stable(g, loop)) if loop.c_h > 0 else StabilityInterval(0.0, None, (), ())
        return HolonomicBoundary.from_interval(self.name, interval)

    def _stable(self, kappa, loop) -> bool:
        """Crossing count Z(T) = 0 (`DelayLoop.is_stable`)."""
        return self.quasi_polynomial(loop).is_stable(kappa)

    @checked
    def unstable_root_count(self, kappa: float, loop: HolonomicLoop) -> int | None:
        """Roots with Re s > 0 (None when a root is on the imaginary axis, e.g. c_h = 0 at T = 0)."""
        return self.quasi_polynomial(loop).unstable_root_count(kappa)

    def _rightmost(self, kappa, loop) -> complex | None:
        """Pseudospectral roots polished by Newton (`DelayLoop.rightmost_roots`); None if unresolved."""
        q = self.quasi_polynomial(loop)
        for nodes in (40, 160):
            roots = q.rightmost_roots(kappa, count=2, nodes=nodes)
            if roots.size:
                top = roots[roots.real >= roots[0].real - 1e-9 * max(1.0, abs(roots[0]))]
                return complex(top[top.imag.argmax()])
        return None  # pragma: no cover - |s|T in the thousands

    @checked
    def critical_delay(self, kappa: float, loop: HolonomicLoop) -> float:
        """T* = the delay margin of the crossing count (0 when c_h <= 0 or κ < 0), s."""
        return float(self.quasi_polynomial(loop).delay_margin(kappa))

    def _damping_range(self, kappa: float, loop: HolonomicLoop) -> tuple:
        if loop.T == 0:
            return HolonomicContinuous()._damping_range(kappa, loop)
        T = loop.T
        if kappa * T * T >= BEST_CURVATURE_PRODUCT:
            return ()
        g = lambda x: x * x * math.cos(x * T) - kappa
        # the second root near ωT = π/2 in v = π/2 − ωT: cos(ωT) = sin(v) keeps its digits where cos(π/2) rounds to 6e-17
        h = lambda v: ((0.5 * math.pi - v) / T) ** 2 * math.sin(v) - kappa
        v = bisect_root(h, 0.0, 0.5 * math.pi - _X0, rtol=1e-15)
        ends = [bisect_root(g, 0.0, _X0 / T, rtol=1e-15), (0.5 * math.pi - v) / T]
        crossings = [Crossing(w * math.sin(w * T), w) for w in ends]
        return stable_set(crossings, lambda c: self._stable(kappa, replace(loop, c_h=c)))


class HolonomicSampled(PolynomialHolonomicModel):
    """The double integrator with a zero-order hold of u_k = −κx_k − c_h v_k.

    Parameters
    ----------
    compute_delay : {0, 1}
        Samples between measurement and actuation.
    """

    name = "sampled"
    equation = "det(zI - Phi_cl(kappa, c_h)) = 0, ZOH of the acceleration, period T"

    def __init__(self, compute_delay: int = 0):
        self.compute_delay = check_integer("compute_delay", compute_delay, 0, 1)

    def options(self) -> dict:
        """``{"compute_delay": d}``."""
        return {"compute_delay": self.compute_delay}

    def __repr__(self) -> str:
        return f"HolonomicSampled(compute_delay={self.compute_delay})"

    def delta_parts(self, loop: HolonomicLoop):
        """(A0, Ac, Ak) of P(w) = (1 + Tw)^d w² + c_h w + κ(1 + Tw/2), descending in w, one length."""
        lead = np.array([loop.T, 1.0, 0.0, 0.0]) if self.compute_delay else np.array([1.0, 0.0, 0.0])
        n = len(lead)
        pad = lambda p: np.pad(np.asarray(p, dtype=float), (n - len(p), 0))
        return lead, pad([1.0, 0.0]), pad([loop.T / 2, 1.0])

    def parts(self, loop: HolonomicLoop):
        """(A0, Ac, Ak) in Tustin's μ (z = (1 + Tμ/2)/(1 − Tμ/2)): stable ⇔ Hurwitz; T = 0: `continuous`'s."""
        if loop.T == 0:
            return HolonomicContinuous().parts(loop)
        parts = self.delta_parts(loop)
        degree = len(parts[0]) - 1
        return tuple(bilinear_polynomial(p, degree, loop.T) for p in parts)

    def z_polynomial(self, kappa: float, loop: HolonomicLoop) -> np.ndarray:
        """det(zI − Φ_cl) = z^d(z − 1)² + c_hT(z − 1) + κT²(z + 1)/2, descending in z (T > 0)."""
        T = loop.T
        head = np.polymul([1.0, -2.0, 1.0], [1.0, 0.0] if self.compute_delay else [1.0])
        return np.polyadd(head, np.polyadd(loop.c_h * T * np.array([1.0, -1.0]), kappa * T * T / 2 * np.array([1.0, 1.0])))

    @checked
    def jury_stable(self, kappa: float, loop: HolonomicLoop) -> bool:
        """Schur–Cohn (Jury) verdict on `z_polynomial` (T > 0; T = 0: `continuous`)."""
        if loop.T == 0:
            return self._stable(kappa, loop)
        return schur_cohn_stable(self.z_polynomial(kappa, loop))

    def _frequency(self, raw: float, loop: HolonomicLoop) -> float:
        """ω (rad/s) of the unit-circle point that μ = jΩ maps to."""
        return 2.0 * math.atan(raw * loop.T / 2.0) / loop.T if loop.T > 0 else raw

    def _extra_crossings(self, d, e, loop) -> list:
        """The gain at which Q's degree drops: a pole passing through z = −1 (ω = π/T)."""
        if loop.T > 0 and e[0] != 0.0 and -d[0] / e[0] > 0:
            return [Crossing(float(-d[0] / e[0]), math.pi / loop.T)]
        return []

    def delta_matrix(self, kappa: float, loop: HolonomicLoop) -> np.ndarray:
        """(Φ_cl − I)/T: its eigenvalues λ give the poles z = 1 + Tλ (T = 0: the continuous loop's matrix)."""
        T, c = loop.T, loop.c_h
        G = np.array([[T / 2], [1.0]])
        F = np.array([[kappa, c]])
        Psi = np.array([[0.0, 1.0], [0.0, 0.0]])
        if self.compute_delay == 0 or T == 0:
            return Psi - G @ F
        return np.block([[Psi, G], [-F / T, np.full((1, 1), -1.0 / T)]])

    def _stable(self, kappa, loop) -> bool:
        """Every pole strictly inside the unit circle: 2 Re λ + T|λ|² < 0 (T = 0: Re λ < 0)."""
        lam = np.linalg.eigvals(self.delta_matrix(kappa, loop))
        return bool(np.all(2.0 * lam.real + loop.T * np.abs(lam) ** 2 < 0.0))

    def _growth_rates(self, kappa: float, loops) -> np.ndarray:
        """σ = max ln|z|/T (1/s) of each loop: the δ-form matrices' eigenvalues in one batch."""
        lam = np.linalg.eigvals(np.stack([self.delta_matrix(kappa, loop) for loop in loops]))
        T = np.array([loop.T for loop in loops])[:, None]
        sampled = T[:, 0] > 0
        out = lam.real.max(axis=1)
        with np.errstate(divide="ignore"):
            radius = 0.5 * np.log1p(np.maximum(2.0 * T * lam.real + T * T * np.abs(lam) ** 2, -1.0)) / np.where(T > 0, T, 1.0)  # |z|² >= 0
        out[sampled] = radius[sampled].max(axis=1)
        return out

    def _rightmost(self, kappa, loop) -> complex:
        """Dominant pole as σ = ln|z|/T, ω = |arg z|/T (T = 0: the continuous root)."""
        lam = np.linalg.eigvals(self.delta_matrix(kappa, loop))
        T = loop.T
        if T == 0:
            return complex(lam[np.lexsort((-lam.imag, -lam.real))[0]])
        with np.errstate(divide="ignore"):
            sigma = 0.5 * np.log1p(2.0 * T * lam.real + T * T * np.abs(lam) ** 2) / T
        omega = np.abs(np.arctan2(T * lam.imag, 1.0 + T * lam.real)) / T
        i = int(np.argmax(sigma))
        return complex(float(sigma[i]), float(omega[i]))


HOLONOMIC_BUILDERS = {
    "continuous": lambda pade_order, compute_delay: HolonomicContinuous(),
    "kb_first_order": lambda pade_order, compute_delay: HolonomicFirstOrder(),
    "pade": lambda pade_order, compute_delay: HolonomicPade(pade_order),
    "exact_delay": lambda pade_order, compute_delay: HolonomicExactDelay(),
    "sampled": lambda pade_order, compute_delay: HolonomicSampled(compute_delay),
}


def make_holonomic_model(name: str, *, pade_order: int = 3, compute_delay: int = 0) -> HolonomicModel:
    """The holonomic model called `name` (one of `parameters.MODEL_NAMES`).

    Parameters
    ----------
    name : str
    pade_order : int
        Padé order for ``"pade"``, 1 … 12.
    compute_delay : {0, 1}
        For ``"sampled"``.
    """
    check_choice("model", name, MODEL_NAMES)
    return HOLONOMIC_BUILDERS[name](pade_order, compute_delay)
