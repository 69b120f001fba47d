"""Every public answer stays as it is: recorded answers of `report`, `traps`, `map` and `sweep`, replayed.

A restructuring of the package (docs/architecture.md) must not change what a user
reads. `data/answers.json.gz` holds the JSON the commands printed (or their exit
status and error line) for:

* `report` on 240 seeded command lines: every law (power, grid, khatib, gnron,
  velocity, velocity-gated, fuzzy), every robot family (steering, kinematic,
  holonomic), both holds and compute delays, walls, corridors and doors,
  subsets of models and Padé orders, random values over wide ranges (`report_cases`);
* `traps` on the four shipped scenes at two resolutions;
* `map` on the three shipped maps, at CARMEL's preset and at a small robot
  (W = 0.3 m, V = 0.5 m/s);
* a 500-point Latin-hypercube `sweep` over V, T, k and L (every model), its table.

Recorded with ``python tests/test_answers_unchanged.py --record``. Replayed here
and compared value by value: strings, booleans, nulls and structure exactly;
numbers to 1e-11 relative (with an absolute floor of 1e-12 in the quantity's SI
unit, for values that are zero up to rounding, e.g. a growth rate at the
boundary). That is far below the 4 significant digits a report prints and above
the differences between CPUs and BLAS builds: at most 2.3e-12 relative on the loop
models' answers (tests/test_c_zero_reference.py) and 1.7e-12 on these (a law
parameter's critical value found by bisection on NV*, and a remedy's percentage
from it, between OpenBLAS's Haswell and SkylakeX kernels). On the machine that
recorded them the answers are checked at 1e-12 with ``ANSWERS_RTOL=1e-12``. A map is compared to
its method's accuracy instead: an equilibrium where F_n jumps at a cell boundary
is located to the bracket / 2^12, about 10 µm (`maps.deciding.equilibria.NEWTON_STEPS`),
and where round-off flips F_n's sign near the jump the offset moves by up to that
(measured: 4e-7 m between numpy's AVX2 and AVX-512 kernels), so offsets compare
to 1e-5 m and everything else of a map to 1e-9 relative (the gains evaluated at
the moved offset: 1e-11 measured). Wall-clock timings and temporary paths are not
answers and are left out.
"""

from __future__ import annotations

import argparse
import contextlib
import gzip
import io
import json
import math
import os
import random
from pathlib import Path

import pytest

from map_helpers import shared_map_analyses
from pfm_stability.cli import main

DATA = Path(__file__).parent / "data" / "answers.json.gz"
VOLATILE = {"timing", "seconds", "out", "plot", "outputs"}
"""Keys whose values are not answers (wall-clock times, paths of this run)."""
RTOL = float(os.environ.get("ANSWERS_RTOL", "1e-11"))
ATOL = 1e-12
MAP_RTOL = 1e-9
MAP_ABSOLUTE = {"offset": 1e-5}
"""A map's tolerances (module docstring): relative, and absolute per key (m)."""

LAWS = ("power", "grid", "khatib", "gnron", "velocity", "velocity-gated", "fuzzy")


def _log_uniform(rng: random.Random, low: float, high: float) -> float:
    return math.exp(rng.uniform(math.log(low), math.log(high)))


def _number(x: float) -> str:
    return repr(float(f"{x:.6g}"))


def _law_options(rng: random.Random, law: str) -> list[str]:
    if law == "power":
        return ["--f", _number(_log_uniform(rng, 0.2, 5)), "--n", _number(rng.uniform(1, 3))]
    if law == "grid":
        options = ["--f", _number(_log_uniform(rng, 0.3, 3))]
        if rng.random() < 0.3:
            options += ["--window-cells", str(rng.choice([21, 33, 45])), "--cell-size", _number(rng.choice([0.05, 0.1]))]
        return options
    if law in ("khatib", "gnron"):
        options = ["--eta", _number(_log_uniform(rng, 0.02, 1)), "--rho0", _number(rng.uniform(0.5, 2)),
                   "--goal-distance", _number(rng.uniform(0.5, 5))]
        if law == "gnron":
            options += ["--goal-exponent", _number(rng.uniform(0.5, 3)), "--attraction-exponent", _number(rng.uniform(1, 3))]
        return options
    if law == "velocity":
        return ["--alpha-p", _number(_log_uniform(rng, 0.1, 2)), "--alpha-v", _number(_log_uniform(rng, 0.01, 1)),
                "--rho0", _number(rng.uniform(0.5, 2))]
    if law == "velocity-gated":
        return ["--a-max", _number(rng.uniform(0.5, 3)), "--variant", rng.choice(["gradient", "squared"]),
                "--rho0", _number(rng.uniform(0.5, 2)), "--no-simulate"]
    return ["--side", rng.choice(["left", "right"]), "--symmetrize", rng.choice(["none", "negative", "positive"])]


