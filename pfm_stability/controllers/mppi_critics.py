"""The critics of Nav2's MPPI (``nav2_mppi_controller/src/critics/*.cpp``, ``tools/utils.hpp``): their parameters and
their scores of a batch of trajectories, in single precision (`controllers.mppi` runs them).

Every critic adds to the batch's costs; `score` runs the enabled ones in the order the parameters list them and stops
once one has failed (every trajectory collides). The shared data of a cycle (``CriticData``) is `CriticData`: the plan,
the costmap and its window, the rollout, and what the critics compute once per cycle — the furthest plan point the
trajectories reach (``findPathFurthestReachedPoint``) and which plan points are free (``findPathCosts``). Arrays are
(time_steps, batch), time along the first axis as Eigen's column-major storage.

* Constraint: cost_weight·Σ over the rollout of the speed beyond [vx_min, vx_max]·dt.
* Cost: the inflated costmap at every ``trajectory_point_step``-th point (point cost: a circular robot); a point on
  lethal, inscribed or unknown cost (off the local costmap: unknown) is a collision, ``collision_cost`` for the
  trajectory; else the costs (``critical_cost`` from ``near_collision_cost`` on), weight/254 per point.
* Obstacles (instead of Cost): distances to obstacles from the cost, (f·r − ln c + ln 253)/f − r.
* Goal, GoalAngle: only within ``threshold_to_consider`` of plan left.
* PathAlign: the mean distance from the trajectory's points to the plan points matched by integrated distance
  (``findClosestPathPt``, each search from the previous match), once the trajectories reach ``offset_from_furthest``
  points along the plan and unless too much of it is blocked (``max_path_occupancy_ratio``).
* PathFollow: the trajectory's end to the plan point ``offset_from_furthest`` beyond the furthest reached.
* PathAngle (forward preference): only when the robot points more than ``max_angle_to_furthest`` away from the plan
  point ahead.
* PreferForward: cost_weight·Σ max(−vx, 0)·dt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ConstraintCritic", "CostCritic", "ObstaclesCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic",
           "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic", "DEFAULT_CRITICS", "CRITIC_NAMES", "CriticData",
           "score", "closest_path_points", "F"]

F = np.float32
DEFAULT_CRITICS = ("ConstraintCritic", "CostCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic", "PathFollowCritic",
                   "PathAngleCritic", "PreferForwardCritic")
"""nav2_bringup's critic list (the source's default is none)."""

CRITIC_NAMES = DEFAULT_CRITICS + ("ObstaclesCritic",)
"""The critics modelled."""


@dataclass(frozen=True)
class ConstraintCritic:
    """``critics/constraint_critic.cpp``: cost_weight·Σ over the rollout of the speed beyond [vx_min, vx_max]·dt.

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 4.0


@dataclass(frozen=True)
class CostCritic:
    """``critics/cost_critic.cpp``: the inflated costmap along the trajectory (point cost, circular robot).

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
        Divided by 254 (the source's normalisation).
    critical_cost : float
    near_collision_cost : int
    collision_cost : float
    near_goal_distance : float
        m: nearer the goal (plan left) the preferential term is off.
    trajectory_point_step : int
    consider_footprint : bool
        False only (a circular robot: point costs).
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 3.81
    critical_cost: float = 300.0
    near_collision_cost: int = 253
    collision_cost: float = 1000000.0
    near_goal_distance: float = 0.5
    trajectory_point_step: int = 2
    consider_footprint: bool = False


@dataclass(frozen=True)
class ObstaclesCritic:
    """``critics/obstacles_critic.cpp``: distances to obstacles from the inflation's cost (point cost).

    Attributes
    ----------
    enabled : bool
    cost_power : int
    repulsion_weight : float
    critical_weight : float
    collision_cost : float
    collision_margin_distance : float
        m.
    near_goal_distance : float
        m.
    consider_footprint : bool
        False only.
    """

    enabled: bool = True
    cost_power: int = 1
    repulsion_weight: float = 1.5
    critical_weight: float = 20.0
    collision_cost: float = 100000.0
    collision_margin_distance: float = 0.10
    near_goal_distance: float = 0.5
    consider_footprint: bool = False


@dataclass(frozen=True)
class GoalCritic:
    """``critics/goal_critic.cpp``: mean distance of the trajectory to the plan's last pose, near the goal only.

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    threshold_to_consider : float
        m of plan left.
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 5.0
    threshold_to_consider: float = 1.4


