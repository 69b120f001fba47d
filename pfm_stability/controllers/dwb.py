"""Nav2's DWB controller (``nav2_dwb_controller``: dwb_core, dwb_plugins, dwb_critics) for a differential-drive robot.

One cycle (``dwb_core/src/dwb_local_planner.cpp``, ``computeVelocityCommands`` and ``coreScoringAlgorithm``):

1. **Prepare** every critic with the robot's pose and measured velocity, the global goal (the plan's last pose)
   and the plan the controller server hands over (`controllers.plan.local_plan`).
2. **Velocity samples** (``dwb_plugins/src/xy_theta_iterator.cpp``, ``include/dwb_plugins/one_d_velocity_iterator.hpp``):
   per axis, ``vx_samples`` / ``vtheta_samples`` values evenly spread over the dynamic window — the velocities
   reachable from the measured one within ``sim_time`` (``StandardTrajectoryGenerator``) or within one controller
   period (``LimitedAccelGenerator``, ``sim_period``), inside [min, max] — with 0 inserted where the samples cross
   it; x outermost, θ innermost; combinations failing ``KinematicParameters::isValidSpeed`` skipped.
3. **Trajectories** (``dwb_plugins/src/standard_traj_generator.cpp``): from the pose, ``sim_time`` in steps of at
   most ``linear_granularity`` and ``angular_granularity`` (``getTimeSteps``, discretised by distance), the
   velocity ramped from the measured one towards the sample at the acceleration limits (``computeNewVelocity``;
   ``LimitedAccelGenerator``: the sample itself), Euler poses; the start pose first and, with
   ``include_last_point``, the last pose twice.
4. **Critics** (``dwb_critics/src``; total = Σ scale·score, a critic's exception makes the trajectory illegal):
   RotateToGoal (0 until within ``xy_goal_tolerance`` of the goal), Oscillation (illegal when a command reverses
   a sign it held, ``oscillation.cpp``; only θ at forward speeds below ``x_only_threshold``), BaseObstacle (the
   cost of the last pose; any pose on lethal, inscribed or unknown cost is illegal), and the map-grid critics
   (``map_grid.cpp``): a grid of Manhattan distances in cells from the plan's cells (PathDist, PathAlign, the plan
   at the costmap's resolution, ``nav_2d_utils::adjustPlanResolution``) or from the last plan pose on the costmap
   (GoalDist, GoalAlign: that pose pushed ``forward_point_distance`` towards the goal), read at the last pose
   (PathDist, GoalDist) or at the point ``forward_point_distance`` ahead of it (PathAlign, GoalAlign). PathAlign's
   scale is resolution·0.5·``scale`` (``PathAlignCritic::getScale``).
5. **Choose** the legal trajectory of least total, the first of equal ones (``score.total < best.total``);
   none legal: `NoValidControl`. The Oscillation critic then records the command (``debrief``).

The grid's distances are propagated by ``costmap_queue`` in order of Euclidean distance from the sources, each cell
taking the Manhattan distance to the source that reached it first; here that source is the cell's Euclidean-nearest
source cell (the first of equally near), which is the queue's on a plan along a grid axis (every cell's nearest plan
cell is straight across it). Only the cells the critics read are computed.

Defaults: the DWB configuration nav2_bringup shipped until MPPI replaced it (``nav2_bringup/params/nav2_params.yaml``
before commit 5a8cbd3fc: the robot's limits, ``linear_granularity`` 0.05, the critics and their scales, both
``forward_point_distance`` 0.1), and the source's declarations for the rest (``vx_samples`` 20, ``vtheta_samples``
20, ``sim_time`` 1.7 s, ``include_last_point``; the source's kinematic defaults are all 0, which drive nowhere, and
its ``forward_point_distance`` 0.325).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..checks import check_integer, check_number
from .base import Command, NoValidControl, RobotState, normalize_angle
from .plan import PRUNE_DISTANCE, local_plan

__all__ = ["DWBParams", "DWBMemory", "MapGridCritic", "BaseObstacle", "RotateToGoal", "Oscillation", "DEFAULT_CRITICS",
           "TRAJECTORY_GENERATORS", "velocity_samples", "command", "with_speed", "nominal_speed", "LINEARIZATION_STEPS",
           "WARMUP_CYCLES", "RANDOM_PHASE", "DRAWS"]

DEFAULT_CRITICS = ("RotateToGoal", "Oscillation", "BaseObstacle", "GoalAlign", "PathAlign", "PathDist", "GoalDist")
"""nav2_bringup's DWB critics, in their order."""

