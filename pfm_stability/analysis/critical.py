"""Named critical values, and those with no closed form: α*, L* and a law's own parameters, per equilibrium.

`WallCritical` and `CorridorCritical` hold one model's critical values in one
geometry (docs/models.md, "Critical values"); `pfm_stability.analysis.criteria` fills them.
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

N jumps where the law changes form (`ForceLaw.breakpoints`: ρ0, where the
repulsion's support ends), so a band of one verdict can be far narrower than
the scan's step: the middle of a corridor is followed in L onto each
breakpoint, and in a law parameter onto the value at which a breakpoint
reaches L (`_passing`). Every critical value carries its stable side
(`CriticalValues.stable_side`): the side on which the verdict is stable just
past it. A critical strength is reported in the user's f (`in_user_f`: a grid
law's cell ratio as f_av).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

from ..laws.fields import Branch, GnronLaw, KhatibLaw
from ..laws.force_law import Equilibrium, ForceLaw, corridor_gain, wall_equilibria
from ..parameters import RANGES, to_degrees
from ..numerics.solve import bisect_root

__all__ = ["CriticalValues", "WallCritical", "CorridorCritical", "is_field_law", "in_user_f", "WallBranches", "CorridorBranches"]


class CriticalValues(Mapping):
    """Critical values of one model in one geometry: named fields, read-only mapping too.

    Subclasses are frozen dataclasses. As a `Mapping` they hold their fields
    in declaration order, leaving out those that are None and `sides`
    (``critical["L_critical"]``, ``.items()``, ``in``, ``len``, iteration):
    the keys and the order of the report's JSON. Equality is the mapping's (so
    a plain dict of the same items compares equal).

    Every value has a stable side (`stable_side`, docs/models.md "Critical
    values"): "below" (stable for values below it: V*, T*, k*), "above" (α*,
    L*; a wall's f*) or, for a value found as the nearest change of verdict
    (a law that is not `monotone`, docs/fields.md), the side on which the
    verdict is stable just past it, given in `sides`.
    """

    __slots__ = ()
    _SIDES: dict = {}

    def _keys(self) -> tuple:
        return tuple(f.name for f in fields(self) if f.name != "sides" and getattr(self, f.name) is not None)

    def stable_side(self, key: str) -> str | None:
        """"below" or "above": on which side of the critical value `key` the loop is stable; None when the value is undefined (NaN).

        Parameters
        ----------
        key : str
            A critical value's name (e.g. ``"L_critical"``).
        """
        value = self[key]
        if isinstance(value, float) and math.isnan(value):
            return None
        return dict(self.sides).get(key, self._SIDES.get(key))

    def stable_sides(self) -> dict:
        """Key → `stable_side` for every value."""
        return {key: self.stable_side(key) for key in self}

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
    dead_time_critical : float or None
        D*, s: the largest dead time of the steering plant the operating point
        tolerates (`LoopModel.critical_dead_time`); only for a robot with a
        dead time or a plant gain (None, and no key, for KB's robot).
    eta_critical, rho0_critical, xi_critical : float or None
        Khatib's and the goal-aware law: the nearest η, ρ0 (m) and ξ at which
        the verdict of this equilibrium changes (docs/fields.md; ``inf``: no
        limit, NaN: no value helps). None (no key) for other laws.
    sides : tuple of (str, str)
        (key, "below" or "above") for the values whose stable side is not
        the default (`stable_side`): those found as the nearest change of
        verdict. Not a key of the mapping.
    """

    _SIDES = {"alpha_critical": "above", "alpha_critical_deg": "above", "f_critical": "above", "V_critical": "below", "T_critical": "below",
              "k_critical": "below", "tau_plus_T_critical": "below", "dead_time_critical": "below"}

    alpha_critical: float
    alpha_critical_deg: float = field(init=False)
    f_critical: float | None = None
    V_critical: float
    T_critical: float
    k_critical: float
    tau_plus_T_critical: float | None = None
    dead_time_critical: float | None = None
    eta_critical: float | None = None
    rho0_critical: float | None = None
    xi_critical: float | None = None
    sides: tuple = ()

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
    dead_time_critical : float or None
        D*, s (see `WallCritical`).
    eta_critical, rho0_critical, xi_critical : float or None
        As in `WallCritical`, for the middle of the corridor.
    sides : tuple of (str, str)
        As in `WallCritical`.
    """

    _SIDES = {"L_critical": "above", "f_critical": "below", "V_critical": "below", "T_critical": "below", "k_critical": "below",
              "tau_plus_T_critical": "below", "dead_time_critical": "below"}

    L_critical: float
    V_critical: float
    f_critical: float | None = None
    T_critical: float
    k_critical: float
    tau_plus_T_critical: float | None = None
    dead_time_critical: float | None = None
    eta_critical: float | None = None
    rho0_critical: float | None = None
    xi_critical: float | None = None
    sides: tuple = ()


_ALPHA_STEPS = 120
"""Even steps of α over its range (0.75° each) when following a wall equilibrium."""


def is_field_law(law: ForceLaw) -> bool:
    """True for Khatib's and the goal-aware law: critical values of η, ρ0 and ξ instead of f.

    Parameters
    ----------
    law : ForceLaw
        Any lateral force law.
    """
    return isinstance(law, (KhatibLaw, GnronLaw))


def in_user_f(law: ForceLaw, strength: float) -> float:
    """A strength (`scale`) of `law` in the user's f: KB's lumped f the law stands for there (`ForceLaw.lumped_f`).

    The force is ∝ the strength, so f = strength·lumped_f/scale: the power law's f
    itself, a grid law's cell ratio ρ as f_av = ρ·f_av(ρ0)/ρ0 (KB §4). ``inf``, 0
    and NaN keep their meaning.

    Parameters
    ----------
    law : ForceLaw
        The law whose strength it is.
    strength : float
        A value of the law's strength (`ForceLaw.scale`).
    """
    if not math.isfinite(strength) or strength == 0:
        return strength
    return strength * (law.lumped_f() / law.scale)


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

    def _critical(self, name: str, NV_critical: float, stable_end: float, unstable_end: float, end_side: str) -> tuple:
        """(p*, stable side) on the branch of `name`; `stable_end` / `unstable_end` (side `end_side`) when N·V never crosses NV*.

        The side is where the verdict is stable just past p*: towards p0 when
        the operating point is stable, away from it when it is not.
        """
        N = self.start.N
        if N < 0 or NV_critical <= 0:
            return unstable_end, end_side
        if math.isinf(NV_critical):
            return stable_end, end_side
        branch = self._branch(name)
        root, _ = branch.nearest_crossing(NV_critical / self.V)
        if root is not None:
            stable_now = N * self.V < NV_critical
            return root, "below" if (root > branch.p0) == stable_now else "above"
        return (stable_end if N * self.V < NV_critical else unstable_end), end_side

    def law_parameters(self, NV_critical: float) -> dict:
        """The law's strength (f*, or η* and ξ*) and ρ0* of a field law, with their stable sides (``sides``)."""
        if not is_field_law(self.law):
            f, side = self._critical("scale", NV_critical, math.inf, math.nan, "below")
            return {"f_critical": in_user_f(self.law, f), "sides": (("f_critical", side),)}
        eta, eta_side = self._critical("eta", NV_critical, math.inf, math.nan, "below")
        rho0, rho0_side = self._critical("rho0", NV_critical, math.inf, math.nan, "below")
        if math.isfinite(eta):  # only η/ξ enters: ξ* = ξη/η*, stable on the other side
            xi, xi_side = self.law.xi * self.law.eta / eta, {"below": "above", "above": "below"}[eta_side]
        else:
            xi, xi_side = eta, eta_side
        return {"eta_critical": eta, "rho0_critical": rho0, "xi_critical": xi,
                "sides": (("eta_critical", eta_side), ("rho0_critical", rho0_side), ("xi_critical", xi_side))}


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
        """α* (rad) and the law's parameters' critical values for a model with this NV* (1/s), and their stable sides.

        Parameters
        ----------
        NV_critical : float
            The model's NV*, 1/s.
        """
        alpha, side = self._critical("alpha", NV_critical, 0.0, math.pi / 2, "above")
        own = self.law_parameters(NV_critical)
        return {"alpha_critical": alpha, **own, "sides": (("alpha_critical", side), ("alpha_critical_deg", side), *own["sides"])}


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
            return Branch(lambda L, _: self._middle(self.law, L), self.L, self.start, self.W / 2 * (1 + 1e-9), RANGES["L"].high,
                          breaks=self.law.breakpoints())
        make = self.law.with_scale if name == "scale" else (lambda p: dataclasses.replace(self.law, **{name: p}))
        lo, hi = _range("f" if name == "scale" else name)
        start = self.law.scale if name == "scale" else getattr(self.law, name)
        return Branch(lambda p, _: self._middle(make(p), self.L), start, self.start, lo, hi, breaks=_passing(make, lo, hi, self.L))

    def critical_L(self, NV_critical: float) -> tuple:
        """(L*, m, stable side): the nearest half-width at which the middle's verdict changes (0: stable at every L; inf: at none).

        Parameters
        ----------
        NV_critical : float
            The model's NV*, 1/s.
        """
        return self._critical("L", NV_critical, 0.0, math.inf, "above")


def _passing(make, lo: float, hi: float, distance: float) -> tuple:
    """The values p in (lo, hi) at which a breakpoint of the law ``make(p)`` passes `distance` (m).

    In a corridor of half-width L a law parameter that moves a breakpoint (ρ0:
    where the repulsion's support ends) makes N jump where the breakpoint
    reaches L; the branch in that parameter steps onto it (`fields.Branch`).
    """
    try:
        ends = make(lo).breakpoints(), make(hi).breakpoints()
    except ValueError:  # a law built in code that refuses an end of the range: no breakpoint is followed
        return ()
    out = []
    for i in range(min(len(ends[0]), len(ends[1]))):
        if (ends[0][i] - distance) * (ends[1][i] - distance) < 0:
            out.append(bisect_root(lambda p, i=i: make(p).breakpoints()[i] - distance, lo, hi))
    return tuple(out)