@dataclass(frozen=True)
class GoalAngleCritic:
    """``critics/goal_angle_critic.cpp``: mean heading error to the goal's, near the goal only.

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    threshold_to_consider : float
        m of plan left.
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 3.0
    threshold_to_consider: float = 0.5


@dataclass(frozen=True)
class PathAlignCritic:
    """``critics/path_align_critic.cpp``: mean distance to the plan points matched by integrated distance.

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    max_path_occupancy_ratio : float
    offset_from_furthest : int
        Plan points the trajectories must reach before the critic applies.
    trajectory_point_step : int
    threshold_to_consider : float
        m of plan left.
    use_path_orientations : bool
        False only.
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 10.0
    max_path_occupancy_ratio: float = 0.07
    offset_from_furthest: int = 20
    trajectory_point_step: int = 4
    threshold_to_consider: float = 0.5
    use_path_orientations: bool = False


@dataclass(frozen=True)
class PathFollowCritic:
    """``critics/path_follow_critic.cpp``: the trajectory's end to the plan point beyond the furthest reached.

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    offset_from_furthest : int
        Plan points.
    threshold_to_consider : float
        m of plan left.
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 5.0
    offset_from_furthest: int = 6
    threshold_to_consider: float = 1.4


@dataclass(frozen=True)
class PathAngleCritic:
    """``critics/path_angle_critic.cpp`` in its forward-preference mode (``mode`` 0).

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    offset_from_furthest : int
        Plan points.
    threshold_to_consider : float
        m of plan left.
    max_angle_to_furthest : float
        rad: below it the critic does not apply.
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 2.2
    offset_from_furthest: int = 4
    threshold_to_consider: float = 0.5
    max_angle_to_furthest: float = 0.785398


@dataclass(frozen=True)
class PreferForwardCritic:
    """``critics/prefer_forward_critic.cpp``: cost_weight·Σ max(−vx, 0)·dt.

    Attributes
    ----------
    enabled : bool
    cost_power : int
    cost_weight : float
    threshold_to_consider : float
        m of plan left.
    """

    enabled: bool = True
    cost_power: int = 1
    cost_weight: float = 5.0
    threshold_to_consider: float = 0.5


def _wrap(a):
    """``utils::normalize_angles`` (single precision)."""
    r = np.fmod(a + F(math.pi), F(2.0 * math.pi))
    return np.where(r < 0, r + F(math.pi), r - F(math.pi)).astype(F)


class CriticData:
    """``CriticData`` for one cycle: the plan, the costmap, the costs, and what the critics share (the furthest plan
    point reached, the plan's valid points). As in Nav2, `prepare` resets these once per cycle, not per iteration:
    with ``iteration_count`` > 1 the costs accumulate and the furthest point of the first iteration is kept.

    Parameters
    ----------
    params : MPPIParams
        The controller's parameters (its critics' among them).
    state : RobotState
        The robot's pose and measured velocity.
    plan : LocalPlan
        The plan the controller server handed over (global frame).
    costmap : CorridorCostmap
        The local costmap.
    window : Window
        Its bounds around the robot.
    """

    def __init__(self, params, state, plan, costmap, window):
        self.params, self.state, self.costmap, self.window = params, state, costmap, window
        self.px, self.py, self.pyaw = (np.asarray(a, dtype=F) for a in (plan.x, plan.y, plan.yaw))
        self.path_length = float(plan.length)
        self.costs = np.zeros(params.batch_size, dtype=F)
        self.fail = False
        self._furthest = self._valid = None

    def rollout(self, vx, wz, x, y, yaws):
        """This iteration's trajectories.

        Parameters
        ----------
        vx, wz : ndarray of float32
            Velocities, m/s and rad/s, (time_steps, batch).
        x, y, yaws : ndarray of float32
            Poses, m and rad, (time_steps, batch).
        """
        self.vx, self.wz, self.x, self.y, self.yaws = vx, wz, x, y, yaws

    def furthest(self) -> int:
        """``findPathFurthestReachedPoint``: the furthest plan point any trajectory's end is nearest to."""
        if self._furthest is None:
            n = self.px.size
            dists = np.concatenate([[F(0)], np.cumsum(np.sqrt(np.diff(self.px) ** 2 + np.diff(self.py) ** 2), dtype=F)])
            length = np.sum(np.sqrt(np.diff(self.x, axis=0) ** 2 + np.diff(self.y, axis=0) ** 2), axis=0, dtype=F)
            reach = np.minimum(np.searchsorted(dists, length, side="left"), n - 1)
            d2 = (self.px[:, None] - self.x[-1]) ** 2 + (self.py[:, None] - self.y[-1]) ** 2
            d2 = np.where(np.arange(n)[:, None] <= reach, d2, np.inf)
            self._furthest = int(np.max(np.argmin(d2, axis=0)))
        return self._furthest

    def valid(self) -> np.ndarray:
        """``findPathCosts``: the plan points (all but the last) not on lethal, inscribed or unknown cost."""
        if self._valid is None:
            c = self.costmap.cost(self.px[:-1], self.py[:-1], self.window)
            self._valid = (c < 253) | ((c == 255) & self.params.track_unknown_space)
        return self._valid

    def add(self, cost, power: int):
        """Add a critic's costs to the batch's, raised to its ``cost_power``.

        Parameters
        ----------
        cost : ndarray of float32
            One per trajectory.
        power : int
            The critic's ``cost_power``.
        """
        self.costs += (cost ** power if power > 1 else cost).astype(F)


