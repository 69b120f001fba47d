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
quantized (DWB: a lattice of velocity samples and of costmap cells) is linearised over `seeds` independent
draws — MPPI's noise, and for every controller with ``RANDOM_PHASE`` the robot's place relative to the plan's
poses and the costmap's cells — with common random numbers between the + and − perturbations; the result is
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

__all__ = ["LateralGains", "linearize", "equilibrium_speed", "configure", "warm_up", "PLAN_BEHIND", "PLAN_AHEAD"]

PLAN_BEHIND = 1.0
"""Plan behind the robot's start, m: within the closest pose's search distance of a 3 m local costmap (1.5 m)."""

PLAN_AHEAD = 10.0
"""Plan ahead of the robot's position after the warm-up, m: far beyond the prune distance and the window, so no goal is near."""


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
        out.update(N=self.N, NV=self.NV)
        return out


def _module(name: str):
    from . import controller_module

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


def _decide(module, params, plan, costmap, state, memory, rng):
    return module.command(state, plan, costmap, params, rng=copy.deepcopy(rng), memory=memory)


def equilibrium_speed(name: str, params, costmap, *, T: float = 0.05, spacing: float = 0.05, cycles: int = 8, seed: int = 0) -> float:
    """The forward speed the controller commands on the centre line, m/s: the last command of a warm-up.

    The warm-up (`warm_up`) runs the controller's ``WARMUP_CYCLES``, at least `cycles`, the robot advancing at its
    commanded speed and measuring it (the lookahead of RPP scales with the measured speed; MPPI's sequence has to
    converge).

    Parameters
    ----------
    name : str
        The controller.
    params : dataclass
        Its parameters.
    costmap : CorridorCostmap
        The corridor (or free space).
    T : float
        Controller period, s.
    spacing : float
        The plan's poses, m.
    cycles : int
        The fewest cycles.
    seed : int
        The controller's random numbers.
    """
    module = _module(name)
    cycles = max(int(cycles), int(getattr(module, "WARMUP_CYCLES", 0)))
    plan = straight_plan(PLAN_BEHIND + PLAN_AHEAD + 2.0 * module.nominal_speed(params) * cycles * T, spacing, x0=-PLAN_BEHIND)
    _, _, _, v = warm_up(name, params, plan, costmap, x=0.0, T=T, rng=np.random.default_rng(seed), cycles=cycles)
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


def linearize(name: str, params, costmap, *, T: float = 0.05, draws: int = 1, seed: int = 0, spacing: float = 0.05,
              steps: tuple | None = None) -> LateralGains:
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
    draws : int
        Independent draws (seeds ``seed`` … ``seed + draws − 1``).
    seed : int
        The first draw's seed.
    spacing : float
        Between the plan's poses, m.
    steps : (float, float, float), optional
        The steps in e_y (m), e_θ (rad) and ω_m (rad/s); default the controller's ``LINEARIZATION_STEPS``.
    """
    module = _module(name)
    draws = check_integer("draws", draws, 1, 100_000)
    T = check_number("T", T, 0.0, 100.0, unit="s")
    hy, ht, hw = module.LINEARIZATION_STEPS if steps is None else tuple(float(s) for s in steps)
    random_phase = bool(getattr(module, "RANDOM_PHASE", False))
    cycles = int(getattr(module, "WARMUP_CYCLES", 0))
    if cycles == 0:  # a controller without memory: its speed's fixed point (RPP's lookahead follows the measured speed)
        V = equilibrium_speed(name, params, costmap, T=T, spacing=spacing, seed=seed)
    plan = straight_plan(PLAN_BEHIND + PLAN_AHEAD + 2.0 * module.nominal_speed(params) * cycles * T + spacing, spacing, x0=-PLAN_BEHIND)
    rows, speeds = [], []
    for d in range(draws):
        rng = np.random.default_rng(seed + d)
        phase = float(rng.uniform(-0.5, 0.5)) if random_phase else 0.0
        memory, pruned, x, v = warm_up(name, params, plan, costmap, x=phase * spacing, T=T, rng=rng)
        if cycles == 0:
            v = V
        speeds.append(v)

        def w(ey=0.0, et=0.0, wm=0.0):
            return _decide(module, params, pruned, costmap, RobotState(x, ey, et, v, wm), memory, rng).w

        rows.append(((w(-hy) - w(hy)) / (2 * hy), (w(et=-ht) - w(et=ht)) / (2 * ht),
                     (w(wm=hw) - w(wm=-hw)) / (2 * hw) if hw > 0 else 0.0, w()))
    a = np.array(rows)
    mean = a.mean(axis=0)
    se = a.std(axis=0, ddof=1) / math.sqrt(draws) if draws > 1 else np.zeros(4)
    return LateralGains(name, float(np.mean(speeds)), *(float(m) for m in mean), *(float(e) for e in se), (hy, ht, hw), draws)
