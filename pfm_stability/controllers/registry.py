"""The controller registry: every path-tracking controller the report analyses, declared once (numpy-free, level 0).

``report --controller NAME`` (docs/path_tracking.md) takes one of `CONTROLLER_NAMES`:

* ``vff`` — the project's own VFF loop (Koren & Borenstein 1991), the default: today's report;
* ``rpp`` — Nav2's Regulated Pure Pursuit (``nav2_regulated_pure_pursuit_controller``);
* ``graceful`` — Nav2's Graceful controller (``nav2_graceful_controller``, Park & Kuipers' smooth control law);
* ``mppi`` — Nav2's MPPI (``nav2_mppi_controller``);
* ``dwb`` — Nav2's DWB (``nav2_dwb_controller``: ``dwb_core``, ``dwb_plugins``, ``dwb_critics``).

Each `Controller` names its pluginlib class(es) as they appear in ``controller_server``'s ``FollowPath:
plugin:`` (the plugins' XML), how its lateral loop is linearised (``closed form`` or ``numeric``: gains measured
from the algorithm), the parameter that is its cruising speed, and its parameters (`Nav2Parameter`) with Nav2's
names (relative to the plugin's namespace; a critic's as ``Critic.name``), the default the source declares
(``declare_or_get_parameter`` / ``getParam``, the file cited in `Controller.source`), a range and one line of
documentation; ``analysed`` marks those the lateral loop reads. The controller server's and the local costmap's
parameters the analysis reads are `SERVER` and `COSTMAP`. Configuration files (`io.nav2.read_path_tracker`), the
command line (``--param NAME=VALUE``) and the analysis (`analysis.path_tracking`) read this table; a parameter is
declared nowhere else.

Defaults are the source's declarations at the Nav2 revision read (rolling, 2026), not nav2_bringup's values: the
bringup file sets, e.g., the local costmap's ``inflation_radius`` 0.70 m and ``cost_scaling_factor`` 3.0 where the
inflation layer declares 0.55 m and 10.0. Imports no numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..checks import check_choice, check_integer, check_number, describe_range

__all__ = [
    "Nav2Parameter",
    "Controller",
    "CONTROLLERS",
    "CONTROLLER_NAMES",
    "DEFAULT_CONTROLLER",
    "NAV2_CONTROLLERS",
    "SERVER",
    "COSTMAP",
    "INFLATION_PLUGIN",
    "SHIM_PLUGIN",
    "DEFAULT_PLUGIN",
    "get_controller",
    "controller_of_plugin",
    "plugin_key",
]

DEFAULT_CONTROLLER = "vff"
"""The controller when none is named: the project's VFF loop (today's report)."""


@dataclass(frozen=True)
class Nav2Parameter:
    """One Nav2 parameter as its source declares it.

    Attributes
    ----------
    name : str
        Nav2's name inside the plugin's namespace (``lookahead_dist``; a critic's ``PathAlign.forward_point_distance``).
    default : bool, int, float, str or tuple
        The default the source declares (a tuple for a list parameter).
    doc : str
        What it does, one line.
    unit : str
        SI unit of a number ("" for none).
    low, high : float
        The range a number must lie in (Nav2's own validation where it has one, else a generous finite one).
    low_open, high_open : bool
        Whether each end is excluded.
    choices : tuple
        The values a text parameter may take (empty: any text).
    analysed : bool
        Whether the lateral loop reads it (docs/path_tracking.md).
    aliases : tuple of str
        Older names Nav2 still reads (RPP's ``desired_linear_vel`` for ``max_linear_vel``).
    """

    name: str
    default: object
    doc: str
    unit: str = ""
    low: float = -1e6
    high: float = 1e6
    low_open: bool = False
    high_open: bool = False
    choices: tuple = ()
    analysed: bool = False
    aliases: tuple = ()

    @property
    def kind(self) -> str:
        """"bool", "int", "float", "str" or "list", from the default's type."""
        if isinstance(self.default, bool):
            return "bool"
        return {int: "int", float: "float", str: "str", tuple: "list"}[type(self.default)]

    def check(self, value, shown: str | None = None):
        """`value` as this parameter's type if it is one Nav2 takes here, else ValueError naming `shown` (default the name).

        An integer is a float where a float is declared (YAML ``1`` for ``1.0``); a float is no integer.

        Parameters
        ----------
        value : object
            The value given (from a YAML file or the command line).
        shown : str, optional
            How the message names the parameter (``controller_server.FollowPath.lookahead_dist``).
        """
        shown = shown or self.name
        kind = self.kind
        if kind == "bool":
            if not isinstance(value, bool):
                raise ValueError(f"{shown} must be true or false; got {value!r}")
            return value
        if kind == "str":
            if not isinstance(value, str):
                raise ValueError(f"{shown} must be a text; got {value!r}")
            return check_choice(shown, value, self.choices) if self.choices else value
        if kind == "list":
            if not (isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value)):
                raise ValueError(f"{shown} must be a list of names; got {value!r}")
            return tuple(value)
        if isinstance(value, bool):
            raise ValueError(f"{shown} must be a number; got {value!r}")
        if kind == "int":
            return check_integer(shown, value, int(self.low), int(self.high))
        return check_number(shown, value, self.low, self.high, low_open=self.low_open, high_open=self.high_open, unit=self.unit)

    def describe(self) -> str:
        """The allowed values for a help text, e.g. ``(0, 100] m`` or ``true or false``."""
        kind = self.kind
        if kind == "bool":
            return "true or false"
        if kind == "str":
            return " or ".join(self.choices) if self.choices else "a text"
        if kind == "list":
            return "a list of names"
        return describe_range(self.low, self.high, self.low_open, self.high_open) + (f" {self.unit}" if self.unit else "")


@dataclass(frozen=True)
class Controller:
    """A path-tracking controller the report analyses.

    Attributes
    ----------
    name : str
        Its short name (`CONTROLLER_NAMES`).
    title : str
        What it is, in words.
    package : str
        The Nav2 package ("" for ``vff``).
    plugins : tuple of str
        Its pluginlib class names, as ``FollowPath: plugin:`` gives them (``pkg::Class``; ``pkg/Class`` is read too).
    linearisation : str
        ``"kb"`` (the VFF loop of the rest of the report), ``"closed form"`` (docs/path_tracking.md) or ``"numeric"``
        (the gains k_θ, k_y are measured from the algorithm and given to the report).
    speed : str or None
        The parameter that is its cruising speed (``--V`` sets it).
    source : str
        The source file(s) whose declarations give the defaults.
    parameters : tuple of Nav2Parameter
    """

    name: str
    title: str
    package: str
    plugins: tuple
    linearisation: str
    speed: str | None
    source: str
    parameters: tuple = ()

    def parameter(self, name: str) -> Nav2Parameter:
        """The parameter called `name` (or one of its aliases), else ValueError listing the controller's.

        Parameters
        ----------
        name : str
            Nav2's name inside the plugin's namespace.
        """
        for p in self.parameters:
            if name == p.name or name in p.aliases:
                return p
        known = ", ".join(p.name for p in self.parameters) or "none"
        raise ValueError(f"{name!r} is not a parameter of {self.package or self.name} ({self.name}); it takes {known}")

    def defaults(self) -> dict:
        """Parameter name → Nav2's declared default, in declaration order."""
        return {p.name: p.default for p in self.parameters}

    @property
    def analysed(self) -> tuple:
        """The parameters the lateral loop reads, in declaration order."""
        return tuple(p for p in self.parameters if p.analysed)


def _nonneg(name, default, doc, unit="", **kw) -> Nav2Parameter:
    """A number Nav2 takes >= 0 (RPP's and the Graceful controller's validation rule)."""
    return Nav2Parameter(name, default, doc, unit, 0.0, kw.pop("high", 1e6), **kw)


def _positive(name, default, doc, unit="", high=100.0, **kw) -> Nav2Parameter:
    """A number the loop divides by or needs above 0: (0, high]."""
    return Nav2Parameter(name, default, doc, unit, 0.0, high, low_open=True, **kw)


def _flag(name, default, doc, **kw) -> Nav2Parameter:
    return Nav2Parameter(name, default, doc, **kw)


def _any(name, default, doc, unit="", **kw) -> Nav2Parameter:
    """A number of any sign (Nav2 checks none)."""
    return Nav2Parameter(name, default, doc, unit, **kw)


def _count(name, default, doc, low=0, high=10**6, **kw) -> Nav2Parameter:
    return Nav2Parameter(name, default, doc, "", low, high, **kw)


# ------------------------------------------------------------------ Regulated Pure Pursuit
_RPP = (
    _positive("max_linear_vel", 0.5, "cruising speed before regulation", "m/s", analysed=True, aliases=("desired_linear_vel",)),
    _any("min_linear_vel", -0.5, "lowest linear speed of the dynamic window (use_dynamic_window)", "m/s"),
    _nonneg("max_angular_vel", 2.5, "highest yaw rate of the dynamic window", "rad/s"),
    _any("min_angular_vel", -2.5, "lowest yaw rate of the dynamic window", "rad/s"),
    _positive("lookahead_dist", 0.6, "fixed lookahead to the carrot (without velocity scaling)", "m", analysed=True),
    _nonneg("min_lookahead_dist", 0.3, "smallest velocity-scaled lookahead", "m", high=100.0, analysed=True),
    _positive("max_lookahead_dist", 0.9, "largest velocity-scaled lookahead", "m", analysed=True),
    _positive("lookahead_time", 1.5, "velocity-scaled lookahead = measured speed x lookahead_time, clamped", "s", analysed=True),
    _nonneg("rotate_to_heading_angular_vel", 1.8, "yaw rate of a rotation in place", "rad/s"),
    _flag("use_velocity_scaled_lookahead_dist", False, "lookahead from the measured speed (lookahead_time), else lookahead_dist",
          analysed=True),
    _nonneg("min_approach_linear_velocity", 0.05, "lowest speed on the approach to the goal", "m/s"),
    _nonneg("approach_velocity_scaling_dist", 0.6, "plan length left below which the speed scales down to the goal", "m"),
    _nonneg("max_allowed_time_to_collision_up_to_carrot", 1.0, "time ahead the collision check looks", "s"),
    _any("min_distance_to_obstacle", -1.0, "distance the collision check looks ahead (<= 0: by time)", "m"),
    _flag("use_regulated_linear_velocity_scaling", True, "curvature heuristic: slow down on tight turns", analysed=True),
    _flag("use_cost_regulated_linear_velocity_scaling", True, "cost heuristic: slow down near obstacles (the costmap's cost at the robot)",
          analysed=True),
    _positive("cost_scaling_dist", 0.6, "distance to obstacles below which the cost heuristic slows down", "m", analysed=True),
    _nonneg("cost_scaling_gain", 1.0, "speed factor per cost_scaling_dist of distance (<= 1)", analysed=True, high=100.0),
    _any("inflation_cost_scaling_factor", 3.0, "the inflation layer's cost_scaling_factor, to turn a cost into a distance "
         "(<= 0 disables the cost heuristic)", "1/m", low=-1e4, high=1e4, analysed=True),
    _nonneg("regulated_linear_scaling_min_radius", 0.90, "turn radius below which the curvature heuristic slows down", "m", analysed=True),
    _nonneg("regulated_linear_scaling_min_speed", 0.25, "lowest speed the heuristics regulate to", "m/s", analysed=True, high=100.0),
    _flag("use_fixed_curvature_lookahead", False, "steer by the curvature to a carrot at curvature_lookahead_dist", analysed=True),
    _positive("curvature_lookahead_dist", 0.6, "the fixed curvature carrot's distance", "m", analysed=True),
    _flag("use_rotate_to_heading", True, "rotate in place when the carrot's bearing is large"),
    _nonneg("rotate_to_heading_min_angle", 0.785, "bearing above which the robot rotates in place", "rad"),
    _nonneg("max_linear_accel", 2.5, "linear acceleration limit of the dynamic window", "m/s^2"),
    _any("max_linear_decel", -2.5, "linear deceleration limit of the dynamic window", "m/s^2"),
    _nonneg("max_angular_accel", 3.2, "yaw acceleration limit of rotations in place and the dynamic window", "rad/s^2"),
    _any("max_angular_decel", -3.2, "yaw deceleration limit of the dynamic window", "rad/s^2"),
    _flag("use_cancel_deceleration", False, "decelerate when a goal is cancelled"),
    _nonneg("cancel_deceleration", 3.2, "deceleration when a goal is cancelled", "m/s^2"),
    _flag("allow_reversing", False, "drive backwards towards a carrot behind"),
    _flag("interpolate_curvature_after_goal", False, "place the curvature carrot beyond the plan's end"),
    _flag("use_collision_detection", True, "stop when a collision is imminent"),
    _flag("use_dynamic_window", False, "Dynamic Window Pure Pursuit: the command inside the velocity and acceleration window",
          analysed=True),
    _flag("allow_obstacle_checking_beyond_goal", False, "collision check beyond the goal"),
)

# ------------------------------------------------------------------ Graceful controller
_GRACEFUL = (
    _nonneg("min_lookahead", 0.25, "declared; not read by the control law", "m"),
    _positive("max_lookahead", 1.0, "distance along the plan to the motion target", "m", analysed=True),
    _nonneg("k_phi", 2.0, "gain of the target's orientation in the control law (Park & Kuipers' k_1)", analysed=True, high=1e3),
    _nonneg("k_delta", 1.0, "gain of the steering angle in the control law (Park & Kuipers' k_2)", analysed=True, high=1e3),
    _nonneg("beta", 0.4, "speed reduction with curvature, v = v_max/(1 + beta |kappa|^lambda)", analysed=True, high=1e3),
    _nonneg("lambda", 2.0, "exponent of the curvature in the speed reduction", analysed=True, high=1e3),
    _nonneg("v_linear_min", 0.1, "lowest forward speed of the control law", "m/s", analysed=True, high=100.0),
    _positive("v_linear_max", 0.5, "highest forward speed of the control law", "m/s", analysed=True),
    _nonneg("v_angular_max", 1.0, "yaw-rate limit of the control law", "rad/s"),
    _nonneg("v_angular_min_in_place", 0.25, "lowest yaw rate of a rotation in place", "rad/s"),
    _positive("slowdown_radius", 1.5, "distance to the motion target below which the speed scales down", "m", analysed=True),
    _positive("deceleration_max", 2.5, "deceleration limit: v <= sqrt(2 r deceleration_max)", "m/s^2", analysed=True),
    _flag("initial_rotation", True, "rotate in place towards a new plan first"),
    _nonneg("initial_rotation_tolerance", 0.75, "bearing below which no initial rotation is made", "rad"),
    _flag("prefer_final_rotation", True, "turn the motion target's heading towards the goal's on the approach"),
    _nonneg("rotation_scaling_factor", 0.5, "yaw rate of a rotation in place per radian, times v_angular_max"),
    _flag("allow_backward", False, "drive backwards"),
    _nonneg("in_place_collision_resolution", 0.1, "angle step of the rotation's collision check", "rad"),
    _flag("use_collision_detection", True, "check the simulated trajectory to the motion target for collisions"),
    _nonneg("footprint_scaling_linear_vel", 0.5, "speed above which the footprint is scaled up in the collision check", "m/s"),
    _nonneg("footprint_scaling_factor", 0.25, "how much the footprint grows at v_linear_max"),
    _nonneg("footprint_scaling_step", 0.1, "speed step of the collision check's retries", "m/s"),
    _count("obstacle_cost_margin", 1, "cost margin of the collision check"),
    _nonneg("final_rotation_search_step", 0.1, "angle step of the final rotation's search", "rad"),
)


# ------------------------------------------------------------------ MPPI
def _critic(name, weight, extra=(), power=True) -> tuple:
    """An MPPI critic's ``enabled``, ``cost_power``, ``cost_weight`` and its own parameters, named ``Critic.parameter``."""
    common = [_flag(f"{name}.enabled", True, f"{name} takes part")]
    if power:
        common.append(_count(f"{name}.cost_power", 1, f"{name}'s exponent", low=1, high=100))
    if weight is not None:
        common.append(_nonneg(f"{name}.cost_weight", weight, f"{name}'s weight"))
    return (*common, *(replace(p, name=f"{name}.{p.name}") for p in extra))


_MPPI = (
    _positive("model_dt", 0.05, "the rollout's time step (set it to the controller's period)", "s", high=10.0),
    _count("time_steps", 56, "the rollout's steps", low=1),
    _count("batch_size", 1000, "rollouts sampled per iteration", low=1),
    _count("iteration_count", 1, "optimisation iterations per cycle", low=1),
    _positive("temperature", 0.3, "the softmax's temperature", high=1e6),
    _nonneg("gamma", 0.015, "the control cost's weight"),
    _any("model_delay_vx", 0.0, "command latency of the linear speed the rollouts model (rounded to model_dt)", "s"),
    _any("model_delay_vy", 0.0, "command latency of the lateral speed the rollouts model", "s"),
    _any("model_delay_wz", 0.0, "command latency of the yaw rate the rollouts model (rounded to model_dt)", "s"),
    _flag("clamp_raw_controls", False, "clamp the sampled controls to the rollout's feasible ones"),
    _positive("vx_max", 0.5, "highest forward speed", "m/s"),
    _any("vx_min", -0.35, "lowest forward speed (< 0: reversing)", "m/s"),
    _nonneg("vy_max", 0.5, "highest lateral speed (holonomic models)", "m/s"),
    _nonneg("wz_max", 1.9, "highest yaw rate", "rad/s"),
    _any("ax_max", 3.0, "forward acceleration limit", "m/s^2"),
    _any("ax_min", -3.0, "forward deceleration limit", "m/s^2"),
    _any("ay_max", 3.0, "lateral acceleration limit", "m/s^2"),
    _any("ay_min", -3.0, "lateral deceleration limit", "m/s^2"),
    _nonneg("az_max", 3.5, "yaw acceleration limit", "rad/s^2"),
    _nonneg("vx_std", 0.2, "standard deviation of the sampled forward speed", "m/s"),
    _nonneg("vy_std", 0.2, "standard deviation of the sampled lateral speed", "m/s"),
    _nonneg("wz_std", 0.4, "standard deviation of the sampled yaw rate", "rad/s"),
    _count("retry_attempt_limit", 1, "retries after a failed optimisation"),
    _flag("open_loop", False, "start the rollouts from the last command, not the measured speed"),
    _count("sgf_order", 2, "order of the Savitzky-Golay filter of the control sequence", low=1),
    Nav2Parameter("motion_model", "diff_drive", "the rollouts' motion model", choices=("diff_drive", "omni", "ackermann")),
    _flag("regenerate_noises", False, "draw new noise every cycle"),
    _flag("visualize", False, "publish the rollouts"),
    _flag("publish_optimal_trajectory", False, "publish the optimal trajectory"),
    Nav2Parameter("critics", (), "the critics in use (the source declares none; nav2_bringup lists eight)"),
    *_critic("ConstraintCritic", 4.0),
    *_critic("CostCritic", 3.81, (_flag("consider_footprint", False, "cost of the footprint, not of the centre"),
                                   _nonneg("critical_cost", 300.0, "weight of costs near collision"),
                                   _count("near_collision_cost", 253, "cost counted as near a collision", high=255),
                                   _nonneg("collision_cost", 1000000.0, "cost of a colliding rollout"),
                                   _nonneg("near_goal_distance", 0.5, "distance to the goal below which the critic is off", "m"),
                                   Nav2Parameter("inflation_layer_name", "", "the costmap's inflation layer (\"\": the first)"),
                                   _count("trajectory_point_step", 2, "rollout points skipped between cost lookups", low=1))),
    *_critic("ObstaclesCritic", None, (_nonneg("repulsion_weight", 1.5, "weight of the inflation's distance"),
                                        _nonneg("critical_weight", 20.0, "weight of points closer than the collision margin"),
                                        _flag("consider_footprint", False, "cost of the footprint, not of the centre"),
                                        _nonneg("collision_cost", 100000.0, "cost of a colliding rollout"),
                                        _nonneg("collision_margin_distance", 0.10, "margin beyond the inscribed radius", "m"),
                                        _nonneg("near_goal_distance", 0.5, "distance to the goal below which the critic is off", "m"),
                                        Nav2Parameter("inflation_layer_name", "", "the costmap's inflation layer (\"\": the first)"))),
    *_critic("GoalCritic", 5.0, (_nonneg("threshold_to_consider", 1.4, "distance to the goal below which the critic acts", "m"),)),
    *_critic("GoalAngleCritic", 3.0, (_nonneg("threshold_to_consider", 0.5, "distance to the goal below which the critic acts", "m"),
                                       _flag("symmetric_yaw_tolerance", False, "a goal heading and its reverse are equal"))),
    *_critic("PathAlignCritic", 10.0, (_nonneg("max_path_occupancy_ratio", 0.07, "share of the plan in collision above which it is off"),
                                        _count("offset_from_furthest", 20, "plan points past the furthest reached before it acts"),
                                        _count("trajectory_point_step", 4, "rollout points between comparisons", low=1),
                                        _nonneg("threshold_to_consider", 0.5, "distance to the goal below which the critic is off", "m"),
                                        _flag("use_path_orientations", False, "compare headings too"))),
    *_critic("PathFollowCritic", 5.0, (_nonneg("threshold_to_consider", 1.4, "distance to the goal below which the critic is off", "m"),
                                        _count("offset_from_furthest", 6, "plan points past the furthest reached to aim at"))),
    *_critic("PathAngleCritic", 2.2, (_count("offset_from_furthest", 4, "plan points past the furthest reached to aim at"),
                                       _nonneg("threshold_to_consider", 0.5, "distance to the goal below which the critic is off", "m"),
                                       _nonneg("max_angle_to_furthest", 0.785398, "bearing below which the critic is off", "rad"),
                                       _count("mode", 0, "0 forward preference, 1 no preference, 2 consider feasible path orientations",
                                              high=2))),
    *_critic("PreferForwardCritic", 5.0, (_nonneg("threshold_to_consider", 0.5, "distance to the goal below which the critic is off",
                                                  "m"),)),
)


# ------------------------------------------------------------------ DWB
def _dwb_critic(name, extra=()) -> tuple:
    """A DWB critic's ``scale`` (``dwb_core/trajectory_critic.hpp``) and its own parameters, named ``Critic.parameter``."""
    return (_any(f"{name}.scale", 1.0, f"{name}'s weight"),
            *(replace(p, name=f"{name}.{p.name}") for p in extra))


_DWB = (
    Nav2Parameter("critics", (), "the critics in use (required: the source declares no default)"),
    Nav2Parameter("default_critic_namespaces", (), "namespaces searched for critic plugins"),
    Nav2Parameter("trajectory_generator_name", "dwb_plugins::StandardTrajectoryGenerator", "the trajectory generator",
                  choices=("dwb_plugins::StandardTrajectoryGenerator", "dwb_plugins::LimitedAccelGenerator")),
    _flag("short_circuit_trajectory_evaluation", True, "stop scoring a trajectory once it is worse than the best"),
    _flag("debug_trajectory_details", False, "log every trajectory's scores"),
    _any("min_vel_x", 0.0, "lowest forward speed", "m/s"),
    _any("min_vel_y", 0.0, "lowest lateral speed", "m/s"),
    _any("max_vel_x", 0.0, "highest forward speed (the source declares 0: give it)", "m/s"),
    _any("max_vel_y", 0.0, "highest lateral speed", "m/s"),
    _any("max_vel_theta", 0.0, "highest yaw rate", "rad/s"),
    _any("min_speed_xy", 0.0, "lowest translational speed", "m/s"),
    _any("max_speed_xy", 0.0, "highest translational speed", "m/s"),
    _any("min_speed_theta", 0.0, "lowest yaw rate", "rad/s"),
    _any("acc_lim_x", 0.0, "forward acceleration limit", "m/s^2"),
    _any("acc_lim_y", 0.0, "lateral acceleration limit", "m/s^2"),
    _any("acc_lim_theta", 0.0, "yaw acceleration limit", "rad/s^2"),
    _any("decel_lim_x", 0.0, "forward deceleration limit", "m/s^2"),
    _any("decel_lim_y", 0.0, "lateral deceleration limit", "m/s^2"),
    _any("decel_lim_theta", 0.0, "yaw deceleration limit", "rad/s^2"),
    _count("vx_samples", 20, "forward speeds sampled", low=1),
    _count("vy_samples", 5, "lateral speeds sampled", low=1),
    _count("vtheta_samples", 20, "yaw rates sampled", low=1),
    _nonneg("sim_time", 1.7, "time each trajectory is simulated ahead", "s"),
    _flag("discretize_by_time", False, "step the trajectories in time_granularity, else in distance"),
    _positive("time_granularity", 0.5, "time step of the trajectories", "s", high=1e6),
    _positive("linear_granularity", 0.5, "distance step of the trajectories", "m", high=1e6),
    _positive("angular_granularity", 0.025, "angle step of the trajectories", "rad", high=1e6),
    _flag("include_last_point", True, "score the trajectory's end point"),
    _flag("limit_vel_cmd_in_traj", False, "limit the commanded velocity inside the trajectory"),
    _nonneg("xy_goal_tolerance", 0.25, "RotateToGoal: distance to the goal below which it rotates", "m"),
    _nonneg("trans_stopped_velocity", 0.25, "RotateToGoal: speed below which the robot counts as stopped", "m/s"),
    *_dwb_critic("PathAlign", (_any("forward_point_distance", 0.325, "distance ahead of the robot of the point scored", "m"),)),
    *_dwb_critic("GoalAlign", (_any("forward_point_distance", 0.325, "distance ahead of the robot of the point scored", "m"),)),
    *_dwb_critic("PathDist", (Nav2Parameter("aggregation_type", "last", "how the trajectory's cells are scored",
                                            choices=("last", "sum", "product")),)),
    *_dwb_critic("GoalDist", (Nav2Parameter("aggregation_type", "last", "how the trajectory's cells are scored",
                                            choices=("last", "sum", "product")),)),
    *_dwb_critic("BaseObstacle", (_flag("sum_scores", False, "sum the cells' costs, else take the largest"),)),
    *_dwb_critic("Oscillation", (_nonneg("oscillation_reset_dist", 0.05, "distance that resets the oscillation flags", "m"),
                                 _nonneg("oscillation_reset_angle", 0.2, "angle that resets the oscillation flags", "rad"),
                                 _any("oscillation_reset_time", -1.0, "time that resets the flags (< 0: never)", "s"),
                                 _nonneg("x_only_threshold", 0.05, "speed below which only rotation is checked", "m/s"))),
    *_dwb_critic("RotateToGoal", (_nonneg("slowing_factor", 5.0, "how strongly it prefers slowing down near the goal"),
                                  _any("lookahead_time", -1.0, "time ahead it projects the pose (< 0: none)", "s"))),
    *_dwb_critic("PreferForward", (_nonneg("penalty", 1.0, "cost of driving backwards"),
                                   _nonneg("strafe_x", 0.1, "speed below which turning is penalised", "m/s"),
                                   _nonneg("strafe_theta", 0.2, "yaw rate above which turning is penalised", "rad/s"),
                                   _nonneg("theta_scale", 10.0, "weight of the yaw rate"))),
)

CONTROLLERS = {
    "vff": Controller("vff", "the VFF force law's steering loop (Koren & Borenstein 1991), the rest of this report", "", (), "kb", None,
                      "docs/theory.md"),
    "rpp": Controller("rpp", "Regulated Pure Pursuit", "nav2_regulated_pure_pursuit_controller",
                      ("nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController",), "closed form", "max_linear_vel",
                      "nav2_regulated_pure_pursuit_controller/src/parameter_handler.cpp", _RPP),
    "graceful": Controller("graceful", "the Graceful controller (Park & Kuipers' smooth control law)", "nav2_graceful_controller",
                           ("nav2_graceful_controller::GracefulController",), "closed form", "v_linear_max",
                           "nav2_graceful_controller/src/parameter_handler.cpp", _GRACEFUL),
    "mppi": Controller("mppi", "the Model Predictive Path Integral controller", "nav2_mppi_controller",
                       ("nav2_mppi_controller::MPPIController",), "numeric", "vx_max",
                       "nav2_mppi_controller/src/optimizer.cpp, src/controller.cpp, src/noise_generator.cpp, src/critics/*.cpp "
                       "(enabled: include/nav2_mppi_controller/critic_function.hpp)", _MPPI),
    "dwb": Controller("dwb", "the Dynamic Window controller with trajectory critics", "nav2_dwb_controller",
                      ("dwb_core::DWBLocalPlanner",), "numeric", "max_vel_x",
                      "dwb_core/src/dwb_local_planner.cpp, dwb_plugins/src/{kinematic_parameters,xy_theta_iterator,"
                      "standard_traj_generator}.cpp, dwb_critics/src/*.cpp (scale: dwb_core/include/dwb_core/trajectory_critic.hpp)",
                      _DWB),
}
"""Every controller, by short name."""

CONTROLLER_NAMES = tuple(CONTROLLERS)
"""``vff``, ``rpp``, ``graceful``, ``mppi``, ``dwb``."""

NAV2_CONTROLLERS = tuple(name for name in CONTROLLER_NAMES if name != "vff")
"""The Nav2 controllers (all but ``vff``)."""

SHIM_PLUGIN = "nav2_rotation_shim_controller::RotationShimController"
"""The Rotation Shim controller: it rotates in place towards a new plan, then hands over to its ``primary_controller``
(a straight path after the rotation is the primary controller's)."""

DEFAULT_PLUGIN = "nav2_mppi_controller::MPPIController"
"""The plugin of ``FollowPath`` when the file names none (``nav2_controller/include/nav2_controller/parameter_handler.hpp``,
``default_controller_types_``)."""

INFLATION_PLUGIN = "nav2_costmap_2d::InflationLayer"
"""The inflation layer's plugin class (``nav2_costmap_2d/costmap_plugins.xml``)."""

SERVER = (
    _positive("controller_frequency", 20.0, "the controller server's rate: T = 1/controller_frequency", "Hz", high=1e6, analysed=True),
    Nav2Parameter("controller_plugins", ("FollowPath",), "the controller plugins' names; the first is followed", analysed=True),
)
"""``controller_server``'s parameters the analysis reads (``nav2_controller/src/parameter_handler.cpp``)."""

COSTMAP = (
    _nonneg("robot_radius", 0.1, "the robot's radius when no footprint is given (inscribed radius)", "m", high=100.0, analysed=True),
    Nav2Parameter("footprint", "[]", "the robot's footprint polygon [[x, y], ...] (m; \"[]\": a circle of robot_radius)", analysed=True),
    _positive("resolution", 0.1, "the costmap's cell size", "m", high=100.0),
    _nonneg("inflation_radius", 0.55, "the inflation layer's reach from obstacles", "m", high=100.0, analysed=True),
    _any("cost_scaling_factor", 10.0, "the inflation layer's decay rate: cost 252 exp(-cost_scaling_factor (d - inscribed radius))", "1/m",
         low=0.0, high=1e4, analysed=True),
)
"""The local costmap's parameters the analysis reads: ``robot_radius``, ``footprint``, ``resolution``
(``nav2_costmap_2d/src/costmap_2d_ros.cpp``) and the inflation layer's ``inflation_radius`` and ``cost_scaling_factor``
(``nav2_costmap_2d/plugins/inflation_layer.cpp``)."""


def get_controller(name: str) -> Controller:
    """The controller called `name`, else ValueError listing `CONTROLLER_NAMES`.

    Parameters
    ----------
    name : str
        A short name (``rpp`` …).
    """
    return CONTROLLERS[check_choice("controller", name, CONTROLLER_NAMES)]


def plugin_key(plugin: str) -> str:
    """A pluginlib class name in one spelling: ``pkg::Class`` (older files write ``pkg/Class``).

    Parameters
    ----------
    plugin : str
        The class name as a file gives it.
    """
    return plugin.strip().replace("/", "::")


def controller_of_plugin(plugin: str) -> Controller | None:
    """The controller whose pluginlib class is `plugin`, or None.

    Parameters
    ----------
    plugin : str
        ``FollowPath: plugin:`` as a file gives it.
    """
    key = plugin_key(plugin)
    return next((c for c in CONTROLLERS.values() if key in c.plugins), None)


def _unique_names() -> None:
    for c in CONTROLLERS.values():
        names = [p.name for p in c.parameters]
        if len(names) != len(set(names)):  # pragma: no cover - a declaration error
            raise RuntimeError(f"{c.name}: a parameter declared twice")
        for p in c.parameters:
            if p.kind == "float" and not (math.isfinite(p.low) and math.isfinite(p.high)):  # pragma: no cover
                raise RuntimeError(f"{c.name}.{p.name}: no finite range")


_unique_names()