def report_cases(count: int = 240, seed: int = 20261126) -> list[list[str]]:
    """Seeded `report` command lines (module docstring)."""
    rng = random.Random(seed)
    cases = []
    for i in range(count):
        law = LAWS[i % len(LAWS)]
        robot = "steering"
        if law in ("velocity", "velocity-gated") and rng.random() < 0.4:
            robot = "holonomic"
        elif law in ("power", "khatib", "velocity") and rng.random() < 0.15:
            robot = "kinematic"
        W = rng.uniform(0.2, 1.0)
        argv = ["report", "--law", law, "--V", _number(_log_uniform(rng, 0.1, 2)), "--T", _number(_log_uniform(rng, 0.01, 0.3)),
                "--k", _number(_log_uniform(rng, 0.5, 10)), "--W", _number(W),
                "--hold", rng.choice(["command", "reference"]), "--compute-delay", str(rng.choice([0, 1]))]
        if robot != "steering":
            argv += ["--robot", robot]
        if robot == "steering":
            argv += ["--tau", _number(0.0 if rng.random() < 0.05 else _log_uniform(rng, 0.05, 1))]
        argv += _law_options(rng, law)
        geometry = rng.random()
        if geometry < 0.4 or law == "fuzzy":
            argv += ["--alpha", _number(rng.uniform(5, 80))]
        if geometry > 0.3:
            argv += ["--L", _number(W / 2 * rng.uniform(1.3, 4))]
        if law == "power" and rng.random() < 0.2:
            argv += ["--door", _number(W * rng.uniform(1.1, 4))]
        if rng.random() < 0.25:
            for model in rng.sample(["continuous", "kb_first_order", "pade", "exact_delay", "sampled"], rng.randint(1, 3)):
                argv += ["--model", model]
        if rng.random() < 0.2:
            argv += ["--pade-order", str(rng.randint(1, 8))]
        cases.append(argv + ["--format", "json"])
    return cases


def other_cases() -> list[list[str]]:
    """`traps` and `map` command lines."""
    cases = []
    for scene in ("gc2000_fig3", "gc2000_fig4", "gc2000_sec6b_khatib", "gc2000_sec6b_gnron"):
        for resolution in ([], ["--resolution", "120"]):
            cases.append(["traps", scene, *resolution, "--format", "json"])
    for name in ("depot", "warehouse", "tb3_sandbox"):
        cases.append(["map", name, "--quiet", "--format", "json"])
        cases.append(["map", name, "--W", "0.3", "--V", "0.5", "--quiet", "--format", "json"])
    return cases


SWEEP_SPEC = """preset: carmel
scenario: {corridor: {L: 0.9}}
sample:
  method: latin-hypercube
  n: 500
  seed: 11
  ranges: {V: [0.1, 2.0], T: [0.005, 0.3], k: [0.3, 10.0], L: [0.45, 2.5]}
"""


def run(argv) -> dict:
    """The command's answer: exit status, its JSON (or None) and its error line."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    text = out.getvalue()
    return {"code": code, "json": _strip(json.loads(text)) if code == 0 and text else None,
            "error": err.getvalue().strip().splitlines()[-1] if code != 0 and err.getvalue().strip() else None}


def sweep_answer(tmp: Path) -> dict:
    """The sweep's table as columns (point order)."""
    from table_helpers import read

    spec = tmp / "spec.yaml"
    spec.write_text(SWEEP_SPEC)
    answer = run(["sweep", str(spec), "--out", str(tmp / "sweep.parquet"), "--workers", "1", "--quiet", "--format", "json"])
    assert answer["code"] == 0, answer
    table = read(tmp / "sweep.parquet")
    return {name: table.column(name).to_pylist() for name in table.column_names}


def _strip(value):
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def differences(now, then, where="", found=None, rtol=RTOL, absolute=None) -> list[str]:
    """Where `now` differs from `then` beyond the tolerances: `rtol` relative, `ATOL` absolute, or `absolute[key]`."""
    found = [] if found is None else found
    absolute = absolute or {}
    if len(found) > 20:
        return found
    if isinstance(then, bool) or then is None or isinstance(then, str):
        if now != then:
            found.append(f"{where}: {now!r} != {then!r}")
    elif isinstance(then, (int, float)):
        if isinstance(now, bool) or not isinstance(now, (int, float)):
            found.append(f"{where}: {now!r} is not a number like {then!r}")
        elif not (now == then or (math.isnan(now) and math.isnan(then))
                  or abs(now - then) <= max(rtol * max(abs(now), abs(then)), absolute.get(where.rsplit(".", 1)[-1], ATOL))):
            found.append(f"{where}: {now!r} != {then!r}")
    elif isinstance(then, list):
        if not isinstance(now, list) or len(now) != len(then):
            found.append(f"{where}: a list of {len(now) if isinstance(now, list) else type(now).__name__} items, was {len(then)}")
        else:
            for i, (a, b) in enumerate(zip(now, then)):
                differences(a, b, f"{where}[{i}]", found, rtol, absolute)
    elif isinstance(then, dict):
        if not isinstance(now, dict) or not set(then) <= set(now):  # new keys are new answers, not changed ones
            keys = set(now) if isinstance(now, dict) else set()
            found.append(f"{where}: keys {sorted(set(then) - keys)} missing")
        else:
            for key in then:
                differences(now[key], then[key], f"{where}.{key}", found, rtol, absolute)
    return found


