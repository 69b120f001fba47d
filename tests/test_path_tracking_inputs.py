"""The path tracker's inputs and outputs (docs/path_tracking.md, docs/config.md "Nav2 controllers"): the controller
registry, a Nav2 parameters file's controller_server and local costmap read (tests/data/nav2_rpp_params.yaml and
variants written here), ``report --controller`` in text, Markdown and JSON (the shipped schema), and its refusals (exit
2, one line)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from cli_helpers import VALIDATOR, report_json, run
from pfm_stability.controllers.registry import CONTROLLERS, COSTMAP, NAV2_CONTROLLERS, SERVER, controller_of_plugin, get_controller
from pfm_stability.io.nav2 import default_tracker, read_path_tracker
from pfm_stability.io.yaml_files import read_yaml

DATA = Path(__file__).parent / "data" / "nav2_rpp_params.yaml"


def _tracker(path, controller=None):
    from dataclasses import replace

    return read_path_tracker(replace(read_yaml(path, "config"), origin=f"Nav2 {path}"), controller)


def _nav2_file(tmp_path, follow_path: str, costmap: str = "") -> Path:
    """A small Nav2 parameters file with this FollowPath block (indented 6) and local costmap parameters (indented 6)."""
    text = ("controller_server:\n  ros__parameters:\n    controller_frequency: 20.0\n    FollowPath:\n" + follow_path
            + ("local_costmap:\n  local_costmap:\n    ros__parameters:\n" + costmap if costmap else ""))
    path = tmp_path / "nav2_params.yaml"
    path.write_text(text)
    return path


# ------------------------------------------------------------------ the registry
def test_registry_declarations_are_consistent():
    """Every controller's declared default passes its own check, names are unique, every Nav2 plugin resolves (also in the
    older ``pkg/Class`` spelling), and the cruising speed of each Nav2 controller is one of its parameters; the server's
    and costmap's declarations check too. Why: the dataclasses of the algorithms take their defaults from here."""
    for entry in CONTROLLERS.values():
        names = [p.name for p in entry.parameters]
        assert len(names) == len(set(names))
        for p in entry.parameters:
            assert p.check(p.default) == p.default
        for plugin in entry.plugins:
            assert controller_of_plugin(plugin) is entry and controller_of_plugin(plugin.replace("::", "/")) is entry
    for name in NAV2_CONTROLLERS:
        entry = get_controller(name)
        assert entry.parameter(entry.speed).kind == "float" and entry.parameters
    assert get_controller("rpp").parameter("desired_linear_vel").name == "max_linear_vel"
    for p in SERVER + COSTMAP:
        if p.kind != "str":
            assert p.check(p.default) == p.default
    with pytest.raises(ValueError, match="lookahead_dist must be a finite number in \\(0, 100\\] m; got -1"):
        get_controller("rpp").parameter("lookahead_dist").check(-1.0)
    with pytest.raises(ValueError, match="must be true or false"):
        get_controller("rpp").parameter("use_velocity_scaled_lookahead_dist").check(1)


def test_registry_imports_no_numpy():
    """The command line reads the registry before loading numpy (as the law registry)."""
    code = "import sys\nimport pfm_stability.controllers.registry\nprint('numpy' in sys.modules)\n"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "False"


# ------------------------------------------------------------------ a Nav2 file
def test_rpp_file_is_read_with_its_provenance():
    """tests/data/nav2_rpp_params.yaml: the RPP plugin, the deprecated desired_linear_vel read as max_linear_vel, the
    file's lookahead, a parameter not in the file at Nav2's default marked ASSUMED, controller_frequency, the footprint's
    inscribed radius (the rectangle's half-width 0.25 m) and the inflation layer found by its plugin class."""
    t = _tracker(DATA)
    assert (t.controller, t.plugin_id, t.plugin) == ("rpp", "FollowPath", "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController")
    values = t.values()
    assert values["max_linear_vel"] == 0.7 and "desired_linear_vel = 0.7" in t.parameters["max_linear_vel"].source
    assert values["lookahead_dist"] == 0.8 and not t.parameters["lookahead_dist"].assumed
    assert values["use_dynamic_window"] is False and t.parameters["use_dynamic_window"].assumed
    assert "parameter_handler.cpp" in t.parameters["curvature_lookahead_dist"].source
    assert t.frequency.value == 10.0 and not t.frequency.assumed
    costmap = t.costmap_values()
    assert costmap["inscribed_radius"] == pytest.approx(0.25, abs=1e-15)
    assert (costmap["inflation_radius"], costmap["cost_scaling_factor"], costmap["resolution"]) == (0.7, 3.0, 0.05)


