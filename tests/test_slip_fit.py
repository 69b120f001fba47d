"""The slide's lag τ_s measured from a pose (`pfm_stability.analysis.slip_fit`, docs/diagnose.md "The slide"): exact
synthetic kinematics with a known τ_s, the inputs it refuses, MuJoCo's robots against their own velocities, and the
``identify`` command."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

from cli_helpers import VALIDATOR, run
from pfm_stability.analysis.slip_fit import MIN_SPEED, fit_slip_lag
from pfm_stability.io.logs import LogError, read_log

FINE = 1e-3
"""The synthetic kinematics' integration step, s (the pose is sampled from it at 50 Hz)."""


def kinematics(slip_lag: float, seed: int, *, noise: float = 0.0, V: float = 0.8, duration: float = 40.0, rate: float = 50.0,
               plant_lag: float = 0.2, amplitude: float = 0.3, offset: float = 0.0, jitter: float = 0.0):
    """(t, x, y, yaw) of a base at speed V whose yaw rate follows random steps (held 1–2.5 s, within ±`amplitude` rad/s)
    through a lag of `plant_lag` s, and whose course χ follows its heading θ through τ_s·χ̇ + χ = θ, both exact on a
    1-ms grid (the lags' responses to piecewise-constant and piecewise-linear inputs); x, y integrate V·(cos χ, sin χ)
    by the trapezoid rule. Sampled at `rate` Hz (each instant moved by up to ±`jitter` of a period), the position with
    Gaussian noise of `noise` m, the yaw offset by `offset` rad (a pose whose heading is askew)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration + FINE / 2, FINE)
    edges, levels = [0.0], [0.0]
    while edges[-1] < duration:
        edges.append(edges[-1] + rng.uniform(1.0, 2.5))
        levels.append(rng.uniform(-amplitude, amplitude))
    u = np.asarray(levels)[np.searchsorted(edges, t, side="right") - 1]
    a, r, z = math.exp(-FINE / plant_lag), np.empty_like(t), 0.0
    for i, ui in enumerate(u.tolist()):
        r[i] = z
        z = ui + (z - ui) * a
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * FINE)])
    chi = theta.copy()
    if slip_lag > 0:
        b, c, th = math.exp(-FINE / slip_lag), 0.0, theta.tolist()
        for i in range(t.size - 1):
            chi[i] = c
            slope = (th[i + 1] - th[i]) / FINE
            c = th[i + 1] - slip_lag * slope + (c - th[i] + slip_lag * slope) * b
        chi[-1] = c
    vx, vy = V * np.cos(chi), V * np.sin(chi)
    x = np.concatenate([[0.0], np.cumsum(0.5 * (vx[1:] + vx[:-1]) * FINE)])
    y = np.concatenate([[0.0], np.cumsum(0.5 * (vy[1:] + vy[:-1]) * FINE)])
    every = int(round(1.0 / (rate * FINE)))
    k = np.arange(every, t.size - every, every)
    if jitter:
        k = k + np.round(rng.uniform(-jitter, jitter, k.size) * every).astype(int)
    xs, ys = x[k] + rng.normal(0.0, noise, k.size), y[k] + rng.normal(0.0, noise, k.size)
    return t[k], xs, ys, np.angle(np.exp(1j * (theta[k] + offset)))


# ------------------------------------------------------------------------------ synthetic kinematics
@pytest.mark.parametrize("slip_lag", [0.009, 0.05, 0.1])
def test_exact_kinematics_give_the_slide(slip_lag):
    """Without noise τ_s comes back within 0.05 ms (the kinematics' trapezoid integration and the chords' second-order
    error leave 11 µs), whatever τ_s: the lag's own lag is corrected (a regression on −V·r alone is 2.5 % low at
    τ_s = 0.1 s here; its bound `lag_bias` says 3.4 %). No heading offset is found where there is none (within 10 µrad)."""
    fit, reason = fit_slip_lag(*kinematics(slip_lag, 1))
    assert reason is None
    assert fit.slip_lag.value == pytest.approx(slip_lag, abs=5e-5)
    assert fit.slip_lag.low <= slip_lag <= fit.slip_lag.high
    assert abs(fit.misalignment.value) < 1e-5 and fit.r2 > 0.99
    assert 0.0 < fit.lag_bias < 0.05 and fit.speed == pytest.approx(0.8, rel=1e-3)


def test_noise_jitter_and_a_skewed_heading():
    """0.1 mm of position noise, sample instants jittered by ±20 % of a period and a pose heading 20 mrad askew: τ_s within
    1 ms (σ ≈ 0.3 ms: 3.5 mm/s of noise per chord over 2000 chords against V·std(r) ≈ 0.13 m/s²; a chord rotated by one
    end's heading would be off by the jitter's r·Δt), and the offset found within 0.5 mrad (its σ ≈ 0.05 mrad)."""
    fit, _ = fit_slip_lag(*kinematics(0.03, 7, noise=1e-4, jitter=0.2, offset=0.02))
    assert fit.slip_lag.value == pytest.approx(0.03, abs=1e-3)
    assert fit.misalignment.value == pytest.approx(0.02, abs=5e-4)


def test_the_intervals_hold_the_truth():
    """20 seeds, τ_s drawn in 0–0.1 s, 0.1 mm of position noise: the 95 % interval holds the truth in at least 16 of 20
    (binomial at 0.95: 15 or fewer happens with probability 0.3 %; the seeds are fixed, so this is a measurement, not a
    flaky draw: 20 of 20 held it when this was written, the errors within 0.3 σ: with white position noise the interval
    is conservative, the module docstring of slip_fit). τ_s = 0 gives an interval holding 0."""
    rng = np.random.default_rng(2024)
    held = []
    for seed, truth in enumerate(rng.uniform(0.0, 0.1, 20)):
        fit, _ = fit_slip_lag(*kinematics(float(truth), 100 + seed, noise=1e-4, duration=30.0))
        held.append(fit.slip_lag.low <= truth <= fit.slip_lag.high)
    assert sum(held) >= 16, held
    fit, _ = fit_slip_lag(*kinematics(0.0, 5, noise=1e-4))
    assert fit.slip_lag.low <= 0.0 <= fit.slip_lag.high


# ------------------------------------------------------------------------------ what it refuses
def test_what_cannot_show_a_slide_is_a_reason():
    t, x, y, yaw = kinematics(0.01, 3)
    straight = (t, 0.8 * t, np.zeros_like(t), np.zeros_like(t))
    fit, reason = fit_slip_lag(*straight)
    assert fit is None and reason.startswith("too little turning")
    still = (t, np.zeros_like(t), np.zeros_like(t), 0.3 * t)  # turning in place
    fit, reason = fit_slip_lag(*still)
    assert fit is None and reason.startswith("the robot did not move") and f"{MIN_SPEED:g} m/s" in reason
    fit, reason = fit_slip_lag(t[:30], x[:30], y[:30], yaw[:30])
    assert fit is None and "only 30 samples" in reason
    slow = (t, np.where(t < 0.4, 0.8 * t, 0.32), np.zeros_like(t), np.zeros_like(t))  # moves for 20 samples, then stops
    fit, reason = fit_slip_lag(*slow)
    assert fit is None and reason.startswith("only") and "while the robot moves" in reason


@pytest.mark.parametrize("bad", ["nan", "inf", "length", "backwards", "shape"])
def test_bad_inputs_are_value_errors(bad):
    t, x, y, yaw = kinematics(0.01, 3, duration=5.0)
    if bad == "nan":
        x = x.copy()
        x[10] = np.nan
    elif bad == "inf":
        yaw = yaw.copy()
        yaw[3] = np.inf
    elif bad == "length":
        y = y[:-1]
    elif bad == "backwards":
        t = t.copy()
        t[5] = t[3]
    else:
        x = np.stack([x, x])
    with pytest.raises(ValueError, match={"nan": "finite", "inf": "finite", "length": "one length", "backwards": "backwards",
                                          "shape": "one-dimensional"}[bad]):
        fit_slip_lag(t, x, y, yaw)


def test_a_csv_pose_is_three_columns(tmp_path):
    """x, y, yaw are read together as the pose (optional: a CSV without them reads as before); one of them blank in a row
    that has the others is a one-line error."""
    path = tmp_path / "log.csv"
    path.write_text("t,cmd_wz,odom_wz,x,y,yaw\n0,0,,,,\n0.02,,0,0,0,0\n0.04,,0,0.016,0,0.001\n")
    pose = read_log(path, need=("command", "odometry"), optional=("pose",)).pose
    assert pose.topic == "x,y,yaw" and pose.t.tolist() == pytest.approx([0.02, 0.04]) and pose.x.tolist() == [0.0, 0.016]
    assert pose.vx == pytest.approx([0.8, 0.8], rel=1e-6)
    path.write_text("t,cmd_wz,odom_wz,x,y,yaw\n0,0,,,,\n0.02,,0,0,0,\n")
    with pytest.raises(LogError, match=r"line 3: the pose is x, y, yaw together; yaw blank"):
        read_log(path, need=("command", "odometry"), optional=("pose",))


# ------------------------------------------------------------------------------ MuJoCo
ROBOTS = ("skid-steer", "diffdrive")
"""Robot C and robot A (docs/mujoco.md)."""


@pytest.fixture(scope="module")
def drives(tmp_path_factory):
    """Each robot's drive (steps then a chirp, V 0.8 m/s, ±0.3 rad/s, T 1/11 s, 40 s), written as a CSV with its true
    pose and one without."""
    pytest.importorskip("mujoco", reason="the optional extra 'mujoco' is not installed (pip install 'pfm-stability[mujoco]')")
    from pfm_stability.engines.mujoco import EngineOptions, drive_log, write_csv_log

    out = {}
    for name in ROBOTS:
        log = drive_log("both", options=EngineOptions(robot_model=name), V=0.8, T=1 / 11, amplitude=0.3, duration=40.0)
        folder = tmp_path_factory.mktemp(name)
        write_csv_log(log, folder / "pose.csv")
        write_csv_log(log, folder / "plain.csv", pose=False)
        out[name] = (log, folder / "pose.csv", folder / "plain.csv")
    return out


def direct_slip_lag(log) -> float:
    """τ_s from MuJoCo's own velocities, not the pose: the body-frame lateral velocity of the base's origin (qvel, at its
    own time) regressed on −V·r (V its forward velocity, r the gyro's yaw rate), through the origin."""
    moving = log.v_forward > MIN_SPEED
    X = -log.v_forward[moving] * log.imu_wz[moving]
    return float(X @ log.v_lateral[moving] / (X @ X))


@pytest.mark.parametrize("name", ROBOTS)
def test_mujoco_robots_slide_as_their_velocities_say(drives, name):
    """The slide identified from the CSV's pose equals the one MuJoCo's velocities give within 0.2 ms (measured 0.01 ms:
    both see the same motion, the pose's chords average it over 40 ms, and the yaw rate's content is below 2 Hz; the
    1.5 ms of the design, the size of an engine step's timing error, is far wider). Both robots slide by more than 5 ms,
    so the comparison is not of two zeros. The plant's g, τ and D do not change with the pose's columns (the same fit of
    the same samples: to 1e-9 relative)."""
    from pfm_stability.analysis.identification import identify

    log, with_pose, plain = drives[name]
    direct = direct_slip_lag(log)
    result = identify(read_log(with_pose, need=("command", "odometry"), optional=("pose",)))
    assert result.slip_reason is None and direct > 0.005
    assert result.slip.slip_lag.value == pytest.approx(direct, abs=2e-4), (result.slip.slip_lag, direct)
    assert result.slip.slip_lag.high - result.slip.slip_lag.low < 1e-3  # exact pose: the interval is tight
    before = identify(read_log(plain, need=("command", "odometry"), optional=("pose",)))
    assert not before.has_pose and before.to_dict()["slip"] is None
    for key in ("g", "tau", "dead_time"):
        a, b = getattr(result.plant, key), getattr(before.plant, key)
        assert (a.value, a.low, a.high) == pytest.approx((b.value, b.low, b.high), rel=1e-9, abs=1e-12), key


def test_the_command_prints_and_writes_the_slide(drives, tmp_path):
    """``identify`` on a CSV with the pose: the JSON (valid against the schema) carries slip.slip_lag, the text prints it,
    ``--out`` writes robot.slip_lag with its interval; without the pose, slip is null and --out writes no slip_lag."""
    log, with_pose, plain = drives["skid-steer"]
    out = tmp_path / "robot.yaml"
    code, text, err = run(["identify", str(with_pose), "--format", "json", "--out", str(out)])
    assert code == 0, err
    data = json.loads(text)
    assert [f"{list(e.absolute_path)}: {e.message}" for e in VALIDATOR.iter_errors(data)] == []
    slip = data["slip"]
    assert slip["reason"] is None and slip["slip_lag"]["low"] <= slip["slip_lag"]["value"] <= slip["slip_lag"]["high"]
    assert slip["slip_lag"]["value"] == pytest.approx(direct_slip_lag(log), abs=2e-4)  # as the library's (above)
    assert data["log"]["topics"]["pose"] == "x,y,yaw"
    config = yaml.safe_load(out.read_text())
    assert config["robot"]["slip_lag"] == pytest.approx(slip["slip_lag"]["value"], rel=1e-5)  # written to 6 digits
    assert "slip_lag:" in out.read_text() and "the base's slide" in out.read_text()
    from pfm_stability.io.config import load_config

    assert load_config(out).robot.slip_lag == pytest.approx(slip["slip_lag"]["value"], rel=1e-5)  # report --config reads it
    code, text, _ = run(["identify", str(with_pose)])
    assert code == 0 and "τ_s (slip lag)" in text and "from the pose x,y,yaw" in text
    code, md, _ = run(["identify", str(with_pose), "--format", "markdown"])
    assert code == 0 and "| τ_s (slip lag) |" in md
    code, text, _ = run(["identify", str(plain), "--format", "json", "--out", str(out)])
    data = json.loads(text)
    assert code == 0 and data["slip"] is None and "pose" not in data["log"]["topics"] and not list(VALIDATOR.iter_errors(data))
    assert "slip_lag" not in yaml.safe_load(out.read_text())["robot"]
    code, text, _ = run(["identify", str(plain)])
    assert "slip" not in text and "slide" not in text


def test_a_bag_gives_the_slide_only_from_the_pose_topic_named(drives, tmp_path):
    """A bag whose /ground_truth carries MuJoCo's true pose (an Odometry, as a simulator's ground-truth plugin publishes):
    ``--pose-topic /ground_truth`` measures the slide as the CSV does (the same samples: within 1e-9 s); without the
    option no slide is looked for (the odometry's own pose would be wheel odometry's, which cannot show one)."""
    pytest.importorskip("rosbags", reason="the optional extra 'logs' is not installed")
    from log_helpers import Plant, Recording, SyntheticLog, write_ros2

    log, with_pose, _ = drives["diffdrive"]
    truth = SyntheticLog(Plant(), Recording(T=1 / 11), log.cmd_t, log.cmd_wz, log.cmd_vx, log.odom_t, log.odom_wz,
                         odom_x=log.x, odom_y=log.y, odom_yaw=log.yaw, odom_vx=log.v_forward)
    bag = write_ros2(truth, tmp_path / "bag", topics={"odometry": "/ground_truth", "command": "/cmd_vel"})
    code, text, err = run(["identify", str(bag), "--odom-topic", "/ground_truth", "--pose-topic", "/ground_truth", "--format", "json"])
    assert code == 0, err
    data = json.loads(text)
    assert data["log"]["topics"]["pose"] == "/ground_truth" and not list(VALIDATOR.iter_errors(data))
    _, csv_text, _ = run(["identify", str(with_pose), "--format", "json"])
    assert data["slip"]["slip_lag"]["value"] == pytest.approx(json.loads(csv_text)["slip"]["slip_lag"]["value"], abs=1e-9)
    code, text, _ = run(["identify", str(bag), "--odom-topic", "/ground_truth", "--format", "json"])
    assert code == 0 and json.loads(text)["slip"] is None
