"""Nav2's MPPI controller (``nav2_mppi_controller``) for a differential-drive robot, as its source computes it.

One control cycle (``src/optimizer.cpp``, ``Optimizer::evalControl``), all arrays in single precision (``float``,
Eigen's ``ArrayXXf``) and vectorised over the batch:

1. **Prepare** (``prepare``): the initial speed is the last command clamped to what the accelerations allow from
   the measured speed within one controller period (``ax_min``/``ax_max``, ``az_max``·T): Nav2's compensation of
   the latency between measurement and command; ``open_loop`` takes the last command itself. The plan is the one
   the controller server hands over (`controllers.plan.local_plan`, global frame).
2. **Sample** (``generateNoisedTrajectories``): ``control_sequence(0)`` is pinned to the initial speed when the
   sequence shifts (``shift_control_sequence``: the controller period equals ``model_dt``; a longer period is
   refused, as Nav2 throws); the noised controls are the sequence plus Gaussian noise of ``vx_std``, ``wz_std``
   (``tools/noise_generator.cpp``: drawn once at reset and reused every cycle unless ``regenerate_noises``).
3. **Motion model** (``include/.../motion_models.hpp``, ``MotionModel::predict``, DiffDrive): velocities from the
   noised controls, each step clamped to the accelerations from the previous (``ax``: sign-dependent), then the
   model delay (``model_delay_vx``, ``model_delay_wz``, rounded to whole ``model_dt`` steps, d): the rollout's
   velocities shift by d − 1 steps and the d − 1 steps after the initial one hold the commands already sent
   (``applyDelayShift`` — so a delay of one step changes nothing). Poses by Euler integration
   (``integrateStateVelocities``).
4. **Critics** (`controllers.mppi_critics`; ``src/critics/*.cpp``, the bringup list `DEFAULT_CRITICS`): Constraint, Cost (the inflated costmap
   at every ``trajectory_point_step``-th point, collisions), Goal and GoalAngle (only within
   ``threshold_to_consider`` of plan left), PathAlign (mean distance from the trajectory's points to the plan points
   matched by integrated distance, once the trajectories reach ``offset_from_furthest`` points along the plan),
   PathFollow (the trajectory's end to the plan point ``offset_from_furthest`` beyond the furthest reached),
   PathAngle (only when the robot points more than ``max_angle_to_furthest`` away from the plan ahead),
   PreferForward; the Obstacles critic is available instead of Cost (``ObstaclesCritic``).
5. **Update** (``updateControlSequence``): costs += γ/σ²·Σ(noise·sequence) per axis; weights
   softmax(−(cost − min)/``temperature``); sequence = weighted mean of the noised controls; the Savitzky–Golay
   filter over the sequence and the last four sent commands (``tools/utils.hpp`` ``savitskyGolayFilter``, order 2,
   nine points); the velocity and acceleration limits along the sequence (``applyControlSequenceConstraints``).
6. **Command**: the sequence's element 1 (0 without shifting); the sequence shifts by one for the next cycle.
   A cycle whose every trajectory collides resets the optimizer and retries once (``retry_attempt_limit``), then
   fails (`NoValidControl`).

The optimizer's state — sequence, the filter's history, the last command, the delay's command history and the
noise — is the `MPPIMemory` carried from cycle to cycle (`Command.memory`; None: a reset). The noise is drawn
from the caller's Generator (Nav2's ``std::mt19937`` cannot be reproduced; its seed is fixed, so every Nav2 robot
draws the same noise at start-up). The trajectory validator is not modelled (``DefaultOptimalTrajectoryValidator``:
it rejects an optimal trajectory that meets lethal cost, which the Cost critic already makes prohibitive).

Defaults: the parameter declarations of ``src/optimizer.cpp`` and of each critic; the critic list, which the source
leaves empty, is nav2_bringup's (``nav2_bringup/params/nav2_params.yaml``); `MPPIParams.bringup` gives that file's
whole configuration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..checks import check_integer, check_number
from .base import Command, NoValidControl, RobotState
from .mppi_critics import (CRITIC_NAMES, DEFAULT_CRITICS, ConstraintCritic, CostCritic, CriticData, F, GoalAngleCritic, GoalCritic,
                           ObstaclesCritic, PathAlignCritic, PathAngleCritic, PathFollowCritic, PreferForwardCritic, score)
from .plan import PRUNE_DISTANCE, local_plan

__all__ = ["MPPIParams", "MPPIMemory", "command", "with_speed", "nominal_speed", "savitzky_golay", "LINEARIZATION_STEPS",
           "WARMUP_CYCLES", "RANDOM_PHASE", "DRAWS", "MEMORY_CYCLES"]

WARMUP_CYCLES = 60
"""Cycles on the centre line before a linearisation or a run (`controllers.linearize.warm_up`): from a reset the
sequence reaches its cruising speed in about 4 cycles (ax_max·T = 0.15 m/s each) and settles within the horizon's
56 steps; 60 cycles (3 s) leave it converged (measured: the last ten commands' ω vary by less than 1e-6 rad/s)."""

RANDOM_PHASE = True
"""The linearisation draws the robot's place relative to the plan's poses and the costmap's cells with the noise."""

DRAWS = 8
"""Draws of the noise (and of the robot's place on the plan) a linearisation averages by default: standard errors of
about 3 % of k_y and k_θ (`controllers.linearize`)."""

MEMORY_CYCLES = 1
"""Cycles of the response a default linearisation measures (1: the one-step gains); the memory of the optimizer
lasts about 15 cycles (docs/controllers.md): ``linearize(..., memory_cycles=16)``."""

LINEARIZATION_STEPS = (0.01, 0.01, 0.0)
"""Central-difference steps (e_y m, e_θ rad, ω_m rad/s); see docs/controllers.md, "MPPI's linearisation": the
gains are flat in the step from 0.005 to 0.02 m with the exact costmap, and a step of a fifth of a cell keeps the
grid costmap's cost steps from dominating the difference. The measured yaw rate enters only the initial speed's clamp
(the last command within az_max·T = 0.175 rad/s of it), which small perturbations never reach: its channel is skipped."""


BRINGUP_DEFAULTS = ("critics",)
"""The fields whose default is nav2_bringup's, not the source's declaration (`controllers.registry`): MPPI's source
declares no critics (an optimizer without them weighs nothing), so the default is bringup's list. Every other field's
default is the registry's (tests/test_controllers_plan.py)."""


@dataclass(frozen=True)
class MPPIParams:
    """MPPI's parameters (Nav2's names; defaults from ``src/optimizer.cpp`` and the critics' sources).

    Attributes
    ----------
    model_dt : float
        s (0.05).
    time_steps : int
        (56).
    batch_size : int
        (1000).
    iteration_count : int
        (1).
    temperature : float
        (0.3).
    gamma : float
        (0.015).
    vx_max, vx_min : float
        m/s (0.5, −0.35).
    wz_max : float
        rad/s (1.9).
    ax_max, ax_min : float
        m/s² (3.0, −3.0).
    az_max : float
        rad/s² (3.5).
    vx_std, wz_std : float
        Noise, m/s and rad/s (0.2, 0.4).
    model_delay_vx, model_delay_wz : float
        s (0, 0).
    open_loop : bool
        (False).
    sgf_order : int
        1 or 2 (2).
    retry_attempt_limit : int
        (1).
    regenerate_noises : bool
        (False).
    critics : tuple of str
        The critics, in order (`DEFAULT_CRITICS`).
    ConstraintCritic, CostCritic, ObstaclesCritic, GoalCritic, GoalAngleCritic, PathAlignCritic, PathFollowCritic, PathAngleCritic, PreferForwardCritic
        Each critic's parameters (Nav2's namespaces).
    prune_distance : float
        The controller server's ``prune_distance``, m (2.0).
    controller_frequency : float
        The controller server's rate, Hz (20.0); 1/rate must not exceed ``model_dt``.
    track_unknown_space : bool
        The costmap's; unknown cells (and points off the local costmap) are collisions when False (False).
    """

    model_dt: float = 0.05
    time_steps: int = 56
    batch_size: int = 1000
    iteration_count: int = 1
    temperature: float = 0.3
    gamma: float = 0.015
    vx_max: float = 0.5
    vx_min: float = -0.35
    wz_max: float = 1.9
    ax_max: float = 3.0
    ax_min: float = -3.0
    az_max: float = 3.5
    vx_std: float = 0.2
    wz_std: float = 0.4
    model_delay_vx: float = 0.0
    model_delay_wz: float = 0.0
    open_loop: bool = False
    sgf_order: int = 2
    retry_attempt_limit: int = 1
    regenerate_noises: bool = False
    critics: tuple = DEFAULT_CRITICS
    ConstraintCritic: ConstraintCritic = field(default_factory=ConstraintCritic)
    CostCritic: CostCritic = field(default_factory=CostCritic)
    ObstaclesCritic: ObstaclesCritic = field(default_factory=ObstaclesCritic)
    GoalCritic: GoalCritic = field(default_factory=GoalCritic)
    GoalAngleCritic: GoalAngleCritic = field(default_factory=GoalAngleCritic)
    PathAlignCritic: PathAlignCritic = field(default_factory=PathAlignCritic)
    PathFollowCritic: PathFollowCritic = field(default_factory=PathFollowCritic)
    PathAngleCritic: PathAngleCritic = field(default_factory=PathAngleCritic)
    PreferForwardCritic: PreferForwardCritic = field(default_factory=PreferForwardCritic)
    prune_distance: float = PRUNE_DISTANCE
    controller_frequency: float = 20.0
    track_unknown_space: bool = False

    def __post_init__(self):
        for name in ("model_dt", "temperature", "controller_frequency", "prune_distance", "vx_max", "wz_max", "ax_max", "az_max"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6))
        for name in ("gamma", "vx_std", "wz_std", "model_delay_vx", "model_delay_wz"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6, low_open=False))
        object.__setattr__(self, "vx_min", check_number("vx_min", self.vx_min, -1e6, self.vx_max, high_open=False))
        object.__setattr__(self, "ax_min", -abs(check_number("ax_min", self.ax_min, -1e6, 1e6)))
        object.__setattr__(self, "time_steps", check_integer("time_steps", self.time_steps, 2, 100_000))
        object.__setattr__(self, "batch_size", check_integer("batch_size", self.batch_size, 1, 10_000_000))
        object.__setattr__(self, "iteration_count", check_integer("iteration_count", self.iteration_count, 1, 1000))
        object.__setattr__(self, "retry_attempt_limit", check_integer("retry_attempt_limit", self.retry_attempt_limit, 0, 1000))
        if self.sgf_order not in (1, 2):
            object.__setattr__(self, "sgf_order", 2)  # Nav2 warns and takes 2
        unknown = [c for c in self.critics if c not in CRITIC_NAMES]
        if unknown:
            raise ValueError(f"critics must be among {', '.join(CRITIC_NAMES)}; got {', '.join(unknown)}")
        if self.CostCritic.consider_footprint or self.ObstaclesCritic.consider_footprint:
            raise ValueError("consider_footprint: only a circular robot (point costs) is modelled; use False")
        if 1.0 / self.controller_frequency > self.model_dt + 1e-6:
            raise ValueError(f"the controller period 1/controller_frequency = {1.0 / self.controller_frequency:g} s is longer than "
                             f"model_dt = {self.model_dt:g} s; Nav2's MPPI refuses it (set model_dt to the period)")

    @property
    def controller_period(self) -> float:
        """1/``controller_frequency``, s."""
        return 1.0 / self.controller_frequency

    @property
    def shift_control_sequence(self) -> bool:
        """The sequence shifts each cycle: the controller period equals ``model_dt`` (``Optimizer::setOffset``)."""
        return abs(self.controller_period - self.model_dt) < 1e-6

    def replace(self, **changes) -> "MPPIParams":
        """A copy with some parameters changed (validated again).

        Parameters
        ----------
        **changes
            Parameter values.
        """
        return replace(self, **changes)

    @classmethod
    def bringup(cls, **changes) -> "MPPIParams":
        """nav2_bringup's configuration (``nav2_bringup/params/nav2_params.yaml``, ``FollowPath``), with `changes`.

        Parameters
        ----------
        **changes
            Parameter values over the file's.
        """
        base = dict(batch_size=2000, regenerate_noises=True,
                    CostCritic=CostCritic(near_goal_distance=1.0),
                    PathAlignCritic=PathAlignCritic(cost_weight=14.0, max_path_occupancy_ratio=0.05),
                    PathFollowCritic=PathFollowCritic(offset_from_furthest=5),
                    PathAngleCritic=PathAngleCritic(cost_weight=2.0, max_angle_to_furthest=1.0))
        return cls(**{**base, **changes})


