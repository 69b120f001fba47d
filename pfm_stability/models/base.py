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

A heading gain c (`Loop.c`, docs/models.md "The heading gain") adds k·c·s to
the gain term: τs³ + s² + ks + k(cs + NV)·e^(−sT) = 0. c = 0 (the default)
is KB's loop and runs exactly the code it always ran. NV < 0 (N < 0: a field
that pushes the robot away from its equilibrium) is accepted by every query
and is unstable in every model (`divergent_reason`). NV = 0 (N = 0: no
restoring force) leaves a neutral lateral root at s = 0 (z = 1); every query
judges the other roots, the heading loop (`neutral_reason`, docs/models.md
"N = 0").
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from ..checks import check_number
from ..parameters import RANGES, T_RESOLUTION, TAU_RESOLUTION, check_parameter
from ..numerics.crossings import first_stable_interval, verdict_at
from ..io.serialize import json_number
from .verdicts import NV_MAX

__all__ = [
    "Loop",
    "Boundary",
    "LoopModel",
    "AffineGainModel",
    "gain_range",
    "checked",
    "check_heading_gain",
    "neutral_quotient",
    "HEADING_GAIN_RANGE",
]

_DELAY_RTOL = 1e-7
"""Relative bracket width at which `critical_delay` stops (reports show 4 digits)."""

HEADING_GAIN_RANGE = (-0.99, 100.0)
"""Closed range of the heading gain c (`Loop.c`, dimensionless).

The steering command is k(δ − θ) = −k(N·x + (1 + c)·θ): c <= −1 removes or
reverses the loop's heading feedback, and the continuous loop
τs³ + s² + k(1 + c)s + kNV is then unstable at every NV (Routh: its s¹
coefficient is <= 0). Such a c is refused rather than answered, with that
reason; −0.99 keeps 1 + c >= 0.01. 100 is a generous cap (a heading term a
hundred times the steering loop's own)."""

def neutral_quotient(p, domain: str = "s") -> np.ndarray:
    """p(s)/s (``domain="s"``) or p(z)/(z − 1) (``"z"``): a characteristic polynomial at NV = 0 without its
    neutral lateral root (descending in and out; the quotient of the exact division).

    Every affine model's D has the root there exactly (D(0) = 0: the s⁰ coefficient is a product with
    the plant's zero constant term), so the s quotient drops that coefficient without arithmetic.
    """
    p = np.trim_zeros(np.asarray(p, dtype=float), "f")
    if domain == "s":
        return p[:-1]
    return np.polydiv(p, [1.0, -1.0])[0]


