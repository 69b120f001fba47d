"""`pfm-stability report --law velocity|fuzzy|velocity-gated` on a steering robot (docs/velocity_and_fuzzy.md).

The velocity attraction and the fuzzy-scheduled law reach the KB loop through N and the
heading gain c: the report's gains are checked against `velocity_laws`/`fuzzy_law` and an
independent reconstruction (N_static from Khatib's law, q from the forces), and its
verdicts against the steering models run with `Loop(τ, T, k, c=c)`. The velocity-gated
law gives the non-smooth verdict with its rest band and, from the planar simulator, its cycle.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from cli_helpers import report_json, run

from pfm_stability import CARMEL
from pfm_stability.laws.force_law import wall_equilibria
from pfm_stability.laws.fuzzy_law import FuzzyScheduledLaw
from pfm_stability.models import ExactDelay, Loop, make_model

FUZZY_WALL = ["--law", "fuzzy", "--alpha-p", "50", "--rho0", "0.5", "--alpha", "60"]  # F_a = 2·50·1 = 100 N (docs/velocity_and_fuzzy.md)


def check_verdicts(models: dict, N: float, c: float, V: float):
    """Each model's NV*, stability and margin from the model itself with the heading gain c (rel 1e-9: the same boundary route)."""
    loop = Loop(CARMEL.robot.tau, CARMEL.controller.T, CARMEL.robot.k, c=c)
    for name, v in models.items():
        model = make_model(name, hold=CARMEL.controller.hold, compute_delay=CARMEL.controller.compute_delay) if name == "sampled" else make_model(name)
        NV_star = model.boundary(loop).NV_critical
        assert v["NV"] == pytest.approx(N * V, rel=1e-12)
        assert v["NV_critical"] == pytest.approx(NV_star, rel=1e-9), name
        assert v["stable"] == model.is_stable(N * V, loop), name
        assert v["margin"] == pytest.approx(NV_star / (N * V) - 1, rel=1e-9), name


def test_fuzzy_wall_gains_per_equilibrium_and_verdicts_use_total_N_and_c():
    """Left wall, ρ0 0.5, F_a 100, α 60°: N frozen 13.459, N total 13.499, c 0.168 (docs/velocity_and_fuzzy.md table,
    3–5 digits); every equilibrium's N, N_frozen, c equal `FuzzyScheduledLaw.wall_equilibria` exactly; the verdicts
    are the models' at N total and c (not N frozen)."""
    d = report_json(FUZZY_WALL)
    law = FuzzyScheduledLaw(0.5, 100.0)
    expected = law.wall_equilibria(math.radians(60), "left")
    eqs = d["environment"]["wall"]["equilibria"]
    assert [(e["d0"], e["N"], e["N_frozen"], e["c"]) for e in eqs] == [(q.x0, q.N, q.N_frozen, q.c) for q in expected]
    first = eqs[0]
    assert first["N_frozen"] == pytest.approx(13.459, abs=5e-4) and first["N"] == pytest.approx(13.499, abs=5e-4)
    assert first["c"] == pytest.approx(0.168, abs=5e-4)
    check_verdicts(first["models"], first["N"], first["c"], CARMEL.robot.V)
    bracket = d["environment"]["wall"]["robust_bracket"]
    assert bracket["N"] == pytest.approx([9.147, 23.175], abs=1e-3)


def test_fuzzy_right_wall_and_corridor():
    """The right wall (tables asymmetric): N total 13.256, c 0.403 (docs table, 3 decimals); the corridor's verdicts
    are at the equilibrium nearest the centre line, with its N total and c."""
    d = report_json([*FUZZY_WALL, "--side", "right", "--L", "0.4", "--model", "exact_delay"])
    e = d["environment"]["wall"]["equilibria"][0]
    assert e["N"] == pytest.approx(13.256, abs=1e-3) and e["c"] == pytest.approx(0.403, abs=1e-3)
    corridor = d["environment"]["corridor"]
    mid = min(corridor["equilibria"], key=lambda q: abs(q["x0"]))
    assert corridor["N"] == mid["N"] and corridor["c"] == mid["c"]
    check_verdicts(d["corridor"], mid["N"], mid["c"], CARMEL.robot.V)


