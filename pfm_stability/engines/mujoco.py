"""The project's VFF controller on a MuJoCo robot: MuJoCo's dynamics and sensing, the package's controller (docs/mujoco.md).

Every sampling period T (`run_scenario`):

1. **Sense.** `rays` horizontal rays from the robot's ``lidar`` site (`mujoco.mj_multiRay`, seeing the walls'
   geom group only, up to `sensor_range`) give hit points; each adds 1 to the certainty value of its
   cell of the robot's own histogram grid (`pfm_stability.sim.grid.HistogramGrid.add_readings`, KB §2),
   which starts empty and has the geometry of the scenario's drawn grid.
2. **Force and command.** The occupied cells of the active window around the robot's cell push it
   (`pfm_stability.sim.vff.cell_repulsion`, KB eq 1–2, with the scenario's cell ratio); the target
   pulls (eq 3); δ is the resultant's direction (eq 4) and u = sat(k·wrap(δ − θ)) (eq 5,
   `pfm_stability.sim.vff.steering_command`).
3. **Hold and delays.** u is held over the period (zero-order hold); with ``compute_delay = 1`` the
   value applied over [t_k, t_k+1) is the one computed at t_k−1; a dead time `command_delay` more
   passes before the wheels receive it (the command path's latency; rounded to the engine's timestep).
4. **Drive.** The turning rate becomes wheel speeds, (V ∓ ψ̇·b/2)/r with ψ̇ = −u (`robots.wheel_speeds`),
   set as the ``left`` and ``right`` velocity actuators' targets; MuJoCo steps the robot (wheel
   servos with their torque limits, tyre and caster contacts, the chassis' inertia).

The engine's timestep is the file's (at most 2 ms), shortened so that T is a whole number of steps
(docs/mujoco.md, "Timestep"). The run is recorded like the package's simulator: the lateral offset at
the sample instants along the scenario's measurement axis, measured by
`pfm_stability.sim.metrics.oscillation_metrics`, the project's one estimator; a contact between the
robot and a wall is a collision and ends the run, and so does a tilt beyond 45° (the robot falls);
a state MuJoCo cannot integrate (non-finite) is a one-line `ValueError`. The result is a `pfm_stability.sim.results.RunResult`,
so the validation's bisection (`pfm_stability.validation`) treats MuJoCo's runs as its own
(`MujocoRuns`).

`drive_log` drives the robot open loop with a step or chirp yaw-rate command and records what a robot's
log holds (the command, the wheel odometry's yaw rate, the gyro's, and the base's true pose, as a motion-capture system
would see it), for ``pfm-stability identify``;
`write_csv_log` writes it as a CSV log (docs/diagnose.md, "Logs").
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..sim.events import Event
from ..sim.grid import HistogramGrid
from ..sim.metrics import oscillation_metrics
from ..sim.results import BatchResult, RunResult, Trajectory
from ..sim.vff import cell_repulsion, direction_of, steering_command, wrap_angle
from ..controllers.registry import NAV2_CONTROLLERS as CONTROLLER_NAMES
from .command_path import CommandPath, Timing, VelocitySmoother
from .robots import WALL_GROUP, check_drives, corridor_world, heading, load_robot_model, place

__all__ = ["EngineOptions", "run_scenario", "run_scenarios", "MujocoRuns", "DriveLog", "drive_log", "write_csv_log",
           "SENSING", "PROFILES", "engine_timestep",
           "CorridorLog", "corridor_log"]

SENSING = ("rays", "drawn")
"""Where the controller's grid comes from: MuJoCo's ray casts (default) or the scenario's drawn grid (an ablation:
perfect sensing)."""

PROFILES = ("steps", "chirp", "both")
"""Open-loop yaw-rate commands of `drive_log`: random steps, a chirp, or steps then a chirp (half the time each)."""


@dataclass(frozen=True)
class EngineOptions:
    """How MuJoCo runs the robot (docs/mujoco.md).

    Attributes
    ----------
    robot_model : str
        A shipped robot's name (``diffdrive``, ``diffdrive-heavy``) or an MJCF file.
    command_delay : float
        Dead time on the command path, s, in [0, 1] (rounded to the engine's timestep).
    rays : int
        Rays per scan, in [8, 10000], evenly spread over 360°.
    sensor_range : float
        The rays' reach, m, in (0, 100].
    sensing : {"rays", "drawn"}
        The controller's grid: filled by the rays, or the scenario's drawn grid (perfect sensing).
    caster_friction : float, optional
        Replaces the casters' sliding friction (0: no caster drag); None keeps the file's.
    torque_limit : float, optional
        Replaces the wheel motors' torque limit, N m (inf: no rate limit); None keeps the file's.
    controller : str
        What computes the command: ``vff`` (the project's VFF controller) or a Nav2 controller of
        `pfm_stability.controllers` (``rpp``, ``graceful``, ``mppi``, ``dwb``; `_Nav2Driver`).
    controller_params : dataclass, optional
        The Nav2 controller's parameters (default Nav2's); its speed and period are set from the scenario's V and T.
    smoother : VelocitySmoother, optional
        Nav2's velocity smoother between the controller and the base (`engines.command_path`); None: none.
    timing : Timing
        The controller's period jitter and the odometry's rate and jitter (`engines.command_path.Timing`).
    """

    robot_model: str = "diffdrive"
    command_delay: float = 0.0
    rays: int = 720
    sensor_range: float = 6.0
    sensing: str = "rays"
    caster_friction: float | None = None
    torque_limit: float | None = None
    controller: str = "vff"
    controller_params: object = None
    smoother: VelocitySmoother | None = None
    timing: Timing = Timing()

    def __post_init__(self):
        object.__setattr__(self, "command_delay", check_number("command_delay", self.command_delay, 0.0, 1.0, low_open=False, unit="s"))
        object.__setattr__(self, "rays", check_integer("rays", self.rays, 8, 10_000))
        object.__setattr__(self, "sensor_range", check_number("sensor_range", self.sensor_range, 0.0, 100.0, unit="m"))
        check_choice("sensing", self.sensing, SENSING)
        if self.caster_friction is not None:
            object.__setattr__(self, "caster_friction", check_number("caster_friction", self.caster_friction, 0.0, 10.0, low_open=False))
        if self.torque_limit is not None:
            object.__setattr__(self, "torque_limit", (math.inf if self.torque_limit == math.inf else check_number("torque_limit", self.torque_limit, 0.0, 1e6, unit="N m")))
        check_choice("controller", self.controller, ("vff",) + CONTROLLER_NAMES)


_UPRIGHT = math.cos(math.radians(45.0))
"""A run ends as a collision when the base tilts by more than 45° (the robot falls onto the floor)."""


def engine_timestep(file_timestep: float, T: float) -> float:
    """The engine's timestep, s: the file's, shortened so that T is a whole number of steps.

    Parameters
    ----------
    file_timestep : float
        The robot file's timestep, s.
    T : float
        The controller's period, s.
    """
    return T / math.ceil(T / file_timestep - 1e-9)


def _check_scenario(scenario) -> None:
    if scenario.target.is_point or scenario.env != "grid":
        raise ValueError(f"the MuJoCo engine runs the corridor scenario in the grid (a target at infinity); got {scenario.name!r} ({scenario.env})")
    if scenario.controller.hold != "command":
        raise ValueError("the MuJoCo engine holds the turning-rate command between samples (hold=command); got hold=reference")
    if scenario.speed_law or scenario.damping:
        raise ValueError("the MuJoCo engine drives at constant speed without damping (no speed law, damping 0)")
    if not scenario.analysis or scenario.analysis.get("kind") != "corridor":
        raise ValueError(f"the MuJoCo engine runs the corridor scenario only; got {scenario.name!r}")


def _window_force(grid: HistogramGrid, x: float, y: float, h: int, scale: float, n: float):
    """The repulsion (F_ct) of the occupied cells of the (2h+1)² window around the robot's cell (KB eq 1–2)."""
    i, j = (int(v) for v in grid.cell_index(x, y))
    nx, ny = grid.shape
    i0, i1, j0, j1 = max(i - h, 0), min(i + h + 1, nx), max(j - h, 0), min(j + h + 1, ny)
    if i0 >= i1 or j0 >= j1:
        return 0.0, 0.0
    block = grid.cv[i0:i1, j0:j1]
    ii, jj = np.nonzero(block)
    if ii.size == 0:
        return 0.0, 0.0
    cx, cy = grid.cell_center(ii + i0, jj + j0)
    fx, fy = cell_repulsion(np.array([[x]]), np.array([[y]]), cx[None, :], cy[None, :], block[ii, jj][None, :].astype(float), n)
    return scale * float(fx[0]), scale * float(fy[0])


class _Nav2Driver:
    """A Nav2 controller in the engine's loop: the corridor's plan and costmap, its memory, and the MuJoCo robot's state.

    The controller sees the scenario's frame mirrored as `pfm_stability.sim.tracking` shows it (X along the corridor,
    Y lateral, yaw = θ), a straight plan along the corridor's centre line with a pose every costmap cell, and the
    corridor's costmap with its walls where the scenario draws them (Nav2's local costmap built from the walls, not
    from the robot's scans); it measures the base's forward speed and yaw rate (wheel odometry without noise).
    Controllers with memory are warmed up on the centre line first (`controllers.linearize.warm_up`).
    """

    def __init__(self, options: EngineOptions, scenario, L: float):
        from ..controllers.costmap import CorridorCostmap
        from ..controllers.linearize import configure
        from ..controllers.base import controller_module, default_params
        from ..controllers.plan import straight_plan
        from ..controllers.linearize import warm_up

        r, c = scenario.robot, scenario.controller
        self.name = options.controller
        self.module = controller_module(self.name)
        params = options.controller_params if options.controller_params is not None else default_params(self.name)
        self.params = configure(self.name, params, V=r.V, T=c.T)
        self.costmap = CorridorCostmap(half_width=L, resolution=0.05)
        self.centre = float(scenario.measure.origin[0])
        plan = straight_plan(3.0 + 1.5 * r.V * scenario.duration + 12.0, self.costmap.resolution, x0=scenario.start.y - 1.0)
        self.rng = np.random.default_rng(scenario.seed or 0)
        self.memory, self.plan, _, _ = warm_up(self.name, self.params, plan, self.costmap, x=scenario.start.y, T=c.T, rng=self.rng)
        self.max_rate = r.max_steering_rate

    def decide(self, data, dof: int, x: float, y: float, theta: float):
        """(forward speed m/s, steering rate θ̇ rad/s) commanded at the robot's pose (`sim.tracking.command_path`'s saturation).

        Parameters
        ----------
        data : mujoco.MjData
            The engine's state.
        dof : int
            The base's free joint's first velocity address.
        x, y : float
            The base's position, m.
        theta : float
            Its heading, rad (from +Y towards +X).
        """
        from ..controllers.base import NoValidControl, RobotState
        from ..controllers.plan import prune

        vx, vy = float(data.qvel[dof]), float(data.qvel[dof + 1])  # world frame; the angular part is the body's: z is up
        state = RobotState(y, x - self.centre, theta, vx * math.sin(theta) + vy * math.cos(theta), -float(data.qvel[dof + 5]))
        self.plan = prune(self.plan, state, self.costmap.window(state.x, state.y))
        try:
            cmd = self.module.command(state, self.plan, self.costmap, self.params, rng=self.rng, memory=self.memory)
        except (NoValidControl, ValueError):
            return 0.0, 0.0
        self.memory = cmd.memory
        return cmd.v, min(max(cmd.w, -self.max_rate), self.max_rate)


def run_scenario(scenario, options: EngineOptions = EngineOptions(), *, record: str = "offset", metrics: bool = True) -> RunResult:
    """One corridor run of the package's VFF controller on the MuJoCo robot (module docstring).

    Parameters
    ----------
    scenario : Scenario
        A ``corridor`` scenario in the grid (`pfm_stability.sim.presets.make_scenario`): robot (V, k, W,
        steering-rate limit), controller (f → cell ratio, n, T, compute delay), the corridor's walls, the
        start, the measurement axis and the duration. The robot's τ, plant gain and dead time are not
        used: the plant is MuJoCo's (they are what the predictions assume of it).
    options : EngineOptions
        The robot file and the engine's settings.
    record : {"offset", "trajectory"}
        Keep the lateral offset only, or every sample's pose too.
    metrics : bool
        Measure the oscillation (`oscillation_metrics`).

    Returns
    -------
    RunResult
        Events (a wall contact is a ``collision``), metrics, the offset in the measurement window.

    Raises
    ------
    ValueError
        A scenario the engine does not run (module docstring), a robot file that cannot be read or cannot drive.
    """
    return _run(scenario, options, record, metrics, None)


def _run(scenario, options: EngineOptions, record: str, metrics: bool, recorder) -> RunResult:
    """`run_scenario`'s loop; `recorder` (a `_Recorder` or None) logs the run as a robot would."""
    import mujoco

    _check_scenario(scenario)
    robot = load_robot_model(options.robot_model)
    check_drives(robot.path)
    r, c = scenario.robot, scenario.controller
    grid0 = scenario.environment
    L = float(scenario.analysis["L"])
    x_lo, x_hi, y_lo, y_hi = grid0.extent
    model = corridor_world(robot.path, L, y_lo, y_hi, options.caster_friction, options.torque_limit)
    data = mujoco.MjData(model)
    dt = engine_timestep(robot.timestep, c.T)
    model.opt.timestep = dt
    delay_steps = int(round(options.command_delay / dt))
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    lidar = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "lidar")
    left, right = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, s) for s in ("left", "right"))
    walls = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"wall_{s}") for s in ("left", "right")}
    q = model.jnt_qposadr[model.body_jntadr[base]]

    scale = scenario.cell_ratio * r.W ** c.n
    h = scenario.window_cells // 2
    ax, ay = math.sin(scenario.target.angle), math.cos(scenario.target.angle)
    if options.sensing == "drawn":
        grid = grid0
    else:
        grid = grid0.copy()
        grid.cv[:] = 0
    angles = 2 * math.pi * np.arange(options.rays) / options.rays
    group = np.zeros(6, dtype=np.uint8)
    group[WALL_GROUP] = 1
    geomid = np.zeros(options.rays, dtype=np.int32)
    dist = np.zeros(options.rays)

    place(model, data, robot, scenario.start.x, scenario.start.y, scenario.start.theta, r.V)
    driver = _Nav2Driver(options, scenario, L) if options.controller != "vff" else None
    speed = r.V
    if recorder is not None:
        recorder.start(model, data, dt, base, lidar, group)
    steps = int(math.ceil(scenario.duration / c.T - 1e-9))
    lat, along = scenario.measure.lateral_unit, scenario.measure.along_unit
    ox_, oy_ = scenario.measure.origin
    off = np.zeros(steps + 1)
    alg = np.zeros(steps + 1)
    pose = np.zeros((steps + 1, 3)) if record == "trajectory" else None
    theta = scenario.start.theta
    pending = path = None
    ticks = options.timing.controller_ticks(c.T, dt)  # the controller's ticks (engine steps), jittered or not
    now = next(ticks)
    tick_t = np.zeros(steps + 1)
    dof = model.jnt_dofadr[model.body_jntadr[base]]
    event = None
    done = steps
    for k in range(steps + 1):
        x, y = float(data.qpos[q]), float(data.qpos[q + 1])
        theta = theta + float(wrap_angle(heading(data.qpos[q + 3:q + 7]) - theta))  # unwrapped
        tick_t[k] = now * dt
        off[k] = (x - ox_) * lat[0] + (y - oy_) * lat[1]
        alg[k] = (x - ox_) * along[0] + (y - oy_) * along[1]
        if pose is not None:
            pose[k] = (x, y, theta)
        if event is not None:
            done = k
            break
        if k == steps:
            break
        # sense (KB eq 1–4) and compute the command (eq 5), or a Nav2 controller's
        if driver is not None:
            speed, u = driver.decide(data, int(dof), x, y, theta)
        elif options.sensing == "rays":
            yaw = math.pi / 2 - theta
            vec = np.column_stack([np.cos(yaw + angles), np.sin(yaw + angles), np.zeros(options.rays)])
            pnt = data.site_xpos[lidar].copy()
            mujoco.mj_multiRay(model, data, pnt, vec.ravel(), group, 1, base, geomid, dist, None, options.rays, options.sensor_range)
            hit = geomid >= 0
            if np.any(hit):
                grid.add_readings(pnt[0] + dist[hit] * vec[hit, 0], pnt[1] + dist[hit] * vec[hit, 1])
        if driver is None:
            fx, fy = _window_force(grid, x, y, h, scale, c.n)
            delta = float(direction_of(fx + ax, fy + ay))
            u = float(steering_command(delta, theta, r.k, r.max_steering_rate))
        if pending is None:  # the robot starts as if it had been running
            pending = u
            data.ctrl[left], data.ctrl[right] = robot.wheel_speeds(speed, u)
            path = CommandPath(dt, delay_steps, options.smoother, options.timing, initial=-u)
        applied = pending if c.compute_delay == 1 else u
        pending = u
        path.publish(now, -applied)  # ROS yaw rate = −θ̇
        if recorder is not None:
            recorder.command(now * dt, -applied, speed)  # published when applied to the command path
        # advance to the next tick, switching the wheels' targets when the command path delivers
        end = next(ticks)
        while now < end:
            reached = path.due(now, float(data.qvel[dof + 5]))
            if reached is not None:
                data.ctrl[left], data.ctrl[right] = robot.wheel_speeds(r.V, -reached)
            nxt = min(end, path.next_event(now))
            if recorder is not None:
                if recorder.due(now):
                    recorder.sample(now)
                nxt = min(nxt, recorder.next_step(now))
            mujoco.mj_step(model, data, nstep=nxt - now)
            now = nxt
            if data.ncon and any(int(g) in walls for pair in data.contact.geom[: data.ncon] for g in pair):
                event = Event("collision", float(data.time), float(data.qpos[q]), float(data.qpos[q + 1]))
                break
        if not np.all(np.isfinite(data.qpos)):
            raise ValueError(f"robot model {robot.name}: MuJoCo's state became non-finite at t = {data.time:.3f} s "
                             f"(V = {r.V:g} m/s, T = {c.T:g} s): beyond what this robot can drive")
        if event is None and data.xmat[base][8] < _UPRIGHT:  # on its side: it hit the floor
            event = Event("collision", float(data.time), float(data.qpos[q]), float(data.qpos[q + 1]))
        now = end
    n = done + 1
    t = np.arange(n) * c.T
    if options.timing.period_jitter > 0:  # the estimator wants uniform samples: the offset between ticks, interpolated
        t = t[t <= tick_t[n - 1]]
        off, alg = np.interp(t, tick_t[:n], off[:n]), np.interp(t, tick_t[:n], alg[:n])
        pose = None if pose is None else np.column_stack([np.interp(t, tick_t[:n], pose[:n, i]) for i in range(3)])
        n = t.size
    window = alg[:n] >= scenario.measure.along_from
    if np.any(window):
        window[np.argmax(window):] = True
    offset_t, offset = t[window], off[:n][window]
    order = (r.tau > 0) + 2 + c.compute_delay
    m = oscillation_metrics(offset_t, offset, c.T, order=int(order), collision_time=event.t if event else None) if metrics else None
    trajectory = Trajectory(t, pose[:n, 0].copy(), pose[:n, 1].copy(), pose[:n, 2].copy()) if pose is not None else None
    clearance = float(L - np.max(np.abs(off[:n] + scenario.measure.origin[0] * lat[0]))) - r.W / 2 if n else None
    return RunResult(scenario, (event,) if event else (), m, done * c.T, done, offset_t, offset.copy(), clearance, trajectory)