def test_rotation_shim_primary_controller_both_spellings(tmp_path):
    """A Rotation Shim FollowPath tracks with its primary controller: ``primary_controller: {plugin: …}`` with its
    parameters inside (Nav2 after Kilted), or a class name with the parameters beside it (before)."""
    new = _nav2_file(tmp_path, '      plugin: "nav2_rotation_shim_controller::RotationShimController"\n      primary_controller:\n'
                     '        plugin: "nav2_graceful_controller::GracefulController"\n        max_lookahead: 1.4\n')
    t = _tracker(new)
    assert t.controller == "graceful" and t.values()["max_lookahead"] == 1.4 and any("Rotation Shim" in n for n in t.notes)
    assert t.plugin_source.endswith("controller_server.FollowPath.primary_controller.plugin")
    old = _nav2_file(tmp_path, '      plugin: "nav2_rotation_shim_controller::RotationShimController"\n'
                     '      primary_controller: "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"\n'
                     '      lookahead_dist: 1.1\n')
    assert _tracker(old).values()["lookahead_dist"] == 1.1


def test_robot_radius_is_nav2s_16_gon_and_defaults_are_assumed(tmp_path):
    """robot_radius r: Nav2's footprint is a 16-gon, inscribed radius r·cos(π/16); a FollowPath without plugin is Nav2's
    default MPPI (noted); with no file every value is Nav2's default, ASSUMED with the reason."""
    t = _tracker(_nav2_file(tmp_path, "      vx_max: 0.6\n", "      robot_radius: 0.3\n"))
    assert t.controller == "mppi" and t.values()["vx_max"] == 0.6 and any("not given" in n for n in t.notes)
    assert t.costmap_values()["inscribed_radius"] == pytest.approx(0.3 * math.cos(math.pi / 16), rel=1e-15)
    d = default_tracker("graceful")
    assert all(s.assumed and "no Nav2 file given" in s.source for s in d.parameters.values())
    assert d.frequency.value == 20.0 and d.costmap_values()["cost_scaling_factor"] == 10.0


@pytest.mark.parametrize("block, controller, message", [
    ('      plugin: "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"\n      lookahead_dist: -0.5\n', None,
     "line 6: controller_server.FollowPath.lookahead_dist must be a finite number in (0, 100] m; got -0.5"),
    ('      plugin: "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"\n      use_rotate_to_heading: 1\n', None,
     "use_rotate_to_heading must be true or false; got 1"),
    ('      plugin: "teb_local_planner::TebLocalPlannerROS"\n', None, "is not a controller the report analyses"),
    ('      plugin: "nav2_mppi_controller::MPPIController"\n', "rpp", "give --controller mppi or auto"),
])
def test_bad_nav2_files_are_one_line_naming_file_line_and_key(tmp_path, block, controller, message):
    """A value of the wrong type or out of range, a plugin the report does not analyse, or a plugin other than the one asked
    for: ValueError naming the file, the line and the key (the CLI prints it, exit 2)."""
    path = _nav2_file(tmp_path, block)
    with pytest.raises(ValueError) as info:
        _tracker(path, controller)
    assert message in str(info.value) and str(path) in str(info.value) and "\n" not in str(info.value)


# ------------------------------------------------------------------ the command line
@pytest.fixture(scope="module")
def rpp_json():
    return report_json(["--controller", "rpp", "--config", str(DATA), "--L", "0.5", "--dead-time", "0.2", "--tau", "0.1",
                        "--param", "cost_scaling_dist=0.8"])


def test_report_reads_the_file_and_the_options(rpp_json):
    """V from the file's desired_linear_vel, T = 1/controller_frequency, --param over the file, the corridor's cost at the
    robot regulating V (⌊252·e^(−3·0.25)⌋ = 119), every model under path.<model> (schema-checked by `report_json`)."""
    inputs, env = rpp_json["inputs"], rpp_json["environment"]["path"]
    assert inputs["V"]["value"] == 0.7 and "desired_linear_vel" in inputs["V"]["source"]
    assert inputs["T"]["value"] == pytest.approx(0.1) and "controller_frequency = 10 Hz" in inputs["T"]["source"]
    assert inputs["cost_scaling_dist"] == {"value": 0.8, "unit": "m", "source": "user"}
    assert inputs["compute_delay"]["value"] == 0 and inputs["compute_delay"]["source"].startswith("ASSUMED")
    assert env["pose_cost"] == 119 and env["geometry"] == "corridor" and env["law"]["V"] < 0.7
    assert set(rpp_json["path"]) == {"continuous", "kb_first_order", "pade", "exact_delay", "sampled"}
    assert "wall" not in rpp_json and "corridor" not in rpp_json and "kb_error" not in rpp_json