TRAJECTORY_GENERATORS = ("StandardTrajectoryGenerator", "LimitedAccelGenerator")

EPSILON = 1e-5
"""``dwb_plugins::EPSILON`` of the velocity iterator."""

FLOAT_EPSILON = float(np.finfo(np.float32).eps)
"""``std::numeric_limits<float>::epsilon()`` of ``isValidSpeed``."""

WARMUP_CYCLES = 4
"""Cycles on the centre line before a linearisation or a run: DWB keeps only the Oscillation critic's flags, which a
forward-moving robot never sets; a few cycles bring the measured speed to the chosen one."""

RANDOM_PHASE = True
"""The decision is quantized by the velocity samples and the costmap's cells: a linearisation draws the robot's place
relative to the plan's poses and the cells (`CorridorCostmap.lattice`), over which the secant's mean is the mean slope."""

DRAWS = 32
"""Draws a linearisation averages by default (the quantized decision's secants scatter by about their own size)."""

LINEARIZATION_STEPS = (0.02, 0.02, 0.0)
"""Central-difference steps (e_y m, e_θ rad, ω_m rad/s). With the lattice's phase uniform the secant of a staircase is
an unbiased estimate of its mean slope for any step; 0.02 m and 0.02 rad keep the trajectories' ends within a cell or
two of the centre (linear in the critics' cells) while crossing enough cell and sample boundaries. The measured yaw rate
only ramps the trajectory's first step (3.2 rad/s² over 0.19 s), never reached by small perturbations: skipped."""


@dataclass(frozen=True)
class MapGridCritic:
    """A map-grid critic's parameters (PathDist, PathAlign, GoalDist, GoalAlign).

    Attributes
    ----------
    scale : float
    forward_point_distance : float
        m (the align critics').
    """

    scale: float = 1.0
    forward_point_distance: float = 0.325


@dataclass(frozen=True)
class BaseObstacle:
    """``BaseObstacleCritic``'s parameters.

    Attributes
    ----------
    scale : float
    sum_scores : bool
        (False: the last pose's cost.)
    """

    scale: float = 1.0
    sum_scores: bool = False


@dataclass(frozen=True)
class RotateToGoal:
    """``RotateToGoalCritic``'s parameters.

    Attributes
    ----------
    scale : float
    slowing_factor : float
    """

    scale: float = 1.0
    slowing_factor: float = 5.0


@dataclass(frozen=True)
class Oscillation:
    """``OscillationCritic``'s parameters.

    Attributes
    ----------
    scale : float
    oscillation_reset_dist : float
        m.
    oscillation_reset_angle : float
        rad.
    x_only_threshold : float
        m/s.
    """

    scale: float = 1.0
    oscillation_reset_dist: float = 0.05
    oscillation_reset_angle: float = 0.2
    x_only_threshold: float = 0.05


BRINGUP_DEFAULTS = ("max_vel_x", "max_vel_theta", "max_speed_xy", "acc_lim_x", "decel_lim_x", "acc_lim_theta", "decel_lim_theta",
                    "linear_granularity", "critics")
"""The fields whose default is nav2_bringup's DWB configuration, not the source's declaration (`controllers.registry`):
the source declares every speed and acceleration limit 0 and no critics (a planner that cannot move), a 0.5 m linear
granularity where bringup samples every 0.05 m. Every other field's default is the registry's
(tests/test_controllers_plan.py; the trajectory generator is the same class, named with and without its namespace)."""


