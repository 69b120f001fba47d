"""The loop driven along a drive's own path as the robot drove it (`maps.judging.driven.DrivenTrack`, `_driven`; docs/maps.md,
"A drive's own path is driven as the robot drove it"): the path's frame turning under the loop (`SampledTransition.turn`), the point the robot steered at
(`validation.map_drives._aims`, `RoutePath.aims`) and the window sum at the loop's own point."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pfm_stability.maps.judging.driven import PREDICTION_OFFSET, DrivenTrack, SampledTransition, _TrackWalk
from pfm_stability.maps.deciding.decide import path_samples
from pfm_stability.maps.reading.routes import path_of
from pfm_stability.models import Loop, models_for
from pfm_stability.models.sampled import continuous_plant
from pfm_stability.parameters import Controller, Robot
from pfm_stability.sim.scenario import Target
from pfm_stability.validation.map_drives import _taken_path
from test_map_driven import _driven, _loops


def test_the_frames_turn_enters_the_state_as_the_plant_integrates_a_heading_rate():
    """`SampledTransition.turn`: a frame turning at a steady rate 1/T rad/s through one period moves the plant's state
    as ẋ = A·x − e_θ/T from rest does (e_θ the heading's row), solved here by `scipy.integrate.solve_ivp` (RK45, rtol
    1e-11, atol 1e-14: agreement to 1e-9 relative, far above that accuracy and far below any physical effect), at
    random loops (τ, T, k, g, D), both holds and both compute delays; the commands on their way (the rest of the
    state) do not move."""
    for loop, hold, delay in _loops(11, 25):
        transition = SampledTransition.of(SimpleNamespace(hold=hold, compute_delay=delay), loop)
        A = continuous_plant(loop, hold)[0]
        n = A.shape[0]
        heading = transition.lateral_index - 1
        rate = np.zeros(n)
        rate[heading] = 1.0 / loop.T
        solved = solve_ivp(lambda _, x: A @ x + rate, (0.0, loop.T), np.zeros(n), rtol=1e-11, atol=1e-14).y[:, -1]
        assert np.allclose(transition.turn[:n], solved, rtol=1e-9, atol=1e-12 * max(1.0, loop.T)), (loop, hold, delay)
        assert np.all(transition.turn[n:] == 0.0)
        if hold == "command":  # the heading only integrates the turn rate: it turns by exactly the frame's angle
            assert transition.turn[heading] == pytest.approx(1.0, rel=1e-12)


def test_a_drives_aims_are_its_carrot_or_its_goal():
    """`RoutePath.aims` of a drive's path (`_taken_path`): following a straight plan along x from (0, 0) to (10, 0)
    with a 2 m lookahead, a robot 2 cm to its side aims at the plan's point 2 m ahead of its own x (the follower's
    progress, `sim.follow`), the plan's end within 2 m of it; towards a point target it aims at the target. Exact up to
    round-off (1e-12 m)."""
    t = np.arange(0.0, 18.0, 0.05)
    x, y = 0.5 * t, np.full(t.size, 0.02)
    plan = Target.follow([(0.0, 0.0), (10.0, 0.0)], 2.0)
    path = _taken_path(x, y, 2.0, 0.05, 0.1, 0, "drive", plan, None)
    expected = np.column_stack([np.minimum(path.points[:, 0] + 2.0, 10.0), np.zeros(len(path.points))])
    assert path.aims.shape == path.points.shape and np.abs(path.aims - expected).max() <= 1e-12
    goal = Target.point(9.0, 0.5, radius=0.3)
    path = _taken_path(x, y, 2.0, 0.05, 0.1, 0, "drive", goal, None)
    assert np.all(path.aims == [9.0, 0.5])


def _circle_track(radius: float, lookahead: float, length: float, cell: float):
    """A path round a circle (counter-clockwise, centre at the origin) with the carrot `lookahead` m ahead along it as
    each point's aim, no field: its samples, track and arc arrays."""
    arcs = np.arange(0.0, length + cell / 2, cell)
    points = radius * np.column_stack([np.cos(arcs / radius), np.sin(arcs / radius)])
    ahead = (arcs + lookahead) / radius
    path = path_of(points, 0, "drive", lookahead=lookahead, aims=radius * np.column_stack([np.cos(ahead), np.sin(ahead)]))
    x, y, tx, ty, route, arc, ds = path_samples([path], cell)
    no_field = lambda px, py: (np.zeros(np.shape(px)), np.zeros(np.shape(px)))  # noqa: E731
    track = DrivenTrack.of(None, None, [path], x, y, tx, ty, route, arc)
    return x, route, arc, DrivenTrack(track.x, track.y, track.heading, track.aims, no_field, track.start)


