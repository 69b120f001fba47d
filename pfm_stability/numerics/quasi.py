"""The retarded quasi-polynomial with several delays, p0(s) + Σ_j p_j(s)·e^(−s·h_j) + K·e^(−s·h_K).

A steering loop whose plant has a dead time D acts with it on the whole command k(δ − θ): the heading term
is delayed by D, the field's by T + D (docs/models.md, "Plant gain and dead time"),

    τs³ + s² + gk·s·e^(−sD) + gk(cs + NV)·e^(−s(T + D)) = 0,

two delays that no single-delay route (`numerics.delay`) takes. This module answers every question the loop
models ask of such an equation, for any real polynomials with deg p_j < deg p0 (retarded), each route
independent of the others:

* **Root count** (`unstable_root_count`): the argument principle on the imaginary axis. f(s) = Δ(s)/q(s) with
  q(s) = lead·(s + w)^n (no zero in Re s >= 0, the same leading term) tends to 1 uniformly in Re s >= 0, so the
  number of roots in Re s > 0 is −(1/π)·Δarg f(jω) over ω from 0 to ∞. The phase is followed on a grid refined
  wherever it turns by more than π/4 between neighbours, up to a frequency beyond which |f − 1| < 1/2 (a
  decreasing majorant proves it), and the rest of the turn is −arg f there. A root on the axis (|Δ| below round-off
  where the phase jumps) gives None: the boundary, undecided.
* **Gain crossings** (`gain_crossings`, `stable_gains`): a root sits at s = jω for the real gain
  K = G(ω) = −A(jω)·e^(jωh_K) (A the rest of Δ), so the crossings are the roots of Im G(ω) = 0 with Re G > 0. The
  root moves right as K grows exactly when the phase of G increases there (Re(ds/dK) = |G|·φ′/|G_s|²). Beyond a
  frequency where a decreasing majorant bounds |d arg(A/p0)/dω| below h_K every crossing destabilises and the
  gains only grow, so finitely many crossings decide the stable set: the count at K → 0+ (the root at s = 0 leaves
  to the left; `heading`, the quotient by s) and ±2 per crossing.
* **Delay margins** (`shift_margin`): with some delays shifted by x >= 0, Δ = U + V·e^(−sx); a root reaches
  s = jω when |U(jω)| = |V(jω)| and e^(−jωx) = −U/V, so the first x of every root ω of |U|² − |V|² is a
  crossing delay, and the smallest is the margin of a loop stable at x = 0 (roots of a retarded equation move
  continuously with its delays and cannot enter Re s > 0 from infinity).
* **Rightmost roots** (`rightmost_roots`): pseudospectral collocation of the infinitesimal generator on
  [−max h, 0] with each delayed state interpolated at its own −h_j (Breda, Maset & Vermiglio, SIAM J. Sci.
  Comput. 27, 2005), each eigenvalue polished by Newton's method on Δ itself.

With one delay and p0 + p_1 undelayed this is the equation `numerics.delay.DelayLoop` solves by the crossing count
of Cooke & van den Driessche; the tests check the two against each other and both against QPmR and cxroots.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .crossings import StabilityInterval, walk_stable_set
from .delay import chebyshev_collocation, single_blas_thread

__all__ = ["DelayedTerm", "QuasiPolynomial", "sign_change_roots"]

_TWO_PI = 2.0 * math.pi
_PHASE_STEP = math.pi / 4
"""Largest turn of the phase of f(jω) between neighbouring grid points the count accepts (a quarter turn: a root
of Δ near the axis turns the phase by nearly π over a short stretch, which the refinement then resolves)."""
_REFINEMENTS = 60
"""Bisections of one grid interval before a phase jump counts as a root on the axis (2⁻⁶⁰ of the interval)."""
_MAX_POINTS = 2_000_000
"""The most grid points one count, crossing search or margin search evaluates (far beyond every loop of the package:
a search that needs more is told so rather than left to run)."""


@dataclass(frozen=True)
class DelayedTerm:
    """One term p(s)·e^(−s·h) of a quasi-polynomial.

    Attributes
    ----------
    poly : tuple of float
        p(s), descending real coefficients.
    delay : float
        h, s, >= 0.
    """

    poly: tuple
    delay: float


def _majorant(p, w):
    """Σ |p_i|·ω^i: a bound of |p(jω)| that increases with ω (p descending)."""
    return np.polyval(np.abs(np.asarray(p, dtype=float)), w)


class QuasiPolynomial:
    """Δ(s; K) = p0(s) + Σ_j p_j(s)·e^(−s·h_j) + K·e^(−s·h_K) (retarded: deg p_j < deg p0, K a constant).

    Parameters
    ----------
    p0 : array_like
        The undelayed polynomial, descending, degree >= 1.
    terms : sequence of DelayedTerm
        The delayed polynomials (a delay of 0 is allowed; such a term is undelayed).
    gain_delay : float
        h_K, s: the delay of the gain term K.
    """

    def __init__(self, p0, terms, gain_delay: float):
        self.p0 = np.trim_zeros(np.asarray(p0, dtype=float), "f")
        if len(self.p0) < 2:
            raise ValueError("p0(s) must have degree >= 1 (a retarded quasi-polynomial)")
        self.terms = tuple(DelayedTerm(tuple(np.trim_zeros(np.asarray(t.poly, dtype=float), "f")), float(t.delay)) for t in terms)
        self.terms = tuple(t for t in self.terms if len(t.poly))
        if any(len(t.poly) >= len(self.p0) for t in self.terms):
            raise ValueError("every delayed p_j(s) must have a lower degree than p0(s) (a retarded quasi-polynomial)")
        self.gain_delay = float(gain_delay)
        self.n = len(self.p0) - 1
        self.lead = float(self.p0[0])
        self.max_delay = max([self.gain_delay] + [t.delay for t in self.terms])
        self.p0_roots = np.roots(self.p0)
        if np.any(self.p0_roots.real > 1e-12 * max(1.0, float(np.max(np.abs(self.p0_roots), initial=0.0)))):
            raise ValueError("p0(s) must have its roots in Re s <= 0 (the drive's lags and the integrators)")

    # ------------------------------------------------------------------ values
    def rest(self, s):
        """A(s) = p0(s) + Σ_j p_j(s)·e^(−s·h_j): Δ without its gain term.

        Parameters
        ----------
        s : complex or ndarray
            Where, 1/s.
        """
        out = np.polyval(self.p0, s)
        for t in self.terms:
            out = out + np.polyval(t.poly, s) * np.exp(-s * t.delay)
        return out

    def value(self, s, K: float):
        """Δ(s; K).

        Parameters
        ----------
        s : complex or ndarray
            Where, 1/s.
        K : float
            The gain.
        """
        return self.rest(s) + K * np.exp(-s * self.gain_delay)

    def _rest_slope(self, s):
        """dA/ds."""
        out = np.polyval(np.polyder(self.p0), s)
        for t in self.terms:
            p = np.asarray(t.poly)
            dp = np.polyval(np.polyder(p), s) if len(p) > 1 else 0.0 * s
            out = out + (dp - t.delay * np.polyval(p, s)) * np.exp(-s * t.delay)
        return out

    def slope(self, s, K: float):
        """dΔ/ds at s.

        Parameters
        ----------
        s : complex or ndarray
            Where, 1/s.
        K : float
            The gain.
        """
        return self._rest_slope(s) - K * self.gain_delay * np.exp(-s * self.gain_delay)

    def heading(self) -> "QuasiPolynomial":
        """Δ(s; 0)/s: the loop at K = 0 without its root at s = 0 (p0 and every p_j vanish at 0).

        Raises
        ------
        ValueError
            If some polynomial does not vanish at s = 0.
        """
        polys = [self.p0] + [np.asarray(t.poly) for t in self.terms]
        if any(p[-1] != 0.0 for p in polys):
            raise ValueError("heading() needs p0(0) = p_j(0) = 0 (a root at s = 0 for K = 0)")
        return QuasiPolynomial(self.p0[:-1], [DelayedTerm(t.poly[:-1], t.delay) for t in self.terms if len(t.poly) > 1], self.gain_delay)

    # --------------------------------------------------------------- bounds
    def _others_majorant(self, w, K: float):
        """A bound of |Δ(jω) − p0(jω)| that increases with ω."""
        out = abs(K) + 0.0 * w
        for t in self.terms:
            out = out + _majorant(t.poly, w)
        return out

    def _root_radius(self, K: float) -> float:
        """R: every root with Re s >= 0 has |s| <= R (|p0(s)| <= Σ|p_j(s)| + |K| there, since |e^(−sh)| <= 1)."""
        w = 1.0
        lower = lambda x: abs(self.lead) * x ** self.n - _majorant(self.p0[1:], x) - self._others_majorant(x, K)
        while lower(w) <= 0:
            w *= 2.0
        return w

    # ------------------------------------------------------------ root count
    def unstable_root_count(self, K: float) -> int | None:
        """Roots with Re s > 0 (argument principle, module docstring), or None when a root is on the imaginary axis.

        Parameters
        ----------
        K : float
            The gain; Δ(0; K) must not vanish (K != 0 for a loop with p0(0) = p_j(0) = 0: use `heading` at K = 0).
        """
        if self.value(0.0, K) == 0.0:
            return None
        w = 1.0 / self.max_delay if self.max_delay > 0 else 1.0
        q = self._reference(w)
        f = lambda om: self.value(1j * om, K) / np.polyval(q, 1j * om)
        end, fine = self._flat_end(q, K)
        omega = self._axis_grid(end, fine, w)
        values = f(omega)
        omega, values = _refine_phase(omega, values, f)
        if omega is None:
            return None
        turn = float(np.sum(_wrapped(np.diff(np.angle(values))))) - float(np.angle(values[-1]))
        count = -turn / math.pi
        nearest = round(count)
        if abs(count - nearest) > 0.25:  # pragma: no cover - the tail bound makes the sum an integer to round-off
            return None
        return int(nearest)

    def is_stable(self, K: float) -> bool:
        """No root in Re s >= 0 (`unstable_root_count` is 0).

        Parameters
        ----------
        K : float
            The gain.
        """
        return self.unstable_root_count(K) == 0

    def _modulus(self, x):
        """|p0(jx)|."""
        return np.abs(np.polyval(self.p0, 1j * np.asarray(x, dtype=float)))  # (a resonant p0 may dip: `_settled` scans it)

    def _lower_modulus(self, roots, x):
        """|lead|·Π(x − |r|), 0 below max |r|: a lower bound of |p(jx)| for the polynomial of `roots` (|jx − r| >= x − |r|)
        that increases with x, so that a ratio with it in the denominator and a lower-degree majorant above decreases."""
        x = np.asarray(x, dtype=float)
        gaps = x[..., None] - np.abs(np.asarray(roots))[None, :] if x.ndim else x - np.abs(np.asarray(roots))
        return abs(self.lead) * np.prod(np.maximum(gaps, 0.0), axis=-1)

    def _reference(self, w: float) -> np.ndarray:
        """q(s): p0 with its roots at 0 moved to −w (descending): no root in Re s >= 0, p0's leading term and lags."""
        roots = np.where(np.abs(self.p0_roots) <= 1e-12 * max(1.0, float(np.max(np.abs(self.p0_roots), initial=0.0))), -w, self.p0_roots)
        return np.real(self.lead * np.poly(roots))

    def _settled(self, bound, threshold: float, start: float) -> float:
        """The smallest x >= start beyond which bound(x) < threshold: scanned on a log grid (64 points a decade) up to
        where its analytic majorant (`_lower_modulus` for the polynomial's modulus: above `bound`, and decreasing) is
        below the threshold itself. `bound(x, analytic)` takes arrays of x."""
        top = max(start, 1.0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # the analytic bound is inf below the roots' moduli
            while not bound(np.array([top]), True)[0] < threshold:
                top *= 2.0
            if top <= start:
                return start
            grid = np.geomspace(start, top, max(2, int(64 * math.log10(top / start)) + 1))
            over = np.flatnonzero(~(bound(grid, False) < threshold))
        return float(grid[min(over[-1] + 1, grid.size - 1)]) if over.size else start

    def _flat_end(self, q, K: float) -> tuple:
        """(end, fine): beyond `end` |f(jω) − 1| < 1/4 for f = Δ/q (the rest of the turn is −arg f there), beyond `fine`
        the delayed terms are below 1/8 of |q| (their exponentials turn f by less than 0.13 rad: a log grid follows it)."""
        difference = np.polysub(self.p0, q)[1:]  # degree < n
        q_roots = np.roots(q)
        modulus = lambda x, analytic: self._lower_modulus(q_roots, x) if analytic else np.abs(
            self.lead * np.prod(1j * x[:, None] - q_roots[None, :], axis=1))
        start = 1e-6 / self.max_delay if self.max_delay > 0 else 1e-6
        end = self._settled(lambda x, a: (_majorant(difference, x) + self._others_majorant(x, K)) / modulus(x, a), 0.25, start)
        fine = self._settled(lambda x, a: self._others_majorant(x, K) / modulus(x, a), 0.125, start)
        return max(end, 1.0 / self.max_delay if self.max_delay > 0 else end), min(fine, end)

    def _axis_grid(self, end: float, fine: float, scale: float) -> np.ndarray:
        """A grid on [0, end]: logarithmic (64 points a decade from 1e-6·scale), and uniform up to `fine` at a step that
        resolves the fastest exponential (π/(8·max h)); beyond `fine` the delayed terms are too small to turn the phase."""
        step = math.pi / (8.0 * self.max_delay) if self.max_delay > 0 else end / 64.0
        count = int(math.ceil(fine / step)) + 1
        if count > _MAX_POINTS:
            raise ValueError(f"the quasi-polynomial's axis needs {count} grid points (delay {self.max_delay:g} s over "
                             f"{fine:g} rad/s), more than {_MAX_POINTS}")
        low = 1e-6 * min(scale, end)
        log = np.geomspace(low, end, max(16, int(64 * math.log10(end / low))))
        return np.unique(np.concatenate([[0.0], log, np.linspace(0.0, fine, count)]))

    # --------------------------------------------------------- gain crossings
    def gain_function(self, omega):
        """G(ω) = −A(jω)·e^(jω·h_K): the gain that puts a root at jω (real there), complex elsewhere.

        Parameters
        ----------
        omega : float or ndarray
            ω, rad/s.
        """
        return -self.rest(1j * omega) * np.exp(1j * omega * self.gain_delay)

    def _gain_phase_slope(self, omega):
        """d arg G/dω (rad per rad/s): positive where a crossing at ω destabilises."""
        G = self.gain_function(omega)
        dG = -(1j * self._rest_slope(1j * omega)) * np.exp(1j * omega * self.gain_delay) + 1j * self.gain_delay * G
        return np.imag(dG / G)

    def _monotone_from(self) -> float:
        """ω beyond which every crossing destabilises (arg G increases): a decreasing majorant of
        |d arg(A/p0)/dω| is below h_K there, and |A/p0 − 1| < 1/2 (module docstring)."""
        if self.gain_delay == 0:
            raise ValueError("a gain term without delay makes a polynomial loop, not a quasi-polynomial")
        if np.any(np.roots(self.p0).real > 0):
            raise ValueError("the gain crossings need p0(s) without roots in Re s > 0 (its phase must not fall)")
        def excess(x, analytic):  # < 1 where the ratio is below 1/2 and the phase's wobble below h_K/2
            modulus = self._lower_modulus(self.p0_roots, x) if analytic else self._modulus(x)
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = sum(_majorant(t.poly, x) for t in self.terms) / modulus if self.terms else 0.0 * x
                slope = sum(_majorant(np.polyder(np.asarray(t.poly)), x) + t.delay * _majorant(t.poly, x) for t in self.terms) / modulus if self.terms else 0.0 * x
            with np.errstate(divide="ignore", over="ignore"):
                wobble = np.where(ratio < 1.0, (slope + ratio * self.n / x) / np.maximum(1.0 - ratio, 1e-300), np.inf)
            return np.maximum(2.0 * ratio, wobble / (0.5 * self.gain_delay))

        return self._settled(excess, 1.0, 1e-6 / self.gain_delay)

    def _gains_above(self, gain: float, start: float) -> float:
        """ω beyond which every crossing's gain exceeds `gain`: |G(jω)| >= |p0(jω)| − Σ|p_j(jω)| > gain there."""
        def ratio(x, analytic):
            modulus = self._lower_modulus(self.p0_roots, x) if analytic else self._modulus(x)
            with np.errstate(divide="ignore"):
                return (self._others_majorant(x, 0.0) + gain) / modulus

        return self._settled(ratio, 1.0, start)

    def _crossings_between(self, low: float, high: float) -> list:
        """Every crossing (gain > 0, frequency, direction ±1; 0 tangent) with low < ω <= high."""
        step = math.pi / (8.0 * self.max_delay)
        count = int(math.ceil((high - low) / step)) + 1
        if count > _MAX_POINTS:
            raise ValueError(f"the gain crossings need {count} grid points, more than {_MAX_POINTS}")
        grid = np.unique(np.concatenate([np.linspace(low, high, count), np.geomspace(max(low, 1e-9 * high), high, 512)]))
        grid = grid[grid > 0]
        roots = sign_change_roots(lambda x: np.imag(self.gain_function(x)), grid)
        gains, slopes = np.real(self.gain_function(roots)), self._gain_phase_slope(roots)
        keep = gains > 0
        directions = np.where(np.abs(slopes) <= 1e-12 * self.gain_delay, 0, np.sign(slopes)).astype(int)
        return [(float(g), float(w), int(d)) for g, w, d in zip(gains[keep], roots[keep], directions[keep])]

    def gain_crossings(self) -> tuple:
        """The crossings (K > 0, ω, direction) that can bound the stable set, sorted by gain, and the count Z(0+).

        Returns
        -------
        crossings : list of (float, float, int)
            (K, ω rad/s, +1 destabilising / −1 stabilising / 0 tangent), ascending in K: every crossing with K <= top.
        top : float
            The largest gain of a crossing that may stabilise (0 if none): above it every crossing destabilises.
        base : int or None
            Roots in Re s > 0 as K → 0+ (the root at s = 0 moves left: `heading`'s count); None on the boundary.
        """
        safe = self._monotone_from()
        found = self._crossings_between(0.0, safe)
        top = max([c[0] for c in found], default=0.0)
        high = max(safe, self._gains_above(top, safe))  # beyond: every crossing destabilises with a gain above every one found
        found += [c for c in self._crossings_between(safe, high) if c[0] <= top]
        return sorted(found), top, self.heading().unstable_root_count(0.0)

    def stable_gains(self, K_max: float) -> StabilityInterval:
        """Every interval of gains 0 < K <= K_max on which every root has Re s < 0, with K* and ω*.

        The count starts at Z(0+) and moves by 2·direction at each crossing (module docstring); above the last
        crossing found it can only grow, and a stretch stable there ends at the next crossing, searched for on.

        Parameters
        ----------
        K_max : float
            The largest gain of interest (a stable stretch reaching it is open, ``inf``).
        """
        crossings, top, base = self.gain_crossings()
        if base is None:
            return StabilityInterval(0.0, None, (), ())
        return walk_stable_set(base, [(gain, w, 2 * direction) for gain, w, direction in crossings],
                               tail=lambda last: self._next_crossing(top, K_max))

    def _next_crossing(self, above: float, K_max: float):
        """(K, ω) of the smallest crossing gain above `above` (every one destabilises there), None up to K_max."""
        low = self._monotone_from()
        best = None
        while True:
            high = 2.0 * low
            for gain, w, _ in self._crossings_between(low, high):
                if gain > above and (best is None or gain < best[0]):
                    best = (gain, w)
            limit = K_max if best is None else best[0]
            if high >= self._gains_above(limit, low):
                return best if best is not None and best[0] <= K_max else None
            low = high

    # ------------------------------------------------------------ delay margins
    def shift_margin(self, K: float, shifted) -> float:
        """The smallest x > 0 at which a root reaches the imaginary axis when the delays of the `shifted` terms grow by x.

        The loop at x = 0 must be stable for this to be its margin (the caller checks); ``inf`` when no root can
        reach the axis.

        Parameters
        ----------
        K : float
            The gain (0: the quotient by s, `heading`, is searched).
        shifted : sequence of bool
            One per term of `terms`, then one for the gain term: whether its delay grows with x.
        """
        shifted = tuple(bool(x) for x in shifted)
        if len(shifted) != len(self.terms) + 1:
            raise ValueError(f"shifted must name every term and the gain: {len(self.terms) + 1} flags; got {len(shifted)}")
        terms = [(np.asarray(t.poly), t.delay, moves) for t, moves in zip(self.terms, shifted)]
        if K != 0.0:
            terms.append((np.array([K]), self.gain_delay, shifted[-1]))
        p0 = self.p0
        if K == 0.0:  # the quotient by s: the root at 0 stays there
            p0, terms = p0[:-1], [(p[:-1], h, moves) for p, h, moves in terms if len(p) > 1]
        if not any(moves for _, _, moves in terms):
            return math.inf
        U = lambda w: np.polyval(p0, 1j * w) + sum(np.polyval(p, 1j * w) * np.exp(-1j * w * h) for p, h, moves in terms if not moves)
        V = lambda w: sum(np.polyval(p, 1j * w) * np.exp(-1j * w * h) for p, h, moves in terms if moves)
        F = lambda w: np.abs(U(w)) ** 2 - np.abs(V(w)) ** 2
        roots = np.roots(p0)

        def ratio(x, analytic):  # < 1 where |U| >= |p0| − Σ|unshifted| > Σ|shifted| >= |V|: no root of |U|² − |V|² beyond
            modulus = self._lower_modulus(roots, x) if analytic else np.abs(np.polyval(p0, 1j * x))
            with np.errstate(divide="ignore"):
                return sum(_majorant(p, x) for p, _, _ in terms) / modulus

        end = self._settled(ratio, 1.0, 1e-6 / self.max_delay if self.max_delay > 0 else 1e-6)
        roots = _sign_changes(F, end, max([h for _, h, _ in terms] + [self.max_delay]))
        margin = math.inf
        for w in roots:
            ratio = -U(w) / V(w)
            x = (-float(np.angle(ratio))) % _TWO_PI / w
            margin = min(margin, x if x > 0 else _TWO_PI / w)
        return margin

    # ---------------------------------------------------------- rightmost roots
    def rightmost_roots(self, K: float, count: int = 6, nodes: int = 40) -> np.ndarray:
        """The `count` roots of largest real part, sorted by decreasing real part (conjugate pairs both).

        Pseudospectral collocation on `nodes` Chebyshev nodes in [−max h, 0], each eigenvalue polished by Newton's
        method on Δ (|Δs| < 1e-13·max(1, |s|)); an empty array where none polishes (|s|·h in the thousands).

        Parameters
        ----------
        K : float
            The gain.
        count : int
            How many roots (at most).
        nodes : int
            Chebyshev nodes of the collocation.
        """
        if self.max_delay == 0:
            p = functools.reduce(np.polyadd, [np.asarray(t.poly) for t in self.terms], np.polyadd(self.p0, [K]))
            roots = np.roots(p)
            return roots[np.argsort(-roots.real)][:count]
        with single_blas_thread():
            eig = np.linalg.eigvals(self._generator(K, nodes))
        eig = eig[np.isfinite(eig)]
        eig = eig[np.argsort(-eig.real)][: max(4 * count, 12)]
        polished = []
        for s in self._newton(eig, K):
            if not any(abs(s - p) <= 1e-8 * max(1.0, abs(s)) for p in polished):
                polished.append(s)
        polished = np.array(polished)
        return polished[np.argsort(-polished.real)][:count]

    def _generator(self, K: float, nodes: int) -> np.ndarray:
        """The collocated infinitesimal generator: derivative rows at the nodes, the equation at θ = 0."""
        n, lead, h = self.n, self.lead, self.max_delay
        A0 = np.zeros((n, n))
        A0[:-1, 1:] = np.eye(n - 1)
        A0[-1, :] = -self.p0[:0:-1] / lead
        delayed = [(np.asarray(t.poly)[::-1], t.delay) for t in self.terms] + [(np.array([K]), self.gain_delay)]
        x, c, D = chebyshev_collocation(nodes)
        D = D * (2.0 / h)  # θ = h(x − 1)/2 ∈ [−h, 0]
        G = np.kron(D, np.eye(n))
        G[:n, :] = 0.0
        G[:n, :n] = A0
        for coefficients, delay in delayed:
            row = np.zeros(n)
            row[: len(coefficients)] = -coefficients / lead
            weights = _lagrange_weights(x, c, 2.0 * (-delay) / h + 1.0)
            for l in np.flatnonzero(weights):
                G[n - 1, l * n:(l + 1) * n] += weights[l] * row
        return G

    def _newton(self, starts, K: float, iterations: int = 50) -> np.ndarray:
        """Newton's method on Δ from every start at once; the roots it converged to (|Δs| < 1e-13·max(1, |s|), or a
        residual below 1e-9·|p0(s)| after `iterations`), in the order of the starts."""
        s = np.asarray(starts, dtype=complex).copy()
        done = np.zeros(s.shape, bool)
        alive = np.ones(s.shape, bool)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for _ in range(iterations):
                active = alive & ~done
                if not active.any():
                    break
                f, df = self.value(s[active], K), self.slope(s[active], K)
                bad = (df == 0) | ~np.isfinite(f) | ~np.isfinite(df)
                step = np.where(bad, 0.0, f / np.where(bad, 1.0, df))
                index = np.flatnonzero(active)
                alive[index[bad]] = False
                s[active] = s[active] - step
                done[index[~bad & (np.abs(step) <= 1e-13 * np.maximum(1.0, np.abs(s[active])))]] = True
            rest = alive & ~done
            if rest.any():
                residual = np.abs(self.value(s[rest], K))
                done[np.flatnonzero(rest)[residual <= 1e-9 * np.maximum(1.0, np.abs(np.polyval(self.p0, s[rest])))]] = True
        return s[done & alive]


def sign_change_roots(f, grid, values=None) -> np.ndarray:
    """Every root of the real function f (arrays in, arrays out) in a cell of `grid` where f changes sign, all refined at
    once to machine precision (`scipy.optimize.elementwise.find_root`, Chandrupatla's bracketing method).

    Parameters
    ----------
    f : callable
        ndarray → ndarray.
    grid : ndarray
        Ascending points.
    values : ndarray, optional
        f(grid), when already computed.
    """
    from scipy.optimize.elementwise import find_root

    values = f(grid) if values is None else values
    cells = np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)
    if cells.size == 0:
        return np.empty(0)
    result = find_root(f, (grid[cells], grid[cells + 1]), tolerances={"xatol": 0.0, "xrtol": 4 * np.finfo(float).eps})
    return np.asarray(result.x, dtype=float)


