"""``pfm-stability sweep`` (cli/sweep.py): summaries, JSON against the schema, plots, and exit statuses.

Bad input exits 2 with one line naming the field, and writes nothing; a chunk
that keeps failing exits 1 naming it. The summary's numbers are recomputed
from the written table (an independent count), not trusted.
"""

from __future__ import annotations

import json
import os

import numpy as np
import pyarrow.parquet as pq
import pytest
from jsonschema import Draft202012Validator
from table_helpers import read, same

from pfm_stability.cli import main
from pfm_stability.io.schema import load_schema

VALIDATOR = Draft202012Validator(load_schema())

GRID_SPEC = """\
preset: carmel
scenario: {corridor: {L: 0.9}}
models: [sampled, exact_delay, kb_first_order]
hold: command
compute_delay: 1
grid:
  V: {from: 0.2, to: 1.6, num: 12}
  T: {from: 0.005, to: 0.2, num: 10, scale: log}
"""


def write(tmp_path, text, name="spec.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def run(capsys, argv):
    code = main(["sweep", *argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_json_summary_validates_and_matches_the_table(tmp_path, capsys):
    """JSON summary: valid against the schema, wall-clock only under timing, fractions equal to counts in the Parquet file."""
    out = tmp_path / "t.parquet"
    code, stdout, err = run(capsys, [write(tmp_path, GRID_SPEC), "--out", str(out), "--format", "json", "--quiet"])
    assert code == 0, err
    data = json.loads(stdout)
    assert [f"{e.message}" for e in VALIDATOR.iter_errors(data)] == []
    assert data["command"] == "sweep" and data["points"] == 120 and set(data["timing"]) == {"seconds", "rate"}
    table = pq.read_table(out)
    for model in ("sampled", "exact_delay", "kb_first_order"):
        verdicts = np.array(table.column(f"{model}_verdict").to_pylist())
        assert data["stable_fraction"][model] == pytest.approx(np.mean(verdicts == "stable"), abs=1e-15)
    a, b = (np.array(table.column(f"{m}_verdict").to_pylist()) for m in ("sampled", "kb_first_order"))
    assert data["agreement"]["sampled"]["kb_first_order"] == pytest.approx(np.mean(a == b), abs=1e-15)
    assert 0 < data["stable_fraction"]["sampled"] < data["stable_fraction"]["exact_delay"] < 1  # the sampled loop is the least stable


def test_text_summary_and_plots(tmp_path, capsys):
    """Text summary names the points, rate, models and output; --plot writes a map (2 varying) or an agreement matrix (1)."""
    png = tmp_path / "map.png"
    code, stdout, err = run(capsys, [write(tmp_path, GRID_SPEC), "--out", str(tmp_path / "t.parquet"), "--plot", str(png)])
    assert code == 0, err
    assert "120 points" in stdout and "points/s" in stdout and "agreement of the verdicts" in stdout and f"plot: {png}" in stdout
    one = GRID_SPEC.replace("  T: {from: 0.005, to: 0.2, num: 10, scale: log}\n", "")
    matrix = tmp_path / "agreement.png"
    code, _, err = run(capsys, [write(tmp_path, one, "one.yaml"), "--out", str(tmp_path / "one.csv"), "--plot", str(matrix), "--quiet"])
    assert code == 0, err
    from PIL import Image

    for path in (png, matrix):
        with Image.open(path) as image:
            assert image.size[0] > 300 and image.size[1] > 250 and np.unique(np.asarray(image.convert("L"))).size > 10


@pytest.mark.parametrize(
    "spec_text, argv, words",
    [
        (GRID_SPEC + "colour: red\n", [], "unknown key colour"),
        (GRID_SPEC.replace("num: 12", "num: 0"), [], "grid.V.num"),
        (GRID_SPEC.replace("[sampled, exact_delay, kb_first_order]", "[sampled, magic]"), [], "magic"),
        (GRID_SPEC, ["--scheduler", "localhost:8786"], "scheduler must be an address tcp://HOST:PORT"),
        (GRID_SPEC, ["--workers", "0"], "workers must be an integer in [1, 4096]"),
        (GRID_SPEC, ["--out", "/nonexistent-dir/t.parquet"], "out must be a writable file path"),
        (GRID_SPEC, ["--out", "t.txt"], "out must be a writable file path ending in .parquet"),
        ("grid: [1, 2\n", [], "not valid YAML"),
    ],
    ids=["unknown key", "num 0", "unknown model", "scheduler address", "workers", "unwritable out", "out suffix", "bad yaml"],
)
def test_bad_input_exits_2_before_any_work(tmp_path, capsys, spec_text, argv, words):
    """One line `pfm-stability: error: ...` naming the field, exit 2, and no file written."""
    spec = write(tmp_path, spec_text)
    before = set(os.listdir(tmp_path))
    if "--out" not in argv:
        argv = [*argv, "--out", str(tmp_path / "t.parquet")]
    code, stdout, err = run(capsys, [spec, *argv, "--quiet"])
    assert code == 2 and stdout == "" and err.startswith("pfm-stability: error:") and words in err and err.count("\n") == 1
    assert set(os.listdir(tmp_path)) == before


def test_unreachable_scheduler_exits_2_naming_it(tmp_path, capsys, monkeypatch):
    """Nothing listens on the port: exit 2 naming the address, within the connection timeout (1 s here), nothing written."""
    from pfm_stability.sweeps import engine

    monkeypatch.setattr(engine, "CONNECT_TIMEOUT", 1.0)
    before = set(os.listdir(tmp_path))
    code, _, err = run(capsys, [write(tmp_path, GRID_SPEC), "--out", str(tmp_path / "t.parquet"), "--scheduler", "tcp://127.0.0.1:9", "--quiet"])
    assert code == 2 and "cannot connect to tcp://127.0.0.1:9" in err and err.count("\n") == 1
    assert set(os.listdir(tmp_path)) == before | {"spec.yaml"}


def test_resume_of_another_spec_exits_2_and_failed_chunk_exits_1(tmp_path, capsys, monkeypatch):
    """--resume over another spec's chunks: exit 2 explaining; a chunk failing every retry: exit 1 naming it, parts kept."""
    from pfm_stability.sweeps import engine

    real = engine.evaluate_chunk

    def broken(spec, start, stop, sample=None):
        if start == 50:
            raise RuntimeError("boom")
        return real(spec, start, stop, sample)

    monkeypatch.setattr(engine, "evaluate_chunk", broken)
    out = str(tmp_path / "t.parquet")
    code, _, err = run(capsys, [write(tmp_path, GRID_SPEC), "--out", out, "--chunk-size", "50", "--quiet"])
    assert code == 1 and "chunk 1 (points 50-99) failed after 2 retries: RuntimeError: boom" in err
    assert sorted(os.listdir(out + ".parts")) == ["chunk-00000.parquet", "chunk-00002.parquet", "manifest.json"]
    other = write(tmp_path, GRID_SPEC.replace("num: 12", "num: 13"), "other.yaml")
    code, _, err = run(capsys, [other, "--out", out, "--resume", "--quiet"])
    assert code == 2 and "different sweep" in err
    monkeypatch.setattr(engine, "evaluate_chunk", real)
    code, stdout, err = run(capsys, [str(tmp_path / "spec.yaml"), "--out", out, "--resume", "--quiet"])
    assert code == 0 and "2 reused from an interrupted run" in stdout and pq.read_table(out).num_rows == 120


def test_config_option_replaces_the_specs_preset(tmp_path, capsys):
    """``sweep --config FILE``: the robot comes from the file, not from the spec's ``preset`` (the command line wins).

    The file changes k and the hold; the table's k column and the sampled verdicts must
    then equal a spec that names the same values through ``config:`` (an independent
    route through the spec parser), and differ from the preset's run.
    """
    config = tmp_path / "robot.yaml"
    config.write_text("robot: {k: 3.5}\ncontroller: {hold: reference, compute_delay: 0}\n")
    spec = write(tmp_path, GRID_SPEC.replace("hold: command\ncompute_delay: 1\n", ""))
    tables = {}
    for name, argv in (("option", [spec, "--config", str(config)]), ("preset", [spec]),
                       ("spec", [write(tmp_path, GRID_SPEC.replace("preset: carmel", f"config: {config}")
                                       .replace("hold: command\ncompute_delay: 1\n", ""), "viaspec.yaml")])):
        out = tmp_path / f"{name}.parquet"
        code, _, err = run(capsys, [*argv, "--out", str(out), "--quiet"])
        assert code == 0, err
        tables[name] = pq.read_table(out).to_pydict()
    assert set(tables["option"]["k"]) == {3.5} and set(tables["preset"]["k"]) == {2.0}
    assert tables["option"]["sampled_verdict"] == tables["spec"]["sampled_verdict"]
    assert tables["option"]["sampled_verdict"] != tables["preset"]["sampled_verdict"]
    code, _, err = run(capsys, [spec, "--config", str(tmp_path / "missing.yaml"), "--out", str(tmp_path / "m.parquet"), "--quiet"])
    assert code == 2 and "config" in err and not (tmp_path / "m.parquet").exists()


SIM_SPEC = """\
preset: carmel
scenario: {wall: {alpha: 40}}
models: [sampled]
simulate: true
sample: {method: latin-hypercube, n: 60, seed: 3, ranges: {V: [0.3, 1.5], T: [0.02, 0.15]}}
"""


def _interrupt_when(argv, parts, count, signal_number):
    """Run `argv` in a session of its own; once `parts` holds `count` finished parts, signal its process group.
    Returns (exit status, stderr, finished parts then)."""
    import subprocess
    import sys
    import time

    # SIGINT back to its default before exec (a background job may inherit it ignored); its own session: a process group
    launch = "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.executable, sys.argv[1:])"
    process = subprocess.Popen([sys.executable, "-c", launch, *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)

    def finished():
        return sum(name.endswith(".parquet") for name in os.listdir(parts)) if os.path.isdir(parts) else 0

    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None and finished() < count:
        time.sleep(0.005)
    assert process.poll() is None, "the sweep ended before it could be interrupted"
    os.killpg(process.pid, signal_number)
    _, err = process.communicate(timeout=60)
    return process.returncode, err, finished()


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
def test_a_really_interrupted_simulation_sweep_resumes_to_the_same_table(tmp_path):
    """The command in a process of its own, interrupted twice by a signal to its whole process group: SIGINT once 2
    parts are written (as Ctrl-C in a terminal: exit 130 and the --resume hint), then, resumed, SIGKILL once 2 more
    are (a crash, ``kill -9``). The last ``--resume`` reuses exactly the parts written, and the table equals the
    uninterrupted in-process evaluation (pyarrow equality: the same floats, no tolerance)."""
    import signal
    import subprocess
    import sys

    from pfm_stability.sweeps import evaluate_chunk, load_spec
    from pfm_stability.sweeps.engine import plan_chunks
    from pfm_stability.sweeps.points import sample_points
    from pfm_stability.sweeps.table import to_arrow

    spec, out = write(tmp_path, SIM_SPEC), tmp_path / "t.parquet"
    parts = f"{out}.parts"
    argv = [sys.executable, "-m", "pfm_stability", "sweep", spec, "--out", str(out), "--workers", "1", "--chunk-size", "6", "--quiet"]
    code, err, first = _interrupt_when(argv, parts, 2, signal.SIGINT)
    assert code == 130 and "rerun with --resume" in err and first >= 2 and not out.exists(), err
    code, err, second = _interrupt_when([*argv, "--resume"], parts, first + 2, signal.SIGKILL)
    assert code == -signal.SIGKILL and second >= first + 2 and not out.exists(), err
    resumed = subprocess.run([*argv, "--resume", "--format", "json"], capture_output=True, text=True, timeout=300, check=False)
    assert resumed.returncode == 0, resumed.stderr
    summary = json.loads(resumed.stdout)
    chunks = len(plan_chunks(60, 6, fine_tail=True))
    assert summary["chunks"] == chunks and summary["reused_chunks"] == second < chunks
    s = load_spec(spec)
    assert same(read(out), to_arrow(evaluate_chunk(s, 0, 60, sample_points(s))))
