"""Potential-field laws as `ForceLaw`s, and an equilibrium followed as a parameter moves (docs/fields.md).

Ge & Cui, "New potential functions for mobile robot path planning", IEEE
T-RA 16(5), 2000 ("GC2000"; equation numbers are theirs). A straight wall at
distance d (ρ = d, n_OR the wall normal) and a goal at the frozen distance ρ_g
in a frozen direction give, in units of the attraction A = (m/2) ξ ρ_g^(m−1)
(eq 1), the two parts of a `ForceLaw`:

* `KhatibLaw`: P(d) = η (1/d − 1/ρ0)/d² / A for d <= ρ0, else 0 (eq 3–4); Q = 0;
* `GnronLaw`: P(d) = F_rep1/A = η (1/d − 1/ρ0) ρ_gⁿ/d² / A (eq 10) and
  Q(d) = F_rep2/A = (n/2) η (1/d − 1/ρ0)² ρ_g^(n−1) / A (eq 11), the part of the
  repulsion that points at the goal; with δ > 0, d → d + δ and ρ0 → ρ0 + δ (eq 40).

The magnitudes come from `pfm_stability.laws.potentials` (P = −U_ρ/A, P′ = −U_ρρ/A,
Q = U_g/A, Q′ = U_ρg/A). Both laws are 0 beyond ρ0 and neither is assumed
monotone: R = P/(1 + Q) can rise over part of (0, ρ0), and a wall then has
three equilibria (docs/fields.md, "Three equilibria"). Only the ratio η/ξ
enters P and Q. The goal convention is KB's: the target direction is frozen
and ρ_g enters only the magnitudes; a finite goal straight ahead would add
1/ρ_g to a corridor's N (`finite_goal_gain`, reported apart, never added).

`make_law` builds any static law of the law registry (`pfm_stability.laws.registry`) from
a robot, a controller and the law's own parameters, with the registry's defaults.
`Branch` follows one equilibrium as a parameter moves (a law parameter, α,
L) and finds where its gain crosses a threshold: the critical values of
`pfm_stability.analysis.critical` for laws that are not monotone.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice
from .effective_force import GridWallLaw, calibrate_cell_ratio
from .force_law import Equilibrium, ForceLaw, PowerLaw
from ..parameters import Controller, Robot, check_parameter
from .registry import FORCE_LAWS, check_parameters
from .potentials import attraction_force, repulsion_derivatives
from ..numerics.solve import newton_increasing

__all__ = ["KhatibLaw", "GnronLaw", "make_law", "finite_goal_gain", "Branch"]

_REACH = 1e-9
"""The laws' domain starts at d = 1e-9·ρ0 (P ∝ 1/d³ there: an equilibrium closer is not representable)."""