def test_velocity_law_steering_gains_against_static_law_and_q():
    """N = N_static/(1 − q), c = q/(1 − q), q = 2α_v V/(F_a sin α) (GC2002 §7, n = 2): N_static from Khatib's law
    (`force_law.wall_equilibria`), on random α_v, α, V; and the models at that c. rel 1e-12 on the gains (same algebra)."""
    rng = np.random.default_rng(7)
    for _ in range(4):
        alpha, V = rng.uniform(30, 80), rng.uniform(0.2, 1.5)
        Fa = 1.0  # defaults: α_p 0.5, m 2, ρ_g 1
        alpha_v = rng.uniform(0.05, 0.6) * Fa * math.sin(math.radians(alpha)) / (2 * V)  # q in (0.05, 0.6)
        d = report_json(["--law", "velocity", "--alpha-v", repr(alpha_v), "--alpha", repr(alpha), "--V", repr(V), "--model", "exact_delay"])
        from pfm_stability.report.families import make_family_law

        static = wall_equilibria(make_family_law("velocity").repulsion(), math.radians(alpha))
        q = 2 * alpha_v * V / (Fa * math.sin(math.radians(alpha)))
        eqs = d["environment"]["wall"]["equilibria"]
        assert len(eqs) == len(static)
        for e, s in zip(eqs, static):
            assert e["d0"] == s.x0 and e["N"] == pytest.approx(s.N / (1 - q), rel=1e-12) and e["c"] == pytest.approx(q / (1 - q), rel=1e-12)
        V_check = eqs[0]["models"]["exact_delay"]
        assert V_check["V_critical"] is None  # N and c move with V: no V* = NV*/N
        check_verdicts(eqs[0]["models"], eqs[0]["N"], eqs[0]["c"], V)


def test_velocity_law_exact_delay_NV_star_for_c_one_half():
    """docs/models.md: CARMEL's exact-delay NV* for c = 0.5 is 3.92682 (5 digits). q = 1/3 gives c = 0.5:
    α_v = F_a sin α/(6V) with F_a = 1, α = 60°, V = 0.8."""
    alpha_v = math.sin(math.radians(60)) / (6 * 0.8)
    d = report_json(["--law", "velocity", "--alpha-v", repr(alpha_v), "--alpha", "60", "--model", "exact_delay"])
    assert d["environment"]["wall"]["c"] == pytest.approx(0.5, rel=1e-12)
    assert d["wall"]["exact_delay"]["NV_critical"] == pytest.approx(3.92682, abs=1e-5)
    assert ExactDelay().boundary(Loop(0.3, 0.065, 2.0, c=0.5)).NV_critical == pytest.approx(3.92682, abs=1e-5)


def test_velocity_gated_is_non_smooth_with_its_band():
    """η 0.1, F_a 1, α 60°: verdict "non-smooth", rest band [0, d_s], d_s = √(η/(F_a cos α)) = 0.4472 m;
    a corridor: non-smooth, friction η/(L ± x)² inside ρ0 (docs/velocity_and_fuzzy.md). No linear verdicts."""
    d = report_json(["--law", "velocity-gated", "--eta", "0.1", "--alpha", "60", "--L", "0.5", "--no-simulate"])
    wall, corridor = d["environment"]["wall"], d["environment"]["corridor"]
    assert wall["verdict"] == "non-smooth" and corridor["verdict"] == "non-smooth"
    d_s = math.sqrt(0.1 / math.cos(math.radians(60)))
    assert wall["d_s"] == pytest.approx(d_s, rel=1e-12) and wall["rest_band"] == [0.0, pytest.approx(d_s, rel=1e-12)]
    assert wall["cycle"] is None and "wall" not in d and "corridor" not in d
    x = np.array(corridor["offsets"])
    inside = (0.5 + x) < 0.8
    assert np.allclose(np.array(corridor["friction_left"])[inside], 0.1 / (0.5 + x[inside]) ** 2, rtol=1e-12)


