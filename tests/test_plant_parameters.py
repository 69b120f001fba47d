"""The steering plant's gain g and dead time D as parameters: `Robot`, `RANGES`, configuration files, the command line.

`Robot.dead_time` (D, s) and `Robot.plant_gain` (g) describe the plant
g·e^(−sD)/(τs + 1) that `pfm-stability identify` measures (docs/config.md,
docs/simulator.md "Plant gain and dead time"). Checked here: the ranges and
their one-line errors, a file written by ``identify --out`` loads with its
values, the options exist on every command that takes the robot options with
their provenance, and `simulate` and `validate` drive the simulated robot with them.
"""

from __future__ import annotations

import json
import math

import pytest
import yaml

from cli_helpers import run
from log_helpers import Plant, Recording, simulate, write_log
from pfm_stability.cli import build_parser
from pfm_stability.cli.options import resolve_parameters
from pfm_stability.io.config import config_from_mapping, load_config
from pfm_stability.parameters import CARMEL, RANGES, Robot
from pfm_stability.validation import validate_boundary

COMMANDS = {"report": [], "simulate": ["--scenario", "corridor"], "validate": ["--scenario", "corridor"],
            "plot": ["rlocus", "--out", "r.png"], "map": ["depot"]}
"""The commands that take the shared robot options (`cli.options.add_parameter_options`), with the arguments each requires."""


@pytest.mark.parametrize("name, value, message", [
    ("dead_time", -0.01, "dead_time must be a finite number in [0, 10] s; got -0.01"),
    ("dead_time", 10.5, "dead_time must be a finite number in [0, 10] s; got 10.5"),
    ("dead_time", math.nan, "dead_time must be a finite number in [0, 10] s; got nan"),
    ("plant_gain", 0.0, "plant_gain must be a finite number in [0.001, 100]; got 0.0"),
    ("plant_gain", -0.8, "plant_gain must be a finite number in [0.001, 100]; got -0.8"),
    ("plant_gain", 101, "plant_gain must be a finite number in [0.001, 100]; got 101"),
])
def test_out_of_range_plant_is_a_one_line_error(name, value, message):
    """`Robot` refuses D outside [0, 10] s and g outside [10⁻³, 100] with the usual one line (`RANGES`)."""
    with pytest.raises(ValueError) as caught:
        CARMEL.robot.replace(**{name: value})
    assert str(caught.value) == message


def test_defaults_are_kb_s_robot_and_the_ends_are_allowed():
    """D = 0 and g = 1 by default (KB eq 6); the closed ends of both ranges are valid values."""
    robot = Robot(V=0.8, tau=0.3, k=2.0, W=0.8)
    assert (robot.dead_time, robot.plant_gain) == (0.0, 1.0) and (CARMEL.robot.dead_time, CARMEL.robot.plant_gain) == (0.0, 1.0)
    for name in ("dead_time", "plant_gain"):
        r = RANGES[name]
        assert getattr(robot.replace(**{name: r.low}), name) == r.low and getattr(robot.replace(**{name: r.high}), name) == r.high


def test_a_file_written_by_identify_loads_with_its_values(tmp_path):
    """``identify --out`` writes ``robot: {tau, dead_time, plant_gain}`` and ``controller: {T}``: `load_config` gives exactly
    the numbers written, each sourced to the file, the rest from the preset."""
    log = write_log(simulate(Plant(g=0.8, tau=0.3, dead_time=0.1), Recording(duration=20.0)), tmp_path, "csv")
    out = tmp_path / "robot.yaml"
    code, _, err = run(["identify", str(log), "--out", str(out)])
    assert code == 0, err
    written = yaml.safe_load(out.read_text())
    config = load_config(out)
    robot = config.robot
    assert (robot.tau, robot.dead_time, robot.plant_gain) == tuple(written["robot"][k] for k in ("tau", "dead_time", "plant_gain"))
    assert config.controller.T == written["controller"]["T"]
    assert robot.dead_time == pytest.approx(0.1, abs=0.02) and robot.plant_gain == pytest.approx(0.8, rel=0.05)
    assert config.sources["dead_time"] == config.sources["plant_gain"] == f"config {out}"
    assert config.sources["V"] == "preset carmel" and robot.V == CARMEL.robot.V


