"""Hypothesis drives the whole command line: every subcommand, every option, good and bad values.

Whatever is typed — values inside and outside each option's range
(`pfm_stability.parameters.RANGES`), NaN, inf, huge and tiny numbers, empty
strings, text, output paths that are directories, lack ``.png``, lie in
missing directories or where nothing can be created (``/proc``, ``/sys``),
unknown options, ``--help``, a full disk (every file the package writes goes
through `pfm_stability.io.files.open_new`, which the fuzz replaces by a disk with
0, 1 or 4096 bytes left now and then) — `main` returns 0 or 2 and
never raises. An exit 2 prints exactly one error line (after any progress lines and
``pfm-stability: note:`` lines) and nothing on stdout, and never blames a value drawn inside its
option's stated range. An exit 0 with ``--format json`` prints strict JSON
(NaN and Infinity tokens rejected) that validates against the shipped schema,
and a reported success wrote the PNG it named; a full disk leaves neither the
output nor a temporary file behind. `map` and `sweep`, too slow to fuzz, are
checked on a full disk and on uncreatable paths by
`test_every_writing_command_on_a_full_disk_and_an_uncreatable_path`.

Examples run in-process (`pfm_stability.cli.main`). Their number follows the
hypothesis profile (``HYPOTHESIS_PROFILE``, tests/conftest.py: ``ci`` by
default, ``dev`` for 10x more), shared out by what a run costs: the
subcommands that simulate or draw get fewer examples, and their valid values
are kept cheap (`CHEAP`: short ``--duration``, large ``--rtol``, few
``--members``, the smallest ``--sweep``, analytic walls unless ``--env`` is
drawn). The ends of the ranges that are expensive to *run* (a 1001-cell
window, a 10⁴ m corridor, a 10⁶ s simulation) are checked where they are
parsed, for every option of every subcommand, by
`test_every_range_end_is_accepted_or_rejected_as_stated`.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import itertools
import json
import math
import os
import re

import pytest
from hypothesis import event, given, note, settings
from hypothesis import strategies as st
from jsonschema import Draft202012Validator

from pfm_stability.cli import build_parser, main
from pfm_stability.cli.options import describe
from pfm_stability.cli.traps import SHIPPED_SCENES
from pfm_stability.parameters import RANGES, SHOWN_AS
from pfm_stability.io.schema import load_schema
from cli_helpers import disk_full
from map_helpers import shared_map_analyses

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")  # a numpy warning is a silent NaN or overflow

PARSER = build_parser()
SUBPARSERS = next(a for a in PARSER._actions if isinstance(a, argparse._SubParsersAction)).choices
VALIDATOR = Draft202012Validator(load_schema())
PNG = b"\x89PNG\r\n\x1a\n"

POSITIONAL_VALUES = {"traps": SHIPPED_SCENES}
"""Valid values of positionals that are not choices (a scene file or a shipped scene's name)."""
SHARE = {"report": 2.0, "simulate": 1.0, "validate": 0.6, "plot": 0.14, "derive": 0.06, "traps": 0.15}
"""Examples per subcommand, as a fraction of the profile's ``max_examples`` (at least 4)."""

CHEAP = {
    ("simulate", "duration"): (0.05, 2.0),
    ("simulate", "T_sampled"): (0.01, 100.0),
    ("simulate", "window_cells"): (3, 61),
    ("simulate", "L"): (0.3, 20.0),
    ("validate", "duration"): (1.0, 5.0),
    ("validate", "T_sampled"): (0.02, 100.0),
    ("validate", "rtol"): (0.15, 0.5),
    ("validate", "members"): (3, 4),
    ("validate", "sweep"): (8, 8),
    ("validate", "L"): (0.3, 20.0),
}
"""(subcommand, RANGES key) → the part of the range whose values are run (the rest costs minutes)."""

ADDED = {
    "simulate": [("--duration", "1")],
    "validate": [("--duration", "3"), ("--rtol", "0.3"), ("--members", "3"), ("--env", "analytic")],
}
"""Cheap settings added when the example did not draw the option itself."""

BAD_NUMBERS = ["nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e309", "-1e309", "1e308", "-1e308", "", " ", "fast",
               "0x10", "1,5", "None", "true", "1e", "--", "-", "1_000", "٣", "1e-320", "-0", "-1e-300"]
BAD_INTEGERS = ["", " ", "x", "1.5", "1e3", "nan", "inf", "0x3", "-", "--", "3.0", "٣", "9" * 5000]
PATH_KINDS = ["ok", "upper", "directory", "empty", "blank", "no_suffix", "missing_dir", "only_suffix", "nul", "proc", "sys"]
_COUNTER = itertools.count()

def _options(command):
    """Option string → action, and the positional actions, of one subcommand."""
    options, positionals = {}, []
    for action in SUBPARSERS[command]._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        if action.option_strings:
            options[max(action.option_strings, key=len)] = action
        else:
            positionals.append(action)
    return options, positionals


def _inside(r, x) -> bool:
    above = x > r.low if r.low_open else x >= r.low
    below = x < r.high if r.high_open else x <= r.high
    return math.isfinite(x) and above and below


def _number_values(command, key):
    """Strategy of (text, whether it lies inside the range) for one float option."""
    r = RANGES[key]
    lo, hi = CHEAP.get((command, key), (r.low, r.high))
    lo, hi = max(lo, r.low), min(hi, r.high)
    lo, hi = max(lo, -1e300), min(hi, 1e300)
    valid = st.floats(lo, hi, allow_nan=False, allow_infinity=False).filter(lambda x: _inside(r, x)).map(lambda x: (repr(x), True))
    ends = []
    for end in (r.low, r.high):
        if math.isfinite(end):
            for x in (end, math.nextafter(end, -math.inf), math.nextafter(end, math.inf)):
                for text in (repr(float(x)), f"{x:.12g}"):
                    y = float(text)
                    if not (_inside(r, y) and not lo <= y <= hi):  # inside but expensive to run: parse-level test only
                        ends.append((text, _inside(r, y)))
    bad = st.sampled_from(BAD_NUMBERS).map(lambda t: (t, False))
    far = st.sampled_from([r.low - 1, -r.high, r.high * 10 + 1]).filter(math.isfinite).map(lambda x: (repr(float(x)), _inside(r, x)))
    other = st.one_of(st.sampled_from(ends), bad, far, st.text(max_size=8).map(lambda t: (t, False)))
    return _mostly(valid, other)


def _integer_values(command, key, odd):
    """Strategy of (text, whether it lies inside the range) for one integer option."""
    r = RANGES[key]
    lo, hi = CHEAP.get((command, key), (r.low, r.high))
    lo, hi = max(lo, r.low), min(hi, r.high)
    ok = (lambda n: r.low <= n <= r.high and (n % 2 == 1 or not odd))
    valid = st.integers(lo, hi).map(lambda n: n + 1 if odd and n % 2 == 0 and n + 1 <= hi else n).map(lambda n: (str(n), ok(n)))
    ends = [(str(n), ok(n)) for n in (r.low - 1, r.low, r.high, r.high + 1) if not (ok(n) and not lo <= n <= hi)]
    bad = st.sampled_from(BAD_INTEGERS).map(lambda t: (t, False))
    return _mostly(valid, st.one_of(st.sampled_from(ends), bad, st.text(max_size=6).map(lambda t: (t, False))))


def _mostly(valid, other):
    """`valid` four times in five (most command lines should run), `other` otherwise."""
    return st.integers(0, 4).flatmap(lambda i: other if i == 4 else valid)


def _path(kind, outdir) -> str:
    n = next(_COUNTER)
    return {
        "ok": os.path.join(outdir, f"out{n}.png"),
        "upper": os.path.join(outdir, f"OUT{n}.PNG"),
        "directory": outdir,
        "empty": "",
        "blank": " ",
        "no_suffix": os.path.join(outdir, f"out{n}"),
        "missing_dir": os.path.join(outdir, "missing", f"out{n}.png"),
        "only_suffix": os.path.join(outdir, ".png"),
        "nul": os.path.join(outdir, "a\0b.png"),
        "proc": f"/proc/out{n}.png",  # a directory root may "write" (os.access) where nothing can be created
        "sys": f"/sys/kernel/out{n}.png",
    }[kind]


@st.composite
def command_lines(draw, command, outdir):
    """An argv for `command`, and the options whose values were drawn inside their ranges."""
    options, positionals = _options(command)
    groups, inside = [], set()  # one group per positional or option with its value
    for action in positionals:
        valid = sorted(action.choices) if action.choices else list(POSITIONAL_VALUES[command])
        groups.append([draw(_mostly(st.sampled_from(valid), st.text(max_size=5)))])
    required = [name for name, a in options.items() if a.required]
    optional = sorted(name for name, a in options.items() if not a.required)
    chosen = [name for name in required if draw(st.integers(0, 9)) != 9]  # now and then a required option is missing
    chosen += draw(st.lists(st.sampled_from(optional), max_size=6, unique=True))
    for name in chosen:
        action = options[name]
        kind = getattr(action.type, "kind", None)
        if action.nargs == 0:
            groups.append([name])
            continue
        if action.choices is not None:
            value, ok = draw(_mostly(st.sampled_from(sorted(action.choices)).map(lambda c: (c, True)), st.text(max_size=6).map(lambda t: (t, False))))
        elif kind == "number":
            value, ok = draw(_number_values(command, action.type.range_key))
        elif kind == "integer":
            value, ok = draw(_integer_values(command, action.type.range_key, action.type.odd))
        elif kind in ("path", "directory"):  # a directory option gets the same paths: new, existing, empty, bad
            value, ok = _path(draw(_mostly(st.just("ok"), st.sampled_from(PATH_KINDS))), outdir), False
        elif kind == "nav2_param":  # report --param NAME=VALUE: a registry parameter (of some controller) or not, any value
            value, ok = draw(_nav2_parameters()), False
        else:
            raise AssertionError(f"{command} {name}: an option without a range (type {action.type!r}); give it one in RANGES")
        groups.append([name, value])
        if ok:  # negative numbers too, e.g. --offset -1e-05 (not read as an option)
            inside.add(name)
    for name, value in ADDED.get(command, ()):
        if name not in chosen:
            groups.append([name, value])
    if command == "report" and not {"--alpha", "--L"} & set(chosen) and draw(_mostly(st.just(True), st.just(False))):
        groups.append(["--L", "1.0"])  # the report needs a geometry; now and then it has none
    extra = draw(_mostly(st.none(), st.sampled_from(["--help", "--bogus", "stray", "-x", "--"])))
    if extra:
        groups.insert(draw(st.integers(0, len(groups))), [extra])
    return [command] + [token for group in groups for token in group], inside


@st.composite
def _nav2_parameters(draw):
    """``NAME=VALUE`` for ``report --param``: a parameter of one of the Nav2 controllers (the controller drawn may not have
    it), or a made-up name, with a number in or far outside any range, a switch, a text or nothing."""
    from pfm_stability.controllers.registry import CONTROLLERS

    names = sorted({p.name for c in CONTROLLERS.values() for p in c.parameters})
    name = draw(_mostly(st.sampled_from(names), st.text(max_size=6)))
    value = draw(st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.sampled_from(["true", "false", "", "x", "[1, 2]"])))
    return f"{name}={value}"


