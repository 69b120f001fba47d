"""Regulated Pure Pursuit as Nav2 implements it (``nav2_regulated_pure_pursuit_controller``).

One cycle (``src/regulated_pure_pursuit_controller.cpp``, ``computeVelocityCommands``):

1. **Lookahead** (``getLookAheadDistance``): ``lookahead_dist``, or with ``use_velocity_scaled_lookahead_dist``
   L = clamp(|v|·``lookahead_time``, ``min_lookahead_dist``, ``max_lookahead_dist``) with v the *measured*
   speed (odometry), so the lookahead follows the speed one cycle late.
2. **Carrot** (``nav2_util::getLookAheadPoint``, `controllers.plan.lookahead_point`): the point at arc L along
   the plan from the pose closest to the robot, in the robot's frame.
3. **Curvature** (``calculateCurvature``): κ = 2·y/(x² + y²) of the carrot (x, y) (0 when x² + y² <= 0.001);
   with ``use_fixed_curvature_lookahead`` a second carrot at ``curvature_lookahead_dist`` gives the curvature
   that regulates the speed, decides the rotation and steers (``angular_vel = linear_vel *
   regulation_curvature``).
4. **Rotate to heading** (``shouldRotateToPath``, ``rotateToHeading``; ``use_rotate_to_heading``): when the
   carrot's bearing exceeds ``rotate_to_heading_min_angle`` the robot turns in place at
   ``rotate_to_heading_angular_vel``, clamped to ``max_angular_accel``·dt around the measured yaw rate and to
   √(2·max_angular_accel·|angle|); within the goal checker's 0.25 m of the goal (``SimpleGoalChecker``
   ``xy_goal_tolerance``) it turns to the goal's heading. Far from the goal and near the plan neither happens:
   path tracking never rotates in place, and ``max_angular_accel`` acts only there (and in the dynamic
   window, ``use_dynamic_window``, not modelled: refused).
5. **Regulated linear velocity** (``applyConstraints``, ``include/.../regulation_functions.hpp``): v starts at
   ``max_linear_vel``; the curvature heuristic (``curvatureConstraint``) scales it by
   1 − |R − R_min|/R_min when the radius R = 1/|κ| is below ``regulated_linear_scaling_min_radius``; the cost
   heuristic (``costConstraint``) turns the costmap's cost c at the robot's position (its cell's, free and
   unknown excepted) into a distance to the obstacle, d = (f·r_inscribed − ln c + ln 253)/f with f =
   ``inflation_cost_scaling_factor``, and scales v by ``cost_scaling_gain``·d/``cost_scaling_dist`` when
   d < ``cost_scaling_dist`` (in a corridor the speed depends on the walls); the lower of the two, at least
   ``regulated_linear_scaling_min_speed``; then the approach to the goal (``approachVelocityConstraint``:
   within ``approach_velocity_scaling_dist`` of plan left, v·(distance to the last pose)/that distance, at
   least ``min_approach_linear_velocity``); finally clamped to [0, ``max_linear_vel``].
6. **Command**: ω = v·κ.

Not modelled: the collision check ahead (``isCollisionImminent``: it only throws; a corridor's centre is free),
cancel deceleration, reversing (``allow_reversing`` false) and the dynamic-window variant (DWPP).

On a straight plan with the robot at lateral offset e_y and heading error e_θ, the carrot at arc L is at
y = −(e_y + L·e_θ) to first order and x² + y² = L², so ω = −(2V/L)·e_θ − (2V/L²)·e_y: `closed_form_gains`.
Defaults are the parameter declarations of ``src/parameter_handler.cpp``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..checks import check_number
from .base import Command, RobotState, normalize_angle
from .plan import PRUNE_DISTANCE, lookahead_point, local_plan, path_length, to_robot_frame

__all__ = ["RPPParams", "command", "lookahead_distance", "curvature", "regulated_speed", "curvature_constraint", "closed_form_gains", "with_speed",
           "nominal_speed", "LINEARIZATION_STEPS",
           "GOAL_XY_TOLERANCE"]

GOAL_XY_TOLERANCE = 0.25
"""The goal checker's ``xy_goal_tolerance``, m (``nav2_controller::SimpleGoalChecker`` default): within it RPP rotates to
the goal's heading."""