class _FieldLaw(ForceLaw):
    """What Khatib's and the goal-aware law share: P, Q and their slopes from the potentials."""

    monotone = False

    def _check(self) -> None:
        for field, key in (("xi", "xi"), ("eta", "eta"), ("rho0", "rho0"), ("m", "attraction_exponent"), ("rho_g", "goal_distance")):
            object.__setattr__(self, field, check_parameter(key, getattr(self, field)))
        object.__setattr__(self, "_attraction", float(attraction_force(self.rho_g, self.xi, self.m)))

    @property
    def _n(self) -> float:
        return 0.0

    @property
    def _delta(self) -> float:
        return 0.0

    @property
    def attraction(self) -> float:
        """A = (m/2) ξ ρ_g^(m−1), the attraction's magnitude (GC2000 eq 1): the unit of every force of the law."""
        return self._attraction

    @property
    def scale(self) -> float:
        """η: P and Q are proportional to it."""
        return self.eta

    @property
    def goal_distance(self) -> float:
        return self.rho_g

    @property
    def has_goal_part(self) -> bool:
        return self._n != 0.0

    def terms(self, d):
        """(P, P′, Q, Q′) at distances d (m), in units of the attraction (0 beyond ρ0)."""
        d = np.asarray(d, dtype=float)
        _, u_r, u_g, u_rr, u_rg, _ = repulsion_derivatives(d, self.rho_g, self.eta, self.rho0, self._n, self._delta)
        A = self.attraction
        with np.errstate(over="ignore"):
            return -u_r / A, -u_rr / A, u_g / A, u_rg / A

    def force(self, d):
        return self.terms(d)[0]

    def slope(self, d):
        return self.terms(d)[1]

    def goal_force(self, d):
        return self.terms(d)[2]

    def goal_slope(self, d):
        return self.terms(d)[3]

    def wall_ratio(self, d):
        return self.wall_balance(d)[0]

    def wall_ratio_slope(self, d):
        return self.wall_balance(d)[1]

    def wall_balance(self, d):
        P, dP, Q, dQ = self.terms(d)
        G = 1.0 + Q
        with np.errstate(all="ignore"):  # inf/inf where the law leaves floating point: NaN, skipped by the root search
            return P / G, (dP * G - P * dQ) / (G * G)

    def with_scale(self, scale: float):
        """The same law with η = `scale`."""
        return dataclasses.replace(self, eta=scale)

    def domain(self) -> tuple[float, float]:
        """(1e-9·ρ0, ρ0), m: beyond ρ0 the law is 0."""
        return (_REACH * self.rho0, self.rho0)

    def breakpoints(self) -> tuple:
        """(ρ0,), m: the repulsion's support ends there (P′ jumps to 0: a corridor's N drops to 0 at L = ρ0)."""
        return (self.rho0,)


@dataclass(frozen=True)
class KhatibLaw(_FieldLaw):
    """Khatib's repulsion of a straight wall over the attraction (GC2000 eq 1, 3–4): P(d), Q = 0.

    P(d) = η (1/d − 1/ρ0)/d² / A for d <= ρ0, else 0, A = (m/2) ξ ρ_g^(m−1);
    its local exponent is ν = −dP′/P = (3 − 2d/ρ0)/(1 − d/ρ0).

    Parameters
    ----------
    xi, eta : float
        Attractive and repulsive scaling factors ξ, η (`RANGES`: [1e-6, 1e6]).
    rho0 : float
        Influence distance ρ0, m.
    m : float
        Attraction exponent, [1, 10] (GC2000: 1 or 2).
    rho_g : float
        Frozen distance to the goal ρ_g, m: sets A (for m ≠ 1).
    """

    xi: float
    eta: float
    rho0: float
    m: float
    rho_g: float
    name = "Khatib repulsion (GC2000 eq 3-4)"
    key = "khatib"

    def __post_init__(self):
        self._check()

    def parameters(self) -> dict:
        return {"xi": self.xi, "eta": self.eta, "rho0": self.rho0, "attraction_exponent": self.m, "goal_distance": self.rho_g}


@dataclass(frozen=True)
class GnronLaw(_FieldLaw):
    """Ge & Cui's goal-aware repulsion of a straight wall over the attraction (GC2000 eq 8–11, 40).

    P = F_rep1/A = η c ρ_gⁿ/(d + δ)² / A and Q = F_rep2/A = (n/2) η c² ρ_g^(n−1) / A,
    c = 1/(d + δ) − 1/(ρ0 + δ), for d <= ρ0 (0 beyond); n = 0, δ = 0 is `KhatibLaw`.

    Parameters
    ----------
    xi, eta, rho0, m : float
        As in `KhatibLaw`.
    n : float
        Goal exponent, [0, 10].
    rho_g : float
        As in `KhatibLaw`.
    delta : float
        Surface offset δ of eq (40), m (default 0).
    """

    xi: float
    eta: float
    rho0: float
    m: float
    n: float
    rho_g: float
    delta: float = 0.0
    name = "goal-aware repulsion (GC2000 eq 8-11, 40)"
    key = "gnron"

    def __post_init__(self):
        self._check()
        object.__setattr__(self, "n", check_parameter("goal_exponent", self.n))
        object.__setattr__(self, "delta", check_parameter("delta", self.delta))

    @property
    def _n(self) -> float:
        return self.n

    @property
    def _delta(self) -> float:
        return self.delta

    def parameters(self) -> dict:
        return {"xi": self.xi, "eta": self.eta, "rho0": self.rho0, "attraction_exponent": self.m, "goal_exponent": self.n,
                "goal_distance": self.rho_g, "delta": self.delta}


