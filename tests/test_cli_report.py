"""`pfm-stability report`: output forms and bad input."""

import json
import subprocess
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pfm_stability.cli import main
from pfm_stability.models import MODEL_NAMES

CARMEL_ARGS = ["report", "--preset", "carmel", "--alpha", "20", "--L", "0.9"]


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_json_has_the_documented_keys(capsys):
    """JSON: `inputs`, and per scenario per model `stable` (bool), `NV_critical` and
    the critical values (wall: alpha_critical_deg, f_critical, V_critical;
    corridor: L_critical, V_critical, f_critical)."""
    code, out, err = run(capsys, *CARMEL_ARGS, "--format", "json")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["inputs"]["k"]["source"].startswith("ASSUMED")
    assert set(data["wall"]) == set(MODEL_NAMES) == set(data["corridor"])
    for name in MODEL_NAMES:
        wall, corridor = data["wall"][name], data["corridor"][name]
        assert isinstance(wall["stable"], bool) and isinstance(corridor["stable"], bool)
        for key in ("NV_critical", "alpha_critical_deg", "f_critical", "V_critical", "omega_critical"):
            assert isinstance(wall[key], float)
        for key in ("NV_critical", "L_critical", "V_critical", "f_critical"):
            assert isinstance(corridor[key], float)
    # KB Fig 5: α = 20° is unstable under (24)
    assert data["wall"]["kb_first_order"]["stable"] is False
    assert data["models"]["sampled"] == {"equation": data["models"]["sampled"]["equation"], "hold": "command", "compute_delay": 1}
    assert "optimistic" in data["kb_error"]["text"] or "conservative" in data["kb_error"]["text"]


def test_text_and_markdown_forms(capsys):
    code, text, _ = run(capsys, *CARMEL_ARGS)
    assert code == 0
    for fragment in ("ASSUMED", "Wall, alpha = 20 deg", "Corridor, L = 0.9 m", "KB's criterion is", "to stabilize"):
        assert fragment in text
    code, md, _ = run(capsys, *CARMEL_ARGS, "--format", "markdown")
    assert code == 0 and md.startswith("# pfm-stability report") and "| model |" in md


def test_model_selection_and_options(capsys):
    code, out, _ = run(capsys, "report", "--L", "1.2", "--model", "sampled", "--model", "pade", "--hold", "reference", "--compute-delay", "0", "--pade-order", "5", "--format", "json")
    assert code == 0
    data = json.loads(out)
    assert list(data["corridor"]) == ["sampled", "pade"]
    assert data["models"]["pade"]["order"] == 5
    assert data["models"]["sampled"]["hold"] == "reference"
    assert "wall" not in data


@pytest.mark.parametrize(
    "args, message",
    [
        (["--L", "0.4"], "L must be a finite number in (W/2, 10000] m = (0.4, 10000] m; got 0.4"),
        (["--hold", "both"], "invalid choice: 'both'"),
        ([], "alpha or L must be given"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, args, message):
    """Exit code 2 and a single stderr line naming the parameter and its range (every option's own range:
    tests/test_cli_fuzz.py::test_every_range_end_is_accepted_or_rejected_as_stated)."""
    extra = [] if any(a in args for a in ("--alpha", "--L")) or args == [] else ["--L", "0.9"]
    code, out, err = run(capsys, "report", *args, *extra)
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("pfm-stability: error: ")
    assert message in err


def test_library_raises_the_same_message():
    from pfm_stability.parameters import Robot

    with pytest.raises(ValueError, match=r"^V must be a finite number in \(0, 100\] m/s; got -1$"):
        Robot(V=-1, tau=0.3, k=2, W=0.8)


OPTION_VALUES = st.sampled_from(["--V", "--tau", "--T", "--k", "--f", "--n", "--W", "--alpha", "--L", "--compute-delay", "--pade-order", "--hold", "--model", "--format"])
TOKENS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-5, 5).map(str),
    st.text(max_size=6),
    st.sampled_from(["command", "reference", "json", "text", "sampled", "1e-300", "1e300", "-0", "0.5"]),
)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(OPTION_VALUES, TOKENS), max_size=5))
def test_random_cli_input_never_escapes_as_a_traceback(args):
    """Whatever the user types, `main` returns 0 or 2; it never raises."""
    argv = ["report"] + [x for pair in args for x in pair]
    try:
        code = main(argv)
    except SystemExit as exc:  # only --help/--version exit this way
        code = exc.code
    assert code in (0, 2)


def test_module_and_console_script_run_in_a_fresh_process():
    """`python -m pfm_stability` is the same program (exit 2 on bad input, no traceback)."""
    done = subprocess.run([sys.executable, "-m", "pfm_stability", "report", "--V", "-3", "--L", "1"], capture_output=True, text=True)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip() == "pfm-stability: error: argument --V: V must be a finite number in (0, 100] m/s; got -3.0"