@dataclass(frozen=True)
class RPPParams:
    """Regulated Pure Pursuit's parameters (Nav2's names; defaults from ``src/parameter_handler.cpp``).

    Attributes
    ----------
    max_linear_vel : float
        m/s (``desired_linear_vel`` before; 0.5).
    lookahead_dist : float
        m (0.6).
    min_lookahead_dist, max_lookahead_dist : float
        m (0.3, 0.9).
    lookahead_time : float
        s (1.5).
    use_velocity_scaled_lookahead_dist : bool
        (False).
    rotate_to_heading_angular_vel : float
        rad/s (1.8).
    use_rotate_to_heading : bool
        (True).
    rotate_to_heading_min_angle : float
        rad (0.785).
    max_angular_accel : float
        rad/s² (3.2).
    use_regulated_linear_velocity_scaling : bool
        (True).
    regulated_linear_scaling_min_radius : float
        m (0.90).
    regulated_linear_scaling_min_speed : float
        m/s (0.25).
    use_cost_regulated_linear_velocity_scaling : bool
        (True).
    cost_scaling_dist : float
        m (0.6).
    cost_scaling_gain : float
        (1.0).
    inflation_cost_scaling_factor : float
        1/m (3.0; should equal the inflation layer's ``cost_scaling_factor``).
    min_approach_linear_velocity : float
        m/s (0.05).
    approach_velocity_scaling_dist : float
        m (0.6).
    use_fixed_curvature_lookahead : bool
        (False).
    curvature_lookahead_dist : float
        m (0.6).
    interpolate_curvature_after_goal : bool
        (False; Nav2 disables it unless ``use_fixed_curvature_lookahead``).
    use_dynamic_window : bool
        (False; True is refused: not modelled).
    prune_distance : float
        The controller server's ``FeasiblePathHandler.prune_distance``, m (2.0).
    controller_frequency : float
        The controller server's rate, Hz (20.0): dt of the rotation's acceleration clamp.
    """

    max_linear_vel: float = 0.5
    lookahead_dist: float = 0.6
    min_lookahead_dist: float = 0.3
    max_lookahead_dist: float = 0.9
    lookahead_time: float = 1.5
    use_velocity_scaled_lookahead_dist: bool = False
    rotate_to_heading_angular_vel: float = 1.8
    use_rotate_to_heading: bool = True
    rotate_to_heading_min_angle: float = 0.785
    max_angular_accel: float = 3.2
    use_regulated_linear_velocity_scaling: bool = True
    regulated_linear_scaling_min_radius: float = 0.90
    regulated_linear_scaling_min_speed: float = 0.25
    use_cost_regulated_linear_velocity_scaling: bool = True
    cost_scaling_dist: float = 0.6
    cost_scaling_gain: float = 1.0
    inflation_cost_scaling_factor: float = 3.0
    min_approach_linear_velocity: float = 0.05
    approach_velocity_scaling_dist: float = 0.6
    use_fixed_curvature_lookahead: bool = False
    curvature_lookahead_dist: float = 0.6
    interpolate_curvature_after_goal: bool = False
    use_dynamic_window: bool = False
    prune_distance: float = PRUNE_DISTANCE
    controller_frequency: float = 20.0

    def __post_init__(self):
        for name in ("max_linear_vel", "lookahead_dist", "min_lookahead_dist", "max_lookahead_dist", "lookahead_time",
                     "rotate_to_heading_angular_vel", "max_angular_accel", "regulated_linear_scaling_min_radius",
                     "cost_scaling_dist", "inflation_cost_scaling_factor", "curvature_lookahead_dist", "prune_distance",
                     "controller_frequency"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6))
        for name in ("rotate_to_heading_min_angle", "regulated_linear_scaling_min_speed", "cost_scaling_gain",
                     "min_approach_linear_velocity", "approach_velocity_scaling_dist"):
            object.__setattr__(self, name, check_number(name, getattr(self, name), 0.0, 1e6, low_open=False))
        if self.use_dynamic_window:
            raise ValueError("use_dynamic_window: the Dynamic Window Pure Pursuit variant is not modelled; use False")
        if self.min_lookahead_dist > self.max_lookahead_dist:
            raise ValueError(f"min_lookahead_dist must be <= max_lookahead_dist; got {self.min_lookahead_dist:g} > {self.max_lookahead_dist:g}")
        if not self.use_fixed_curvature_lookahead and self.interpolate_curvature_after_goal:
            object.__setattr__(self, "interpolate_curvature_after_goal", False)  # Nav2 disables it with a warning

    def replace(self, **changes) -> "RPPParams":
        """A copy with some parameters changed (validated again).

        Parameters
        ----------
        **changes
            Parameter values.
        """
        return replace(self, **changes)


