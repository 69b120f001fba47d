"""The JSON output of every command against the shipped schema (`pfm_stability/schema/output.schema.json`).

Every ``--format json`` output carries ``schema_version`` and ``command``,
parses as strict JSON (NaN and Infinity tokens rejected), validates against
the schema, writes an infinite number as "inf"/"-inf" and an undefined one as
null, and is byte-identical from run to run once ``timing`` is dropped.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import math
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator

from pfm_stability.cli import main
from pfm_stability.io.schema import SCHEMA_FILE, load_schema
from pfm_stability.io.serialize import SCHEMA_VERSION

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = load_schema()
VALIDATOR = Draft202012Validator(SCHEMA)

COMMANDS = {
    "report wall and corridor": ["report", "--alpha", "20", "--L", "0.9"],
    "report corridor, T = 0": ["report", "--L", "5", "--T", "0"],
    "report wall, stable": ["report", "--alpha", "80", "--model", "sampled", "--model", "pade"],
    "report goal-aware law, three wall equilibria": ["report", "--law", "gnron", "--goal-distance", "0.02", "--goal-exponent", "0.5",
                                                     "--eta", "1", "--alpha", "60", "--L", "0.6", "--model", "sampled"],
    "report grid law": ["report", "--law", "grid", "--alpha", "30", "--L", "1", "--model", "kb_first_order"],
    "simulate grid collision": ["simulate", "--scenario", "kb-fig6-narrow", "--duration", "8"],
    "simulate analytic wall, trajectory": ["simulate", "--scenario", "wall", "--env", "analytic", "--law", "grid", "--duration", "2", "--trajectory"],
    "simulate point target": ["simulate", "--scenario", "straight", "--duration", "2", "--speed-law", "--seed", "3", "--jitter", "0.01"],
    "validate analytic corridor": ["validate", "--scenario", "corridor", "--env", "analytic", "--rtol", "0.1", "--members", "3"],
    "validate grid wall in V": ["validate", "--scenario", "wall", "--parameter", "V", "--env", "grid", "--rtol", "0.2", "--members", "3",
                                "--duration", "10"],
}


def run_json(argv) -> tuple[str, dict]:
    """stdout of ``main(argv + --format json)`` and its strict parse."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([*argv, "--format", "json", *(["--quiet"] if argv[0] in ("simulate", "validate") else [])])
    assert code == 0, err.getvalue()
    return out.getvalue(), strict_loads(out.getvalue())


@functools.lru_cache(maxsize=1)
def _report_text() -> str:
    return run_json(COMMANDS["report wall and corridor"])[0]


def strict_loads(text: str):
    """json.loads that rejects NaN, Infinity and -Infinity."""

    def reject(token):
        raise ValueError(f"non-standard JSON token {token}")

    return json.loads(text, parse_constant=reject)


def schema_errors(data) -> list[str]:
    return [f"{list(e.absolute_path)}: {e.message[:300]}" for e in sorted(VALIDATOR.iter_errors(data), key=lambda e: list(e.absolute_path))]


def without_timing(data) -> dict:
    return {k: v for k, v in data.items() if k != "timing"}


def test_schema_is_a_valid_draft_2020_12_schema_of_this_version():
    Draft202012Validator.check_schema(SCHEMA)
    assert SCHEMA["properties"]["schema_version"]["const"] == SCHEMA_VERSION
    assert SCHEMA["properties"]["command"]["enum"][:4] == ["report", "simulate", "validate", "traps"]
    assert "sweep" in SCHEMA["properties"]["command"]["enum"]


