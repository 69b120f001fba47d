"""A disturbance of a given size: does a start that far off the equilibrium settle, or grow into a cycle? (docs/wobble.md)

The loop models decide small starts: below V* every small disturbance settles. The nonlinearities the linear
verdict leaves out act at finite amplitude — the drive's yaw acceleration limit (a velocity smoother) is linear
below its threshold and lags beyond it — so a large start can grow where a small one settles: the boundary depends
on the disturbance's size. It is read off the describing-function branch V(A) of the cycles
(`wobble.corridor_branch`, `wobble.wall_branch`; with the limiter `wobble.limited_branch`):

* **the start's amplitude.** A start at offset D from the equilibrium (heading 0, the robot not turning, the
  smoother's last output 0, the commands in flight the first one) puts a(V) on the loop's oscillatory mode: the
  sampled loop run from it with the drive's limiter and the field's own steering for a period and a quarter, its
  state projected on the critical pair of the closed-loop matrix at V and averaged over the last period
  (`start_amplitude`; the other modes decay faster). a/D is not 1: the start's commands in flight and the fast
  modes take their share (0.68–0.77 for CARMEL).
* **the boundary.** At a speed V the start settles when V <= V* and a(V) lies inside the innermost cycle of the
  branch at V; a cycle of amplitude A exists at V(A), so the start of size D grows for V above
  V*(D) = min(V*, min{V(A) : A <= a(V(A))}) (`disturbance_speed`): V* itself for a small start or a supercritical
  branch, lower where the branch bends below V* (a subcritical branch, or the limiter's lag).
* **past it** the start ends on the nearest stable cycle outward of a(V) (`WobbleBranch.cycles_at`), or at a wall
  when no cycle inside the clearance holds it (`Disturbance.reaches_wall`).

The start's transient is the sampled loop's with the field's steering and the drive's saturation and limiter (the
heading taken linear); the cycles are the describing function's. Measured against the simulator
(tests/test_rate_limit_disturbance.py, docs/wobble.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..checks import check_number
from ..io.serialize import json_number
from ..laws.force_law import ForceLaw
from .limiter import motor_loop
from .wobble import THIRD_HARMONIC_LIMIT, WobbleBranch, corridor_branch, corridor_steering, reported_cycle, wall_branch, wall_steering

__all__ = ["Disturbance", "start_amplitude", "disturbance_speed", "corridor_disturbance", "wall_disturbance"]


def start_amplitude(robot, controller, N: float, V: float, disturbance: float, model: str = "sampled", steering=None) -> float:
    """a: the lateral amplitude a start at offset D puts on the loop's oscillatory mode at speed V, m (module docstring).

    The sampled loop (T > 0; `models.sampled.command_form` in the motor's units, field gain K = g·k·N·V) runs from
    the start — offset D (y = x/V), heading and rate 0, the smoother's last output 0, every command in flight the
    first one the drive passes (`sim.engine`'s start) — with the drive's saturation at g·ω_max and its limiter at
    g·R·T on the command, and the field's own steering δ(x) when given (else −N·x): for a large start the limiter
    holds the first commands back for several periods, a transient the linear projection of the start itself
    misses (14 % on CARMEL with 2 rad/s², docs/wobble.md). Over the mode's period P (in samples) from P/4 on, the
    state's coordinate c on the eigenvector v of the oscillatory eigenvalue of largest modulus of the closed-loop
    matrix at K gives 2|c·v_y|·V, averaged (the nonlinear state is not the linear mode: its projection swings ±4 %
    with the phase). T = 0: the projection of the start itself on the continuous loop without the dead time.

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, g, D, τ_a, `max_steering_rate`, `yaw_accel_limit`.
    controller : parameters.Controller
        T, hold, compute delay.
    N : float
        The field's gain at the equilibrium, 1/m (> 0).
    V : float
        Speed, m/s (> 0).
    disturbance : float
        D, m (> 0).
    model : {"exact_delay", "sampled"}
        ``exact_delay`` takes the sampled loop's start too when T > 0 (its own start is a history, not a state).
    steering : callable, optional
        δ(x), rad, of the offset x from the equilibrium, m (`wobble.corridor_steering`, `wobble.wall_steering`).

    Returns
    -------
    float
        m; D itself when the loop has no oscillatory mode.
    """
    from ..models.sampled import closed_loop_matrix, command_form, continuous_plant

    g, gk = robot.plant_gain, robot.plant_gain * robot.k
    T = controller.T
    loop = motor_loop(robot, controller)
    if T == 0:
        loop = replace(loop, dead_time=0.0)
    K = gk * N * V
    plant = continuous_plant(loop, controller.hold)[0].shape[0]
    if T == 0:
        A, B, F0, F1 = continuous_plant(loop, controller.hold)
        lam, vectors = np.linalg.eig(A - B @ (F0 + K * F1)[None, :])
        state = np.zeros(plant)
        state[plant - 1] = disturbance / V
        oscillatory = np.flatnonzero(lam.imag > 1e-12)
        if oscillatory.size == 0:
            return float(disturbance)
        i = oscillatory[np.argmax(lam[oscillatory].real)]
        return float(2.0 * abs(np.linalg.solve(vectors, state.astype(complex))[i] * vectors[plant - 1, i]) * V)
    lam, vectors = np.linalg.eig(closed_loop_matrix(loop, K, controller.hold, controller.compute_delay))
    oscillatory = np.flatnonzero(lam.imag > 1e-12)
    if oscillatory.size == 0:
        return float(disturbance)
    i = oscillatory[np.argmax(np.abs(lam[oscillatory]))]
    row = np.linalg.inv(vectors)[i]
    period = 2.0 * math.pi / abs(np.angle(lam[i]))
    M, n, F0, F1 = command_form(loop, controller.hold, controller.compute_delay)
    command = controller.hold == "command"
    saturation = g * robot.max_steering_rate if command else math.inf
    step = g * robot.yaw_accel_limit * T if command else math.inf

    def computed(x):
        field = gk * steering(V * x[plant - 1]) if steering is not None else -K * x[plant - 1]
        return float(np.clip(-(F0 @ x) + field, -saturation, saturation))

    x = np.zeros(M.shape[0])
    x[plant - 1] = disturbance / V
    last = float(np.clip(computed(x), -step, step))
    x[plant:] = last  # the commands in flight at t_0: the first
    projections = []
    for k in range(int(math.ceil(1.25 * period)) + 1):
        if k >= 0.25 * period:
            projections.append(abs(row @ x))
        v = computed(x)
        last += float(np.clip(v - last, -step, step)) if math.isfinite(step) else v - last
        x = M @ x + n * last
    return float(2.0 * np.mean(projections) * abs(vectors[plant - 1, i]) * V)


def disturbance_speed(branch: WobbleBranch, robot, controller, disturbance: float, steering=None) -> tuple:
    """(V*(D), a): the speed at or below which a start of size D settles, m/s, and the start's amplitude there, m.

    V*(D) = min(V*, min{V(A) : A <= a(V(A))}) over the branch from its smallest amplitude (module docstring), the
    crossing A = a(V(A)) interpolated between branch points; a = `start_amplitude` at each point's speed.

    Parameters
    ----------
    branch : WobbleBranch
        The cycles (with its field gain `gain`).
    robot, controller : Robot, Controller
        The robot and controller of the branch.
    disturbance : float
        D, m.
    steering : callable, optional
        The field's δ(x) (`start_amplitude`).
    """
    A, S = branch.amplitudes, branch.speeds
    reach_of = _start_amplitudes(branch, robot, controller, disturbance, steering)
    best, at = branch.V_critical, reach_of(branch.V_critical)
    previous = None
    for a, v in zip(A, S):
        if not math.isfinite(v):  # no cycle of that amplitude (the heading swing or the saturation): the next may have one
            continue
        reach = reach_of(v) - a
        if reach < 0:
            if previous is not None:  # the crossing between the last point inside and this one
                a0, v0, r0 = previous
                t = r0 / (r0 - reach)
                v_cross = v0 + t * (v - v0)
                if v_cross < best:
                    best, at = v_cross, a0 + t * (a - a0)
            break
        if v < best:
            best, at = v, reach + a
        previous = (a, v, reach)
    return float(best), float(at)


_SPEEDS = 24
"""Speeds at which `disturbance_speed` runs the start (`start_amplitude`), interpolated between: a(V) is smooth in V."""


def _start_amplitudes(branch: WobbleBranch, robot, controller, disturbance: float, steering):
    """V ↦ a(V) over the branch's speeds: `start_amplitude` at `_SPEEDS` speeds from the branch's slowest to V*, linear between."""
    finite = branch.speeds[np.isfinite(branch.speeds)]
    lo = float(min(finite.min(), branch.V_critical)) if finite.size else branch.V_critical
    hi = float(max(finite.max(), branch.V_critical)) if finite.size else branch.V_critical
    grid = np.linspace(lo, hi, _SPEEDS) if hi > lo else np.array([lo])
    values = np.array([start_amplitude(robot, controller, branch.gain, v, disturbance, branch.model, steering) for v in grid])
    return lambda v: float(np.interp(v, grid, values))


@dataclass(frozen=True)
class Disturbance:
    """What a start of a given size does (module docstring; JSON ``corridor.disturbance``, ``wall.disturbance``).

    Attributes
    ----------
    disturbance : float
        D, the start's offset from the equilibrium, m.
    start_amplitude : float or None
        a = κ(V)·D at the robot's speed: what the start puts on the oscillatory mode, m.
    V_critical : float
        V*, m/s: the linear boundary (small starts).
    V_disturbance : float or None
        V*(D), m/s: the fastest speed at which a start of size D settles (nan when the branch is unavailable).
    settles : bool or None
        At the robot's speed, the start settles.
    amplitude : float or None
        The lateral amplitude of the cycle the start ends on, m (0 when it settles; None when it reaches a wall or the
        describing function is not trusted there, see `reason`).
    omega : float or None
        Its frequency, rad/s.
    reaches_wall : bool or None
        The start grows until the robot touches a wall.
    criticality : str or None
        The Hopf bifurcation at V*: ``"supercritical"`` or ``"subcritical"`` (the limiter is linear there: it does not
        change it).
    cycles_below_critical : bool or None
        Cycles exist below V* (the branch bends below it: subcritical, or the limiter's lag at finite amplitude): a
        large enough start grows where a small one settles.
    V_fold : float or None
        The slowest speed with a cycle inside the clearance, m/s (below it every start inside settles).
    yaw_accel_limit : float
        The limit R, rad/s² (inf: none).
    limiter_gain, limiter_lag : float or None
        |N_r| and the phase lag (rad) of the limiter at the cycle (1 and 0: not limiting; None without a cycle).
    method : str
    reason : str or None
        Why a value is null, or what to know.
    """

    disturbance: float
    start_amplitude: float | None
    V_critical: float
    V_disturbance: float | None
    settles: bool | None
    amplitude: float | None
    omega: float | None
    reaches_wall: bool | None
    criticality: str | None
    cycles_below_critical: bool | None
    V_fold: float | None
    yaw_accel_limit: float
    limiter_gain: float | None
    limiter_lag: float | None
    method: str
    reason: str | None = None

    @classmethod
    def unavailable(cls, disturbance: float, yaw_accel_limit: float, reason: str) -> "Disturbance":
        """No branch to read (N <= 0, no oscillatory boundary, …): every number null, with the reason.

        Parameters
        ----------
        disturbance : float
            D, m.
        yaw_accel_limit : float
            R, rad/s².
        reason : str
            Why.
        """
        return cls(disturbance, None, math.nan, None, None, None, None, None, None, None, None, yaw_accel_limit, None, None, "none", reason)

    def to_dict(self) -> dict:
        """JSON: every field, numbers through `json_number` (nan and None as null, an infinite limit as "inf")."""
        number = lambda x: None if x is None or (isinstance(x, float) and math.isnan(x)) else json_number(x)
        return {
            "disturbance": number(self.disturbance),
            "start_amplitude": number(self.start_amplitude),
            "V_critical": number(self.V_critical),
            "V_disturbance": number(self.V_disturbance),
            "settles": self.settles,
            "amplitude": number(self.amplitude),
            "omega": number(self.omega),
            "reaches_wall": self.reaches_wall,
            "criticality": self.criticality,
            "cycles_below_critical": self.cycles_below_critical,
            "V_fold": number(self.V_fold),
            "yaw_accel_limit": number(self.yaw_accel_limit),
            "limiter_gain": number(self.limiter_gain),
            "limiter_lag": number(self.limiter_lag),
            "method": self.method,
            "reason": self.reason,
        }


def _response(branch: WobbleBranch, robot, controller, disturbance: float, method: str, steering) -> Disturbance:
    """What the branch says of a start of size D at the robot's speed (module docstring)."""
    V = robot.V
    V_D, _ = disturbance_speed(branch, robot, controller, disturbance, steering)
    a = start_amplitude(robot, controller, branch.gain, V, disturbance, branch.model, steering)
    cycles = branch.cycles_at(V)
    below = bool(branch.fold_speed < branch.V_critical)
    common = dict(disturbance=disturbance, start_amplitude=a, V_critical=branch.V_critical, V_disturbance=V_D,
                  criticality=branch.criticality, cycles_below_critical=below, V_fold=branch.fold_speed,
                  yaw_accel_limit=robot.yaw_accel_limit, method=method)
    inner = [c for c in cycles if c.amplitude < a]
    outer = [c for c in cycles if c.amplitude >= a]
    grows = (inner[-1].stable is False) if inner else V > branch.V_critical  # the flow at a: outward past an unstable cycle
    if not grows:
        if not inner:
            return Disturbance(settles=True, amplitude=0.0, omega=None, reaches_wall=False, limiter_gain=None, limiter_lag=None,
                               reason="the start settles", **common)
        target = inner[-1]  # a stable cycle below the start: it shrinks onto it
    else:
        stable = [c for c in outer if c.stable]
        if not stable:
            return Disturbance(settles=False, amplitude=None, omega=None, reaches_wall=True, limiter_gain=None, limiter_lag=None,
                               reason="no cycle inside the clearance holds the start: it grows until the robot touches a wall", **common)
        target = stable[0]
    shown = reported_cycle(branch, V, target)
    target = shown or target
    limiter = dict(limiter_gain=target.limiter_gain, limiter_lag=target.limiter_lag)
    if shown is None:
        return Disturbance(settles=False, amplitude=None, omega=None, reaches_wall=False, **limiter,
                           reason=f"a cycle of {target.amplitude:.3g} m, but the describing function is not trusted there (third harmonic "
                                  f"{target.third_harmonic:.2f} > {THIRD_HARMONIC_LIMIT:g} or the steering-rate limit's "
                                  f"{target.rate_harmonic:.3f}; docs/wobble.md)", **common)
    return Disturbance(settles=False, amplitude=target.amplitude, omega=target.omega, reaches_wall=False, **limiter, **common)


def _method(model: str, robot) -> str:
    limiter = ", the drive's yaw acceleration limit" if math.isfinite(robot.yaw_accel_limit) else ""
    return (f"the start projected on the {model} loop's oscillatory mode, read against the harmonic-balance branch (the field, "
            f"the heading, the steering-rate limit{limiter})")


def corridor_disturbance(robot, controller, law: ForceLaw, L: float, disturbance: float, *, model: str = "sampled") -> Disturbance:
    """What a start `disturbance` m off the centre line does at the robot's speed, and V*(D) (module docstring).

    Parameters
    ----------
    robot : parameters.Robot
        V, τ, k, W, g, D, `max_steering_rate`, `yaw_accel_limit`.
    controller : parameters.Controller
        T, hold, compute delay.
    law : ForceLaw
        The corridor's lateral law.
    L : float
        Half-width, m.
    disturbance : float
        D, m, in (0, L − W/2).
    model : {"exact_delay", "sampled"}

    Returns
    -------
    Disturbance
    """
    disturbance = check_number("disturbance", disturbance, 0.0, L - robot.W / 2, unit="m")
    branch = corridor_branch(robot, controller, law, L, model=model)
    return _response(branch, robot, controller, disturbance, _method(model, robot), corridor_steering(law, L))


def wall_disturbance(robot, controller, law: ForceLaw, alpha: float, disturbance: float, *, model: str = "sampled") -> Disturbance:
    """What a start `disturbance` m off the wall's equilibrium does (the biased describing function, `wobble.wall_branch`).

    Parameters
    ----------
    robot : parameters.Robot
        V, τ, k, W, g, D, `max_steering_rate`, `yaw_accel_limit`.
    controller : parameters.Controller
        T, hold, compute delay.
    law : ForceLaw
        The wall's lateral law.
    alpha : float
        Target angle from the wall normal, rad.
    disturbance : float
        D, m (> 0; beyond the branch's clearance the start touches the wall).
    model : {"exact_delay", "sampled"}

    Returns
    -------
    Disturbance
    """
    disturbance = check_number("disturbance", disturbance, 0.0, math.inf, unit="m")
    branch = wall_branch(robot, controller, law, alpha, model=model)
    return _response(branch, robot, controller, disturbance, _method(model, robot), wall_steering(law, alpha))
