"""`pfm-stability report --robot kinematic|holonomic`: the robot loop families in the report (docs/models.md, "Robot loop families").

Every number the report prints for a holonomic or kinematic robot is checked against the
library route it claims to come from (`velocity_laws`, `models.holonomic*`, `tracking`,
`models.holonomic.kinematic_loop`) and, where one exists, against the closed form of
docs/models.md computed here independently. Every JSON output validates against the
shipped schema.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from cli_helpers import report_json, run

from pfm_stability import CARMEL
from pfm_stability.report.families import make_family_law
from pfm_stability.report.stability import build_report
from pfm_stability.models import ExactDelay, make_model
from pfm_stability.models.holonomic import HolonomicLoop, kinematic_loop
from pfm_stability.parameters import MODEL_NAMES

KHATIB_CORRIDOR = ["--robot", "holonomic", "--law", "velocity", "--eta", "0.3", "--rho0", "2", "--L", "0.5", "--alpha-v", "0.1"]


def exact_delay_T(kappa: float, c_h: float) -> float:
    """docs/models.md: T* = atan2(c_h ω, κ)/ω, ω² = (c_h² + √(c_h⁴ + 4κ²))/2."""
    w = math.sqrt((c_h**2 + math.sqrt(c_h**4 + 4 * kappa**2)) / 2)
    return math.atan2(c_h * w, kappa) / w


def test_khatib_corridor_example_kappa_c_h_and_delay_margins():
    """Khatib corridor η 0.3, ρ0 2, L 0.5, α_v 0.1 (docs/models.md table): κ 24, c_h 0.2, T* 8.33 ms (pure delay),
    16.7 ms (ZOH), 5.55 ms (ZOH + 1 sample). The table's values are rounded to 3 digits: rel 1e-3."""
    ds = {cd: report_json([*KHATIB_CORRIDOR, "--compute-delay", str(cd)]) for cd in (0, 1)}
    env = ds[0]["environment"]["corridor"]
    assert env["kappa"] == pytest.approx(24.0, rel=1e-12) and env["c_h"] == pytest.approx(0.2, rel=1e-12)
    assert ds[0]["corridor"]["exact_delay"]["T_critical"] == pytest.approx(8.33e-3, rel=1e-3)
    assert ds[0]["corridor"]["sampled"]["T_critical"] == pytest.approx(1 / 60, rel=1e-6)  # 2c_h/κ exactly
    assert ds[1]["corridor"]["sampled"]["T_critical"] == pytest.approx(5.55e-3, rel=2e-3)
    for d in ds.values():  # T = 65 ms is far past every finite T*: unstable, and "lower T" is the remedy
        for name, v in d["corridor"].items():
            assert v["stable"] == (v["T_critical"] == "inf"), name
    assert ds[0]["corridor"]["sampled"]["to_stabilize"]["T"]["to"] == ds[0]["corridor"]["sampled"]["T_critical"]


def test_holonomic_gains_and_delay_margins_on_random_parameters():
    """κ, c_h equal `holonomic_corridor_gains`; T* of every model equals the model's `critical_delay`; exact_delay's T*
    equals the closed form and the ZOH one min(2/c_h, 2c_h/κ) (docs/models.md), on 6 random parameter sets far from CARMEL's.
    Tolerance 1e-6: T* is bisected to 1e-9 relative, the closed forms are exact."""
    rng = np.random.default_rng(19)
    for _ in range(6):
        eta, rho0 = 10 ** rng.uniform(-2, 1), 10 ** rng.uniform(-0.5, 1)
        L, alpha_v, mass = rho0 * rng.uniform(0.2, 0.9), 10 ** rng.uniform(-2, 1), 10 ** rng.uniform(-1, 1)
        T = 10 ** rng.uniform(-3, -1)
        law = make_family_law("velocity", eta=eta, rho0=rho0, alpha_v=alpha_v)
        controller = CARMEL.controller.replace(T=T, compute_delay=0)
        report = build_report(CARMEL.robot, controller, family="holonomic", law=law, L=L, mass=mass)
        d = report.to_dict()
        gains = law.velocity_attraction().holonomic_corridor_gains(law.repulsion(), L, 1.0, mass, CARMEL.robot.V)
        mid = min(gains, key=lambda g: abs(g.x0))
        kappa, c_h = d["environment"]["corridor"]["kappa"], d["environment"]["corridor"]["c_h"]
        assert (kappa, c_h) == (mid.kappa, mid.c_h)
        assert c_h == pytest.approx(2 * alpha_v / mass, rel=1e-12)
        loop = HolonomicLoop(T, c_h)
        for name in MODEL_NAMES:
            expected = make_model(name, compute_delay=0).critical_delay(kappa, loop)
            got = d["corridor"][name]["T_critical"]
            assert (got == "inf" and math.isinf(expected)) or got == pytest.approx(expected, rel=1e-12), name
        assert d["corridor"]["exact_delay"]["T_critical"] == pytest.approx(exact_delay_T(kappa, c_h), rel=1e-6)
        assert d["corridor"]["sampled"]["T_critical"] == pytest.approx(min(2 / c_h, 2 * c_h / kappa), rel=1e-6)


