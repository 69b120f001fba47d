"""Configuration files with robot families and the velocity and fuzzy laws (docs/config.md, `report` only).

Checked: ``robot.family``, ``robot.mass`` and a ``law`` of `parameters.FAMILY_LAWS` reach the report's
JSON with the file as their source; ``report --config FILE`` gives the JSON of the same values typed
(but the sources), for each family law and robot family, at random values far from CARMEL's; an
option typed beats the file, and the file's mass and law parameters apply only where its family and
law are the ones in force; every bad key or value is a one-line error naming the file and the key
(exit 2, the option's range word for word); the other commands and sweeps refuse what they cannot
analyse; the shipped example runs and gives Ge & Cui 2002's corridor numbers, checked against the
closed form of Khatib's corridor stiffness. Every command is run in-process.
"""

from __future__ import annotations

import json
import random
from pathlib import Path

import pytest
import yaml

from pfm_stability.cli import main
from pfm_stability.io.config import load_config
from pfm_stability.sweeps.spec import load_spec
from cli_helpers import file_error

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "docs" / "examples" / "holonomic_robot.yaml"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def write(tmp_path, data, name="robot.yaml") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data), encoding="utf-8")
    return path


def report_json(capsys, *argv) -> dict:
    code, out, err = run(capsys, "report", *argv, "--format", "json")
    assert code == 0, err
    return json.loads(out)


def without_sources(report: dict) -> dict:
    """The report with every input's source removed (what differs between a file and typed options)."""
    inputs = {name: {k: v for k, v in entry.items() if k != "source"} for name, entry in report["inputs"].items()}
    return {**report, "inputs": inputs}


def option(key: str) -> str:
    return "--" + key.replace("_", "-")


def khatib_corridor_kappa(eta, rho0, L, mass) -> float:
    """κ = −F_x′(0)/m at the centre of a corridor of half-width L with Khatib's repulsion from both walls:
    F(d) = η(1/d − 1/ρ0)/d² (d < ρ0), so F_x′(0) = 2F′(L) and κ = 2η(3/L⁴ − 2/(ρ0 L³))/m."""
    return 2 * eta * (3 / L**4 - 2 / (rho0 * L**3)) / mass


# ------------------------------------------------------------------ the example
def test_example_file_runs_and_gives_ge_cui_corridor(capsys):
    """The shipped example (Ge & Cui 2002 Sec 6: η = 0.3, ρ0 = 2 m, L = 0.5 m, α_v = 0.1, 1 kg) runs, every value
    it gives is sourced to it, and κ, c_h equal the closed forms (κ above; c_h = 2α_v/m for n = 2) to 1e-9
    relative: the report computes them by a root search and finite geometry, the closed form by hand."""
    d = report_json(capsys, "--config", EXAMPLE)
    source = f"config {EXAMPLE}"
    for name in ("robot", "mass", "alpha_p", "alpha_v", "eta", "rho0", "L"):
        assert d["inputs"][name]["source"] == source, name
    assert d["inputs"]["robot"]["value"] == "holonomic" and d["inputs"]["eta"]["value"] == 0.3
    corridor = d["environment"]["corridor"]
    assert corridor["kappa"] == pytest.approx(khatib_corridor_kappa(0.3, 2.0, 0.5, 1.0), rel=1e-9)
    assert corridor["kappa"] == pytest.approx(24.0, rel=1e-9) and corridor["c_h"] == pytest.approx(0.2, rel=1e-9)
    code, out, _ = run(capsys, "report", "--config", EXAMPLE)
    assert code == 0 and "kappa = 24 1/s^2, c_h = 0.2 1/s" in out


def test_load_config_reads_family_and_mass(tmp_path):
    """The library: `Config.family`, `Config.mass` and the law's values and sources, as written (no conversion)."""
    config = load_config(EXAMPLE)
    assert (config.family, config.mass) == ("holonomic", 1.0)
    assert config.law == {"name": "velocity", "alpha_p": 0.5, "alpha_v": 0.1, "attraction_exponent": 2.0, "velocity_exponent": 2.0,
                          "eta": 0.3, "rho0": 2.0, "goal_distance": 1.0}
    assert config.sources["robot"] == config.sources["mass"] == config.sources["alpha_v"] == f"config {EXAMPLE}"
    plain = load_config(write(tmp_path, {"robot": {"V": 0.5}}))
    assert (plain.family, plain.mass) == (None, None) and "robot" not in plain.sources