@pytest.mark.parametrize("family", ["steering", "kinematic", "holonomic"])
def test_velocity_gated_cycle_from_the_planar_simulator(family, monkeypatch):
    """With the simulator: η 0.1, a_max 1, F_a 1, α 60°, CARMEL's V 0.8, τ 0.3, k 2, hold, T 0.065, compute delay 1.
    The report's cycle is `sim.cycles.wall_cycle` of the family's robot (KB's steering robot, τ = 0 for kinematic,
    a point mass for holonomic), exactly: the wiring is checked against a direct call with the parameters written
    out here; and it lies where the band says (mean and closest distance inside the rest band (0, d_s]). The text
    report of the same command line renders that cycle: the 60-second simulation runs once for the JSON and the
    text (`validation.non_smooth.simulated_cycle` answers a second call with equal arguments from the first)."""
    from pfm_stability.sim.cycles import wall_cycle
    from pfm_stability.sim.planar import PointMass, Steering
    from pfm_stability.laws.velocity_laws import VelocityGatedRepulsion
    from pfm_stability.validation import non_smooth

    simulated, real = [], non_smooth.simulated_cycle

    def once(*args, **kwargs):
        for known_args, known_kwargs, cycle in simulated:
            if known_args == args and known_kwargs == kwargs:
                return cycle
        simulated.append((args, kwargs, real(*args, **kwargs)))
        return simulated[-1][2]

    monkeypatch.setattr(non_smooth, "simulated_cycle", once)
    argv = ["--law", "velocity-gated", "--eta", "0.1", "--a-max", "1", "--alpha", "60", "--robot", family]
    d = report_json(argv)
    cycle = d["environment"]["wall"]["cycle"]
    robot = PointMass(1.0, 1.0) if family == "holonomic" else Steering(0.8, 0.0 if family == "kinematic" else 0.3, 2.0, hold="command")
    direct = wall_cycle(VelocityGatedRepulsion(0.1, 0.8, 1.0), 1.0, math.radians(60), robot, T=0.065, compute_delay=1).to_dict()
    assert cycle == direct  # JSON keeps floats exactly (repr round trip)
    d_s = d["environment"]["wall"]["d_s"]
    assert 0 < cycle["min_distance"] <= cycle["mean_distance"] <= d_s and not cycle["touches_wall"]
    code, out, _ = run(["report", *argv])
    assert code == 0 and "NON-SMOOTH" in out and "simulated cycle: mean distance" in out
    assert len(simulated) == 1  # the text shows the JSON's cycle


def test_velocity_gated_with_a_continuous_controller_has_no_cycle():
    """T = 0: nothing sampled to simulate; the band alone, exit 0."""
    d = report_json(["--law", "velocity-gated", "--alpha", "60", "--T", "0"])
    assert d["environment"]["wall"]["cycle"] is None


@pytest.mark.parametrize("argv,message", [
    (["--alpha-p", "1", "--L", "1"], "--alpha-p applies to --law velocity, velocity-gated or fuzzy, not to --law power"),
    (["--law", "velocity", "--xi", "1", "--L", "1"], "--xi applies to --law khatib or gnron, not to --law velocity"),
    (["--law", "fuzzy", "--alpha-v", "1", "--alpha", "60"], "--alpha-v applies to --law velocity, not to --law fuzzy"),
    (["--law", "velocity", "--f", "2", "--alpha", "60"], "--f applies to --law power or grid, not to --law velocity"),
    (["--law", "velocity", "--side", "left", "--alpha", "60"], "--side applies to --law fuzzy"),
    (["--law", "velocity", "--alpha-v", "10", "--alpha", "60"], "V must be below the speed at which the velocity attraction cancels"),
])
def test_bad_input_exits_2_naming_the_option(argv, message):
    """Bad input: exit 2, nothing on stdout, one line naming the law the option applies to (its range: tests/test_cli_fuzz.py)."""
    code, out, err = run(["report", *argv])
    assert code == 2 and out == "", err
    assert err.startswith("pfm-stability: error: ") and message in err and len(err.splitlines()) == 1, err


# ------------------------------------------------------------------ KB's error with a heading gain
@functools.lru_cache(maxsize=1)
def _kb_first_order_routh():
    """KB's first-order loop with a heading gain, derived here: τs³ + s² + ks + k(cs + NV)(1 − sT) expanded by sympy;
    Routh–Hurwitz for a cubic (every coefficient > 0 and a2·a1 > a3·a0). Returns the coefficients and the roots in NV of
    the boundary a2·a1 = a3·a0 (a quadratic), as functions of (τ, T, k, c[, NV])."""
    import sympy as sp

    s, NV, tau, T, k, c = sp.symbols("s NV tau T k c")
    coefficients = sp.Poly(sp.expand(tau * s**3 + s**2 + k * s + k * (c * s + NV) * (1 - s * T)), s).all_coeffs()
    a3, a2, a1, a0 = coefficients
    roots = sp.solve(sp.Eq(a2 * a1 - a3 * a0, 0), NV)
    return sp.lambdify((tau, T, k, c, NV), coefficients), [sp.lambdify((tau, T, k, c), r) for r in roots]


def _kb_first_order_NV_star(tau: float, T: float, k: float, c: float) -> float:
    """The smallest positive root of the Routh boundary at which every coefficient is still positive just below it."""
    coefficients, roots = _kb_first_order_routh()
    values = [complex(r(tau, T, k, c)) for r in roots]
    real = [v.real for v in values if abs(v.imag) <= 1e-12 * abs(v) and v.real > 0]
    return min(x for x in real if all(a > 0 for a in coefficients(tau, T, k, c, x * (1 - 1e-9))))


