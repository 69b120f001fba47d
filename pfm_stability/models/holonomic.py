"""Robot loop families beside KB's steering loop: the holonomic robot and kinematic steering.

**Holonomic robot, force = acceleration** (Ge & Cui 2002 §6 and its conference
form §V). The robot obeys m·ẍ = F_x(x, ẋ); linearised about an equilibrium,
with the force computed from sensor data that are T old (docs/models.md,
"Robot loop families"):

    s² + (c_h·s + κ)·e^(−sT) = 0,   κ = −∂F_x/∂x / m  (1/s²),   c_h = −∂F_x/∂v_x / m  (1/s).

κ is the loop gain (NV's part in KB's loop), c_h the damping a velocity-
dependent field adds. The five models of KB's loop have a holonomic twin:

================  ==========================================  ===========================
name              characteristic equation                     decided by
================  ==========================================  ===========================
continuous        s² + c_h s + κ = 0                           Routh: c_h > 0 and κ > 0
kb_first_order    s² + (c_h s + κ)(1 − sT) = 0                 Routh
pade              s² Q_m(s) + (c_h s + κ) P_m(s) = 0           Routh; axis crossings
exact_delay       s² + (c_h s + κ) e^(−sT) = 0                 crossing count (`delay`)
sampled           ZOH of u_k = −κx_k − c_h v_k, 0/1 delay      eigenvalues; bilinear + Routh
================  ==========================================  ===========================

Each model answers `boundary` (κ* and the stable set in κ at fixed T, c_h),
`is_stable`, `rightmost_root`, `critical_delay` (T*: stable for every T in
[0, T*)) and `damping_range` (the stable set in c_h at fixed κ, T), with the
names of the steering models (`models.base.LoopModel`). κ < 0 is unstable
in every model (a real root s > 0, as NV < 0); κ = 0 is refused (a root at
s = 0); c_h <= 0 is unstable in every model (c_h = 0: the undamped
oscillator, which any delay destabilises, T* = 0).

**Kinematic steering** (Ge & Cui 2002 §7: ω = K_s(θ_f − θ), no motor lag) is
KB's steering loop with τ = 0 and k = K_s, s² + K_s s + K_s(cs + NV)e^(−sT):
`kinematic_loop` builds that `Loop`, which every steering model takes.
The polynomial holonomic models live here, `exact_delay` and `sampled` in
`models.holonomic_delay`; `make_holonomic_model` builds any of them by name.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from ..checks import check_number
from ..numerics.crossings import Crossing, affine_crossings, stable_interval, stable_set, verdict_at
from ..parameters import RANGES, T_RESOLUTION, check_parameter
from ..io.serialize import json_number
from .base import Loop, LoopModel
from .pade import MAX_PADE_ORDER, pade_coefficients

__all__ = [
    "HolonomicBoundary",
    "HolonomicContinuous",
    "HolonomicFirstOrder",
    "HolonomicLoop",
    "HolonomicModel",
    "HolonomicPade",
    "PolynomialHolonomicModel",
    "check_kappa",
    "kinematic_loop",
]


@dataclass(frozen=True)
class HolonomicLoop:
    """Loop parameters of the holonomic family (everything but the gain κ).

    Parameters
    ----------
    T : float
        Loop delay / sampling period, s, in [0, 100] (``RANGES["T"]``); below `T_RESOLUTION` (10⁻¹² s) stored as 0.
    c_h : float
        Damping c_h = −∂F_x/∂v_x / m, 1/s, in [−10¹⁵, 10¹⁵] (``RANGES["c_h"]``).
        c_h <= 0 is accepted and unstable in every model.
    """

    T: float
    c_h: float

    def __post_init__(self):
        object.__setattr__(self, "T", check_parameter("T", self.T))
        if self.T < T_RESOLUTION:  # faster than a picosecond: a continuous controller, as `Loop`
            object.__setattr__(self, "T", 0.0)
        object.__setattr__(self, "c_h", check_parameter("c_h", self.c_h))


def check_kappa(kappa) -> float:
    """κ (1/s²) as a float: finite, in ``RANGES["kappa"]``, non-zero (κ = 0 puts a root at s = 0)."""
    kappa = check_parameter("kappa", kappa)
    if kappa == 0.0:
        raise ValueError("kappa must be a finite non-zero number 1/s^2 (kappa = 0: no force gradient, a root at s = 0); got 0.0")
    return kappa


def _check_loop(loop) -> HolonomicLoop:
    if not isinstance(loop, HolonomicLoop):
        raise ValueError(f"loop must be a HolonomicLoop (T, c_h); got {loop!r}")
    return loop


def checked(method):
    """Validate a public method's (kappa, loop) arguments: ValueError naming the bad one."""

    @functools.wraps(method)
    def wrapper(self, kappa, loop, *args, **kwargs):
        return method(self, check_kappa(kappa), _check_loop(loop), *args, **kwargs)

    return wrapper


