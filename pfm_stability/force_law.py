"""Lateral repulsion laws F_r(d) and the environment gain N they produce.

Forces are in units of the attractive force constant F_a (KB's F_ct), so a law
is the dimensionless ratio F_r(d)/F_a. KB's lumped law (Koren & Borenstein 1991
eq 8 with eq 13) is the power law F_r/F_a = f·(W/d)^n. Any decreasing law works
(docs/theory.md, "Any force law"):

* wall (KB eq 22–23): the equilibrium distance solves F_r(d0) = F_a cos α, and
  the linearization (eq 10–11, δ = 0) gives N = −F_r′(d0)/(F_a sin α);
* corridor, target straight ahead: N = −2F_r′(L)/F_a (both walls push).

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

from .checks import check_number, check_type
from .parameters import Controller, Robot, check_parameter, to_degrees
from .solve import bisect_root, expand_bracket, invert_decreasing

__all__ = [
    "law_in_force",
    "ForceLaw",
    "PowerLaw",
    "wall_equilibrium",
    "wall_gain",
    "wall_gain_arrays",
    "wall_gain_at_distance",
    "corridor_gain",
    "power_law_wall_gain",
    "power_law_corridor_gain",
]


class ForceLaw:
    """A decreasing lateral repulsion law F_r(d)/F_a, d in m.

    Subclasses implement `force`, `slope` and `with_scale`; `distance_for`
    has a numerical default (bisection on the monotone law).

    Attributes
    ----------
    scale : float
        The law's strength parameter (KB's f for the power law; the cell
        force ratio for a grid law); `with_scale` returns the same law with
        another strength, the force being proportional to it.
    """

    scale: float = 1.0
    name: str = "force law"

    def force(self, d):
        """F_r(d)/F_a (dimensionless)."""
        raise NotImplementedError  # pragma: no cover - interface

    def slope(self, d):
        """d(F_r/F_a)/dd, 1/m (negative)."""
        raise NotImplementedError  # pragma: no cover - interface

    def with_scale(self, scale: float) -> "ForceLaw":
        """The same law with strength `scale` (force ∝ scale)."""
        raise NotImplementedError  # pragma: no cover - interface

    def domain(self) -> tuple[float, float]:
        """(d_min, d_max), m: where the law is defined and decreasing."""
        return (1e-9, math.inf)

    def distance_for(self, force: float) -> float:
        """d with F_r(d)/F_a = `force` (m); ``inf`` if the law never gets that weak.

        Bisection on the monotone law over its `domain` (module `solve`).
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
        """Local exponent −d·F′/F (n for the power law)."""
        d = np.asarray(d, dtype=float)
        return -d * self.slope(d) / self.force(d)

    def equivalent_f(self, d, n: float, W: float):
        """KB's lumped f that gives this law's force at d: F_r(d)·(d/W)^n (KB §4 f_av)."""
        d = np.asarray(d, dtype=float)
        return self.force(d) * (d / W) ** n


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

    def distance_for(self, force: float) -> float:
        """KB eq (23): d0 = W (f/F)^(1/n) (``inf`` where it overflows: no finite equilibrium)."""
        with np.errstate(over="ignore"):
            return float(self.W * np.power(self.f / force, 1.0 / self.n))


def wall_equilibrium(law: ForceLaw, alpha: float) -> float:
    """Equilibrium distance to the wall d0, m (KB eq 22–23: F_r(d0) = F_a cos α).

    Parameters
    ----------
    law : ForceLaw
    alpha : float
        Target angle from the wall normal, rad, in [1e-6°, 90° − 1e-6°].
    """
    check_type("law", law, ForceLaw, "a ForceLaw (e.g. PowerLaw or GridWallLaw)")
    return law.distance_for(math.cos(check_parameter("alpha", alpha)))


def wall_gain(law: ForceLaw, alpha) -> tuple:
    """(d0 in m, N in 1/m) for travel along a wall (KB eq 11 with δ = 0, eq 23).

    N = −F_r′(d0)/(F_a sin α); 0 when no equilibrium exists (d0 = inf).
    An array of α (rad) gives arrays (`wall_gain_arrays`, unchecked).

    Raises
    ------
    ValueError
        For a law that is not a `ForceLaw`, α out of range, or an equilibrium
        that floating point cannot represent (d0 = 0 or N infinite).
    """
    if np.ndim(alpha) > 0:
        check_type("law", law, ForceLaw, "a ForceLaw (e.g. PowerLaw or GridWallLaw)")
        return wall_gain_arrays(law, alpha)
    d0 = wall_equilibrium(law, alpha)
    if math.isinf(d0):
        return d0, 0.0
    N = float(-law.slope(d0) / math.sin(alpha)) if d0 > 0 else math.inf
    if not (d0 > 0 and math.isfinite(N)):
        raise ValueError(f"the wall equilibrium is outside floating point (d0 = {d0:g} m, N = {N:g} 1/m) for {law!r} at alpha = {to_degrees(alpha):g} deg")
    return d0, N