@dataclass(frozen=True)
class DWBParams:
    """DWB's parameters (Nav2's names; defaults: module docstring).

    Attributes
    ----------
    min_vel_x, max_vel_x : float
        m/s (0, 0.26).
    max_vel_theta : float
        rad/s (1.0).
    min_speed_xy, max_speed_xy : float
        m/s (0, 0.26).
    min_speed_theta : float
        rad/s (0).
    acc_lim_x, decel_lim_x : float
        m/s² (2.5, −2.5).
    acc_lim_theta, decel_lim_theta : float
        rad/s² (3.2, −3.2).
    vx_samples, vtheta_samples : int
        (20, 20).
    sim_time : float
        s (1.7).
    linear_granularity, angular_granularity : float
        m and rad (0.05, 0.025).
    include_last_point : bool
        (True).
    trajectory_generator_name : str
        One of `TRAJECTORY_GENERATORS` (the standard one).
    critics : tuple of str
        `DEFAULT_CRITICS`.
    RotateToGoal, Oscillation, BaseObstacle, GoalAlign, PathAlign, PathDist, GoalDist
        Each critic's parameters (bringup: scales 32, 1, 0.02, 24, 32, 32, 24; align points 0.1 m).
    xy_goal_tolerance : float
        m (0.25).
    trans_stopped_velocity : float
        m/s (0.25).
    prune_distance : float
        The controller server's, m (2.0).
    controller_frequency : float
        Hz (20): the ``LimitedAccelGenerator``'s ``sim_period`` is its inverse.
    track_unknown_space : bool
        The costmap's (False).
    """

    min_vel_x: float = 0.0
    max_vel_x: float = 0.26
    max_vel_theta: float = 1.0
    min_speed_xy: float = 0.0
    max_speed_xy: float = 0.26
    min_speed_theta: float = 0.0
    acc_lim_x: float = 2.5
    decel_lim_x: float = -2.5
    acc_lim_theta: float = 3.2
    decel_lim_theta: float = -3.2
    vx_samples: int = 20
    vtheta_samples: int = 20
    sim_time: float = 1.7
    linear_granularity: float = 0.05
    angular_granularity: float = 0.025
    include_last_point: bool = True
    trajectory_generator_name: str = "StandardTrajectoryGenerator"
    critics: tuple = DEFAULT_CRITICS
    RotateToGoal: RotateToGoal = field(default_factory=lambda: RotateToGoal(scale=32.0))
    Oscillation: Oscillation = field(default_factory=Oscillation)
    BaseObstacle: BaseObstacle = field(default_factory=lambda: BaseObstacle(scale=0.02))
    GoalAlign: MapGridCritic = field(default_factory=lambda: MapGridCritic(24.0, 0.1))
    PathAlign: MapGridCritic = field(default_factory=lambda: MapGridCritic(32.0, 0.1))
    PathDist: MapGridCritic = field(default_factory=lambda: MapGridCritic(32.0))
    GoalDist: MapGridCritic = field(default_factory=lambda: MapGridCritic(24.0))
    xy_goal_tolerance: float = 0.25
    trans_stopped_velocity: float = 0.25
    prune_distance: float = PRUNE_DISTANCE
    controller_frequency: float = 20.0
    track_unknown_space: bool = False

    def __post_init__(self):
        for name in ("max_vel_x", "max_vel_theta", "max_speed_xy", "sim_time", "linear_granularity", "angular_granularity",
                     "prune_distance", "controller_frequency"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6))
        for name in ("acc_lim_x", "acc_lim_theta", "min_speed_xy", "min_speed_theta", "xy_goal_tolerance", "trans_stopped_velocity"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6, low_open=False))
        for name in ("decel_lim_x", "decel_lim_theta"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), -1e6, 0.0, high_open=False))
        object.__setattr__(self, "min_vel_x", check_number("min_vel_x", self.min_vel_x, -1e6, self.max_vel_x, high_open=False))
        for name in ("vx_samples", "vtheta_samples"):
            object.__setattr__(self, name, check_integer(name, getattr(self, name), 1, 100_000))
        if self.trajectory_generator_name not in TRAJECTORY_GENERATORS:
            raise ValueError(f"trajectory_generator_name must be one of {', '.join(TRAJECTORY_GENERATORS)}; got {self.trajectory_generator_name!r}")
        unknown = [c for c in self.critics if c not in DEFAULT_CRITICS]
        if unknown:
            raise ValueError(f"critics must be among {', '.join(DEFAULT_CRITICS)}; got {', '.join(unknown)}")

    def replace(self, **changes) -> "DWBParams":
        """A copy with some parameters changed (validated again).

        Parameters
        ----------
        **changes
            Parameter values.
        """
        return replace(self, **changes)


@dataclass(frozen=True)
class DWBMemory:
    """What DWB's critics keep between cycles: the Oscillation critic's trends and RotateToGoal's flags.

    Attributes
    ----------
    trends : tuple
        (sign, positive_only, negative_only) for x, y and θ (``CommandTrend``).
    stationary : tuple
        (x, y, yaw) where the oscillation flags were last set (``prev_stationary_pose_``).
    in_window, rotating : bool
        RotateToGoal's.
    """

    trends: tuple = ((0, False, False),) * 3
    stationary: tuple = (0.0, 0.0, 0.0)
    in_window: bool = False
    rotating: bool = False


