"""The lateral gains of a Nav2 controller, by numeric linearisation of its decision about a straight plan.

The robot sits on a straight plan (the centre line of a corridor, or a plan in free space) heading along it at
the speed the controller itself chooses there (`equilibrium_speed`); the decision is perturbed in the lateral
offset e_y (m, to the left), the heading error e_θ (rad) and the measured yaw rate ω_m (rad/s), one at a time,
and the commanded yaw rate read back:

    k_y = −∂ω/∂e_y (1/(m·s)),   k_θ = −∂ω/∂e_θ (1/s),   k_ω = ∂ω/∂ω_m,

by central differences, ω(+h) − ω(−h) over 2h, with a step h chosen from the algorithm's own resolution (each
controller's ``LINEARIZATION_STEPS``, with its reason). A linear lateral controller ω = −k_θ·e_θ − k_y·e_y is
Koren & Borenstein's steering command u = −kθ − K·y with k = k_θ and N = k_y/k_θ, so NV = k_y·V/k_θ
(`LateralGains.NV`; docs/controllers.md).

Controllers with memory (MPPI's control sequence, DWB's oscillation flags) are first warmed up: ``WARMUP_CYCLES``
cycles on the centre line, the robot advancing at the speed it commands and measuring that speed, so that the memory
is the one the controller carries while tracking; every perturbation then starts from that same memory, and V is
the warm-up's last command (its mean over the draws). A sampling controller (MPPI) or one whose decision is
quantized (DWB: a lattice of velocity samples and of costmap cells) is linearised over `draws` independent
draws — MPPI's noise, and for every controller with ``RANDOM_PHASE`` the robot's place relative to the plan's
poses and the costmap's cells (``CorridorCostmap.lattice``, uniform over a cell) — with common random numbers
between the + and − perturbations; the result is
the mean and its standard error over the draws (`LateralGains.k_y_se`, …). A deterministic, smooth controller
(RPP, Graceful) needs one draw at phase 0 (the robot on a pose of the plan) and has no sampling error.
"""

from __future__ import annotations

import math
import copy
from dataclasses import dataclass, fields

import numpy as np

from ..checks import check_integer, check_number
from .base import RobotState
from .plan import prune, straight_plan

__all__ = ["LateralGains", "ImpulseResponse", "linearize", "equilibrium_speed", "configure", "warm_up", "centre_plan", "PLAN_BEHIND",
           "PLAN_AHEAD"]

PLAN_BEHIND = 1.0
"""Plan behind the robot's start, m: within the closest pose's search distance of a 3 m local costmap (1.5 m)."""

PLAN_AHEAD = 10.0
"""Plan ahead of the robot's position after the warm-up, m: far beyond the prune distance and the window, so no goal is near."""