@dataclass(frozen=True)
class MPPIMemory:
    """The optimizer's state between cycles (module docstring).

    Attributes
    ----------
    vx, wz : ndarray of float32
        The control sequence, (time_steps,).
    history : ndarray of float32
        The last four sent commands (vx, wz), (4, 2), oldest first (the filter's).
    last_command : ndarray of float32
        (vx, wz) sent last.
    delay_vx, delay_wz : ndarray of float32
        The motion model's command history for the model delay (its length in model steps).
    noise_vx, noise_wz : ndarray of float32 or None
        The noise, (time_steps, batch_size) (None when regenerated every iteration).
    """

    vx: np.ndarray
    wz: np.ndarray
    history: np.ndarray
    last_command: np.ndarray
    delay_vx: np.ndarray
    delay_wz: np.ndarray
    noise_vx: np.ndarray | None
    noise_wz: np.ndarray | None


def with_speed(params: MPPIParams, V: float) -> MPPIParams:
    """The parameters with ``vx_max`` = V (m/s).

    Parameters
    ----------
    params : MPPIParams
    V : float
        m/s.
    """
    return params.replace(vx_max=V)


def nominal_speed(params: MPPIParams) -> float:
    """The speed to start from when looking for the cruising speed: ``vx_max``, m/s.

    Parameters
    ----------
    params : MPPIParams
    """
    return params.vx_max