def wall_gain_arrays(law: ForceLaw, alpha, scale_factor=1.0):
    """(d0 in m, N in 1/m) at the wall equilibrium for arrays of α (rad) and force multipliers c (F = c·law).

    The equilibrium c·F_r(d0) = F_a cos α is solved for every element at once
    (`solve.invert_decreasing`); N = −c·F_r′(d0)/(F_a sin α). Where the law
    never gets that weak (d0 = inf) N = 0; where it never pushes that hard
    (the robot at the wall) d0 = nan and N = inf. Nothing is range-checked:
    the caller checks its axes.
    """
    alpha, c = np.broadcast_arrays(np.asarray(alpha, dtype=float), np.asarray(scale_factor, dtype=float))
    target = np.cos(alpha) / c  # law.force(d0) = cos α / c
    lo = max(law.domain()[0], 1e-9)
    d0 = invert_decreasing(lambda d: np.asarray(law.force(d), dtype=float), target.ravel(), lo, 1.0).reshape(target.shape)
    finite = np.isfinite(d0) & (d0 > 0)
    safe = np.where(finite, d0, 1.0)
    N = np.where(finite, -c * np.asarray(law.slope(safe), dtype=float) / np.sin(alpha), 0.0)
    return d0, np.where(np.isnan(d0), np.inf, N)


def wall_gain_at_distance(law: ForceLaw, d0):
    """(α in rad, N in 1/m) of the wall equilibrium at distance d0 (m; numbers or arrays; KB eq 11, 23).

    The parametric form of `wall_gain`: F_r(d0) = F_a cos α gives α, and
    N = −F_r′(d0)/(F_a sin α) with sin α = √(1 − cos²α). Unchecked.
    """
    d0 = np.asarray(d0, dtype=float)
    F = np.asarray(law.force(d0), dtype=float)
    with np.errstate(invalid="ignore"):
        alpha = np.arccos(np.clip(F, -1.0, 1.0))
        N = -np.asarray(law.slope(d0), dtype=float) / np.sqrt(np.maximum(1.0 - F * F, 0.0))
    return alpha, N


def corridor_gain(law: ForceLaw, L):
    """N = −2F_r′(L)/F_a, 1/m, in the middle of a corridor of half-width L (KB §5.4).

    A number is checked against its range and gives a float; an array of L
    (m) gives an array, evaluated as it is (the caller checks its axis).

    Raises
    ------
    ValueError
        For a law that is not a `ForceLaw`, L out of range, or N that floating
        point cannot represent.
    """
    check_type("law", law, ForceLaw, "a ForceLaw (e.g. PowerLaw or GridWallLaw)")
    if np.ndim(L) > 0:
        return -2.0 * np.asarray(law.slope(L), dtype=float)
    L = check_parameter("L", L)
    N = float(-2.0 * law.slope(L))
    if not math.isfinite(N):
        raise ValueError(f"the corridor gain is outside floating point (N = {N:g} 1/m) for {law!r} at L = {L:g} m")
    return N


def power_law_wall_gain(f, n, W, alpha):
    """N, 1/m, of KB's power law at the wall equilibrium, for numbers or arrays (broadcast):
    N = (n/W) f^(−1/n) cos^((n+1)/n) α / sin α (KB eq 11 at the equilibrium of eq 23). Unchecked."""
    return (n / W) * f ** (-1.0 / n) * np.cos(alpha) ** ((n + 1.0) / n) / np.sin(alpha)


def power_law_corridor_gain(f, n, W, L):
    """N, 1/m, of KB's power law in the middle of a corridor, for numbers or arrays (broadcast):
    N = 2nfWⁿ/L^(n+1) (KB eq 25). Unchecked."""
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
    return check_type("law", law, ForceLaw, "a ForceLaw (e.g. PowerLaw or GridWallLaw)")