# ----------------------------------------------------------------------------------- closed-loop logs
@dataclass(frozen=True)
class CorridorLog:
    """A corridor run recorded as a robot's log (times in s from the start; world frame = odometry frame).

    Attributes
    ----------
    run : RunResult
        The run itself (`run_scenario`'s result).
    cmd_t, cmd_wz, cmd_vx : ndarray
        Every period's command, stamped when it is published (when it enters the command path), its yaw rate
        (rad/s, ROS sign: counter-clockwise positive) and forward speed (m/s).
    odom_t, odom_x, odom_y, odom_yaw, odom_vx, odom_wz : ndarray
        The base's pose (m, m, rad: yaw from +x towards +y) and its forward speed (m/s) and yaw rate (rad/s), MuJoCo's
        state, at the odometry's rate.
    scan_t, scan_ranges : ndarray
        The scans' times and ranges (scans × beams, m; inf: no wall within the range), beam i at angle −π + 2πi/beams
        from the base's heading (counter-clockwise), cast from the ``lidar`` site by `mujoco.mj_multiRay`.
    """

    run: RunResult
    cmd_t: np.ndarray
    cmd_wz: np.ndarray
    cmd_vx: np.ndarray
    odom_t: np.ndarray
    odom_x: np.ndarray
    odom_y: np.ndarray
    odom_yaw: np.ndarray
    odom_vx: np.ndarray
    odom_wz: np.ndarray
    scan_t: np.ndarray
    scan_ranges: np.ndarray