def finite_goal_gain(law: ForceLaw, N: float) -> float | None:
    """N + 1/ρ_g: a corridor's gain with a finite goal straight ahead at ρ_g (docs/fields.md); None for a target at infinity.

    The goal-directed forces (attraction and Q) then point at the goal, so at
    a lateral offset x they have a lateral part −(1 + 2Q)·x/ρ_g, which adds
    1/ρ_g to N = −∂F_x/∂x / F_y. KB's frozen direction (the report's N) leaves it out.

    Parameters
    ----------
    law : ForceLaw
        The law (its goal distance ρ_g, m, if it has one).
    N : float
        The corridor's gain with the target at infinity, 1/m.
    """
    rho_g = law.goal_distance
    return None if rho_g is None else N + 1.0 / rho_g


def make_law(name: str, robot: Robot, controller: Controller, **parameters) -> ForceLaw:
    """The static law `name` (``registry.FORCE_LAWS``) for this robot and controller.

    ``power``: KB's `PowerLaw(f, n, W)`. ``grid``: `GridWallLaw` with ``cell_ratio``
    (default: calibrated so that its f_av is the controller's f, KB §4),
    ``cell_size`` and ``window_cells``. ``khatib`` / ``gnron``:
    ``xi``, ``eta``, ``rho0``, ``attraction_exponent``, ``goal_exponent``,
    ``delta`` and ``goal_distance`` (required). The parameters each law takes and
    their defaults are the law registry's (`pfm_stability.laws.registry`: the grid's
    0.1 m cells and 33-cell window, KB §2; GC2000 Sec VI's ξ = 1, η = 0.1, ρ0 = 0.8 m,
    m = n = 2, and δ = 0). A parameter given as None is not given.

    Parameters
    ----------
    name : str
        The law (`registry.FORCE_LAWS`).
    robot : Robot
        W (m).
    controller : Controller
        f and n of KB's laws.
    **parameters
        The law's own parameters (`registry.LAWS`), over its defaults.

    Raises
    ------
    ValueError
        A parameter the law does not take (`registry.refusal`), a missing goal distance, or a value out of range.
    """
    check_choice("law", name, FORCE_LAWS)
    given = {k: v for k, v in parameters.items() if v is not None}
    law = check_parameters(name, [k for k in given if k not in ("f", "n")], laws=FORCE_LAWS)
    v = {**law.defaults(), **given}
    if name == "power":
        return PowerLaw(controller.f, controller.n, robot.W)
    if name == "grid":
        size, cells = v["cell_size"], v["window_cells"]
        ratio = given["cell_ratio"] if "cell_ratio" in given else calibrate_cell_ratio(controller.f, controller.n, robot.W, size, cells)
        return GridWallLaw(ratio, controller.n, robot.W, size, cells)
    common = (v["xi"], v["eta"], v["rho0"], v["attraction_exponent"])
    if name == "khatib":
        return KhatibLaw(*common, v["goal_distance"])
    return GnronLaw(*common, v["goal_exponent"], v["goal_distance"], v["delta"])


# ------------------------------------------------------------------ following an equilibrium
def _follow(previous: Equilibrium, before, now):
    """The equilibrium of `now` that continues `previous` (one of `before`), or None if it has vanished.

    Roots of one lateral force keep their order until two of them merge (a
    fold, where N changes sign). With as many equilibria now as before, the
    one at the same place in the order continues `previous` (if N kept its
    sign). Otherwise (a pair was born or merged: `Branch` has made the step
    small) it is the nearest with N of the same sign, unless another
    equilibrium of `before` lies between them.
    """
    itself = min(before, key=lambda e: abs(e.x0 - previous.x0), default=None)  # `previous` as `before` lists it
    if itself is not None and len(now) == len(before):
        candidate = now[before.index(itself)]
        return candidate if (candidate.N < 0) == (previous.N < 0) and math.isfinite(candidate.x0) else None
    same = [e for e in now if (e.N < 0) == (previous.N < 0) and math.isfinite(e.x0)]
    if not same:
        return None
    candidate = min(same, key=lambda e: abs(e.x0 - previous.x0))
    lo, hi = sorted((previous.x0, candidate.x0))
    if any(lo < e.x0 < hi for e in before if e is not itself):
        return None
    return candidate