@dataclass(frozen=True)
class Loop:
    """Loop parameters every model needs.

    Parameters
    ----------
    tau : float
        Steering time constant τ, s, >= 0 (KB eq 6); τ with τk < 10⁻⁹ is
        stored as 0 (`TAU_RESOLUTION`).
    T : float
        Sampling period / loop delay, s, >= 0 (KB eq 18); T < 10⁻¹² s is
        stored as 0, a continuous controller (`T_RESOLUTION`).
    k : float
        Steering gain, 1/s, > 0 (KB eq 5).
    c : float, keyword only
        Heading gain, dimensionless, in `HEADING_GAIN_RANGE` ([−0.99, 100]);
        default 0 (KB's loop). The linearized reference is
        δ = −N·(x − x0) − c·θ, so the gain term of every model becomes
        k(cs + NV) (delayed by e^(−sT) with the rest of the sensor data);
        docs/models.md, "The heading gain".
    """

    tau: float
    T: float
    k: float
    c: float = field(default=0.0, kw_only=True)

    def __post_init__(self):
        for name in ("tau", "T", "k"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        if self.tau * self.k < TAU_RESOLUTION:  # a lag 10⁹ times faster than the steering loop: an ideal motor
            object.__setattr__(self, "tau", 0.0)
        if self.T < T_RESOLUTION:  # faster than a picosecond: a continuous controller
            object.__setattr__(self, "T", 0.0)
        if self.c.__class__ is not float or self.c != 0.0:
            object.__setattr__(self, "c", check_heading_gain(self.c))

    @property
    def plant(self) -> np.ndarray:
        """a(s) = τs³ + s² + ks, descending (KB eq 17 without the gain term)."""
        return np.array([self.tau, 1.0, self.k, 0.0]) if self.tau > 0 else np.array([1.0, self.k, 0.0])

    @property
    def heading(self) -> float:
        """kc, 1/s: the s-coefficient of the gain term k(cs + NV) (0 for KB's loop)."""
        return self.k * self.c

    @property
    def closed_plant(self) -> np.ndarray:
        """a(s) + kc·s = τs³ + s² + k(1 + c)s, descending: the loop without delay and without NV.

        ``plant`` itself when c = 0 (the same array, the same floats).
        """
        if self.c == 0.0:
            return self.plant
        return np.array([self.tau, 1.0, self.k * (1.0 + self.c), 0.0]) if self.tau > 0 else np.array([1.0, self.k * (1.0 + self.c), 0.0])


@dataclass(frozen=True)
class Boundary:
    """Stability boundary of one model for one loop (τ, T, k, c).

    Attributes
    ----------
    model : str
        Model name (`parameters.MODEL_NAMES`, docs/models.md).
    NV_critical : float
        NV*, 1/s: stable for every 0 < NV < NV* (``inf``: stable for every
        NV; 0: unstable at every NV close to 0 — "unstable at any speed").
    omega_critical : float or None
        Angular frequency of the oscillation that starts at NV*, rad/s (None
        when NV* is 0 or infinite).
    K_critical : float
        K* = k·NV*, 1/s².
    stable_set : tuple of (float, float)
        Every interval of NV (1/s) on which the loop is stable, ascending. The
        first is (0, NV*) when NV* > 0; a sampled loop can have more, or one
        that does not start at 0.
    """

    model: str
    NV_critical: float
    omega_critical: float | None
    K_critical: float
    stable_set: tuple = ()

    @classmethod
    def from_interval(cls, model: str, interval, k: float) -> "Boundary":
        """From a `crossings.StabilityInterval` in gain K = kNV."""
        intervals = tuple((lo / k, hi / k) for lo, hi in interval.intervals)
        return cls(model, interval.gain / k, interval.frequency, interval.gain, intervals)

    def contains(self, NV: float) -> bool:
        """True when NV lies strictly inside a stable interval."""
        return any(lo < NV < hi for lo, hi in self.stable_set)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "model": self.model,
            "NV_critical": json_number(self.NV_critical),
            "omega_critical": self.omega_critical,
            "K_critical": json_number(self.K_critical),
            "stable_set": [[json_number(lo), json_number(hi)] for lo, hi in self.stable_set],
        }


def _check_NV(NV) -> float:
    """NV as a float: finite (negative: N < 0, `divergent_reason`; 0: N = 0, `neutral_reason`; −0.0 becomes 0.0)."""
    return check_number("NV", NV, unit="1/s") + 0.0


def check_heading_gain(c) -> float:
    """c as a float if it is finite and in `HEADING_GAIN_RANGE`, else ValueError (with the reason for c <= −1)."""
    low, high = HEADING_GAIN_RANGE
    try:
        return check_number("c", c, low, high, low_open=False, high_open=False)
    except ValueError as exc:
        if isinstance(c, (int, float)) and not isinstance(c, bool) and c <= -1:
            raise ValueError(f"{exc} (c <= -1 removes the heading feedback: unstable at any NV)") from None
        raise


def _check_loop(loop) -> "Loop":
    if not isinstance(loop, Loop):
        raise ValueError(f"loop must be a Loop (tau, T, k); got {loop!r}")
    return loop


