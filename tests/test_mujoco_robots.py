"""The MuJoCo robots that test identification (docs/mujoco.md, "Robots B and C") and the command path between the
controller and the wheels (`pfm_stability.engines.command_path`): Nav2's velocity smoother, a jittered controller, a
jittered odometry. Skipped, with the reason, when the optional extra ``mujoco`` is not installed.

Truths are the files' and the options' own numbers: the actuator filter's time constant (the MJCF ``dynprm``), the
smoother's limit, the jitter's bound. Nav2's smoother rule is checked against its source's cases (nav2_velocity_smoother
``applyConstraints``: accelerating when |command| ≥ |current| and the signs agree, else decelerating; the limit per
tick is the acceleration over the nominal frequency; the timer's period a whole number of milliseconds).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="the optional extra 'mujoco' is not installed (pip install 'pfm-stability[mujoco]')")

from pfm_stability.analysis.identification import fit_plant, controller_timing  # noqa: E402
from pfm_stability.engines.command_path import CommandPath, Timing, VelocitySmoother  # noqa: E402
from pfm_stability.engines.mujoco import EngineOptions, corridor_log, drive_log  # noqa: E402
from pfm_stability.engines.robots import corridor_world, load_robot_model, place  # noqa: E402
from pfm_stability.io.logs import TimeSeries  # noqa: E402
from pfm_stability.parameters import Controller, Robot  # noqa: E402
from pfm_stability.sim.presets import make_scenario  # noqa: E402

NAV2 = VelocitySmoother(max_accel=2.0, max_decel=2.0)
"""Robot C's smoother: Nav2's defaults (20 Hz, OPEN_LOOP) with an angular acceleration limit of 2 rad/s²."""
C_TIMING = Timing(period_jitter=0.15, odom_rate=20.0, odom_jitter=0.1, seed=1)
"""Robot C's timing: the controller's period within ±15 %, odometry at 20 Hz within ±10 %."""


# ------------------------------------------------------------------------------ Nav2's smoother
def test_the_smoother_applies_nav2s_constraints():
    """Speeding up is limited by max_accel/f, slowing down and passing through zero by max_decel/f; the command is
    clamped to max_velocity first; the timer's period is int(1000/f) ms."""
    s = VelocitySmoother(max_accel=2.0, max_decel=4.0, smoothing_frequency=20.0, max_velocity=1.0)
    assert s.step(0.5, 1.0) == pytest.approx(0.6)  # speeding up: 2/20
    assert s.step(0.5, 0.0) == pytest.approx(0.3)  # slowing down: 4/20
    assert s.step(0.1, -1.0) == pytest.approx(-0.1)  # through zero counts as slowing down
    assert s.step(0.0, 5.0) == pytest.approx(0.1)  # clamped to 1 rad/s, then limited
    assert s.step(0.95, 5.0) == pytest.approx(1.0)
    assert VelocitySmoother(2.0, 2.0, smoothing_frequency=30.0).period == 0.033
    with pytest.raises(ValueError, match="feedback"):
        VelocitySmoother(2.0, 2.0, feedback="SOMETIMES")


def test_the_command_path_ramps_holds_delays_and_times_out():
    """A step of 1 rad/s through the OPEN_LOOP smoother at 20 Hz reaches the wheels as a staircase of 0.1 rad/s every
    50 ms, each 30 ms after its tick (the command's dead time); a command older than the timeout becomes 0."""
    path = CommandPath(0.001, 30, NAV2, Timing())
    path.publish(0, 1.0)
    seen, step = [], 0
    while step < 700:
        reached = path.due(step, 0.0)
        if reached is not None:
            seen.append((step, reached))
        step = path.next_event(step)
    assert [s for s, _ in seen[:4]] == [30, 80, 130, 180]
    assert [v for _, v in seen[:10]] == pytest.approx(np.arange(1, 11) * 0.1)
    late = CommandPath(0.001, 0, VelocitySmoother(2.0, 2.0, velocity_timeout=0.2), Timing(), initial=0.5)
    late.publish(0, 0.5)
    values = {}
    step = 0
    while step < 600:
        reached = late.due(step, 0.0)
        if reached is not None:
            values[step] = reached
        step = late.next_event(step)
    assert values[200] == pytest.approx(0.5) and values[250] == pytest.approx(0.4)  # timed out after 0.2 s: decelerates