def test_config_keys_are_checked_like_the_options():
    """``robot.dead_time`` and ``robot.plant_gain`` in a file: the options' ranges and words, prefixed by the key."""
    config = config_from_mapping({"robot": {"dead_time": 0.07, "plant_gain": 0.85}, "assumed": {"dead_time": "read off a plot"}}, "config x.yaml")
    assert (config.robot.dead_time, config.robot.plant_gain) == (0.07, 0.85)
    assert config.sources["dead_time"] == "ASSUMED (config x.yaml): read off a plot" and config.sources["plant_gain"] == "config x.yaml"
    with pytest.raises(ValueError, match=r"^config x\.yaml: robot\.plant_gain must be a finite number in \[0\.001, 100\]; got 0$"):
        config_from_mapping({"robot": {"plant_gain": 0}}, "config x.yaml")


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_with_the_robot_options_takes_the_plant_and_records_its_source(command, tmp_path):
    """``--dead-time`` and ``--plant-gain`` on each command: typed → ``user``; from ``--config`` → ``config FILE``;
    neither → ``preset carmel`` (`resolve_parameters`, which the report's inputs and the JSON ``sources`` read)."""
    parser = build_parser()
    path = tmp_path / "robot.yaml"
    path.write_text("robot: {dead_time: 0.05}\n")
    required = COMMANDS[command]
    typed = parser.parse_args([command, *required, "--dead-time", "0.12", "--plant-gain", "0.9"])
    params = resolve_parameters(typed)
    assert (params.robot.dead_time, params.robot.plant_gain) == (0.12, 0.9)
    assert params.sources["dead_time"] == params.sources["plant_gain"] == "user"
    filed = resolve_parameters(parser.parse_args([command, *required, "--config", str(path)]))
    assert (filed.robot.dead_time, filed.robot.plant_gain) == (0.05, 1.0)
    assert filed.sources["dead_time"] == f"config {path}" and filed.sources["plant_gain"] == "preset carmel"
    code, _, err = run([command, *required, "--plant-gain", "200"])
    assert code == 2 and err.strip().endswith("plant_gain must be a finite number in [0.001, 100]; got 200.0") and err.count("\n") == 1


def test_simulate_drives_the_robot_with_the_plant_and_refuses_a_servo_dead_time():
    """`simulate --dead-time --plant-gain`: the JSON inputs carry them (source ``user``) and the run differs from KB's robot;
    a dead time with ``--hold reference`` exits 2 with one line naming both."""
    base = ["simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "4", "--format", "json"]
    code, out, err = run(base + ["--dead-time", "0.05", "--plant-gain", "0.8"])
    assert code == 0, err
    data = json.loads(out)
    assert (data["inputs"]["dead_time"], data["inputs"]["plant_gain"]) == (0.05, 0.8)
    assert data["inputs"]["sources"]["dead_time"] == "user"
    code, plain, _ = run(base)
    assert code == 0 and json.loads(plain)["metrics"] != data["metrics"]
    code, out, err = run(base + ["--hold", "reference", "--dead-time", "0.05"])
    assert code == 2 and out == "" and err.count("\n") == 1 and "dead_time must be 0 with hold=reference" in err


def test_validate_simulates_with_the_plant():
    """`validate_boundary` builds its simulated robots from `Robot`: D and g reach them and its inputs.

    CARMEL's corridor (bisection to 3 %): a dead time of 40 ms widens the
    simulated L* (a later command destabilizes, 0.97 against 0.92 m), a plant gain
    of 0.7 narrows it (a softer loop, 0.90 m).
    """
    kb = validate_boundary("corridor", rtol=0.03, members=3)
    late = validate_boundary("corridor", robot=CARMEL.robot.replace(dead_time=0.04), rtol=0.03, members=3)
    soft = validate_boundary("corridor", robot=CARMEL.robot.replace(plant_gain=0.7), rtol=0.03, members=3)
    assert (late.inputs["dead_time"], soft.inputs["plant_gain"]) == (0.04, 0.7)
    assert late.simulated_boundary > 1.03 * kb.simulated_boundary and soft.simulated_boundary < 0.99 * kb.simulated_boundary