def with_speed(params: RPPParams, V: float) -> RPPParams:
    """The parameters with the cruising speed set: ``max_linear_vel`` = V.

    Parameters
    ----------
    params : RPPParams
    V : float
        m/s.
    """
    return params.replace(max_linear_vel=V)


def lookahead_distance(params: RPPParams, v: float) -> float:
    """``getLookAheadDistance``: L, m, from the measured speed v (m/s).

    Parameters
    ----------
    params : RPPParams
    v : float
        Measured forward speed, m/s.
    """
    if not params.use_velocity_scaled_lookahead_dist:
        return params.lookahead_dist
    return min(max(abs(v) * params.lookahead_time, params.min_lookahead_dist), params.max_lookahead_dist)


def curvature(x: float, y: float) -> float:
    """``calculateCurvature``: 2y/(x² + y²) of a point in the robot's frame, 1/m (0 within √0.001 m of the robot).

    Parameters
    ----------
    x, y : float
        The carrot, m.
    """
    d2 = x * x + y * y
    return 2.0 * y / d2 if d2 > 0.001 else 0.0


def curvature_constraint(v: float, kappa: float, min_radius: float) -> float:
    """``curvatureConstraint``: the speed v (m/s) scaled by 1 − |R − R_min|/R_min when the radius R = 1/|κ| is below
    R_min = ``regulated_linear_scaling_min_radius`` (v itself at κ = 0 or R >= R_min), m/s.

    Parameters
    ----------
    v : float
        m/s.
    kappa : float
        The regulation curvature, 1/m.
    min_radius : float
        R_min, m.
    """
    if kappa == 0.0:
        return v
    radius = abs(1.0 / kappa)
    return v * (1.0 - abs(radius - min_radius) / min_radius) if radius < min_radius else v


def regulated_speed(params: RPPParams, kappa: float, pose_cost: float, inscribed_radius: float, remaining: float,
                    goal_distance: float) -> float:
    """``applyConstraints``: the regulated forward speed, m/s (module docstring, step 5).

    Parameters
    ----------
    params : RPPParams
    kappa : float
        The regulation curvature, 1/m.
    pose_cost : float
        The costmap's cost at the robot's position (0 free … 255 unknown).
    inscribed_radius : float
        The costmap's inscribed radius, m.
    remaining : float
        Length of the plan the controller sees, m.
    goal_distance : float
        Straight-line distance from the robot to the plan's last pose, m.
    """
    v = params.max_linear_vel
    curvature_v = cost_v = v
    if params.use_regulated_linear_velocity_scaling:
        curvature_v = curvature_constraint(v, kappa, params.regulated_linear_scaling_min_radius)
    if params.use_cost_regulated_linear_velocity_scaling and pose_cost not in (0.0, 255.0):
        f = params.inflation_cost_scaling_factor
        distance = (f * inscribed_radius - math.log(pose_cost) + math.log(253.0)) / f
        if distance < params.cost_scaling_dist:
            cost_v = v * (params.cost_scaling_gain * distance / params.cost_scaling_dist)
    v = max(min(cost_v, curvature_v), params.regulated_linear_scaling_min_speed)
    if remaining < params.approach_velocity_scaling_dist:
        approach = max(v * goal_distance / params.approach_velocity_scaling_dist, params.min_approach_linear_velocity)
        v = min(v, approach)
    return min(max(abs(v), 0.0), params.max_linear_vel)


