"""What every loop model shares: the loop families, the boundary result, verdicts.

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

Every robot family closes a loop of one shape (docs/models.md, "Robot loop
families"): a(s) + (δ·s + K)·e^(−sT) = 0, with a plant a(s), a delayed rate
term δ·s and a loop gain K. `family.Characteristic` is that shape; `Loop` is KB's
steering robot (a(s) = τs³ + s² + ks, δ = kc, K = kNV; kinematic steering is
τ = 0) and `models.holonomic.HolonomicLoop` the holonomic one (a(s) = s²,
δ = c_h, K = κ). Each model (`continuous`, `kb_first_order`, `pade`,
`exact_delay`, `sampled`) is one implementation that reads the loop it is
given through `Characteristic` only, so it decides every family; a family's
`family.LoopFamily` names its gain and the equation each model solves
(`models.loop.STEERING`).

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
from functools import lru_cache

import numpy as np

from ..checks import check_number
from ..parameters import RANGES
from ..numerics.crossings import Crossing, StabilityInterval, affine_crossings, stable_interval, stable_set, verdict_at
from .family import Characteristic
from .loop import _DELAY_RTOL, Loop, gain_range

__all__ = ["LoopModel", "AffineGainModel", "checked", "neutral_quotient"]


def neutral_quotient(p, domain: str = "s") -> np.ndarray:
    """p(s)/s (``domain="s"``) or p(z)/(z − 1) (``"z"``): a characteristic polynomial at NV = 0 without its
    neutral lateral root (descending in and out; the quotient of the exact division).

    Every affine model's D has the root there exactly (D(0) = 0: the s⁰ coefficient is a product with
    the plant's zero constant term), so the s quotient drops that coefficient without arithmetic.

    Parameters
    ----------
    p : array_like
        The polynomial, descending.
    domain : str, optional
        ``"s"`` or ``"z"``.
    """
    p = np.trim_zeros(np.asarray(p, dtype=float), "f")
    if domain == "s":
        return p[:-1]
    return np.polydiv(p, [1.0, -1.0])[0]


def _check_NV(NV) -> float:
    """NV as a float: finite (negative: N < 0, `divergent_reason`; 0: N = 0, `neutral_reason`; −0.0 becomes 0.0)."""
    return check_number("NV", NV, unit="1/s") + 0.0


def _check_loop(loop) -> Characteristic:
    if not isinstance(loop, Characteristic):
        raise ValueError(f"loop must be a Loop (tau, T, k) or a HolonomicLoop (T, c_h); got {loop!r}")
    return loop


def checked(method):
    """Validate a public model method's (gain, loop) arguments: ValueError naming the bad one.

    The gain is the loop's family's (`Characteristic.check_gain`): NV for a steering
    loop, capped at |NV| <= `NV_MAX` here only (internal probes, a stable interval
    checked beyond the last crossing gain, may go further); NV < 0 is accepted
    (N < 0, `divergent_reason`), and NV = 0 (N = 0: the heading loop is judged,
    `neutral_reason`). κ for a holonomic loop (non-zero).

    Parameters
    ----------
    method : callable
        A model method ``method(self, gain, loop, ...)``.
    """

    @functools.wraps(method)
    def wrapper(self, gain, loop, *args, **kwargs):
        loop = _check_loop(loop)
        return method(self, loop.check_gain(gain), loop, *args, **kwargs)

    return wrapper


def _steering(loop: Characteristic, what: str) -> Loop:
    """`loop` if it is a steering loop; ValueError for a query that has none in another family (k*: the steering gain)."""
    if not isinstance(loop, Loop):
        raise ValueError(f"loop must be a Loop (tau, T, k) for {what}: a {loop.family.name} loop has no steering gain k; got {loop!r}")
    return loop


@lru_cache(maxsize=8192)
def _cached_boundary(model: "LoopModel", loop: Characteristic):
    return model.compute_boundary(loop)


class LoopModel:
    """Base class: a named loop model, for the loop of any family (`Characteristic`). Subclasses implement the queries.

    Each query takes the family's gain (NV for a `Loop`, κ for a `HolonomicLoop`) and the
    loop; a boundary is the family's (`Boundary` in NV, `HolonomicBoundary` in κ). Models are
    immutable and hashable, so `boundary` is cached per (model, loop): a report asks for
    the same boundary many times.
    """

    name: str = ""

    def options(self) -> dict:
        """The options that configure this model, in the order JSON writes them.

        ``{}`` for a model without options; ``{"order": m}`` for `Pade`,
        ``{"hold": …, "compute_delay": …}`` for `Sampled` (docs/models.md).
        """
        return {}

    def boundary(self, loop: Characteristic):
        """The critical gain (NV* or κ*), the boundary frequency and the stable set for the loop (cached).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return _cached_boundary(self, _check_loop(loop))

    def compute_boundary(self, loop: Characteristic):  # pragma: no cover - interface
        """`boundary`, uncached.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    @checked
    def is_stable(self, gain: float, loop: Characteristic) -> bool:
        """Verdict at the gain (NV 1/s, κ 1/s²) by a route independent of `boundary`.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return self._stable(gain, loop)

    def _stable(self, gain: float, loop: Characteristic) -> bool:  # pragma: no cover - interface
        """`is_stable` without the public argument checks (internal probes)."""
        raise NotImplementedError

    @checked
    def rightmost_root(self, gain: float, loop: Characteristic) -> complex:  # pragma: no cover - interface
        """Dominant root σ + jω (1/s, rad/s, ω >= 0); sampled models map z by ln(z)/T.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    def growth_rates(self, gain: float, loops) -> np.ndarray:
        """Real part of the dominant root, 1/s, at the gain for each loop of a sequence.

        At NV = 0 the heading loop's (`neutral_reason`: the neutral lateral
        root left out), as `rightmost_root`. Models override `_growth_rates`
        with a vectorized version where they can.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loops : sequence of Characteristic
            The loops, one growth rate each.
        """
        return self._growth_rates(_check_NV(gain), loops)

    def _growth_rates(self, gain: float, loops) -> np.ndarray:
        """`growth_rates` of a gain already checked (the searches of `critical_delay` and `critical_gain_k`)."""
        return np.array([self.rightmost_root(gain, loop).real for loop in loops])

    @checked
    def critical_delay(self, gain: float, loop: Characteristic) -> float:
        """T*: the smallest sampling period / delay at which the gain loses stability (the rest fixed), s.

        The operating point's delay margin, the same definition in every
        model: stable for every T in [0, T*). 0 if the gain is unstable already
        at T → 0; ``inf`` if it stays stable up to the largest allowed T
        (100 s). Found by `solve.first_crossing` on the dominant growth rate
        over T (a geometric grid with its local maxima refined, then
        bisection to the family's tolerance, `Characteristic.delay_search`:
        1e-7 relative for a steering loop, 1e-9 for a holonomic one); models
        with an exact route override it.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged; its own T, s, is replaced by the searched ones.
        """
        def search():  # probes of the checked loop: T in [start, RANGES["T"].high]
            start, rtol, atol = loop.delay_search(gain)
            return start, RANGES["T"].high, {"rtol": rtol, "atol": atol}

        return self.first_loss(gain, loop._with_delay, 0.0, search)

    @checked
    def critical_gain_k(self, NV: float, loop: Loop) -> float:
        """k*: the smallest steering gain at which NV loses stability (τ, T fixed), 1/s; a steering loop's only.

        Stable for every k in (0, k*): lowering k below k* is a remedy that
        works. 0 if no k is small enough; ``inf`` if NV stays stable up to the
        largest allowed k (10⁴ 1/s). Same search as `critical_delay`, over k.

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            The steering loop judged; its own k is replaced by the searched ones.
        """
        loop = _steering(loop, "critical_gain_k")
        lo, hi = gain_range(loop)  # probes of the checked loop: k in gain_range
        return self.first_loss(NV, loop._with_steering_gain, lo, lambda: (lo, hi, {"start": lo, "rtol": _DELAY_RTOL, "atol": 1e-12 * lo}))

    def first_loss(self, gain: float, probe, origin: float, search) -> float:
        """The first value x > `origin` at which the gain loses stability, the loop `probe(x)`: the one search behind every
        critical value of a parameter (T*, k*, D* here; a path tracker's lookahead and speed, `analysis.path_tracking`).

        0 when unstable already at `origin` (or gain < 0), else `solve.first_crossing` of the growth rate
        (`searched_growth_rates`) on the interval ``search()`` gives (asked only then; ``inf``: stable up to its high end).

        Parameters
        ----------
        gain : float
            The family's loop gain, already checked.
        probe : callable
            x → the loop at x (an unchecked copy of a checked loop, its x kept in range by `search`).
        origin : float
            Where the search starts; the loop there is judged first.
        search : callable
            () → (low, high, keyword arguments of `solve.first_crossing`).
        """
        from ..numerics.solve import first_crossing

        if gain < 0 or self.searched_growth_rates(gain, [probe(origin)])[0] >= 0:
            return 0.0
        low, high, options = search()
        return first_crossing(lambda xs: self.searched_growth_rates(gain, [probe(x) for x in xs]), low, high, **options)

    def searched_growth_rates(self, gain: float, loops) -> np.ndarray:
        """The growth rates (1/s) `first_loss` measures: the dominant root's real part (`sampled` with more commands in flight
        than its eigenvalues resolve reads the verdict's sign, ±1).

        Parameters
        ----------
        gain : float
            The family's loop gain, already checked.
        loops : sequence of Characteristic
            The probed loops.
        """
        return self._growth_rates(gain, loops)

    @checked
    def critical_dead_time(self, gain: float, loop: Loop) -> float:
        """D*: the largest dead time of the steering plant the gain tolerates, T fixed, s (`dead_time.search_dead_time`).

        Parameters
        ----------
        gain : float
            Loop gain NV, 1/s.
        loop : Loop
            τ, T, k, c and g (its own D is replaced).
        """
        from .dead_time import search_dead_time

        return search_dead_time(self, gain, _steering(loop, "critical_dead_time"))

    @checked
    def damping_range(self, gain: float, loop: Characteristic) -> tuple:  # pragma: no cover - interface
        """Every interval of the damping δ (the holonomic c_h, 1/s) that makes the gain stable at the loop's T.

        Parameters
        ----------
        gain : float
            The family's loop gain (κ, 1/s², of a holonomic loop).
        loop : Characteristic
            The loop judged; its T, s, is kept and its own damping ignored.
        """
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and vars(self) == vars(other)

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(sorted(vars(self).items()))))


def _aligned(*polys) -> tuple:
    """The polynomials (descending) padded with leading zeros to one length."""
    polys = [np.asarray(p, dtype=float) for p in polys]
    n = max(len(p) for p in polys)
    return tuple(np.pad(p, (n - len(p), 0)) for p in polys)


class AffineGainModel(LoopModel):
    """A model whose characteristic polynomial is affine in the loop gain and in the damping: P0 + δ·P1 + K·P2.

    Subclasses provide `polynomials(loop) -> (D, E)`, D + K·E in descending powers
    of s (``domain = "s"``) or z (``domain = "z"``), and `parts(loop) -> (P0, P1, P2)`
    in s (Tustin's μ for the sampled model), one length. The boundary: every gain
    at which a root crosses the imaginary axis (`crossings.affine_crossings`) or
    leaves through infinity (the degree of the polynomial drops), each stretch
    between them decided by the model's own verdict (`crossings.stable_interval`);
    the damping range is the same in δ.
    """

    domain = "s"

    def polynomials(self, loop: Characteristic):  # pragma: no cover - interface
        """(D, E), descending coefficients: the characteristic polynomial is D + K·E.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    def parts(self, loop: Characteristic):  # pragma: no cover - interface
        """(P0, P1, P2), descending, one length: the characteristic polynomial P0 + δ·P1 + K·P2 (s; μ for `sampled`).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    @checked
    def characteristic(self, gain: float, loop: Characteristic) -> np.ndarray:
        """Characteristic polynomial D + K·E, descending coefficients.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        d, e = _aligned(*self.polynomials(loop))
        return np.trim_zeros(d + loop.loop_gain(_check_NV(gain)) * e, "f")

    def _frequency(self, raw: float, loop: Characteristic) -> float:
        """The crossing frequency in rad/s from that of the polynomial's variable (identity in s)."""
        return raw

    def _infinite_frequency(self, loop: Characteristic) -> float:
        """The frequency at which a root leaves when the degree drops: s = ∞ (``inf``)."""
        return math.inf

    def _crossings(self, d, e, loop: Characteristic) -> list | None:
        """Every gain g > 0 at which a root of d + g·e crosses the imaginary axis or passes through infinity, sorted;
        None when d·conj(e) is real on the whole axis (a root pair that stays on it: no crossing is isolated)."""
        d, e = _aligned(d, e)
        try:
            found = affine_crossings(d, e, "s")
        except ValueError:
            return None
        out = [Crossing(c.gain, self._frequency(c.frequency, loop)) for c in found]
        if e[0] != 0.0 and -d[0] / e[0] > 0:  # the degree drops: a root passes through infinity (z = −1 for `sampled`)
            out.append(Crossing(float(-d[0] / e[0]), self._infinite_frequency(loop)))
        return sorted(out, key=lambda c: (c.gain, c.frequency))

    def _interval(self, d, e, stable, loop: Characteristic) -> StabilityInterval:
        """The stable gains from the crossings of d + K·e in s, each stretch decided by ``stable(K)``."""
        crossings = self._crossings(d, e, loop)
        return StabilityInterval(0.0, None, (), ()) if crossings is None else stable_interval(crossings, stable)

    def stable_gains(self, loop: Characteristic) -> StabilityInterval:
        """Every stable loop gain K (1/s²), K* and ω*, uncached (`boundary` gives them in the family's gain).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        d, e = self.polynomials(loop)
        return self._interval(d, e, lambda K: verdict_at(d, e, K, self.domain), loop)

    def compute_boundary(self, loop: Characteristic):
        return loop.boundary_from(self.name, self.stable_gains(loop))

    def _stable(self, gain: float, loop: Characteristic) -> bool:
        """`is_stable` without the public argument checks (internal probes); NV = 0: D's quotient by its neutral root."""
        d, e = self.polynomials(loop)
        if gain == 0:
            return verdict_at(neutral_quotient(d, self.domain), [0.0], 0.0, self.domain)
        return verdict_at(d, e, loop.loop_gain(gain), self.domain)

    @checked
    def damping_range(self, gain: float, loop: Characteristic) -> tuple:
        """Every interval of the damping δ (1/s) that makes the gain stable at the loop's T, ascending.

        A holonomic loop's c_h (`HolonomicLoop`; ``loop.c_h`` itself is ignored);
        ``()`` when no damping helps (a negative gain, or a delay too long for it).

        Parameters
        ----------
        gain : float
            The family's loop gain (κ, 1/s², of a holonomic loop).
        loop : Characteristic
            The loop judged; its T, s, is kept and its own damping ignored.
        """
        loop.with_damping(0.0)  # a family whose damping is a parameter of its own
        if gain < 0:
            return ()
        p0, p1, p2 = self.parts(loop)
        crossings = self._crossings(p0 + loop.loop_gain(gain) * p2, p1, loop)
        if crossings is None:  # pragma: no cover - only δ·P1 real on the axis, not met
            return ()
        return stable_set(crossings, lambda damping: self._stable(gain, loop.with_damping(damping)))

    @checked
    def roots(self, gain: float, loop: Characteristic) -> np.ndarray:
        """All roots of the characteristic polynomial (s or z).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return np.roots(self.characteristic(gain, loop))

    def batch_polynomials(self, loops):
        """(D, E) of each loop as two arrays of rows of one length (descending; leading zeros allowed).

        Parameters
        ----------
        loops : sequence of Characteristic
            The loops, one row each.
        """
        pairs = [self.polynomials(loop) for loop in loops]
        width = max(max(len(d), len(e)) for d, e in pairs)
        D = np.array([np.pad(d, (width - len(d), 0)) for d, _ in pairs])
        E = np.array([np.pad(e, (width - len(e), 0)) for _, e in pairs])
        return D, E

    def _growth_rates(self, gain: float, loops) -> np.ndarray:
        """max Re s (1/s) at the gain for each loop: eigenvalues of the companion matrices, batched by degree
        (NV = 0: of D/s, the heading loop; −inf for a constant)."""
        loops = list(loops)
        D, E = self.batch_polynomials(loops)
        P = D + np.array([loop.loop_gain(gain) for loop in loops])[:, None] * E
        if gain == 0:  # D(0) = 0 exactly: drop the neutral lateral root
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
    def rightmost_root(self, gain: float, loop: Characteristic) -> complex:
        """Dominant root σ + jω (1/s, rad/s; of a pair the one with ω > 0); NV = 0: the heading loop's (−inf when only
        the neutral root is left).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if gain == 0:
            roots = np.roots(neutral_quotient(self.characteristic(gain, loop), self.domain))
            if roots.size == 0:
                return complex(-math.inf, 0.0)
        else:
            roots = self.roots(gain, loop)
        if roots.size == 0:  # pragma: no cover - a constant polynomial: degree 0 only at c_h·T = 1 and κ = c_h/T together
            return complex(-math.inf, 0.0)
        if self.domain == "z":
            z = roots[np.argmax(np.abs(roots))]
            return complex(np.log(z) / loop.T)
        return _dominant(roots)


def _dominant(roots) -> complex:
    """The root of largest real part; of roots level with it to round-off, the one of largest imaginary part (ω > 0)."""
    top = roots[roots.real >= roots.real.max() - 1e-12 * max(1.0, np.abs(roots).max())]
    return complex(top[np.argmax(top.imag)])