class _Recorder:
    """Samples the odometry (jittered as `Timing` says) and the scans of a run at whole engine steps (`_run` stops the
    engine at each)."""

    def __init__(self, timing: Timing, scan_rate: float, beams: int, scan_range: float):
        self.timing, self.scan_rate, self.beams, self.scan_range = timing, scan_rate, beams, scan_range
        self.cmd, self.odom, self.scans, self.scan_t = [], [], [], []
        self.done = -1

    def start(self, model, data, dt, base, lidar, group):
        self.model, self.data, self.dt, self.base, self.lidar, self.group = model, data, dt, base, lidar, group
        self.dof = model.jnt_dofadr[model.body_jntadr[base]]
        self.odom_ticks = self.timing.odometry_ticks(dt)
        self.next_odom = next(self.odom_ticks)
        self.scan_every = max(1, int(round(1.0 / (self.scan_rate * dt))))
        self.angles = -math.pi + 2 * math.pi * np.arange(self.beams) / self.beams
        self.geomid = np.zeros(self.beams, dtype=np.int32)
        self.dist = np.zeros(self.beams)

    def command(self, t: float, wz: float, vx: float):
        self.cmd.append((t, wz, vx))

    def due(self, step: int) -> bool:
        return step > self.done and (step >= self.next_odom or step % self.scan_every == 0)

    def next_step(self, step: int) -> int:
        return min(self.next_odom if self.next_odom > step else step + 1, (step // self.scan_every + 1) * self.scan_every)

    def sample(self, step: int):
        import mujoco

        self.done = step
        data, t = self.data, step * self.dt
        R = data.xmat[self.base]
        yaw = math.atan2(R[3], R[0])
        if step >= self.next_odom:
            v = data.qvel[self.dof:self.dof + 2]
            self.odom.append((t, float(data.xpos[self.base][0]), float(data.xpos[self.base][1]), yaw,
                              float(v[0] * math.cos(yaw) + v[1] * math.sin(yaw)), float(data.qvel[self.dof + 5])))
            while self.next_odom <= step:
                self.next_odom = next(self.odom_ticks)
        if step % self.scan_every == 0:
            a = yaw + self.angles
            vec = np.column_stack([np.cos(a), np.sin(a), np.zeros(self.beams)])
            mujoco.mj_multiRay(self.model, data, data.site_xpos[self.lidar].copy(), vec.ravel(), self.group, 1, self.base,
                               self.geomid, self.dist, None, self.beams, self.scan_range)
            self.scan_t.append(t)
            self.scans.append(np.where(self.geomid >= 0, self.dist, np.inf))


def corridor_log(scenario, options: EngineOptions = EngineOptions(), *, odom_rate: float | None = None, scan_rate: float = 10.0,
                 beams: int = 360, scan_range: float = 30.0) -> CorridorLog:
    """One corridor run (`run_scenario`) recorded as a robot's log: what ``pfm-stability diagnose`` reads
    (docs/mujoco.md, "Logs of corridor runs").

    Parameters
    ----------
    scenario : Scenario
        A ``corridor`` scenario in the grid (`run_scenario`).
    options : EngineOptions
        The robot file and the engine's settings.
    odom_rate : float, optional
        The odometry's rate, Hz, in (0, 1000] (rounded to whole engine steps); default `options.timing`'s (50 Hz), its
        jitter always `options.timing`'s.
    scan_rate : float
        The scans' rate, Hz, in (0, 1000] (rounded to whole engine steps).
    beams : int
        Beams per scan, in [8, 10000].
    scan_range : float
        The scans' reach, m, in (0, 100].

    Returns
    -------
    CorridorLog
    """
    timing = options.timing if odom_rate is None else replace(
        options.timing, odom_rate=check_number("odom_rate", odom_rate, 0.0, 1000.0, unit="Hz"))
    scan_rate = check_number("scan_rate", scan_rate, 0.0, 1000.0, unit="Hz")
    beams = check_integer("beams", beams, 8, 10_000)
    scan_range = check_number("scan_range", scan_range, 0.0, 100.0, unit="m")
    rec = _Recorder(timing, scan_rate, beams, scan_range)
    run = _run(scenario, options, "offset", True, rec)
    cmd = np.asarray(rec.cmd, dtype=float).reshape(-1, 3)
    odom = np.asarray(rec.odom, dtype=float).reshape(-1, 6)
    return CorridorLog(run, cmd[:, 0], cmd[:, 1], cmd[:, 2], *odom.T, np.asarray(rec.scan_t, dtype=float),
                       np.asarray(rec.scans, dtype=float).reshape(-1, beams))


def run_scenarios(scenarios, options: EngineOptions = EngineOptions(), *, record: str = "offset", metrics: bool = True) -> BatchResult:
    """`run_scenario` for each scenario in turn (MuJoCo is deterministic: the same batch gives the same runs).

    Parameters
    ----------
    scenarios : sequence of Scenario
        Corridor scenarios in the grid.
    options : EngineOptions
        The robot file and the engine's settings.
    record : {"offset", "trajectory"}
        What to keep of each run.
    metrics : bool
        Measure each run's oscillation.
    """
    started = time.perf_counter()
    runs = tuple(run_scenario(s, options, record=record, metrics=metrics) for s in scenarios)
    return BatchResult(runs, int(sum(r.steps for r in runs)), time.perf_counter() - started)


class MujocoRuns:
    """The validation's runner (`pfm_stability.validation.bisection.ParameterRuns`'s interface) with MuJoCo's runs.

    ``runs(name, values)`` → the `RunResult`s of the corridor at each value of `name` (``V``, ``L`` or
    ``f``); ``runs.runs`` counts them. Build one with `MujocoRuns.factory(options)`, the callable
    `pfm_stability.validation.validate_boundary` takes as ``runner``.

    Parameters
    ----------
    scenario : str
        ``"corridor"``.
    env : str
        ``"grid"``: the controller's grid.
    robot, controller : Robot, Controller
        The robot and controller of the scenarios.
    fixed : dict
        Parameters held fixed unless varied.
    common : dict
        Options of every scenario (offset, duration, window, cells).
    options : EngineOptions
        The robot file and the engine's settings.
    """

    def __init__(self, scenario, env, robot, controller, fixed, common, options: EngineOptions = EngineOptions()):
        if scenario != "corridor" or env != "grid":
            raise ValueError(f"the MuJoCo engine runs the corridor scenario with env grid; got scenario {scenario}, env {env}")
        self.scenario, self.env = scenario, env
        self.robot, self.controller = robot, controller
        self.fixed, self.common, self.options = fixed, common, options
        self.runs = 0
        o = options
        self.notes = {"engine": (
            f"MuJoCo {_mujoco_version()}: robot model {load_robot_model(o.robot_model).name}, {o.rays} rays to {o.sensor_range:g} m "
            f"({o.sensing} sensing), command dead time {1000 * o.command_delay:g} ms"
            + (f", caster friction {o.caster_friction:g}" if o.caster_friction is not None else "")
            + (f", torque limit {o.torque_limit:g} N m" if o.torque_limit is not None else "")
            + "; the robot's tau, plant gain and dead time are the predictions' (MuJoCo's plant is its own)"
        )}

    @classmethod
    def factory(cls, options: EngineOptions):
        """A runner builder with these options: ``factory(options)(scenario, env, robot, controller, fixed, common)``.

        Parameters
        ----------
        options : EngineOptions
            The robot file and the engine's settings.
        """
        return lambda scenario, env, robot, controller, fixed, common: cls(scenario, env, robot, controller, fixed, common, options)

    def __call__(self, name, values, second=None):
        from ..sim.api import batch_scenarios

        arrays = {name: np.asarray(values, dtype=float)}
        if second is not None:
            arrays[second[0]] = np.asarray(second[1], dtype=float)
        if "alpha" in arrays:
            raise ValueError("the MuJoCo engine runs the corridor scenario only (no alpha)")
        fixed = {k: v for k, v in self.fixed.items() if k not in arrays}
        scenarios = batch_scenarios(self.scenario, env=self.env, robot=self.robot, controller=self.controller, **fixed, **self.common, **arrays)
        batch = run_scenarios(scenarios, self.options)
        self.runs += len(batch)
        return batch.runs


def _mujoco_version() -> str:
    import mujoco

    return mujoco.__version__


# ----------------------------------------------------------------------------------- open-loop logs
@dataclass(frozen=True)
class DriveLog:
    """An open-loop drive recorded as a robot's log (times in s from the start).

    Attributes
    ----------
    cmd_t, cmd_wz, cmd_vx : ndarray
        The command's times (every T), yaw rate (rad/s, ROS sign: counter-clockwise positive) and forward speed (m/s).
    odom_t, odom_wz : ndarray
        The wheel odometry's yaw rate, (ω_right − ω_left)·r/b (rad/s), at its rate.
    imu_t, imu_wz : ndarray
        The gyro's yaw rate (the base's angular velocity about its z axis, rad/s), at the same instants.
    x, y, yaw : ndarray
        The base's true pose at the odometry's instants (MuJoCo's state, as a motion-capture system would see it): its
        origin's position (m) and its heading (rad from +x towards +y, the odometry convention of `CorridorLog`).
    v_forward, v_lateral : ndarray
        The base origin's true velocity at the same instants in the base's frame (m/s; lateral positive to the left),
        from MuJoCo's velocities, not from the pose: the ground truth of a slide (docs/diagnose.md, "The slide").
    """

    cmd_t: np.ndarray
    cmd_wz: np.ndarray
    cmd_vx: np.ndarray
    odom_t: np.ndarray
    odom_wz: np.ndarray
    imu_t: np.ndarray
    imu_wz: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    v_forward: np.ndarray
    v_lateral: np.ndarray


def _profile(name: str, t: np.ndarray, amplitude: float, duration: float, seed: int) -> np.ndarray:
    if name == "both":
        half = duration / 2
        first = t < half
        return np.where(first, _profile("steps", t, amplitude, half, seed), _profile("chirp", t - half, amplitude, half, seed))
    if name == "steps":
        rng = np.random.default_rng(seed)
        edges, levels = [0.0], [0.0]
        while edges[-1] < duration:
            edges.append(edges[-1] + rng.uniform(1.0, 2.5))
            levels.append(rng.uniform(-amplitude, amplitude))
        return np.asarray(levels)[np.searchsorted(edges, t, side="right") - 1]
    f0, f1 = 0.05, 2.0  # chirp, Hz
    return amplitude * np.sin(2 * np.pi * (f0 * t + (f1 - f0) * t**2 / (2 * duration)))


def drive_log(profile: str = "both", *, options: EngineOptions = EngineOptions(), V: float = 0.8, T: float = 0.05, amplitude: float = 0.1,
              duration: float = 60.0, rate: float = 50.0, seed: int = 0) -> DriveLog:
    """Drive the MuJoCo robot open loop at speed V with a yaw-rate command every T and record it as a log.

    Parameters
    ----------
    profile : {"steps", "chirp", "both"}
        Random steps (levels held 1–2.5 s, seeded), a chirp from 0.05 to 2 Hz, or steps then a chirp.
    options : EngineOptions
        The robot file, the command path's dead time and the ablations.
    V : float
        Forward speed, m/s.
    T : float
        The command's period, s (jittered as `options.timing` says; a smoother in `options` acts on the commands).
    amplitude : float
        The yaw-rate command's amplitude, rad/s (small: the loop models describe small oscillations,
        and MuJoCo's contacts make the lag depend on the amplitude; docs/mujoco.md).
    duration : float
        s.
    rate : float
        The odometry's and the gyro's rate, Hz.
    seed : int
        Seed of the steps.

    Returns
    -------
    DriveLog
    """
    import mujoco

    check_choice("profile", profile, PROFILES)
    V = check_number("V", V, 0.0, 100.0, unit="m/s")
    T = check_number("T", T, 0.0, 10.0, unit="s")
    duration = check_number("duration", duration, 0.0, 1e5, unit="s")
    robot = load_robot_model(options.robot_model)
    check_drives(robot.path)
    model = corridor_world(robot.path, math.inf, 0.0, 0.0, options.caster_friction, options.torque_limit)
    data = mujoco.MjData(model)
    dt = engine_timestep(robot.timestep, T)
    model.opt.timestep = dt
    place(model, data, robot, 0.0, 0.0, 0.0, V)
    total = int(round(duration / dt))
    ticks = options.timing.controller_ticks(T, dt)
    cmd_step = np.array([next(ticks) for _ in range(int(math.floor(duration / T + 1e-9)))], dtype=np.int64)
    cmd_step = cmd_step[cmd_step <= total]
    cmd_t = cmd_step * dt if options.timing.period_jitter > 0 else np.arange(cmd_step.size) * T
    cmd_wz = _profile(profile, cmd_t, amplitude, duration, seed)
    path = CommandPath(dt, int(round(options.command_delay / dt)), options.smoother, options.timing)
    odometry = replace(options.timing, odom_rate=rate).odometry_ticks(dt)
    next_odom = next(odometry)
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    dof = model.jnt_dofadr[model.body_jntadr[base]]
    left, right = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, s) for s in ("left", "right"))
    wl, wr = (model.jnt_dofadr[model.actuator_trnid[a, 0]] for a in (left, right))
    q = model.jnt_qposadr[model.body_jntadr[base]]
    lag = 0.0 if model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4 else dt / 2  # _true_motion
    odom_t, odom_wz, imu_wz, truth = [], [], [], []
    j, now = 0, 0
    while now <= total:
        while j < cmd_step.size and cmd_step[j] <= now:
            path.publish(now, float(cmd_wz[j]))
            j += 1
        reached = path.due(now, float(data.qvel[dof + 5]))
        if reached is not None:
            data.ctrl[left], data.ctrl[right] = robot.wheel_speeds(V, -reached)  # ROS yaw rate = −θ̇
        if now == next_odom and now < total:
            odom_t.append(now * dt)
            odom_wz.append((data.qvel[wr] - data.qvel[wl]) * robot.wheel_radius / robot.track)
            imu_wz.append(float(data.qvel[dof + 5]))
            truth.append(_true_motion(data, q, dof, lag))
        while next_odom <= now:
            next_odom = next(odometry)
        nxt = min(int(cmd_step[j]) if j < cmd_step.size else total + 1, next_odom, path.next_event(now), total + 1)
        if nxt > total:
            break
        mujoco.mj_step(model, data, nstep=nxt - now)
        now = nxt
    odom_t = np.asarray(odom_t)
    return DriveLog(cmd_t, cmd_wz, np.full_like(cmd_t, V), odom_t, np.asarray(odom_wz), odom_t.copy(), np.asarray(imu_wz),
                    *np.asarray(truth, dtype=float).reshape(-1, 5).T)


