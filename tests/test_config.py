"""Configuration files (`pfm_stability.io.config`, ``--config FILE``; docs/config.md) and Nav2 parameter files.

Checked: the shipped CARMEL preset holds Koren & Borenstein's values and notes and reads the same
through the strict loader; a file reproducing CARMEL gives the report of ``--preset carmel``; the
precedence option > file > the file's preset > carmel (with a second, non-CARMEL preset); every bad
key or value is a one-line ValueError naming the file and the key, and exit status 2 from the CLI,
with the same range as the command-line option; Nav2 files give T, V and W from the documented keys;
the provenance reaches the report. Every command is run in-process.
"""

from __future__ import annotations

import json
import math
import random
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from jsonschema import Draft202012Validator

from pfm_stability import parameters
from pfm_stability.cli import build_parser, main
from pfm_stability.cli import options as cli_options
from pfm_stability.io.config import Config, config_from_mapping, load_config
from pfm_stability.parameters import Controller, Robot, get_preset
from pfm_stability.io.schema import load_schema
from cli_helpers import file_error

VALIDATOR = Draft202012Validator(load_schema())

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "pfm_stability" / "data" / "presets" / "carmel.yaml"
NAV2_EXAMPLE = ROOT / "docs" / "examples" / "nav2_params.yaml"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def report_json(capsys, *argv) -> dict:
    code, out, err = run(capsys, "report", *argv, "--model", "sampled", "--format", "json")
    assert code == 0, err
    return json.loads(out)


def write(tmp_path, data, name="robot.yaml") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data), encoding="utf-8")
    return path


def without_sources(report: dict) -> dict:
    return {**report, "inputs": {k: {**v, "source": None} for k, v in report["inputs"].items()}}


# ------------------------------------------------------------------ the shipped preset
def test_shipped_carmel_is_kbs_robot():
    """The preset read from carmel.yaml has KB §4/§5.4's values (typed here from the paper, not from
    the file) and notes for exactly the three values KB do not give; exact equality: the YAML decimals
    are the paper's and parse to the same floats."""
    carmel = get_preset("carmel")
    assert carmel.robot == Robot(V=0.8, tau=0.3, k=2.0, W=0.8, max_steering_rate=math.radians(120.0))
    assert carmel.controller == Controller(f=0.8, n=2.0, T=0.065, hold="command", compute_delay=1)
    assert (carmel.cell_size, carmel.window_cells) == (0.1, 33)
    assert sorted(carmel.assumed) == ["compute_delay", "hold", "k"]
    assert "damping ratio of 0.65" in carmel.assumed["k"] and "Z-80" in carmel.assumed["hold"]
    assert parameters.CARMEL is carmel and list(parameters.PRESETS) == ["carmel"]


def test_shipped_preset_passes_the_strict_loader():
    """The shipped file is a configuration file: `load_config` (the strict reader, an independent route
    from `parameters`' own) gives the same robot, controller and ASSUMED notes."""
    config = load_config(SHIPPED)
    carmel = get_preset("carmel")
    assert (config.robot, config.controller) == (carmel.robot, carmel.controller)
    assert config.preset.assumed == carmel.assumed and config.law is None and config.scenario == {}
    assert config.sources["k"] == f"ASSUMED (config {SHIPPED}): {carmel.assumed['k']}"
    assert config.sources["V"] == f"config {SHIPPED}"


