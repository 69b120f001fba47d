"""The global plan as Nav2's controller server hands it to a controller, and the lookahead point on it.

* `Plan`: the poses of a global plan (a polyline with headings), e.g. `straight_plan` at a planner's
  resolution (Nav2's planners give a pose per costmap cell, 0.05 m).
* `local_plan`: what ``nav2_controller/plugins/feasible_path_handler.cpp`` (``FeasiblePathHandler::
  findPlanSegment`` and ``transformLocalPlan``) passes to ``computeVelocityCommands``: from the pose closest
  to the robot (Euclidean; the last of equally close ones, ``nav2_util::geometry_utils::min_by``; never the
  last pose, so that two remain), the poses up to ``prune_distance`` of integrated length
  (``first_after_integrated_distance``: the first pose beyond it is excluded), stopping at the first pose
  outside the local costmap.
* `lookahead_point`: ``nav2_util/src/controller_utils.cpp`` ``getLookAheadPoint``, used by Regulated Pure
  Pursuit and the Graceful controller: the point at a distance *along* the plan from its first pose, by linear
  interpolation on the segment that reaches it (``linearInterpolation``; the current source — the
  circle–segment intersection ``circleSegmentIntersection`` it used until 2025, a point at Euclidean
  distance L from the robot, is kept in nav2_util but no longer called). Beyond the end: the last pose and
  the distance to it, or the last segment extended (``interpolate_after_goal``).

Two things follow that matter to a lateral loop. The carrot sits at arc L from the *closest pose*, not from
the robot's projection on the plan: with poses every h along a straight plan the lookahead to the
projection ripples in [L − h/2, L + h/2] as the robot passes the poses (docs/controllers.md measures what
that does). The pruning of the plan behind the robot is the controller server's state: `Plan.pruned` keeps the plan from
the last closest pose on (``prunePlan``), and the closest pose is searched only among the poses within
``max_robot_pose_search_dist`` of integrated length from the pruned plan's start (Nav2's default: half the local
costmap's larger side); a caller that passes the whole plan every cycle gets the same on a plan that never comes
back within reach of the robot (a straight plan, a corridor) as long as the robot is near its start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_number
from .base import RobotState

__all__ = ["Plan", "LocalPlan", "straight_plan", "local_plan", "closest_pose", "prune", "search_distance", "to_robot_frame",
           "lookahead_point", "path_length", "PRUNE_DISTANCE"]

PRUNE_DISTANCE = 2.0
"""``FeasiblePathHandler``'s ``prune_distance`` default, m (nav2_controller/plugins/feasible_path_handler.cpp)."""


@dataclass(frozen=True)
class Plan:
    """The poses of a global plan, in the costmap's global frame.

    Attributes
    ----------
    x, y : ndarray
        Positions, m (at least two poses).
    yaw : ndarray
        Headings, rad.
    arc : ndarray
        Integrated length to each pose, m, from the first pose of the plan it was pruned from (computed).
    """

    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    arc: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        arrays = [np.asarray(getattr(self, n), dtype=float).ravel() for n in ("x", "y", "yaw")]
        if len({a.size for a in arrays}) != 1 or arrays[0].size < 2:
            raise ValueError(f"a plan needs at least two poses with x, y and yaw each; got sizes {[a.size for a in arrays]}")
        if not all(np.all(np.isfinite(a)) for a in arrays):
            raise ValueError("a plan's poses must be finite numbers")
        for name, a in zip(("x", "y", "yaw"), arrays):
            a.setflags(write=False)
            object.__setattr__(self, name, a)

        arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(self.x), np.diff(self.y)))])
        arc.setflags(write=False)
        object.__setattr__(self, "arc", arc)

    @property
    def size(self) -> int:
        """Number of poses."""
        return int(self.x.size)

    def pruned(self, first: int) -> "Plan":
        """The plan from pose `first` on (what ``FeasiblePathHandler`` keeps after pruning the part passed), in O(1).

        Parameters
        ----------
        first : int
            The first pose kept (at most the last but one).
        """
        first = int(min(max(first, 0), self.size - 2))
        out = object.__new__(Plan)
        for name in ("x", "y", "yaw", "arc"):
            object.__setattr__(out, name, getattr(self, name)[first:])
        return out


@dataclass(frozen=True)
class LocalPlan:
    """The part of the plan a controller sees in one cycle (global frame; `local_plan`).

    Attributes
    ----------
    x, y, yaw : ndarray
        Poses, m and rad; the first is the pose closest to the robot.
    first : int
        Index of the first pose in the global plan.
    """

    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    first: int

    @property
    def length(self) -> float:
        """Integrated length, m (``calculate_path_length``)."""
        return path_length(self.x, self.y)


def straight_plan(length: float, spacing: float = 0.05, *, y: float = 0.0, x0: float = 0.0) -> Plan:
    """A straight plan along +x at height `y`, one pose every `spacing` from `x0` (heading 0).

    Parameters
    ----------
    length : float
        m, > 0.
    spacing : float
        Between poses, m (a planner's resolution; Nav2's NavFn and Smac give about the costmap's 0.05 m).
    y : float
        Lateral position of the plan, m.
    x0 : float
        Position of the first pose, m.
    """
    length = check_number("length", length, 0.0, unit="m")
    spacing = check_number("spacing", spacing, 0.0, length, high_open=False, unit="m")
    n = int(math.floor(length / spacing + 1e-9)) + 1
    xs = x0 + spacing * np.arange(n)
    return Plan(xs, np.full(n, float(y)), np.zeros(n))


def path_length(x, y) -> float:
    """Integrated length of a polyline, m (``nav2_util::geometry_utils::calculate_path_length``).

    Parameters
    ----------
    x, y : ndarray
        Vertices, m.
    """
    return float(np.sum(np.hypot(np.diff(x), np.diff(y))))