def test_text_and_markdown_say_what_the_json_says(rpp_json):
    """The text and Markdown renderings carry the JSON's numbers (V*, the table's rows) and the notes."""
    argv = ["report", "--controller", "rpp", "--config", str(DATA), "--L", "0.5", "--dead-time", "0.2", "--tau", "0.1",
            "--param", "cost_scaling_dist=0.8"]
    code, text, _ = run(argv)
    assert code == 0 and "Regulated Pure Pursuit tracking in a corridor of half-width L = 0.5 m" in text
    V_star = rpp_json["path"]["sampled"]["V_critical"]
    assert f"{V_star:.4g}" in text and "cost heuristic: V = max_linear_vel x" in text
    code, md, _ = run([*argv, "--format", "markdown"])
    assert code == 0 and md.startswith("# pfm-stability report: Nav2's Regulated Pure Pursuit") and f"{V_star:.4g}" in md


def test_auto_takes_the_files_plugin_and_mppi_takes_gains(tmp_path):
    """``--controller auto`` analyses the file's FollowPath; MPPI's measured gains give a verdict over their uncertainty
    and the model delay recommendation (JSON schema-checked)."""
    data = report_json(["--controller", "auto", "--config", str(DATA), "--model", "exact_delay"])
    assert data["inputs"]["controller"]["value"] == "rpp" and data["inputs"]["controller"]["source"].startswith("auto")
    mppi = report_json(["--controller", "mppi", "--k-theta", "1.1", "--k-y", "1.9", "--k-theta-se", "0.05", "--k-y-se", "0.1", "--dead-time", "0.12",
                        "--model", "sampled"])
    v = mppi["path"]["sampled"]
    assert v["lookahead_critical"] is None and len(v["margin_range"]) == 2 and mppi["environment"]["path"]["model_delay"]["steps"] == 2


@pytest.mark.parametrize("argv, message", [
    (["--controller", "rpp", "--param", "nope=1"], "'nope' is not a parameter of nav2_regulated_pure_pursuit_controller (rpp)"),
    (["--controller", "rpp", "--param", "lookahead_dist=0"], "--param lookahead_dist must be a finite number in (0, 100] m; got 0"),
    (["--controller", "rpp", "--param", "max_linear_vel=1"], "--param max_linear_vel: the cruising speed is --V"),
    (["--controller", "mppi", "--k-theta", "1.1"], "give both --k-theta and --k-y, or neither"),
    (["--controller", "rpp", "--k-theta", "1"], "--k-theta applies to --controller mppi or dwb"),
    (["--controller", "rpp", "--param", "lookahead_dist"], "--param must be NAME=VALUE"),
    (["--controller", "rpp", "--alpha", "20"], "alpha applies to --controller vff"),
    (["--controller", "rpp", "--f", "2"], "--f applies to --controller vff"),
    (["--param", "lookahead_dist=1"], "--param applies to --controller rpp, graceful, mppi, dwb, not to --controller vff"),
    (["--controller", "auto"], "--controller auto takes the controller from a Nav2 parameters file"),
    (["--controller", "dwb", "--k-theta", "1", "--k-y", "2"], "max_vel_x is 0 m/s"),
    (["--controller", "rpp", "--L", "0.05"], "L must exceed the robot's inscribed radius"),
])
def test_refusals_are_one_line_and_exit_2(argv, message):
    """Bad input: exit 2 and one line naming what the user gave and the allowed range or the option that applies."""
    code, out, err = run(["report", *argv])
    assert code == 2 and out == "" and message in err and len(err.strip().splitlines()) == 1, err


def test_a_controllers_report_reads_its_own_keys_without_the_vff_notes(tmp_path):
    """RPP's current name max_linear_vel is the cruising speed (the VFF reading's SPEED_KEYS do not list it: its note
    "V is the preset's" would mislead, so a controller's report prints none); the Rotation Shim's note is in the report."""
    path = _nav2_file(tmp_path, '      plugin: "nav2_rotation_shim_controller::RotationShimController"\n      primary_controller:\n'
                      '        plugin: "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"\n'
                      '        max_linear_vel: 0.65\n')
    code, out, err = run(["report", "--controller", "auto", "--config", str(path), "--model", "sampled"])
    assert code == 0 and err == "" and "V (cruising speed)                     0.65 m/s" in out and "Rotation Shim controller" in out