def test_holonomic_wall_lists_every_equilibrium_with_its_gains():
    """A wall: κ, c_h per equilibrium equal `holonomic_wall_gains` (exactly: the same route), verdicts of the first."""
    law = make_family_law("velocity", eta=0.3, rho0=2.0, alpha_v=0.1)
    d = report_json(["--robot", "holonomic", "--law", "velocity", "--eta", "0.3", "--rho0", "2", "--alpha", "60", "--model", "exact_delay"])
    gains = law.velocity_attraction().holonomic_wall_gains(law.repulsion(), math.radians(60), 1.0, 1.0, CARMEL.robot.V)
    eqs = d["environment"]["wall"]["equilibria"]
    assert [(e["d0"], e["kappa"], e["c_h"]) for e in eqs] == [(g.x0, g.kappa, g.c_h) for g in gains]
    assert d["wall"] == eqs[0]["models"]
    assert d["wall"]["exact_delay"]["T_critical"] == pytest.approx(exact_delay_T(gains[0].kappa, gains[0].c_h), rel=1e-6)


@pytest.mark.parametrize("alpha_v,zeta", [(0.0, 0.0), (0.02, 0.2), (0.1, 1.0), (0.2, 2.0)])
def test_tracking_damping_ratio_and_natural_frequency(alpha_v, zeta):
    """GC2002 eq 34–36, α_p = 0.005, m = 1: ζ = 0, 0.2, 1, 2 and ω_n = 0.1; cross-checked with the roots of
    s² + 2α_v s + 2α_p (ζ = −Re s/|s| for complex roots, ω_n = √(s₁s₂)). Tolerance 1e-9 (floating point)."""
    d = report_json([*KHATIB_CORRIDOR[:-1], str(alpha_v), "--alpha-p", "0.005", "--model", "continuous"])
    t = d["tracking"]
    assert t["damping_ratio"] == pytest.approx(zeta, abs=1e-12) and t["natural_frequency"] == pytest.approx(0.1, rel=1e-12)
    roots = np.roots([1.0, 2 * alpha_v, 2 * 0.005])
    assert math.sqrt(abs(np.prod(roots))) == pytest.approx(t["natural_frequency"], rel=1e-9)
    assert -np.sum(roots).real / (2 * t["natural_frequency"]) == pytest.approx(t["damping_ratio"], abs=1e-9)


def test_undamped_holonomic_robot_is_unstable_at_every_delay():
    """α_v = 0: c_h = 0, the undamped oscillator (docs/models.md edge cases): unstable in every model, T* = 0."""
    d = report_json([*KHATIB_CORRIDOR[:-1], "0"])
    assert all(v["verdict"] == "unstable" and v["T_critical"] == 0 for v in d["corridor"].values())