def kinematic_loop(K_s, T, c=0.0) -> Loop:
    """KB's steering `Loop` of Ge & Cui 2002 §7's kinematic robot: τ = 0, k = K_s.

    ω = K_s(θ_f − θ) with no motor lag gives s² + K_s s + K_s(cs + NV)e^(−sT) = 0;
    every steering model (`continuous`, …, `sampled`) takes the result.

    Parameters
    ----------
    K_s : float
        Heading gain, 1/s, in ``RANGES["k"]``.
    T : float
        Delay / sampling period, s.
    c : float
        Heading gain of the field (`Loop.c`), dimensionless.
    """
    low, high = RANGES["k"].low, RANGES["k"].high
    K_s = check_number("K_s", K_s, low, high, low_open=False, high_open=False, unit="1/s")
    return Loop(0.0, T, K_s, c=c)


@dataclass(frozen=True)
class HolonomicBoundary:
    """Stability boundary in κ of one holonomic model for one loop (T, c_h).

    Attributes
    ----------
    model : str
        Model name.
    kappa_critical : float
        κ*, 1/s²: stable for every 0 < κ < κ* (``inf``: for every κ > 0;
        0: unstable at every small κ).
    omega_critical : float or None
        Frequency of the oscillation that starts at κ*, rad/s (None when κ*
        is 0 or infinite).
    stable_set : tuple of (float, float)
        Every interval of κ (1/s²) on which the loop is stable, ascending.
    """

    model: str
    kappa_critical: float
    omega_critical: float | None
    stable_set: tuple = ()

    @classmethod
    def from_interval(cls, model: str, interval) -> HolonomicBoundary:
        """From a `crossings.StabilityInterval` in κ."""
        return cls(model, interval.gain, interval.frequency, tuple(interval.intervals))

    def contains(self, kappa: float) -> bool:
        """True when κ lies strictly inside a stable interval."""
        return any(lo < kappa < hi for lo, hi in self.stable_set)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "model": self.model,
            "kappa_critical": json_number(self.kappa_critical),
            "omega_critical": self.omega_critical,
            "stable_set": [[json_number(lo), json_number(hi)] for lo, hi in self.stable_set],
        }


@lru_cache(maxsize=4096)
def _cached_boundary(model: HolonomicModel, loop: HolonomicLoop) -> HolonomicBoundary:
    return model.compute_boundary(loop)


_DELAY_RTOL = 1e-9
"""Relative bracket width at which the searched `critical_delay` stops."""