def closest_pose(plan: Plan, state: RobotState, search_distance: float = math.inf) -> int:
    """``FeasiblePathHandler::findPlanSegment``'s closest pose: the last of the poses nearest the robot among those
    within `search_distance` of integrated length from the plan's first (``max_robot_pose_search_dist``), never the
    last pose.

    Parameters
    ----------
    plan : Plan
        The (pruned) global plan.
    state : RobotState
        The robot's pose.
    search_distance : float
        m (Nav2's default: half the local costmap's larger side).
    """
    bound = int(np.searchsorted(plan.arc, plan.arc[0] + search_distance, side="right"))  # first_after_integrated_distance: exclusive
    bound = min(max(bound, 1), plan.size)
    d2 = (plan.x[:bound] - state.x) ** 2 + (plan.y[:bound] - state.y) ** 2
    closest = int(bound - 1 - np.argmin(d2[::-1]))  # min_by keeps the last of equal minima
    return min(closest, plan.size - 2)


def search_distance(window) -> float:
    """``max_robot_pose_search_dist``'s default: half the local costmap's larger side, m (inf without a window).

    Parameters
    ----------
    window : Window or None
        The local costmap's bounds.
    """
    return math.inf if window is None else 0.5 * window.resolution * max(window.nx, window.ny)


def prune(plan: Plan, state: RobotState, window=None) -> Plan:
    """The plan pruned at the pose closest to the robot (``FeasiblePathHandler``'s ``prunePlan``, the server's state).

    Parameters
    ----------
    plan : Plan
        The plan as pruned last cycle.
    state : RobotState
        The robot's pose.
    window : Window, optional
        The local costmap's bounds (for the search distance).
    """
    return plan.pruned(closest_pose(plan, state, search_distance(window)))


def local_plan(plan: Plan, state: RobotState, window=None, prune_distance: float = PRUNE_DISTANCE) -> LocalPlan:
    """The poses ``FeasiblePathHandler`` hands the controller this cycle (module docstring).

    Parameters
    ----------
    plan : Plan
        The global plan (pruned or not: `Plan.pruned`).
    state : RobotState
        The robot's pose.
    window : Window, optional
        The local costmap's bounds (``window.contains(x, y) -> bool array``, `controllers.costmap.Window`); the
        closest pose is searched within half its larger side of integrated length (Nav2's default
        ``max_robot_pose_search_dist``). None: unbounded.
    prune_distance : float
        Integrated length kept ahead of the closest pose, m.

    Raises
    ------
    ValueError
        If the pose closest to the robot is outside the local costmap (Nav2: "Resulting plan has 0 poses").
    """
    closest = closest_pose(plan, state, search_distance(window))
    end = int(np.searchsorted(plan.arc, plan.arc[closest] + prune_distance, side="right"))
    end = min(max(end, closest + 1), plan.size)
    xs, ys, yaws = plan.x[closest:end], plan.y[closest:end], plan.yaw[closest:end]
    if window is not None:
        outside = np.flatnonzero(~window.contains(xs, ys))
        if outside.size:
            xs, ys, yaws = xs[: outside[0]], ys[: outside[0]], yaws[: outside[0]]
    if xs.size == 0:
        raise ValueError("the plan's pose closest to the robot is outside the local costmap: no plan to follow")
    return LocalPlan(xs, ys, yaws, closest)


def to_robot_frame(x, y, state: RobotState):
    """Points of the global frame in the robot's frame (x forward, y left), m.

    Parameters
    ----------
    x, y : float or ndarray
        Global positions, m.
    state : RobotState
        The robot's pose.
    """
    c, s = math.cos(state.yaw), math.sin(state.yaw)
    dx, dy = np.asarray(x, dtype=float) - state.x, np.asarray(y, dtype=float) - state.y
    return c * dx + s * dy, -s * dx + c * dy


def lookahead_point(x, y, yaw, distance: float, interpolate_after_goal: bool = False):
    """``getLookAheadPoint``: the point `distance` along a plan from its first pose (module docstring).

    Parameters
    ----------
    x, y : ndarray
        The plan's poses in the robot's frame, m (the first is the closest pose).
    yaw : ndarray
        Their headings in the robot's frame, rad (the last pose's is returned when the plan ends first).
    distance : float
        The lookahead distance, m.
    interpolate_after_goal : bool
        Beyond the plan's end, extend its last segment (``interpolate_after_goal``) instead of taking the last pose.

    Returns
    -------
    (float, float, float, float)
        The point (m), its heading (rad: the segment's it lies on, or the last pose's own), and the distance
        used (m; shorter than `distance` when the plan ends first and the last pose is taken, as Nav2 updates
        ``lookahead_dist``).
    """
    seg = np.hypot(np.diff(x), np.diff(y))
    before = np.concatenate([[0.0], np.cumsum(seg)])  # path_dist before each segment
    reached = np.flatnonzero(before[1:] >= distance)
    if reached.size:
        i = int(reached[0]) + 1  # the first pose at or beyond the distance
        ratio = (distance - before[i - 1]) / seg[i - 1]
        dx, dy = x[i] - x[i - 1], y[i] - y[i - 1]
        return float(x[i - 1] + ratio * dx), float(y[i - 1] + ratio * dy), math.atan2(dy, dx), float(distance)
    if interpolate_after_goal and x.size >= 2:
        heading = math.atan2(y[-1] - y[-2], x[-1] - x[-2])
        past = distance - before[-1]
        return float(x[-1] + past * math.cos(heading)), float(y[-1] + past * math.sin(heading)), heading, float(distance)
    return float(x[-1]), float(y[-1]), float(yaw[-1]), float(before[-1])