def checked(method):
    """Validate a public model method's (NV, loop) arguments: ValueError naming the bad one.

    NV is capped at |NV| <= `NV_MAX` here only: internal probes (a stable
    interval checked beyond the last crossing gain) may go further. NV < 0
    is accepted (N < 0, `divergent_reason`), and NV = 0 (N = 0: the heading
    loop is judged, `neutral_reason`).
    """

    @functools.wraps(method)
    def wrapper(self, NV, loop, *args, **kwargs):
        NV = check_number("NV", NV, -NV_MAX, NV_MAX, low_open=False, high_open=False, unit="1/s") + 0.0
        return method(self, NV, _check_loop(loop), *args, **kwargs)

    return wrapper


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

    def options(self) -> dict:
        """The options that configure this model, in the order JSON writes them.

        ``{}`` for a model without options; ``{"order": m}`` for `Pade`,
        ``{"hold": …, "compute_delay": …}`` for `Sampled` (docs/models.md).
        """
        return {}

    def boundary(self, loop: Loop) -> Boundary:
        """NV* and the boundary frequency for (τ, T, k) (cached)."""
        return _cached_boundary(self, _check_loop(loop))

    def compute_boundary(self, loop: Loop) -> Boundary:  # pragma: no cover - interface
        """NV* and ω* for (τ, T, k), uncached (`boundary` caches it)."""
        raise NotImplementedError

    @checked
    def is_stable(self, NV: float, loop: Loop) -> bool:  # pragma: no cover - interface
        """Verdict for NV (1/s) by a route independent of `boundary`."""
        raise NotImplementedError

    @checked
    def rightmost_root(self, NV: float, loop: Loop) -> complex:  # pragma: no cover - interface
        """Dominant root σ + jω (1/s, rad/s); sampled models map z by ln(z)/T."""
        raise NotImplementedError

    def growth_rates(self, NV: float, loops) -> np.ndarray:
        """Real part of the dominant root, 1/s, at NV for each loop of a sequence.

        At NV = 0 the heading loop's (`neutral_reason`: the neutral lateral
        root left out), as `rightmost_root`. Models override this with a
        vectorized version where they can.
        """
        NV = _check_NV(NV)
        return np.array([self.rightmost_root(NV, loop).real for loop in loops])

    @checked
    def critical_delay(self, NV: float, loop: Loop) -> float:
        """T*: the smallest sampling period / delay at which NV loses stability (τ, k fixed), s.

        The operating point's delay margin, the same definition in every
        model: stable for every T in [0, T*). 0 if NV is unstable already at
        T → 0; ``inf`` if it stays stable up to the largest allowed T
        (100 s). Found by `solve.first_crossing` on the dominant growth rate
        over T (a geometric grid with its local maxima refined, then
        bisection to 1e-7 relative); models with an exact route override it.
        """
        from ..numerics.solve import first_crossing

        NV = _check_NV(NV)
        if NV < 0 or self.growth_rates(NV, [Loop(loop.tau, 0.0, loop.k, c=loop.c)])[0] >= 0:
            return 0.0

        def measure(Ts):
            return self.growth_rates(NV, [Loop(loop.tau, float(T), loop.k, c=loop.c) for T in Ts])

        scale = _time_scale(loop, NV)
        return first_crossing(measure, scale * 1e-2, RANGES["T"].high, rtol=_DELAY_RTOL, atol=1e-12 * scale)

    @checked
    def critical_gain_k(self, NV: float, loop: Loop) -> float:
        """k*: the smallest steering gain at which NV loses stability (τ, T fixed), 1/s.

        Stable for every k in (0, k*): lowering k below k* is a remedy that
        works. 0 if no k is small enough; ``inf`` if NV stays stable up to the
        largest allowed k (10⁴ 1/s). Same search as `critical_delay`, over k.
        """
        from ..numerics.solve import first_crossing

        NV = _check_NV(NV)
        lo, hi = gain_range(loop)
        if NV < 0 or self.growth_rates(NV, [Loop(loop.tau, loop.T, lo, c=loop.c)])[0] >= 0:
            return 0.0

        def measure(ks):
            return self.growth_rates(NV, [Loop(loop.tau, loop.T, float(k), c=loop.c) for k in ks])

        return first_crossing(measure, lo, hi, start=lo, rtol=_DELAY_RTOL, atol=1e-12 * lo)

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and vars(self) == vars(other)

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(sorted(vars(self).items()))))


def _time_scale(loop: Loop, NV: float) -> float:
    """The loop's fastest time scale, s: min(τ, 1/k, 1/NV) (τ counts when > 0, 1/NV when NV != 0)."""
    scales = [1.0 / loop.k] + ([1.0 / abs(NV)] if NV != 0 else []) + ([loop.tau] if loop.tau > 0 else [])
    return min(scales)


