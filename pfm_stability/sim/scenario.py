"""What one simulated run is: robot, controller, environment, start, target, measurement.

A `Scenario` is one member of a batch. Every field is validated on
construction and an impossible run raises :class:`ValueError` with one line
naming the parameter (T <= 0, an even window, a robot that does not fit the
window, a start pose touching an obstacle, a target inside an obstacle, …).
Presets (``kb-fig3``, ``corridor``, …) live in `pfm_stability.sim.presets`.

`scenario_law` is the one place that decides which lateral force law a
straight wall of the simulated environment exerts (the grid's `GridWallLaw`,
KB's power law, or a given law): `Scenario.effective_law`, the presets, the
validation and the command line all ask it (docs/simulator.md, grid
quantization and the effective force law).

Directions are radians from +Y towards +X (docs/theory.md, notation: X
lateral, Y along the corridor), so heading θ moves the robot by
(V sin θ, V cos θ).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_choice, check_number
from ..laws.effective_force import DEFAULT_CV, GridWallLaw, calibrate_cell_ratio, check_window_cells, working_range
from ..laws.force_law import ForceLaw, law_in_force
from ..parameters import TAU_RESOLUTION, Controller, Robot, check_parameter
from .environment import AnalyticEnvironment
from .grid import HistogramGrid
from .robot import delay_split

__all__ = ["Pose", "Target", "MeasureAxis", "Scenario", "MAX_SAMPLES", "LAW_NAMES", "scenario_law"]

LAW_NAMES = ("power", "grid")
"""Lateral laws of analytic walls by name: KB's lumped power law, or the grid's effective law (`scenario_law`)."""

MAX_SAMPLES = 5e7
"""Most samples one run may take (the recorder keeps two float arrays of this length: 800 MB)."""


def scenario_law(
    env: str,
    robot: Robot,
    controller: Controller,
    window_cells: int = 33,
    cell_size: float = 0.1,
    *,
    law: ForceLaw | str | None = None,
    cell_ratio: float | None = None,
    cv: float = DEFAULT_CV,
) -> ForceLaw:
    """The lateral force law a straight wall of the simulated environment exerts.

    ``env="grid"``: the grid's `GridWallLaw` (KB eq 1–2 summed over a wall of
    cells and averaged along it; exact for walls along the grid axes) with
    cell ratio ρ = `cell_ratio`, or, when not given, the ρ whose f_av equals
    the controller's f over the window's working range (KB §4,
    `calibrate_cell_ratio`). ``env="analytic"``: `law` — a `ForceLaw`, or by
    name ``"grid"`` (that same `GridWallLaw` without its quantization) or
    ``"power"`` — or, when not given, KB's power law f(W/d)^n (eq 8, 13).
    `make_scenario`, the validation (`validate_boundary`, `verdict_sweep`) and
    the command line (a configuration file's ``law``) all ask this function.

    Parameters
    ----------
    env : {"grid", "analytic"}
    robot, controller : Robot, Controller
        W; f and n.
    window_cells, cell_size
        Grid window side (odd) and cell size (m).
    law : ForceLaw or {"power", "grid"}, optional
        Analytic walls' law (a grid's law is its cells: not allowed with ``env="grid"``).
    cell_ratio : float, optional
        ρ = F_cr/F_ct of the grid, or of the analytic ``law="grid"``.
    cv : float
        The wall cells' certainty value.

    Raises
    ------
    ValueError
        A law with ``env="grid"``, an unknown law name, or a cell ratio the law does not take.
    """
    if env == "grid":
        if law is not None:
            raise ValueError("law applies to env=analytic only; the grid's law is its cells")
        ratio = cell_ratio if cell_ratio is not None else calibrate_cell_ratio(controller.f, controller.n, robot.W, cell_size, window_cells, cv)
        return GridWallLaw(ratio, controller.n, robot.W, cell_size, window_cells, cv)
    if isinstance(law, str):
        check_choice("law", law, LAW_NAMES)
        if law == "grid":
            return scenario_law("grid", robot, controller, window_cells, cell_size, cell_ratio=cell_ratio, cv=cv)
        law = None
    if cell_ratio is not None:
        raise ValueError("cell_ratio applies to env=grid, or to env=analytic with law=grid")
    return law_in_force(robot, controller, law)


@dataclass(frozen=True)
class Pose:
    """Position (m) and heading θ (rad, from +Y towards +X).

    Attributes
    ----------
    x, y : float
        Position, m.
    theta : float
        Heading θ, rad from +Y towards +X.
    """

    x: float
    y: float
    theta: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "x", check_number("start x", self.x, unit="m"))
        object.__setattr__(self, "y", check_number("start y", self.y, unit="m"))
        object.__setattr__(self, "theta", check_number("start heading", self.theta, unit="rad"))


@dataclass(frozen=True)
class Target:
    """A point target, a direction "at infinity" (KB eq 3; docs/simulator.md), or a path to follow.

    Use `Target.point`, `Target.direction` or `Target.follow`. A direction keeps
    α constant along a wall, as KB's analysis assumes (α̇ ≈ 0). A path pulls the
    robot towards a point `lookahead` m ahead of it along the path (a pure-pursuit
    carrot, `sim.follow`); it is reached at its last point, (x, y).

    Attributes
    ----------
    x, y : float or None
        Point target, m.
    angle : float or None
        Direction target, rad from +Y towards +X.
    radius : float
        Point target: reached when the robot centre is this close, m.
    finish : float or None
        Direction target: reached when the robot has advanced this far along
        the direction from its start, m (None: never).
    path : tuple of (float, float) or None
        Path target: its vertices, m (the last one is (x, y)).
    lookahead : float
        Path target: how far ahead along the path the robot is pulled, m.
    """

    x: float | None = None
    y: float | None = None
    angle: float | None = None
    radius: float = 0.2
    finish: float | None = None
    path: tuple | None = None
    lookahead: float = 0.0

    @classmethod
    def point(cls, x: float, y: float, radius: float = 0.2) -> "Target":
        """A target at (x, y), m, reached within `radius` m.

        Parameters
        ----------
        x, y : float
            Position, m.
        radius : float
            Reached within this distance, m.
        """
        return cls(
            x=check_number("target x", x, unit="m"),
            y=check_number("target y", y, unit="m"),
            radius=check_number("target radius", radius, 0.0, unit="m"),
        )

    @classmethod
    def direction(cls, angle: float, finish: float | None = None) -> "Target":
        """A target at infinity in direction `angle` (rad from +Y towards +X).

        Parameters
        ----------
        angle : float
            Direction, rad from +Y towards +X.
        finish : float, optional
            Reached when the robot has advanced this far along the direction from its start, m (None: never).
        """
        finish = None if finish is None else check_number("finish", finish, 0.0, unit="m")
        return cls(angle=check_number("target angle", angle, unit="rad"), finish=finish)

    @classmethod
    def follow(cls, points, lookahead: float, radius: float = 0.2) -> "Target":
        """A path to follow: the robot is pulled towards the point `lookahead` m ahead of it along the polyline
        `points` (`sim.follow`), and reaches the target within `radius` m of its last point.

        Parameters
        ----------
        points : array_like, shape (n, 2)
            Vertices, m (n >= 2; repeated points are dropped).
        lookahead : float
            How far ahead along the path the robot is pulled, m (> 0).
        radius : float
            Reached within this distance of the last point, m.
        """
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
            raise ValueError(f"path must be finite (x, y) points in m; got an array of shape {pts.shape}")
        keep = np.concatenate([[True], np.hypot(*np.diff(pts, axis=0).T) > 0]) if len(pts) else np.zeros(0, bool)
        pts = pts[keep]
        if len(pts) < 2:
            raise ValueError(f"path must hold at least two distinct points; got {len(pts)}")
        lookahead = check_number("lookahead", lookahead, 0.0, unit="m")
        return cls(x=float(pts[-1, 0]), y=float(pts[-1, 1]), radius=check_number("target radius", radius, 0.0, unit="m"),
                   path=tuple(map(tuple, pts.tolist())), lookahead=lookahead)

    @property
    def is_point(self) -> bool:
        return self.angle is None

    @property
    def is_path(self) -> bool:
        return self.path is not None

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        if self.is_path:
            return {"kind": "path", "points": [list(p) for p in self.path], "lookahead": self.lookahead, "radius": self.radius}
        if self.is_point:
            return {"kind": "point", "x": self.x, "y": self.y, "radius": self.radius}
        return {"kind": "direction", "angle_deg": math.degrees(self.angle), "finish": self.finish}


@dataclass(frozen=True)
class MeasureAxis:
    """Where and along which line the oscillation metrics are measured (docs/simulator.md, measuring oscillation).

    The lateral offset is the coordinate of the robot centre to the right of
    the line through `origin` in direction `angle`; samples count once the
    robot has advanced `along_from` m along it (e.g. past a disturbance).

    Attributes
    ----------
    origin : (float, float)
        m.
    angle : float
        Direction of travel along the line, rad from +Y towards +X.
    along_from : float
        m.
    """

    origin: tuple = (0.0, 0.0)
    angle: float = 0.0
    along_from: float = -math.inf

    @property
    def along_unit(self) -> tuple[float, float]:
        return (math.sin(self.angle), math.cos(self.angle))

    @property
    def lateral_unit(self) -> tuple[float, float]:
        return (math.cos(self.angle), -math.sin(self.angle))

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "origin": list(self.origin),
            "angle_deg": math.degrees(self.angle),
            "along_from": None if math.isinf(self.along_from) else self.along_from,
        }


def check_first_order(robot) -> None:
    """ValueError unless the robot's drive is first order (`Robot.actuator_lag` = 0) and it moves where it points
    (`Robot.slip_lag` = 0: its kinematics are ẋ = V·sin θ, KB's): the simulator's solution between
    samples is the exact one of τω̇ + ω = g·u (`sim.robot`); a second lag is the loop models' (docs/models.md), and the
    MuJoCo robots carry one of their own (docs/mujoco.md). Asked where the simulator steps a robot (`sim.engine.run_batch`,
    `sim.reference.simulate_reference`, `sim.tracking.simulate_tracking`), not of a scenario MuJoCo runs.

    Parameters
    ----------
    robot : Robot
    """
    if robot.actuator_lag > 0:
        raise ValueError(f"actuator_lag must be 0 for the simulator (its drive is the first-order lag tau, solved exactly between "
                         f"samples; the loop models take a second lag: docs/simulator.md); got {robot.actuator_lag}")
    if robot.slip_lag > 0:
        raise ValueError(f"slip_lag must be 0 for the simulator (its robot moves where it points; the loop models take a course "
                         f"that lags the heading, and MuJoCo's skid-steer slides: docs/simulator.md); got {robot.slip_lag}")


@dataclass(frozen=True)
class Scenario:
    """One simulated run.

    Parameters
    ----------
    name : str
    robot : Robot
        V, τ, k, W, max steering rate (KB eq 5–6; §4), plant gain g and dead
        time D (the motor τω̇ + ω = g·u(t − D); D > 0 only with a held command:
        docs/simulator.md, "Plant gain and dead time").
    controller : Controller
        f, n, T, hold, compute_delay (T must be > 0: the simulator samples).
        In the grid, f is KB's f_av used to calibrate `cell_ratio` when that
        is not given.
    environment : HistogramGrid or AnalyticEnvironment
    start : Pose
    target : Target
    duration : float
        Simulated time, s.
    cell_ratio : float, optional
        Grid: ρ = F_cr/F_ct; default `calibrate_cell_ratio(controller.f, …)`.
    law : ForceLaw, optional
        Analytic: the walls' lateral law; default KB's `PowerLaw(f, n, W)`.
    window_cells : int
        Grid: active window side w_s (odd, >= 3; KB: 33).
    measure : MeasureAxis
    speed_law : bool
        Use the VFF speed law V = V(1 − |cos φ|) instead of constant speed.
    trap_time, trap_distance : float
        Trapped: less than `trap_distance` m of progress towards the target
        within `trap_time` s.
    analysis : dict or None
        The linear analysis that applies inside the measurement window:
        ``{"kind": "corridor", "L": m}`` or ``{"kind": "wall", "alpha": rad}``
        (used by `pfm_stability.validation.predict`); None when none applies.
    seed : int or None
        Seed of the random start jitter (with `start_jitter`).
    start_jitter : float
        Standard deviation of a random lateral start offset, m (0: none).
    damping : float
        A velocity-dependent force −β·v added to the sensed field, β in
        F_ct per m/s (0: none). On a straight path at speed V it gives the
        heading gain c = βV/F_y of the loop (docs/fields.md, "heading gain").
    notes : dict
        Documented choices (geometry, calibration), reported with the inputs.
    """

    name: str
    robot: Robot
    controller: Controller
    environment: object
    start: Pose
    target: Target
    duration: float
    cell_ratio: float | None = None
    law: ForceLaw | None = None
    window_cells: int = 33
    measure: MeasureAxis = field(default_factory=MeasureAxis)
    speed_law: bool = False
    trap_time: float = 10.0
    trap_distance: float = 0.5
    analysis: dict | None = None
    seed: int | None = None
    start_jitter: float = 0.0
    damping: float = 0.0
    notes: dict = field(default_factory=dict)

    def __post_init__(self):
        check_parameter("T_sampled", self.controller.T)
        if self.robot.dead_time > 0 and self.controller.hold == "reference":
            raise ValueError(f"dead_time must be 0 with hold=reference (a dead time inside the continuous steering servo is a delay "
                             f"differential equation, which the simulator does not solve; docs/simulator.md); got {self.robot.dead_time}")
        if math.isfinite(self.robot.yaw_accel_limit) and self.controller.hold == "reference":
            raise ValueError(f"yaw_accel_limit needs hold=command (the velocity smoother limits a sequence of held yaw-rate commands; "
                             f"a servo closing k(δ − θ) continuously has none; docs/simulator.md); got {self.robot.yaw_accel_limit} rad/s^2")
        object.__setattr__(self, "duration", check_number("duration", self.duration, 0.0, 1e6, unit="s"))
        samples = self.duration / self.controller.T
        if samples > MAX_SAMPLES:
            raise ValueError(
                f"duration must be at most {MAX_SAMPLES:g} sampling periods ({MAX_SAMPLES * self.controller.T:g} s at "
                f"T = {self.controller.T:g} s); got {self.duration!r} s ({samples:.3g} periods)"
            )
        object.__setattr__(self, "trap_time", check_number("trap_time", self.trap_time, 0.0, unit="s"))
        object.__setattr__(self, "trap_distance", check_number("trap_distance", self.trap_distance, 0.0, unit="m"))
        object.__setattr__(self, "start_jitter", check_number("start_jitter", self.start_jitter, 0.0, low_open=False, unit="m"))
        if self.seed is not None and (isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0):
            raise ValueError(f"seed must be a non-negative integer; got {self.seed!r}")
        if isinstance(self.environment, HistogramGrid):
            object.__setattr__(self, "window_cells", check_window_cells(self.window_cells))
            working_range(self.robot.W, self.environment.cell_size, self.window_cells)
            if self.cell_ratio is None:
                object.__setattr__(self, "cell_ratio", self.calibrated_ratio())
            object.__setattr__(self, "cell_ratio", check_number("cell_ratio", self.cell_ratio, 0.0))
            if self.law is not None:
                raise ValueError("law applies to env=analytic only; the grid's law is its cells")
        elif isinstance(self.environment, AnalyticEnvironment):
            if self.cell_ratio is not None:
                raise ValueError("cell_ratio applies to env=grid only")
        else:
            raise ValueError(f"environment must be a HistogramGrid or an AnalyticEnvironment; got {type(self.environment).__name__}")
        self._check_start_and_target()

    # -------------------------------------------------------------- derived
    @property
    def env(self) -> str:
        """"grid" or "analytic"."""
        return "grid" if isinstance(self.environment, HistogramGrid) else "analytic"

    def loop_order(self) -> int:
        """State dimension of the sampled loop this run follows: the linear-prediction order of its metrics (`sim.metrics`).

        (τ > 0) + 2 + m + (ε > 0): lateral offset, heading and (with a lag) the
        steering rate, and the delay line's m + (ε > 0) commands, where a
        command reaches the motor m·T + ε after its data (`robot.delay_split`:
        d·T + D). τ counts as 0 when τ·g·k is below `parameters.TAU_RESOLUTION`,
        as the engine and the models take it.
        """
        r, c = self.robot, self.controller
        m, eps = delay_split(np.array([c.T]), np.array([c.compute_delay]), np.array([r.dead_time]))
        return int(r.tau * r.plant_gain * r.k >= TAU_RESOLUTION) + 2 + int(m[0]) + int(eps[0] > 0)

    def calibrated_ratio(self) -> float:
        """ρ giving the grid's f_av = controller.f over the working range (KB §4; `scenario_law`)."""
        g = self.environment
        return scenario_law("grid", self.robot, self.controller, self.window_cells, g.cell_size, cv=g.cv_max).ratio

    def effective_law(self) -> ForceLaw:
        """The lateral law the analysis should use for this run (`scenario_law`).

        Grid: `GridWallLaw` of a straight wall with this run's ρ, n, W, cells
        and window (exact for straight walls along the grid axes). Analytic:
        `law`, or KB's power law.
        """
        if self.env == "grid":
            g = self.environment
            return scenario_law("grid", self.robot, self.controller, self.window_cells, g.cell_size, cell_ratio=self.cell_ratio, cv=g.cv_max)
        return scenario_law("analytic", self.robot, self.controller, law=self.law)

    def clearance(self, x, y) -> np.ndarray:
        """Distance from robot centres to the nearest obstacle, m (minus W/2: < 0 = collision).

        Parameters
        ----------
        x, y : array_like
            Robot centres, m.
        """
        return self.environment.clearance(x, y) - self.robot.W / 2

    def _check_start_and_target(self) -> None:
        gap = float(self.clearance([self.start.x], [self.start.y])[0])
        if not gap > 0:
            raise ValueError(
                f"start must leave the robot (W = {self.robot.W:g} m) clear of obstacles; "
                f"it overlaps them by {-gap:.3g} m at ({self.start.x:g}, {self.start.y:g}) m"
            )
        t = self.target
        if t.is_point:
            inside = self.clearance([t.x], [t.y])[0] + self.robot.W / 2 <= 0
            if self.env == "grid":
                inside = inside or bool(self.environment.occupied_at([t.x], [t.y])[0])
            else:
                inside = inside or _behind_a_wall(self.environment, t.x, t.y)
            if inside:
                raise ValueError(f"target must not lie inside an obstacle; got ({t.x:g}, {t.y:g}) m")

    def inputs(self) -> dict:
        """Everything that defines the run, for reports (SI units, angles in degrees)."""
        r, c = self.robot, self.controller
        out = {
            "scenario": self.name,
            "env": self.env,
            "V": r.V,
            "tau": r.tau,
            "k": r.k,
            "W": r.W,
            "max_steering_rate_deg": math.degrees(r.max_steering_rate),
            "dead_time": r.dead_time,
            "plant_gain": r.plant_gain,
            "f": c.f,
            "n": c.n,
            "T": c.T,
            "hold": c.hold,
            "compute_delay": c.compute_delay,
            "duration": self.duration,
            "start": {"x": self.start.x, "y": self.start.y, "heading_deg": math.degrees(self.start.theta)},
            "target": self.target.to_dict(),
            "speed_law": self.speed_law,
            "measure": self.measure.to_dict(),
            "seed": self.seed,
            "start_jitter": self.start_jitter,
            "damping": self.damping,
        }
        if self.env == "grid":
            g = self.environment
            out.update(cell_ratio=self.cell_ratio, cell_size=g.cell_size, window_cells=self.window_cells, cv=g.cv_max)
        else:
            out["law"] = self.effective_law().name
        out["notes"] = dict(self.notes)
        return out


def _behind_a_wall(env: AnalyticEnvironment, x: float, y: float) -> bool:
    """True if (x, y) lies on the blocked side of a wall, within its extent."""
    from .environment import wall_coordinates

    walls = env.arrays()
    s, d = wall_coordinates(walls, x, y)
    return bool(np.any((s >= 0) & (s <= walls["length"]) & (d < 0)))