@pytest.mark.parametrize("radius, lookahead", [(3.0, 1.0), (6.0, 2.0), (2.0, 0.6)])
def test_round_a_bend_the_loop_holds_pure_pursuits_circle(radius, lookahead, monkeypatch):
    """Round a circle of radius R with no field, pursuing the carrot D ahead along it, the loop settles on the circle
    of radius R − y that pure pursuit holds: its progress along the path is V·R/(R − y) (`_TrackWalk`), so its frame
    turns at V/(R − y), and its steering asks for that turn, g·k·δ(y) = V/(R − y), where the carrot seen from the offset
    y (left, inwards) leads the tangent by δ(y) = atan2(R(1 − cos β) − y, R·sin β), β = D/R. That y* is found here by
    `scipy.optimize.brentq` (to 1e-12 m). Run for 15 time constants D/V, the loop's last lateral position matches it to
    50 µm: the path is a polygon of 1 cm chords (sagitta c²/8R <= 6 µm) whose carrot is interpolated along the chords,
    and its settling is e^-15 of a few centimetres, with margin. Without the frame's turn it would steer at the
    carrot's lead unopposed and leave the circle; with the frame turning at V/R (the loop walking the path at V) it
    would settle where g·k·δ = V/R instead, centimetres away."""
    from scipy.optimize import brentq

    robot = Robot(V=0.5, tau=0.3, k=2.0, W=0.3)
    controller = Controller(f=0.8, n=2.0, T=0.065, hold="command", compute_delay=1)
    model = models_for(controller, ["sampled"])[0]
    loop = Loop.of(robot, controller, c=0.0)
    transition = SampledTransition.of(model, loop)
    x, route, arc, track = _circle_track(radius, lookahead, 15 * lookahead, 0.01)
    n = x.size
    offsets = np.arange(-1.0, 1.0 + 1e-9, 0.0125)
    profile = (offsets, np.zeros((n, offsets.size)), np.zeros((n, offsets.size)))
    captured = {}
    import pfm_stability.maps.judging.episodes as episodes

    original = episodes.lateral_extent

    def spy(t, lateral, period):
        captured["lateral"] = np.array(lateral)
        return original(t, lateral, period)

    monkeypatch.setattr(episodes, "lateral_extent", spy)
    stopped = np.zeros((2, n), dtype=bool)
    _driven(route, arc, stopped, profile, np.zeros(n), np.ones(n), np.zeros(n), robot.V, transition, 2.8, True, track)
    beta = lookahead / radius

    def imbalance(y):
        return loop.steering_gain * math.atan2(radius * (1 - math.cos(beta)) - y, radius * math.sin(beta)) - robot.V / (radius - y)

    settled = brentq(imbalance, -radius / 2, radius / 2, xtol=1e-12)
    lateral = captured["lateral"]
    assert lateral.size * controller.T >= 14 * lookahead / robot.V
    assert abs(lateral[-1] - settled) <= 5e-5, (lateral[-1], settled)


def test_a_loop_weaving_about_its_path_covers_less_of_it():
    """`_TrackWalk.advance`: a step moves a loop on along its path by V·T·cos θ/(1 − κ·y) (a robot at heading θ from
    the path's, y to the left of a path bending left at curvature κ), and returns the path's turn over the step, κ
    times the arc covered on a circle. Checked to 1e-9 m and 1e-8 rad: the curvature and the turn come from the
    directions of the 1 cm chords of the circle (`_TrackWalk`), right to a few parts in 1e7 there."""
    radius = 4.0
    x, route, arc, track = _circle_track(radius, 1.0, 20.0, 0.01)
    walk = _TrackWalk(track, route, arc, [0], 0.05)
    start = walk.s.copy()
    turn = walk.advance(np.array([0.3]), np.array([0.2]))
    covered = 0.05 * math.cos(0.3) / (1 - 0.2 / radius)
    assert walk.s - start == pytest.approx([covered], abs=1e-9)
    assert turn == pytest.approx([covered / radius], abs=1e-8)


