"""Ge & Cui 2002's velocity potentials as lateral laws: their N and heading gain c, and the non-smooth verdict.

Ge & Cui, "Dynamic motion planning for mobile robots using potential field method",
Autonomous Robots 13, 2002 (GC2002; its conference form, 2000, "GC-conf"), make both
potentials depend on velocity (docs/velocity_and_fuzzy.md):

* `VelocityAttraction` (eq 1, 7–9): F_att = mα_p‖e‖^(m−1) n_RT + nα_v‖ė‖^(n−1) n_VRT,
  position and velocity gradients added, no ½. For a steering robot at speed V the
  velocity part is −nα_v V^(n−1)(sin θ, cos θ) (stationary target): it lowers the forward
  force and adds a heading gain, q = nα_v V^(n−1)/F_y,static, N = N_static/(1 − q),
  c = q/(1 − q) (`steering_wall_equilibria`). For a holonomic robot (force =
  acceleration) it is damping: c_h = nα_v V^(n−2)/m_rob, κ = −F_x′/m_rob (`holonomic_wall_gains`).
* `VelocityGatedRepulsion` (eq 10–12, 19–20): a repulsion that acts only while the robot
  closes on the obstacle, with the braking distance in the clearance. Forces are the true
  gradients: a wall has no tangential part (eq 20 ≡ 0) and a ball's tangential part uses the
  centre distance. Parallel to a wall it exerts nothing, so no smooth equilibrium exists:
  `non_smooth_wall` gives the Filippov rest band instead; `stall_band` the 1-D band of eq (23).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_number, check_type
from .force_law import Equilibrium, ForceLaw, corridor_equilibria, wall_equilibria
from ..parameters import check_parameter
from ..numerics.solve import bisect_root

__all__ = [
    "OBSTACLE_KINDS",
    "VARIANTS",
    "HolonomicGains",
    "NonSmoothCorridor",
    "NonSmoothWall",
    "RepulsionResult",
    "StallBand",
    "VelocityAttraction",
    "VelocityGatedRepulsion",
    "stall_band",
]

VARIANTS = ("gradient", "squared", "paper_eq23")
"""Repulsion magnitudes: η/D² (the gradient of eq 12, reading A), η(1/D − 1/ρ0)² (reading B),
η³(1/D − 1/ρ0)² (as printed in eq 23 and GC-conf eq 19, reading C)."""

OBSTACLE_KINDS = ("point", "ball", "wall")

_LAW = "a ForceLaw in units of the attraction (e.g. KhatibLaw)"


def _vector(name: str, value) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    if v.shape != (2,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be a finite 2-vector (x, y); got {value!r}")
    return v


@dataclass(frozen=True)
class HolonomicGains:
    """Lateral gains of a holonomic robot (m ẍ = F_x(x, ẋ)) at one equilibrium: s² + (c_h s + κ)e^(−sT).

    Attributes
    ----------
    x0 : float
        d0 (wall) or the offset towards the right wall (corridor), m.
    kappa : float
        κ = −∂F_x/∂x / m_rob, 1/s².
    c_h : float
        c_h = −∂F_x/∂v_x / m_rob, 1/s.
    """

    x0: float
    kappa: float
    c_h: float


@dataclass(frozen=True)
class VelocityAttraction:
    """GC2002's velocity-aware attraction (eq 1, 7–9), stationary or moving target.

    Parameters
    ----------
    alpha_p : float
        Position gain α_p, N/m^m, > 0.
    alpha_v : float
        Velocity gain α_v, N/(m/s)^n, ≥ 0.
    m, n : float
        Exponents of ‖e‖ and ‖ė‖, in (0, 10] (soft landing needs m, n > 1, GC2002 Remark 2).
    """

    alpha_p: float
    alpha_v: float
    m: float = 2.0
    n: float = 2.0

    def __post_init__(self):
        object.__setattr__(self, "alpha_p", check_parameter("alpha_p", self.alpha_p))
        object.__setattr__(self, "alpha_v", check_parameter("alpha_v", self.alpha_v))
        object.__setattr__(self, "m", check_number("m", self.m, 0.0, 10.0, high_open=False))
        object.__setattr__(self, "n", check_number("n", self.n, 0.0, 10.0, high_open=False))

    def force(self, p, v, p_tar=(0.0, 0.0), v_tar=(0.0, 0.0)) -> np.ndarray:
        """F_att, N (2-vector): mα_p‖e‖^(m−1) e/‖e‖ + nα_v‖ė‖^(n−1) ė/‖ė‖, e = p_tar − p, ė = v_tar − v.

        A part whose error is exactly 0 is 0 (for m ≤ 1 or n ≤ 1 the force is discontinuous there).

        Parameters
        ----------
        p, v : 2-vector
            Robot position (m) and velocity (m/s).
        p_tar, v_tar : 2-vector, optional
            Target position (m) and velocity (m/s).
        """
        e = _vector("p_tar", p_tar) - _vector("p", p)
        de = _vector("v_tar", v_tar) - _vector("v", v)
        out = np.zeros(2)
        for gain, k, err in ((self.alpha_p, self.m, e), (self.alpha_v, self.n, de)):
            r = math.hypot(*err)
            if r > 0:
                out += k * gain * r ** (k - 2.0) * err
        return out

    def position_force(self, rho_g: float) -> float:
        """F_a = mα_p ρ_g^(m−1), N: the position part's magnitude at goal distance ρ_g (m).

        Parameters
        ----------
        rho_g : float
            Distance to the goal, m.
        """
        return self.m * self.alpha_p * check_parameter("goal_distance", rho_g) ** (self.m - 1.0)

    def velocity_force(self, V: float) -> float:
        """nα_v V^(n−1), N: the velocity part's magnitude at speed V (m/s), stationary target.

        Parameters
        ----------
        V : float
            Speed, m/s.
        """
        return self.n * self.alpha_v * check_parameter("V", V) ** (self.n - 1.0)

    def damping_ratio(self, mass: float = 1.0) -> float:
        """ζ = α′_v/√(2α′_p), α′ = α/m_rob (GC2002 eq 34–36; for m = n = 2).

        Parameters
        ----------
        mass : float, optional
            Robot mass m_rob, kg.
        """
        mass = check_parameter("mass", mass)
        self._require_quadratic()
        return (self.alpha_v / mass) / math.sqrt(2.0 * self.alpha_p / mass)

    def natural_frequency(self, mass: float = 1.0) -> float:
        """ω_n = √(2α′_p), rad/s (GC2002 eq 36; for m = n = 2).

        Parameters
        ----------
        mass : float, optional
            Robot mass m_rob, kg.
        """
        mass = check_parameter("mass", mass)
        self._require_quadratic()
        return math.sqrt(2.0 * self.alpha_p / mass)

    def _require_quadratic(self):
        if self.m != 2.0 or self.n != 2.0:
            raise ValueError(f"m and n must be 2 for the linear error dynamics (GC2002 eq 33); got m={self.m:g}, n={self.n:g}")

    def hard_landing_speed(self) -> float:
        """Closing speed of a hard landing, m/s: (α_p/(nα_v))^(1/(n−1)) for m = 1 (α_p/(2α_v) for n = 2).

        With m = 1 the position part has constant magnitude α_p; the robot approaches
        radially at the speed where the velocity part nα_v V^(n−1) balances it
        (GC2002 Fig 12: α_p = 0.05, α_v = 0.4 gives 0.0625 m/s).
        """
        if self.m != 1.0:
            raise ValueError(f"m must be 1 for a hard landing at constant closing speed; got {self.m:g}")
        if self.n <= 1.0 or self.alpha_v == 0.0:
            raise ValueError(f"n must be > 1 and alpha_v > 0 for a finite closing speed; got n={self.n:g}, alpha_v={self.alpha_v:g}")
        return (self.alpha_p / (self.n * self.alpha_v)) ** (1.0 / (self.n - 1.0))

    def _steering(self, static: Equilibrium, forward_static: float, V: float) -> Equilibrium:
        """N, c of a steering robot from a static equilibrium whose forward force is `forward_static` (N)."""
        b = self.velocity_force(V)
        forward = forward_static - b
        if not forward > 0:
            raise ValueError(
                f"V must be below the speed at which the velocity attraction cancels the forward pull "
                f"(n·alpha_v·V^(n-1) = {b:.6g} N >= {forward_static:.6g} N): no forward force, no equilibrium"
            )
        q = b / forward_static
        return Equilibrium(static.x0, static.N / (1.0 - q), q / (1.0 - q))

    def steering_wall_equilibria(self, law: ForceLaw, alpha: float, V: float, rho_g: float) -> tuple:
        """Every wall equilibrium of a steering robot at speed V (m/s): (d0, N, c) (docs/velocity_and_fuzzy.md).

        `law` is the repulsion in units of the position part F_a = mα_p ρ_g^(m−1) (its
        P and goal part Q). The velocity part −nα_v V^(n−1)(sin θ, cos θ) leaves d0 as it
        is and gives F_y = F_a(1 + Q(d0)) sin α − nα_v V^(n−1), so with
        q = nα_v V^(n−1)/(F_a(1 + Q) sin α): N = N_static/(1 − q), c = q/(1 − q).
        ValueError when q ≥ 1 (no forward force).

        Parameters
        ----------
        law : ForceLaw
            The wall's repulsion.
        alpha : float
            Target angle from the wall normal, rad.
        V : float
            Speed, m/s.
        rho_g : float
            Distance to the goal, m.
        """
        check_type("law", law, ForceLaw, _LAW)
        Fa = self.position_force(rho_g)
        alpha = check_parameter("alpha", alpha)
        out = []
        for eq in wall_equilibria(law, alpha):
            if not math.isfinite(eq.x0):
                continue
            forward = Fa * (1.0 + float(law.goal_force(eq.x0))) * math.sin(alpha)
            out.append(self._steering(eq, forward, V))
        return tuple(out)

    def steering_corridor_equilibria(self, law: ForceLaw, L: float, V: float, rho_g: float) -> tuple:
        """Every corridor equilibrium (target straight ahead) of a steering robot at speed V: (x0, N, c).

        F_y = F_a(1 + Q(L + x0) + Q(L − x0)) − nα_v V^(n−1); N and c as for a wall.

        Parameters
        ----------
        law : ForceLaw
            The walls' repulsion.
        L : float
            Corridor half-width, m.
        V : float
            Speed, m/s.
        rho_g : float
            Distance to the goal, m.
        """
        check_type("law", law, ForceLaw, _LAW)
        Fa = self.position_force(rho_g)
        out = []
        for eq in corridor_equilibria(law, check_parameter("L", L)):
            forward = Fa * (1.0 + float(law.goal_force(L + eq.x0)) + float(law.goal_force(L - eq.x0)))
            out.append(self._steering(eq, forward, V))
        return tuple(out)

    def _damping(self, V: float, mass: float) -> float:
        """c_h = nα_v V^(n−2)/m_rob, 1/s: −∂F_x/∂v_x / m_rob at lateral velocity 0 and forward speed V."""
        if self.n == 2.0:
            return 2.0 * self.alpha_v / mass
        if not V > 0:
            raise ValueError(f"V must be > 0 m/s for n != 2 (the damping nα_v V^(n-2) is 0 or infinite at rest); got {V!r}")
        return self.n * self.alpha_v * V ** (self.n - 2.0) / mass

    def _holonomic_inputs(self, law, rho_g: float, mass: float, V: float) -> tuple:
        """(F_a in N, m_rob in kg, c_h in 1/s) of a holonomic robot's equilibria, after checking the law, ρ_g, the mass and V."""
        check_type("law", law, ForceLaw, _LAW)
        Fa, mass = self.position_force(rho_g), check_parameter("mass", mass)
        return Fa, mass, self._damping(check_number("V", V, 0.0, 100.0, low_open=False, unit="m/s"), mass)

    def holonomic_wall_gains(self, law: ForceLaw, alpha: float, rho_g: float, mass: float = 1.0, V: float = 0.0) -> tuple:
        """(x0 = d0, κ, c_h) at every wall equilibrium of a holonomic robot (GC2002 §6: force = acceleration).

        κ = −F_a(P′(d0) − Q′(d0) cos α)/m_rob with `law` in units of F_a = mα_p ρ_g^(m−1);
        c_h = nα_v V^(n−2)/m_rob (2α_v/m_rob for n = 2, whatever V, m/s).

        Parameters
        ----------
        law : ForceLaw
            The wall's repulsion.
        alpha : float
            Target angle from the wall normal, rad.
        rho_g : float
            Distance to the goal, m.
        mass : float, optional
            Robot mass m_rob, kg.
        V : float, optional
            Speed along the wall, m/s.
        """
        alpha = check_parameter("alpha", alpha)
        Fa, mass, c_h = self._holonomic_inputs(law, rho_g, mass, V)
        out = []
        for eq in wall_equilibria(law, alpha):
            if math.isfinite(eq.x0):
                slope = float(law.slope(eq.x0)) - float(law.goal_slope(eq.x0)) * math.cos(alpha)
                out.append(HolonomicGains(eq.x0, -Fa * slope / mass, c_h))
        return tuple(out)

    def holonomic_corridor_gains(self, law: ForceLaw, L: float, rho_g: float, mass: float = 1.0, V: float = 0.0) -> tuple:
        """(x0, κ, c_h) at every corridor equilibrium of a holonomic robot: κ = −F_a(P′(L + x0) + P′(L − x0))/m_rob.

        Parameters
        ----------
        law : ForceLaw
            The walls' repulsion.
        L : float
            Corridor half-width, m.
        rho_g : float
            Distance to the goal, m.
        mass : float, optional
            Robot mass m_rob, kg.
        V : float, optional
            Speed along the corridor, m/s.
        """
        L = check_parameter("L", L)
        Fa, mass, c_h = self._holonomic_inputs(law, rho_g, mass, V)
        out = []
        for eq in corridor_equilibria(law, L):
            slope = float(law.slope(L + eq.x0)) + float(law.slope(L - eq.x0))
            out.append(HolonomicGains(eq.x0, -Fa * slope / mass, c_h))
        return tuple(out)