def _true_motion(data, q: int, dof: int, lag: float) -> tuple[float, float, float, float, float]:
    """(x, y, yaw, v_forward, v_lateral) of the base from MuJoCo's current state.

    The pose is the free joint's position and quaternion (qpos, not xpos/xmat, which `mj_step` leaves one step behind),
    yaw from +x towards +y (the body's x axis is its forward direction, `robots.place`). The velocity is its origin's
    (qvel's linear part, world frame) in the base's frame at the velocity's own time: MuJoCo's Euler and implicit
    integrators move the position by the step's new velocity, so qvel is the velocity over the last step, `lag` = half
    a step before the pose; it is rotated by the heading then, yaw − r·lag (r the body's yaw rate). Rotated by the
    heading of the step's end it would read a slide half a step longer than the pose shows (0.5 ms at 1-ms steps); a
    heading one step stale (xmat) with this velocity, half a step shorter."""
    w, qx, qy, qz = (float(v) for v in data.qpos[q + 3:q + 7])
    yaw = math.atan2(2.0 * (w * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    vx, vy = float(data.qvel[dof]), float(data.qvel[dof + 1])
    then = yaw - float(data.qvel[dof + 5]) * lag
    c, s = math.cos(then), math.sin(then)
    return float(data.qpos[q]), float(data.qpos[q + 1]), yaw, vx * c + vy * s, -vx * s + vy * c


def write_csv_log(log: DriveLog, path, *, pose: bool = True) -> None:
    """Write `log` as a CSV log (``t, cmd_wz, odom_wz, imu_wz`` and, with `pose`, the base's true pose ``x, y, yaw`` at
    the odometry's instants: one row per time, blank where a series has no value; docs/diagnose.md), atomically.

    Parameters
    ----------
    log : DriveLog
        The recorded drive.
    path : str or os.PathLike
        The CSV file.
    pose : bool
        Write the pose's columns (what ``identify`` measures the slide from; docs/diagnose.md, "The slide").
    """
    from ..io.files import atomic_file

    series = [(log.cmd_t, (log.cmd_wz,)), (log.odom_t, (log.odom_wz,)), (log.imu_t, (log.imu_wz,))]
    if pose:
        series.append((log.odom_t, (log.x, log.y, log.yaw)))
    width = sum(len(values) for _, values in series)
    rows, column = {}, 0
    for ts, values in series:
        for i, t_ in enumerate(ts.tolist()):
            row = rows.setdefault(round(t_, 9), [""] * width)
            for k, v in enumerate(values):
                row[column + k] = repr(float(v[i]))
        column += len(values)
    with atomic_file(path, "w", what="log") as fh:
        fh.write("t,cmd_wz,odom_wz,imu_wz" + (",x,y,yaw" if pose else "") + "\n")
        for t_ in sorted(rows):
            fh.write(f"{t_!r}," + ",".join(rows[t_]) + "\n")
