"""Lateral force laws and the equilibria and environment gains N they produce.

Forces are in units of the attraction (KB's F_ct = F_a), so a law is
dimensionless. A law has two parts (docs/fields.md, "The field interface"):

* P(d) = `force`: the repulsion along the wall normal, F_r(d)/F_a; KB's lumped
  law (Koren & Borenstein 1991 eq 8 with eq 13) is the power law f·(W/d)^n;
* Q(d) = `goal_force`: a repulsion component that points at the goal (Ge &
  Cui 2000's F_rep2, eq 11), 0 for KB's laws. The goal direction is frozen.

With the target at angle α from the wall normal the lateral and forward forces
are F_x(d) = P(d) − (1 + Q(d)) cos α and F_y = (1 + Q(d)) sin α, so

* wall: the equilibria are every root of F_x, i.e. of R(d) = P/(1 + Q) = cos α
  (`wall_ratio`; KB eq 22–23 when Q = 0), and at each the linearization (eq 10–11,
  δ = 0) gives N = −(P′ − Q′cos α)/((1 + Q) sin α) = −R′(d0)/sin α and the
  heading gain c = 0 (a static law);
* corridor, target straight ahead: F_x(x) = P(L + x) − P(L − x),
  F_y = 1 + Q(L + x) + Q(L − x), N = −2P′(L)/(1 + 2Q(L)) in the middle.

Laws are not assumed monotone: `wall_equilibria` finds every root (a dense
scan in log d, each sign change narrowed by `solve.newton_increasing`).
A law that declares itself decreasing without a goal part (``monotone``:
`PowerLaw`, the grid's law) keeps the one-root closed paths.

Everything downstream depends on the product NV only. The gains take numbers
or numpy arrays: `wall_gain` and `corridor_gain` check a number against its
range and evaluate an array as it is (the caller checks its axis);
`wall_gain_at_distance` gives α and N on the equilibrium distance, and
`power_law_wall_gain` / `power_law_corridor_gain` are KB's closed forms on
arrays of every parameter. Every N on arrays in the package comes from here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_number, check_type
from ..parameters import Controller, Robot, check_parameter, to_degrees
from ..numerics.solve import bisect_root, expand_bracket, invert_decreasing, newton_increasing

__all__ = [
    "law_in_force",
    "ForceLaw",
    "PowerLaw",
    "Equilibrium",
    "wall_equilibrium",
    "wall_equilibria",
    "corridor_equilibria",
    "wall_gain",
    "wall_gain_arrays",
    "wall_gain_at_distance",
    "corridor_gain",
    "power_law_wall_gain",
    "power_law_corridor_gain",
]


class ForceLaw:
    """A lateral force law in units of the attraction: P(d) = `force`, Q(d) = `goal_force`; d in m.

    Subclasses implement `force`, `slope` and `with_scale`; a law with a
    goal-directed part (Ge & Cui 2000's F_rep2) also `goal_force` and
    `goal_slope` (default 0). `distance_for` has a numerical default.

    Attributes
    ----------
    scale : float
        The law's strength parameter (KB's f for the power law; the cell
        force ratio for a grid law); `with_scale` returns the same law with
        another strength, the force being proportional to it.
    monotone : bool
        True when the law declares P decreasing on its whole `domain` and
        Q = 0 (`PowerLaw`, `GridWallLaw`): one wall equilibrium, found by
        `distance_for`. Otherwise (the default: nothing is assumed) every
        root is searched (`wall_equilibria`).
    key : str or None
        The law's name in the law registry (`laws.registry.FORCE_LAWS`; None for a law built in code).
    goal_distance : float or None
        ρ_g, m, for a law whose magnitudes depend on a frozen goal distance
        (docs/fields.md, "The frozen goal"); None for a target at infinity.
    """

    scale: float = 1.0
    name: str = "force law"
    monotone: bool = False
    key: str | None = None
    goal_distance: float | None = None

    def force(self, d):
        """P(d) = F_r(d)/F_a (dimensionless).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        raise NotImplementedError  # pragma: no cover - interface

    def slope(self, d):
        """P′(d) = d(F_r/F_a)/dd, 1/m.

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        raise NotImplementedError  # pragma: no cover - interface

    def goal_force(self, d):
        """Q(d): the repulsion's component towards the goal over the attraction (0 by default).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        return np.zeros(np.shape(d))

    def goal_slope(self, d):
        """Q′(d), 1/m (0 by default).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        return np.zeros(np.shape(d))

    @property
    def has_goal_part(self) -> bool:
        """True when Q is not identically 0 (`goal_force` overridden)."""
        return type(self).goal_force is not ForceLaw.goal_force

    def wall_ratio(self, d):
        """R(d) = P/(1 + Q): the wall equilibria solve R(d0) = cos α (P itself when Q = 0).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        if not self.has_goal_part:
            return self.force(d)
        with np.errstate(invalid="ignore", over="ignore"):
            return np.asarray(self.force(d), dtype=float) / (1.0 + np.asarray(self.goal_force(d), dtype=float))

    def wall_ratio_slope(self, d):
        """R′(d) = (P′(1 + Q) − P Q′)/(1 + Q)², 1/m (P′ when Q = 0); N = −R′(d0)/sin α.

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        if not self.has_goal_part:
            return self.slope(d)
        P, dP = np.asarray(self.force(d), dtype=float), np.asarray(self.slope(d), dtype=float)
        G, dQ = 1.0 + np.asarray(self.goal_force(d), dtype=float), np.asarray(self.goal_slope(d), dtype=float)
        with np.errstate(invalid="ignore", over="ignore"):
            return (dP * G - P * dQ) / (G * G)

    def wall_balance(self, d):
        """(R, R′) at d in one evaluation (`wall_ratio`, `wall_ratio_slope`): what the wall's root search needs.

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        return np.asarray(self.wall_ratio(d), dtype=float), np.asarray(self.wall_ratio_slope(d), dtype=float)

    def with_scale(self, scale: float) -> "ForceLaw":
        """The same law with strength `scale` (force ∝ scale).

        Parameters
        ----------
        scale : float
            The law's strength (`scale`).
        """
        raise NotImplementedError  # pragma: no cover - interface

    def parameters(self) -> dict:
        """The law's parameters by name, SI units, for the report (``{}`` by default)."""
        return {}

    def domain(self) -> tuple[float, float]:
        """(d_min, d_max), m: where the law is defined (and P > 0)."""
        return (1e-9, math.inf)

    def breakpoints(self) -> tuple:
        """Distances d (m) where P or Q changes form (e.g. where the repulsion's support ends); none by default.

        N jumps where an equilibrium crosses one, so the searches for critical
        values step onto each (`pfm_stability.analysis.critical`, docs/fields.md).
        """
        return ()

    def lumped_f(self) -> float:
        """KB's lumped f this law stands for (the user's f): its `scale` by default, a grid law's f_av.

        The force is proportional to `scale`, so the law at strength s stands for
        f = s·lumped_f()/scale: a critical strength is reported in f this way.
        """
        return self.scale

    def distance_for(self, force: float) -> float:
        """d with F_r(d)/F_a = `force` (m); ``inf`` if the law never gets that weak.

        Bisection on a decreasing law over its `domain` (module `solve`); a law
        that is not `monotone` has `wall_equilibria` instead.

        Parameters
        ----------
        force : float
            The force ratio F_r/F_a, dimensionless.
        """
        lo, hi = self.domain()
        if self.force(lo) <= force:
            return lo
        if math.isinf(hi):
            bracket = expand_bracket(lambda d: self.force(d) - force, max(lo, 1e-3))
            if bracket is None:
                return math.inf
            lo, hi = max(lo, bracket[0]), bracket[1]
        elif self.force(hi) > force:
            return math.inf
        return bisect_root(lambda d: float(self.force(d)) - force, lo, hi, rtol=1e-14)

    def local_exponent(self, d):
        """Local exponent ν = −d·F′/F (n for the power law); N = cot α·ν(d0)/d0 at a wall when Q = 0.

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        d = np.asarray(d, dtype=float)
        return -d * self.slope(d) / self.force(d)

    def equivalent_f(self, d, n: float, W: float):
        """KB's lumped f that gives this law's force at d: F_r(d)·(d/W)^n (KB §4 f_av).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        n : float
            KB's exponent.
        W : float
            Robot width, m.
        """
        d = np.asarray(d, dtype=float)
        return self.force(d) * (d / W) ** n


@dataclass(frozen=True)
class Equilibrium:
    """One equilibrium of a wall or a corridor and its linear gains (docs/fields.md).

    Attributes
    ----------
    x0 : float
        Where it lies, m: the distance d0 to the wall (wall), or the offset
        from the centre line towards the right wall (corridor).
    N : float
        Position gain −∂F_x/∂x / F_y, 1/m (KB eq 11): < 0 is an unstable
        equilibrium of the field itself.
    c : float
        Heading gain −∂F_x/∂θ / F_y (dimensionless): 0 for every static law;
        a velocity-dependent law sets it.
    """

    x0: float
    N: float
    c: float = 0.0

    @property
    def d0(self) -> float:
        """x0 under its wall name: the distance to the wall, m."""
        return self.x0


@dataclass(frozen=True)
class PowerLaw(ForceLaw):
    """KB's lumped law F_r/F_a = f·(W/d)^n (Koren & Borenstein 1991 eq 8, 13).

    Parameters
    ----------
    f : float
        Force-constant ratio F_cr/F_ct, > 0 (eq 13).
    n : float
        Exponent, > 0 (eq 1, 8).
    W : float
        Robot width, m, > 0 (eq 1).
    """

    f: float
    n: float
    W: float
    name = "power law (KB eq 8)"
    monotone = True
    key = "power"

    def __post_init__(self):
        object.__setattr__(self, "f", check_number("f", self.f, 0.0))
        object.__setattr__(self, "n", check_number("n", self.n, 0.0))
        object.__setattr__(self, "W", check_number("W", self.W, 0.0, unit="m"))

    @property
    def scale(self) -> float:
        return self.f

    def force(self, d):
        return self.f * (self.W / np.asarray(d, dtype=float)) ** self.n

    def slope(self, d):
        d = np.asarray(d, dtype=float)
        return -self.n * self.f * self.W**self.n / d ** (self.n + 1)

    def with_scale(self, scale: float) -> "PowerLaw":
        return PowerLaw(scale, self.n, self.W)

    def parameters(self) -> dict:
        return {"f": self.f, "n": self.n, "W": self.W}

    def distance_for(self, force: float) -> float:
        """KB eq (23): d0 = W (f/F)^(1/n) (``inf`` where it overflows: no finite equilibrium).

        Parameters
        ----------
        force : float
            The force ratio F_r/F_a, dimensionless.
        """
        with np.errstate(over="ignore"):
            return float(self.W * np.power(self.f / force, 1.0 / self.n))


_LAW = "a ForceLaw (e.g. PowerLaw, GridWallLaw, KhatibLaw or GnronLaw)"

_POINTS_PER_DECADE = 64
"""Density of the scan in log d for the roots of a law that is not monotone (docs/fields.md)."""


def wall_equilibrium(law: ForceLaw, alpha: float) -> float:
    """Equilibrium distance to the wall d0, m (KB eq 22–23: F_r(d0) = F_a cos α); the nearest one if there are several.

    Parameters
    ----------
    law : ForceLaw
    alpha : float
        Target angle from the wall normal, rad, in [1e-6°, 90° − 1e-6°].
    """
    check_type("law", law, ForceLaw, _LAW)
    alpha = check_parameter("alpha", alpha)
    if law.monotone:
        return law.distance_for(math.cos(alpha))
    return wall_gain(law, alpha)[0]


def wall_equilibria(law: ForceLaw, alpha: float, *, polish: bool = True) -> tuple:
    """Every wall equilibrium, sorted by d0: roots of F_x = P − (1 + Q) cos α on the law's domain (docs/fields.md).

    N = −(P′ − Q′ cos α)/((1 + Q) sin α) = −R′(d0)/sin α at each (KB eq 11
    with δ = 0), c = 0. A `monotone` law has one (KB eq 23; d0 = inf, N = 0
    where it never gets that weak). Otherwise R(d) − cos α is scanned on a
    log grid of the domain (64 points per decade, and 200 geometric towards a
    finite end; on an infinite domain up to 10⁶ m, then a bracket is grown)
    and every sign change is narrowed by
    `solve.newton_increasing`; two roots closer than one grid step (a factor
    1.037 in d) are not resolved. ``polish=False`` interpolates d0 and N
    linearly between the grid points instead (one evaluation of the law; N
    to ~1e-3 relative): a cheap scan for following an equilibrium (`fields.Branch`).

    Parameters
    ----------
    law : ForceLaw
        The wall's law.
    alpha : float
        Target angle from the wall normal, rad.
    polish : bool, optional
        Refine each root by Newton's method.

    Returns
    -------
    tuple of Equilibrium
        Empty when P never balances the pull (the robot is pushed against the wall).
    """
    check_type("law", law, ForceLaw, _LAW)
    alpha = check_parameter("alpha", alpha)
    if law.monotone:
        return (Equilibrium(*wall_gain(law, alpha)),)
    cos_a, sin_a = math.cos(alpha), math.sin(alpha)
    lo, hi = law.domain()
    top = hi if math.isfinite(hi) else max(1e6, 1e3 * lo)
    grid = np.geomspace(lo, top, int(math.ceil(_POINTS_PER_DECADE * math.log10(top / lo))) + 1)
    if math.isfinite(hi):  # resolve a law that ends at its reach (Khatib's: R′ jumps there)
        grid = np.unique(np.concatenate([grid, hi - (hi - lo) * np.geomspace(1e-9, 0.5, 200)]))
    with np.errstate(all="ignore"):
        R, dR = law.wall_balance(grid)
    F = R - cos_a
    out = []
    if not polish:
        a, b = F[:-1], F[1:]
        i = np.flatnonzero(np.isfinite(a) & np.isfinite(b) & (a != 0) & ((a > 0) != (b > 0)))
        with np.errstate(all="ignore"):
            t = a[i] / (a[i] - b[i])
            d0 = grid[i] + t * (grid[i + 1] - grid[i])
            N = -(dR[i] + t * (dR[i + 1] - dR[i])) / sin_a
        out += [Equilibrium(float(x), float(n)) for x, n in zip(d0, N)]
        if math.isinf(hi) and F[-1] > 0:
            out.append(Equilibrium(math.inf, 0.0))
        return tuple(out)

    def balance(d):
        R, dR = law.wall_balance(d)
        return R - cos_a, dR

    roots = list(_sign_change_roots(balance, grid, F))
    if math.isinf(hi) and F[-1] > 0:  # still pushing at 10⁶ m: the root lies further out, or at infinity
        bracket = expand_bracket(lambda d: float(law.wall_ratio(d)) - cos_a, top)
        roots.append(bisect_root(lambda d: float(law.wall_ratio(d)) - cos_a, *bracket, rtol=1e-14) if bracket else math.inf)
    finite = np.array([d for d in roots if math.isfinite(d)])
    if finite.size:
        with np.errstate(all="ignore"):
            N = -np.asarray(law.wall_ratio_slope(finite), dtype=float) / sin_a
        out += [Equilibrium(float(d0), float(n)) for d0, n in zip(finite, N)]
    out += [Equilibrium(math.inf, 0.0) for d in roots if math.isinf(d)]
    return tuple(sorted(out, key=lambda e: e.x0))


def _sign_change_roots(func, grid, F, zeros: bool = True):
    """Roots of f (``func(x) -> (f, f′)``, vectorized) between grid points where F = f(grid) changes sign, and exact zeros (if `zeros`).

    Each bracket is narrowed by `solve.newton_increasing` on ±f (the sign that
    makes f increasing across it). A bracket touching a NaN is skipped.
    """
    a, b = F[:-1], F[1:]
    change = np.flatnonzero(np.isfinite(a) & np.isfinite(b) & (a != 0) & (b != 0) & ((a > 0) != (b > 0)))
    zeros = grid[np.flatnonzero(F == 0)] if zeros else grid[:0]
    if change.size == 0:
        return zeros.tolist()
    sign = np.where(a[change] < 0, 1.0, -1.0)

    def increasing(x):
        with np.errstate(all="ignore"):
            f, df = func(x)
        return sign * f, sign * df

    found = newton_increasing(increasing, grid[change], grid[change + 1])
    return sorted(np.concatenate([found, zeros]).tolist())


def corridor_equilibria(law: ForceLaw, L: float, W: float = 0.0) -> tuple:
    """Every lateral equilibrium in a corridor of half-width L with the target straight ahead, sorted by x0 (docs/fields.md).

    F_x(x) = P(L + x) − P(L − x) (x towards the right wall), F_y = 1 + Q(L + x) + Q(L − x),
    N = −F_x′(x0)/F_y(x0), c = 0. The middle x0 = 0 is always one (N = −2P′(L)/(1 + 2Q(L)),
    `corridor_gain`); for a law that is not `monotone` the others on
    (−(L − W/2), L − W/2) (the robot of width W fits) are found by a scan and
    `solve.newton_increasing`, and come in pairs ±x0. Where F_x vanishes on
    a whole band (both walls beyond a finite reach) only the middle is listed.

    Parameters
    ----------
    law : ForceLaw
        The walls' law.
    L : float
        Corridor half-width, m.
    W : float, optional
        Robot width, m (equilibria closer than W/2 to a wall are left out).
    """
    middle = Equilibrium(0.0, corridor_gain(law, L))
    W = check_number("W", W, 0.0, math.inf, low_open=False, unit="m")
    reach = L - W / 2
    if law.monotone or not reach > 0:
        return (middle,)
    t = np.unique(np.concatenate([np.linspace(0.0, 1.0, 513), np.geomspace(1e-9, 0.5, 200), 1.0 - np.geomspace(1e-12, 0.5, 200)]))
    x = reach * t[(t > 0) & (t < 1)]

    def lateral(x):
        with np.errstate(all="ignore"):
            F = np.asarray(law.force(L + x), dtype=float) - np.asarray(law.force(L - x), dtype=float)
            dF = np.asarray(law.slope(L + x), dtype=float) + np.asarray(law.slope(L - x), dtype=float)
        return F, dF

    out = [middle]
    for x0 in _sign_change_roots(lateral, x, lateral(x)[0], zeros=False):
        with np.errstate(all="ignore"):
            Fy = 1.0 + float(law.goal_force(L + x0)) + float(law.goal_force(L - x0))
            N = -float(lateral(np.array([x0]))[1][0]) / Fy
        out += [Equilibrium(-x0, N), Equilibrium(x0, N)]
    return tuple(sorted(out, key=lambda e: e.x0))


def wall_gain(law: ForceLaw, alpha) -> tuple:
    """(d0 in m, N in 1/m) for travel along a wall (KB eq 11 with δ = 0, eq 23): the nearest equilibrium.

    N = −R′(d0)/sin α (= −F_r′(d0)/(F_a sin α) for KB's laws); 0 when no
    equilibrium exists (d0 = inf). A law that is not `monotone` gives the
    first of `wall_equilibria`. An array of α (rad) gives arrays
    (`wall_gain_arrays`, unchecked).

    Parameters
    ----------
    law : ForceLaw
        The wall's law.
    alpha : float or ndarray
        Target angle from the wall normal, rad.

    Raises
    ------
    ValueError
        For a law that is not a `ForceLaw`, α out of range, no equilibrium
        (a law that is not monotone and never balances the pull), or an
        equilibrium that floating point cannot represent (d0 = 0 or N infinite).
    """
    check_type("law", law, ForceLaw, _LAW)
    if np.ndim(alpha) > 0:
        return wall_gain_arrays(law, alpha)
    check_parameter("alpha", alpha)
    return _wall_gain(law, alpha)


def _wall_gain(law: ForceLaw, alpha: float) -> tuple:
    """`wall_gain` of a checked law at a checked scalar α, rad (a search over α in range: `critical_alpha`)."""
    if law.monotone:
        d0 = law.distance_for(math.cos(alpha))
        if math.isinf(d0):
            return d0, 0.0
        N = float(-law.slope(d0) / math.sin(alpha)) if d0 > 0 else math.inf
    else:
        equilibria = wall_equilibria(law, alpha)
        if not equilibria:
            top = float(np.max(law.wall_ratio(np.geomspace(*_finite_domain(law), 2000))))
            raise ValueError(
                f"no wall equilibrium for {law.name} at alpha = {to_degrees(alpha):g} deg: the repulsion never balances "
                f"the target's pull (P/(1 + Q) <= {top:.4g} < cos alpha = {math.cos(alpha):.4g}); the robot is pushed against the wall"
            )
        d0, N = equilibria[0].x0, equilibria[0].N
    if not (d0 > 0 and math.isfinite(N)):
        raise ValueError(f"the wall equilibrium is outside floating point (d0 = {d0:g} m, N = {N:g} 1/m) for {law!r} at alpha = {to_degrees(alpha):g} deg")
    return d0, N


def _finite_domain(law: ForceLaw) -> tuple[float, float]:
    lo, hi = law.domain()
    return lo, hi if math.isfinite(hi) else max(1e6, 1e3 * lo)


def wall_gain_arrays(law: ForceLaw, alpha, scale_factor=1.0):
    """(d0 in m, N in 1/m) at the wall equilibrium for arrays of α (rad) and force multipliers c (F = c·law).

    The equilibrium c·F_r(d0) = F_a cos α is solved for every element at once
    (`solve.invert_decreasing`); N = −c·F_r′(d0)/(F_a sin α). Where the law
    never gets that weak (d0 = inf) N = 0; where it never pushes that hard
    (the robot at the wall) d0 = nan and N = inf. Nothing is range-checked:
    the caller checks its axes. A law that is not `monotone` takes the first
    of `wall_equilibria` element by element where c = 1; force multipliers
    c ≠ 1 assume a decreasing law without a goal part (ValueError for one with).

    Parameters
    ----------
    law : ForceLaw
        The wall's law.
    alpha : ndarray
        Target angles from the wall normal, rad.
    scale_factor : float or ndarray, optional
        Force multipliers c (broadcast with `alpha`).
    """
    alpha, c = np.broadcast_arrays(np.asarray(alpha, dtype=float), np.asarray(scale_factor, dtype=float))
    if not law.monotone and law.has_goal_part and np.any(c != 1.0):
        raise ValueError(f"{law.name} has a goal-directed part: its force does not scale with one factor, so the force multipliers must be 1")
    if not law.monotone and np.all(c == 1.0):
        d0, N = np.full(alpha.shape, np.nan), np.full(alpha.shape, np.inf)
        for index, a in np.ndenumerate(alpha):
            first = wall_equilibria(law, float(a))[:1]
            if first:
                d0[index], N[index] = first[0].x0, first[0].N
        return d0, N
    target = np.cos(alpha) / c  # law.force(d0) = cos α / c
    lo = max(law.domain()[0], 1e-9)
    d0 = invert_decreasing(lambda d: np.asarray(law.force(d), dtype=float), target.ravel(), lo, 1.0).reshape(target.shape)
    finite = np.isfinite(d0) & (d0 > 0)
    safe = np.where(finite, d0, 1.0)
    N = np.where(finite, -c * np.asarray(law.slope(safe), dtype=float) / np.sin(alpha), 0.0)
    return d0, np.where(np.isnan(d0), np.inf, N)


def wall_gain_at_distance(law: ForceLaw, d0):
    """(α in rad, N in 1/m) of the wall equilibrium at distance d0 (m; numbers or arrays; KB eq 11, 23).

    The parametric form of `wall_gain`: R(d0) = cos α gives α (R = P/(1 + Q),
    F_r/F_a for KB's laws), and N = −R′(d0)/sin α with sin α = √(1 − R²). Unchecked.

    Parameters
    ----------
    law : ForceLaw
        The wall's law.
    d0 : float or ndarray
        Equilibrium distance, m.
    """
    d0 = np.asarray(d0, dtype=float)
    F = np.asarray(law.wall_ratio(d0), dtype=float)
    with np.errstate(invalid="ignore"):
        alpha = np.arccos(np.clip(F, -1.0, 1.0))
        N = -np.asarray(law.wall_ratio_slope(d0), dtype=float) / np.sqrt(np.maximum(1.0 - F * F, 0.0))
    return alpha, N


def corridor_gain(law: ForceLaw, L):
    """N = −2P′(L)/(1 + 2Q(L)), 1/m, in the middle of a corridor of half-width L (KB §5.4: −2F_r′(L)/F_a when Q = 0).

    A number is checked against its range and gives a float; an array of L
    (m) gives an array, evaluated as it is (the caller checks its axis).

    Parameters
    ----------
    law : ForceLaw
        The walls' law.
    L : float or ndarray
        Corridor half-width, m.

    Raises
    ------
    ValueError
        For a law that is not a `ForceLaw`, L out of range, or N that floating
        point cannot represent.
    """
    check_type("law", law, ForceLaw, _LAW)
    if np.ndim(L) > 0:
        return _middle_gain(law, np.asarray(L, dtype=float))
    L = check_parameter("L", L)
    N = float(_middle_gain(law, L))
    if not math.isfinite(N):
        raise ValueError(f"the corridor gain is outside floating point (N = {N:g} 1/m) for {law!r} at L = {L:g} m")
    return N


def _middle_gain(law: ForceLaw, L):
    if not law.has_goal_part:
        return -2.0 * np.asarray(law.slope(L), dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        return -2.0 * np.asarray(law.slope(L), dtype=float) / (1.0 + 2.0 * np.asarray(law.goal_force(L), dtype=float))


def power_law_wall_gain(f, n, W, alpha):
    """N, 1/m, of KB's power law at the wall equilibrium, for numbers or arrays (broadcast):
    N = (n/W) f^(−1/n) cos^((n+1)/n) α / sin α (KB eq 11 at the equilibrium of eq 23). Unchecked.

    Parameters
    ----------
    f, n : float or ndarray
        KB's strength and exponent.
    W : float or ndarray
        Robot width, m.
    alpha : float or ndarray
        Target angle from the wall normal, rad.
    """
    return (n / W) * f ** (-1.0 / n) * np.cos(alpha) ** ((n + 1.0) / n) / np.sin(alpha)


def power_law_corridor_gain(f, n, W, L):
    """N, 1/m, of KB's power law in the middle of a corridor, for numbers or arrays (broadcast):
    N = 2nfWⁿ/L^(n+1) (KB eq 25). Unchecked.

    Parameters
    ----------
    f, n : float or ndarray
        KB's strength and exponent.
    W : float or ndarray
        Robot width, m.
    L : float or ndarray
        Corridor half-width, m.
    """
    return 2.0 * n * f * W**n / L ** (n + 1.0)


def law_in_force(robot: Robot, controller: Controller, law: ForceLaw | None = None) -> ForceLaw:
    """The lateral law a robot and controller see: `law` if given, else KB's `PowerLaw(f, n, W)`.

    Parameters
    ----------
    robot : Robot
        W (m).
    controller : Controller
        f and n of KB's law.
    law : ForceLaw, optional

    Raises
    ------
    ValueError
        If an argument has the wrong type.
    """
    check_type("robot", robot, Robot, "a Robot")
    check_type("controller", controller, Controller, "a Controller")
    if law is None:
        return PowerLaw(controller.f, controller.n, robot.W)
    return check_type("law", law, ForceLaw, _LAW)
