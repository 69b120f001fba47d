"""The scene of the planar simulator and its field over a batch's members (docs/simulator.md, "Planar robots").

`Field` (attraction plus repulsion), `World` (target and obstacles) and `Start` describe one
member's scene. `FieldArrays` compiles the scenes of a batch into arrays — each member its
own attraction (`VelocityAttraction` towards its `Target`, or a constant `Pull`), its own
obstacles (`Wall`, `PointObstacle`, `Ball` of `sim.movers`, fixed or moving; padded to the
batch's largest count) and its own repulsion (`VelocityGatedRepulsion`, a static
`ForceLaw` in units of `repulsion_scale`, or none), summed over the obstacles or from the
nearest only — and `FieldArrays.sense` evaluates them for every member at once at one
sample: the force and, per obstacle, what the events need (`Sensed`). The formulas are
those of `VelocityAttraction.force` and `VelocityGatedRepulsion.evaluate` (GC2002 eq 1,
7–12, 19–20, corrected gradients), written element-wise in the member; the obstacles'
forces are added one obstacle after the other, in the world's order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_number, check_type
from ..laws.force_law import ForceLaw
from ..laws.velocity_laws import VARIANTS, VelocityAttraction, VelocityGatedRepulsion
from .engine import _law_key  # equal laws share one evaluation, as in the VFF engine
from .movers import Obstacle, Pull, Target, Wall, vector
from .planar_robots import positive

__all__ = ["Field", "FieldArrays", "Sensed", "Start", "World"]


@dataclass(frozen=True)
class Field:
    """Attraction plus repulsion.

    Parameters
    ----------
    attraction : VelocityAttraction or Pull
        GC2002's attraction towards the world's target, or a constant pull.
    repulsion : VelocityGatedRepulsion, ForceLaw or None
        GC2002's velocity-gated repulsion, or a static law P(ρ) of the clearance (with its
        goal part Q(ρ) towards the target), scaled by `repulsion_scale`.
    repulsion_scale : float
        Newtons per unit of a `ForceLaw` (its "units of the attraction"), in (0, 1e12].
    nearest_only : bool
        Only the nearest obstacle repels (the conference paper's Assumption 4).
    """

    attraction: object
    repulsion: object = None
    repulsion_scale: float = 1.0
    nearest_only: bool = False

    def __post_init__(self):
        check_type("attraction", self.attraction, (VelocityAttraction, Pull), "a VelocityAttraction or a Pull")
        if self.repulsion is not None:
            check_type("repulsion", self.repulsion, (VelocityGatedRepulsion, ForceLaw), "a VelocityGatedRepulsion, a ForceLaw or None")
        object.__setattr__(self, "repulsion_scale", positive("repulsion_scale", self.repulsion_scale, "N", 1e12))
        check_type("nearest_only", self.nearest_only, bool, "True or False")


@dataclass(frozen=True)
class World:
    """A target (needed by a `VelocityAttraction`) and obstacles (`sim.movers`).

    Attributes
    ----------
    target : Target or None
        The target.
    obstacles : tuple
        `sim.movers` obstacles (`Wall`, `PointObstacle`, `Ball`).
    """

    target: Target | None = None
    obstacles: tuple = ()

    def __post_init__(self):
        if self.target is not None:
            check_type("target", self.target, Target, "a Target or None")
        obstacles = tuple(self.obstacles)
        for o in obstacles:
            check_type("obstacles", o, Obstacle, "a sequence of Wall, PointObstacle or Ball")
        object.__setattr__(self, "obstacles", obstacles)


@dataclass(frozen=True)
class Start:
    """Initial state: `position` (m), `velocity` (m/s; a steering robot's speed is always V) and `heading`.

    `heading` (rad from +x) defaults to the velocity's direction, or 0 at rest.

    Attributes
    ----------
    position : (float, float)
        m.
    velocity : (float, float)
        m/s.
    heading : float or None
        rad from +x (None: the velocity's direction).
    """

    position: tuple
    velocity: tuple = (0.0, 0.0)
    heading: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "position", vector("start position", self.position))
        object.__setattr__(self, "velocity", vector("start velocity", self.velocity))
        if self.heading is None:
            vx, vy = self.velocity
            object.__setattr__(self, "heading", math.atan2(vy, vx) if (vx or vy) else 0.0)
        else:
            object.__setattr__(self, "heading", check_number("heading", self.heading, -100.0, 100.0, unit="rad"))


@dataclass(frozen=True)
class Sensed:
    """The field of every member at one sample.

    Attributes
    ----------
    fx, fy : ndarray, shape (B,)
        The force, N (an undefined repulsion counted as 0).
    clearance : ndarray, shape (B, O)
        ρ_s of each obstacle slot, m (+inf for a padding slot).
    closing_speed : ndarray, shape (B, O)
        v_RO, m/s, > 0 approaching (NaN without a velocity-gated repulsion).
    braked : ndarray, shape (B, O)
        D = ρ_s − v_RO²/(2a_max), m (NaN without a velocity-gated repulsion).
    collision : ndarray of bool, shape (B, O)
        The gated repulsion is undefined (evaluated, approaching, D ≤ 0: GC2002 eq 12).
    nearest : ndarray, shape (B,)
        The smallest clearance, m (+inf without obstacles).
    """

    fx: np.ndarray
    fy: np.ndarray
    clearance: np.ndarray
    closing_speed: np.ndarray
    braked: np.ndarray
    collision: np.ndarray
    nearest: np.ndarray


class FieldArrays:
    """The fields and worlds of a batch as arrays; `sense` evaluates them at one sample.

    Parameters
    ----------
    fields : sequence of Field
        One per member.
    worlds : sequence of World
        One per member (a `VelocityAttraction` needs its target).
    """

    def __init__(self, fields, worlds):
        fields, worlds = list(fields), list(worlds)
        B = self.size = len(fields)
        self._compile_attraction(fields, worlds)
        O = self.slots = max((len(w.obstacles) for w in worlds), default=0)
        shape = (B, O)
        self.valid = np.zeros(shape, dtype=bool)
        self.is_wall = np.zeros(shape, dtype=bool)
        self.ox, self.oy, self.ovx, self.ovy, self.radius = (np.zeros(shape) for _ in range(5))
        self.nx, self.ny = np.ones(shape), np.zeros(shape)
        for m, w in enumerate(worlds):
            for j, o in enumerate(w.obstacles):
                self.valid[m, j] = True
                self.ovx[m, j], self.ovy[m, j] = o.velocity
                if isinstance(o, Wall):
                    self.is_wall[m, j] = True
                    (self.ox[m, j], self.oy[m, j]), (self.nx[m, j], self.ny[m, j]) = o.point, o.normal
                else:
                    self.ox[m, j], self.oy[m, j] = o.position
                    self.radius[m, j] = o.radius
        self.any_wall = bool(np.any(self.valid & self.is_wall))
        self.any_point = bool(np.any(self.valid & ~self.is_wall))
        self.moving = bool(np.any(self.ovx != 0.0) or np.any(self.ovy != 0.0))
        self._compile_repulsion(fields)
        self.slot = np.arange(O)[None, :]

    def _compile_attraction(self, fields, worlds):
        B = self.size
        self.pull = np.array([isinstance(f.attraction, Pull) for f in fields], dtype=bool)
        self.pull_x, self.pull_y, self.unit_x, self.unit_y = (np.zeros(B) for _ in range(4))
        for m, f in enumerate(fields):
            if self.pull[m]:
                unit = f.attraction.unit
                force = f.attraction.magnitude * unit
                self.pull_x[m], self.pull_y[m] = force
                self.unit_x[m], self.unit_y[m] = unit
        self.va = np.flatnonzero(~self.pull)
        self.all_pull = self.va.size == 0
        att = [fields[m].attraction for m in self.va]
        targets = [worlds[m].target for m in self.va]
        take = lambda name: np.array([float(getattr(a, name)) for a in att])  # noqa: E731
        self.alpha_p, self.alpha_v, self.m, self.n = take("alpha_p"), take("alpha_v"), take("m"), take("n")
        self.position_gain, self.velocity_gain = self.m * self.alpha_p, self.n * self.alpha_v
        self.m_is_2, self.n_is_2 = bool(np.all(self.m == 2.0)), bool(np.all(self.n == 2.0))
        self.tx, self.ty = np.array([t.position[0] for t in targets]), np.array([t.position[1] for t in targets])
        self.tvx, self.tvy = np.array([t.velocity[0] for t in targets]), np.array([t.velocity[1] for t in targets])

    def _compile_repulsion(self, fields):
        rep = [f.repulsion for f in fields]
        self.repels = np.array([r is not None for r in rep], dtype=bool)
        self.nearest_only = np.array([f.nearest_only for f in fields], dtype=bool)[:, None]
        self.any_nearest_only = bool(self.nearest_only.any())
        self.gated = np.array([isinstance(r, VelocityGatedRepulsion) for r in rep], dtype=bool)
        self.any_gated, self.all_gated = bool(self.gated.any()), bool(self.gated.all())
        gated = [r if isinstance(r, VelocityGatedRepulsion) else None for r in rep]
        value = lambda name, default: np.array([[getattr(g, name) if g is not None else default] for g in gated], dtype=float)  # noqa: E731
        self.eta, self.rho0, self.a_max, self.robot_radius = value("eta", 1.0), value("rho0", 1.0), value("a_max", 1.0), value("robot_radius", 0.0)
        self.eta_cubed = np.array([[g.eta**3 if g is not None else 1.0] for g in gated])
        self.variant = np.array([[VARIANTS.index(g.variant) if g is not None else 0] for g in gated])
        self.variants = set(self.variant[self.gated, 0].tolist())
        self.scale = np.array([[f.repulsion_scale] for f in fields])
        self.law_groups = {}
        for m, r in enumerate(rep):
            if isinstance(r, ForceLaw):
                self.law_groups.setdefault(_law_key(r), (r, []))[1].append(m)
        self.law_groups = {key: (law, np.array(rows)) for key, (law, rows) in self.law_groups.items()}
        self.any_static = bool(self.law_groups)

    # --------------------------------------------------------------- the field
    def _attraction(self, t, px, py, vx, vy):
        """(fx, fy, goal_x, goal_y): the attraction and the unit vector towards the target (0 at it)."""
        if self.all_pull:
            return self.pull_x, self.pull_y, self.unit_x, self.unit_y
        i = self.va
        tt = t[i]
        ex, ey = (self.tx + self.tvx * tt) - px[i], (self.ty + self.tvy * tt) - py[i]
        dx, dy = self.tvx - vx[i], self.tvy - vy[i]
        r, rv = np.hypot(ex, ey), np.hypot(dx, dy)
        on, von = r > 0, rv > 0
        safe_r, safe_rv = np.where(on, r, 1.0), np.where(von, rv, 1.0)
        c = self.position_gain if self.m_is_2 else self.position_gain * safe_r ** (self.m - 2.0)  # r⁰ = 1 exactly
        cv = self.velocity_gain if self.n_is_2 else self.velocity_gain * safe_rv ** (self.n - 2.0)
        ax = np.where(on, 0.0 + c * ex, 0.0)
        ay = np.where(on, 0.0 + c * ey, 0.0)
        ax, ay = np.where(von, ax + cv * dx, ax), np.where(von, ay + cv * dy, ay)
        gx, gy = np.where(on, ex / safe_r, 0.0), np.where(on, ey / safe_r, 0.0)
        if self.va.size == self.size:
            return ax, ay, gx, gy
        fx, fy, ux, uy = self.pull_x.copy(), self.pull_y.copy(), self.unit_x.copy(), self.unit_y.copy()
        fx[i], fy[i], ux[i], uy[i] = ax, ay, gx, gy
        return fx, fy, ux, uy

    def _geometry(self, t, px, py):
        """(clearance, away_x, away_y, R), (B, O): ρ_s, the unit vector obstacle → robot and the centre distance of every slot.

        R (m) is the distance to a point's or a ball's centre (+inf for a wall; None when the batch has only walls).
        """
        if self.moving:
            cx, cy = self.ox + self.ovx * t[:, None], self.oy + self.ovy * t[:, None]
        else:
            cx, cy = self.ox, self.oy
        rx, ry = px[:, None] - cx, py[:, None] - cy
        if self.any_wall:
            wall = rx * self.nx + ry * self.ny
        if not self.any_point:
            return np.where(self.valid, wall, math.inf), self.nx, self.ny, None
        R = np.hypot(rx, ry)
        inside = R > 0
        safe = np.where(inside, R, 1.0)
        ux, uy = np.where(inside, rx / safe, 1.0), np.where(inside, ry / safe, 0.0)
        clearance = R - self.radius
        if self.any_wall:
            clearance = np.where(self.is_wall, wall, clearance)
            ux, uy = np.where(self.is_wall, self.nx, ux), np.where(self.is_wall, self.ny, uy)
        return np.where(self.valid, clearance, math.inf), ux, uy, R

    def sense(self, t, px, py, vx, vy) -> Sensed:
        """The force and the per-obstacle quantities at one sample (times t, state p, v; arrays of shape (B,)).

        Parameters
        ----------
        t : ndarray, shape (B,)
            Each member's time, s.
        px, py : ndarray, shape (B,)
            Positions, m.
        vx, vy : ndarray, shape (B,)
            Velocities, m/s.
        """
        fx, fy, gx, gy = self._attraction(t, px, py, vx, vy)
        B, O = self.size, self.slots
        if O == 0:
            empty = np.zeros((B, 0))
            return Sensed(fx, fy, empty, empty, empty, empty.astype(bool), np.full(B, math.inf))
        clearance, ux, uy, R = self._geometry(t, px, py)
        nearest = np.min(clearance, axis=1)
        evaluated = self.repels[:, None] & self.valid & (clearance > 0)
        if self.any_nearest_only:
            evaluated &= ~self.nearest_only | (self.slot == np.argmin(clearance, axis=1)[:, None])
        collision = np.zeros((B, O), dtype=bool)
        if not self.any_gated:
            v_ro = D = np.full((B, O), math.nan)
        else:
            relx, rely = vx[:, None] - self.ovx, vy[:, None] - self.ovy
            v_ro = -(relx * ux + rely * uy)
            D = clearance - self.robot_radius - v_ro * v_ro / (2.0 * self.a_max)
            gate = evaluated & self.gated[:, None] & (v_ro > 0)
            collision = gate & (D <= 0)
            active = gate & (D > 0) & (D < self.rho0)
            if np.any(active):
                fx, fy = self._gated_force(fx, fy, active, D, v_ro, relx, rely, ux, uy, R)
            if not self.all_gated:
                v_ro = np.where(self.gated[:, None], v_ro, math.nan)
                D = np.where(self.gated[:, None], D, math.nan)
        if self.any_static:
            fx, fy = self._static_force(fx, fy, evaluated, clearance, ux, uy, gx, gy)
        return Sensed(fx, fy, clearance, v_ro, D, collision, nearest)

    def _gated_force(self, fx, fy, active, D, v_ro, relx, rely, ux, uy, R):
        """Add F_rep1 + F_rep2 of the active slots (`VelocityGatedRepulsion.evaluate`), one slot after the other."""
        D = np.where(active, D, 1.0)
        if self.variants == {0}:
            M = self.eta / D**2
        else:
            u = (1.0 / D - 1.0 / self.rho0) ** 2
            M = np.where(self.variant == 0, self.eta / D**2, np.where(self.variant == 1, self.eta * u, self.eta_cubed * u))
        n_x, n_y = -ux, -uy  # n_RO: robot → obstacle
        radial = -M * (1.0 + v_ro / self.a_max)
        px, py = radial * n_x, radial * n_y
        if self.any_point:
            tangential = M * v_ro / (self.a_max * np.where(self.is_wall | ~active, 1.0, R))
            px = np.where(self.is_wall, px, px + tangential * (relx - v_ro * n_x))
            py = np.where(self.is_wall, py, py + tangential * (rely - v_ro * n_y))
        for j in range(self.slots):
            on = active[:, j]
            fx, fy = np.where(on, fx + px[:, j], fx), np.where(on, fy + py[:, j], fy)
        return fx, fy

    def _static_force(self, fx, fy, evaluated, clearance, ux, uy, gx, gy):
        """Add scale·(P(ρ)·away + Q(ρ)·towards the target) of the evaluated slots, one slot after the other."""
        B, O = self.size, self.slots
        P, Q = np.zeros((B, O)), np.zeros((B, O))
        safe = np.where(evaluated, clearance, 1.0)
        for law, rows in self.law_groups.values():
            P[rows] = law.force(safe[rows])
            Q[rows] = law.goal_force(safe[rows])
        on = evaluated & ((P != 0) | (Q != 0))
        sx = self.scale * (P * ux + Q * gx[:, None])
        sy = self.scale * (P * uy + Q * gy[:, None])
        for j in range(O):
            fx, fy = np.where(on[:, j], fx + sx[:, j], fx), np.where(on[:, j], fy + sy[:, j], fy)
        return fx, fy