# ------------------------------------------------------------------ file = typed options
def _random_case(rng, law):
    """A random robot and law far from CARMEL's and the defaults: (file mapping, typed options)."""
    family = {"velocity": rng.choice(["holonomic", "kinematic", "steering"]), "velocity-gated": "holonomic", "fuzzy": "kinematic"}[law]
    robot = {"family": family, "V": round(rng.uniform(0.2, 3.0), 3), "W": round(rng.uniform(0.2, 1.2), 3)}
    values = {"alpha_p": round(10 ** rng.uniform(-1, 1), 4), "rho0": round(rng.uniform(1.5, 4.0), 3)}
    if law != "fuzzy":
        values["eta"] = round(10 ** rng.uniform(-1.5, 0.5), 4)
    if law == "velocity":
        values.update(alpha_v=round(10 ** rng.uniform(-2, 0), 4), velocity_exponent=rng.choice([2.0, 1.5, 3.0]))
    if law == "velocity-gated":
        values["a_max"] = round(10 ** rng.uniform(-0.5, 1), 3)
    if family == "holonomic":
        robot["mass"] = round(10 ** rng.uniform(-1, 1.5), 3)
    scenario = {"corridor": {"L": round(values["rho0"] * rng.uniform(0.25, 0.6), 3)}} if law == "velocity" else {"wall": {"alpha": rng.choice([30, 45, 60])}}
    data = {"robot": robot, "controller": {"T": round(10 ** rng.uniform(-3, -1), 5)}, "law": {"name": law, **values}, "scenario": scenario}
    if law == "fuzzy":
        data["law"]["side"] = rng.choice(["left", "right"])
    typed = ["--robot", family, "--law", law, "--V", robot["V"], "--W", robot["W"], "--T", data["controller"]["T"]]
    typed += [x for key, value in data["law"].items() if key != "name" for x in (option(key), value)]
    typed += ["--mass", robot["mass"]] if "mass" in robot else []
    typed += ["--L", scenario["corridor"]["L"]] if "corridor" in scenario else ["--alpha", scenario["wall"]["alpha"]]
    return data, typed


@pytest.mark.parametrize("law, seed", [("velocity", 1), ("velocity", 2), ("velocity-gated", 3), ("fuzzy", 4)])
def test_file_gives_the_report_of_the_same_values_typed(tmp_path, capsys, law, seed):
    """``report --config FILE`` equals ``report`` with the same values typed, byte for byte after dropping the
    sources (exact: the same numbers reach the same code), and every value the file gives is sourced to it
    while the typed run says ``user``. Random robots and laws (seeded), far from CARMEL and the defaults.
    For a holonomic velocity law in a corridor, κ is also checked against the closed form (1e-9 relative)."""
    rng = random.Random(seed)
    data, typed = _random_case(rng, law)
    path = write(tmp_path, data)
    from_file = report_json(capsys, "--config", path, *(["--no-simulate"] if law == "velocity-gated" else []))
    from_typed = report_json(capsys, *typed, *(["--no-simulate"] if law == "velocity-gated" else []))
    assert without_sources(from_file) == without_sources(from_typed)
    given = [k for k in data["law"] if k != "name"] + ["robot", "V", "W", "T"] + (["mass"] if "mass" in data["robot"] else [])
    for name in given:
        if name == "W" and "W" not in from_typed["inputs"]:  # the family laws' reports list no width (D is the distance)
            assert name not in from_file["inputs"]
            continue
        assert from_file["inputs"][name]["source"] == f"config {path}", name
        assert from_typed["inputs"][name]["source"] == "user", name
    if law == "velocity" and data["robot"]["family"] == "holonomic":
        corridor = from_file["environment"]["corridor"]
        expected = khatib_corridor_kappa(data["law"]["eta"], data["law"]["rho0"], data["scenario"]["corridor"]["L"], data["robot"]["mass"])
        assert corridor["kappa"] == pytest.approx(expected, rel=1e-9)