def with_speed(params: DWBParams, V: float) -> DWBParams:
    """The parameters with ``max_vel_x`` = ``max_speed_xy`` = V (m/s).

    Parameters
    ----------
    params : DWBParams
    V : float
        m/s.
    """
    return params.replace(max_vel_x=V, max_speed_xy=V)


def nominal_speed(params: DWBParams) -> float:
    """The speed to start from: ``max_vel_x``, m/s.

    Parameters
    ----------
    params : DWBParams
    """
    return params.max_vel_x


def _project(v0, accel, decel, dt, target):
    """``projectVelocity``: v0 moved towards target by at most the acceleration (or deceleration) over dt."""
    return np.where(v0 < target, np.minimum(target, v0 + accel * dt), np.maximum(target, v0 + decel * dt))


def _axis_samples(current, low, high, accel, decel, dt, samples):
    """``OneDVelocityIterator``: the values of one axis, in order (0 inserted where they cross it)."""
    current = min(max(current, low), high)
    top = float(_project(current, accel, decel, dt, high))
    bottom = float(_project(current, accel, decel, dt, low))
    if abs(bottom - top) < EPSILON:
        return [bottom]
    increment = (top - bottom) / max(1, max(2, samples) - 1)
    out, value, zero = [], bottom, True
    while value <= top + EPSILON:
        out.append(value)
        if zero and value < 0.0 < value + increment and value + increment <= top + EPSILON:
            out.append(0.0)
            zero = False
        value += increment
    return out


def _valid_speed(params: DWBParams, x, theta):
    """``KinematicParameters::isValidSpeed`` for a differential drive (y = 0), element-wise."""
    speed2 = x * x
    too_fast = (params.max_speed_xy >= 0.0) & (speed2 > params.max_speed_xy ** 2 + FLOAT_EPSILON)
    too_slow = ((params.min_speed_xy >= 0.0) & (speed2 + FLOAT_EPSILON < params.min_speed_xy ** 2)
                & (params.min_speed_theta >= 0.0) & (np.abs(theta) + FLOAT_EPSILON < params.min_speed_theta))
    return ~too_fast & ~too_slow & ~((speed2 == 0.0) & (theta == 0.0))


def velocity_samples(params: DWBParams, v: float, w: float):
    """The sampled commands (vx, ω), in the iterator's order (x outermost), invalid speeds skipped (module docstring, 2).

    Parameters
    ----------
    params : DWBParams
    v, w : float
        The measured velocity, m/s and rad/s.
    """
    dt = params.sim_time if params.trajectory_generator_name == "StandardTrajectoryGenerator" else 1.0 / params.controller_frequency
    xs = _axis_samples(v, params.min_vel_x, params.max_vel_x, params.acc_lim_x, params.decel_lim_x, dt, params.vx_samples)
    ws = _axis_samples(w, -params.max_vel_theta, params.max_vel_theta, params.acc_lim_theta, params.decel_lim_theta, dt, params.vtheta_samples)
    vx, wz = (a.ravel() for a in np.meshgrid(np.array(xs), np.array(ws), indexing="ij"))
    keep = _valid_speed(params, vx, wz)
    return vx[keep], wz[keep]


def _step_counts(params: DWBParams, vx, wz):
    """``getTimeSteps`` (by distance): steps per trajectory, at least one."""
    n = np.ceil(np.maximum(np.abs(vx) * params.sim_time / params.linear_granularity, np.abs(wz) * params.sim_time / params.angular_granularity))
    return np.maximum(n, 1).astype(np.int64)


def _trajectories(params: DWBParams, state: RobotState, vx, wz):
    """Every sample's poses (module docstring, 3): (x, y, yaw) arrays (samples, steps + 1) and which steps exist."""
    n = _step_counts(params, vx, wz)
    dt = params.sim_time / n
    steps = int(n.max())
    x, y, yaw = (np.full((vx.size, steps + 1), v, dtype=float) for v in (state.x, state.y, state.yaw))
    ramp = params.trajectory_generator_name == "StandardTrajectoryGenerator"
    v, w = np.full(vx.size, state.v), np.full(vx.size, state.w)
    for k in range(steps):
        live = k < n
        if ramp:
            v = np.where(live, _project(v, params.acc_lim_x, params.decel_lim_x, dt, vx), v)
            w = np.where(live, _project(w, params.acc_lim_theta, params.decel_lim_theta, dt, wz), w)
        else:
            v, w = vx, wz
        th = yaw[:, k]
        x[:, k + 1] = np.where(live, x[:, k] + v * np.cos(th) * dt, x[:, k])
        y[:, k + 1] = np.where(live, y[:, k] + v * np.sin(th) * dt, y[:, k])
        yaw[:, k + 1] = np.where(live, th + w * dt, th)
    return x, y, yaw


