"""The fuzzy-scheduled repulsion of the DFAPF paper as a lateral law: N (total and frozen) and c.

The DFAPF paper ("Dynamic fuzzy artificial potential field") scales Ge & Cui 2000's
repulsion (eq 8–9) by a gain η that a fuzzy controller computes every step from the
obstacle's distance d and bearing θ (`fuzzy`, Table 1). Beside a straight wall at
distance d, with KB's heading deviation ψ (positive away from the wall) and the
target at angle α from the wall normal (docs/velocity_and_fuzzy.md):

    F_x(d, ψ) = η(d, θ_obs)·p(d)·ρ_gⁿ − F_a cos α,    F_y = F_a sin α,
    p(d) = (1/d − 1/ρ0)/d² (0 beyond ρ0),    θ_obs = ±(π/2 + ψ)

(+ for a wall on the robot's left, − on its right). The controller is memoryless, so the
loop stays KB's third-order loop with three changes, all computed here:

* N (total) = −[∂η/∂d·p + η·p′]ρ_gⁿ/F_y: the gain moves with the state;
* N_frozen = −η·p′·ρ_gⁿ/F_y: η held at its equilibrium value (optimistic when ∂η/∂d < 0);
* c = −∂F_x/∂ψ / F_y = ∓∂η/∂θ·p·ρ_gⁿ/F_y: η depends on the heading through θ_obs.

∂η/∂d and ∂η/∂θ are the exact derivatives of the discretised centroid
(`fuzzy.FuzzySystem.evaluate_with_gradient`). The goal-directed part of Ge & Cui's
repulsion (their F_rep2, ∝ n) and the velocity term K_V are not included: with n = 0,
the case the paper's numbers use, the former vanishes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_choice, check_number, check_type
from .force_law import Equilibrium
from .fuzzy import DfapfControllers, load_dfapf
from ..parameters import check_parameter
from ..numerics.solve import bisect_root

__all__ = ["FuzzyScheduledLaw", "RobustBracket", "ScheduledEquilibrium"]

_KINK = 1e-9
"""Offset, rad, at which the one-sided θ-slopes of η are taken (`ScheduledEquilibrium.c_plus`)."""

_SCAN = 801
"""Points of the scan for equilibria (wall: geometric in d; corridor: uniform in x)."""


@dataclass(frozen=True)
class ScheduledEquilibrium(Equilibrium):
    """An equilibrium of the fuzzy-scheduled law with its total and frozen gains.

    Attributes
    ----------
    x0, N, c : float
        As `force_law.Equilibrium`: d0 (wall) or the offset towards the right wall
        (corridor), m; the total-derivative N, 1/m; the heading gain c.
    N_frozen : float
        N with η frozen at its equilibrium value, 1/m.
    eta : float
        η at the equilibrium (for a corridor: the left wall's).
    eta_d : float
        ∂η/∂d at the equilibrium, 1/m (for a corridor: the left wall's).
    c_plus, c_minus : float
        The one-sided heading gains for ψ > 0 and ψ < 0 (corridor: θ > 0, θ < 0).
        θ_obs = ±90° is the centre of a bearing set, where its two neighbours tie, so
        η has a kink in θ there; c is their mean (the central difference).
    """

    N_frozen: float = math.nan
    eta: float = math.nan
    eta_d: float = math.nan
    c_plus: float = math.nan
    c_minus: float = math.nan


@dataclass(frozen=True)
class RobustBracket:
    """Frozen-gain extremes over the range of the controller's output (not rigorous: ignores ∂η/∂d and c).

    Attributes
    ----------
    eta : tuple of float
        (η_min, η_max): the output's range over the inputs.
    N : tuple of float
        N at η_min and at η_max, 1/m.
    d0 : tuple of float
        d0 at η_min and at η_max, m.
    """

    eta: tuple
    N: tuple
    d0: tuple


@dataclass(frozen=True)
class FuzzyScheduledLaw:
    """The DFAPF paper's repulsion with η from its fuzzy controller 1 (docs/velocity_and_fuzzy.md).

    Parameters
    ----------
    rho0 : float
        Influence distance ρ0, m.
    attraction : float
        The attraction's magnitude F_a, N (its forward part F_a sin α is F_y at a wall).
    n : float
        Goal exponent of the regulatory factor ρ_gⁿ, [0, 10] (0 by default).
    rho_g : float
        Frozen distance to the goal ρ_g, m (1 by default; enters only as ρ_gⁿ).
    controllers : DfapfControllers, optional
        The fuzzy controllers; `fuzzy.load_dfapf()` (the tables as printed) by default.
    """

    rho0: float
    attraction: float
    n: float = 0.0
    rho_g: float = 1.0
    controllers: DfapfControllers = field(default=None)

    def __post_init__(self):
        object.__setattr__(self, "rho0", check_parameter("rho0", self.rho0))
        object.__setattr__(self, "attraction", check_number("attraction", self.attraction, 0.0, 1e9, unit="N"))
        object.__setattr__(self, "n", check_parameter("goal_exponent", self.n) if self.n else 0.0)
        object.__setattr__(self, "rho_g", check_parameter("goal_distance", self.rho_g))
        if self.controllers is None:
            object.__setattr__(self, "controllers", load_dfapf())
        check_type("controllers", self.controllers, DfapfControllers, "fuzzy.DfapfControllers (fuzzy.load_dfapf())")

    @property
    def factor(self) -> float:
        """ρ_gⁿ, the regulatory factor."""
        return self.rho_g**self.n

    def shape(self, d):
        """(p, p′) at d (m): p = (1/d − 1/ρ0)/d² for 0 < d < ρ0, else 0; p′ in 1/m⁴.

        Parameters
        ----------
        d : float or ndarray
            Distance, m.
        """
        d = np.asarray(d, dtype=float)
        inside = (d > 0) & (d < self.rho0)
        with np.errstate(divide="ignore", invalid="ignore"):
            p = np.where(inside, (1.0 / d - 1.0 / self.rho0) / d**2, 0.0)
            dp = np.where(inside, -3.0 / d**4 + 2.0 / (self.rho0 * d**3), 0.0)
        return p, dp

    def _side(self, side: str) -> float:
        return 1.0 if check_choice("side", side, ("left", "right")) == "left" else -1.0

    def wall_force(self, d, psi, alpha: float, side: str = "left"):
        """(F_x, F_y), N, at distance d (m) and heading deviation ψ (rad, positive away from the wall).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        psi : float or ndarray
            Heading deviation, rad, positive away from the wall.
        alpha : float
            Target angle from the wall normal, rad.
        side : str, optional
            The wall's side, ``"left"`` or ``"right"``.
        """
        s = self._side(side)
        p, _ = self.shape(d)
        eta = self.controllers.eta_of(d, s * (0.5 * math.pi + np.asarray(psi, dtype=float)))
        Fx = eta * p * self.factor - self.attraction * math.cos(alpha)
        return Fx, np.full(np.shape(Fx), self.attraction * math.sin(alpha))

    def wall_equilibria(self, alpha: float, side: str = "left") -> tuple:
        """Every equilibrium beside a wall on the robot's `side` (``"left"``/``"right"``), sorted by d0.

        Roots of F_x(d, 0) on (0, ρ0), found by a geometric scan of 801 points and
        `solve.bisect_root`; at each, N (total), N_frozen and c (module docstring).

        Parameters
        ----------
        alpha : float
            Target angle from the wall normal, rad.
        side : str, optional
            The wall's side, ``"left"`` or ``"right"``.
        """
        alpha = check_parameter("alpha", alpha)
        s = self._side(side)
        theta = s * 0.5 * math.pi

        def lateral(d):
            return self.wall_force(d, 0.0, alpha, side)[0]

        grid = self.rho0 * np.geomspace(1e-4, 1.0 - 1e-9, _SCAN)
        F = lateral(grid)
        out = []
        for i in np.flatnonzero(np.sign(F[:-1]) * np.sign(F[1:]) < 0):
            d0 = bisect_root(lambda d: float(lateral(d)), float(grid[i]), float(grid[i + 1]), rtol=1e-14)
            eta, eta_d, _ = self.controllers.eta_with_slopes(d0, theta)
            t_plus, t_minus = self._theta_slopes(d0, theta, s)
            p, dp = (float(v) for v in self.shape(d0))
            Fy = self.attraction * math.sin(alpha)
            g = self.factor / Fy
            c_plus, c_minus = -s * float(t_plus) * p * g, -s * float(t_minus) * p * g
            out.append(ScheduledEquilibrium(
                d0, -(eta_d * p + eta * dp) * g, 0.5 * (c_plus + c_minus), -eta * dp * g, eta, eta_d, c_plus, c_minus,
            ))
        return tuple(out)

    def _theta_slopes(self, d, theta, direction):
        """∂η/∂θ (1/rad) just after and just before θ along `direction` (±1): the two sides of a kink."""
        after = self.controllers.eta_with_slopes(d, theta + direction * _KINK)[2]
        before = self.controllers.eta_with_slopes(d, theta - direction * _KINK)[2]
        return after, before

    def _corridor_terms(self, L, x, theta):
        """Lateral force (towards the right wall) and its total x- and θ-derivatives at offset x, heading θ."""
        dl, dr = L + x, L - x
        pl, dpl = self.shape(dl)
        pr, dpr = self.shape(dr)
        el, eld, elt = self.controllers.eta_with_slopes(dl, 0.5 * math.pi + theta)
        er, erd, ert = self.controllers.eta_with_slopes(dr, -0.5 * math.pi + theta)
        f = self.factor
        F = (el * pl - er * pr) * f
        dF = (eld * pl + el * dpl + erd * pr + er * dpr) * f
        dF_frozen = (el * dpl + er * dpr) * f
        dF_theta = (elt * pl - ert * pr) * f
        return F, dF, dF_frozen, dF_theta, el, eld

    def corridor_lateral_force(self, L: float, x, theta=0.0):
        """F_x, N, towards the right wall at offset x (m) and heading θ (rad, positive towards the right wall).

        The left wall is at distance L + x and bearing π/2 + θ; the right wall at
        L − x and bearing −π/2 + θ.

        Parameters
        ----------
        L : float
            Corridor half-width, m.
        x : float or ndarray
            Offset from the middle, m, towards the right wall.
        theta : float or ndarray, optional
            Heading, rad, positive towards the right wall.
        """
        return self._corridor_terms(L, np.asarray(x, dtype=float), np.asarray(theta, dtype=float))[0]

    def corridor_equilibria(self, L: float, forward: float | None = None) -> tuple:
        """Every equilibrium in a corridor of half-width L (m), target straight ahead, sorted by x0.

        x0 is the offset towards the right wall; N = −F_x′(x0)/F_y (total), N_frozen,
        c = −∂F_x/∂θ/F_y, with F_y = `forward` (N; the attraction F_a by default).
        The asymmetric tables move x0 off the centre line.

        Parameters
        ----------
        L : float
            Corridor half-width, m.
        forward : float, optional
            Forward pull F_a, N (default the law's).
        """
        L = check_parameter("L", L)
        Fy = self.attraction if forward is None else check_number("forward", forward, 0.0, 1e9, unit="N")
        reach = L * (1.0 - 1e-9)
        grid = np.linspace(-reach, reach, _SCAN)
        F = self.corridor_lateral_force(L, grid)
        out = []
        for i in np.flatnonzero(np.sign(F[:-1]) * np.sign(F[1:]) < 0):
            x0 = bisect_root(lambda x: float(self.corridor_lateral_force(L, x)), float(grid[i]), float(grid[i + 1]), rtol=1e-12)
            _, dF, dF_frozen, _, el, eld = self._corridor_terms(L, x0, 0.0)
            c_plus = -float(self._corridor_terms(L, x0, _KINK)[3]) / Fy
            c_minus = -float(self._corridor_terms(L, x0, -_KINK)[3]) / Fy
            out.append(ScheduledEquilibrium(
                x0, -float(dF) / Fy, 0.5 * (c_plus + c_minus), -float(dF_frozen) / Fy, float(el), float(eld), c_plus, c_minus,
            ))
        return tuple(out)

    def robust_bracket(self, alpha: float) -> RobustBracket:
        """Frozen-gain N and d0 at a wall for η at both ends of the controller's output range.

        Parameters
        ----------
        alpha : float
            Target angle from the wall normal, rad.
        """
        alpha = check_parameter("alpha", alpha)
        lo, hi = self.controllers.eta.output_range()
        Fy = self.attraction * math.sin(alpha)
        pull = self.attraction * math.cos(alpha)
        d0s, Ns = [], []
        for eta in (lo, hi):
            k = eta * self.factor
            top = self.rho0 * (1.0 - 1e-12)
            d0 = bisect_root(lambda d: k * float(self.shape(d)[0]) - pull, self.rho0 * 1e-6, top, rtol=1e-14)
            d0s.append(d0)
            Ns.append(-k * float(self.shape(d0)[1]) / Fy)
        return RobustBracket((lo, hi), tuple(Ns), tuple(d0s))