def test_closed_loop_feedback_starts_from_the_odometry():
    """CLOSED_LOOP: the current velocity is the mean of the odometry's yaw rates within odom_duration of the newest
    (Nav2's OdomSmoother), so a robot that turns at 0.3 rad/s whatever it is told gets 0.3 + 2/20 at every tick — where
    OPEN_LOOP would ramp on from its own output."""
    outputs = {}
    for feedback in ("CLOSED_LOOP", "OPEN_LOOP"):
        path = CommandPath(0.001, 0, VelocitySmoother(2.0, 2.0, feedback=feedback, odom_duration=0.1), Timing(odom_rate=100.0))
        path.publish(0, 1.0)
        out, step = {}, 0
        while step <= 200:
            reached = path.due(step, 0.3)
            if reached is not None:
                out[step] = reached
            step = path.next_event(step)
        outputs[feedback] = out
    assert [outputs["CLOSED_LOOP"][s] for s in (0, 50, 100, 150, 200)] == pytest.approx([0.4] * 5)
    assert [outputs["OPEN_LOOP"][s] for s in (0, 50, 100, 150, 200)] == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5])


def test_the_controller_and_the_odometry_jitter_within_their_bounds():
    ticks = C_TIMING.controller_ticks(1 / 11, 0.001)
    steps = np.diff([next(ticks) for _ in range(2000)])
    assert steps.min() >= math.floor(0.85 * 1000 / 11) and steps.max() <= math.ceil(1.15 * 1000 / 11)
    assert np.mean(steps) == pytest.approx(1000 / 11, rel=0.01) and np.std(steps) > 3
    odom = C_TIMING.odometry_ticks(0.001)
    gaps = np.diff([next(odom) for _ in range(500)])
    assert 45 <= gaps.min() and gaps.max() <= 55 and np.std(gaps) > 1


def test_a_timer_does_not_drift_by_the_rounding_to_the_engine_step():
    """A 20-Hz timer (the smoother's, 50 ms) on engine steps of (1/11)/91 s (robot C's: 1/11 s in whole steps) ticks at
    whole multiples of 50 ms, each within half a step: rounding each interval to 50 steps would make it 49.95 ms, 60 ms
    (more than a tick) off after a minute, and the identified smoother's phase would drift through the log (a dead time
    of −21 ms and a spurious second lag came of it). The jittered controller's ticks keep their mean period the same way."""
    from pfm_stability.engines.command_path import jittered_steps

    dt = (1 / 11) / 91
    ticks = jittered_steps(0, 0.05, 0.0, dt, None)
    steps = np.array([next(ticks) for _ in range(1201)])
    assert np.all(np.abs(steps * dt - 0.05 * np.arange(1201)) <= dt / 2 + 1e-12)
    jittered = C_TIMING.controller_ticks(1 / 11, dt)
    after = [next(jittered) for _ in range(6601)][-1]
    # 6600 intervals of (1/11)(1 + ε), ε uniform in ±0.15: their sum's standard deviation is (1/11)·0.15·√(6600/3) = 0.64 s
    assert abs(after * dt - 600.0) < 4 * 0.64


# ------------------------------------------------------------------------------ the robots
@pytest.fixture(scope="module")
def drives():
    """One identification drive per robot (steps then a chirp, 40 s): B at 1.2 m/s, C at 0.7 m/s through its smoother
    and timing with 0.5 rad/s steps (large enough for the limit to act)."""
    return {"B": drive_log("both", options=EngineOptions(robot_model="diffdrive-filtered"), V=1.2, T=0.05, amplitude=0.1,
                           duration=40.0),
            "C": drive_log("both", options=EngineOptions(robot_model="skid-steer", smoother=NAV2, timing=C_TIMING), V=0.7,
                           T=1 / 11, amplitude=0.5, duration=40.0)}


def _fit(log):
    fit, reason = fit_plant(log.cmd_t, log.cmd_wz, TimeSeries("/imu", "sensor_msgs/msg/Imu", log.imu_t, log.imu_wz, "header"),
                            controller_timing(log.cmd_t).T)
    assert fit is not None, reason
    return fit