def _lagrange_weights(x, c, point: float) -> np.ndarray:
    """The barycentric Lagrange weights of the Chebyshev points x (weights c) at `point` in [−1, 1]."""
    difference = point - x
    exact = np.flatnonzero(np.abs(difference) <= 1e-14)
    if exact.size:
        out = np.zeros(len(x))
        out[exact[0]] = 1.0
        return out
    terms = c / difference
    return terms / terms.sum()


def _wrapped(angles):
    """Angles wrapped into (−π, π]."""
    return (np.asarray(angles) + math.pi) % _TWO_PI - math.pi


def _refine_phase(omega, values, f):
    """Insert grid points where the phase of f turns by more than `_PHASE_STEP` between neighbours, until none does.

    Returns (omega, values), or (None, None) when an interval shrinks to round-off with the jump left (a root on the axis).
    """
    for _ in range(_REFINEMENTS):
        jumps = np.flatnonzero(np.abs(_wrapped(np.diff(np.angle(values)))) > _PHASE_STEP)
        if jumps.size == 0:
            return omega, values
        lo, hi = omega[jumps], omega[jumps + 1]
        if np.any(hi - lo <= 4e-16 * np.maximum(hi, 1e-300)) or omega.size > _MAX_POINTS:
            return None, None
        middle = 0.5 * (lo + hi)
        omega = np.concatenate([omega, middle])
        values = np.concatenate([values, f(middle)])
        order = np.argsort(omega, kind="stable")
        omega, values = omega[order], values[order]
    return None, None