class Branch:
    """One equilibrium followed as a parameter p moves from p0 to both ends of its range.

    The points are scanned lazily and shared by every threshold asked
    (`nearest_crossing`). Where the number of equilibria changes between two
    points the step is halved (down to 2⁻¹⁰ of it), so that a pair born or
    merging is resolved before the followed one is matched. Where the
    equilibrium vanishes (a fold: N → 0 there) the branch ends and N counts
    as 0 beyond.

    Parameters
    ----------
    equilibria_at : callable
        ``equilibria_at(p, polish)`` → the tuple of `Equilibrium` at p
        (sorted; a ValueError means none); ``polish=False`` may return them
        to ~1e-3 (`force_law.wall_equilibria`), for the scan.
    p0 : float
        The current value.
    start : Equilibrium
        The equilibrium followed (one of ``equilibria_at(p0, True)``).
    lo, hi : float
        The range of p.
    log : bool
        Steps geometric (p > 0) or even.
    steps : int
        Steps per decade (geometric) or over the whole range (even).
    breaks : sequence of float
        Values of p where N may jump (the law changes form there,
        `force_law.ForceLaw.breakpoints`): the scan steps onto each from both
        sides (a relative 1e-9 away), so a band that ends at one is never
        stepped over.
    """

    _FINEST = 2.0**-10

    _BREAK_GAP = 1e-9
    """Relative distance from a break at which the scan stops on either side of it."""

    def __init__(self, equilibria_at, p0: float, start: Equilibrium, lo: float, hi: float, *, log: bool = True, steps: int = 8, breaks=()):
        self._at = equilibria_at
        self.p0, self.start, self.log = p0, start, log
        self._nominal = math.log(10.0) / steps if log else (hi - lo) / steps
        gap = self._BREAK_GAP * (1.0 if log else hi - lo)
        self._fences = sorted({q for b in breaks for q in ((b * (1 - gap), b * (1 + gap)) if log else (b - gap, b + gap)) if lo < q < hi and q != p0})
        before = self._equilibria(p0, False)
        self._points = {+1: [(p0, start, before)], -1: [(p0, start, before)]}
        self._end = {+1: hi, -1: lo}
        self._done = {+1: not p0 < hi, -1: not p0 > lo}
        self._scale = {+1: 1.0, -1: 1.0}
        self._exact = {}

    def _equilibria(self, p: float, polish: bool):
        try:
            return tuple(self._at(p, polish))
        except ValueError:
            return ()

    def _distance(self, p: float) -> float:
        return abs(math.log(p / self.p0)) if self.log else abs(p - self.p0)

    def _next(self, p: float, side: int) -> float:
        step = side * self._nominal * self._scale[side]
        q = p * math.exp(step) if self.log else p + step
        q = min(q, self._end[side]) if side > 0 else max(q, self._end[side])
        fences = [f for f in self._fences if (p < f < q if side > 0 else q < f < p)]  # never step over a break
        return (min(fences) if side > 0 else max(fences)) if fences else q

    def _advance(self, side: int) -> None:
        points = self._points[side]
        p, eq, before = points[-1]
        while True:
            q = self._next(p, side)
            now = self._equilibria(q, False)
            if len(now) == len(before) or self._scale[side] <= self._FINEST or q == p:
                break
            self._scale[side] /= 2
        nxt = _follow(eq, before, now) if eq is not None else None
        points.append((q, nxt, now))
        self._done[side] = nxt is None or q == self._end[side]
        if len(now) == len(before):
            self._scale[side] = min(1.0, 2 * self._scale[side])

    def point(self, side: int, k: int):
        """(p, N) of the k-th scanned point on `side` (+1 towards hi, −1 towards lo); None past the end; N = 0 past a fold.

        Parameters
        ----------
        side : int
            +1 (towards hi) or −1 (towards lo).
        k : int
            Index of the scanned point.
        """
        points = self._points[side]
        while len(points) <= k and not self._done[side]:
            self._advance(side)
        if k >= len(points):
            return None
        p, eq, _ = points[k]
        return p, (eq.N if eq is not None else 0.0)

    def gain(self, side: int, k: int, p: float) -> float:
        """N, exact, of the followed equilibrium at p, between the points k and k + 1 of `side` (0 if it has vanished).

        Parameters
        ----------
        side : int
            +1 (towards hi) or −1 (towards lo).
        k : int
            Index of the scanned point before p.
        p : float
            The parameter, between points k and k + 1.
        """
        _, eq, before = self._points[side][k]
        nxt = _follow(eq, before, self._equilibria(p, True)) if eq is not None else None
        return nxt.N if nxt is not None else 0.0

    def _exact_gain(self, side: int, k: int) -> float:
        """N, exact, at the k-th scanned point of `side` (followed from point k − 1)."""
        if k == 0:
            return self.start.N
        if (side, k) not in self._exact:
            self._exact[side, k] = self.gain(side, k - 1, self._points[side][k][0])
        return self._exact[side, k]

    def _crossing(self, side: int, k: int, threshold: float, above: bool, rtol: float):
        """The exact crossing near the scanned point k of `side` (the scan found N across there), or None."""
        last = len(self._points[side]) - 1
        first = max(1, k - 2)
        while first > 1 and (self._exact_gain(side, first - 1) > threshold) != above:  # the scan was late: look further back
            first -= 1
        for j in range(first, min(k + 1, last) + 1):
            if self.point(side, j) is not None and (self._exact_gain(side, j) > threshold) != above:
                a, b = sorted((self._points[side][j - 1][0], self._points[side][j][0]))
                sign = -1.0 if above == (side > 0) else 1.0  # N − threshold falls from the point j − 1 to j when above

                def rising(p, j=j, sign=sign):  # sign·(N − threshold), increasing from a to b, and its slope by a forward difference
                    p = float(p[0])
                    h = 1e-7 * abs(p) or 1e-12
                    f0 = sign * (self.gain(side, j - 1, p) - threshold)
                    return np.array([f0]), np.array([(sign * (self.gain(side, j - 1, p + h) - threshold) - f0) / h])

                return float(newton_increasing(rising, np.array([a]), np.array([b]), rtol=rtol)[0])
        return None

    def nearest_crossing(self, threshold: float, rtol: float = 1e-9):
        """The p nearest p0 (in log p, or p) where N crosses `threshold`: (p*, side), or (None, None) if N never does.

        The two sides are scanned in order of distance from p0. Where the
        scanned N crosses, the exact N of the neighbouring points finds the
        cell of the exact crossing, which `solve.newton_increasing` narrows to
        `rtol` (a safeguarded Newton step on a forward difference, bisection
        where it does not converge: a law with a kink, e.g. at ρ0, is bracketed
        too); the scan stops once no nearer crossing can follow.

        Parameters
        ----------
        threshold : float
            The value of N, 1/m.
        rtol : float, optional
            Relative tolerance of p*.
        """
        above = self.start.N > threshold
        k = {+1: 0, -1: 0}
        best = None
        while True:
            frontier = []
            for side in (+1, -1):
                here, nxt = self.point(side, k[side]), self.point(side, k[side] + 1)
                if nxt is not None and (best is None or self._distance(here[0]) < best[0]):
                    frontier.append((self._distance(nxt[0]), side))
            if not frontier:
                return (best[1], best[2]) if best else (None, None)
            _, side = min(frontier)
            k[side] += 1
            if (self.point(side, k[side])[1] > threshold) != above:
                root = self._crossing(side, k[side], threshold, above, rtol)
                if root is not None and (best is None or self._distance(root) < best[0]):
                    best = (self._distance(root), root, side)
