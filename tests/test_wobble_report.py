"""``report --wobble [TOL]``: JSON ``corridor.wobble`` (schema-checked), the text and Markdown sections, the refusals."""

import math

import pytest
from cli_helpers import report_json, run

from pfm_stability.analysis.wobble import DEFAULT_TOLERANCE_FRACTION
from pfm_stability.laws.force_law import corridor_gain, law_in_force
from pfm_stability.models import make_model
from pfm_stability.models.loop import Loop
from pfm_stability.parameters import CARMEL

KEYS = {"amplitude", "heading_amplitude", "omega", "reaches_wall", "criticality", "V_tolerance", "tolerance", "V_critical", "V_fold",
        "third_harmonic", "rate_harmonic", "method", "reason"}


@pytest.fixture(scope="module")
def carmel():
    return report_json(["--preset", "carmel", "--L", "0.9", "--wobble", "--model", "sampled"])


def test_json_wobble(carmel):
    """CARMEL at 0.8 m/s, L = 0.9 m: every key; the cycle within 15 % / 5 % of the independent simulator's 0.21 m at 2.27 rad/s;
    V* the sampled model's NV*/N (its own boundary, KB eq 25's N); the default tolerance a tenth of L − W/2 = 0.05 m;
    the verdicts beside it unchanged (the wobble is one more key of ``corridor``)."""
    w = carmel["corridor"]["wobble"]
    assert set(w) == KEYS
    assert w["amplitude"] == pytest.approx(0.21, rel=0.15) and w["omega"] == pytest.approx(2.27, rel=0.05)
    r, c = CARMEL.robot, CARMEL.controller
    NV = make_model("sampled", hold=c.hold, compute_delay=c.compute_delay).boundary(Loop(r.tau, c.T, r.k)).NV_critical
    assert w["V_critical"] == pytest.approx(NV / corridor_gain(law_in_force(r, c), 0.9), rel=1e-12)
    assert w["V_critical"] == pytest.approx(carmel["corridor"]["sampled"]["V_critical"], rel=1e-9)
    assert w["tolerance"] == pytest.approx(DEFAULT_TOLERANCE_FRACTION * (0.9 - r.W / 2), rel=1e-12)
    assert w["V_critical"] < w["V_tolerance"] < r.V
    assert w["criticality"] == "supercritical" and w["reaches_wall"] is False and w["reason"] is None
    assert set(carmel["corridor"]) - {"wobble"} == set(carmel["models"])


def test_no_wobble_key_without_the_option():
    """Without --wobble nothing changes: no ``wobble`` key (the recorded answers replay unchanged)."""
    data = report_json(["--preset", "carmel", "--L", "0.9", "--model", "sampled"])
    assert "wobble" not in data["corridor"]


def test_tolerance_and_no_branch():
    """A given tolerance is used as typed; a law without a restoring centre (Khatib's beyond its reach: N = 0) has no branch:
    every number null, the reason, still valid JSON; a kinematic robot (τ = 0) has one."""
    w = report_json(["--preset", "carmel", "--L", "0.9", "--wobble", "0.1", "--V", "0.7", "--model", "sampled"])["corridor"]["wobble"]
    assert w["tolerance"] == 0.1 and w["amplitude"] == 0.0 and "settles" in w["reason"]
    k = report_json(["--law", "khatib", "--goal-distance", "1", "--rho0", "0.8", "--L", "1.0", "--model", "sampled", "--wobble"])
    w = k["corridor"]["wobble"]
    assert w["criticality"] is None and w["amplitude"] is None and "N > 0" in w["reason"]
    kin = report_json(["--robot", "kinematic", "--L", "0.9", "--model", "sampled", "--wobble"])["corridor"]["wobble"]
    assert kin["criticality"] in ("supercritical", "subcritical") and math.isfinite(kin["V_critical"])


def test_text_and_markdown():
    """The text and Markdown sections say what the JSON says (amplitude, criticality, V_tolerance to 4 digits)."""
    code, text, _ = run(["report", "--preset", "carmel", "--L", "0.9", "--wobble", "--model", "sampled"])
    assert code == 0
    assert "Wobble in the corridor" in text and "lateral amplitude 0.2094 m" in text and "supercritical" in text
    assert "V_tolerance = 0.7581 m/s" in text
    code, md, _ = run(["report", "--preset", "carmel", "--L", "0.9", "--wobble", "--model", "sampled", "--format", "markdown"])
    assert code == 0 and "## Wobble in the corridor" in md and "- limit cycle: lateral amplitude 0.2094 m" in md


def test_wall_wobble():
    """With --alpha the wall gets its wobble too (JSON ``wall.wobble``, the biased describing function): CARMEL at 0.8 m/s
    beside a wall at 30 deg is past the sampled model's V* (the wall's verdict says so) and has a cycle; the text says it."""
    data = report_json(["--preset", "carmel", "--alpha", "30", "--model", "sampled", "--wobble"])
    w = data["wall"]["wobble"]
    assert set(w) == KEYS and "biased" in w["method"]
    assert w["V_critical"] == pytest.approx(data["wall"]["sampled"]["V_critical"], rel=1e-9)
    assert w["amplitude"] > 0 and w["criticality"] == "supercritical"
    code, text, _ = run(["report", "--preset", "carmel", "--alpha", "30", "--model", "sampled", "--wobble"])
    assert code == 0 and "Wobble beside the wall" in text


def test_refusals():
    """--wobble for a holonomic robot: exit 2, one line, nothing on stdout."""
    code, out, err = run(["report", "--robot", "holonomic", "--law", "velocity", "--L", "1", "--wobble"])
    assert code == 2 and out == ""
    assert err.strip().splitlines() == ["pfm-stability: error: --wobble applies to a wall (--alpha) or a corridor (--L) with --robot "
                                        "steering or kinematic and a static law (power, grid, khatib, gnron)"]
