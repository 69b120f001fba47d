"""What every loop model shares: the loop parameters, the boundary result, verdicts.

Koren & Borenstein 1991 (KB) reduce robot + environment to a loop whose only
environment-dependent quantity is the product NV (eq 16–19): the characteristic
equation of every model here is a function of τ, T, k and the loop gain
K = kNV. A model therefore answers three questions for given (τ, T, k):

* `boundary`: the critical NV* (stable for 0 < NV < NV*) and the oscillation
  frequency there;
* `is_stable(NV, …)`: a verdict by a route that does not use the boundary
  (Routh, Schur–Cohn, a crossing count);
* `rightmost_root(NV, …)`: the dominant root as a continuous-time rate
  σ + jω (1/s, rad/s); sampled models convert z by s = ln(z)/T.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..checks import check_number
from ..parameters import RANGES, check_parameter
from ..crossings import first_stable_interval, verdict_at
from ..serialize import json_number
from ..solve import bisect_root

__all__ = ["Loop", "Boundary", "LoopModel", "AffineGainModel", "verdict_label", "UNDECIDED_RTOL"]

_DELAY_RTOL = 1e-7
"""Relative bracket width at which `critical_delay` stops (reports show 4 digits)."""

UNDECIDED_RTOL = 1e-9
"""|NV/NV* − 1| below this is reported as "undecided" (on the boundary)."""


@dataclass(frozen=True)
class Loop:
    """Loop parameters every model needs.

    Parameters
    ----------
    tau : float
        Steering time constant τ, s, >= 0 (KB eq 6).
    T : float
        Sampling period / loop delay, s, >= 0 (KB eq 18).
    k : float
        Steering gain, 1/s, > 0 (KB eq 5).
    """

    tau: float
    T: float
    k: float

    def __post_init__(self):
        for name in ("tau", "T", "k"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))

    @property
    def plant(self) -> np.ndarray:
        """a(s) = τs³ + s² + ks, descending (KB eq 17 without the gain term)."""
        return np.array([self.tau, 1.0, self.k, 0.0]) if self.tau > 0 else np.array([1.0, self.k, 0.0])


@dataclass(frozen=True)
class Boundary:
    """Stability boundary of one model for one (τ, T, k).

    Attributes
    ----------
    model : str
        Model name (DESIGN §4).
    NV_critical : float
        NV*, 1/s: stable for 0 < NV < NV* (``inf``: stable for every NV).
    omega_critical : float or None
        Angular frequency of the oscillation that starts at NV*, rad/s.
    K_critical : float
        K* = k·NV*, 1/s².
    """

    model: str
    NV_critical: float
    omega_critical: float | None
    K_critical: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "model": self.model,
            "NV_critical": json_number(self.NV_critical),
            "omega_critical": self.omega_critical,
            "K_critical": json_number(self.K_critical),
        }


def verdict_label(NV: float, boundary: Boundary, stable: bool, rtol: float = UNDECIDED_RTOL) -> str:
    """"stable", "unstable" or "undecided" (within `rtol` of NV*)."""
    if math.isfinite(boundary.NV_critical) and abs(NV / boundary.NV_critical - 1.0) <= rtol:
        return "undecided"
    return "stable" if stable else "unstable"


@lru_cache(maxsize=8192)
def _cached_boundary(model: "LoopModel", loop: Loop) -> Boundary:
    return model.compute_boundary(loop)


class LoopModel:
    """Base class: a named loop model. Subclasses implement the queries.

    Models are immutable and hashable, so `boundary` is cached per
    (model, loop): a report asks for the same boundary many times.
    """

    name: str = ""
    equation: str = ""

    def boundary(self, loop: Loop) -> Boundary:
        """NV* and the boundary frequency for (τ, T, k) (cached)."""
        return _cached_boundary(self, loop)

    def compute_boundary(self, loop: Loop) -> Boundary:  # pragma: no cover - interface
        """NV* and ω* for (τ, T, k), uncached (`boundary` caches it)."""
        raise NotImplementedError

    def is_stable(self, NV: float, loop: Loop) -> bool:  # pragma: no cover - interface
        """Verdict for NV (1/s) by a route independent of `boundary`."""
        raise NotImplementedError

    def rightmost_root(self, NV: float, loop: Loop) -> complex:  # pragma: no cover - interface
        """Dominant root σ + jω (1/s, rad/s); sampled models map z by ln(z)/T."""
        raise NotImplementedError

    def critical_delay(self, NV: float, loop: Loop) -> float:
        """Largest sampling period / delay T that keeps NV stable (τ, k fixed), s.

        The first T at which NV*(T) falls to NV: a doubling search from
        T = 10⁻³(τ + 1/k) brackets it and bisection refines it to 1e-7
        relative. 0 if NV is unstable already at T = 0; ``inf`` if NV*(T)
        stays above NV up to the largest allowed T (100 s).
        """
        NV = _check_NV(NV)

        def excess(T):
            return self.boundary(Loop(loop.tau, T, loop.k)).NV_critical - NV

        if excess(0.0) <= 0:
            return 0.0
        start = 1e-3 * (loop.tau + 1.0 / loop.k)
        if excess(start) <= 0:
            return bisect_root(excess, 0.0, start, rtol=_DELAY_RTOL)
        lo, T_max = start, RANGES["T"].high
        while lo < T_max:
            hi = min(2 * lo, T_max)
            if excess(hi) <= 0:
                return bisect_root(excess, lo, hi, rtol=_DELAY_RTOL)
            lo = hi
        return math.inf

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and vars(self) == vars(other)

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(sorted(vars(self).items()))))


def _check_NV(NV) -> float:
    return check_number("NV", NV, 0.0, unit="1/s")


class AffineGainModel(LoopModel):
    """A model whose characteristic polynomial is D + K·E with K = kNV.

    Subclasses provide `polynomials(loop) -> (D, E)` in descending powers of s
    (``domain = "s"``) or z (``domain = "z"``).
    """

    domain = "s"

    def polynomials(self, loop: Loop):  # pragma: no cover - interface
        """(D, E), descending coefficients: the characteristic polynomial is D + kNV·E."""
        raise NotImplementedError

    def characteristic(self, NV: float, loop: Loop) -> np.ndarray:
        """Characteristic polynomial D + kNV·E, descending coefficients."""
        d, e = self.polynomials(loop)
        n = max(len(d), len(e))
        d = np.pad(d, (n - len(d), 0))
        e = np.pad(e, (n - len(e), 0))
        return np.trim_zeros(d + loop.k * _check_NV(NV) * e, "f")

    def _frequency(self, raw: float | None, loop: Loop) -> float | None:
        if raw is None:
            return None
        return raw / loop.T if self.domain == "z" else raw

    def compute_boundary(self, loop: Loop) -> Boundary:
        d, e = self.polynomials(loop)
        interval = first_stable_interval(d, e, self.domain)
        return Boundary(self.name, interval.gain / loop.k, self._frequency(interval.frequency, loop), interval.gain)

    def is_stable(self, NV: float, loop: Loop) -> bool:
        d, e = self.polynomials(loop)
        return verdict_at(d, e, loop.k * _check_NV(NV), self.domain)

    def roots(self, NV: float, loop: Loop) -> np.ndarray:
        """All roots of the characteristic polynomial (s or z)."""
        return np.roots(self.characteristic(NV, loop))

    def rightmost_root(self, NV: float, loop: Loop) -> complex:
        roots = self.roots(NV, loop)
        if self.domain == "z":
            z = roots[np.argmax(np.abs(roots))]
            return complex(np.log(z) / loop.T)
        return complex(roots[np.argmax(roots.real)])