def test_kinematic_robot_delay_margin_against_kinematic_loop_and_closed_form():
    """--robot kinematic --k 2 with NV = 2 (KB's law, L = 1 m: N = 2.048 1/m, V = 2/N): exact_delay's T* is
    `kinematic_loop`'s and docs/models.md's T* = atan2(K_s, ω)/ω, ω² = (−K_s² + √(K_s⁴ + 4K_s²N²V²))/2 = 0.575307 s.
    τ is reported as not used. Tolerance 1e-6 (T* bisected to 1e-9)."""
    V = 2 / 2.048
    d = report_json(["--robot", "kinematic", "--k", "2", "--L", "1", "--V", repr(V), "--T", "0.3", "--model", "exact_delay"])
    assert d["environment"]["corridor"]["NV"] == pytest.approx(2.0, rel=1e-12)
    assert d["inputs"]["tau"]["source"].startswith("not used") and d["inputs"]["robot"]["value"] == "kinematic"
    got = d["corridor"]["exact_delay"]["T_critical"]
    assert got == pytest.approx(ExactDelay().critical_delay(2.0, kinematic_loop(2.0, 0.3)), rel=1e-6)
    K, NV = 2.0, 2.0
    w = math.sqrt((-K * K + math.sqrt(K**4 + 4 * K * K * NV * NV)) / 2)
    assert got == pytest.approx(math.atan2(K, w) / w, rel=1e-6) and got == pytest.approx(0.575307, rel=1e-6)


def test_kinematic_random_laws_match_tau_zero():
    """A kinematic robot is KB's loop with τ = 0, k = K_s: its report equals the steering report of that robot
    (exactly: the same route), for KB's law and for Khatib's."""
    for extra in ([], ["--law", "khatib", "--goal-distance", "2", "--eta", "0.3"]):
        kin = report_json(["--robot", "kinematic", "--k", "3.5", "--tau", "0.7", "--alpha", "40", "--L", "0.9", *extra])
        ste = report_json(["--k", "3.5", "--tau", "0", "--alpha", "40", "--L", "0.9", *extra])
        assert kin["wall"] == ste["wall"] and kin["corridor"] == ste["corridor"]


def test_steering_default_is_byte_identical():
    """--robot steering (typed) prints exactly what the report printed before the families existed."""
    for fmt in ("text", "json", "markdown"):
        a = run(["report", "--alpha", "20", "--L", "0.9", "--format", fmt])
        b = run(["report", "--robot", "steering", "--alpha", "20", "--L", "0.9", "--format", fmt])
        assert a == b and a[0] == 0


def test_holonomic_text_and_markdown_render():
    """The text and Markdown forms carry κ, c_h, T* and the tracking line (what a user reads)."""
    code, out, _ = run(["report", *KHATIB_CORRIDOR, "--compute-delay", "0"])
    assert code == 0 and "kappa = 24 1/s^2, c_h = 0.2 1/s" in out and "0.01667" in out and "zeta = 0.1, omega_n = 1 rad/s" in out
    code, out, _ = run(["report", *KHATIB_CORRIDOR, "--format", "markdown"])
    assert code == 0 and "## Corridor, L = 0.5 m, holonomic robot" in out


@pytest.mark.parametrize("argv,message", [
    (["--mass", "2", "--L", "1"], "--mass applies to --robot holonomic, not to --robot steering"),
    (["--robot", "holonomic", "--law", "grid", "--L", "1"], "--robot holonomic takes --law velocity or velocity-gated"),
    (["--robot", "holonomic", "--L", "1"], "--robot holonomic takes --law velocity or velocity-gated"),
    (["--robot", "holonomic", "--law", "velocity", "--L", "1"], "no lateral stiffness"),
    (["--robot", "holonomic", "--law", "velocity", "--k", "3", "--tau", "0.1", "--L", "0.5", "--door", "1"], "--door applies to --robot steering"),
    (["--robot", "wheeled", "--L", "1"], "argument --robot: invalid choice"),
])
def test_bad_input_exits_2_naming_the_option(argv, message):
    """Bad input: exit 2, nothing on stdout, one line naming the option (its range: tests/test_cli_fuzz.py)."""
    code, out, err = run(["report", *argv])
    assert code == 2 and out == ""
    assert err.startswith("pfm-stability: error: ") and message in err and len(err.splitlines()) == 1


