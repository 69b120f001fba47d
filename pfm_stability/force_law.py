"""Lateral repulsion laws F_r(d) and the environment gain N they produce.

Forces are in units of the attractive force constant F_a (KB's F_ct), so a law
is the dimensionless ratio F_r(d)/F_a. KB's lumped law (Koren & Borenstein 1991
eq 8 with eq 13) is the power law F_r/F_a = f·(W/d)^n. Any decreasing law works
(DESIGN §3, "General force law"):

* wall (KB eq 22–23): the equilibrium distance solves F_r(d0) = F_a cos α, and
  the linearization (eq 10–11, δ = 0) gives N = −F_r′(d0)/(F_a sin α);
* corridor, target straight ahead: N = −2F_r′(L)/F_a (both walls push).

Everything downstream depends on the product NV only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .checks import check_number, check_type
from .parameters import check_parameter
from .solve import bisect_root, expand_bracket

__all__ = ["ForceLaw", "PowerLaw", "wall_equilibrium", "wall_gain", "corridor_gain"]


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


def wall_gain(law: ForceLaw, alpha: float) -> tuple[float, float]:
    """(d0 in m, N in 1/m) for travel along a wall (KB eq 11 with δ = 0, eq 23).

    N = −F_r′(d0)/(F_a sin α); 0 when no equilibrium exists (d0 = inf).

    Raises
    ------
    ValueError
        For a law that is not a `ForceLaw`, α out of range, or an equilibrium
        that floating point cannot represent (d0 = 0 or N infinite).
    """
    d0 = wall_equilibrium(law, alpha)
    if math.isinf(d0):
        return d0, 0.0
    N = float(-law.slope(d0) / math.sin(alpha)) if d0 > 0 else math.inf
    if not (d0 > 0 and math.isfinite(N)):
        raise ValueError(f"the wall equilibrium is outside floating point (d0 = {d0:g} m, N = {N:g} 1/m) for {law!r} at alpha = {math.degrees(alpha):g} deg")
    return d0, N


def corridor_gain(law: ForceLaw, L: float) -> float:
    """N = −2F_r′(L)/F_a, 1/m, in the middle of a corridor of half-width L (KB §5.4).

    Raises
    ------
    ValueError
        For a law that is not a `ForceLaw`, L out of range, or N that floating
        point cannot represent.
    """
    check_type("law", law, ForceLaw, "a ForceLaw (e.g. PowerLaw or GridWallLaw)")
    L = check_parameter("L", L)
    N = float(-2.0 * law.slope(L))
    if not math.isfinite(N):
        raise ValueError(f"the corridor gain is outside floating point (N = {N:g} 1/m) for {law!r} at L = {L:g} m")
    return N
