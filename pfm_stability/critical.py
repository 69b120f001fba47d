"""Named critical values, and those with no closed form: α*, L* and a law's own parameters, per equilibrium.

`WallCritical` and `CorridorCritical` hold one model's critical values in one
geometry (docs/models.md, "Critical values"); `pfm_stability.criteria` fills them.
The rest of this module finds them where no closed form exists (docs/fields.md).

A law that is not `monotone` (Khatib's, Ge & Cui's, any law built in code)
may have several wall equilibria, and its gain N need not fall as a
parameter grows. Each critical value is therefore found on the equilibrium
itself: `fields.Branch` follows it as one parameter moves from its current
value p0, the others fixed, and the critical value p* is the value nearest
p0 (in log p; in α for α) at which N·V crosses the model's NV* — where the
verdict of that equilibrium changes. The parameters:

* wall: α (even steps over its range), the law's strength (``scale``: f for a
  law in code, η for Khatib's and the goal-aware law) and ρ0;
* corridor (the middle, N explicit): L, η and ρ0;
* ξ* = ξ·η/η* exactly, since only η/ξ enters P and Q (fields module docstring).

Where no value of the range gives a crossing the answer says which way it
failed, in the package's conventions (docs/models.md, "Edge cases"): stable
throughout gives α* = 0, L* = 0 and η*, ρ0*, ξ*, f* = inf ("no limit");
unstable throughout gives α* = 90°, L* = inf and NaN for the others (JSON
null: no value of that parameter alone helps). An equilibrium with N < 0 is
unstable throughout: N keeps its sign along a branch until the branch ends
at a fold.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

from .fields import Branch, GnronLaw, KhatibLaw
from .force_law import Equilibrium, ForceLaw, corridor_gain, wall_equilibria
from .parameters import RANGES, to_degrees

__all__ = ["CriticalValues", "WallCritical", "CorridorCritical", "is_field_law", "WallBranches", "CorridorBranches"]


class CriticalValues(Mapping):
    """Critical values of one model in one geometry: named fields, read-only mapping too.

    Subclasses are frozen dataclasses. As a `Mapping` they hold their fields
    in declaration order, leaving out those that are None (``critical["L_critical"]``,
    ``.items()``, ``in``, ``len``, iteration): the keys and the order of the
    report's JSON. Equality is the mapping's (so a plain dict of the same
    items compares equal).
    """

    __slots__ = ()

    def _keys(self) -> tuple:
        return tuple(f.name for f in fields(self) if getattr(self, f.name) is not None)

    def __getitem__(self, key: str):
        if isinstance(key, str) and key in self._keys():
            return getattr(self, key)
        raise KeyError(key)

    def __iter__(self):
        return iter(self._keys())

    def __len__(self) -> int:
        return len(self._keys())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self.items())})"


@dataclass(frozen=True, eq=False, repr=False, kw_only=True)
class WallCritical(CriticalValues):
    """One model's critical values along a wall, each with the other inputs fixed (docs/models.md).

    Attributes
    ----------
    alpha_critical : float
        α*, rad: stable for α > α* (0 when NV* = inf; π/2 when NV* = 0); for
        a law that is not `monotone`, the nearest α at which the verdict of
        this equilibrium changes (docs/fields.md).
    alpha_critical_deg : float
        α* in degrees (set from `alpha_critical`).
    f_critical : float or None
        f*: stable for f > f* (KB eq 24 generalized; ``inf`` when NV* = 0); the
        nearest f at which the verdict changes for a law that is not
        `monotone`. None (no key) for Khatib's and the goal-aware law.
    V_critical : float
        V* = NV*/N, m/s: every slower speed is stable (0 when N < 0).
    T_critical : float
        T*, s: the smallest sampling period / delay at which the operating
        point loses stability (0: already at T → 0; ``inf``: stable up to 100 s).
    k_critical : float
        k*, 1/s: the smallest steering gain at which it loses stability.
    tau_plus_T_critical : float or None
        (τ + T)* = 1/NV, s: KB eq (20) solved for the loop's time constants
        (``kb_first_order`` only; None, and no key, otherwise).
    eta_critical, rho0_critical, xi_critical : float or None
        Khatib's and the goal-aware law: the nearest η, ρ0 (m) and ξ at which
        the verdict of this equilibrium changes (docs/fields.md; ``inf``: no
        limit, NaN: no value helps). None (no key) for other laws.
    """

    alpha_critical: float
    alpha_critical_deg: float = field(init=False)
    f_critical: float | None = None
    V_critical: float
    T_critical: float
    k_critical: float
    tau_plus_T_critical: float | None = None
    eta_critical: float | None = None
    rho0_critical: float | None = None
    xi_critical: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "alpha_critical_deg", to_degrees(self.alpha_critical))


@dataclass(frozen=True, eq=False, repr=False, kw_only=True)
class CorridorCritical(CriticalValues):
    """One model's critical values in the middle of a corridor, each with the other inputs fixed (docs/models.md).

    Attributes
    ----------
    L_critical : float
        L*, m: stable for L > L* (KB eq 25 generalized; ``inf`` when NV* = 0);
        for a law that is not `monotone`, the nearest L at which the middle's
        verdict changes (docs/fields.md).
    V_critical : float
        V* = NV*/N, m/s: every slower speed is stable.
    f_critical : float or None
        f*: stable for f < f* (N ∝ f; 0 when NV* = 0). None (no key) for
        Khatib's and the goal-aware law.
    T_critical : float
        T*, s (see `WallCritical`).
    k_critical : float
        k*, 1/s (see `WallCritical`).
    tau_plus_T_critical : float or None
        (τ + T)* = 1/NV, s (``kb_first_order`` only; None, and no key, otherwise).
    eta_critical, rho0_critical, xi_critical : float or None
        As in `WallCritical`, for the middle of the corridor.
    """

    L_critical: float
    V_critical: float
    f_critical: float | None = None
    T_critical: float
    k_critical: float
    tau_plus_T_critical: float | None = None
    eta_critical: float | None = None
    rho0_critical: float | None = None
    xi_critical: float | None = None


_ALPHA_STEPS = 120
"""Even steps of α over its range (0.75° each) when following a wall equilibrium."""


def is_field_law(law: ForceLaw) -> bool:
    """True for Khatib's and the goal-aware law: critical values of η, ρ0 and ξ instead of f."""
    return isinstance(law, (KhatibLaw, GnronLaw))