def _constraint(d: CriticData, c: ConstraintCritic):
    over = np.maximum(d.vx - F(d.params.vx_max), 0) + np.maximum(F(d.params.vx_min) - d.vx, 0)
    d.add(np.sum(over * F(d.params.model_dt), axis=0, dtype=F) * F(c.cost_weight), c.cost_power)


def _in_collision(d: CriticData, cost):
    lethal = (cost >= 253) & (cost < 255)  # LETHAL, and INSCRIBED for a point cost
    return lethal | ((cost >= 255) & (not d.params.track_unknown_space))


def _cost(d: CriticData, c: CostCritic):
    step = c.trajectory_point_step
    xs, ys = d.x[::step], d.y[::step]
    cost = d.costmap.cost(xs, ys, d.window).astype(F)
    collide = _in_collision(d, np.floor(cost))
    near_goal = d.path_length < c.near_goal_distance
    per_point = np.where(cost < 1, F(0), np.where(cost >= c.near_collision_cost, F(c.critical_cost), F(0) if near_goal else cost))
    collided = np.any(collide, axis=0)
    repulsive = np.where(collided, F(c.collision_cost), np.sum(per_point, axis=0, dtype=F))
    d.add(repulsive * F(c.cost_weight / 254.0 / xs.shape[0]), c.cost_power)
    d.fail = d.fail or bool(np.all(collided))


def _obstacles(d: CriticData, c: ObstaclesCritic):
    inf = d.costmap.inflation
    cost = d.costmap.cost(d.x, d.y, d.window).astype(F)
    hits = _in_collision(d, np.floor(cost)) & (cost >= 1)
    collide = np.any(hits, axis=0)
    before = np.cumsum(hits, axis=0) == 0  # the loop breaks at a trajectory's first collision
    with np.errstate(divide="ignore"):
        dist = (F(inf.cost_scaling_factor * inf.inscribed_radius) - np.log(cost) + F(math.log(253.0))) / F(inf.cost_scaling_factor)
    dist = dist - F(inf.inscribed_radius)
    active = (cost >= 1) & before
    near = np.sum(np.where(active & (dist < c.collision_margin_distance), F(c.collision_margin_distance) - dist, F(0)), axis=0, dtype=F)
    far = F(0) if d.path_length < c.near_goal_distance else np.sum(np.where(active, F(inf.inflation_radius) - dist, F(0)), axis=0, dtype=F)
    raw = np.where(collide, F(c.collision_cost), near)
    repulsive = far - np.min(far) if np.ndim(far) else np.zeros_like(raw)
    total = F(c.critical_weight) * raw + F(c.repulsion_weight) * repulsive / F(d.x.shape[0])
    d.add(total, c.cost_power)
    d.fail = d.fail or bool(np.all(collide))


def _goal(d: CriticData, c: GoalCritic):
    if d.path_length > c.threshold_to_consider:
        return
    dist = np.sqrt((d.x - d.px[-1]) ** 2 + (d.y - d.py[-1]) ** 2)
    d.add(np.mean(dist, axis=0, dtype=F) * F(c.cost_weight), c.cost_power)


def _goal_angle(d: CriticData, c: GoalAngleCritic):
    if d.path_length > c.threshold_to_consider:
        return
    d.add(np.mean(np.abs(_wrap(d.pyaw[-1] - d.yaws)), axis=0, dtype=F) * F(c.cost_weight), c.cost_power)