def test_robot_b_shows_its_actuator_filter(drives):
    """The filter of robot B (dynprm 0.1 s) is the second lag `identify` selects, within 5 % (the yaw rate's other lag is
    the wheel servo's and the chassis', about 0.13 s), with the dead time near 0: the first order would fold it into a
    dead time of 30 ms or more."""
    fit = _fit(drives["B"])
    assert fit.model == "two_lags" and fit.actuator_lag.value == pytest.approx(0.1, rel=0.05)
    assert abs(fit.dead_time.value) < 0.005
    first = next(m for m in fit.models if m.model == "first_order")
    assert first.parameters.dead_time > 0.03 and first.bic > next(m for m in fit.models if m.selected).bic


def test_robot_c_shows_its_smoother(drives):
    """Robot C's commands pass Nav2's smoother (2 rad/s² at 20 Hz) and a jittered controller: `identify` selects a plant
    with a slew limit fitted as a 20-Hz smoother, within 10 % of 2 rad/s² and its interval holding it, and the mean wait
    of the commands for a tick near half a tick (the controller's clock is its own); the jitter shows in the stamps.
    (With 0.3 rad/s steps instead of 0.5 the limit comes out 1.6–7 % high: docs/mujoco.md.)"""
    fit = _fit(drives["C"])
    assert fit.yaw_accel_limit is not None and fit.yaw_accel_limit.value == pytest.approx(2.0, rel=0.1)
    assert fit.yaw_accel_limit.low <= 2.0 <= fit.yaw_accel_limit.high
    assert fit.smoother.frequency == 20.0 and fit.smoother.mean_wait == pytest.approx(0.025, abs=0.003)
    timing = controller_timing(drives["C"].cmd_t)
    assert 0.077 < timing.p5 < timing.T < timing.p95 < 0.105


def test_a_plant_behind_the_smoother_is_the_plant_without_it(drives):
    """The smoother and the jitter identified as what they are leave the robot's own plant: robot A (a linear differential
    drive) behind robot C's smoother and timing gives the gain, the lag and the dead time that the same drive gives
    without them (to 0.5 %, 1 % and 2 ms: the fits' noise), and robot C (which skids: its yaw rate is mildly nonlinear
    beyond 0.3 rad/s, and the smoother's ramps weigh its response differently) within 2 %, 8 % and 5 ms (the issue's
    targets are 5 %, 10 % and 20 ms; measured 0.2 %, 5.2 %, 3.7 ms); neither with a second lag standing in for a timer's
    drift."""
    fits = {}
    for name, through in (("diffdrive", None), ("diffdrive", drives), ("skid-steer", None), ("skid-steer", drives)):
        if through is not None and name == "skid-steer":
            log = drives["C"]
        else:
            options = EngineOptions(robot_model=name, **({} if through is None else dict(smoother=NAV2, timing=C_TIMING)))
            log = drive_log("both", options=options, V=0.7, T=1 / 11, amplitude=0.5, duration=40.0)
        fits[name, through is not None] = _fit(log)
    for name, (g, tau, D) in (("diffdrive", (0.005, 0.01, 0.002)), ("skid-steer", (0.02, 0.08, 0.005))):
        bare, fit = fits[name, False], fits[name, True]
        assert bare.model == "first_order" and fit.model == "slew_limited", name
        assert fit.g.value == pytest.approx(bare.g.value, rel=g) and fit.tau.value == pytest.approx(bare.tau.value, rel=tau), name
        assert abs(fit.dead_time.value - bare.dead_time.value) < D and abs(bare.dead_time.value) < 0.002, name  # no delay in either file


def test_the_skid_steer_turns_linearly_by_skidding():
    """Robot C's steady yaw rate is the same fraction of a 0.01 and a 0.3 rad/s turn of its wheels (to 0.5 %: the loop
    models' small-signal assumption holds) and well below it (it skids: 0.2–0.6); its base slides sideways in a turn
    (unlike a differential drive), more in a sharper one."""
    robot = load_robot_model("skid-steer")
    model = corridor_world(robot.path, math.inf, 0.0, 0.0)
    data = mujoco.MjData(model)
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    gains, side = [], []
    for command in (0.01, 0.3):
        place(model, data, robot, 0.0, 0.0, 0.0, 0.8)
        data.ctrl[:] = robot.wheel_speeds(0.8, -command)
        mujoco.mj_step(model, data, nstep=3000)
        gains.append(float(data.qvel[5]) / command)
        local = data.xmat[base].reshape(3, 3).T @ data.qvel[:3]
        side.append(abs(local[1] / local[0]))
    assert gains[0] == pytest.approx(gains[1], rel=0.005) and 0.2 < gains[0] < 0.6
    assert side[1] > 10 * side[0] > 0