def _range(name: str) -> tuple[float, float]:
    r = RANGES[name]
    return r.low, r.high


class _Branches:
    """Branches of one equilibrium, made when first asked for and shared by every model."""

    def __init__(self, law: ForceLaw, start: Equilibrium, V: float):
        self.law, self.start, self.V = law, start, V
        self._made = {}

    def _branch(self, name: str) -> Branch:
        if name not in self._made:
            self._made[name] = self._make(name)
        return self._made[name]

    def _make(self, name: str) -> Branch:  # pragma: no cover - interface
        raise NotImplementedError

    def _critical(self, name: str, NV_critical: float, stable_end: float, unstable_end: float) -> float:
        """p* on the branch of `name`; `stable_end` / `unstable_end` when N·V never crosses NV*."""
        N = self.start.N
        if N < 0 or NV_critical <= 0:
            return unstable_end
        if math.isinf(NV_critical):
            return stable_end
        root, _ = self._branch(name).nearest_crossing(NV_critical / self.V)
        if root is not None:
            return root
        return stable_end if N * self.V < NV_critical else unstable_end

    def law_parameters(self, NV_critical: float) -> dict:
        """The law's strength (f*, or η* and ξ*) and ρ0* of a field law."""
        if not is_field_law(self.law):
            return {"f_critical": self._critical("scale", NV_critical, math.inf, math.nan)}
        eta = self._critical("eta", NV_critical, math.inf, math.nan)
        xi = self.law.xi * self.law.eta / eta if math.isfinite(eta) else eta
        return {"eta_critical": eta, "rho0_critical": self._critical("rho0", NV_critical, math.inf, math.nan), "xi_critical": xi}


class WallBranches(_Branches):
    """A wall equilibrium of a law that is not monotone, followed in α and in the law's parameters.

    Parameters
    ----------
    law : ForceLaw
    alpha : float
        Rad.
    start : Equilibrium
        One of ``force_law.wall_equilibria(law, alpha)``.
    V : float
        m/s.
    """

    def __init__(self, law: ForceLaw, alpha: float, start: Equilibrium, V: float):
        super().__init__(law, start, V)
        self.alpha = alpha

    def _make(self, name: str) -> Branch:
        if name == "alpha":
            return Branch(lambda a, polish: wall_equilibria(self.law, a, polish=polish), self.alpha, self.start, *_range("alpha"),
                          log=False, steps=_ALPHA_STEPS)
        if name == "scale":
            return Branch(lambda s, polish: wall_equilibria(self.law.with_scale(s), self.alpha, polish=polish), self.law.scale, self.start, *_range("f"))
        return Branch(lambda p, polish: wall_equilibria(dataclasses.replace(self.law, **{name: p}), self.alpha, polish=polish),
                      getattr(self.law, name), self.start, *_range(name))

    def critical(self, NV_critical: float) -> dict:
        """α* (rad) and the law's parameters' critical values for a model with this NV* (1/s)."""
        return {"alpha_critical": self._critical("alpha", NV_critical, 0.0, math.pi / 2), **self.law_parameters(NV_critical)}


class CorridorBranches(_Branches):
    """The middle of a corridor (N = −2P′(L)/(1 + 2Q(L))) followed in L and in the law's parameters.

    Parameters
    ----------
    law : ForceLaw
    L : float
        Half-width, m.
    W : float
        Robot width, m (L > W/2).
    N : float
        The middle's gain, 1/m.
    V : float
        m/s.
    """

    def __init__(self, law: ForceLaw, L: float, W: float, N: float, V: float):
        super().__init__(law, Equilibrium(0.0, N), V)
        self.L, self.W = L, W

    def _middle(self, law: ForceLaw, L: float):
        return (Equilibrium(0.0, corridor_gain(law, L)),)

    def _make(self, name: str) -> Branch:
        if name == "L":
            return Branch(lambda L, _: self._middle(self.law, L), self.L, self.start, self.W / 2 * (1 + 1e-9), RANGES["L"].high)
        if name == "scale":
            return Branch(lambda s, _: self._middle(self.law.with_scale(s), self.L), self.law.scale, self.start, *_range("f"))
        return Branch(lambda p, _: self._middle(dataclasses.replace(self.law, **{name: p}), self.L), getattr(self.law, name), self.start,
                      *_range(name))

    def critical_L(self, NV_critical: float) -> float:
        """L*, m: the nearest half-width at which the middle's verdict changes (0: stable at every L; inf: at none)."""
        return self._critical("L", NV_critical, 0.0, math.inf)