def test_velocity_gated_cycle_from_file_equals_typed(tmp_path, capsys):
    """With the simulated limit cycle (velocity-gated, a holonomic robot on a wall): the file and the typed values
    give the same JSON after the sources (the simulator is deterministic: exact)."""
    data = {"robot": {"family": "holonomic", "mass": 2.0}, "law": {"name": "velocity-gated", "eta": 0.2, "a_max": 0.5},
            "scenario": {"wall": {"alpha": 40}}}
    path = write(tmp_path, data)
    typed = ["--robot", "holonomic", "--mass", "2", "--law", "velocity-gated", "--eta", "0.2", "--a-max", "0.5", "--alpha", "40"]
    a, b = report_json(capsys, "--config", path), report_json(capsys, *typed)
    assert without_sources(a) == without_sources(b)
    assert a["inputs"]["a_max"]["source"] == f"config {path}"


# ------------------------------------------------------------------ precedence
def test_options_beat_the_file(tmp_path, capsys):
    """An option typed beats the file's value (source ``user``), the others stay the file's; a typed --robot
    drops the file's mass (it applies to holonomic only), a typed --law of another law drops the file's law
    parameters (defaults), as a typed static law drops a file's static law parameters."""
    path = write(tmp_path, {"robot": {"family": "holonomic", "mass": 4.0},
                            "law": {"name": "velocity", "alpha_v": 0.3, "eta": 0.5, "rho0": 2.5}, "scenario": {"corridor": {"L": 0.8}}})
    d = report_json(capsys, "--config", path, "--mass", "2", "--alpha-v", "0.05")
    assert (d["inputs"]["mass"]["value"], d["inputs"]["mass"]["source"]) == (2.0, "user")
    assert (d["inputs"]["alpha_v"]["value"], d["inputs"]["alpha_v"]["source"]) == (0.05, "user")
    assert (d["inputs"]["eta"]["value"], d["inputs"]["eta"]["source"]) == (0.5, f"config {path}")
    assert d["environment"]["corridor"]["c_h"] == pytest.approx(2 * 0.05 / 2.0, rel=1e-12)
    kin = report_json(capsys, "--config", path, "--robot", "kinematic")
    assert kin["inputs"]["robot"] == {"value": "kinematic", "unit": "", "source": "user"}
    assert "mass" not in kin["inputs"]  # a kinematic robot has no mass: the file's is not in force
    assert kin["inputs"]["alpha_v"]["source"] == f"config {path}"  # the file's law is still the law in force
    gated = report_json(capsys, "--config", path, "--law", "velocity-gated", "--no-simulate")
    assert gated["inputs"]["eta"]["value"] == 0.1 and gated["inputs"]["eta"]["source"].startswith("default")
    assert gated["inputs"]["mass"]["source"] == f"config {path}"


def test_file_law_with_static_law_typed(tmp_path, capsys):
    """A typed static law replaces the file's family law (and its parameters): the report is KB's, equal to the
    one without the file's law; a family option typed against the file's static law names the file."""
    path = write(tmp_path, {"law": {"name": "fuzzy", "side": "right", "alpha_p": 3}})
    a = report_json(capsys, "--config", path, "--law", "power", "--L", "1")
    b = report_json(capsys, "--law", "power", "--L", "1")
    assert without_sources(a) == without_sources(b)
    static = write(tmp_path, {"law": {"name": "khatib", "goal_distance": 2}}, "static.yaml")
    code, out, err = run(capsys, "report", "--config", static, "--alpha-v", "0.2", "--L", "1")
    assert (code, out) == (2, "")
    assert err == f"pfm-stability: error: --alpha-v applies to --law velocity, not to law khatib of --config {static}\n"


