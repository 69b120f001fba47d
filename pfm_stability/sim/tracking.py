"""Nav2's path-tracking controllers driving the simulator's robot along a straight plan (docs/controllers.md).

The robot is the VFF simulator's (docs/simulator.md, "Plant gain and dead time"): a yaw-rate motor
τω̇ + ω = g·u(t − D), heading θ̇ = ω, synchro-drive motion at the commanded forward speed, solved exactly
between samples (`sim.robot`). What computes u is now a Nav2 controller of `pfm_stability.controllers`, called
every period T as the controller server calls it. One step, for every member still running:

1. **Events** at t_k: a collision (in a corridor: the robot's disc of diameter W reaches the walls' cells,
   |lateral offset| + W/2 >= the walls' offset, checked at the samples), or the controller found no command
   at the previous sample (``no_valid_control``: Nav2's ``NoValidControl``, or the plan's closest pose off the
   local costmap).
2. **Measure**: the pose, and the measured velocity — the forward speed held over the last period and the
   motor's yaw rate ω(t_k) (odometry without noise or latency).
3. **Decide**: ``command(state, plan, costmap, params, rng, memory)``: the member's own seeded Generator, its
   memory carried from cycle to cycle.
4. **Command path** (`command_path`): the commanded yaw rate saturated at the robot's ``max_steering_rate``,
   before the plant gain, then the drive's velocity smoother when the robot has a ``yaw_accel_limit``
   (`sim.robot.CommandPath`, the VFF simulator's: at most R·T of change per period, from 0).
5. **Hold and delays**: held over the period; applied d periods late (compute delay), and reaching the motor D
   later, at t_k + m·T + ε (`sim.robot.delay_split`), so a period may hold two commands, each solved exactly. The
   forward speed is delayed by the compute delay only, as in the VFF simulator (the dead time is the motor's).
6. **Advance** over [t_k, t_k+1) (`sim.robot.advance_held`).

Frames: the simulator's x is lateral (the offset measured, to the plan's left) and y along the plan, θ from +y
towards +x (KB's). A controller sees the mirror image X = y, Y = x, yaw = θ, in which the plan runs along +X and
the yaw rate is θ̇: a command ω *is* the steering-rate command u of KB eq 6. The plan is a straight line of poses
every ``spacing`` (a planner's resolution), the costmap the corridor's (or free space). Before the run a
controller with memory is warmed up on the centre line (`controllers.linearize.warm_up`), then the robot starts
at ``offset`` with ``heading``; the lateral offset at every sample is measured by
`sim.metrics.oscillation_metrics`, the package's one estimator, whose verdict the validation bisects.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..checks import check_integer, check_number
from ..controllers.registry import NAV2_CONTROLLERS as CONTROLLER_NAMES
from ..controllers.costmap import CorridorCostmap
from ..controllers.base import NoValidControl, RobotState, controller_module, default_params
from ..controllers.linearize import configure
from ..controllers.plan import prune
from ..controllers.linearize import PLAN_AHEAD, centre_plan, warm_up
from ..parameters import TAU_RESOLUTION, Robot
from .events import Event
from .metrics import oscillation_metrics
from .results import BatchResult, RunResult, Trajectory
from .robot import CommandPath, advance_held, constant_input, constant_input_modes, delay_split, graded_rule, slow_rate
from .scenario import MeasureAxis, check_first_order

__all__ = ["TrackingScenario", "simulate_tracking", "command_path"]


@dataclass(frozen=True)
class TrackingScenario:
    """One run of a Nav2 controller along a straight plan, in free space or a corridor (module docstring).

    Attributes
    ----------
    controller : str
        ``rpp``, ``graceful``, ``mppi`` or ``dwb``.
    robot : Robot
        The plant: ``tau``, ``plant_gain``, ``dead_time``, ``max_steering_rate`` and ``W`` as the VFF simulator takes
        them; ``V`` is the speed the controller is set to cruise at (`controllers.configure`); ``k`` is not used.
    T : float
        Controller period, s (the controller server's 1/``controller_frequency``).
    params : dataclass, optional
        The controller's parameters (default Nav2's); speed and period are set from ``robot.V`` and ``T``.
    compute_delay : int
        d, periods (0 or 1).
    costmap : CorridorCostmap
        The corridor (``half_width``) or free space, its inflation, resolution and window.
    spacing : float
        Between the plan's poses, m.
    offset : float
        Start's lateral offset, m (to the left of the plan).
    heading : float
        Start's heading error, rad.
    duration : float
        s.
    seed : int
        The controller's random numbers (MPPI's noise).
    warmup : bool
        Warm the controller's memory up on the centre line before the start.
    """

    controller: str
    robot: Robot
    T: float
    params: object = None
    compute_delay: int = 0
    costmap: CorridorCostmap = field(default_factory=CorridorCostmap)
    spacing: float = 0.05
    offset: float = 0.02
    heading: float = 0.0
    duration: float = 20.0
    seed: int = 0
    warmup: bool = True

    name = "tracking"

    def __post_init__(self):
        if self.controller not in CONTROLLER_NAMES:
            raise ValueError(f"controller must be one of {', '.join(CONTROLLER_NAMES)}; got {self.controller!r}")
        object.__setattr__(self, "T", check_number("T", self.T, 0.0, 100.0, unit="s"))
        object.__setattr__(self, "compute_delay", check_integer("compute_delay", self.compute_delay, 0, 1))
        object.__setattr__(self, "spacing", check_number("spacing", self.spacing, 0.0, 10.0, unit="m"))
        object.__setattr__(self, "duration", check_number("duration", self.duration, 0.0, 1e5, unit="s"))
        object.__setattr__(self, "heading", check_number("heading", self.heading, -math.pi / 2, math.pi / 2, unit="rad"))
        walls = self.costmap.walls or (-math.inf, math.inf)
        object.__setattr__(self, "offset", check_number("offset", self.offset, walls[0] + 0.5 * self.robot.W, walls[1] - 0.5 * self.robot.W, unit="m"))
        if self.params is None:
            object.__setattr__(self, "params", default_params(self.controller))

    @property
    def measure(self) -> MeasureAxis:
        """The lateral offset is measured from the plan, over the whole run."""
        return MeasureAxis()

    def controller_params(self):
        """The controller's parameters set to cruise at ``robot.V`` every ``T`` (`controllers.configure`)."""
        return configure(self.controller, self.params, V=self.robot.V, T=self.T)

    def loop_order(self) -> int:
        """The linear-prediction order of the metrics: lateral offset, heading, the lag's rate, the commands on their way."""
        r = self.robot
        m, eps = delay_split(np.array([self.T]), np.array([self.compute_delay]), np.array([r.dead_time]))
        return int(r.tau >= TAU_RESOLUTION * self.T) + 2 + int(m[0]) + int(eps[0] > 0)

    def replace(self, **changes) -> "TrackingScenario":
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes
            Field values.
        """
        return replace(self, **changes)

    def inputs(self) -> dict:
        """Everything that defines the run, for reports (SI units)."""
        r = self.robot
        params = self.controller_params()
        return {
            "scenario": self.name, "controller": self.controller, "params": dict(params.__dict__),
            "V": r.V, "tau": r.tau, "W": r.W, "max_steering_rate_deg": math.degrees(r.max_steering_rate),
            "dead_time": r.dead_time, "plant_gain": r.plant_gain, "T": self.T, "compute_delay": self.compute_delay,
            "half_width": self.costmap.half_width, "exact_costmap": self.costmap.exact, "spacing": self.spacing,
            "offset": self.offset, "heading_deg": math.degrees(self.heading), "duration": self.duration,
            "seed": self.seed, "measure": self.measure.to_dict(),
        }


def command_path(w, previous, max_rate):
    """The yaw-rate command on its way from the controller to the drive: saturated at ±max_steering_rate (then the
    drive's velocity smoother, `robot.CommandPath`, as in the VFF simulator, when the robot has a yaw acceleration limit).

    The one place the command is shaped before the drive (module docstring, step 4).

    Parameters
    ----------
    w : ndarray
        The controllers' yaw-rate commands, rad/s.
    previous : ndarray
        What this function returned at the previous sample, rad/s (for a shaping that has memory).
    max_rate : ndarray
        ``max_steering_rate`` per member, rad/s.
    """
    return np.clip(w, -max_rate, max_rate)


class _Plant:
    """Per-member plant constants and the exact held-command solution over one period (module docstring, step 5)."""

    def __init__(self, scenarios):
        get = lambda f: np.array([f(s) for s in scenarios], dtype=float)
        self.T = get(lambda s: s.T)
        self.tau = get(lambda s: s.robot.tau)
        self.tau = np.where(self.tau < TAU_RESOLUTION * self.T, 0.0, self.tau)
        self.gain = get(lambda s: s.robot.plant_gain)
        self.max_rate = get(lambda s: s.robot.max_steering_rate)
        self.delayed = np.array([s.compute_delay == 1 for s in scenarios])
        self.lag, self.switch = delay_split(self.T, self.delayed.astype(np.int64), get(lambda s: s.robot.dead_time))
        self.steps = np.ceil(get(lambda s: s.duration) / self.T - 1e-9).astype(np.int64)
        self.history = int(np.max(np.minimum(self.lag, self.steps))) + 2
        slow = slow_rate(np.inf, self.max_rate, self.gain)
        split = self.switch > 0
        self.whole, self.split = np.flatnonzero(~split), np.flatnonzero(split)

        def coef(h, idx):
            return constant_input(self.tau[idx], graded_rule(h, *constant_input_modes(self.tau[idx]), slow[idx]))

        self.whole_coef = coef(self.T[self.whole], self.whole)
        self.before_coef = coef(self.switch[self.split], self.split)
        self.after_coef = coef(self.T[self.split] - self.switch[self.split], self.split)

    def advance(self, theta, omega, earlier, later, V, x, y):
        """(x, y, θ, ω) at t_k+1: the motor's input g·`earlier` for the first ε, g·`later` after (rad/s)."""
        out = [x.copy(), y.copy(), theta.copy(), omega.copy()]
        w, s, g = self.whole, self.split, self.gain
        if w.size:
            for a, b in zip(out, advance_held(self.whole_coef, theta[w], omega[w], g[w] * later[w], V[w], x[w], y[w])):
                a[w] = b
        if s.size:
            xs, ys, ts, os_ = advance_held(self.before_coef, theta[s], omega[s], g[s] * earlier[s], V[s], x[s], y[s])
            for a, b in zip(out, advance_held(self.after_coef, ts, os_, g[s] * later[s], V[s], xs, ys)):
                a[s] = b
        return tuple(out)


class _Members:
    """Each member's controller, plan, costmap, memory and Generator (module docstring, steps 2–3)."""

    def __init__(self, scenarios):
        self.scenarios = scenarios
        self.modules = [controller_module(s.controller) for s in scenarios]
        self.params = [s.controller_params() for s in scenarios]
        self.rngs = [np.random.default_rng(s.seed) for s in scenarios]
        self.plans, self.memory, self.start = [], [], []
        for s, p, rng in zip(scenarios, self.params, self.rngs):
            reach = 1.5 * s.robot.V * s.duration + PLAN_AHEAD
            cycles = int(getattr(controller_module(s.controller), "WARMUP_CYCLES", 0)) if s.warmup else 0
            plan = centre_plan(reach + 2.0 * s.robot.V * cycles * s.T, s.spacing)
            memory, plan, x, _ = warm_up(s.controller, p, plan, s.costmap, x=0.0, T=s.T, rng=rng, cycles=cycles)
            self.plans.append(plan)
            self.memory.append(memory)
            self.start.append(x)

    def decide(self, m: int, along: float, lateral: float, theta: float, v: float, omega: float):
        """Member m's command (v, ω) at its pose (sim frame: `along` = y, `lateral` = x); None if it has none.

        The plan handed over is pruned at the last closest pose, as the controller server keeps it (`Plan.pruned`).
        """
        s = self.scenarios[m]
        state = RobotState(along, lateral, theta, v, omega)
        self.plans[m] = plan = prune(self.plans[m], state, s.costmap.window(along, lateral))
        try:
            cmd = self.modules[m].command(state, plan, s.costmap, self.params[m], rng=self.rngs[m], memory=self.memory[m])
        except (NoValidControl, ValueError):
            return None
        self.memory[m] = cmd.memory
        return cmd.v, cmd.w

    def decide_all(self, k, T, running, alive, events, x, y, theta, v, omega):
        """Every running member's command at sample k (sim frame); a member without one gets its event and stops
        (`running`, `alive` and `events` updated in place). Returns (v, ω) arrays, 0 for the others."""
        v_cmd, w_cmd = np.zeros(x.size), np.zeros(x.size)
        for m in np.flatnonzero(running):
            cmd = self.decide(m, y[m], x[m], theta[m], v[m], omega[m])
            if cmd is None:
                events[m] = Event("no_valid_control", float(k * T[m]), float(x[m]), float(y[m]))
                alive[m] = running[m] = False
                continue
            v_cmd[m], w_cmd[m] = cmd
        return v_cmd, w_cmd


def simulate_tracking(scenarios, *, record: str = "offset", metrics: bool = True, progress=None) -> BatchResult:
    """Run Nav2 controllers on the simulator's robot, every scenario together (module docstring).

    Parameters
    ----------
    scenarios : sequence of TrackingScenario
    record : {"offset", "trajectory"}
        Keep the lateral offset only, or every sample's pose (sim frame) too.
    metrics : bool
        Measure the oscillation (`sim.metrics.oscillation_metrics`).
    progress : callable, optional
        ``progress(step, total)`` every 256 steps and at the end.

    Returns
    -------
    BatchResult
        One `RunResult` per scenario (its ``scenario`` the `TrackingScenario`).
    """
    scenarios = list(scenarios)
    if not scenarios or not all(isinstance(s, TrackingScenario) for s in scenarios):
        raise ValueError("scenarios must be one or more TrackingScenario")
    if record not in ("offset", "trajectory"):
        raise ValueError(f"record must be 'offset' or 'trajectory'; got {record!r}")
    started = time.perf_counter()
    for s in scenarios:
        check_first_order(s.robot)
    plant, members = _Plant(scenarios), _Members(scenarios)
    B = len(scenarios)
    x = np.array([s.offset for s in scenarios])  # lateral (ROS y)
    y = np.array(members.start)  # along the plan (ROS x)
    theta = np.array([s.heading for s in scenarios])
    omega = np.zeros(B)
    V0 = np.array([s.robot.V for s in scenarios])
    measured_v, pending_v, shaped = V0.copy(), V0.copy(), np.zeros(B)
    step = np.array([s.robot.yaw_accel_limit for s in scenarios]) * plant.T  # the velocity smoother's largest change a period
    line = CommandPath(B, plant.history, step if np.isfinite(step).any() else None)
    low = np.array([-math.inf if s.costmap.walls is None else s.costmap.walls[0] for s in scenarios])
    high = np.array([math.inf if s.costmap.walls is None else s.costmap.walls[1] for s in scenarios])
    half = np.array([0.5 * s.robot.W for s in scenarios])
    alive = np.ones(B, dtype=bool)
    events, done = [None] * B, np.zeros(B, dtype=np.int64)
    rec = np.zeros((int(plant.steps.max()) + 1, B, 3))
    total = int(plant.steps.max())
    for k in range(total + 1):
        due = alive & (k <= plant.steps)
        done[due] = k
        rec[k] = np.stack([x, y, theta], axis=1)
        hit = due & ((x + half >= high) | (x - half <= low))
        for m in np.flatnonzero(hit):
            events[m] = Event("collision", float(k * plant.T[m]), float(x[m]), float(y[m]))
        alive &= ~hit
        running = alive & (k < plant.steps)
        if not running.any():
            break
        v_cmd, w_cmd = members.decide_all(k, plant.T, running, alive, events, x, y, theta, measured_v, omega)
        shaped = np.where(running, command_path(w_cmd, shaped, plant.max_rate), shaped)
        if k == 0:
            pending_v = np.where(running, v_cmd, pending_v)
        line.push(k, shaped)
        later = line.back(k, plant.lag)
        earlier = line.back(k, plant.lag + 1) if plant.split.size else later
        applied_v = np.where(plant.delayed, pending_v, v_cmd)
        pending_v = np.where(running, v_cmd, pending_v)
        nx, ny, nt, no = plant.advance(theta, omega, earlier, later, applied_v, x, y)
        x, y, theta, omega = (np.where(running, new, old) for new, old in ((nx, x), (ny, y), (nt, theta), (no, omega)))
        measured_v = np.where(running, applied_v, measured_v)
        if not np.all(np.isfinite(x[running])):
            raise FloatingPointError(f"the tracking simulation became non-finite at step {k}")
        if progress is not None and k % 256 == 0:
            progress(k, total)
    seconds = time.perf_counter() - started
    if progress is not None:
        progress(total, total)
    runs = tuple(_result(s, rec[: done[m] + 1, m], done[m], events[m], metrics) for m, s in enumerate(scenarios))
    return BatchResult(runs, int(done.sum()), seconds) if record == "offset" else BatchResult(
        tuple(replace(r, trajectory=_trajectory(s, rec[: done[m] + 1, m])) for m, (s, r) in enumerate(zip(scenarios, runs))),
        int(done.sum()), seconds)


def _trajectory(s: TrackingScenario, rows) -> Trajectory:
    t = np.arange(rows.shape[0]) * s.T
    return Trajectory(t, rows[:, 0].copy(), rows[:, 1].copy(), rows[:, 2].copy())


def _result(s: TrackingScenario, rows, steps: int, event, want_metrics: bool) -> RunResult:
    t = np.arange(rows.shape[0]) * s.T
    offset = rows[:, 0].copy()
    m = None
    if want_metrics:
        m = oscillation_metrics(t, offset, s.T, order=s.loop_order(), collision_time=event.t if event and event.type == "collision" else None)
    walls = s.costmap.walls
    clearance = None if walls is None else float(min(walls[1] - np.max(offset), np.min(offset) - walls[0]) - 0.5 * s.robot.W)
    return RunResult(s, (event,) if event else (), m, float(steps * s.T), int(steps), t, offset, clearance)