def test_vff_default_is_todays_report():
    """Without --controller the report is the VFF loop's (its answers are replayed by tests/test_answers_unchanged.py):
    no path section, the KB error line, and a Nav2 file gives T, V and W as before."""
    data = report_json(["--config", str(DATA), "--L", "0.9", "--model", "kb_first_order", "--model", "sampled"])
    assert "path" not in data and "corridor" in data and data["inputs"]["T"]["value"] == pytest.approx(0.1)
    assert not VALIDATOR.is_valid({**data, "path": {"sampled": {}}})  # a path verdict has its required keys
    json.dumps(data)


def test_readme_worked_example_is_what_the_report_prints():
    """README's "Will my Nav2 robot weave?": its command, run, prints every table row the README shows (the numbers a
    reader is told to read), and the remedies it quotes for --dead-time 0.7."""
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = readme.split("## Will my Nav2 robot weave?", 1)[1].split("\n## ", 1)[0]
    command = section.split("```bash\n", 1)[1].split("\n```", 1)[0]
    assert command == "pfm-stability report --controller rpp --dead-time 0.364 --tau 0"
    shown = section.split("```bash\n", 1)[1].split("\n```\n", 1)[1].split("```\n", 1)[1].split("```", 1)[0]
    code, out, _ = run(command.split()[1:])
    assert code == 0
    rows = [line for line in shown.splitlines() if line.startswith("  ") and line.split()[0] in
            ("model", "continuous", "kb_first_order", "pade", "exact_delay", "sampled")]
    assert len(rows) == 6 and all(row in out for row in rows)
    code, out, _ = run(["report", "--controller", "rpp", "--dead-time", "0.7", "--tau", "0", "--model", "sampled"])
    assert "lower max_linear_vel to <= 0.4308 m/s (-14 %); raise lookahead_dist to >= 0.6964 m (+16 %); lower dead_time to <= 0.5997 s (-14 %)" in out
    assert "lower max_linear_vel to <= 0.4308 m/s (-14 %); raise lookahead_dist to >= 0.6964 m (+16 %); lower dead_time to <= 0.5997 s (-14 %)" in section


def test_mppi_without_typed_gains_measures_them_with_the_files_values(tmp_path, monkeypatch):
    """No --k-theta/--k-y: the report measures MPPI's gains from its algorithm (`MeasuredGains.measure`, stubbed here with
    known taps: the measurement itself is tests/test_controllers_mppi_dwb.py's) with the values the Nav2 file gave and
    not the assumed ones, at the report's V, T and corridor; its memory gives the report's memory verdict (schema-checked)
    and the stderr note says the gains were measured."""
    from pfm_stability.analysis import path_laws

    seen = {}

    def measure(cls, name, given, costmap, *, V, T, half_width=None, seed=0, memory_cycles=path_laws.MEMORY_CYCLES):
        seen.update(name=name, given=given, V=V, T=T, half_width=half_width)
        return cls(name, 1.1, 1.9, V, 0.05, 0.1, ((1.1, 0.6, 0.3), (1.9, 1.0, 0.5), (0.0, 0.0, 0.0)))

    monkeypatch.setattr(path_laws.MeasuredGains, "measure", classmethod(measure))
    path = tmp_path / "nav2.yaml"
    path.write_text("controller_server:\n  ros__parameters:\n    controller_frequency: 20.0\n    FollowPath:\n"
                    "      plugin: \"nav2_mppi_controller::MPPIController\"\n      vx_max: 0.4\n      CostCritic:\n        cost_weight: 4.0\n")
    code, out, err = run(["report", "--controller", "auto", "--config", str(path), "--L", "0.8", "--dead-time", "0.1", "--format", "json"])
    assert code == 0 and "measuring mppi's gains from its algorithm" in err
    data = json.loads(out)
    assert not [e.message for e in VALIDATOR.iter_errors(data)]
    assert seen["name"] == "mppi" and seen["given"]["vx_max"] == 0.4 and seen["given"]["CostCritic.cost_weight"] == 4.0
    assert "batch_size" not in seen["given"] and seen["T"] == pytest.approx(0.05) and seen["half_width"] == 0.8
    memory = data["environment"]["path"]["memory"]
    assert memory["cycles"] == 3 and 0 < memory["dead_time_critical"] < data["path"]["sampled"]["dead_time_critical"]
