"""What every subcommand shares: one range table in the units typed, output paths checked before any
work, progress on stderr (tqdm on a terminal), and a start-up that imports nothing heavy."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from pfm_stability.checks import check_output_path
from pfm_stability.cli import main

OUTPUT_OPTIONS = [
    (["plot", "force-law"], "--out", "out"),
    (["simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "1"], "--plot", "plot"),
    (["validate", "--scenario", "corridor", "--env", "analytic", "--quiet"], "--plot", "plot"),
    (["validate", "--scenario", "corridor", "--env", "analytic", "--quiet", "--sweep", "8"], "--sweep-plot", "sweep-plot"),
]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def no_work(monkeypatch):
    """Make every expensive step fail loudly: a bad path must stop the command before any of them."""

    def forbidden(*args, **kwargs):
        raise AssertionError("work started before the output path was checked")

    import pfm_stability.cli.plot
    import pfm_stability.sim.api
    import pfm_stability.validation

    monkeypatch.setattr(pfm_stability.cli.plot, "_draw", forbidden)
    monkeypatch.setattr(pfm_stability.sim.api, "simulate", forbidden)
    monkeypatch.setattr(pfm_stability.validation, "validate_boundary", forbidden)
    monkeypatch.setattr(pfm_stability.validation, "verdict_sweep", forbidden)


@pytest.mark.parametrize("argv,option,name", OUTPUT_OPTIONS, ids=[f"{a[0]} {o}" for a, o, _ in OUTPUT_OPTIONS])
@pytest.mark.parametrize(
    "kind,why",
    [
        ("directory", "an existing directory"),
        ("empty", "empty"),
        ("no_suffix", "the file name must end in .png"),
        ("missing_dir", "does not exist"),
        ("only_suffix", "no file name before .png"),
        ("jpg", "the file name must end in .png"),
    ],
)
def test_bad_output_paths_exit_2_before_any_work(tmp_path, capsys, no_work, argv, option, name, kind, why):
    path = {
        "directory": str(tmp_path),
        "empty": "",
        "no_suffix": str(tmp_path / "figure"),
        "missing_dir": str(tmp_path / "missing" / "figure.png"),
        "only_suffix": str(tmp_path / ".png"),
        "jpg": str(tmp_path / "figure.jpg"),
    }[kind]
    before = sorted(os.listdir(tmp_path))
    code, out, err = run(capsys, *argv, option, path)
    assert code == 2 and out == ""
    assert err.startswith(f"pfm-stability: error: argument {option}: {name} must be a writable file path ending in .png; got {path!r} (")
    assert why in err and err.count("\n") == 1
    assert sorted(os.listdir(tmp_path)) == before  # nothing written (no DIR.png, no figure.png)


def test_unwritable_directory_is_found_before_the_work(tmp_path, capsys, no_work, monkeypatch):
    """The check creates a file where the output will go (root passes os.access anywhere): a directory that refuses
    it is named before any work. Simulated by a file system that refuses new files in `locked`."""
    import tempfile

    locked = str(tmp_path)
    real_mkstemp = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and os.path.abspath(dir) == locked:
            raise PermissionError(13, "Permission denied", dir)
        return real_mkstemp(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    code, _, err = run(capsys, "simulate", "--scenario", "corridor", "--plot", str(tmp_path / "x.png"))
    assert code == 2 and f"(nothing can be created in {locked}: Permission denied)" in err


def test_check_output_path_messages(tmp_path):
    assert check_output_path("plot", str(tmp_path / "a.png")) == str(tmp_path / "a.png")
    assert check_output_path("plot", str(tmp_path / "A.PNG")) == str(tmp_path / "A.PNG")
    with pytest.raises(ValueError, match=r"^out must be a writable file path ending in \.png; got '' \(empty\)$"):
        check_output_path("out", "")
    with pytest.raises(ValueError, match=r"contains a NUL character"):
        check_output_path("out", "a\0.png")
    with pytest.raises(ValueError, match=r"must be a writable file path ending in \.svg"):
        check_output_path("out", str(tmp_path / "a.png"), suffix=".svg")


def test_upper_case_suffix_writes_that_file(tmp_path, capsys):
    png = tmp_path / "TRAJECTORY.PNG"
    code, out, _ = run(capsys, "simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "1", "--plot", str(png))
    assert code == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and sorted(os.listdir(tmp_path)) == ["TRAJECTORY.PNG"]


# ----------------------------------------------------------------- ranges
@pytest.mark.parametrize(
    "argv,message",
    [
        (["validate", "--scenario", "corridor", "--parameter", "V", "--L", "0.3"], "L must be a finite number in (W/2, 10000] m = (0.4, 10000] m; got 0.3"),
        (["simulate", "--scenario", "corridor", "--L", "0.3"], "L must be a finite number in (W/2, 10000] m = (0.4, 10000] m; got 0.3"),
    ],
)
def test_one_range_per_option_in_the_units_typed(capsys, argv, message):
    """A range that depends on another value (L > W/2) is stated in the units typed, both ranges in one line.

    Every option's own range, at its ends, in every subcommand (the message, exit 2, the one line
    ``argument --X: ...``): tests/test_cli_fuzz.py::test_every_range_end_is_accepted_or_rejected_as_stated."""
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "" and err == f"pfm-stability: error: {message}\n"


def test_alpha_at_the_ends_of_its_range_is_accepted(capsys):
    """--alpha 89.999999 and 1e-6 (the stated ends) run; a refusal names a geometry, never a range in radians."""
    for argv in (
        ["report", "--alpha", "89.999999"],
        ["report", "--alpha", "1e-6"],
        ["simulate", "--scenario", "wall", "--env", "analytic", "--alpha", "1e-6", "--duration", "1", "--quiet"],
        ["validate", "--scenario", "wall", "--parameter", "V", "--env", "analytic", "--alpha", "89.999999", "--quiet"],
        ["validate", "--scenario", "wall", "--parameter", "V", "--env", "grid", "--alpha", "1e-6", "--quiet"],
    ):
        code, _, err = run(capsys, *argv)
        assert code in (0, 2) and "must be a finite number in" not in err, (argv, err)


def test_negative_numbers_in_scientific_notation_are_values(capsys):
    code, out, err = run(capsys, "simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "0.5", "--offset", "-1e-3",
                         "--format", "json", "--quiet")
    assert code == 0, err
    import json

    assert json.loads(out)["inputs"]["start"]["x"] == -1e-3


def test_options_are_not_abbreviated(capsys):
    """Options are the paper's case-sensitive symbols, so no prefix stands for an option: `--t` is not `--tau`
    (argparse's abbreviations took it silently, though the user meant T), `--l` is not `--law` (it meant L).
    Every subcommand's parser refuses prefixes; `report --t 0.1` is refused, not read as τ = 0.1."""
    from pfm_stability.cli import build_parser

    parser = build_parser()
    assert parser.allow_abbrev is False and all(sub.allow_abbrev is False for sub in parser.subcommands.values())
    for prefix in ("--t", "--l", "--compute"):
        code, _, err = run(capsys, "report", "--L", "1", prefix, "1")
        assert code == 2 and err.startswith(f"pfm-stability: error: unrecognized arguments: {prefix} 1"), err


@pytest.mark.parametrize("argv, hint", [
    (["--v", "0.5"], "; did you mean --V? (options are case-sensitive)"),
    (["--t", "0.1"], "; did you mean --T? (options are case-sensitive)"),
    (["--tua", "0.3"], "; did you mean --tau?"),
    (["--tua", "0.3", "--l", "2"], "; did you mean --tau (for --tua), --L (for --l)? (options are case-sensitive)"),
    (["--zzz", "1"], ""),
])
def test_unknown_options_name_the_option_meant(capsys, argv, hint):
    """An option that differs from a real one only in case, or is close to one, is named; nothing is guessed otherwise."""
    code, _, err = run(capsys, "report", "--L", "1", *argv)
    assert code == 2 and err.strip() == f"pfm-stability: error: unrecognized arguments: {' '.join(argv)}{hint}"


# ----------------------------------------------------------------- progress
@pytest.fixture
def terminal(monkeypatch):
    import pfm_stability.cli.progress

    monkeypatch.setattr(pfm_stability.cli.progress, "stderr_is_terminal", lambda: True)


SIMULATE = ["simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "80", "--format", "json"]
VALIDATE = ["validate", "--scenario", "wall", "--env", "analytic", "--rtol", "0.1", "--members", "3", "--format", "json"]


def test_simulate_draws_a_bar_on_a_terminal(capsys, terminal):
    code, out, err = run(capsys, *SIMULATE)
    assert code == 0 and out.lstrip().startswith("{")
    assert "simulate: 100%" in err and "sample" in err  # tqdm: 1231/1231 samples


def test_simulate_is_silent_when_quiet_or_not_on_a_terminal(capsys, terminal):
    assert run(capsys, *SIMULATE, "--quiet")[2] == ""


def test_simulate_is_silent_in_a_log(capsys):
    assert run(capsys, *SIMULATE)[2] == ""


def test_validate_writes_its_lines_above_a_status_line_on_a_terminal(capsys, terminal):
    code, out, err = run(capsys, *VALIDATE)
    assert code == 0 and out.lstrip().startswith("{")
    assert "validate: round 1: alpha in [" in err and "validate: oscillation checks: 3 runs" in err
    assert "validate: working," in err and "elapsed" in err


def test_validate_prints_plain_lines_in_a_log_and_nothing_when_quiet(capsys, terminal, monkeypatch):
    import pfm_stability.cli.progress

    assert run(capsys, *VALIDATE, "--quiet")[2] == ""
    monkeypatch.setattr(pfm_stability.cli.progress, "stderr_is_terminal", lambda: False)
    lines = run(capsys, *VALIDATE)[2].splitlines()
    assert lines[0].startswith("validate: validate wall (analytic): bisecting alpha") and all(line.startswith("validate: ") for line in lines)
    assert not any("elapsed" in line for line in lines)


def test_start_up_imports_nothing_heavy():
    """Building the parser and parsing (what every command does first, and all of ``--help``) import no numpy, PyYAML,
    tqdm, matplotlib, scipy or sympy: the law options come from the numpy-free law registry and files are read only
    when a command runs; a report does not import tqdm or matplotlib either."""
    code = (
        "import sys\n"
        "from pfm_stability.cli import build_parser, main\n"
        "for argv in (['report', '--L', '1'], ['simulate', '--scenario', 'wall', '--plot', 'x.png', '--quiet'],"
        " ['validate', '--scenario', 'wall', '--sweep', '8'], ['plot', 'rlocus', '--out', 'x.png'], ['derive'],"
        " ['map', 'depot'], ['sweep', 's.yaml', '--out', 'x.parquet']):\n"
        "    build_parser().parse_args(argv)\n"
        "heavy = ('numpy', 'yaml', 'tqdm', 'matplotlib', 'scipy', 'sympy')\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
        "main(['report', '--L', '1'])\n"
        "print(sorted(m for m in ('tqdm', 'matplotlib') if m in sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    lines = done.stdout.strip().splitlines()
    assert lines[0] == "[]" and lines[-1] == "[]", done.stdout


# ----------------------------------------------------------------- optional extras
@pytest.mark.parametrize("argv, extra, module, package", [
    (["map", "depot"], "maps", "skimage", "scikit-image"),
    (["map", "depot"], "maps", "PIL", "Pillow"),
    (["sweep", "spec.yaml", "--out", "t.parquet"], "sweep", "pyarrow", "pyarrow"),
    (["sweep", "spec.yaml", "--out", "t.parquet"], "sweep", "dask", "dask[distributed]"),
])
def test_a_command_without_its_extra_says_so_in_one_line(capsys, monkeypatch, tmp_path, argv, extra, module, package):
    """Without the extra's package (its import fails, as on a plain `pip install .`): exit 2, one line naming the command,
    the extra, the missing package and the pip command, before any work."""
    (tmp_path / "spec.yaml").write_text("preset: carmel\nscenario: {corridor: {L: 0.9}}\ngrid: {V: {from: 0.2, to: 1, num: 3}}\n")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, module, None)  # `import module` now raises ImportError
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err == (f"pfm-stability: error: pfm-stability {argv[0]} needs the optional extra '{extra}' (missing: {package}): "
                   f"pip install 'pfm-stability[{extra}]'\n")


def test_the_report_needs_no_extra():
    """The main job's dependencies are the documented seven (and threadpoolctl); what one command needs is an extra
    (pfm_stability.extras names the same packages as pyproject.toml)."""
    import tomllib

    from pfm_stability.extras import EXTRAS

    with open(os.path.join(os.path.dirname(__file__), "..", "pyproject.toml"), "rb") as fh:
        project = tomllib.load(fh)["project"]
    names = {dep.split(">")[0].split("[")[0].split("=")[0].strip().lower() for dep in project["dependencies"]}
    assert names == {"numpy", "scipy", "sympy", "control", "matplotlib", "tqdm", "pyyaml", "threadpoolctl"}
    for extra, packages in EXTRAS.items():
        declared = {dep.split(">")[0].strip() for dep in project["optional-dependencies"][extra]}
        assert declared == set(packages.values()), extra
