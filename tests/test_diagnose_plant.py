"""What `diagnose` takes from the identified plant (`validation.diagnose.complete_from_log`, docs/diagnose.md "What it
needs"): the second lag τ_a and the slew limit reach the prediction through the Robot; the loop's dead time carries a
smoother's mean wait; a second lag the loop models do not take yet is predicted with the candidate without it.

The identifications are of `log_helpers`' plants (exact, independent of the package); the checks compare the Robot
`complete_from_log` returns with the fit's own numbers (which tests/test_identify_models.py checks against the truth).
"""

from __future__ import annotations

import math

import pytest

from log_helpers import Plant, Recording, simulate, write_log
from pfm_stability.analysis.identification import identify
from pfm_stability.io.logs import read_log
from pfm_stability.parameters import CARMEL
from pfm_stability.validation.diagnose import complete_from_log

PRESET = {name: "preset carmel" for name in ("tau", "T", "dead_time", "plant_gain", "actuator_lag", "yaw_accel_limit")}
"""Nothing given by the user: every log parameter comes from the log."""


@pytest.fixture(scope="module")
def identifications(tmp_path_factory):
    out = {}
    for name, plant in {"first": Plant(), "lags": Plant(g=0.85, tau=0.3, dead_time=0.06, tau2=0.05),
                        "smoother": Plant(g=0.9, tau=0.2, dead_time=0.08, slew=2.0, phase=0.013)}.items():
        path = write_log(simulate(plant, Recording(profile="steps", seed=4, duration=40.0)), tmp_path_factory.mktemp(name), "csv")
        out[name] = identify(read_log(path, need=("command", "odometry")), "odometry")
    return out


def test_a_first_order_plant_has_neither_and_says_so(identifications):
    r = identifications["first"]
    robot, controller, sources = complete_from_log(CARMEL.robot, CARMEL.controller, PRESET, r)
    assert robot.actuator_lag == 0.0 and math.isinf(robot.yaw_accel_limit)
    assert "none" in sources["actuator_lag"] and "none" in sources["yaw_accel_limit"]
    assert robot.tau == pytest.approx(r.plant.tau.value) and robot.dead_time == pytest.approx(max(r.plant.dead_time.value, 0))


def test_a_second_lag_reaches_the_robot(identifications):
    """A two-lag fit gives the Robot its τ, D, g and τ_a (the loop models take the second lag: `models.Loop.of`), each
    source naming the log and the interval."""
    r = identifications["lags"]
    robot, _, sources = complete_from_log(CARMEL.robot, CARMEL.controller, PRESET, r)
    assert r.plant.model == "two_lags"
    assert robot.actuator_lag == pytest.approx(r.plant.actuator_lag.value) and robot.tau == pytest.approx(r.plant.tau.value)
    assert "identified from" in sources["actuator_lag"] and "identified from" in sources["tau"]


def test_a_smoother_gives_the_slew_limit_and_its_wait(identifications):
    """The smoother's limit is the Robot's yaw_accel_limit, and the dead time the prediction uses is D plus the mean wait
    of the log's commands for a tick (the controller at 20 Hz, the smoother's phase 13 ms: the wait about 13 ms)."""
    r = identifications["smoother"]
    p = r.plant
    robot, _, sources = complete_from_log(CARMEL.robot, CARMEL.controller, PRESET, r)
    assert robot.yaw_accel_limit == pytest.approx(p.yaw_accel_limit.value) and "identified from" in sources["yaw_accel_limit"]
    assert p.smoother is not None and p.smoother.frequency == 20.0
    assert robot.dead_time == pytest.approx(max(p.loop_dead_time, 0.0)) and p.loop_dead_time > p.dead_time.value
    assert abs(p.loop_dead_time - 0.08 - 0.013) < 0.02  # the base's 80 ms and the wait for the 20-Hz tick


def test_what_the_user_gives_is_kept(identifications):
    r = identifications["smoother"]
    sources = dict(PRESET, yaw_accel_limit="user", actuator_lag="user")
    robot, _, out = complete_from_log(CARMEL.robot.replace(yaw_accel_limit=5.0), CARMEL.controller, sources, r)
    assert robot.yaw_accel_limit == 5.0 and out["yaw_accel_limit"] == "user"