@dataclass(frozen=True)
class RepulsionResult:
    """The velocity-gated repulsion at one state.

    Attributes
    ----------
    status : str
        ``"inactive"`` (v_RO ≤ 0, or D ≥ ρ0: no force), ``"active"``, or ``"collision"``
        (v_RO > 0 and D ≤ 0: GC2002 eq 12 leaves it undefined, collision unavoidable).
    force : numpy.ndarray or None
        F_rep = F_rep1 + F_rep2, N (2-vector); None when ``"collision"``.
    potential : float or None
        U_rep, J (eq 12; the `gradient` variant's potential); None when ``"collision"``.
    clearance : float
        ρ_s, m (minus the robot radius, eq 12′).
    closing_speed : float
        v_RO, m/s (eq 10), > 0 when approaching.
    D : float
        ρ_s − v_RO²/(2a_max), m: the clearance left after braking (eq 11–12).
    """

    status: str
    force: np.ndarray | None
    potential: float | None
    clearance: float
    closing_speed: float
    D: float

    @property
    def collision(self) -> bool:
        """True when the collision cannot be avoided (D ≤ 0 while approaching)."""
        return self.status == "collision"


@dataclass(frozen=True)
class NonSmoothWall:
    """Why the velocity-gated repulsion has no linear verdict at a wall, and where it rests.

    Attributes
    ----------
    verdict : str
        ``"non-smooth"``: parallel to the wall v_RO = 0, the repulsion is a relay in the
        heading and no smooth equilibrium exists (no N, no c).
    rest_band : tuple of float
        (0, d_s), m: every clearance where the repulsion at v_RO = 0⁺ outweighs the pull
        F_a cos α is a Filippov rest point of a holonomic robot.
    d_s : float
        The band's edge, m: √(η/(F_a cos α)) for the `gradient` variant, never beyond ρ0.
    friction : float
        F_a cos α, N: the pull that the repulsion must match.
    """

    verdict: str
    rest_band: tuple
    d_s: float
    friction: float


