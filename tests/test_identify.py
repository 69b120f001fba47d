"""`pfm-stability identify` (`pfm_stability.analysis.identification`): the plant and the controller's period from logs
with a known truth (`log_helpers`: a simulated robot, its bags written by rosbags).

Tolerances are the brief's: over a seeded set of random plants (g 0.5–1.2, τ 0.05–0.8 s, D 0–0.2 s, T 0.02–0.2 s with
jitter, dropped commands and sensor noise; step turns or chirps, 90 s) τ within 10 %, D within one odometry period
(20 ms), g within 5 % and T within 1 %; the 95 % intervals hold the truth in most cases (measured: 69 of the 72
intervals of `SEED`'s 24 plants, 96 %; asserted ≥ 90 %). On the VFF simulator's corridors and walls (one frequency
excited) the fit is flagged ``narrowband`` with null intervals, and the plant's gain and phase at that frequency —
what such a log does determine — are the truth's. The exactness of the response is checked against the helpers'
independent event loop to 1e-9 rad/s (round-off of a few hundred exponential updates).
"""

from __future__ import annotations

import contextlib
import io
import json
import math

import numpy as np
import pytest
import yaml
from jsonschema import Draft202012Validator

from log_helpers import (BAD_LOGS, Leg, Plant, Recording, bad_log, corridor_log, drive, random_corridor, random_plant,
                         simulate, write_log, write_ros2)
from pfm_stability.analysis.identification import (
    BAND, NARROWBAND, Excitation, command_spectrum, controller_timing, excitation_windows, identify, lag_response, ridge_point)
from pfm_stability.analysis.plant_response import affine_scan as _affine_scan
from pfm_stability.cli import main
from pfm_stability.io.logs import read_log
from pfm_stability.io.schema import load_schema

VALIDATOR = Draft202012Validator(load_schema())
SEED, PLANTS = 2024, 24
FORMATS = ("sqlite3", "mcap", "ros1", "csv")