@dataclass(frozen=True)
class ImpulseResponse:
    """A controller's response over several cycles to a perturbation at one (its memory: MPPI's sequence and filter).

    Element j is the response j cycles after the perturbation (j = 0: the one-step gain), the robot back on the
    centre line after it; ω_j = −Σ_i (y_i·e_y,(j−i) + theta_i·e_θ,(j−i)) + Σ_i w_i·ω_m,(j−i) to first order.

    Attributes
    ----------
    y : tuple of float
        −∂ω_j/∂e_y,0, 1/(m·s).
    theta : tuple of float
        −∂ω_j/∂e_θ,0, 1/s.
    w : tuple of float
        ∂ω_j/∂ω_m,0.
    y_se, theta_se, w_se : tuple of float
        Their standard errors over the draws.
    """

    y: tuple
    theta: tuple
    w: tuple
    y_se: tuple
    theta_se: tuple
    w_se: tuple

    @property
    def cycles(self) -> int:
        """Cycles measured."""
        return len(self.y)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {k: list(v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class LateralGains:
    """A controller's linearised lateral decision about a straight plan (module docstring).

    Attributes
    ----------
    controller : str
        Its name (``rpp``, ``graceful``, ``mppi``, ``dwb``).
    V : float
        The forward speed it commands on the plan, m/s.
    k_y : float
        −∂ω/∂e_y, 1/(m·s).
    k_theta : float
        −∂ω/∂e_θ, 1/s.
    k_w : float
        ∂ω/∂ω_m, the measured yaw rate's share of the command (dimensionless).
    w0 : float
        ω on the plan, unperturbed, rad/s (a sampling controller's bias; 0 by symmetry otherwise).
    k_y_se, k_theta_se, k_w_se, w0_se : float
        Standard errors of the means over the draws (0 with one draw).
    steps : (float, float, float)
        The central differences' steps h in e_y (m), e_θ (rad) and ω_m (rad/s).
    draws : int
        Independent draws averaged.
    memory : ImpulseResponse or None
        The response over the following cycles, for a controller with memory (None: one cycle measured).
    """

    controller: str
    V: float
    k_y: float
    k_theta: float
    k_w: float
    w0: float
    k_y_se: float
    k_theta_se: float
    k_w_se: float
    w0_se: float
    steps: tuple
    draws: int
    memory: ImpulseResponse | None = None

    @property
    def N(self) -> float:
        """k_y/k_θ, 1/m: KB's environment gain N of the equivalent steering loop."""
        return self.k_y / self.k_theta

    @property
    def NV(self) -> float:
        """k_y·V/k_θ, 1/s: KB's NV with steering gain k = k_θ."""
        return self.k_y * self.V / self.k_theta

    def to_dict(self) -> dict:
        """The fields and N, NV as a JSON-ready dict (SI units)."""
        out = dict(self.__dict__)
        out["steps"] = list(self.steps)
        out["memory"] = self.memory.to_dict() if self.memory is not None else None
        out.update(N=self.N, NV=self.NV)
        return out


def centre_plan(length: float, spacing: float):
    """A straight plan along y = 0 from `PLAN_BEHIND` behind x = 0 over `length`, with a pose at x = 0.

    Parameters
    ----------
    length : float
        Ahead of x = 0, m.
    spacing : float
        Between poses, m.
    """
    behind = spacing * math.ceil(PLAN_BEHIND / spacing - 1e-9)
    return straight_plan(behind + length, spacing, x0=-behind)


def _module(name: str):
    from .base import controller_module

    return controller_module(name)


def configure(name: str, params, *, V: float | None = None, T: float | None = None):
    """A controller's parameters set to cruise at V and run every T (where it has such parameters).

    Parameters
    ----------
    name : str
        The controller.
    params : dataclass
        Its parameters.
    V : float, optional
        Cruising speed, m/s (the module's ``with_speed``).
    T : float, optional
        Controller period, s: ``controller_frequency`` = 1/T where the parameters have it.
    """
    if V is not None:
        params = _module(name).with_speed(params, check_number("V", V, 0.0, 100.0, unit="m/s"))
    if T is not None and "controller_frequency" in {f.name for f in fields(params)}:
        params = params.replace(controller_frequency=1.0 / check_number("T", T, 0.0, 100.0, unit="s"))
    return params


def equilibrium_speed(name: str, params, costmap, *, x: float = 0.0, spacing: float = 0.05, cycles: int = 8, seed: int = 0) -> float:
    """The forward speed a memoryless controller commands on the centre line at x, its measured speed fed back, m/s.

    A fixed-point iteration at one place (the lookahead of RPP scales with the measured speed); a controller with
    memory takes its warm-up's last command instead (`warm_up`).

    Parameters
    ----------
    name : str
        The controller.
    params : dataclass
        Its parameters.
    costmap : CorridorCostmap
        The corridor (or free space).
    x : float
        Where along the plan, m (0: on a pose).
    spacing : float
        The plan's poses, m.
    cycles : int
        Iterations.
    seed : int
        The controller's random numbers.
    """
    module = _module(name)
    plan = centre_plan(PLAN_AHEAD + abs(x), spacing)
    plan = prune(plan, RobotState(x, 0.0, 0.0), costmap.window(x, 0.0))
    rng = np.random.default_rng(seed)
    v, memory = module.nominal_speed(params), None
    for _ in range(int(cycles)):
        cmd = module.command(RobotState(x, 0.0, 0.0, v, 0.0), plan, costmap, params, rng=rng, memory=memory)
        v, memory = cmd.v, cmd.memory
    return float(v)


def warm_up(name: str, params, plan, costmap, *, x: float, T: float, rng, cycles: int | None = None):
    """A controller's memory after tracking the centre line for `cycles` cycles (module docstring).

    The robot starts at (x, 0) heading along the plan at the controller's nominal speed, advances at the speed it
    commands (v·T per cycle), and measures that speed and no yaw rate.

    Parameters
    ----------
    name : str
        The controller.
    params : dataclass
        Its parameters.
    plan : Plan
        A straight plan along y = 0.
    costmap : CorridorCostmap
        The corridor.
    x : float
        Where the warm-up starts along the plan, m.
    T : float
        Controller period, s.
    rng : numpy.random.Generator
        The controller's random numbers (advanced by the warm-up).
    cycles : int, optional
        Default the controller's ``WARMUP_CYCLES``.

    Returns
    -------
    (object, Plan, float, float)
        The memory, the plan as the controller server has pruned it, where the robot is (x, m) and its measured
        speed (m/s) after the warm-up.
    """
    module = _module(name)
    cycles = int(getattr(module, "WARMUP_CYCLES", 0)) if cycles is None else int(cycles)
    memory, v = None, module.nominal_speed(params)
    for _ in range(cycles):
        state = RobotState(x, 0.0, 0.0, v, 0.0)
        plan = prune(plan, state, costmap.window(x, 0.0))
        cmd = module.command(state, plan, costmap, params, rng=rng, memory=memory)
        memory, v = cmd.memory, cmd.v
        x += v * T
    return memory, prune(plan, RobotState(x, 0.0, 0.0), costmap.window(x, 0.0)), x, v


def _response(module, params, plan, costmap, T, memory, x, v, rng, channel: int, h: float, cycles: int):
    """ω over `cycles` cycles after a perturbation of size `h` in one channel (0: e_y, 1: e_θ, 2: ω_m) at the first.

    After the perturbed cycle the robot is back on the centre line, advancing at its commanded speed and measuring
    it, with no yaw rate; the controller's memory and random numbers are the warm-up's (common to every call).
    """
    rng = copy.deepcopy(rng)
    out = []
    for k in range(cycles):
        e = [0.0, 0.0, 0.0]
        if k == 0:
            e[channel] = h
        state = RobotState(x, e[0], e[1], v, e[2])
        plan = prune(plan, state, costmap.window(x, 0.0))
        cmd = module.command(state, plan, costmap, params, rng=rng, memory=memory)
        memory = cmd.memory
        out.append(cmd.w)
        x, v = x + cmd.v * T, cmd.v
    return np.array(out)


def _draw(module, name, params, plan, costmap, T, spacing, steps, cycles, seed, speed):
    """One draw: (V, w0, responses (3, cycles)): −∂ω/∂e_y, −∂ω/∂e_θ and ∂ω/∂ω_m at every cycle after the perturbation."""
    rng = np.random.default_rng(seed)  # the controller's: the same noise as a simulated run with this seed
    phase = 0.0
    if getattr(module, "RANDOM_PHASE", False):
        phase, ox, oy = np.random.default_rng([seed, 1]).uniform(-0.5, 0.5, 3)
        costmap = costmap.replace(lattice=(ox * costmap.resolution, oy * costmap.resolution))
    memory, pruned, x, v = warm_up(name, params, plan, costmap, x=phase * spacing, T=T, rng=rng)
    v = v if speed is None else speed
    w0 = _response(module, params, pruned, costmap, T, memory, x, v, rng, 0, 0.0, 1)[0]
    rows = np.zeros((3, cycles))
    for channel, (h, sign) in enumerate(zip(steps, (-1.0, -1.0, 1.0))):
        if h > 0:
            up, down = (_response(module, params, pruned, costmap, T, memory, x, v, rng, channel, s * h, cycles) for s in (1.0, -1.0))
            rows[channel] = sign * (up - down) / (2.0 * h)
    return v, w0, rows


def linearize(name: str, params, costmap, *, T: float = 0.05, draws: int | None = None, seed: int = 0, spacing: float = 0.05,
              steps: tuple | None = None, memory_cycles: int | None = None) -> LateralGains:
    """Numeric lateral gains of a controller about a straight plan (module docstring).

    Parameters
    ----------
    name : str
        ``rpp``, ``graceful``, ``mppi`` or ``dwb``.
    params : dataclass
        Its parameters (`configure` sets the speed and period).
    costmap : CorridorCostmap
        The corridor whose centre line is the plan (or free space, ``half_width=None``).
    T : float
        Controller period, s: the warm-up's advance per cycle.
    draws : int, optional
        Independent draws (seeds ``seed`` … ``seed + draws − 1``); default the controller's ``DRAWS`` (1).
    seed : int
        The first draw's seed.
    spacing : float
        Between the plan's poses, m.
    steps : (float, float, float), optional
        The steps in e_y (m), e_θ (rad) and ω_m (rad/s); default the controller's ``LINEARIZATION_STEPS`` (a step 0
        skips its channel: a controller that does not read it).
    memory_cycles : int, optional
        Cycles of the response to a perturbation to measure (`LateralGains.memory`); default the controller's
        ``MEMORY_CYCLES`` (1: the one-step gains only).
    """
    module = _module(name)
    draws = check_integer("draws", int(getattr(module, "DRAWS", 1)) if draws is None else draws, 1, 100_000)
    cycles = check_integer("memory_cycles", int(getattr(module, "MEMORY_CYCLES", 1)) if memory_cycles is None else memory_cycles, 1, 10_000)
    T = check_number("T", T, 0.0, 100.0, unit="s")
    steps = module.LINEARIZATION_STEPS if steps is None else tuple(float(s) for s in steps)
    warm = int(getattr(module, "WARMUP_CYCLES", 0))
    speed = None if warm else equilibrium_speed(name, params, costmap, spacing=spacing, seed=seed)  # memoryless: its fixed point
    reach = 2.0 * module.nominal_speed(params) * (warm + cycles) * T
    plan = centre_plan(PLAN_AHEAD + reach + spacing, spacing)
    results = [_draw(module, name, params, plan, costmap, T, spacing, steps, cycles, seed + d, speed) for d in range(draws)]
    V = np.array([r[0] for r in results])
    w0 = np.array([r[1] for r in results])
    taps = np.array([r[2] for r in results])  # (draws, 3, cycles)
    mean = taps.mean(axis=0)
    se = taps.std(axis=0, ddof=1) / math.sqrt(draws) if draws > 1 else np.zeros_like(mean)
    w0_se = float(w0.std(ddof=1) / math.sqrt(draws)) if draws > 1 else 0.0
    memory = ImpulseResponse(*(tuple(float(v) for v in mean[c]) for c in range(3)), *(tuple(float(v) for v in se[c]) for c in range(3))) if cycles > 1 else None
    return LateralGains(name, float(V.mean()), float(mean[0, 0]), float(mean[1, 0]), float(mean[2, 0]), float(w0.mean()),
                        float(se[0, 0]), float(se[1, 0]), float(se[2, 0]), w0_se, tuple(steps), draws, memory)