def test_schema_ships_as_package_data():
    """`pip install .` takes the schema along: pyproject lists it as package data of pfm_stability.io.schema."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    data = config["tool"]["setuptools"]["package-data"]["pfm_stability.io.schema"]
    assert any(Path(SCHEMA_FILE).match(pattern) for pattern in data)
    assert (ROOT / "pfm_stability" / "io" / "schema" / SCHEMA_FILE).is_file() and (ROOT / "pfm_stability" / "io" / "schema" / "__init__.py").is_file()


def _keys_outside_timing(o):
    if isinstance(o, dict):
        for k, v in o.items():
            if k != "timing":
                yield k
                yield from _keys_outside_timing(v)
    elif isinstance(o, list):
        for v in o:
            yield from _keys_outside_timing(v)


@pytest.mark.parametrize("argv", list(COMMANDS.values()), ids=list(COMMANDS))
def test_every_command_output_validates(argv):
    """Strict JSON, valid against the schema, with wall-clock values (seconds, rate) under `timing` only."""
    _, data = run_json(argv)
    assert data["schema_version"] == SCHEMA_VERSION and data["command"] == argv[0]
    assert schema_errors(data) == []
    assert not {"seconds", "rate", "sweep_seconds"} & set(_keys_outside_timing(data))
    if argv[0] != "report":
        assert "seconds" in data["timing"]


def test_validate_with_sweep_and_stability_map_validates(tmp_path):
    """The optional parts: a sweep, and the stability map behind --plot."""
    png = tmp_path / "v.png"
    _, data = run_json(["validate", "--scenario", "wall", "--env", "analytic", "--rtol", "0.2", "--members", "3", "--duration", "4",
                        "--plot", str(png), "--sweep", "8"])
    assert schema_errors(data) == []
    assert data["sweep"]["count"] == 8 and len(data["stability_map"]["points"]) == 63
    assert set(data["timing"]) == {"seconds", "sweep_seconds"} and "timing" not in data["sweep"] and "seconds" not in data["sweep"]


@pytest.mark.parametrize(
    "mutate",
    [
        lambda d: d.update(command="simulate"),
        lambda d: d.pop("schema_version"),
        lambda d: d.update(schema_version="0.9"),
        lambda d: d.update(extra=1),
        lambda d: d["corridor"]["sampled"].update(NV_critical="Infinity"),
        lambda d: d["corridor"]["sampled"].update(stable="yes"),
        lambda d: d["kb_error"].update(direction=None),
        lambda d: d["corridor"]["sampled"]["stable_side"].update(L_critical="sideways"),
        lambda d: d["wall"]["sampled"].pop("stable_side"),
    ],
    ids=["wrong command", "no version", "other version", "unknown key", "infinity spelled otherwise", "bool as text", "null direction",
         "a side that is no side", "no stable side"],
)
def test_schema_rejects_what_it_should(mutate):
    data = strict_loads(_report_text())
    assert schema_errors(data) == []
    mutate(data)
    assert schema_errors(data)


@pytest.mark.parametrize("argv", [COMMANDS["report wall and corridor"], COMMANDS["simulate grid collision"], COMMANDS["validate analytic corridor"]],
                         ids=["report", "simulate", "validate"])
def test_output_is_byte_identical_without_timing(argv):
    """Two runs give the same bytes once the wall-clock `timing` is dropped (the only key that may differ)."""
    first, second = (without_timing(run_json(argv)[1]) for _ in range(2))
    dump = lambda d: json.dumps(d, indent=2, allow_nan=False)
    assert dump(first) == dump(second)


def test_simulate_output_is_identical_across_processes():
    """Also across fresh processes with different hash seeds (no set or dict-order dependence)."""
    argv = [sys.executable, "-m", "pfm_stability", "simulate", "--scenario", "corridor", "--duration", "3", "--format", "json", "--quiet"]
    outs = []
    for seed in ("1", "2"):
        done = subprocess.run(argv, capture_output=True, text=True, env={**os.environ, "PYTHONHASHSEED": seed}, check=True)
        outs.append(json.dumps(without_timing(strict_loads(done.stdout)), indent=2))
    assert outs[0] == outs[1]


# ---------------------------------------------------- infinite vs undefined in the to_dict methods
def test_model_prediction_infinite_and_undefined():
    from pfm_stability.validation.predict import ModelPrediction, Prediction

    p = ModelPrediction("sampled", "power law", 1.0, math.inf, "stable", -0.5, math.nan, -math.inf)
    d = p.to_dict()
    assert (d["NV_critical"], d["angular_frequency"], d["critical"]) == ("inf", None, "-inf")
    whole = Prediction("wall", 30.0, "alpha_critical (deg)", p, p).to_dict()
    strict_loads(json.dumps(whole, allow_nan=False))


def test_run_result_measures_from_minus_infinity_and_timing_of_a_batch():
    from pfm_stability.sim.api import simulate_batch

    batch = simulate_batch("corridor", env="analytic", L=[0.8, 1.0], duration=1.0)
    d = batch.to_dict()
    assert d["members"][0]["inputs"]["measure"]["along_from"] == "-inf"
    assert set(d["timing"]) == {"seconds", "rate"} and "seconds" not in d
    strict_loads(json.dumps(d, allow_nan=False))


def test_boundary_validation_relative_error_of_an_infinite_prediction():
    from pfm_stability.validation.boundary import BoundaryValidation, OscillationCheck, SimulatedPoint

    predicted = {"continuous": math.inf, "kb_first_order": 0.0, "pade": 1.1, "exact_delay": math.nan, "sampled": 1.0}
    relative = {"continuous": None, "kb_first_order": -1.0, "pade": 0.1, "exact_delay": None, "sampled": 0.0}
    v = BoundaryValidation(
        scenario="corridor", env="analytic", parameter="L", unit="m", simulated_boundary=1.0, bracket=(0.99, 1.01), stable_above=True,
        predicted_boundary=predicted, relative_error=relative, law="power law", lumped_predicted_boundary=None, lumped_relative_error=None,
        oscillation=(OscillationCheck(1.0, None, math.nan, "none", -0.1, 2.0, None, None),),
        points=(SimulatedPoint(1.0, "stable", "metrics", None),), stability_map=None, inputs={"L": None, "duration": 20.0},
        notes={}, runs=3, seconds=1.5,
    )
    d = v.to_dict()
    assert d["predicted_boundary"]["continuous"] == "inf" and d["relative_error"]["continuous"] == "inf"
    assert d["predicted_boundary"]["exact_delay"] is None and d["relative_error"]["exact_delay"] is None
    assert d["oscillation"][0]["angular_frequency"] is None and d["timing"] == {"seconds": 1.5} and "seconds" not in d
    strict_loads(json.dumps(d, allow_nan=False))


def test_sweep_with_nothing_included_has_undefined_agreement():
    from pfm_stability.validation.sweep import SweepResult

    s = SweepResult(count=8, seed=0, env="analytic", exclude=0.03, included=0, agreement=math.nan, disagreements=(),
                    wrong_verdict_rate={"sampled": math.nan}, wrong_verdicts={"sampled": {"stable_but_unstable": 0, "unstable_but_stable": 0}},
                    points=(), ranges={"V": (0.3, 1.5)}, seconds=2.0)
    d = s.to_dict()
    assert d["agreement"] is None and d["wrong_verdict_rate"] == {"sampled": None} and d["timing"] == {"seconds": 2.0}
    strict_loads(json.dumps(d, allow_nan=False))


def test_no_direction_without_a_value():
    """kb_error.direction is left out when KB's criterion and the sampled loop agree (relative error 0)."""
    _, data = run_json(COMMANDS["report corridor, T = 0"])
    assert data["kb_error"]["relative"] == 0.0 and "direction" not in data["kb_error"]