class HolonomicModel:
    """Base class of the holonomic models (immutable, hashable: `boundary` is cached)."""

    name: str = ""
    equation: str = ""

    def options(self) -> dict:
        """The options that configure this model (``{}``, ``{"order": m}``, ``{"compute_delay": d}``)."""
        return {}

    def boundary(self, loop: HolonomicLoop) -> HolonomicBoundary:
        """κ*, ω* and the stable set in κ for (T, c_h) (cached)."""
        return _cached_boundary(self, _check_loop(loop))

    def compute_boundary(self, loop: HolonomicLoop) -> HolonomicBoundary:  # pragma: no cover - interface
        """`boundary`, uncached."""
        raise NotImplementedError

    @checked
    def is_stable(self, kappa: float, loop: HolonomicLoop) -> bool:
        """Verdict at κ (1/s²) by a route independent of `boundary`."""
        return self._stable(kappa, loop)

    def _stable(self, kappa: float, loop: HolonomicLoop) -> bool:  # pragma: no cover - interface
        raise NotImplementedError

    @checked
    def rightmost_root(self, kappa: float, loop: HolonomicLoop) -> complex | None:
        """Dominant root σ + jω (1/s, rad/s); sampled models map z by ln(z)/T."""
        return self._rightmost(kappa, loop)

    def _rightmost(self, kappa: float, loop: HolonomicLoop) -> complex | None:  # pragma: no cover - interface
        raise NotImplementedError

    @checked
    def critical_delay(self, kappa: float, loop: HolonomicLoop) -> float:
        """T*: stable for every delay / period T in [0, T*) at this κ and c_h, s.

        0 when the point is unstable already at T = 0 (κ < 0 or c_h <= 0);
        ``inf`` if it stays stable up to 100 s. Found by `solve.first_crossing`
        on the dominant growth rate over T (bisection to 1e-9 relative, however
        small T* is: a delay below `T_RESOLUTION` is T = 0, so T* >= 10⁻¹² s and
        the bracket's absolute floor, 10⁻⁹·10⁻¹² s, never decides first);
        models with an exact route override it.
        """
        from ..numerics.solve import first_crossing

        if not self._stable(kappa, replace(loop, T=0.0)):
            return 0.0

        def measure(Ts):
            return self._growth_rates(kappa, [replace(loop, T=float(T)) for T in Ts])

        scale = min(1.0 / abs(loop.c_h), 1.0 / math.sqrt(abs(kappa)))
        return first_crossing(measure, scale * 1e-3, RANGES["T"].high, rtol=_DELAY_RTOL, atol=_DELAY_RTOL * T_RESOLUTION)

    def _growth_rates(self, kappa: float, loops) -> np.ndarray:
        """Real part of the dominant root (1/s) at κ for each loop (models batch this where they can)."""
        return np.array([self._rightmost(kappa, loop).real for loop in loops])

    @checked
    def damping_range(self, kappa: float, loop: HolonomicLoop) -> tuple:
        """Every interval of damping c_h (1/s) that makes κ stable at the loop's T, ascending.

        ``loop.c_h`` is ignored. c_h <= 0 is never stable, so the intervals
        lie in c_h > 0; ``()`` when no damping helps (κ < 0, or a delay too
        long for κ).
        """
        if kappa < 0:
            return ()
        return self._damping_range(kappa, loop)

    def _damping_range(self, kappa: float, loop: HolonomicLoop) -> tuple:  # pragma: no cover - interface
        raise NotImplementedError

    # equal and hashed by type and options, as the steering models (`boundary`'s cache keys on them)
    __repr__ = LoopModel.__repr__
    __eq__ = LoopModel.__eq__
    __hash__ = LoopModel.__hash__


class PolynomialHolonomicModel(HolonomicModel):
    """A holonomic model whose characteristic polynomial is A0 + c_h·Ac + κ·Ak.

    Affine in κ (the boundary: `crossings.affine_crossings` in κ) and in c_h
    (the damping range: the same, in c_h); every stretch between crossing
    gains is decided by Routh on the polynomial itself (`crossings.stable_set`).
    Subclasses give `parts(loop)` in descending powers of s (or, for the
    sampled model, of Tustin's μ).
    """

    def parts(self, loop: HolonomicLoop):  # pragma: no cover - interface
        """(A0, Ac, Ak): descending coefficients, one length."""
        raise NotImplementedError

    def characteristic(self, kappa: float, loop: HolonomicLoop) -> np.ndarray:
        """A0 + c_h·Ac + κ·Ak, descending, leading zeros trimmed."""
        a0, ac, ak = self.parts(loop)
        return np.trim_zeros(a0 + loop.c_h * ac + kappa * ak, "f")

    def _extra_crossings(self, d, e, loop) -> list:
        """The gain at which the degree of D + g·E drops: a root passes through s = ∞.

        `affine_crossings` sees only roots on the axis; a root leaving through
        infinity changes the verdict too (`kb_first_order` at c_hT = 1). Its
        frequency is reported as ``inf``.
        """
        if e[0] != 0.0 and -d[0] / e[0] > 0:
            return [Crossing(float(-d[0] / e[0]), math.inf)]
        return []

    def _frequency(self, raw: float, loop: HolonomicLoop) -> float:
        """Boundary frequency in rad/s from the crossing's (identity in s)."""
        return raw

    def _crossings(self, d, e, loop) -> list:
        try:
            found = affine_crossings(d, e, "s")
        except ValueError:  # D·conj E real on the whole axis: c_h = 0, T = 0, a root pair stays on the axis
            return None
        out = [Crossing(c.gain, self._frequency(c.frequency, loop)) for c in found]
        return sorted(out + self._extra_crossings(d, e, loop), key=lambda c: (c.gain, c.frequency))

    def compute_boundary(self, loop: HolonomicLoop) -> HolonomicBoundary:
        a0, ac, ak = self.parts(loop)
        crossings = self._crossings(a0 + loop.c_h * ac, ak, loop)
        if crossings is None:
            return HolonomicBoundary(self.name, 0.0, None, ())
        return HolonomicBoundary.from_interval(self.name, stable_interval(crossings, lambda g: self._stable(g, loop)))

    def _damping_range(self, kappa: float, loop: HolonomicLoop) -> tuple:
        a0, ac, ak = self.parts(loop)
        crossings = self._crossings(a0 + kappa * ak, ac, loop)
        if crossings is None:  # pragma: no cover - only c_h·Ac real on the axis, not met
            return ()
        return stable_set(crossings, lambda c: self._stable(kappa, replace(loop, c_h=c)))

    def _stable(self, kappa: float, loop: HolonomicLoop) -> bool:
        a0, ac, ak = self.parts(loop)
        return verdict_at(a0 + loop.c_h * ac, ak, kappa, "s")

    def _growth_rates(self, kappa: float, loops) -> np.ndarray:
        """max Re s (1/s) of each loop: eigenvalues of the companion matrices, batched by degree."""
        polys = [self.characteristic(kappa, loop) for loop in loops]
        out = np.empty(len(polys))
        for degree in {len(p) - 1 for p in polys}:
            rows = [i for i, p in enumerate(polys) if len(p) - 1 == degree]
            if degree == 0:  # pragma: no cover - see `_rightmost`
                out[rows] = -np.inf
                continue
            companion = np.zeros((len(rows), degree, degree))
            companion[:, 0, :] = -np.array([polys[i][1:] / polys[i][0] for i in rows])
            companion[:, np.arange(1, degree), np.arange(degree - 1)] = 1.0
            out[rows] = np.linalg.eigvals(companion).real.max(axis=1)
        return out

    def _rightmost(self, kappa: float, loop: HolonomicLoop) -> complex:
        roots = np.roots(self.characteristic(kappa, loop))
        if roots.size == 0:  # pragma: no cover - degree 0 only at c_h·T = 1 and κ = c_h/T together
            return complex(-math.inf, 0.0)
        top = roots[roots.real >= roots.real.max() - 1e-12 * max(1.0, np.abs(roots).max())]
        return complex(top[np.argmax(top.imag)])


