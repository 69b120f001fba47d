"""Nav2's Graceful controller (``nav2_graceful_controller``): Park & Kuipers' smooth control law towards a motion target.

One cycle (``src/graceful_controller.cpp``, ``computeVelocityCommands``):

1. The plan in the robot's frame; ``validateOrientations`` gives every pose the heading to the next one when the
   plan carries no orientations of its own (all its inner poses share one yaw).
2. **Motion target**: the point at arc ``max_lookahead`` along the plan from the pose closest to the robot
   (``nav2_util::getLookAheadPoint``, no interpolation after the goal), heading = its segment's; it is
   valid when no farther than ``max_lookahead`` (``validateTargetPose``) and its simulated trajectory is free
   (``simulateTrajectory``: a corridor's centre always is; the collision check is not modelled). Near the goal
   (``dist_to_goal < max_lookahead`` with ``prefer_final_rotation``) the target's heading becomes its bearing
   (``validateTargetPoseOnApproach``). ``min_lookahead`` is declared (0.25) but not read by the current source.
3. **Initial rotation** (``initial_rotation``, state ``do_initial_rotation_``, set on a new plan): while the
   target's bearing is at least ``initial_rotation_tolerance``, turn in place (``rotateToTarget``:
   ``rotation_scaling_factor``·angle·``v_angular_max``, at least ``v_angular_min_in_place``); the first cycle
   with the bearing inside the tolerance ends it for the plan.
4. **Control law** (``src/smooth_control_law.cpp``, ``calculateRegularVelocity``; polar coordinates of
   ``include/.../ego_polar_coords.hpp`` in single precision, ``float``): with the line of sight
   ψ = atan2(−y, x) to the target (x, y), r = |(x, y)|, φ = wrap(yaw_target + ψ), δ = wrap(ψ),
   κ = −(1/r)·[k_δ·(δ − atan(−k_φ·φ)) + (1 + k_φ/(1 + (k_φ·φ)²))·sin δ];
   v = ``v_linear_max``/(1 + β·|κ|^λ), then min(v, ``v_linear_max``·r/``slowdown_radius``), min(v,
   √(2·r·``deceleration_max``)), clamped to [``v_linear_min``, ``v_linear_max``]; ω = κ·v clamped to
   ±``v_angular_max``, and v = ω/κ after that clamp.

On a straight plan, robot at e_y, e_θ, target at arc L = max_lookahead: ψ ≈ e_θ + e_y/L, φ ≈ e_y/L, r ≈ L, so
κ ≈ −[(1 + k_δ + k_φ)·e_θ + (1 + k_δ)(1 + k_φ)·e_y/L]/L (`closed_form_gains`), and the cruising speed is
``v_linear_max``·min(1, L/slowdown_radius, …): with the defaults (L = 1 m, slowdown radius 1.5 m) two thirds of
``v_linear_max``. Defaults: ``src/parameter_handler.cpp``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..checks import check_number
from .base import Command, RobotState, normalize_angle
from .plan import PRUNE_DISTANCE, lookahead_point, local_plan, path_length, to_robot_frame

__all__ = ["GracefulParams", "command", "control_law", "polar_coordinates", "cruise_speed", "closed_form_gains", "with_speed",
           "nominal_speed", "LINEARIZATION_STEPS"]


@dataclass(frozen=True)
class GracefulParams:
    """The Graceful controller's parameters (Nav2's names; defaults from ``src/parameter_handler.cpp``).

    Attributes
    ----------
    max_lookahead : float
        m (1.0).
    min_lookahead : float
        m (0.25; declared, not read by the source).
    k_phi, k_delta : float
        The control law's gains (2.0, 1.0).
    beta, lambda_ : float
        The curvature's slow-down (0.4, 2.0; Nav2's ``lambda``).
    v_linear_min, v_linear_max : float
        m/s (0.1, 0.5).
    v_angular_max : float
        rad/s (1.0).
    v_angular_min_in_place : float
        rad/s (0.25).
    slowdown_radius : float
        m (1.5).
    deceleration_max : float
        m/s² (2.5).
    initial_rotation : bool
        (True).
    initial_rotation_tolerance : float
        rad (0.75).
    prefer_final_rotation : bool
        (True).
    rotation_scaling_factor : float
        (0.5).
    prune_distance : float
        The controller server's ``prune_distance``, m (2.0).
    """

    max_lookahead: float = 1.0
    min_lookahead: float = 0.25
    k_phi: float = 2.0
    k_delta: float = 1.0
    beta: float = 0.4
    lambda_: float = 2.0
    v_linear_min: float = 0.1
    v_linear_max: float = 0.5
    v_angular_max: float = 1.0
    v_angular_min_in_place: float = 0.25
    slowdown_radius: float = 1.5
    deceleration_max: float = 2.5
    initial_rotation: bool = True
    initial_rotation_tolerance: float = 0.75
    prefer_final_rotation: bool = True
    rotation_scaling_factor: float = 0.5
    prune_distance: float = PRUNE_DISTANCE

    def __post_init__(self):
        for name in ("max_lookahead", "v_linear_max", "v_angular_max", "slowdown_radius", "deceleration_max", "prune_distance"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6))
        for name in ("min_lookahead", "k_phi", "k_delta", "beta", "lambda_", "v_linear_min", "v_angular_min_in_place",
                     "initial_rotation_tolerance", "rotation_scaling_factor"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6, low_open=False))
        if self.v_linear_min > self.v_linear_max:
            raise ValueError(f"v_linear_min must be <= v_linear_max; got {self.v_linear_min:g} > {self.v_linear_max:g}")

    def replace(self, **changes) -> "GracefulParams":
        """A copy with some parameters changed (validated again).

        Parameters
        ----------
        **changes
            Parameter values.
        """
        return replace(self, **changes)


def with_speed(params: GracefulParams, V: float) -> GracefulParams:
    """The parameters with ``v_linear_max`` = V (the cruising speed is V·min(1, max_lookahead/slowdown_radius, …)).

    Parameters
    ----------
    params : GracefulParams
    V : float
        m/s (at least ``v_linear_min``).
    """
    return params.replace(v_linear_max=V)


def polar_coordinates(x: float, y: float, target_yaw: float) -> tuple:
    """``EgocentricPolarCoordinates`` of a target in the robot's frame, in single precision as Nav2 computes them.

    Parameters
    ----------
    x, y : float
        The target, m.
    target_yaw : float
        Its heading, rad.

    Returns
    -------
    (float, float, float)
        r (m), φ and δ (rad).
    """
    dx, dy = np.float32(x), np.float32(y)
    sight = np.arctan2(-dy, dx)
    r = np.float32(np.sqrt(dx * dx + dy * dy))
    phi = np.float32(normalize_angle(float(target_yaw) + float(sight)))
    delta = np.float32(normalize_angle(float(sight)))
    return float(r), float(phi), float(delta)


def control_law(params: GracefulParams, r: float, phi: float, delta: float) -> Command:
    """``SmoothControlLaw::calculateRegularVelocity`` forwards (module docstring, step 4).

    Parameters
    ----------
    params : GracefulParams
    r : float
        Distance to the target, m (> 0).
    phi, delta : float
        The target's and the robot's angle to the line of sight, rad.
    """
    kp, kd = params.k_phi, params.k_delta
    prop = kd * (delta - math.atan(-kp * phi))
    feedback = (1.0 + kp / (1.0 + (kp * phi) ** 2)) * math.sin(delta)
    kappa = -1.0 / r * (prop + feedback)
    v = params.v_linear_max / (1.0 + params.beta * abs(kappa) ** params.lambda_)
    v = min(params.v_linear_max * (r / params.slowdown_radius), v)
    v = min(math.sqrt(2.0 * r * params.deceleration_max), v)
    v = min(max(v, params.v_linear_min), params.v_linear_max)
    w = min(max(kappa * v, -params.v_angular_max), params.v_angular_max)
    return Command(w / kappa if kappa != 0.0 else v, w)


def _rotate_to(params: GracefulParams, angle: float) -> Command:
    """``rotateToTarget``: turn in place towards `angle` (rad)."""
    w = params.rotation_scaling_factor * angle * params.v_angular_max
    return Command(0.0, math.copysign(1.0, w) * max(abs(w), params.v_angular_min_in_place))


def _plan_headings(x, y, yaw):
    """``validateOrientations``: headings to the next pose when the inner poses share one yaw (else unchanged)."""
    if x.size < 3:
        return yaw
    if np.any(normalize_angle(yaw[1] - yaw[2:-1]) > 1e-6):  # shortest_angular_distance(this, initial) > 1e-6
        return yaw
    out = np.array(yaw, dtype=float)
    out[:-1] = np.arctan2(np.diff(y), np.diff(x))
    return out


def command(state: RobotState, plan, costmap, params: GracefulParams = GracefulParams(), rng=None, memory=None) -> Command:
    """One cycle of the Graceful controller (module docstring).

    Parameters
    ----------
    state : RobotState
        Pose (the measured velocity is not read).
    plan : Plan
        The global plan.
    costmap : CorridorCostmap
        The local costmap (its window bounds the plan).
    params : GracefulParams
    rng : numpy.random.Generator, optional
        Unused (deterministic).
    memory : bool, optional
        ``do_initial_rotation_``: whether the initial rotation may still happen (None: a new plan, True).

    Returns
    -------
    Command
        With ``memory`` the flag for the next cycle.
    """
    rotating = True if memory is None else bool(memory)
    part = local_plan(plan, state, costmap.window(state.x, state.y), params.prune_distance)
    xr, yr = to_robot_frame(part.x, part.y, state)
    yawr = _plan_headings(xr, yr, normalize_angle(part.yaw - state.yaw))
    tx, ty, tyaw, _ = lookahead_point(xr, yr, yawr, params.max_lookahead)
    if path_length(xr, yr) < params.max_lookahead and params.prefer_final_rotation:
        tyaw = math.atan2(ty, tx)
    bearing = math.atan2(ty, tx)
    if rotating and params.initial_rotation and abs(bearing) >= params.initial_rotation_tolerance:
        cmd = _rotate_to(params, bearing)
        return Command(cmd.v, cmd.w, True)
    cmd = control_law(params, *polar_coordinates(tx, ty, tyaw))
    return Command(cmd.v, cmd.w, False)


def cruise_speed(params: GracefulParams, r: float | None = None) -> float:
    """The speed the control law commands on a straight plan with the robot on it (κ = 0), m/s.

    Parameters
    ----------
    params : GracefulParams
    r : float, optional
        Distance to the target, m (default ``max_lookahead``).
    """
    r = params.max_lookahead if r is None else r
    v = min(params.v_linear_max, params.v_linear_max * r / params.slowdown_radius, math.sqrt(2.0 * r * params.deceleration_max))
    return min(max(v, params.v_linear_min), params.v_linear_max)


def closed_form_gains(params: GracefulParams, V: float | None = None, L: float | None = None) -> tuple:
    """The control law's lateral gains on a straight plan (module docstring; derived with sympy in the tests).

    Parameters
    ----------
    params : GracefulParams
    V : float, optional
        Speed, m/s (default `cruise_speed`).
    L : float, optional
        Distance to the motion target, m (default ``max_lookahead``).

    Returns
    -------
    (float, float)
        k_θ = V(1 + k_δ + k_φ)/L (1/s) and k_y = V(1 + k_δ)(1 + k_φ)/L² (1/(m·s)).
    """
    L = params.max_lookahead if L is None else L
    V = cruise_speed(params, L) if V is None else V
    return V * (1.0 + params.k_delta + params.k_phi) / L, V * (1.0 + params.k_delta) * (1.0 + params.k_phi) / (L * L)


LINEARIZATION_STEPS = (1e-4, 1e-4, 0.0)
"""Central-difference steps (e_y m, e_θ rad, ω_m rad/s) of `controllers.linearize`: the polar coordinates are single
precision, rounded to 6e-8 of themselves — of the perturbation, not of L — so the derivative keeps ~1e-7 relative;
the truncation (h/L)² is 1e-8 at L = 1 m; ω_m is not read (0: skipped)."""


def nominal_speed(params: GracefulParams) -> float:
    """The speed to start from when looking for the cruising speed: `cruise_speed`, m/s.

    Parameters
    ----------
    params : GracefulParams
    """
    return cruise_speed(params)
