"""`pfm-stability diagnose` (`validation.diagnose`, `analysis.stretches`, the pose in `io.logs`): the oscillation measured
on synthetic logs of the project's VFF simulator (`log_helpers.drive`: corridors and a wall driven by `sim`, scans
ray-cast against the walls, odometry pose at 50 Hz, the held commands) against the simulator's own truth.

Tolerances: the measured ω within 5 % of the simulator's (`oscillation_metrics` on the exact offset at every sample;
measured ≤ 2.5 % over 40 random corridors and walls, experiments/diagnose_agreement.py), σ within 0.01 1/s of it (the
same estimator on the offset seen through noisy odometry and fitted walls: 39 of those 40), L and d0 within 2 cm (the
walls are fitted to 1 cm range noise), and the predicted verdict equal to the sign of the measured growth on every run
of the reduced set (|margin| > 5 %; 39 of the 40).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from dataclasses import replace

import numpy as np
import pytest
from jsonschema import Draft202012Validator

from log_helpers import Leg, bad_log, corridor_run, drive, ray_cast, write_ros1, write_ros2
from pfm_stability.analysis.stretches import find_stretches, lateral_offset, wall_lines
from pfm_stability.cli import main
from pfm_stability.io.logs import LogError, Scan, read_log
from pfm_stability.io.schema import load_schema
from pfm_stability.parameters import CARMEL
from pfm_stability.validation.diagnose import diagnose, missing_parameters

pytestmark = pytest.mark.xdist_group("diagnose")
VALIDATOR = Draft202012Validator(load_schema())
LEGS = (Leg("corridor", 30.0, L=0.9), Leg("still", 3.0), Leg("turn", 4.0), Leg("wall", 30.0, offset=0.1),
        Leg("turn", 2.6, rate=0.6), Leg("steps", 30.0))
CONFIG = "robot: {k: 2.0, W: 0.8}\ncontroller: {f: 0.8, n: 2}\n"


def run(argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def driven(tmp_path_factory):
    """The log of CARMEL driving an unstable corridor (L = 0.9 m), standing, turning, along a stable wall and turning in
    steps, with 5 % of the messages dropped, as an MCAP bag; and a configuration with k, W, f, n."""
    directory = tmp_path_factory.mktemp("driven")
    log = drive(LEGS, seed=1, drop=0.05)
    path = write_ros2(log.log, directory / "bag", storage="mcap")
    config = directory / "robot.yaml"
    config.write_text(CONFIG)
    return log, path, config


# ------------------------------------------------------------------------------ reading
def test_the_pose_is_read_from_the_message_bytes(driven, tmp_path):
    """x, y, yaw and the forward speed read from the bytes equal what rosbags serialized (ROS 2 and ROS 1), to round-off."""
    log, path, _ = driven
    for where in (path, write_ros1(log.log, tmp_path / "log.bag")):
        pose = read_log(where, need=("pose",)).pose
        np.testing.assert_allclose(pose.x, log.log.odom_x, atol=1e-12)
        np.testing.assert_allclose(pose.y, log.log.odom_y, atol=1e-12)
        np.testing.assert_allclose(np.angle(np.exp(1j * (pose.yaw - log.log.odom_yaw))), 0.0, atol=1e-12)
        np.testing.assert_allclose(pose.vx, log.log.odom_vx, atol=1e-12)


def test_a_csv_without_the_pose_columns_has_no_pose(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("t,cmd_wz,odom_wz\n0,0,\n0.1,,0\n")
    with pytest.raises(LogError, match="has no column 'x'"):
        read_log(path, need=("pose",))
    assert read_log(path, need=("command",), optional=("pose",)).pose is None


# ------------------------------------------------------------------------------ walls from one scan
@pytest.mark.parametrize("yaw, half_width, shift", [(0.0, 0.9, 0.0), (0.3, 0.6, 0.2), (-0.5, 1.5, -0.4)])
def test_wall_lines_finds_both_walls_of_a_corridor(yaw, half_width, shift):
    """A scan ray-cast (the helpers' own intersection) in a corridor y = ±L from a robot at lateral `shift`, heading `yaw`:
    each side's distance is the perpendicular one, L ∓ shift (whatever the heading), to 2 cm (1 cm range noise, 360 beams), and
    its normal is ±90° − yaw to 1°."""
    rng = np.random.default_rng(0)
    walls = (((-20.0, half_width), (20.0, half_width)), ((-20.0, -half_width), (20.0, -half_width)))
    angles = -math.pi + 2 * math.pi * np.arange(360) / 360
    ranges = ray_cast(0.0, shift, yaw, angles, walls) + rng.normal(0.0, 0.01, 360)
    line = wall_lines(Scan(0.0, -math.pi, 2 * math.pi / 360, 0.05, 30.0, ranges))
    assert line[0] == pytest.approx(half_width - shift, abs=0.02)
    assert line[3] == pytest.approx(half_width + shift, abs=0.02)
    assert math.degrees(abs(math.remainder(line[1] - (math.pi / 2 - yaw), 2 * math.pi))) < 1.0
    assert math.degrees(abs(math.remainder(line[4] - (-math.pi / 2 - yaw), 2 * math.pi))) < 1.0


def test_wall_lines_ignores_a_wall_across_the_path_and_empty_space():
    """A wall straight ahead (normal along the heading) is no wall alongside; no echo at all gives no line."""
    angles = -math.pi + 2 * math.pi * np.arange(360) / 360
    ahead = ray_cast(0.0, 0.0, 0.0, angles, (((1.5, -10.0), (1.5, 10.0)),))
    assert np.isnan(wall_lines(Scan(0.0, -math.pi, 2 * math.pi / 360, 0.05, 30.0, ahead))).all()
    assert np.isnan(wall_lines(Scan(0.0, -math.pi, 2 * math.pi / 360, 0.05, 30.0, np.full(360, np.inf)))).all()


# ------------------------------------------------------------------------------ stretches and measurement
@pytest.fixture(scope="module")
def read(driven):
    return read_log(driven[1], need=("command", "odometry", "pose", "scan"), scan_reducer=wall_lines)


def test_stretches_are_the_corridor_and_the_wall(driven, read):
    """The judged stretches lie inside the corridor and wall legs and cover most of them; standing, turning in place and
    step turns in the open give none of 5 s or more; L and d0 are the simulator's to 2 cm."""
    log = driven[0]
    stretches = find_stretches(read.scan.t, read.scan.values, read.pose)
    long = [s for s in stretches if s.duration >= 5.0]
    assert [s.kind for s in long] == ["corridor", "wall"]
    for s, truth in zip(long, (log.truth[0], log.truth[3])):
        assert truth.t_start - 0.2 <= s.start and s.end <= truth.t_end + 0.2
        assert s.duration > 0.8 * (truth.t_end - truth.t_start)
        assert lateral_offset(s, read.pose).geometry == pytest.approx(truth.geometry, abs=0.02)


def test_measured_oscillation_is_the_simulators(driven, read):
    """On both legs the measured ω is the simulator's within 5 % and σ within 0.01 1/s (module docstring)."""
    log = driven[0]
    result = diagnose(read, CARMEL.robot, CARMEL.controller)
    judged = [s for s in result.stretches if s.judged]
    assert [s.stretch.kind for s in judged] == ["corridor", "wall"]
    for s, truth in zip(judged, (log.truth[0], log.truth[3])):
        assert s.measured.omega == pytest.approx(truth.metrics.angular_frequency, rel=0.05)
        assert s.measured.sigma == pytest.approx(truth.metrics.growth_rate, abs=0.01)
        assert s.V == pytest.approx(truth.V, rel=0.01)
    corridor, wall = judged
    assert not corridor.measured.stable and wall.measured.stable
    assert result.verdict == "oscillating" and result.worst == corridor.stretch.index
    assert corridor.predicted["sampled"].stable is False and wall.predicted["sampled"].stable is True
    assert corridor.matching == "sampled" and corridor.remedies["V"]["direction"] == "lower"
    for s in result.stretches:
        assert s.judged or s.reason
        if s.stretch.duration < 5.0:
            assert not s.judged and s.reason.startswith("shorter than 5 s")


@pytest.mark.slow
def test_verdicts_agree_on_random_corridors_and_walls(tmp_path):
    """4 random corridors and 4 walls away from the boundary (|margin| > 5 %; the full set of 40 is
    experiments/diagnose_agreement.py): the ``sampled`` verdict is the sign of the measured growth, ω is the
    simulator's within 5 %, L and d0 within 2 cm (the median of an oscillation about a wall's nonlinear force is not
    quite its equilibrium: α inferred from d0 moved 2° for a 1 cm error at α = 36°). Only ``sampled`` is predicted
    with (``models=("sampled",)``): the verdict checked is its own, which the other models do not change, and their
    critical values (the report of the judged stretch) cost most of a diagnosis; every model is predicted on the
    driven log (`test_measured_oscillation_is_the_simulators`,
    `test_json_validates_and_answers_for_the_whole_log_and_each_stretch`)."""
    for seed in range(100, 108):
        kind = ("corridor", "wall")[seed % 2]
        path, robot, controller, geometry, margin, truth = corridor_run(seed, tmp_path, duration=20.0, kind=kind)
        result = diagnose(read_log(path, need=("pose", "scan"), scan_reducer=wall_lines), robot, controller,
                          models=("sampled",))
        s = result.judged
        assert s is not None and s.stretch.kind == kind, result.reason
        assert s.predicted["sampled"].stable == s.measured.stable == (margin > 0), (seed, margin, s.measured)
        assert s.measured.omega == pytest.approx(truth.metrics.angular_frequency, rel=0.05)
        assert s.geometry == pytest.approx(truth.geometry, abs=0.02)  # L, or the wall's equilibrium d0


# ------------------------------------------------------------------------------ nothing to diagnose
def test_standing_still_and_turning_in_place_is_nothing_to_diagnose(tmp_path):
    """A robot that stands and turns in place beside walls it saw before has no stretch: exit 0 and the reason."""
    log = drive((Leg("still", 8.0), Leg("turn", 8.0)), seed=2)
    path = write_ros2(log.log, tmp_path / "bag", storage="mcap")
    config = tmp_path / "robot.yaml"
    config.write_text(CONFIG)
    code, out, err = run(["diagnose", str(path), "--config", str(config), "--tau", "0.3", "--T", "0.065", "--format", "json"])
    data = json.loads(out)
    assert code == 0 and err == "" and data["verdict"] == "nothing to diagnose" and "no wall in view" in data["reason"]
    assert data["measured"] is None and data["stretches"] == [] and list(VALIDATOR.iter_errors(data)) == []


def test_a_settled_corridor_is_stable_without_an_oscillation(tmp_path):
    """A robot on the centre line of a corridor far from its boundary (CARMEL, L = 1.2 m, no start offset) shows no
    oscillation and settles: judged stable, no σ."""
    log = drive((Leg("corridor", 15.0, L=1.2, offset=0.0),), seed=3, pose_noise=0.0)
    path = write_ros2(log.log, tmp_path / "bag", storage="mcap")
    result = diagnose(read_log(path, need=("pose", "scan"), scan_reducer=wall_lines), CARMEL.robot, CARMEL.controller)
    assert result.verdict == "stable" and result.judged.measured.stable


# ------------------------------------------------------------------------------ the command
@pytest.mark.slow
def test_json_validates_and_answers_for_the_whole_log_and_each_stretch(driven, tmp_path):
    """JSON: measured {omega, sigma, amplitude, stretch} and predicted.<model> {stable, V_critical, margin, omega, sigma} on
    top (the worst stretch) and in each stretch; the schema holds; τ and T came from the log; the PNG is written."""
    _, path, config = driven
    png = tmp_path / "d.png"
    code, out, err = run(["diagnose", str(path), "--config", str(config), "--format", "json", "--plot", str(png)])
    assert code == 0 and err == ""
    data = json.loads(out)
    assert [f"{list(e.absolute_path)}: {e.message}" for e in VALIDATOR.iter_errors(data)] == []
    assert data["command"] == "diagnose" and data["verdict"] == "oscillating"
    assert set(data["predicted"]) == {"continuous", "kb_first_order", "pade", "exact_delay", "sampled"}
    top = data["stretches"][data["measured"]["stretch"]]
    assert top["measured"] == data["measured"] and top["predicted"] == data["predicted"]
    assert data["parameters"]["tau"]["source"].startswith("identified from") and data["identification"]["identified"]
    assert data["parameters"]["tau"]["value"] == pytest.approx(0.3, rel=0.15)
    assert data["critical"]["V"] == pytest.approx(data["predicted"][data["matching_model"]]["V_critical"])
    assert png.stat().st_size > 10_000
    bad = dict(data, measured={"omega": 1.0})
    assert list(VALIDATOR.iter_errors(bad))


def test_text_and_markdown(driven):
    _, path, config = driven
    code, text, _ = run(["diagnose", str(path), "--config", str(config), "--tau", "0.3", "--T", "0.065"])
    assert code == 0 and "verdict: oscillating" in text and "matching model: sampled" in text and "to stabilize: lower V" in text
    assert "not judged: shorter than 5 s" in text
    code, md, _ = run(["diagnose", str(path), "--config", str(config), "--tau", "0.3", "--T", "0.065", "--format", "markdown"])
    assert code == 0 and "**Verdict: oscillating**" in md and "| sampled | unstable |" in md


def test_what_a_log_cannot_show_is_refused_by_name(driven, tmp_path):
    """Without k, W, f, n the command names them and where to give them (exit 2, one line); given as options it runs."""
    _, path, _ = driven
    code, out, err = run(["diagnose", str(path)])
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "diagnose needs k, W, f, n" in err and "robot.k, robot.W, controller.f, controller.n in --config" in err
    partial = tmp_path / "partial.yaml"
    partial.write_text("robot: {k: 2.0}\n")
    code, _, err = run(["diagnose", str(path), "--config", str(partial)])
    assert code == 2 and "diagnose needs W, f, n" in err
    code, _, err = run(["diagnose", str(path), "--k", "2", "--W", "0.8", "--f", "0.8", "--n", "2", "--tau", "0.3", "--T", "0.065"])
    assert code == 0, err


def test_missing_parameters_reads_the_sources():
    sources = {"k": "config a.yaml", "W": "preset carmel", "f": "ASSUMED (preset carmel): why", "n": "user"}
    assert missing_parameters(sources) == ("W", "f")


@pytest.mark.parametrize("kind", ["truncated mcap", "renamed topic", "corrupt db3", "csv missing column", "missing path"])
def test_bad_logs_are_one_line(kind, tmp_path):
    path = bad_log(kind, tmp_path)
    code, out, err = run(["diagnose", str(path), "--k", "2", "--W", "0.8", "--f", "0.8", "--n", "2"])
    assert code == 2 and out == "" and err.count("\n") == 1 and err.startswith("pfm-stability: error:")


def test_a_renamed_scan_topic_is_found_with_the_option(tmp_path):
    log = drive((Leg("corridor", 12.0, L=0.9),), seed=4)
    path = write_ros2(log.log, tmp_path / "bag", storage="mcap", topics={"scan": "/robot/scan"})
    args = ["diagnose", str(path), "--k", "2", "--W", "0.8", "--f", "0.8", "--n", "2", "--tau", "0.3", "--T", "0.065"]
    code, _, err = run(args)
    assert code == 2 and "has no scan topic /scan" in err and "/robot/scan" in err
    code, out, err = run(args + ["--scan-topic", "/robot/scan", "--format", "json"])
    assert code == 0 and json.loads(out)["verdict"] == "oscillating"


def test_dead_time_and_plant_gain_are_measured_through_and_identified(tmp_path):
    """A robot whose motor sees 0.85·u(t − 70 ms) (the simulator's delayed command): the measured ω is the simulator's
    within 5 % and σ within 0.01 1/s; without them in the configuration, D and g come from the log (identify's accuracy
    on VFF driving plus step turns: D within 20 ms, g within 5 %), and the ``sampled`` model of the delayed loop (margin
    +3 %: without D and g it would be +30 %) predicts the measured root: ω within 5 %, σ within 0.005 1/s (measured
    −0.0218 against −0.0214 1/s)."""
    robot = CARMEL.robot.replace(dead_time=0.07, plant_gain=0.85)
    log = drive((Leg("corridor", 25.0, L=1.0), Leg("turn", 2.0), Leg("steps", 25.0)), robot, seed=5)
    path = write_ros2(log.log, tmp_path / "bag", storage="mcap")
    config = tmp_path / "robot.yaml"
    config.write_text(CONFIG + "# tau from the log\n")
    code, out, err = run(["diagnose", str(path), "--config", str(config), "--format", "json"])
    assert code == 0, err
    data = json.loads(out)
    truth = log.truth[0].metrics
    assert data["measured"]["omega"] == pytest.approx(truth.angular_frequency, rel=0.05)
    assert data["measured"]["sigma"] == pytest.approx(truth.growth_rate, abs=0.01)
    sampled = data["predicted"]["sampled"]  # the models take g and D: the delayed loop's verdict and root
    assert sampled["stable"] is data["measured"]["stable"] is (truth.growth_rate < 0)
    assert sampled["omega"] == pytest.approx(data["measured"]["omega"], rel=0.05)
    assert sampled["sigma"] == pytest.approx(data["measured"]["sigma"], abs=0.005)
    assert data["matching_model"] == "sampled"
    p = data["parameters"]
    assert p["dead_time"]["value"] == pytest.approx(0.07, abs=0.02) and p["dead_time"]["source"].startswith("identified from")
    assert p["plant_gain"]["value"] == pytest.approx(0.85, rel=0.05) and p["plant_gain"]["source"].startswith("identified from")
    # the simulator's robot goes where it points: its pose shows no slide, and the prediction takes none
    assert p["slip_lag"]["value"] == 0.0 and p["slip_lag"]["source"].startswith("none: ")


@pytest.mark.slow
def test_two_plants_on_the_ridge_predict_the_same_root():
    """What a narrowband log determines is enough for the prediction: two plants with the same gain and phase at the
    loop's ω (τ2 = τ/2 and 3τ/4, g2 and D2 from the closed forms g/√(1 + ω²τ²) and −ωD − atan(ωτ)) give the same
    ``sampled`` root within ε·|s0|, where ε = |P2(s0)/P1(s0) − 1| is how much the plants differ at the root s0 = σ + jω
    itself (they agree exactly at jω; closed form). Derivation: a relative change ε of the loop L at its root moves it
    by δs ≈ ε/|d ln L/ds|, and |d ln L/ds| ≥ 1/|s0| for these loops (at least one integrator, and delays and lags only
    add phase lag with ω); measured δs ≤ 0.82·ε·|s0|. A plant off the ridge (τ2 with g and D unchanged) moves the root
    7× as far or more (asserted 5×), so the tolerance does discriminate. Eight random robots and loop gains NV (KB eq 25's N·V)
    that ring as a corridor log does (6 swings before decaying by e³, as `random_corridor` draws them; a heavily damped
    root lies far from jω, where the plants differ more, and shows no oscillation to identify from)."""
    from pfm_stability.models import Loop, models_for

    rng = np.random.default_rng(7)
    checked = 0
    while checked < 8:  # random robots in `random_corridor`'s ranges, growing or decaying
        robot = CARMEL.robot.replace(V=rng.uniform(0.3, 1.2), tau=rng.uniform(0.1, 0.5), k=rng.uniform(1.0, 4.0),
                                     dead_time=rng.uniform(0.0, 0.1), plant_gain=rng.uniform(0.7, 1.2))
        controller = CARMEL.controller.replace(T=rng.uniform(0.02, 0.1), hold="command",
                                               compute_delay=int(rng.integers(0, 2)))
        NV = float(np.exp(rng.uniform(math.log(0.3), math.log(10.0))))
        model = models_for(controller, ["sampled"])[0]

        def root(r):
            return complex(model.rightmost_root(NV, Loop.of(r, controller)))

        s0 = root(robot)
        if not s0.imag > 0.2 or abs(s0.real) * 6 * 2 * math.pi / s0.imag >= 3.0:
            continue  # a log narrowband enough to need this rings: 6 swings before it decays by e³ (`random_corridor`)
        checked += 1
        w, g, tau, D = s0.imag, robot.plant_gain, robot.tau, robot.dead_time
        for factor in (0.5, 0.75):
            tau2 = factor * tau
            g2, D2 = g * math.hypot(1, w * tau2) / math.hypot(1, w * tau), D + (math.atan(w * tau) - math.atan(w * tau2)) / w
            plant = lambda s, g, t, d: g * np.exp(-s * d) / (t * s + 1)
            eps = abs(plant(s0, g2, tau2, D2) / plant(s0, g, tau, D) - 1)
            moved = abs(root(robot.replace(tau=tau2, plant_gain=g2, dead_time=D2)) - s0)
            assert moved <= eps * abs(s0), (robot, controller, NV, factor, moved, eps * abs(s0))
            assert abs(root(robot.replace(tau=tau2)) - s0) > 5 * eps * abs(s0)


@pytest.mark.slow
def test_a_corridor_log_alone_is_narrowband_yet_predicts_the_measured_root(tmp_path):
    """A log of one corridor: τ, D and g are not separately identifiable (`identify` says ``narrowband``), but the
    fitted plant has the truth's gain and phase at the oscillation's ω, so ``sampled`` still predicts the measured
    root — verdict the measured one, ω within 5 %, σ within 0.02 1/s (the agreement experiment's tolerances on σ for
    peaks-estimated growth, docs/diagnose.md) — and every plant parameter's source says it was not separately
    identifiable and what the prediction rests on. The compute delay is the configuration's, not counted in D."""
    path, robot, controller, geometry, margin, truth = corridor_run(11, tmp_path, duration=20.0)
    config = tmp_path / "robot.yaml"
    config.write_text(f"robot: {{k: {robot.k}, W: {robot.W}}}\ncontroller: {{f: {controller.f}, n: 2, hold: command, "
                      f"compute_delay: {controller.compute_delay}}}\n")
    code, out, err = run(["diagnose", str(path), "--config", str(config), "--format", "json"])
    assert code == 0, err
    data = json.loads(out)
    assert list(VALIDATOR.iter_errors(data)) == []
    assert data["identification"]["plant"]["identifiable"] is False
    for name in ("tau", "dead_time", "plant_gain"):
        assert "not separately identifiable" in data["parameters"][name]["source"]
        assert "the prediction uses the plant's gain" in data["parameters"][name]["source"]
    sampled = data["predicted"]["sampled"]
    assert sampled["stable"] is data["measured"]["stable"] is (margin > 0)
    assert sampled["omega"] == pytest.approx(truth.metrics.angular_frequency, rel=0.05)
    assert sampled["sigma"] == pytest.approx(truth.metrics.growth_rate, abs=0.02)


@pytest.mark.slow
def test_a_narrowband_plant_stays_on_its_ridge_with_the_users_value(tmp_path):
    """With a narrowband log and τ given by the user, D and g come from the ridge the log determines (`ridge_point`),
    not from the fit's own point: the ridge passes through the truth, so with the true τ they are the truth's (D within
    5 ms = the 0.011 rad phase error seen at ω ≈ 2.8 rad/s, doubled; g within 2 %), where the fit's point is far off.
    Without any of them and a fit's negative D, D = 0 on the ridge, never the fit's point with D clamped."""
    from log_helpers import corridor_log, write_log
    from pfm_stability.analysis.identification import identify
    from pfm_stability.validation.diagnose import complete_from_log

    log, robot, controller, _, _ = corridor_log(11, scans=False, duration=20.0)
    path = write_log(log.log, tmp_path, "csv")
    identification = identify(read_log(path, need=("command", "odometry")))
    assert not identification.plant.identifiable
    sources = {"tau": "configuration", "T": "configuration", "dead_time": "preset CARMEL", "plant_gain": "preset CARMEL"}
    start = CARMEL.robot.replace(tau=robot.tau)
    completed, _, new = complete_from_log(start, controller, sources, identification)
    assert completed.tau == robot.tau
    assert completed.dead_time == pytest.approx(robot.dead_time, abs=0.005)
    assert completed.plant_gain == pytest.approx(robot.plant_gain, rel=0.02)
    assert "not separately identifiable" in new["dead_time"] and new["tau"] == "configuration"
    x = identification.plant.excitation
    negative = type(identification.plant)(identification.plant.g, identification.plant.tau,
                                          type(identification.plant.dead_time)(-0.05, math.nan, math.nan),
                                          identification.plant.quality, identification.plant.warnings, x)
    sources = dict(sources, tau="preset CARMEL")
    completed, _, _ = complete_from_log(CARMEL.robot, controller, sources, replace(identification, plant=negative))
    assert completed.dead_time == 0.0
    w = x.omega
    assert completed.plant_gain / math.hypot(1, w * completed.tau) == pytest.approx(x.gain, rel=1e-9)
    assert -math.atan(w * completed.tau) == pytest.approx(x.phase, abs=1e-9)


def test_batched_reduction_is_the_scan_by_scan_one(driven, read):
    """Scans reduced in batches of 7 (`scan_batch`; the last batch short) give the numbers of one scan at a time, and the
    scans' numbers read from the bytes are those rosbags serialized (the ranges as float32)."""
    from pfm_stability.analysis.stretches import wall_lines_batch

    batched = read_log(driven[1], need=("scan",), scan_reducer=wall_lines_batch, scan_batch=7).scan
    np.testing.assert_array_equal(batched.t, read.scan.t)
    np.testing.assert_allclose(batched.values, read.scan.values, rtol=0, atol=1e-12)
    first = read_log(driven[1], need=("scan",), scan_reducer=lambda s: s.ranges.copy()).scan.values[0]
    np.testing.assert_array_equal(first, driven[0].log.scan_ranges[0])


def test_another_law_in_the_configuration_is_refused(driven, tmp_path):
    """diagnose predicts with KB's power law or the grid's law: a configuration whose law is another is refused in one
    line, not ignored."""
    config = tmp_path / "khatib.yaml"
    config.write_text(CONFIG + "law: {name: khatib, goal_distance: 1.0}\n")
    code, out, err = run(["diagnose", str(driven[1]), "--config", str(config)])
    assert code == 2 and out == "" and err.count("\n") == 1 and "law khatib of --config" in err


def test_the_grid_law_of_the_configuration_is_the_one_predicted_with(driven, tmp_path):
    """``law: grid`` in the configuration: the predictions use the grid's law. The loop (the identified plant, k, T) is
    the same as with KB's power law, so each model's NV* is too, and V* = NV*/N: the ratio of the sampled V* under the
    two laws is the inverse ratio of their corridor gains at the measured L (`corridor_gain` of each law built by
    `make_law`, an independent evaluation; 1e-9 relative)."""
    from pfm_stability.laws.fields import make_law
    from pfm_stability.laws.force_law import corridor_gain
    from pfm_stability.parameters import Controller, Robot

    grid_config = tmp_path / "grid.yaml"
    grid_config.write_text(CONFIG + "law: {name: grid, cell_ratio: 0.3}\n")
    answers = []
    for config in (driven[2], grid_config):
        code, out, err = run(["diagnose", str(driven[1]), "--config", str(config), "--format", "json"])
        assert code == 0, err
        data = json.loads(out)
        stretch = next(s for s in data["stretches"] if s["judged"] and s["kind"] == "corridor")
        answers.append((stretch["L"], stretch["predicted"]["sampled"]["V_critical"]))
    (L, V_power), (L_grid, V_grid) = answers
    assert L == L_grid
    robot, controller = Robot(V=0.8, tau=0.3, k=2.0, W=0.8), Controller(f=0.8, n=2.0, T=0.065)
    N_power = corridor_gain(make_law("power", robot, controller), L)
    N_grid = corridor_gain(make_law("grid", robot, controller, cell_ratio=0.3), L)
    assert V_grid / V_power == pytest.approx(N_power / N_grid, rel=1e-9)


def test_a_bag_without_commands_is_diagnosed_when_tau_and_T_are_given(tmp_path):
    """Given τ and T, the log is not identified: a bag without /cmd_vel is diagnosed (D and g keep 0 and 1); without them
    the missing topic is named."""
    log = drive((Leg("corridor", 12.0, L=0.9),), seed=6)
    path = write_ros2(log.log, tmp_path / "bag", storage="mcap", topics={"command": "/other"})
    base = ["diagnose", str(path), "--k", "2", "--W", "0.8", "--f", "0.8", "--n", "2", "--format", "json"]
    code, out, err = run(base + ["--tau", "0.3", "--T", "0.065"])
    assert code == 0, err
    data = json.loads(out)
    assert data["identification"] is None and data["parameters"]["dead_time"]["value"] == 0.0
    code, _, err = run(base)
    assert code == 2 and "has no command topic /cmd_vel" in err