def gain_range(loop: Loop) -> tuple[float, float]:
    """(k_lo, k_hi), 1/s: where `critical_gain_k` searches, inside k's range (`RANGES["k"]`).

    k_lo = 1e-3·k, but never below the smallest allowed k (a loop with a k
    outside its range cannot be built: the search would fail on its own probe).
    """
    return max(1e-3 * loop.k, RANGES["k"].low), RANGES["k"].high


class AffineGainModel(LoopModel):
    """A model whose characteristic polynomial is D + K·E with K = kNV.

    Subclasses provide `polynomials(loop) -> (D, E)` in descending powers of s
    (``domain = "s"``) or z (``domain = "z"``).
    """

    domain = "s"

    def polynomials(self, loop: Loop):  # pragma: no cover - interface
        """(D, E), descending coefficients: the characteristic polynomial is D + kNV·E."""
        raise NotImplementedError

    @checked
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
        b = Boundary.from_interval(self.name, interval, loop.k)
        return Boundary(b.model, b.NV_critical, self._frequency(b.omega_critical, loop), b.K_critical, b.stable_set)

    @checked
    def is_stable(self, NV: float, loop: Loop) -> bool:
        return self._stable(NV, loop)

    def _stable(self, NV: float, loop: Loop) -> bool:
        """`is_stable` without the public argument checks (internal probes); NV = 0: D's quotient by its neutral root."""
        d, e = self.polynomials(loop)
        if NV == 0:
            return verdict_at(neutral_quotient(d, self.domain), [0.0], 0.0, self.domain)
        return verdict_at(d, e, loop.k * NV, self.domain)

    @checked
    def roots(self, NV: float, loop: Loop) -> np.ndarray:
        """All roots of the characteristic polynomial (s or z)."""
        return np.roots(self.characteristic(NV, loop))

    def batch_polynomials(self, loops):
        """(D, E) of each loop as two arrays of rows of one length (descending; leading zeros allowed)."""
        pairs = [self.polynomials(loop) for loop in loops]
        width = max(max(len(d), len(e)) for d, e in pairs)
        D = np.array([np.pad(d, (width - len(d), 0)) for d, _ in pairs])
        E = np.array([np.pad(e, (width - len(e), 0)) for _, e in pairs])
        return D, E

    def growth_rates(self, NV: float, loops) -> np.ndarray:
        """max Re s (1/s) at NV for each loop: eigenvalues of the companion matrices, batched by degree
        (NV = 0: of D/s, the heading loop; −inf for a constant)."""
        loops = list(loops)
        D, E = self.batch_polynomials(loops)
        P = D + (np.array([loop.k for loop in loops]) * _check_NV(NV))[:, None] * E
        if NV == 0:  # D(0) = 0 exactly: drop the neutral lateral root
            P = P[:, :-1]
        polys = [row[np.flatnonzero(row)[0]:] for row in P]
        out = np.empty(len(polys))
        for degree in {len(p) - 1 for p in polys}:
            rows = [i for i, p in enumerate(polys) if len(p) - 1 == degree]
            if degree == 0:
                out[rows] = -np.inf
                continue
            monic = np.array([polys[i][1:] / polys[i][0] for i in rows])
            companion = np.zeros((len(rows), degree, degree))
            companion[:, 0, :] = -monic
            companion[:, np.arange(1, degree), np.arange(degree - 1)] = 1.0
            out[rows] = np.linalg.eigvals(companion).real.max(axis=1)
        return out

    @checked
    def rightmost_root(self, NV: float, loop: Loop) -> complex:
        """Dominant root σ + jω (1/s, rad/s); NV = 0: the heading loop's (−inf when only the neutral root is left)."""
        if NV == 0:
            roots = np.roots(neutral_quotient(self.characteristic(NV, loop), self.domain))
            if roots.size == 0:
                return complex(-math.inf, 0.0)
        else:
            roots = self.roots(NV, loop)
        if self.domain == "z":
            z = roots[np.argmax(np.abs(roots))]
            return complex(np.log(z) / loop.T)
        return complex(roots[np.argmax(roots.real)])