def _rotate(params: RPPParams, angle: float, w_measured: float) -> float:
    """``rotateToHeading``: the in-place yaw rate towards `angle` (rad), rad/s."""
    sign = 1.0 if angle > 0.0 else -1.0
    dt = 1.0 / params.controller_frequency
    w = sign * params.rotate_to_heading_angular_vel
    w = min(max(w, w_measured - params.max_angular_accel * dt), w_measured + params.max_angular_accel * dt)
    stop = math.sqrt(2.0 * params.max_angular_accel * abs(angle))
    return sign * stop if abs(w) > stop else w


def command(state: RobotState, plan, costmap, params: RPPParams = RPPParams(), rng=None, memory=None) -> Command:
    """One cycle of Regulated Pure Pursuit (module docstring): the ``cmd_vel`` for this state.

    Parameters
    ----------
    state : RobotState
        Pose and measured velocity.
    plan : Plan
        The global plan.
    costmap : CorridorCostmap
        The local costmap (its window bounds the plan; its cost at the robot regulates the speed).
    params : RPPParams
    rng : numpy.random.Generator, optional
        Unused (RPP is deterministic); accepted for the common interface.
    memory : object, optional
        Unused (RPP keeps no state between cycles on this path).
    """
    window = costmap.window(state.x, state.y)
    part = local_plan(plan, state, window, params.prune_distance)
    xr, yr = to_robot_frame(part.x, part.y, state)
    yawr = normalize_angle(part.yaw - state.yaw)
    L = lookahead_distance(params, state.v)
    cx, cy, _, _ = lookahead_point(xr, yr, yawr, L)
    kappa = curvature(cx, cy)
    bearing_x, bearing_y = cx, cy
    if params.use_fixed_curvature_lookahead:
        bearing_x, bearing_y, _, _ = lookahead_point(xr, yr, yawr, params.curvature_lookahead_dist, params.interpolate_curvature_after_goal)
        kappa = curvature(bearing_x, bearing_y)
    goal_distance = math.hypot(xr[-1], yr[-1])
    if params.use_rotate_to_heading and math.hypot(plan.x[-1] - state.x, plan.y[-1] - state.y) <= GOAL_XY_TOLERANCE:
        return Command(0.0, _rotate(params, float(yawr[-1]), state.w))
    angle = math.atan2(bearing_y, bearing_x)
    if params.use_rotate_to_heading and abs(angle) > params.rotate_to_heading_min_angle:
        return Command(0.0, _rotate(params, angle, state.w))
    pose_cost = float(costmap.cost(state.x, state.y, window))
    v = regulated_speed(params, kappa, pose_cost, costmap.inflation.inscribed_radius, path_length(xr, yr), goal_distance)
    return Command(v, v * kappa)


def closed_form_gains(V: float, L: float) -> tuple:
    """Pure pursuit's lateral gains on a straight plan at speed V with lookahead L (module docstring).

    Parameters
    ----------
    V : float
        The regulated speed, m/s.
    L : float
        The lookahead, m.

    Returns
    -------
    (float, float)
        k_θ = 2V/L (1/s) and k_y = 2V/L² (1/(m·s)): ω = −k_θ·e_θ − k_y·e_y.
    """
    return 2.0 * V / L, 2.0 * V / (L * L)


LINEARIZATION_STEPS = (1e-4, 1e-4, 0.0)
"""Central-difference steps (e_y m, e_θ rad, ω_m rad/s) of `controllers.linearize`: the decision is smooth in double
precision, so the truncation error (h/L)² is 3e-8 at L = 0.6 m and the rounding 1e-12; ω_m is not read (0: skipped)."""


def nominal_speed(params: RPPParams) -> float:
    """The speed to start from when looking for the cruising speed: ``max_linear_vel``, m/s.

    Parameters
    ----------
    params : RPPParams
    """
    return params.max_linear_vel