def _delay_steps(delay: float, dt: float) -> int:
    """``MotionModel::offsetSteps``: a delay in whole model steps, rounded to the nearest."""
    return 0 if delay <= 0.0 or dt <= 0.0 else int(math.floor(delay / dt + 0.5))


def _noise(params: MPPIParams, rng):
    """Noise of each axis, (time_steps, batch) — time along the first axis, as Eigen's column-major storage."""
    shape = (params.time_steps, params.batch_size)
    return F(params.vx_std) * rng.standard_normal(shape, dtype=F), F(params.wz_std) * rng.standard_normal(shape, dtype=F)


def _reset(params: MPPIParams, rng) -> MPPIMemory:
    """``Optimizer::reset``: zero sequence, history and commands; the noise drawn anew (once, or every iteration)."""
    n = params.time_steps
    zeros = np.zeros(n, dtype=F)
    noise = (None, None) if params.regenerate_noises else _noise(params, rng)
    return MPPIMemory(zeros, zeros.copy(), np.zeros((4, 2), dtype=F), np.zeros(2, dtype=F),
                      np.zeros(_delay_steps(params.model_delay_vx, params.model_dt), dtype=F),
                      np.zeros(_delay_steps(params.model_delay_wz, params.model_dt), dtype=F), *noise)