def run(argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def identified(tmp_path, plant=Plant(), recording=Recording(), kind="mcap", rate_source="odometry", **write):
    """The identification of the log of `plant` driven as `recording`, written as `kind`."""
    log = simulate(plant, recording)
    path = write_log(log, tmp_path, kind, **write)
    return identify(read_log(path, need=("command", rate_source)), rate_source)


# ------------------------------------------------------------------------------ the exact response
def test_the_affine_scan_is_the_recursion():
    rng = np.random.default_rng(0)
    a, b = rng.uniform(0, 1, 1000), rng.normal(size=1000)
    x = [0.3]
    for ak, bk in zip(a, b):
        x.append(ak * x[-1] + bk)
    np.testing.assert_allclose(_affine_scan(a, b, 0.3), x, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("tau, delay", [(0.2, 0.0), (0.05, 0.137), (0.8, 0.2)])
def test_the_response_is_the_independent_integration(tau, delay):
    """Without noise the model's response at the odometry's times is the helpers' event loop (a different algorithm)."""
    log = simulate(Plant(g=1.0, tau=tau, dead_time=delay), Recording(duration=20.0, odom_noise=0.0, T=0.07, jitter=0.1, seed=3))
    mine = lag_response(log.cmd_t, log.cmd_wz, log.odom_t, tau, delay)
    np.testing.assert_allclose(mine, log.odom_wz, rtol=0, atol=1e-9)


def test_the_analytic_derivatives_are_the_finite_differences():
    log = simulate(Plant(), Recording(duration=10.0, odom_noise=0.0))
    x, dtau, dD = lag_response(log.cmd_t, log.cmd_wz, log.odom_t, 0.2, 0.08, derivatives=True)
    h = 1e-6
    fd_tau = (lag_response(log.cmd_t, log.cmd_wz, log.odom_t, 0.2 + h, 0.08) - lag_response(log.cmd_t, log.cmd_wz, log.odom_t, 0.2 - h, 0.08)) / (2 * h)
    fd_D = (lag_response(log.cmd_t, log.cmd_wz, log.odom_t, 0.2, 0.08 + h) - lag_response(log.cmd_t, log.cmd_wz, log.odom_t, 0.2, 0.08 - h)) / (2 * h)
    np.testing.assert_allclose(dtau, fd_tau, atol=1e-6)  # central differences: O(h²) and round-off 1e-16/h
    away = np.abs(dD - fd_D) > 1e-6  # dx/dD jumps where a delayed command takes effect: a sample within h of one
    assert np.count_nonzero(away) <= 2


# ------------------------------------------------------------------------------ the controller's period
def test_controller_timing_counts_what_it_says():
    t = np.concatenate([np.arange(0, 10, 0.1), np.arange(10.25, 20, 0.1)])  # one interval of 0.25 s = 2.5·T
    timing = controller_timing(t)
    assert timing.T == pytest.approx(0.1, rel=1e-9) and timing.missed == 1 and timing.messages == t.size
    assert timing.nominal == pytest.approx(10.0) and timing.rate == pytest.approx((t.size - 1) / (t[-1] - t[0]))
    assert timing.p5 == pytest.approx(0.1) and timing.p95 == pytest.approx(0.1)
    with pytest.raises(ValueError, match="at least 3"):
        controller_timing(np.array([0.0, 1.0]))


def test_windows_skip_long_constant_stretches():
    t = np.arange(0, 60, 0.05)
    u = np.where(t < 30, 0.0, 0.5)  # one change at 30 s
    windows = excitation_windows(t, u)
    np.testing.assert_allclose(windows, [[30.0 - 0.5, 30.0 + 4.0]], atol=1e-9)
    assert excitation_windows(t, np.zeros_like(t)).shape == (0, 2)


# ------------------------------------------------------------------------------ known truth
@pytest.fixture(scope="module")
def random_plants(tmp_path_factory):
    rng = np.random.default_rng(SEED)
    out = []
    for i in range(PLANTS):
        plant, recording = random_plant(rng)
        out.append((plant, recording, identified(tmp_path_factory.mktemp(f"plant{i}"), plant, recording, FORMATS[i % 4])))
    return out


@pytest.mark.xdist_group("identify_random_plants")  # its module fixture once per suite (tests/conftest.py)
def test_random_plants_are_identified_within_the_tolerances(random_plants):
    for plant, recording, result in random_plants:
        assert result.identified, result.reason
        p = result.plant
        where = f"{plant} {recording.T=:.3f} {recording.profile}"
        assert abs(p.tau.value / plant.tau - 1) <= 0.10, where
        assert abs(p.dead_time.value - plant.dead_time) <= 1.0 / recording.odom_rate, where
        assert abs(p.g.value / plant.g - 1) <= 0.05, where
        assert abs(result.controller.T / recording.T - 1) <= 0.01, where
        assert p.warnings == (), where  # an exact first-order plant: nothing unexplained


@pytest.mark.xdist_group("identify_random_plants")  # its module fixture once per suite (tests/conftest.py)
def test_random_plants_intervals_hold_the_truth_in_most_cases(random_plants):
    """95 % intervals: 69 of 72 hold the truth at SEED (96 %); ≥ 90 % asserted (72 draws at 0.95: 3.6 misses expected,
    standard deviation 1.8; 90 % allows 7). Steps and chirps are never narrowband (their spectra are broad)."""
    assert all(r.plant.identifiable and r.plant.excitation.outside > 2 * NARROWBAND for _, _, r in random_plants)
    held = [p.g.low <= plant.g <= p.g.high for plant, _, r in random_plants for p in [r.plant]]
    held += [p.tau.low <= plant.tau <= p.tau.high for plant, _, r in random_plants for p in [r.plant]]
    held += [p.dead_time.low <= plant.dead_time <= p.dead_time.high for plant, _, r in random_plants for p in [r.plant]]
    assert np.mean(held) >= 0.90, np.mean(held)


# ------------------------------------------------------------------------------ identifiability
def test_command_spectrum_is_the_closed_form_of_tones():
    """A held sine has all its power at its frequency (outside ≈ 0, the Hann window's leakage stays within the band);
    two equal tones a factor 3 apart (outside the band of either) split it in halves: outside = 1/2 to 2 % (leakage).
    ω is the tone's to within one FFT bin (2π/span = 0.05 rad/s here)."""
    T = 0.05
    t = np.arange(0.0, 120.0, T)
    omega, outside = command_spectrum(t, 0.4 * np.sin(2.3 * t) + 0.1, T)
    assert omega == pytest.approx(2.3, abs=2 * math.pi / 120) and outside < 0.01
    omega, outside = command_spectrum(t, np.sin(1.1 * t) + np.sin(3.3 * t), T)
    assert outside == pytest.approx(0.5, abs=0.02)
    assert math.isnan(command_spectrum(t, np.full(t.size, 0.3), T)[0])


def test_ridge_point_keeps_the_gain_and_phase_at_omega():
    """From each single value the two others follow the closed forms: the returned plant's g/√(1 + ω²τ²) and
    −ωD − atan(ωτ) are the ridge's to round-off (1e-12), and the value given is kept; a value no plant of the ridge
    has (a gain below the gain at ω, a dead time beyond the phase) gives None; not exactly one value is a ValueError."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        w, g, tau, D = rng.uniform(0.5, 6), rng.uniform(0.5, 1.5), rng.uniform(0.02, 0.8), rng.uniform(0, 0.2)
        ridge = Excitation(w, 0.01, True, g / math.hypot(1, w * tau), -w * D - math.atan(w * tau))
        for given in ({"tau": rng.uniform(0.01, 1.0)}, {"dead_time": D * rng.uniform(0, 1)},
                      {"plant_gain": ridge.gain * rng.uniform(1, 3)}):
            g2, tau2, D2 = ridge_point(ridge, **given)
            assert g2 / math.hypot(1, w * tau2) == pytest.approx(ridge.gain, rel=1e-12)
            assert -w * D2 - math.atan(w * tau2) == pytest.approx(ridge.phase, abs=1e-12)
            assert dict(tau=tau2, dead_time=D2, plant_gain=g2)[next(iter(given))] == pytest.approx(next(iter(given.values())))
        assert ridge_point(ridge, tau=tau) == pytest.approx((g, tau, D), rel=1e-9, abs=1e-12)
        assert ridge_point(ridge, plant_gain=0.9 * ridge.gain) is None
        assert ridge_point(ridge, dead_time=D + math.pi / w) is None
    with pytest.raises(ValueError, match="exactly one"):
        ridge_point(ridge, tau=0.1, dead_time=0.1)


NARROW_SEEDS = (11, 12, 13, 15, 17, 18, 19, 20, 22, 23)
"""Corridors (odd) and walls (even) whose random draw `random_corridor` accepts quickly (its rejection loop costs up to
15 s on some seeds); every seed from 10 to 23 was checked the same way when this was written."""


@pytest.mark.slow
def test_corridor_and_wall_logs_are_narrowband_and_their_gain_and_phase_are_the_truths(tmp_path):
    """The VFF simulator's own corridors and walls (10 seeds, 20 s, compute delay 0 or 1, D 0–0.1 s, g 0.7–1.2):
    the commands excite one frequency (outside < 0.02 measured; `NARROWBAND` 0.05), so g, τ, D get null intervals and
    the ``narrowband`` warning, and ``--out`` refuses to write them. What the log does determine, the plant's gain
    g/√(1 + ω²τ²) and phase −ωD − atan(ωτ) at that ω, is the truth's (closed form of the true plant): gain within 3 %,
    phase within 0.03 rad (3× the largest seen, 0.6 % and 0.011 rad: harmonics and the 2 % dropped commands, which
    the simulated motor saw and the log does not hold). The dead time is the robot's own: the commands are stamped when
    published, after the compute delay (docs/diagnose.md, "Time"), so the phase would miss by ω·d·T ≥ 0.06 rad if
    the compute delay were counted in D."""
    for seed in NARROW_SEEDS:
        log, robot, controller, _, _ = corridor_log(seed, kind=("corridor", "wall")[seed % 2 == 0], scans=False,
                                                   duration=20.0)
        (tmp_path / str(seed)).mkdir()
        path = write_log(log.log, tmp_path / str(seed), "csv")
        result = identify(read_log(path, need=("command", "odometry")))
        p = result.plant
        assert result.identified and not p.identifiable, seed
        assert p.warnings[0].kind == "narrowband" and "record step turns" in p.warnings[0].message
        assert all(math.isnan(e.low) and math.isnan(e.high) for e in (p.g, p.tau, p.dead_time))
        w = p.excitation.omega
        assert p.excitation.gain == pytest.approx(robot.plant_gain / math.hypot(1, w * robot.tau), rel=0.03), seed
        assert p.excitation.phase == pytest.approx(-w * robot.dead_time - math.atan(w * robot.tau), abs=0.03), seed
    code, out, err = run(["identify", str(path), "--out", str(tmp_path / "robot.yaml"), "--format", "json"])
    assert code == 2 and "not separately identifiable" in err and not (tmp_path / "robot.yaml").exists()
    assert err.count("\n") == 1 and "Traceback" not in err


def test_narrowband_json_validates_and_step_turns_make_it_identifiable(tmp_path):
    """The JSON of a narrowband log validates (null intervals, ``plant.identifiable`` false, ``fit.excitation``), and
    the same robot with 25 s of step turns after its corridor is identified with intervals holding the truth, D the
    robot's own (within one odometry period, 20 ms; the compute delay, one period of 61 ms, is not in it): the
    commands are stamped when published (docs/diagnose.md, "Time")."""
    log, robot, controller, geometry, _ = corridor_log(11, scans=False, duration=20.0)
    assert controller.compute_delay == 1
    (tmp_path / "narrow").mkdir()
    path = write_log(log.log, tmp_path / "narrow", "csv")
    code, out, err = run(["identify", str(path), "--format", "json"])
    data = json.loads(out)
    assert code == 0
    assert list(VALIDATOR.iter_errors(data)) == []
    assert data["plant"]["identifiable"] is False and data["plant"]["tau"]["low"] is None
    assert data["fit"]["excitation"]["narrowband"] is True
    both = drive((Leg("corridor", 20.0, L=geometry), Leg("steps", 25.0, rate=0.8)), robot, controller, seed=11,
                 scan_rate=0.0)
    (tmp_path / "steps").mkdir()
    path = write_log(both.log, tmp_path / "steps", "csv")
    p = identify(read_log(path, need=("command", "odometry"))).plant
    assert p.identifiable and p.warnings == ()
    assert abs(p.dead_time.value - robot.dead_time) <= 0.02
    for estimate, truth in ((p.g, robot.plant_gain), (p.tau, robot.tau), (p.dead_time, robot.dead_time)):
        assert estimate.low <= truth <= estimate.high


def test_profiles_turn_in_place_and_imu(tmp_path):
    """A robot turning in place (one amplitude) and the IMU as the rate source (its bias is the fitted offset)."""
    truth = Plant(g=0.8, tau=0.3, dead_time=0.12)
    r = identified(tmp_path / "a", truth, Recording(profile="turn_in_place"))
    assert r.identified and r.plant.g.value == pytest.approx(0.8, rel=0.02) and r.plant.tau.value == pytest.approx(0.3, rel=0.05)
    r = identified(tmp_path / "b", truth, Recording(imu_rate=100.0, imu_bias=0.02), rate_source="imu")
    assert r.identified and r.log.rate_source == "imu" and r.log.rate_topic == "/imu"
    assert r.plant.g.value == pytest.approx(0.8, rel=0.02) and abs(r.plant.dead_time.value - 0.12) < 0.01
    assert r.plant.quality.bias == pytest.approx(0.02, abs=0.005)


# ------------------------------------------------------------------------------ nothing to identify
@pytest.mark.parametrize("profile, reason", [
    ("still", "the command never changes (the robot was told to stand still)"),
    ("stopped", "the robot did not follow the commands"),
])
def test_a_log_without_excitation_identifies_nothing_and_says_why(tmp_path, profile, reason):
    r = identified(tmp_path, recording=Recording(profile=profile, duration=20.0))
    assert not r.identified and r.plant is None and reason in r.reason
    assert r.controller.T == pytest.approx(0.05, rel=0.01)  # the period is measured all the same


def test_excitation_too_small_for_the_noise(tmp_path):
    r = identified(tmp_path, recording=Recording(amplitude=0.002, odom_noise=0.05, duration=20.0))
    assert not r.identified and ("too little for the noise" in r.reason or "did not follow" in r.reason)


# ------------------------------------------------------------------------------ what the model does not explain
CASES = {
    "deadband": Plant(deadband=0.15),
}
"""What the fitted plants do not carry (a second lag and a slew limit are fitted: tests/test_identify_models.py)."""


@pytest.mark.parametrize("profile", ["steps", "chirp"])
@pytest.mark.parametrize("kind", list(CASES))
def test_each_warning_names_its_effect(tmp_path, kind, profile):
    """The log with the effect warns of it alone."""
    r = identified(tmp_path, CASES[kind], Recording(profile=profile, seed=3))
    assert r.identified and [w.kind for w in r.plant.warnings] == [kind], r.plant.warnings


@pytest.mark.parametrize("profile", ["steps", "chirp", "turn_in_place"])
@pytest.mark.parametrize("plant", [Plant(), Plant(g=0.7, tau=0.6, dead_time=0.15), Plant(g=1.1, tau=0.06, dead_time=0.0)],
                         ids=["typical", "slow", "fast"])
def test_a_first_order_log_warns_of_nothing(tmp_path, plant, profile):
    """An exact first-order plant with white noise: no warning, and the first order is the plant the data support (a
    richer candidate lowers the residual by the noise it fits, less than BIC's ln n per parameter)."""
    r = identified(tmp_path, plant, Recording(profile=profile, seed=3))
    assert r.identified and r.plant.warnings == () and r.plant.quality.white and r.plant.quality.r2 > 0.99
    assert r.plant.model == "first_order" and r.plant.actuator_lag is None and r.plant.yaw_accel_limit is None


# ------------------------------------------------------------------------------ the command
def test_json_output_validates_and_carries_the_numbers(tmp_path):
    path = write_log(simulate(Plant(), Recording(duration=30.0)), tmp_path, "mcap")
    code, out, err = run(["identify", str(path), "--format", "json"])
    assert code == 0 and err == ""
    data = json.loads(out)
    assert [f"{list(e.absolute_path)}: {e.message}" for e in VALIDATOR.iter_errors(data)] == []
    assert data["command"] == "identify" and data["identified"] is True
    assert data["plant"]["tau"]["low"] <= data["plant"]["tau"]["value"] <= data["plant"]["tau"]["high"]
    assert abs(data["plant"]["dead_time"]["value"] - 0.08) < 0.02 and data["controller"]["missed"] >= 0
    assert data["log"]["topics"] == {"command": "/cmd_vel", "rate": "/odom"} and data["log"]["format"] == "ros2-mcap"


def test_json_of_nothing_identified_validates(tmp_path):
    path = write_log(simulate(Plant(), Recording(profile="still", duration=10.0)), tmp_path, "csv")
    code, out, _ = run(["identify", str(path), "--format", "json"])
    data = json.loads(out)
    assert code == 0 and data["identified"] is False and data["plant"] is None and data["reason"]
    assert list(VALIDATOR.iter_errors(data)) == []
    bad = dict(data, plant={"g": 1})
    assert list(VALIDATOR.iter_errors(bad))


def test_text_and_markdown(tmp_path):
    path = write_log(simulate(Plant(), Recording(duration=30.0)), tmp_path, "sqlite3")
    code, text, _ = run(["identify", str(path)])
    assert code == 0 and "plant g·e^(−sD)/(τs + 1), 95 % intervals" in text and "warnings: none" in text
    code, md, _ = run(["identify", str(path), "--format", "markdown"])
    assert code == 0 and "| τ (lag) |" in md and "| T |" in md


def test_out_writes_a_configuration_with_the_identified_values(tmp_path):
    path = write_log(simulate(Plant(g=0.8, tau=0.3, dead_time=0.1), Recording(duration=40.0)), tmp_path, "ros1")
    out = tmp_path / "robot.yaml"
    code, _, err = run(["identify", str(path), "--out", str(out), "--format", "json"])
    assert code == 0, err
    config = yaml.safe_load(out.read_text())
    assert set(config) == {"robot", "controller"} and set(config["robot"]) == {"tau", "dead_time", "plant_gain"}
    assert config["robot"]["tau"] == pytest.approx(0.3, rel=0.05) and config["robot"]["plant_gain"] == pytest.approx(0.8, rel=0.02)
    assert config["robot"]["dead_time"] == pytest.approx(0.1, abs=0.02) and config["controller"]["T"] == pytest.approx(0.05, rel=0.01)
    assert "identified from log.bag" in out.read_text()


def test_out_with_nothing_identified_is_an_error_and_writes_nothing(tmp_path):
    path = write_log(simulate(Plant(), Recording(profile="still", duration=10.0)), tmp_path, "csv")
    out = tmp_path / "robot.yaml"
    code, stdout, err = run(["identify", str(path), "--out", str(out)])
    assert code == 2 and stdout == "" and not out.exists()
    assert err.startswith("pfm-stability: error: nothing identified from") and err.count("\n") == 1


def test_topics_and_rate_source_options(tmp_path):
    log = simulate(Plant(), Recording(duration=20.0, imu_rate=100.0))
    path = write_ros2(log, tmp_path / "bag", topics={"command": "/r1/cmd_vel", "imu": "/r1/imu"})
    code, out, err = run(["identify", str(path), "--cmd-topic", "/r1/cmd_vel", "--imu-topic", "/r1/imu",
                          "--rate-source", "imu", "--format", "json"])
    assert code == 0, err
    assert json.loads(out)["log"]["topics"] == {"command": "/r1/cmd_vel", "rate": "/r1/imu"}
    code, _, err = run(["identify", str(path), "--cmd-topic", "not a topic"])
    assert code == 2 and "cmd-topic must be a ROS topic name" in err


@pytest.mark.parametrize("kind", BAD_LOGS)
def test_every_bad_log_exits_2_with_one_line(tmp_path, kind):
    code, out, err = run(["identify", str(bad_log(kind, tmp_path))])
    assert code == 2 and out == ""
    assert err.startswith("pfm-stability: error: ") and err.count("\n") == 1 and "Traceback" not in err


def test_a_bag_without_the_extra_says_so_in_one_line(tmp_path, monkeypatch):
    import sys

    path = write_log(simulate(Plant(), Recording(duration=5.0)), tmp_path, "mcap")
    monkeypatch.setitem(sys.modules, "rosbags", None)
    code, out, err = run(["identify", str(path)])
    assert code == 2 and err == ("pfm-stability: error: pfm-stability identify needs the optional extra 'logs' "
                                 "(missing: rosbags): pip install 'pfm-stability[logs]'\n")


def test_the_period_of_a_fast_controller_with_jitter(tmp_path):
    """T within 1 % at 50 Hz with 10 % jitter and 5 % dropped commands, from Twist receive times."""
    r = identified(tmp_path, recording=Recording(T=0.02, jitter=0.1, drop=0.05, duration=30.0))
    assert r.controller.T == pytest.approx(0.02, rel=0.01) and r.controller.missed > 0
    assert r.controller.rate < r.controller.nominal  # dropped commands lower the achieved rate
    assert math.isfinite(r.controller.p5) and r.controller.p5 < 0.02 < r.controller.p95