def test_kb_error_compares_the_loop_the_tables_decide():
    """A small robot with the velocity attraction (W 0.3 m, α 30°, L 0.4 m, ρ0 1 m): wall and corridor have different
    heading gains c, so KB's error is given per loop (``kb_errors``, wall first). Each compares kb_first_order's NV*
    with the heading gain against sampled's for that loop: both equal the table's values read back from the same JSON
    (rel 1e-12: the same computation), and KB's side equals the Routh bound of τs³ + s² + ks + k(cs + NV)(1 − sT)
    derived here with sympy (rel 1e-9). The text prints those numbers, not KB's c = 0 ones (2.74 vs 2.123)."""
    argv = ["--law", "velocity", "--alpha", "30", "--L", "0.4", "--rho0", "1.0", "--W", "0.3"]
    d = report_json(argv)
    errors = d["kb_errors"]
    assert [e["where"] for e in errors] == [["wall"], ["corridor"]] and d["kb_error"] == errors[0]
    r, ctl = CARMEL.robot, CARMEL.controller
    code, text, _ = run(["report", *argv])
    assert code == 0
    for e, geometry in zip(errors, ("wall", "corridor")):
        c = d["environment"][geometry]["c"]
        assert e["c"] == c != 0
        assert e["NV_critical_kb_first_order"] == pytest.approx(d[geometry]["kb_first_order"]["NV_critical"], rel=1e-12)
        assert e["NV_critical_sampled"] == pytest.approx(d[geometry]["sampled"]["NV_critical"], rel=1e-12)
        assert e["NV_critical_kb_first_order"] == pytest.approx(_kb_first_order_NV_star(r.tau, ctl.T, r.k, c), rel=1e-9)
        assert e["relative"] == pytest.approx(e["NV_critical_kb_first_order"] / e["NV_critical_sampled"] - 1, rel=1e-12)
        line = next(x for x in text.splitlines() if x.startswith("KB's criterion") and f"kb_first_order, {geometry})" in x)
        assert line.endswith(f"NV* = {e['NV_critical_kb_first_order']:.4g} vs {e['NV_critical_sampled']:.4g} 1/s.")
    assert "NV* = 2.74 vs 2.123 1/s" not in text


def test_kb_error_of_the_fuzzy_law_is_its_wall_loop():
    """The fuzzy law's wall (docs/velocity_and_fuzzy.md example): one loop, c = 0.1683; KB's error compares the table's
    kb_first_order and sampled NV*, the former also equal to the sympy Routh bound (rel 1e-9)."""
    d = report_json([*FUZZY_WALL, "--model", "kb_first_order", "--model", "sampled"])
    e, c = d["kb_error"], d["environment"]["wall"]["c"]
    assert "kb_errors" not in d and e["where"] == ["wall"] and e["c"] == c
    assert e["NV_critical_kb_first_order"] == pytest.approx(d["wall"]["kb_first_order"]["NV_critical"], rel=1e-12)
    assert e["NV_critical_sampled"] == pytest.approx(d["wall"]["sampled"]["NV_critical"], rel=1e-12)
    assert e["NV_critical_kb_first_order"] == pytest.approx(_kb_first_order_NV_star(CARMEL.robot.tau, CARMEL.controller.T, CARMEL.robot.k, c), rel=1e-9)


def test_a_heading_gain_beyond_the_models_is_answered():
    """The fuzzy law in a narrow corridor (L 0.25 m, W 0.18 m) has c ≈ 943, beyond the models' [−0.99, 100]: the report
    answers (exit 0) instead of failing on an internal check ("c must be ... got 942.76", a value never typed). Every
    verdict is "undecided" with NV*, margin and critical values null and a reason naming c and the corridor; no remedy,
    no KB error for that loop; a wall in the same report is decided as usual (docs/velocity_and_fuzzy.md)."""
    d = report_json(["--law", "fuzzy", "--L", "0.25", "--W", "0.18", "--alpha", "60"])
    c = d["environment"]["corridor"]["c"]
    assert c > 100
    for v in d["corridor"].values():
        assert v["verdict"] == "undecided" and v["stable"] is False and v["NV_critical"] is None and v["margin"] is None
        assert v["T_critical"] is None and v["to_stabilize"] == {}
        assert f"c = {c:.4g}" in v["reason"] and "L = 0.25 m" in v["reason"] and "[-0.99, 100]" in v["reason"]
    assert d["kb_error"]["where"] == ["wall"] and "kb_errors" not in d
    assert all(v["verdict"] in ("stable", "unstable") for v in d["wall"].values())
    code, text, err = run(["report", "--law", "fuzzy", "--L", "0.25", "--W", "0.18"])
    assert code == 0 and err == "" and "every model: undecided (c = " in text and "to stabilize" not in text