def _initial_speed(params: MPPIParams, state: RobotState, last):
    """``Optimizer::prepare``'s initial speed (vx, wz): the last command within one period's accelerations of the measured."""
    if params.open_loop:
        return F(last[0]), F(last[1])
    dt = params.controller_period
    vx = min(max(float(last[0]), state.v + dt * params.ax_min), state.v + dt * params.ax_max)
    wz = min(max(float(last[1]), state.w - dt * params.az_max), state.w + dt * params.az_max)
    return F(vx), F(wz)


def _rate_limit(out, controls, bounds):
    """out[i] = controls[i − 1] within bounds(out[i − 1]) along the first axis (in place; out[0] is given)."""
    for i in range(1, controls.shape[0]):
        lo, hi = bounds(out[i - 1])
        np.minimum(np.maximum(controls[i - 1], lo, out=out[i]), hi, out=out[i])


def _rollout_velocities(params: MPPIParams, speed, cvx, cwz, memory: MPPIMemory):
    """``MotionModel::predict`` (DiffDrive): the rollout's velocities, (time_steps, batch) each (module docstring, 3)."""
    dt = F(params.model_dt)
    max_dvx, min_dvx, max_dwz = dt * F(params.ax_max), dt * F(params.ax_min), dt * F(params.az_max)
    vx, wz = np.empty_like(cvx), np.empty_like(cwz)
    vx[0], wz[0] = speed
    if min_dvx == -max_dvx:  # symmetric limits: the sign of the previous speed does not matter
        _rate_limit(vx, cvx, lambda prev: (prev - max_dvx, prev + max_dvx))
    else:
        _rate_limit(vx, cvx, lambda prev: (np.where(prev > 0, prev + min_dvx, prev - max_dvx), np.where(prev > 0, prev + max_dvx, prev - min_dvx)))
    _rate_limit(wz, cwz, lambda prev: (prev - max_dwz, prev + max_dwz))
    for velocities, history in ((vx, memory.delay_vx), (wz, memory.delay_wz)):
        offset = history.size
        if offset > 0:  # applyDelayShift: shift by offset − 1, fill steps 1 … offset − 1 with the commands in flight
            steps = velocities.shape[0]
            if offset < steps:
                velocities[offset:] = velocities[1:steps - offset + 1].copy()
            for j in range(1, min(offset, steps)):
                velocities[j] = history[j]
    return vx, wz