class HolonomicContinuous(PolynomialHolonomicModel):
    """No delay: s² + c_h s + κ = 0 (stable ⇔ c_h > 0 and κ > 0)."""

    name = "continuous"
    equation = "s^2 + c_h s + kappa = 0"

    def parts(self, loop):
        """A0 = s², Ac = s, Ak = 1."""
        return np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])

    @checked
    def critical_delay(self, kappa: float, loop: HolonomicLoop) -> float:
        """T does not enter: ``inf`` if stable, else 0 (s)."""
        return math.inf if self._stable(kappa, loop) else 0.0


class HolonomicFirstOrder(PolynomialHolonomicModel):
    """KB's approximation e^(−sT) ≈ 1 − sT: (1 − c_hT)s² + (c_h − κT)s + κ = 0.

    Routh: stable ⇔ κ > 0, c_h > κT and c_hT < 1, so κ* = c_h/T and
    T* = min(1/c_h, c_h/κ) — half the sampled loop's (the tests' closed form).
    """

    name = "kb_first_order"
    equation = "s^2 + (c_h s + kappa)(1 - s T) = 0"

    def parts(self, loop):
        """A0 = s², Ac = s(1 − sT), Ak = 1 − sT."""
        T = loop.T
        return np.array([1.0, 0.0, 0.0]), np.array([-T, 1.0, 0.0]), np.array([0.0, -T, 1.0])


class HolonomicPade(PolynomialHolonomicModel):
    """e^(−sT) ≈ P_m(s)/Q_m(s): s²·Q_m + (c_h s + κ)·P_m = 0.

    Parameters
    ----------
    order : int
        Padé order m, 1 … 12.
    """

    name = "pade"
    equation = "s^2 Q_m(s) + (c_h s + kappa) P_m(s) = 0  (Pade(m,m))"

    def __init__(self, order: int = 3):
        from ..checks import check_integer

        self.order = check_integer("pade_order", order, 1, MAX_PADE_ORDER)

    def options(self) -> dict:
        """``{"order": m}``."""
        return {"order": self.order}

    def parts(self, loop):
        """A0 = s²Q_m, Ac = s·P_m, Ak = P_m (P_m(0) = Q_m(0) = 1)."""
        num, den = pade_coefficients(loop.T, self.order)
        num, den = num / den[-1], den / den[-1]
        n = len(den) + 2
        pad = lambda p: np.pad(p, (n - len(p), 0))
        return pad(np.polymul([1.0, 0.0, 0.0], den)), pad(np.polymul([1.0, 0.0], num)), pad(num)

    def __repr__(self) -> str:
        return f"HolonomicPade(order={self.order})"