# ------------------------------------------------------------------ bad files
BAD = [
    ({"robot": {"family": "holonomic", "mass": 0}}, "robot.mass must be a finite number in (0, 1000000] kg; got 0"),
    ({"robot": {"family": "holonomic", "mass": "heavy"}}, "robot.mass must be a finite number in (0, 1000000] kg; got 'heavy'"),
    ({"robot": {"mass": 2}}, "robot.mass applies to robot family holonomic (robot.family: holonomic), not to family steering"),
    ({"robot": {"family": "kinematic", "mass": 2}}, "robot.mass applies to robot family holonomic"),
    ({"robot": {"family": "wheeled"}}, "robot.family must be one of steering, kinematic, holonomic; got 'wheeled'"),
    ({"robot": {"a_max": 2}}, "robot.a_max is not a key (did you mean law.a_max?); robot takes V, tau, k, W, max_steering_rate, dead_time, plant_gain, actuator_lag, yaw_accel_limit, slip_lag, family, mass"),
    ({"robot": {"famly": "holonomic"}}, "robot.famly is not a key (did you mean family?)"),
    ({"robot": {"family": "holonomic"}, "law": {"name": "grid"}}, "robot.family holonomic takes law velocity or velocity-gated"),
    ({"law": {"name": "power", "alpha_p": 1}}, "law.alpha_p applies to velocity, velocity-gated or fuzzy, not to law power"),
    ({"law": {"name": "khatib", "alpha_v": 1}}, "law.alpha_v applies to velocity, not to law khatib"),
    ({"law": {"name": "grid", "side": "left"}}, "law.side applies to fuzzy, not to law grid"),
    ({"law": {"name": "velocity", "a_max": 1}}, "law.a_max applies to velocity-gated, not to law velocity"),
    ({"law": {"name": "fuzzy", "eta": 1}}, "law.eta applies to khatib, gnron, velocity or velocity-gated, not to law fuzzy"),
    ({"law": {"name": "fuzzy", "side": "up"}}, "law.side must be one of left, right; got 'up'"),
    ({"law": {"name": "velocity", "alpah_v": 1}}, "law.alpah_v is not a key (did you mean alpha_v?)"),
    ({"law": {"name": "velocity", "velocity_exponent": 0}}, "law.velocity_exponent must be a finite number in (0, 10]; got 0"),
    ({"law": {"name": "velocity-gated", "a_max": -1}}, "law.a_max must be a finite number in (0, 1000000] m/s^2; got -1"),
    ({"law": {"name": "magnetic"}}, "law.name must be one of power, grid, khatib, gnron; got 'magnetic' (report also takes velocity, velocity-gated or fuzzy"),
    ({"controller": {"mass": 1}}, "controller.mass is not a key (did you mean robot.mass?)"),
]


@pytest.mark.parametrize("data, message", BAD, ids=[m.split(" ")[0] + f"-{i}" for i, (_, m) in enumerate(BAD)])
def test_bad_family_keys_are_one_line_errors(tmp_path, capsys, data, message):
    """Each bad family key or value: ValueError from the library starting ``config FILE: <key> …``, and exit 2
    from ``report`` with that line and nothing on stdout."""
    path = write(tmp_path, data)
    with pytest.raises(ValueError) as caught:
        load_config(path)
    assert file_error(str(caught.value), f"config {path}", path).startswith(message) and "\n" not in str(caught.value)
    code, out, err = run(capsys, "report", "--config", path, "--L", "1")
    assert (code, out, err) == (2, "", f"pfm-stability: error: {caught.value}\n")


@pytest.mark.parametrize("opt, key, value, law", [
    ("--mass", "robot.mass", "-2", "velocity"), ("--alpha-p", "law.alpha_p", "0", "velocity"), ("--alpha-v", "law.alpha_v", "-1", "velocity"),
    ("--velocity-exponent", "law.velocity_exponent", "11", "velocity"), ("--a-max", "law.a_max", "0", "velocity-gated"),
])
def test_file_ranges_are_the_options_ranges(tmp_path, capsys, opt, key, value, law):
    """The file's range for each new key is the option's, word for word (both from `parameters.RANGES`)."""
    code, _, err = run(capsys, "report", "--robot", "holonomic", "--law", law, "--L", "1", opt, value)
    assert code == 2
    option_rule = err.split(" must be ", 1)[1].split("; got")[0]
    section, name = key.split(".")
    data = {"robot": {"family": "holonomic"}, "law": {"name": law}}
    data[section][name] = float(value)
    with pytest.raises(ValueError) as caught:
        load_config(write(tmp_path, data))
    assert f"{key} must be {option_rule}; got" in str(caught.value)