def _sources(part, costmap):
    """The map-grid sources: the plan's cells at the costmap's resolution, in order (``adjustPlanResolution``)."""
    r = costmap.resolution
    xs, ys = [part.x[0]], [part.y[0]]
    for px, py in zip(part.x[1:], part.y[1:]):
        gap = math.hypot(px - xs[-1], py - ys[-1])
        if gap > 2.0 * r:  # holes of more than two cells get points in between
            k = int((gap - 2.0 * r) / r) - 1
            xs += list(xs[-1] + (px - xs[-1]) * np.arange(1, k) / k)
            ys += list(ys[-1] + (py - ys[-1]) * np.arange(1, k) / k)
        xs.append(px)
        ys.append(py)
    return np.array(xs), np.array(ys)


def _manhattan(costmap, window, sources_x, sources_y, qx, qy):
    """Grid distance (cells) at query points: Manhattan to the Euclidean-nearest source cell (module docstring)."""
    ci, cj = costmap.columns(sources_x), costmap.rows(sources_y)
    qi, qj = costmap.columns(qx), costmap.rows(qy)
    d2 = (qi[..., None] - ci) ** 2 + (qj[..., None] - cj) ** 2
    nearest = np.argmin(d2, axis=-1)
    return (np.abs(qi - ci[nearest]) + np.abs(qj - cj[nearest])).astype(float)


def _on_costmap(costmap, window, x, y):
    """The first run of the points on the costmap with known cost (``PathDistCritic::prepare``,
    ``GoalDistCritic::getLastPoseOnCostmap``: from the first such point until one is not)."""
    known = window.contains(x, y) & (costmap.cost(x, y, window) != 255)
    if not known.any():
        return x[:0], y[:0]
    first = int(np.argmax(known))
    off = np.flatnonzero(~known[first:])
    end = first + (int(off[0]) if off.size else known.size - first)
    return x[first:end], y[first:end]


def _path_sources(part, costmap, window):
    """PathDist's and PathAlign's sources: the plan, at the costmap's resolution, on the costmap."""
    return _on_costmap(costmap, window, *_sources(part, costmap))


def _goal_source(part, costmap, window, push=None):
    """GoalDist's source, the last pose of the plan on the costmap; GoalAlign's (`push`: (dx, dy) added to the plan's
    last pose first)."""
    x, y = np.array(part.x, dtype=float), np.array(part.y, dtype=float)
    if push is not None:
        x[-1] += push[0]
        y[-1] += push[1]
    sx, sy = _on_costmap(costmap, window, *_sources(type(part)(x, y, part.yaw, part.first), costmap))
    return sx[-1:], sy[-1:]


def _oscillating(memory: DWBMemory, vx, wz):
    """``CommandTrend::isOscillating`` on x and θ: a sign reversed that was flipped before (illegal)."""
    out = np.zeros(vx.shape, dtype=bool)
    for (sign, positive_only, negative_only), v in zip((memory.trends[0], memory.trends[2]), (vx, wz)):
        out |= (positive_only & (v < 0.0)) | (negative_only & (v > 0.0))
    return out


def _debrief(params: DWBParams, memory: DWBMemory, state: RobotState, vx: float, wz: float) -> DWBMemory:
    """``OscillationCritic::debrief``: update the trends with the chosen command, reset them once the robot moved."""
    def update(trend, v):
        sign, positive_only, negative_only = trend
        flag = False
        if v < 0.0:
            flag, negative_only = sign == 1, negative_only or sign == 1
            sign = -1
        elif v > 0.0:
            flag, positive_only = sign == -1, positive_only or sign == -1
            sign = 1
        return (sign, positive_only, negative_only), flag

    c = params.Oscillation
    tx, fx = update(memory.trends[0], vx)
    trends, flagged = [tx, memory.trends[1], memory.trends[2]], fx
    if c.x_only_threshold < 0.0 or abs(vx) <= c.x_only_threshold:
        trends[2], ft = update(memory.trends[2], wz)
        flagged |= ft
    stationary = (state.x, state.y, state.yaw) if flagged else memory.stationary
    if any(t[1] or t[2] for t in trends):
        moved = math.hypot(state.x - stationary[0], state.y - stationary[1]) > c.oscillation_reset_dist
        turned = abs(normalize_angle(state.yaw - stationary[2])) > c.oscillation_reset_angle
        if (c.oscillation_reset_dist >= 0.0 and moved) or (c.oscillation_reset_angle >= 0.0 and turned):
            trends = [(0, False, False)] * 3
    return replace(memory, trends=tuple(trends), stationary=stationary)