def closest_path_points(dists, traj_dist):
    """``utils::findClosestPathPt`` along each trajectory's points, each search starting at the previous match.

    Parameters
    ----------
    dists : ndarray of float32
        The plan's integrated distances (increasing from 0), m.
    traj_dist : ndarray of float32
        The trajectories' integrated distances at their points, (points, batch), m.

    Returns
    -------
    ndarray of int
        The matched plan point of every trajectory point, (points, batch).
    """
    size = dists.size
    matched = np.zeros(traj_dist.shape, dtype=np.int64)
    init = np.zeros(traj_dist.shape[1], dtype=np.int64)
    for p in range(traj_dist.shape[0]):
        d = traj_dist[p]
        i = np.maximum(np.searchsorted(dists, d, side="right"), init + 1)
        inside = i < size
        safe = np.minimum(i, size - 1)
        lower = (d - dists[safe - 1]) < (dists[safe] - d)
        init = np.where(inside, np.where(lower, safe - 1, safe), size - 1)
        matched[p] = init
    return matched


def _path_align(d: CriticData, c: PathAlignCritic):
    if d.path_length < c.threshold_to_consider:
        return
    count = d.furthest()
    if count < c.offset_from_furthest:
        return
    valid = d.valid()[:count]
    invalid = np.cumsum(~valid)
    if np.any((invalid / count > c.max_path_occupancy_ratio) & (invalid > 2)):
        return
    dists = np.concatenate([[F(0)], np.cumsum(np.sqrt(np.diff(d.px[:count]) ** 2 + np.diff(d.py[:count]) ** 2), dtype=F)])
    xs, ys = d.x[::c.trajectory_point_step], d.y[::c.trajectory_point_step]
    traj = np.cumsum(np.sqrt(np.diff(xs, axis=0) ** 2 + np.diff(ys, axis=0) ** 2), axis=0, dtype=F)
    matched = closest_path_points(dists, traj)
    ok = valid[matched]
    dist = np.sqrt((d.px[matched] - xs[1:]) ** 2 + (d.py[matched] - ys[1:]) ** 2)
    samples = np.sum(ok, axis=0)
    mean = np.where(samples > 0, np.sum(np.where(ok, dist, F(0)), axis=0, dtype=F) / np.maximum(samples, 1).astype(F), F(0))
    d.add(mean * F(c.cost_weight), c.cost_power)


def _path_follow(d: CriticData, c: PathFollowCritic):
    if d.px.size < 2 or d.path_length < c.threshold_to_consider:
        return
    last = d.px.size - 1
    idx = min(d.furthest() + c.offset_from_furthest, last)
    valid = d.valid()
    while idx < last - 1 and not valid[idx]:
        idx += 1
    dist = np.sqrt((d.x[-1] - d.px[idx]) ** 2 + (d.y[-1] - d.py[idx]) ** 2)
    d.add(dist * F(c.cost_weight), c.cost_power)


def _path_angle(d: CriticData, c: PathAngleCritic):
    if d.path_length < c.threshold_to_consider:
        return
    idx = min(d.furthest() + c.offset_from_furthest, d.px.size - 1)
    gx, gy = d.px[idx], d.py[idx]
    bearing = math.atan2(float(gy) - d.state.y, float(gx) - d.state.x)
    if abs(math.remainder(d.state.yaw - bearing, 2 * math.pi)) < c.max_angle_to_furthest:
        return
    towards = np.arctan2(gy - d.y[-1], gx - d.x[-1]).astype(F)
    d.add(np.abs(_wrap(towards - d.yaws[-1])) * F(c.cost_weight), c.cost_power)


def _prefer_forward(d: CriticData, c: PreferForwardCritic):
    if d.path_length < c.threshold_to_consider:
        return
    d.add(np.sum(np.maximum(-d.vx, 0) * F(d.params.model_dt), axis=0, dtype=F) * F(c.cost_weight), c.cost_power)


_SCORE = {"ConstraintCritic": _constraint, "CostCritic": _cost, "ObstaclesCritic": _obstacles, "GoalCritic": _goal,
          "GoalAngleCritic": _goal_angle, "PathAlignCritic": _path_align, "PathFollowCritic": _path_follow,
          "PathAngleCritic": _path_angle, "PreferForwardCritic": _prefer_forward}


def score(d: CriticData):
    """``CriticManager::evalTrajectoriesScores``: each enabled critic in order, stopping once one has failed.

    Parameters
    ----------
    d : CriticData
        The cycle's data with this iteration's rollout; its costs and failure flag are updated.
    """
    for name in d.params.critics:
        if d.fail:
            break
        critic = getattr(d.params, name)
        if critic.enabled:
            _SCORE[name](d, critic)