def _integrate(params: MPPIParams, state: RobotState, vx, wz):
    """``integrateStateVelocities``: poses (x, y, yaw), (time_steps, batch) each, by Euler steps of ``model_dt``."""
    dt = F(params.model_dt)
    n = vx.shape[0]
    yaws, x, y = (np.empty((n + 1, vx.shape[1]), dtype=F) for _ in range(3))  # the start, then the increments
    yaws[0], x[0], y[0] = F(state.yaw), F(state.x), F(state.y)
    np.multiply(wz, dt, out=yaws[1:])
    _accumulate(yaws)
    dist = vx * dt
    np.multiply(dist, np.cos(yaws[:-1]), out=x[1:])
    np.multiply(dist, np.sin(yaws[:-1]), out=y[1:])
    _accumulate(x)
    _accumulate(y)
    return x[1:], y[1:], yaws[1:]


def _accumulate(a):
    """Running sums down the first axis, in place and in order (float32 additions as Nav2's loop makes them)."""
    for i in range(1, a.shape[0]):
        np.add(a[i - 1], a[i], out=a[i])
    return a


def savitzky_golay(sequence, history, order: int = 2):
    """``utils::savitskyGolayFilter`` on one axis: every element but the last, over the four sent commands before it.

    Parameters
    ----------
    sequence : ndarray of float32
        The control sequence of one axis, (time_steps,).
    history : ndarray of float32
        The last four sent values of that axis, oldest first.
    order : int
        1 (moving average of nine) or 2 (Savitzky–Golay, quadratic, nine points).

    Returns
    -------
    ndarray of float32
        The filtered sequence (unchanged when it has fewer than 21 elements, as Nav2 skips it).
    """
    n = sequence.size - 1
    if n < 20:
        return sequence
    taps = np.full(9, 1.0 / 9.0, dtype=F) if order == 1 else np.array([-21, 14, 39, 54, 59, 54, 39, 14, -21], dtype=F) / F(231.0)
    extended = np.concatenate([history, sequence, np.full(4, sequence[-1], dtype=F)]).astype(F)
    windows = np.lib.stride_tricks.sliding_window_view(extended, 9)[:n]
    out = sequence.copy()
    out[:n] = np.sum(windows * taps, axis=1, dtype=F)
    return out


def _clamp_scalar(last, value, min_delta, max_delta):
    """``utils::clampVelocityByAccel`` on scalars."""
    if last >= 0:
        return min(last + max_delta, max(value, last + min_delta))
    return min(last - min_delta, max(value, last - max_delta))


def _constrain(params: MPPIParams, vx, wz, speed):
    """``applyControlSequenceConstraints``: limits along the sequence, the first step within one period of the speed."""
    v_in, w_in = vx.tolist(), wz.tolist()
    if params.shift_control_sequence:
        v_in[0], w_in[0] = float(speed[0]), float(speed[1])
    last_v, last_w = float(speed[0]), float(speed[1])
    vmin, vmax, wmax = params.vx_min, params.vx_max, params.wz_max
    v_out, w_out = [], []
    for i in range(len(v_in)):  # double precision between float32 values: the results differ by at most a float32 rounding
        dt = params.controller_period if i == 0 else params.model_dt
        a_z = dt * params.az_max
        last_v = _clamp_scalar(last_v, min(vmax, max(v_in[i], vmin)), dt * params.ax_min, dt * params.ax_max)
        last_w = _clamp_scalar(last_w, min(wmax, max(w_in[i], -wmax)), -a_z, a_z)
        v_out.append(last_v)
        w_out.append(last_w)
    return np.array(v_out, dtype=F), np.array(w_out, dtype=F)