def _scores(params, state, part, costmap, window, memory, goal, vx, wz, x, y, yaw, live):
    """(total, legal) per sample (module docstring, 4)."""
    total = np.zeros(vx.size)
    legal = np.ones(vx.size, dtype=bool)
    if any(c in params.critics for c in ("BaseObstacle", "PathDist", "GoalDist")):  # they score every pose: off the grid throws
        legal &= np.all(window.contains(x, y) | ~live, axis=1)
    cost = costmap.cost(x, y, window)
    if "BaseObstacle" in params.critics:  # lethal, inscribed or unknown cost on any pose throws
        legal &= np.all(((cost < 253) | ((cost == 255) & params.track_unknown_space)) | ~live, axis=1)
    path = _path_sources(part, costmap, window)
    last = (x[:, -1], y[:, -1], yaw[:, -1])
    dgoal2 = (state.x - goal[0]) ** 2 + (state.y - goal[1]) ** 2
    for name in params.critics:
        c = getattr(params, name)
        if name == "RotateToGoal":
            continue  # far from the goal (RotateToGoal's window is checked in `command`)
        if name == "Oscillation":
            legal &= ~_oscillating(memory, vx, wz)
        elif name == "BaseObstacle":
            total += c.scale * (np.sum(np.where(live, cost, 0.0), axis=1) if c.sum_scores else costmap.cost(*last[:2], window))
        else:
            align = name in ("PathAlign", "GoalAlign")
            px, py = last[0], last[1]
            if align:
                px, py = px + c.forward_point_distance * np.cos(last[2]), py + c.forward_point_distance * np.sin(last[2])
                legal &= window.contains(px, py)
            if name.startswith("Path"):
                src = path
                scale = (0.0 if dgoal2 <= c.forward_point_distance ** 2 else costmap.resolution * 0.5 * c.scale) if align else c.scale
            else:
                bearing = math.atan2(goal[1] - state.y, goal[0] - state.x)
                push = (c.forward_point_distance * math.cos(bearing), c.forward_point_distance * math.sin(bearing)) if align else None
                src = _goal_source(part, costmap, window, push)
                scale = c.scale
            if scale == 0.0 or src[0].size == 0:
                continue
            total += scale * _manhattan(costmap, window, src[0], src[1], px, py)
    return total, legal


def command(state: RobotState, plan, costmap, params: DWBParams = DWBParams(), rng=None, memory: DWBMemory | None = None) -> Command:
    """One cycle of DWB (module docstring).

    Parameters
    ----------
    state : RobotState
        Pose and measured velocity.
    plan : Plan
        The global plan.
    costmap : CorridorCostmap
        The local costmap (its cells carry the map-grid critics).
    params : DWBParams
    rng : numpy.random.Generator, optional
        Unused (deterministic).
    memory : DWBMemory, optional
        The critics' state (None: a new plan).

    Raises
    ------
    NoValidControl
        When no sampled trajectory is legal.
    """
    memory = DWBMemory() if memory is None else memory
    window = costmap.window(state.x, state.y)
    part = local_plan(plan, state, window, params.prune_distance)
    goal = (float(plan.x[-1]), float(plan.y[-1]))
    near = (state.x - goal[0]) ** 2 + (state.y - goal[1]) ** 2 <= params.xy_goal_tolerance ** 2 and part.length <= 1.0
    if "RotateToGoal" in params.critics and (memory.in_window or near):
        raise NoValidControl("DWB's goal approach (RotateToGoal within xy_goal_tolerance) is not modelled")
    vx, wz = velocity_samples(params, state.v, state.w)
    if vx.size == 0:
        raise NoValidControl("DWB: no valid velocity sample")
    x, y, yaw = _trajectories(params, state, vx, wz)
    n = _step_counts(params, vx, wz)
    live = np.arange(x.shape[1])[None, :] <= n[:, None]
    total, legal = _scores(params, state, part, costmap, window, memory, goal, vx, wz, x, y, yaw, live)
    if not legal.any():
        raise NoValidControl("DWB: no legal trajectory")
    best = int(np.flatnonzero(legal)[np.argmin(total[legal])])  # the first of the least
    return Command(float(vx[best]), float(wz[best]), _debrief(params, memory, state, float(vx[best]), float(wz[best])))