@dataclass(frozen=True)
class NonSmoothCorridor:
    """The velocity-gated repulsion in a corridor: neutral lateral position, friction from both walls.

    Attributes
    ----------
    verdict : str
        ``"non-smooth"``.
    offsets : numpy.ndarray
        x, m (towards the right wall).
    friction_left, friction_right : numpy.ndarray
        The repulsion magnitude at v_RO = 0⁺ of each wall, N (η/(L + x)² and η/(L − x)²
        for the `gradient` variant; 0 beyond ρ0): Coulomb-like friction levels.
    """

    verdict: str
    offsets: np.ndarray
    friction_left: np.ndarray
    friction_right: np.ndarray


@dataclass(frozen=True)
class StallBand:
    """The stall band of GC2002 eq (23): robot positions x (target at 0) where it rests short of the target.

    Attributes
    ----------
    variant : str
        The repulsion magnitude (`VARIANTS`).
    intervals : tuple of tuple of float
        Disjoint (x_lo, x_hi), m, where mα_p|x|^(m−1) ≤ F_r(D) at ẋ = 0⁺ and 0 < D < ρ0:
        Filippov equilibria on ẋ = 0.
    """

    variant: str
    intervals: tuple


@dataclass(frozen=True)
class VelocityGatedRepulsion:
    """GC2002's velocity-gated repulsion (eq 10–12, 19–20, corrected gradients; docs/velocity_and_fuzzy.md).

    U = η(1/D − 1/ρ0) while v_RO > 0 and 0 < D < ρ0, D = ρ_s − v_RO²/(2a_max); else 0.

    Parameters
    ----------
    eta : float
        Repulsion gain η, N·m (for the `gradient` variant).
    rho0 : float
        Influence distance ρ0, m.
    a_max : float
        Maximum deceleration a_max, m/s², > 0.
    variant : str
        ``"gradient"`` (default: F = −∇_p U − ∇_v U, magnitude η/D²), ``"squared"``
        (η(1/D − 1/ρ0)²) or ``"paper_eq23"`` (η³(1/D − 1/ρ0)², as printed in eq 23 and
        GC-conf eq 19). The last two are not gradients of U.
    robot_radius : float
        ρ_rob, m, subtracted from the clearance (eq 12′), default 0.
    """

    eta: float
    rho0: float
    a_max: float
    variant: str = "gradient"
    robot_radius: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "eta", check_parameter("eta", self.eta))
        object.__setattr__(self, "rho0", check_parameter("rho0", self.rho0))
        object.__setattr__(self, "a_max", check_parameter("a_max", self.a_max))
        check_choice("variant", self.variant, VARIANTS)
        object.__setattr__(self, "robot_radius", check_number("robot_radius", self.robot_radius, 0.0, 1e4, low_open=False, unit="m"))

    def braked_clearance(self, distance, closing_speed):
        """D = (distance − ρ_rob) − v_RO²/(2a_max), m: the clearance left after braking at a_max (eq 11, 12, 12′).

        `distance` is to the obstacle's surface (m), `closing_speed` v_RO (m/s, > 0 approaching).

        Parameters
        ----------
        distance : float or ndarray
            Distance to the obstacle, m.
        closing_speed : float or ndarray
            Speed towards it v_RO, m/s.
        """
        return distance - self.robot_radius - closing_speed * closing_speed / (2.0 * self.a_max)

    def magnitude(self, D):
        """The repulsion's magnitude factor at braked clearance D (m): η/D², η(1/D − 1/ρ0)² or η³(1/D − 1/ρ0)².

        Parameters
        ----------
        D : float or ndarray
            Braked clearance, m.
        """
        D = np.asarray(D, dtype=float)
        with np.errstate(divide="ignore"):
            if self.variant == "gradient":
                return self.eta / D**2
            u = (1.0 / D - 1.0 / self.rho0) ** 2
            return self.eta * u if self.variant == "squared" else self.eta**3 * u

    def evaluate(self, p, v, obstacle: str, where, radius: float = 0.0, v_obs=(0.0, 0.0)) -> RepulsionResult:
        """The repulsion on a robot at p (m) with velocity v (m/s) from one obstacle.

        The force is F_rep1 + F_rep2 with F_rep1 = −M(D)(1 + v_RO/a_max) n_RO and
        F_rep2 = M(D) v_RO v_RO⊥/(a_max R) n_RO⊥, M the `magnitude`, R the distance to
        the point or the ball's centre (not ρ_s: the true gradient), F_rep2 ≡ 0 for a
        wall (n_RO is constant). Events: at v_RO = 0 and at D = ρ0 the force jumps
        (``"inactive"`` beyond); D ≤ 0 while approaching is ``"collision"``.

        Parameters
        ----------
        p, v : 2-vector
            Robot position (m) and velocity (m/s).
        obstacle : str
            ``"point"`` (at `where`), ``"ball"`` (centre `where`, `radius` m) or
            ``"wall"`` (`where` = (point on the line, unit normal): a 2×2 array, the
            normal pointing to the robot's side).
        where : array_like
            The point, the ball's centre, or the wall's point and normal, m.
        radius : float, optional
            A ball's radius, m.
        v_obs : 2-vector, optional
            The obstacle's velocity, m/s.
        """
        check_choice("obstacle", obstacle, OBSTACLE_KINDS)
        p, v, v_obs = _vector("p", p), _vector("v", v), _vector("v_obs", v_obs)
        if obstacle == "wall":
            w = np.asarray(where, dtype=float)
            if w.shape != (2, 2) or not np.all(np.isfinite(w)) or not math.isclose(math.hypot(*w[1]), 1.0, rel_tol=1e-9):
                raise ValueError("where must be ((x, y) on the wall, (nx, ny) unit normal) for a wall")
            dist = float((p - w[0]) @ w[1])
            if not dist > 0:
                raise ValueError(f"p must be on the side of the wall its normal points to; got signed distance {dist:g} m")
            n_ro, R = -w[1], math.inf
        else:
            c = _vector("where", where)
            radius = check_number("radius", radius, 0.0, 1e4, low_open=False, unit="m") if obstacle == "ball" else 0.0
            R = math.hypot(*(c - p))
            if not R > 0:
                raise ValueError("p must differ from the obstacle's centre")
            n_ro = (c - p) / R
            dist = R - radius
        rho_s = dist - self.robot_radius
        rel = v - v_obs
        v_ro = float(rel @ n_ro)
        D = self.braked_clearance(dist, v_ro)
        if v_ro > 0 and D <= 0:
            return RepulsionResult("collision", None, None, rho_s, v_ro, D)
        if not v_ro > 0 or D >= self.rho0:
            return RepulsionResult("inactive", np.zeros(2), 0.0, rho_s, v_ro, D)
        M = float(self.magnitude(D))
        force = -M * (1.0 + v_ro / self.a_max) * n_ro
        if math.isfinite(R):
            tangential = rel - v_ro * n_ro  # v_RO⊥ n_RO⊥ (eq 16)
            force = force + M * v_ro / (self.a_max * R) * tangential
        return RepulsionResult("active", force, self.eta * (1.0 / D - 1.0 / self.rho0), rho_s, v_ro, D)

    def potential(self, p, v, obstacle: str, where, radius: float = 0.0, v_obs=(0.0, 0.0)) -> float:
        """U_rep, J (eq 12): η(1/D − 1/ρ0) while active, 0 otherwise; ValueError on a collision state.

        Parameters
        ----------
        p, v : 2-vector
            Robot position (m) and velocity (m/s).
        obstacle : str
            ``"point"``, ``"ball"`` or ``"wall"`` (`evaluate`).
        where : array_like
            The obstacle's position (a wall: a point on it and its unit normal).
        radius : float, optional
            A ball's radius, m.
        v_obs : 2-vector, optional
            The obstacle's velocity, m/s.
        """
        r = self.evaluate(p, v, obstacle, where, radius, v_obs)
        if r.collision:
            raise ValueError("p, v: collision unavoidable (D <= 0 while approaching): the potential is undefined")
        return r.potential

    def at_rest_force(self, d):
        """The repulsion at v_RO = 0⁺ and clearance d (m): M(d) for 0 < d < ρ0, else 0, N.

        Parameters
        ----------
        d : float or ndarray
            Clearance, m.
        """
        d = np.asarray(d, dtype=float)
        inside = (d > 0) & (d < self.rho0)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(inside, self.magnitude(np.where(inside, d, 1.0)), 0.0)

    def non_smooth_wall(self, attraction: float, alpha: float) -> NonSmoothWall:
        """The non-smooth verdict beside a wall, target at angle α (rad) from the wall normal, pull F_a (N).

        Parameters
        ----------
        attraction : float
            The target's pull F_a, N.
        alpha : float
            Target angle from the wall normal, rad.
        """
        Fa = check_number("attraction", attraction, 0.0, 1e9, unit="N")
        alpha = check_parameter("alpha", alpha)
        pull = Fa * math.cos(alpha)
        if self.variant == "gradient":
            d_s = min(math.sqrt(self.eta / pull), self.rho0)
        else:
            d_s = self._edge(lambda d: float(self.at_rest_force(d)) - pull)
        return NonSmoothWall("non-smooth", (0.0, d_s), d_s, pull)

    def _edge(self, excess) -> float:
        """The largest d in (0, ρ0) with excess(d) ≥ 0 for a decreasing excess (ρ0 if it never changes sign)."""
        hi = self.rho0 * (1.0 - 1e-12)
        if excess(hi) >= 0:
            return self.rho0
        return bisect_root(excess, self.rho0 * 1e-9, hi, rtol=1e-14)

    def non_smooth_corridor(self, L: float, offsets=None) -> NonSmoothCorridor:
        """The non-smooth verdict in a corridor of half-width L (m): friction levels of both walls at offsets x.

        Parameters
        ----------
        L : float
            Corridor half-width, m.
        offsets : array_like, optional
            Offsets x from the middle, m, inside (−L, L) (default 19 points across 90 % of it).
        """
        L = check_parameter("L", L)
        x = np.linspace(-0.9 * L, 0.9 * L, 19) if offsets is None else np.asarray(offsets, dtype=float)
        if x.size == 0 or not np.all(np.isfinite(x)) or np.any(np.abs(x) >= L):
            raise ValueError(f"offsets must be finite and inside (-L, L) = (-{L:g}, {L:g}) m")
        return NonSmoothCorridor("non-smooth", x, self.at_rest_force(L + x), self.at_rest_force(L - x))