def record(path: Path) -> None:
    import tempfile

    answers = {" ".join(argv): run(argv) for argv in report_cases() + other_cases()}
    with tempfile.TemporaryDirectory() as tmp:
        answers["sweep"] = sweep_answer(Path(tmp))
    path.parent.mkdir(exist_ok=True)
    with gzip.open(path, "wt", encoding="utf-8") as fh:
        json.dump(answers, fh)
    codes = [a["code"] for k, a in answers.items() if k != "sweep"]
    print(f"{len(answers)} answers; exit 0: {codes.count(0)}, exit 2: {codes.count(2)}")


@pytest.fixture(scope="module")
def recorded():
    with gzip.open(DATA, "rt", encoding="utf-8") as fh:
        return json.load(fh)


def _chunks(cases, size):
    return [cases[i:i + size] for i in range(0, len(cases), size)]


@pytest.mark.parametrize("argvs", _chunks(report_cases(), 20), ids=lambda argvs: f"report-{report_cases().index(argvs[0])}")
def test_report_answers_are_unchanged(recorded, argvs):
    """Twenty recorded `report` command lines per test, every value as recorded (module docstring)."""
    for argv in argvs:
        found = differences(run(argv), recorded[" ".join(argv)])
        assert not found, f"{' '.join(argv)}:\n" + "\n".join(found)


DEPOT_AT_CARMEL = ["map", "depot", "--quiet", "--format", "json"]
"""The map line whose analysis other tests read too (tests/map_helpers.py): their tests share an xdist group."""


def _other_case(argv):
    marks = [pytest.mark.xdist_group("map_depot_carmel")] if argv == DEPOT_AT_CARMEL else []
    return pytest.param(argv, marks=marks, id="-".join(argv[:2] + argv[2:4]))


@pytest.mark.parametrize("argv", [_other_case(argv) for argv in other_cases()])
def test_traps_and_map_answers_are_unchanged(recorded, argv):
    """Each recorded `traps` and `map` command line, a map to its method's accuracy (module docstring). A map's
    analysis is computed once per process for this test and others that read the same map with the same options
    (tests/map_helpers.py)."""
    tolerances = {"rtol": MAP_RTOL, "absolute": MAP_ABSOLUTE} if argv[0] == "map" else {}
    with shared_map_analyses():
        now = run(argv)
    then = recorded[" ".join(argv)]
    if argv[0] == "map" and then["code"] == 2 and "has no route long enough" in (then["error"] or "") and now["code"] == 0:
        # a map refused for want of a straight corridor now has routes of any shape (docs/maps.md, "Verdicts along
        # every route"): a new answer where there was none; no segment verdict can have flipped, there are none
        assert now["json"]["segments"] == [] and now["json"]["paths"]["summary"]["route_length_m"] > 0
        return
    found = differences(now, then, **tolerances)
    assert not found, "\n".join(found)


def test_sweep_table_is_unchanged(recorded, tmp_path):
    found = differences(sweep_answer(tmp_path), recorded["sweep"])
    assert not found, "\n".join(found)


def test_the_record_covers_what_it_claims(recorded):
    """Most recorded reports ran (an error answer is an answer, but the record must exercise the analyses): every law
    and family appears with exit 0, and walls, corridors and doors."""
    ran = [argv for argv in report_cases() if recorded[" ".join(argv)]["code"] == 0]
    assert len(ran) >= 0.8 * len(report_cases())
    for law in LAWS:
        assert any(law == argv[argv.index("--law") + 1] for argv in ran), law
    for option in ("--alpha", "--L", "--door", "--robot"):
        assert any(option in argv for argv in ran), option
    assert any("holonomic" in argv for argv in ran) and any("kinematic" in argv for argv in ran)


if __name__ == "__main__":
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    parser = argparse.ArgumentParser(description="Record the answers (see the module docstring).")
    parser.add_argument("--record", type=Path, default=DATA)
    record(parser.parse_args().record)