def test_help_reads_no_preset_and_loads_neither_numpy_nor_yaml():
    """``--help`` lists the preset names from the file names alone: no YAML parser, no numpy (start-up)."""
    code = ("import sys; from pfm_stability.cli import build_parser; build_parser().format_help(); "
            "print(sorted(m for m in ('numpy', 'yaml') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


# ------------------------------------------------------------------ round trip and precedence
CARMEL_FILE = {
    "robot": {"V": 0.8, "tau": 0.3, "k": 2.0, "W": 0.8},
    "controller": {"f": 0.8, "n": 2.0, "T": 0.065, "hold": "command", "compute_delay": 1},
}


def test_round_trip_reproduces_the_preset_report(tmp_path, capsys):
    """A file with CARMEL's values (over the preset, and the shipped file itself) gives the report JSON of
    ``--preset carmel`` exactly, but for the sources, which name the file."""
    reference = report_json(capsys, "--preset", "carmel", "--alpha", "20", "--L", "0.9")
    path = write(tmp_path, CARMEL_FILE)
    for config in (path, SHIPPED):
        got = report_json(capsys, "--config", config, "--alpha", "20", "--L", "0.9")
        VALIDATOR.validate(got)
        assert without_sources(got) == without_sources(reference)
        assert got["inputs"]["V"]["source"] == f"config {config}"
    assert got["inputs"]["k"]["source"].startswith(f"ASSUMED (config {SHIPPED}): KB do not give")
    assert reference["inputs"]["k"]["source"].startswith("ASSUMED (preset carmel)")


@pytest.fixture
def two_presets(tmp_path, monkeypatch):
    """A preset directory with carmel and a second robot far from it ("slow"), in place of the shipped one."""
    directory = tmp_path / "presets"
    directory.mkdir()
    (directory / "carmel.yaml").write_text(SHIPPED.read_text(encoding="utf-8"), encoding="utf-8")
    slow = {"name": "slow", "robot": {"V": 0.05, "tau": 2.5, "k": 40.0, "W": 3.0},
            "controller": {"f": 300.0, "n": 0.5, "T": 1.5, "hold": "reference", "compute_delay": 0},
            "assumed": {"tau": "a guess"}}
    (directory / "slow.yaml").write_text(yaml.safe_dump(slow), encoding="utf-8")
    presets = parameters._Presets(directory)
    monkeypatch.setattr(parameters, "PRESETS", presets)
    monkeypatch.setattr(cli_options, "PRESETS", presets)
    return slow


def test_precedence_option_file_preset(tmp_path, capsys, two_presets):
    """Option typed > file > the file's preset > carmel, value by value, with a base far from CARMEL."""
    path = write(tmp_path, {"preset": "slow", "robot": {"V": 0.07}, "controller": {"T": 0.9}})
    inputs = report_json(capsys, "--config", path, "--T", "0.7", "--L", "4")["inputs"]
    assert (inputs["T"]["value"], inputs["T"]["source"]) == (0.7, "user")
    assert (inputs["V"]["value"], inputs["V"]["source"]) == (0.07, f"config {path}")
    assert (inputs["k"]["value"], inputs["k"]["source"]) == (40.0, "preset slow")
    assert inputs["tau"]["source"] == "ASSUMED (preset slow): a guess" and inputs["hold"]["value"] == "reference"
    # a typed --preset replaces the file's preset key; the file still beats it
    inputs = report_json(capsys, "--config", path, "--preset", "carmel", "--L", "4")["inputs"]
    assert (inputs["V"]["value"], inputs["k"]["value"], inputs["T"]["value"]) == (0.07, 2.0, 0.9)
    assert inputs["k"]["source"].startswith("ASSUMED (preset carmel)")
    # without a preset key the base is carmel
    inputs = report_json(capsys, "--config", write(tmp_path, {"robot": {"V": 0.07}}, "plain.yaml"), "--L", "4")["inputs"]
    assert (inputs["k"]["value"], inputs["tau"]["value"]) == (2.0, 0.3)


def test_scenario_law_and_assumed_notes(tmp_path, capsys):
    """The file's scenario fills --alpha/--L (a typed one wins), its law is the report's unless --law is
    typed, and its assumed notes become the ASSUMED sources; a random robot far from CARMEL."""
    rng = random.Random(7)
    robot = {"V": round(rng.uniform(0.05, 5), 3), "tau": round(rng.uniform(0, 1), 3), "k": round(rng.uniform(0.1, 50), 3), "W": 0.3}
    data = {"robot": robot, "controller": {"T": 0.2, "compute_delay": 0}, "law": {"name": "grid", "cell_size": 0.05, "window_cells": 41},
            "scenario": {"wall": {"alpha": 35}, "corridor": {"L": 1.7}}, "assumed": {"k": "tuned by hand"}}
    path = write(tmp_path, data)
    inputs = report_json(capsys, "--config", path, "--L", "2.5")["inputs"]
    assert (inputs["alpha_deg"]["value"], inputs["alpha_deg"]["source"]) == (35.0, f"config {path}")
    assert (inputs["L"]["value"], inputs["L"]["source"]) == (2.5, "user")
    assert (inputs["cell_size"]["value"], inputs["window_cells"]["value"]) == (0.05, 41)
    assert inputs["cell_size"]["source"] == f"config {path}" and inputs["cell_ratio"]["source"].startswith("calibrated")
    assert inputs["k"] == {"value": robot["k"], "unit": "1/s", "source": f"ASSUMED (config {path}): tuned by hand"}
    assert inputs["compute_delay"]["value"] == 0 and inputs["compute_delay"]["source"] == f"config {path}"
    inputs = report_json(capsys, "--config", path, "--law", "power")["inputs"]
    assert "cell_size" not in inputs and inputs["L"]["value"] == 1.7


def test_provenance_in_the_text_report(tmp_path, capsys):
    """The text report's input table names the file, and marks the file's assumed values ASSUMED."""
    path = write(tmp_path, {"robot": {"k": 1.5}, "assumed": {"k": "from a step response"}, "scenario": {"corridor": {"L": 1.2}}})
    code, out, err = run(capsys, "report", "--config", path, "--model", "sampled")
    assert code == 0, err
    assert f"<-- ASSUMED (config {path}): from a step response" in out
    assert f"1.2 m  (config {path})" in out and "(preset carmel)" in out


def test_config_on_every_parameter_command():
    """Every subcommand with the robot options has --config (it comes with `add_parameter_options`)."""
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    with_robot = {name: p for name, p in sub.choices.items() if any("--V" in a.option_strings for a in p._actions)}
    assert {"report", "simulate", "validate", "plot"} <= set(with_robot)
    for name, p in with_robot.items():
        assert any("--config" in a.option_strings for a in p._actions), name


def test_simulate_reads_the_file(tmp_path, capsys):
    """``simulate --config``: the file's robot, and the corridor half-width of its scenario for the corridor
    scenario only (a scenario that takes no L is not given one)."""
    path = write(tmp_path, {"robot": {"V": 0.4}, "scenario": {"corridor": {"L": 1.3}, "wall": {"alpha": 40}}})
    code, out, err = run(capsys, "simulate", "--config", path, "--scenario", "corridor", "--env", "analytic",
                         "--duration", "1", "--format", "json", "--quiet")
    assert code == 0, err
    result = json.loads(out)
    assert result["inputs"]["sources"]["V"] == f"config {path}" and result["inputs"]["sources"]["L"] == f"config {path}"
    assert result["inputs"]["V"] == 0.4 and "half-width L = 1.3 m" in result["inputs"]["notes"]["geometry"]
    code, out, err = run(capsys, "simulate", "--config", path, "--scenario", "straight", "--duration", "0.5", "--format", "json", "--quiet")
    assert code == 0, err  # without the scenario filter: "L does not apply to scenario straight"
    assert "L" not in json.loads(out)["inputs"]["sources"]


class _Stop(Exception):
    pass


def test_validate_and_plot_take_the_file(tmp_path, capsys, monkeypatch):
    """``validate`` gets the file's fixed geometry only when V or f is bisected (bisecting L, a given L would
    be ignored); ``plot force-law`` and ``validate`` draw the grid of the file's grid law. The work itself is
    replaced by a probe: what is checked is what reaches it."""
    import pfm_stability.cli.plot as cli_plot
    import pfm_stability.cli.validate as cli_validate

    seen = {}

    def probe(args, params, *rest):
        seen.update(L=args.L, alpha=args.alpha, grid=(params.preset.cell_size, params.preset.window_cells), V=params.robot.V)
        raise _Stop

    monkeypatch.setattr(cli_validate, "_work", probe)
    monkeypatch.setattr(cli_plot, "_draw", lambda kind, params, order: probe(argparse_namespace(L=None, alpha=None), params))
    path = write(tmp_path, {"robot": {"V": 0.6}, "law": {"name": "grid", "cell_size": 0.08, "window_cells": 25},
                            "scenario": {"corridor": {"L": 1.4}, "wall": {"alpha": 25}}})
    for argv, expected in ((["--scenario", "corridor", "--parameter", "V"], (1.4, None)), (["--scenario", "corridor"], (None, None)),
                           (["--scenario", "wall", "--parameter", "f"], (None, 25.0)), (["--scenario", "wall"], (None, None))):
        seen.clear()
        with pytest.raises(_Stop):
            main(["validate", "--config", str(path), "--quiet", *argv])
        assert (seen["L"], seen["alpha"], seen["grid"], seen["V"]) == (*expected, (0.08, 25), 0.6), argv
    with pytest.raises(_Stop):
        main(["plot", "force-law", "--config", str(path), "--out", str(tmp_path / "f.png")])
    assert seen["grid"] == (0.08, 25)


def argparse_namespace(**values):
    import argparse

    return argparse.Namespace(**values)


# ------------------------------------------------------------------ bad files
BAD = [
    ({"robot": {"V": -1}}, "robot.V must be a finite number in (0, 100] m/s; got -1"),
    ({"robot": {"V": "fast"}}, "robot.V must be a finite number in (0, 100] m/s; got 'fast'"),
    ({"robot": {"tau": 101}}, "robot.tau must be a finite number in [0, 100] s; got 101"),
    ({"robot": {"max_steering_rate": 0}}, "robot.max_steering_rate must be a finite number in (0, inf) deg/s; got 0"),
    ({"robot": {"speed": 1}}, "robot.speed is not a key; robot takes V, tau, k, W, max_steering_rate"),
    ({"robot": {"v": 1}}, "robot.v is not a key (did you mean V?)"),
    ({"robot": [1, 2]}, "robot must be a mapping of key: value with keys V, tau, k, W, max_steering_rate, dead_time, plant_gain, actuator_lag, yaw_accel_limit, slip_lag; got [1, 2]"),
    ({"controller": {"compute-delay": 1}}, "controller.compute-delay is not a key (did you mean compute_delay?)"),
    ({"controller": {"compute_delay": 1.5}}, "controller.compute_delay must be an integer in [0, 1]; got 1.5"),
    ({"controller": {"hold": "both"}}, "controller.hold must be one of command, reference; got 'both'"),
    ({"controller": {"T": 1e3}}, "controller.T must be a finite number in [0, 100] s; got 1000.0"),
    ({"law": {"name": "magnetic"}}, "law.name must be one of power, grid, khatib, gnron; got 'magnetic'"),
    ({"law": {"name": "power", "xi": 1}}, "law.xi applies to khatib or gnron, not to law power"),
    ({"law": {"name": "grid", "window_cells": 32}}, "law.window_cells must be an odd integer in [3, 1001]; got 32"),
    ({"law": ["grid"]}, "law must be a law's name or a mapping of key: value with keys name, cell_ratio"),
    ({"scenario": {"wall": {"alpha": 95}}}, "scenario.wall.alpha must be a finite number in [1e-06, 89.999999] deg; got 95"),
    ({"scenario": {"door": {"width": 1}}}, "scenario.door is not a key; scenario takes wall, corridor"),
    ({"scenario": {"corridor": [0.9]}}, "scenario.corridor must be a mapping"),
    ({"assumed": {"k": 3}}, "assumed.k must be a text saying why the value is assumed; got 3"),
    ({"assumed": {"goal": "x"}}, "assumed.goal is not a key; assumed takes V, tau, k, W, dead_time, plant_gain, actuator_lag, yaw_accel_limit, slip_lag, f, n, T, hold, compute_delay"),
    ({"robott": {}}, "robott is not a key (did you mean robot?); the file takes preset, name, source, robot"),
    ({"preset": "nope"}, "preset must be one of carmel; got 'nope'"),
    ({"name": 3}, "name must be a text; got 3"),
    ("- 1\n- 2\n", "the file must be a mapping of key: value with keys preset"),
    ("robot: {V: [1\n", "not valid YAML: expected ',' or ']'"),
    ("robot:\n  V: 1\n  V: 2\n", "robot.V is given twice"),
]


@pytest.mark.parametrize("data, message", BAD, ids=[m.split(" ")[0] + f"-{i}" for i, (_, m) in enumerate(BAD)])
def test_bad_file_is_a_one_line_error(tmp_path, capsys, data, message):
    """Each bad key, type, range or shape: ValueError from the library, exit 2 from every command, one
    line naming the file, the line of the key and the key (`cli_helpers.file_error` checks the line holds it)."""
    path = write(tmp_path, data)
    with pytest.raises(ValueError) as caught:
        load_config(path)
    assert file_error(str(caught.value), f"config {path}", path).startswith(message)
    assert "\n" not in str(caught.value)
    for command in (["report", "--alpha", "20"], ["plot", "force-law", "--out", str(tmp_path / "x.png")]):
        code, out, err = run(capsys, *command, "--config", path)
        assert (code, out) == (2, "") and err == f"pfm-stability: error: {caught.value}\n"
    assert not (tmp_path / "x.png").exists()


def test_missing_file_and_directory(tmp_path, capsys):
    """A missing file or a directory: exit 2, naming the file and why."""
    for path, why in ((tmp_path / "none.yaml", "No such file or directory"), (tmp_path, "Is a directory")):
        code, _, err = run(capsys, "report", "--config", path, "--L", "1")
        assert code == 2 and err == f"pfm-stability: error: config {path}: cannot read the file ({why})\n"


@pytest.mark.parametrize("option, key, value", [
    ("--V", "robot.V", "0"), ("--tau", "robot.tau", "-0.5"), ("--k", "robot.k", "1e5"), ("--W", "robot.W", "1e-4"),
    ("--f", "controller.f", "2e6"), ("--n", "controller.n", "0.001"), ("--T", "controller.T", "-1"),
    ("--cell-size", "law.cell_size", "2"), ("--goal-distance", "law.goal_distance", "0"), ("--L", "scenario.corridor.L", "0"),
])
def test_file_ranges_are_the_options_ranges(tmp_path, capsys, option, key, value):
    """The file's message states the option's range word for word (both from `parameters.RANGES`): the
    CLI's error for the option and the file's error for the key agree after the name."""
    code, _, err = run(capsys, "report", "--L", "1", "--law", "khatib" if "goal" in key else "grid" if "cell" in key else "power", option, value)
    assert code == 2
    option_rule = err.split(" must be ", 1)[1].split("; got")[0]
    *sections, name = key.split(".")
    data = {sections[0]: {name: float(value)}} if len(sections) == 1 else {"scenario": {"corridor": {"L": float(value)}}}
    if sections[0] == "law":
        data["law"]["name"] = "khatib" if "goal" in key else "grid"
    with pytest.raises(ValueError) as caught:
        load_config(write(tmp_path, data))
    assert str(caught.value).split(" must be ", 1)[0].endswith(key)
    assert str(caught.value).split(" must be ", 1)[1].split("; got")[0] == option_rule


def test_scientific_notation_is_a_number(tmp_path):
    """``k: 1e-3`` is the number 10⁻³ (plain YAML 1.1 would read the text '1e-3' and the check would call
    a valid value a wrong type); words that merely contain an e stay text and are rejected."""
    config = load_config(write(tmp_path, "robot: {k: 1e-3, V: 2E+0}\ncontroller: {f: .5e1}\n"))
    assert (config.robot.k, config.robot.V, config.controller.f) == (1e-3, 2.0, 5.0)
    with pytest.raises(ValueError, match=r"robot.k must be a finite number .*; got 'e3'$"):
        load_config(write(tmp_path, "robot: {k: e3}\n"))


def test_mapping_api_and_empty_file(tmp_path):
    """`config_from_mapping` names its origin in errors and sources; an empty file or None is the preset."""
    config = config_from_mapping({"robot": {"V": 0.3}}, "sweep s.yaml: config")
    assert isinstance(config, Config) and config.path is None and config.sources["V"] == "sweep s.yaml: config"
    with pytest.raises(ValueError, match=r"^sweep s.yaml: config: robot.V must be"):
        config_from_mapping({"robot": {"V": 0}}, "sweep s.yaml: config")
    empty = load_config(write(tmp_path, ""))
    assert (empty.robot, empty.controller) == (get_preset("carmel").robot, get_preset("carmel").controller)
    assert empty.sources["V"] == "preset carmel"


# ------------------------------------------------------------------ Nav2
def nav2(tmp_path, *, frequency=None, plugins=None, costmap=None, name="nav2.yaml") -> Path:
    server = {"use_sim_time": True}
    if frequency is not None:
        server["controller_frequency"] = frequency
    if plugins is not None:
        server["controller_plugins"] = list(plugins)
        server.update(plugins)
    data = {"bt_navigator": {"ros__parameters": {"use_sim_time": True}}, "controller_server": {"ros__parameters": server}}
    if costmap is not None:
        data["local_costmap"] = {"local_costmap": {"ros__parameters": {"resolution": 0.05, **costmap}}}
    return write(tmp_path, data, name)


def test_nav2_example(capsys):
    """The example of docs/examples: T = 1/20 Hz, V = FollowPath.max_vel_x (DWB's first key), W = 2 ×
    robot_radius; the rest CARMEL's; every value's key in the report, no notes. 1/20 is exact in binary to
    the last bit of the division, so equality."""
    config = load_config(NAV2_EXAMPLE)
    assert (config.controller.T, config.robot.V, config.robot.W) == (1 / 20.0, 0.26, 0.44)
    carmel = get_preset("carmel")
    assert (config.robot.tau, config.robot.k, config.controller.f, config.controller.hold) == (carmel.robot.tau, 2.0, 0.8, "command")
    assert config.notes == ()
    report = report_json(capsys, "--config", NAV2_EXAMPLE, "--L", "1")
    VALIDATOR.validate(report)
    inputs = report["inputs"]
    origin = f"Nav2 {NAV2_EXAMPLE}"
    assert inputs["T"]["source"] == f"{origin}: controller_server.controller_frequency = 20 Hz"
    assert inputs["V"]["source"] == f"{origin}: controller_server.FollowPath.max_vel_x = 0.26 m/s"
    assert inputs["W"]["source"] == f"{origin}: local_costmap.local_costmap.robot_radius = 0.22 m"
    assert inputs["k"]["source"].startswith("ASSUMED (preset carmel)")
    # a Nav2 file gives no steering lag, force ratio or exponent: the preset's values are assumptions, said so
    for name in ("tau", "f", "n", "hold", "compute_delay"):
        assert inputs[name]["source"].startswith("ASSUMED (preset carmel): "), name
    assert "Nav2 file does not give the steering lag" in inputs["tau"]["source"]
    assert "no VFF force ratio" in inputs["f"]["source"]


@pytest.mark.parametrize("seed", range(4))
def test_nav2_footprint_and_controller_plugins(tmp_path, seed):
    """Random footprints (as Nav2's string) far from CARMEL: W = max y − min y of the vertices as typed here,
    the footprint beats robot_radius; V from the first plugin with a speed key, in the documented key order
    (max_vel_x, max_speed_xy, desired_linear_vel, vx_max). Tolerance: the floats typed are the floats read."""
    rng = random.Random(seed)
    ys = [round(rng.uniform(-2, 2), 3) for _ in range(rng.randint(3, 7))]
    ys[0] = ys[0] if max(ys) - min(ys) > 1e-3 else ys[0] + 0.5
    footprint = "[" + ", ".join(f"[{round(rng.uniform(-1, 1), 3)}, {y}]" for y in ys) + "]"
    speeds = {"max_vel_x": 1.1, "max_speed_xy": 1.2, "desired_linear_vel": 1.3, "vx_max": 1.4}
    keys = list(speeds)[rng.randint(0, 3):]
    plugins = {"Empty": {"plugin": "x"}, "Main": {"plugin": "y", **{k: speeds[k] for k in keys}}, "Later": {"vx_max": 9.0}}
    path = nav2(tmp_path, frequency=rng.choice([5, 12.5, 40]), plugins=plugins, costmap={"footprint": footprint, "robot_radius": 9.0})
    config = load_config(path)
    assert config.robot.W == max(ys) - min(ys)
    assert config.robot.V == speeds[keys[0]] and config.sources["V"].endswith(f"controller_server.Main.{keys[0]} = {speeds[keys[0]]:g} m/s")
    assert config.sources["W"].endswith(f"local_costmap.local_costmap.footprint = {footprint}")


def test_nav2_missing_keys_are_notes(tmp_path, capsys):
    """A Nav2 file with only a frequency: T from it, V and W the preset's, one note each on stderr (not an
    error); the JSON on stdout is untouched."""
    path = nav2(tmp_path, frequency=10.0)
    config = load_config(path)
    assert config.controller.T == 0.1 and config.robot.V == 0.8 and len(config.notes) == 2
    assert "V is the preset's" in config.notes[0] and "max_vel_x, max_speed_xy, desired_linear_vel, vx_max" in config.notes[0]
    code, out, err = run(capsys, "report", "--config", path, "--L", "1", "--model", "sampled", "--format", "json")
    assert code == 0 and json.loads(out)["inputs"]["V"]["source"] == "ASSUMED (preset carmel): not found in the Nav2 file: the preset carmel's value"
    assert err.count("pfm-stability: note: Nav2 ") == 2 and "W is the preset's" in err


@pytest.mark.parametrize("kwargs, message", [
    ({}, "none of the Nav2 keys read was found (looked for T: controller_server.controller_frequency"),
    ({"frequency": 0}, "controller_server.controller_frequency must be a finite number in [0.01, 1000000] Hz; got 0"),
    ({"frequency": "fast"}, "controller_server.controller_frequency must be a finite number"),
    ({"plugins": {"FollowPath": {"max_vel_x": -0.2}}}, "controller_server.FollowPath.max_vel_x must be a finite number in (0, 100] m/s"),
    ({"costmap": {"footprint": "[[0.3, 0.2], [0.3]]"}}, "local_costmap.local_costmap.footprint must be a polygon [[x, y], ...]"),
    ({"costmap": {"footprint": "[[1, 0.2], [2, 0.2], [3, 0.2]]"}}, "footprint lateral extent (max y - min y) must be a finite number in [0.001, 100] m; got 0.0"),
    ({"costmap": {"robot_radius": 0}}, "local_costmap.local_costmap.robot_radius must be a finite number in [0.0005, 50] m; got 0"),
])
def test_nav2_bad_values(tmp_path, capsys, kwargs, message):
    """Bad Nav2 values, or none of the keys: one line naming the file and the key; exit 2."""
    path = nav2(tmp_path, **kwargs)
    with pytest.raises(ValueError) as caught:
        load_config(path)
    assert message in file_error(str(caught.value), f"Nav2 {path}", path)
    code, _, err = run(capsys, "report", "--config", path, "--L", "1")
    assert code == 2 and err == f"pfm-stability: error: {caught.value}\n"