def _iterate(params: MPPIParams, state, data: CriticData, vx, wz, history, speed, memory, rng):
    """One iteration (module docstring, 2–5): the new sequence (vx, wz) and filter history (`data` carries the costs)."""
    if params.shift_control_sequence:
        vx, wz = vx.copy(), wz.copy()
        vx[0], wz[0] = speed
    else:
        dt = F(params.controller_period)
        vx, wz = vx.copy(), wz.copy()
        vx[0] = F(_clamp_scalar(speed[0], vx[0], dt * F(params.ax_min), dt * F(params.ax_max)))
        wz[0] = F(_clamp_scalar(speed[1], wz[0], -dt * F(params.az_max), dt * F(params.az_max)))
    nvx, nwz = (memory.noise_vx, memory.noise_wz) if memory.noise_vx is not None else _noise(params, rng)
    cvx, cwz = nvx + vx[:, None], nwz + wz[:, None]
    rvx, rwz = _rollout_velocities(params, speed, cvx, cwz, memory)
    data.rollout(rvx, rwz, *_integrate(params, state, rvx, rwz))
    score(data)
    data.costs += F(params.gamma / params.vx_std ** 2) * (vx @ (cvx - vx[:, None])).astype(F)
    if params.wz_std > 0:
        data.costs += F(params.gamma / params.wz_std ** 2) * (wz @ (cwz - wz[:, None])).astype(F)
    costs = data.costs
    weights = np.exp(-(costs - costs.min()) / F(params.temperature)).astype(F)
    weights /= weights.sum(dtype=F)
    new_vx, new_wz = (cvx @ weights).astype(F), (cwz @ weights).astype(F)
    new_vx, new_wz = savitzky_golay(new_vx, history[:, 0], params.sgf_order), savitzky_golay(new_wz, history[:, 1], params.sgf_order)
    if params.time_steps - 1 >= 20:
        offset = 1 if params.shift_control_sequence else 0
        history = np.concatenate([history[1:], [[new_vx[offset], new_wz[offset]]]]).astype(F)
    new_vx, new_wz = _constrain(params, new_vx, new_wz, speed)
    return new_vx, new_wz, history


def _push(buffer, value):
    return np.concatenate([buffer[1:], [F(value)]]).astype(F) if buffer.size else buffer


def command(state: RobotState, plan, costmap, params: MPPIParams = MPPIParams(), rng=None, memory: MPPIMemory | None = None) -> Command:
    """One cycle of Nav2's MPPI (module docstring).

    Parameters
    ----------
    state : RobotState
        Pose and measured velocity.
    plan : Plan
        The global plan.
    costmap : CorridorCostmap
        The local costmap.
    params : MPPIParams
    rng : numpy.random.Generator, optional
        The noise's source (default: a Generator seeded with 0).
    memory : MPPIMemory, optional
        The optimizer's state from the previous cycle (None: a reset).

    Returns
    -------
    Command
        With the `MPPIMemory` for the next cycle.

    Raises
    ------
    NoValidControl
        When every trajectory collides twice in a row (after the reset in between).
    """
    rng = np.random.default_rng(0) if rng is None else rng
    memory = _reset(params, rng) if memory is None else memory
    window = costmap.window(state.x, state.y)
    part = local_plan(plan, state, window, params.prune_distance)
    speed = _initial_speed(params, state, memory.last_command)  # prepare: once per cycle, not again after a reset
    data = CriticData(params, state, part, costmap, window)
    for attempt in range(params.retry_attempt_limit + 1):
        vx, wz, history = memory.vx, memory.wz, memory.history
        for _ in range(params.iteration_count):
            vx, wz, history = _iterate(params, state, data, vx, wz, history, speed, memory, rng)
        if not data.fail:
            break
        memory = _reset(params, rng)
    else:
        raise NoValidControl("MPPI: every sampled trajectory collides (Optimizer fail to compute path)")
    offset = 1 if params.shift_control_sequence else 0
    sent = np.array([vx[offset], wz[offset]], dtype=F)
    if params.shift_control_sequence:
        vx, wz = np.concatenate([vx[1:], vx[-1:]]), np.concatenate([wz[1:], wz[-1:]])
    out = MPPIMemory(vx, wz, history, sent, _push(memory.delay_vx, sent[0]), _push(memory.delay_wz, sent[1]),
                     memory.noise_vx, memory.noise_wz)
    return Command(float(sent[0]), float(sent[1]), out)
