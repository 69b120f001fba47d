"""``report --disturbance D`` and the yaw acceleration limit in the report (docs/wobble.md): text, Markdown, JSON and schema.

What the numbers are is checked against the simulator in tests/test_rate_limit_disturbance.py; here: the sections
appear where they should and nowhere else, the JSON follows the shipped schema, the refusals are one line.
"""

import math

import pytest

from cli_helpers import report_json, run

LIMITED = ["--L", "0.9", "--yaw-accel-limit", "2"]


@pytest.fixture(scope="module")
def limited():
    """CARMEL at 0.6 m/s with a 2 rad/s² smoother, a 0.2 m start, wall (30°) and corridor."""
    return report_json([*LIMITED, "--V", "0.6", "--alpha", "30", "--disturbance", "0.2"])


def test_json_of_a_disturbance(limited):
    """Schema-valid (report_json); corridor.disturbance and wall.disturbance beside the verdicts: V*(D) <= V* (a start
    settles at most as fast as a small one), the limit and the input listed."""
    for geometry in ("corridor", "wall"):
        d = limited[geometry]["disturbance"]
        assert d["disturbance"] == 0.2 and d["yaw_accel_limit"] == 2.0
        assert d["V_disturbance"] <= d["V_critical"] * (1 + 1e-12)
        assert d["criticality"] in ("supercritical", "subcritical") and isinstance(d["cycles_below_critical"], bool)
    corridor = limited["corridor"]["disturbance"]
    assert corridor["cycles_below_critical"] and corridor["V_disturbance"] < 0.95 * corridor["V_critical"]  # the limiter's fold
    assert limited["inputs"]["yaw_accel_limit"] == {"value": 2.0, "unit": "rad/s^2", "source": "user"}
    assert limited["corridor"]["sampled"]["V_critical"] == pytest.approx(corridor["V_critical"], rel=1e-12)  # the linear verdict


def test_wobble_with_the_limiter():
    """``--wobble`` with a limit: JSON's wobble gains the limiter's gain and lag (schema-valid), and at 0.7 m/s, below V*
    but above the limiter's fold, no amplitude: a small start settles, a large one jumps (the reason says so)."""
    w = report_json([*LIMITED, "--V", "0.7", "--wobble"])["corridor"]["wobble"]
    assert "limiter_gain" in w and "limiter_lag" in w and w["amplitude"] is None and "--disturbance D says which" in w["reason"]
    assert "limiter_gain" not in report_json(["--L", "0.9", "--wobble"])["corridor"]["wobble"]


def test_text_and_markdown_sections():
    """Text: a "Disturbance in the corridor" section with V*(D); Markdown: the same as a heading and a list."""
    code, text, err = run(["report", *LIMITED, "--disturbance", "0.05"])
    assert code == 0, err
    assert "Disturbance in the corridor, off the centre line: a start 0.05 m off" in text and "V*(D) =" in text
    code, md, _ = run(["report", *LIMITED, "--disturbance", "0.05", "--format", "markdown"])
    assert "## Disturbance in the corridor" in md and "- a start of 0.05 m settles at or below V*(D)" in md


def test_a_limit_alone_says_the_verdicts_are_linear_and_nothing_else_changes():
    """With a limit and no --disturbance: the limit listed and one section saying the verdicts hold for small starts;
    without a limit and without --disturbance: neither (the report of before, tests/test_answers_unchanged.py)."""
    code, text, _ = run(["report", *LIMITED])
    assert "R = 2 rad/s^2 is not in these linear verdicts" in text
    plain = report_json(["--L", "0.9"])
    assert "yaw_accel_limit" not in plain["inputs"] and "disturbance" not in plain["corridor"]
    code, text, _ = run(["report", "--L", "0.9"])
    assert "yaw acceleration limit" not in text and "Disturbance" not in text


@pytest.mark.parametrize("argv, message", [
    (["--L", "0.9", "--disturbance", "-1"], "--disturbance: disturbance must be a finite number in (0, 10000] m; got -1"),
    (["--robot", "holonomic", "--law", "velocity", "--L", "0.9", "--disturbance", "0.05"], "--disturbance applies to a wall"),
])
def test_refusals_are_one_line(argv, message):
    """Bad input: exit 2, one line naming the option and the range, or what it applies to."""
    code, _, err = run(["report", *argv])
    assert code == 2 and message in err and err.count("\n") == 1


def test_what_cannot_be_said_is_null_with_the_reason():
    """A start wider than the corridor's play, and a limit with the servo's hold (no command sequence to limit): the
    disturbance's numbers null with the reason; the report itself still answers."""
    data = report_json(["--L", "0.9", "--disturbance", "0.6"])
    d = data["corridor"]["disturbance"]
    assert d["V_disturbance"] is None and "disturbance must be" in d["reason"] and math.isnan(float("nan"))
    data = report_json([*LIMITED, "--hold", "reference", "--disturbance", "0.05"])
    assert "needs hold=command" in data["corridor"]["disturbance"]["reason"]