def _bag(log, path):
    """Robot C's corridor log written as an MCAP bag (its commands, odometry with MuJoCo's pose, scans)."""
    from log_helpers import Plant, Recording, SyntheticLog, write_ros2

    synthetic = SyntheticLog(Plant(), Recording(T=1 / 11, scan_rate=10.0), log.cmd_t, log.cmd_wz, log.cmd_vx, log.odom_t,
                             log.odom_wz, scan_t=log.scan_t, odom_x=log.odom_x, odom_y=log.odom_y, odom_yaw=log.odom_yaw,
                             odom_vx=log.odom_vx, scan_ranges=log.scan_ranges)
    return write_ros2(synthetic, path, storage="mcap")


@pytest.fixture(scope="module")
def corridor_c():
    robot = Robot(V=0.6, tau=0.1, k=2.0, W=0.5)
    scenario = make_scenario("corridor", env="grid", robot=robot, controller=Controller(f=3.0, n=2.0, T=1 / 11, compute_delay=1),
                             L=0.7, offset=0.05, duration=10.0)
    return corridor_log(scenario, EngineOptions(robot_model="skid-steer", smoother=NAV2, timing=C_TIMING))


def test_a_corridor_run_of_robot_c_is_recorded_as_its_log(corridor_c):
    """The log of a corridor run through the command path: commands at the jittered ticks (10–13 Hz), odometry at 20 Hz
    with its jitter, the offset measured on the nominal grid (interpolated between the ticks)."""
    log = corridor_c
    gaps = np.diff(log.cmd_t)
    assert 0.076 <= gaps.min() and gaps.max() <= 0.106 and np.std(gaps) > 0.003  # ±15 % of 1/11 s, in whole engine steps
    odom = np.diff(log.odom_t)
    assert 0.044 <= odom.min() and odom.max() <= 0.056 and np.mean(odom) == pytest.approx(0.05, rel=0.02)
    assert np.allclose(np.diff(log.run.offset_t), 1 / 11) and log.run.metrics.angular_frequency > 0


def _grid_law(config):
    """The grid law of a configuration file, as diagnose builds it."""
    from pfm_stability.laws.force_law import law_in_force
    from pfm_stability.sim.scenario import scenario_law

    return law_in_force(config.robot, config.controller, scenario_law("grid", config.robot, config.controller))