@pytest.mark.parametrize("direction", [0.0, 2.3, -1.1])
def test_the_loop_starts_where_the_robot_started(direction, monkeypatch):
    """`DrivenTrack.start` and the loop's first steps (`_driven`): a straight path in any direction, the robot's start
    pose (`RoutePath.start`, the simulator's `Pose`: heading from +Y towards +X) y0 to the left of its first sample and
    turned θ0 to the left of it: the track records (y0, θ0) to round-off (1e-12), and the loop's lateral position starts
    at y0 and moves V·T·θ0 in the first period, to round-off (with the command held and one period of compute delay
    the first period's command is the one in flight, zero; no field, the path straight: nothing else moves it). At a
    path without a start pose the loop starts `PREDICTION_OFFSET` off as on a route."""
    robot = Robot(V=0.5, tau=0.3, k=2.0, W=0.3)
    controller = Controller(f=0.8, n=2.0, T=0.065, hold="command", compute_delay=1)
    transition = SampledTransition.of(models_for(controller, ["sampled"])[0], Loop.of(robot, controller, c=0.0))
    ux, uy = math.cos(direction), math.sin(direction)
    arcs = np.arange(0.0, 12.0, 0.05)
    points = np.column_stack([3.0 + arcs * ux, -1.0 + arcs * uy])
    y0, theta0 = 0.021, -0.07
    sx, sy = 3.0 - uy * y0, -1.0 + ux * y0  # y0 to the left of the path's start
    pose = math.pi / 2 - (direction + theta0)  # the simulator's heading: from +Y towards +X
    no_field = lambda px, py: (np.zeros(np.shape(px)), np.zeros(np.shape(px)))  # noqa: E731
    import pfm_stability.maps.judging.episodes as episodes

    original = episodes.lateral_extent
    for start, first in (((sx, sy, pose), y0), (None, PREDICTION_OFFSET)):
        path = path_of(points, 0, "drive", aims=points + 20.0 * np.array([ux, uy]), start=start)
        x, y, tx, ty, route, arc, _ = path_samples([path], 0.05)
        track = DrivenTrack.of(None, None, [path], x, y, tx, ty, route, arc)
        if start is not None:
            assert track.start[:, 0] == pytest.approx([y0, theta0], abs=1e-12)
        else:
            assert np.isnan(track.start).all()
        captured = {}

        def spy(t, lateral, period):
            captured["lateral"] = np.array(lateral)
            return original(t, lateral, period)

        monkeypatch.setattr(episodes, "lateral_extent", spy)
        n = x.size
        offsets = np.arange(-1.0, 1.0 + 1e-9, 0.0125)
        profile = (offsets, np.zeros((n, offsets.size)), np.zeros((n, offsets.size)))
        _driven(route, arc, np.zeros((2, n), dtype=bool), profile, np.zeros(n), np.ones(n), np.zeros(n), robot.V, transition,
                2.8, True, DrivenTrack(track.x, track.y, track.heading, track.aims, no_field, track.start))
        lateral = captured["lateral"]
        assert lateral[0] == pytest.approx(first, abs=1e-12)
        if start is not None:
            assert lateral[1] - lateral[0] == pytest.approx(robot.V * controller.T * theta0, abs=1e-12)


@pytest.mark.parametrize("start", [(0.0, 1.0), (0.0, float("nan"), 1.0), (0.0, 0.0, float("inf"))])
def test_a_start_pose_must_be_three_finite_numbers(start):
    """`path_of`'s ``start`` (`RoutePath.start`): anything but x, y (m) and a heading (rad), finite, is a ValueError naming
    it, not a loop that dies on a NaN state (`_driven`)."""
    with pytest.raises(ValueError, match="start must be a pose"):
        path_of([(0.0, 0.0), (1.0, 0.0)], 0, "drive", start=start)