def _sign_changes(F, end: float, delay: float) -> list:
    """Every root ω in (0, end] of the real function F: its sign changes on a grid that resolves the exponentials
    (π/(16·delay)), and a pair of close roots found where a local minimum of |F| on the grid dips through 0."""
    from scipy.optimize import brentq, minimize_scalar  # here: the report's cold start does not load scipy.optimize

    step = math.pi / (16.0 * delay) if delay > 0 else end / 256.0
    count = int(math.ceil(end / step)) + 1
    if count > _MAX_POINTS:
        raise ValueError(f"the delay margin needs {count} grid points, more than {_MAX_POINTS}")
    grid = np.unique(np.concatenate([np.linspace(0.0, end, count), np.geomspace(1e-9 * end, end, 1024)]))[1:]
    values = F(grid)
    roots = list(sign_change_roots(F, grid, values))
    magnitude = np.abs(values)
    dips = (magnitude[1:-1] < 0.5 * magnitude[:-2]) & (magnitude[1:-1] < 0.5 * magnitude[2:])  # a sharp local minimum of |F|
    for i in np.flatnonzero(dips) + 1:
        if not np.sign(values[i - 1]) == np.sign(values[i]) == np.sign(values[i + 1]) or values[i] == 0:
            continue
        sign = np.sign(values[i])
        best = minimize_scalar(lambda w: sign * F(w), bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                               options={"xatol": 1e-14 * grid[i + 1]})
        if sign * best.fun < 0 and np.sign(F(grid[i - 1])) == np.sign(F(grid[i + 1])) == sign:  # a dip through 0, not round-off
            roots.append(brentq(F, grid[i - 1], best.x, xtol=1e-15 * grid[i + 1], rtol=1e-15))
            roots.append(brentq(F, best.x, grid[i + 1], xtol=1e-15 * grid[i + 1], rtol=1e-15))
    return sorted(roots)