def test_diagnose_sets_the_slew_limit_against_the_commands(corridor_c, tmp_path):
    """`diagnose` of robot C's run (logged as a bag) with the slew limit in the configuration: the JSON (valid) carries
    the limit, that the table's prediction is the linear loop's, the limited loop's V* for a weave the size the judged
    stretch shows (wired: the value `analysis.disturbance` gives there, which tests/test_rate_limit_disturbance.py checks
    against the simulator), and the commands' 95th-percentile |du/dt| over the judged stretch — recomputed here from the
    logged commands; from 5 cm off at 0.6 m/s it stays below the limit."""
    import json

    from cli_helpers import VALIDATOR, run as run_cli
    log = corridor_c
    bag = _bag(log, tmp_path / "c")
    config = tmp_path / "robot.yaml"
    config.write_text("robot: {k: 2.0, W: 0.5, tau: 0.13, plant_gain: 0.3, yaw_accel_limit: 2.0}\n"
                      "controller: {T: 0.0909, f: 3.0, n: 2, hold: command, compute_delay: 1}\nlaw: grid\n")
    code, out, err = run_cli(["diagnose", str(bag), "--config", str(config), "--format", "json"])
    assert code == 0, err
    data = json.loads(out)
    assert [f"{list(e.absolute_path)}: {e.message[:120]}" for e in VALIDATOR.iter_errors(data)] == []
    limiter = data["limiter"]
    assert limiter["yaw_accel_limit"] == 2.0 and "linear" in limiter["note"]
    # the limited loop asked at the weave the judged stretch shows: analysis.disturbance's V*(D) at that amplitude
    from pfm_stability.analysis.disturbance import corridor_disturbance
    from pfm_stability.io.config import load_config

    judged = data["stretches"][data["measured"]["stretch"]]
    filed = load_config(config)
    robot = filed.robot.replace(V=judged["V"], tau=data["parameters"]["tau"]["value"], dead_time=data["parameters"]["dead_time"]["value"],
                                plant_gain=data["parameters"]["plant_gain"]["value"])
    expected = corridor_disturbance(robot, filed.controller.replace(T=data["parameters"]["T"]["value"]), _grid_law(filed),
                                    judged["L"], limiter["disturbance"]).V_disturbance
    assert limiter["in_prediction"] is True and limiter["disturbance"] == pytest.approx(judged["measured"]["amplitude"])
    assert limiter["V_disturbance"] == pytest.approx(expected, rel=1e-9) and limiter["V_disturbance"] > 0
    stretch = data["stretches"][data["measured"]["stretch"]]
    inside = (log.cmd_t >= stretch["start"]) & (log.cmd_t <= stretch["end"])
    rates = np.abs(np.diff(log.cmd_wz[inside]) / np.diff(log.cmd_t[inside]))
    # the bag's stamps are read back as seconds since 1.7e9 s: float64 holds them to 2.4e-7 s, which over the shortest
    # command interval (0.077 s, 11 Hz - 15 %) moves a rate by up to 2 * 2.4e-7 / 0.077 = 6e-6 of itself
    assert limiter["commanded_acceleration"] == pytest.approx(np.percentile(rates, 95), rel=2e-5)
    assert limiter["reached"] is False and data["parameters"]["yaw_accel_limit"]["value"] == 2.0


def test_robot_bs_second_lag_predicts_its_boundary():
    """The loop models take τ_a: robot B identified at 0.8 m/s (a two-lag plant) predicts MuJoCo's V* in a 0.9 m
    corridor (0.796 m/s from 1 cm, T = 0.1 s, k = 2, f = 3, n = 2, compute delay 1: experiments/results/diagnose_mujoco.json,
    a 1 % bracket) within 3 % with the ``sampled`` model, where its first-order candidate lands 4.8 % low."""
    from pfm_stability.sim.scenario import scenario_law
    from pfm_stability.validation.common import predicted_boundaries, validation_models

    log = drive_log("both", options=EngineOptions(robot_model="diffdrive-filtered"), V=0.8, T=0.05, amplitude=0.1, duration=40.0)
    fit = _fit(log)
    assert fit.model == "two_lags"
    robot = Robot(V=0.8, tau=fit.tau.value, k=2.0, W=0.5, plant_gain=fit.g.value, dead_time=max(fit.dead_time.value, 0.0),
                  actuator_lag=fit.actuator_lag.value)
    controller = Controller(f=3.0, n=2.0, T=0.1, hold="command", compute_delay=1)
    V = predicted_boundaries("corridor", "V", robot, controller, scenario_law("grid", robot, controller), 0.9,
                             validation_models(controller))["sampled"]
    assert V == pytest.approx(0.796, rel=0.03)


def test_diagnose_measures_robot_cs_slide_from_its_pose(corridor_c, tmp_path):
    """`diagnose` without τ and T identifies the plant from the bag and the base's slide from its /odom pose (MuJoCo's
    state, which sees the base move): τ_s within 1 ms of the 9.53 ms robot C's drive gives (docs/diagnose.md, "The
    slide"; a 10-s run at 0.6 m/s turns less than the drive, hence the looser tolerance), and the prediction uses it."""
    import json

    from cli_helpers import run as run_cli
    log = corridor_c
    bag = _bag(log, tmp_path / "c")
    config = tmp_path / "robot.yaml"
    config.write_text("robot: {k: 2.0, W: 0.5}\ncontroller: {f: 3.0, n: 2, hold: command, compute_delay: 1}\nlaw: grid\n")
    code, out, err = run_cli(["diagnose", str(bag), "--config", str(config), "--format", "json"])
    assert code == 0, err
    slip = json.loads(out)["parameters"]["slip_lag"]
    assert slip["value"] == pytest.approx(0.00953, abs=0.001) and slip["source"].startswith("identified from the pose of")