# ------------------------------------------------------------------ other commands and sweeps
def test_other_commands_refuse_a_robot_family(tmp_path, capsys):
    """simulate, validate, plot and map analyse KB's steering robot: a file's kinematic or holonomic family is an
    error naming it; ``robot.family: steering`` is accepted (plot draws); map refuses a file's family law."""
    path = write(tmp_path, {"robot": {"family": "kinematic"}})
    commands = [["simulate", "--scenario", "corridor", "--duration", "1"], ["validate", "--scenario", "corridor"],
                ["plot", "force-law", "--out", tmp_path / "x.png"], ["map", "depot"]]
    for command in commands:
        code, out, err = run(capsys, *command, "--config", path)
        assert (code, out) == (2, ""), command
        assert err.startswith(f"pfm-stability: error: robot.family kinematic of --config {path} is read by report only"), command
    assert not (tmp_path / "x.png").exists()
    steering = write(tmp_path, {"robot": {"family": "steering"}}, "steering.yaml")
    code, _, err = run(capsys, "plot", "force-law", "--config", steering, "--out", tmp_path / "y.png")
    assert code == 0 and (tmp_path / "y.png").exists(), err
    fuzzy = write(tmp_path, {"law": {"name": "fuzzy"}}, "fuzzy.yaml")
    code, _, err = run(capsys, "map", "depot", "--config", fuzzy)
    assert code == 2 and err.startswith(f"pfm-stability: error: law fuzzy of --config {fuzzy} is analysed by report only")


@pytest.mark.parametrize("config, key", [
    ({"robot": {"family": "holonomic"}, "law": {"name": "velocity"}}, "robot.family holonomic"),
    ({"robot": {"family": "kinematic"}}, "robot.family kinematic"),
    ({"law": {"name": "velocity-gated", "a_max": 2}}, "law.name velocity-gated"),
])
def test_sweep_refuses_families_and_family_laws(tmp_path, config, key):
    """A sweep spec's config file with a robot family or a family law is refused before any work, naming the
    key and saying that sweeps do not support it; the spec's own law replaces a file's family law."""
    write(tmp_path, config, "robot.yaml")
    spec = write(tmp_path, "config: robot.yaml\nscenario: {corridor: {L: 1}}\ngrid: {V: {from: 0.2, to: 1.0, num: 3}}\n", "spec.yaml")
    with pytest.raises(ValueError) as caught:
        load_spec(spec)
    detail = file_error(str(caught.value), f"spec {spec}", spec)
    assert detail.startswith(f"config: {key} is not supported: sweeps analyse KB's steering robot")
    if "family" not in config.get("robot", {}):
        own = write(tmp_path, "config: robot.yaml\nlaw: {name: power}\nscenario: {corridor: {L: 1}}\ngrid: {V: {from: 0.2, to: 1.0, num: 3}}\n",
                    "own.yaml")
        assert load_spec(own).law == "power"


@pytest.mark.parametrize("law", [
    {"name": "fuzzy", "alpha_p": 50, "rho0": 0.5, "symmetrize": "negative"},
    {"name": "velocity-gated", "eta": 0.2, "variant": "squared"},
    {"name": "velocity", "eta": 0.05, "alpha_v": 0.3},
])
def test_a_files_family_law_is_in_force_without_typing_law(tmp_path, capsys, law):
    """A steering robot's file naming a family law gives that law's report with no --law typed, equal (sources aside)
    to the same values typed: the report follows the law resolved from the file, not the --law default. Exact JSON."""
    path = write(tmp_path, {"law": law})
    typed = ["--law", law["name"]] + [item for key, value in law.items() if key != "name" for item in (option(key), str(value))]
    from_file = report_json(capsys, "--config", str(path), "--alpha", "60", "--no-simulate")
    assert from_file["law"]["name"] == law["name"]
    assert without_sources(from_file) == without_sources(report_json(capsys, *typed, "--alpha", "60", "--no-simulate"))