def _reject_constant(token):
    raise ValueError(f"non-standard JSON token {token}")


def run_cli(argv):
    """(exit status, stdout, stderr) of `main(argv)` in-process; exceptions propagate."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # --help
            code = exc.code
    return code, out.getvalue(), err.getvalue()


OUTPUT_OPTIONS = ("--out", "--plot", "--sweep-plot")


def check_run(command, argv, inside, room=None):
    """Every property of one command line (module docstring); `room`: bytes left on a full disk (None: not full)."""
    note(f"argv = {argv!r}; disk room {room!r}")
    if room is None:
        code, out, err = run_cli(argv)  # any exception is a traceback: a failure
    else:
        with disk_full(room):
            code, out, err = run_cli(argv)
        _nothing_left_behind(argv)
    note(f"exit {code}; stderr = {err!r}")
    event(f"exit {code}")
    assert code in (0, 2)
    lines = err.splitlines()
    progress = [line for line in lines if line.startswith(f"{command}: ")]
    notes = [line for line in lines if line.startswith("pfm-stability: note: ")]  # e.g. measuring MPPI's gains takes seconds
    others = [line for line in lines if line not in progress and line not in notes]
    if code == 2:
        assert out == ""
        assert len(others) == 1 and lines[-1] == others[0] and others[0].startswith("pfm-stability: error: ")
        message = others[0]
        assert "Traceback" not in err and "not JSON compliant" not in message
        assert " rad; got" not in message, "a range stated in radians: every option is typed in degrees"
        for name in inside:
            assert not message.startswith(f"pfm-stability: error: argument {name}:"), f"{name}: a value inside the stated range was rejected"
        _check_blamed_value(command, argv, message)
        return
    if "--help" in argv:
        assert out.startswith("usage:")
        return
    assert others == [] and out
    for name in OUTPUT_OPTIONS:
        if name in argv:
            path = argv[argv.index(name) + 1]
            assert path.lower().endswith(".png") and os.path.isfile(path), f"{name} {path!r}: success without the file"
            with open(path, "rb") as fh:
                assert fh.read(8) == PNG
    if "--format" in argv and argv[argv.index("--format") + 1] == "json":
        data = json.loads(out, parse_constant=_reject_constant)
        errors = sorted(VALIDATOR.iter_errors(data), key=lambda e: list(e.absolute_path))
        assert not errors, [f"{list(e.absolute_path)}: {e.message[:200]}" for e in errors[:5]]
        assert data["command"] == command


def _nothing_left_behind(argv) -> None:
    """After a run on a full disk: no output file (none existed: the names are new) and no temporary file beside it."""
    for name in OUTPUT_OPTIONS:
        if name in argv:
            path = argv[argv.index(name) + 1]
            if not path.strip() or "\0" in path or os.path.isdir(path):
                continue
            assert not os.path.exists(path), f"{name} {path!r} written on a full disk"
            folder = os.path.dirname(os.path.abspath(path))
            if os.path.isdir(folder) and os.access(folder, os.R_OK):
                assert not [f for f in os.listdir(folder) if f.startswith(f".{os.path.basename(path)}.")], "a temporary file left"


def _same_value(got: str, typed: str) -> bool:
    """True when the value a message quotes is the one typed (as a number where both parse, else as text)."""
    got = got.strip("'\"")
    try:
        return float(got) == float(typed) or (math.isnan(float(got)) and math.isnan(float(typed)))
    except ValueError:
        return got == typed


def _check_blamed_value(command, argv, message):
    """A message "X must be …; got Y" about an option the user typed quotes the value typed, never an internal one
    (k* once probed 1e-3·k below k's range and blamed the user's k for it)."""
    found = re.match(r"pfm-stability: error: (\w+) must be .*; got (.+)$", message)
    if not found:
        return
    options, _ = _options(command)
    typed = {}
    for token, value in zip(argv, argv[1:]):
        action = options.get(token)
        if action is not None and getattr(action.type, "kind", None) in ("number", "integer"):
            typed[SHOWN_AS.get(action.type.range_key, action.type.range_key)] = value
    key, got = found.groups()
    if key in typed:
        assert _same_value(got, typed[key]), f"{message!r}: {key} was typed as {typed[key]!r}"


@pytest.fixture(scope="module")
def outdir(tmp_path_factory):
    return str(tmp_path_factory.mktemp("cli_fuzz"))


def _fuzz_test(command):
    examples = max(4, round(settings.default.max_examples * SHARE[command]))

    @settings(max_examples=examples)
    @given(data=st.data())
    def test(outdir, data):
        argv, inside = data.draw(command_lines(command, outdir), label="argv")
        room = data.draw(_mostly(st.none(), st.sampled_from([0, 1, 4096])), label="disk room")  # now and then the disk is full
        check_run(command, argv, inside, room)

    test.__name__ = f"test_fuzz_{command}"
    test.__doc__ = f"Random `pfm-stability {command}` command lines: exit 0 or 2, one error line, strict JSON, files written ({examples} examples)."
    if command == "derive":  # on the worker of tests/test_derivation.py: the derivation's sympy steps once (tests/conftest.py)
        test = pytest.mark.xdist_group("derivation")(test)
    return pytest.mark.slow(test)  # seconds each: scheduled first (tests/conftest.py)


test_fuzz_report = _fuzz_test("report")
test_fuzz_simulate = _fuzz_test("simulate")
test_fuzz_validate = _fuzz_test("validate")
test_fuzz_plot = _fuzz_test("plot")
test_fuzz_derive = _fuzz_test("derive")
test_fuzz_traps = _fuzz_test("traps")


# ------------------------------------------------------- every range, every option
def _ranged_options():
    for command in sorted(SUBPARSERS):
        options, _ = _options(command)
        for name, action in sorted(options.items()):
            kind = getattr(action.type, "kind", None)
            if kind in ("number", "integer"):
                yield pytest.param(command, name, action, id=f"{command}{name}")


@pytest.mark.parametrize("command,name,action", list(_ranged_options()))
def test_every_range_end_is_accepted_or_rejected_as_stated(command, name, action):
    """Each numeric option parses with `RANGES[key]` in the units typed: an end is accepted
    exactly when the range includes it, and a refusal is the one message the help states, quoting
    the value typed: ``"<name> must be a finite number in <range> <unit>; got <value>"`` (the
    value as parsed, or the text if it is no number) or ``"<name> must be an [odd ]integer in
    [low, high]; got '<text>'"``; an odd option refuses an even value inside its range too.
    On the command line the refusal is exit 2, nothing on stdout and the one line
    ``pfm-stability: error: argument <option>: <message>`` (the hand-written tables of range
    messages that once lived in the CLI tests are these cases)."""
    key = action.type.range_key
    r = RANGES[key]
    shown = SHOWN_AS.get(key, key)
    assert describe(key) in action.help, f"{command} {name}: help does not state {describe(key)}"
    rejected = []  # (text, message)
    if action.type.kind == "integer":
        odd = action.type.odd
        message = f"{shown} must be an {'odd ' if odd else ''}integer in [{r.low}, {r.high}]; got {{!r}}"
        ends = [r.low - 1, r.low, r.high, r.high + 1] + ([r.low + 1] if odd else [])
        for n in ends:
            inside = r.low <= n <= r.high and (n % 2 == 1 or not odd)
            if inside:
                assert action.type(str(n)) == n
            else:
                rejected.append((str(n), message.format(str(n))))
        rejected += [(text, message.format(text)) for text in ("x", "1.5", "")]
    else:
        for end in (r.low, r.high):
            if not math.isfinite(end):
                continue
            for x in (end, math.nextafter(end, -math.inf), math.nextafter(end, math.inf)):
                if _inside(r, x):
                    assert action.type(repr(x)) == x
                else:
                    rejected.append((repr(x), f"{shown} must be a finite number in {describe(key)}; got {x!r}"))
        for text in ("nan", "inf", "-inf", "", "fast"):
            try:
                value = float(text)
            except ValueError:
                value = text
            rejected.append((text, f"{shown} must be a finite number in {describe(key)}; got {value!r}"))
    for text, message in rejected:
        with pytest.raises(argparse.ArgumentTypeError) as info:
            action.type(text)
        assert str(info.value) == message, (command, name, text)
    text, message = rejected[0]
    assert run_cli([command, name, text]) == (2, "", f"pfm-stability: error: argument {name}: {message}\n")


def test_every_option_is_fuzzed():
    """Every option of every subcommand has a range, choices, a path check or is a flag (so the fuzz can draw it)."""
    for command in SUBPARSERS:
        options, _ = _options(command)
        for name, action in options.items():
            assert action.nargs == 0 or action.choices is not None or getattr(action.type, "kind", None) in ("number", "integer", "path", "directory", "address", "topic", "nav2_param"), (command, name)


# -------------------------------------------- once tracebacks, now defined answers
def test_once_a_traceback_grid_calibration_with_a_subnormal_n():
    code, out, err = run_cli(["simulate", "--scenario", "corridor", "--n", "2.2250738585072014e-308", "--duration", "1"])
    assert code in (0, 2)


def test_once_a_traceback_wall_with_small_n():
    code, out, err = run_cli(["report", "--alpha", "45", "--n", "0.015625"])
    assert code in (0, 2)


def test_once_a_traceback_subnormal_k():
    code, out, err = run_cli(["report", "--L", "1", "--k", "2.2250738585072014e-308"])
    assert code in (0, 2)


def test_once_a_traceback_exact_delay_with_a_tiny_tau():
    code, out, err = run_cli(["report", "--model", "exact_delay", "--L", "1.0", "--tau", "1e-300"])
    assert code in (0, 2)


def test_once_a_traceback_exact_delay_without_roots():
    code, out, err = run_cli(["report", "--L", "1", "--tau", "1e-38", "--V", "0.03125"])
    assert code in (0, 2)


def test_once_an_internal_value_blamed_on_the_user_k_star_probe():
    """`report --k 1e-4` (inside k's range) failed with "k must be … got 1e-07": the k* search probed 1e-3·k."""
    argv = ["report", "--k", "1e-4", "--L", "0.9"]
    code, out, err = run_cli(argv)
    assert code == 0 and err == "", err


def test_once_an_internal_value_blamed_on_the_user_heading_gain():
    """`report --law fuzzy --L 0.25 --W 0.18` failed with "c must be … got 942.76", an internal heading gain; now
    every model's verdict is "undecided" with the reason (docs/velocity_and_fuzzy.md)."""
    code, out, err = run_cli(["report", "--law", "fuzzy", "--L", "0.25", "--W", "0.18", "--format", "json"])
    assert code == 0 and err == "", err
    data = json.loads(out, parse_constant=_reject_constant)
    assert not list(VALIDATOR.iter_errors(data)) and {v["verdict"] for v in data["corridor"].values()} == {"undecided"}


def test_a_message_quotes_the_typed_value():
    """The property the fuzz checks on every exit 2 (`_check_blamed_value`), on messages it must accept and reject."""
    _check_blamed_value("report", ["report", "--L", "0.4"], "pfm-stability: error: L must be a finite number in (W/2, 10000] m; got 0.4")
    _check_blamed_value("report", ["report", "--alpha", "90"], "pfm-stability: error: alpha must be a finite number in [1e-06, 89.999999] deg; got 90.0")
    with pytest.raises(AssertionError):
        _check_blamed_value("report", ["report", "--k", "1e-4", "--L", "0.9"], "pfm-stability: error: k must be a finite number in [1e-06, 10000] 1/s; got 1e-07")


def test_once_a_traceback_alpha_at_the_end_of_its_range_in_simulate():
    code, out, err = run_cli(["simulate", "--scenario", "wall", "--env", "analytic", "--alpha", "89.999999", "--duration", "2"])
    assert code == 0, err


# ------------------------------------------- full disk, uncreatable paths: every writer
SWEEP_SPEC = "preset: carmel\nscenario: {corridor: {L: 0.9}}\nmodels: [sampled]\ngrid:\n  V: {from: 0.2, to: 1.6, num: 30}\n"

WRITERS = {
    "plot": (["plot", "force-law", "--out", "{target}.png"], "{target}.png"),
    "simulate": (["simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "0.5", "--plot", "{target}.png"], "{target}.png"),
    "validate": (["validate", "--scenario", "corridor", "--env", "analytic", "--quiet", "--duration", "3", "--rtol", "0.3",
                  "--members", "3", "--plot", "{target}.png"], "{target}.png"),
    "traps": (["traps", "gc2000_fig3", "--plot", "{target}.png"], "{target}.png"),
    "map": (["map", "depot", "--quiet", "--out-dir", "{target}"], "{target}/stability.png"),
    "sweep": (["sweep", "{spec}", "--quiet", "--workers", "1", "--out", "{target}.parquet"], "{target}.parquet"),
    "sweep-plot": (["sweep", "{spec}", "--quiet", "--workers", "1", "--out", "{other}.parquet", "--plot", "{target}.png"], "{target}.png"),
}
"""Every command that writes a file: its argv (with the output at {target}) and the file it writes."""


def _writer_argv(name, target, tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text(SWEEP_SPEC)
    argv, written = WRITERS[name]
    fill = {"target": str(target), "spec": str(spec), "other": str(tmp_path / "other")}
    return [a.format(**fill) for a in argv], written.format(**fill)


@pytest.mark.parametrize("room", [0, 3000])
@pytest.mark.parametrize("name", [pytest.param(name, marks=[pytest.mark.xdist_group("map_depot_carmel")] * (name == "map"))
                                  for name in sorted(WRITERS)])
def test_every_writing_command_on_a_full_disk_and_an_uncreatable_path(tmp_path, name, room):
    """A full disk (0 or 3000 bytes left): exit 2, one line "could not write … No space left on device", no output, no
    temporary file, and a file already at the output path untouched (the write is atomic: a rename once complete).
    An output where nothing can be created (/proc, /sys: root passes os.access there) is refused before any work.
    The depot's analysis, which comes before the writing, is computed once per process for the two rooms and the other
    tests that read it (tests/map_helpers.py)."""
    argv, written = _writer_argv(name, tmp_path / "out", tmp_path)
    if name != "map":
        with open(written, "wb") as fh:
            fh.write(b"the user's old file")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    with disk_full(room), shared_map_analyses():
        code, out, err = run_cli(argv)
    assert code == 2 and out == "", err
    assert err.splitlines()[-1].startswith("pfm-stability: error: could not write ") and err.endswith("No space left on device\n") or \
        "No space left on device; the finished chunks are kept in" in err, err
    if name == "map":
        assert not os.path.exists(tmp_path / "out"), "a map directory created on a full disk is removed again"
    else:
        with open(written, "rb") as fh:
            assert fh.read() == b"the user's old file"
    after = sorted(p.name for p in tmp_path.rglob("*") if not p.name.endswith(".parts") and ".parts" not in str(p))
    assert after == before, "temporary files left behind"
    for place in ("/proc/nope", "/sys/kernel/nope"):
        argv, _ = _writer_argv(name, place, tmp_path)
        code, out, err = run_cli(argv)
        assert code == 2 and out == "" and len(err.splitlines()) == 1, err
        assert "nothing can be created in /" in err, err