def test_one_report_types_each_family_result():
    """`build_report` is the one entry point: each geometry's result is typed by the loop that decides it (a steering
    analysis, a holonomic scene, a non-smooth scene), the remedies are held once under the report's keys for every family
    (a holonomic verdict's: the period T*), and the JSON is what those objects hold. Exact comparisons: the same values."""
    from pfm_stability.analysis.criteria import CorridorAnalysis, WallAnalysis
    from pfm_stability.models.holonomic import HOLONOMIC, HolonomicVerdict
    from pfm_stability.report.families import HolonomicScene, NonSmoothScene

    controller = CARMEL.controller
    static = build_report(CARMEL.robot, controller, alpha_deg=20.0, L=0.9)
    assert isinstance(static.wall, WallAnalysis) and isinstance(static.corridor, CorridorAnalysis) and not hasattr(static, "extras")
    law = make_family_law("velocity", eta=0.3, rho0=2.0, alpha_v=0.1)
    holonomic = build_report(CARMEL.robot, controller, family="holonomic", law=law, alpha_deg=60.0, L=0.5)
    assert isinstance(holonomic.wall, HolonomicScene) and isinstance(holonomic.corridor, HolonomicScene) and holonomic.family is HOLONOMIC
    assert holonomic.kb_errors == () and holonomic.tracking is not None
    d = holonomic.to_dict()
    for name, v in holonomic.corridor.models.items():
        assert isinstance(v, HolonomicVerdict) and d["corridor"][name]["to_stabilize"] == holonomic.remedies[("corridor", name)]
        if not v.stable and 0 < v.T_critical < controller.T:
            assert holonomic.remedies[("corridor", name)]["T"]["to"] == v.T_critical
    for i, e in enumerate(holonomic.wall.equilibria):
        assert [d["environment"]["wall"]["equilibria"][i][k] for k in ("kappa", "c_h")] == [e.gains.kappa, e.gains.c_h]
    gated = build_report(CARMEL.robot, controller, law=make_family_law("velocity-gated", eta=0.1), alpha_deg=60.0, L=0.5)
    assert isinstance(gated.wall, NonSmoothScene) and gated.models == () and gated.remedies == {} and gated.wall.cycle is None


def test_simulated_cycle_is_handed_to_the_report():
    """The non-smooth wall's cycle comes from the callable the caller gives (the CLI: `validation.non_smooth.simulated_cycle`),
    called with the family, robot, controller, law, α (rad) and mass; a corridor and a continuous controller (T = 0) have none."""
    calls = []

    def cycle(family, robot, controller, law, alpha, *, mass):
        calls.append((family, alpha, mass))
        return {"period": 1.0}

    law = make_family_law("velocity-gated", eta=0.1)
    report = build_report(CARMEL.robot, CARMEL.controller, family="holonomic", law=law, alpha_deg=60.0, L=0.5, mass=2.0, simulate_cycle=cycle)
    assert len(calls) == 1 and calls[0][0] == "holonomic" and calls[0][2] == 2.0 and calls[0][1] == pytest.approx(math.radians(60.0), rel=1e-15)
    assert report.to_dict()["environment"]["wall"]["cycle"] == {"period": 1.0} and report.corridor.cycle is None
    calls.clear()
    build_report(CARMEL.robot, CARMEL.controller.replace(T=0.0), law=law, alpha_deg=60.0, simulate_cycle=cycle)
    assert calls == []


@pytest.mark.parametrize("family, law", [("kinematic", None), ("steering", "velocity"), ("holonomic", "velocity")])
def test_door_applies_to_a_static_law_on_a_steering_robot_only(family, law):
    """`build_report` itself refuses a door with a robot family or a family law (one line naming both)."""
    with pytest.raises(ValueError, match=r"^--door applies to --robot steering with a static law"):
        build_report(CARMEL.robot, CARMEL.controller, family=family, law=make_family_law(law) if law else None, L=0.9, door=1.0)