def stall_band(repulsion: VelocityGatedRepulsion, attraction: VelocityAttraction, rho_to: float) -> StallBand:
    """The stall band of GC2002 eq (23): target at 0, obstacle surface at ρ_TO > 0, robot at x < 0.

    At ẋ = 0⁺ the robot feels the pull mα_p|x|^(m−1) towards the target and the
    repulsion F_r(D) with D = ρ_TO − x (m_rob = 1; the factor 1 + ẋ/a_max is 1). Where
    the repulsion is at least the pull (and 0 < D < ρ0) the robot rests (a Filippov
    equilibrium on ẋ = 0). The band is searched on x ∈ (ρ_TO − ρ0, 0) by a scan of 4001
    points and `solve.bisect_root`.

    Parameters
    ----------
    repulsion : VelocityGatedRepulsion
        The obstacle's repulsion.
    attraction : VelocityAttraction
        The target's pull.
    rho_to : float
        Distance from the target to the obstacle's surface ρ_TO, m.
    """
    check_type("repulsion", repulsion, VelocityGatedRepulsion, "a VelocityGatedRepulsion")
    check_type("attraction", attraction, VelocityAttraction, "a VelocityAttraction")
    rho_to = check_number("rho_to", rho_to, 0.0, 1e4, unit="m")
    lo = min(rho_to - repulsion.rho0, 0.0)

    def excess(x):
        x = np.asarray(x, dtype=float)
        return repulsion.at_rest_force(rho_to - x) - attraction.m * attraction.alpha_p * np.abs(x) ** (attraction.m - 1.0)

    if lo >= 0.0:
        return StallBand(repulsion.variant, ())
    x = np.linspace(lo, 0.0, 4001)[1:-1]
    inside = excess(x) >= 0
    intervals = []
    edges = np.flatnonzero(np.diff(inside.astype(int)))
    starts = ([x[0]] if inside[0] else [])
    ends = []
    for i in edges:
        root = bisect_root(lambda t: float(excess(t)), float(x[i]), float(x[i + 1]), rtol=1e-14)
        (ends if inside[i] else starts).append(root)
    if inside[-1]:
        ends.append(0.0)
    if inside[0]:
        starts[0] = lo  # the band reaches the edge of the influence region
    intervals = tuple((float(a), float(b)) for a, b in zip(starts, ends))
    return StallBand(repulsion.variant, intervals)
