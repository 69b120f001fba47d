"""The loop models with the steering plant's gain g and dead time D (docs/models.md, "Plant gain and dead time").

The motor is τω̇ + ω = g·u(t − D): every model's loop gain is g·k where k
multiplies the command, the continuous-time models see the delay T + D, and
the `sampled` model a command that reaches the motor d·T + D = m·T + ε after
its data (the modified z-transform). Checked against routes that share
nothing with the models' code:

* D a whole number of periods is a compute delay (another structure of the model);
* the fractional-delay closed-loop matrix built in `tests/test_sim_dead_time.py`
  from scipy's ``expm`` in the physical coordinates (x, θ, ω);
* cxroots (argument principle) on τs³ + s² + gks + gkNV·e^(−s(T+D)) written out here;
* KB's closed forms with the delay T + D;
* the VFF simulator's linear regime (σ, ω from its linear-prediction fit) and
  its bisected corridor boundary (`validate`);
* ``identify --out`` then ``report --config`` against the same values typed.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from cli_helpers import run
from log_helpers import Plant, Recording, simulate, write_log
from pfm_stability.laws.force_law import PowerLaw, corridor_gain
from pfm_stability.models import ExactDelay, KBFirstOrder, Loop, Pade, Sampled
from pfm_stability.parameters import CARMEL
from pfm_stability.report.stability import build_report
from pfm_stability.sim import run_batch
from pfm_stability.sim.metrics import LINEAR_RESIDUAL, linear_prediction
from pfm_stability.validation import validate_boundary
from test_sim_dead_time import N_EXP, W, _corridor, _random_cases, _sampled_loop

MODELS = (KBFirstOrder(), Pade(3), ExactDelay(), Sampled("command", 0), Sampled("command", 1))


def _loop(case) -> Loop:
    return Loop(case["tau"], case["T"], case["k"], plant_gain=case["g"], dead_time=case["D"])


# ---------------------------------------------------------------- identities
def test_defaults_are_kb_s_loop_and_g_scales_k():
    """g = 1, D = 0 (typed or default) is the loop before them, bit for bit; (k, g) is (g·k, 1) for NV*, ω* and the roots.

    The identity holds in every model because the loop is τs³ + s² + gks + gkNV·e^(−sT):
    it differs from (g·k, 1) only in how g·k is rounded (one product), hence 1e-12.
    """
    rng = np.random.default_rng(3)
    for _ in range(4):
        tau, T, k, g = rng.uniform(0.05, 0.5), rng.uniform(0.02, 0.2), rng.uniform(0.5, 4.0), rng.uniform(0.3, 2.0)
        kb = Loop(tau, T, k)
        assert Loop(tau, T, k, plant_gain=1.0, dead_time=0.0) == kb
        assert Loop.of(CARMEL.robot.replace(tau=tau, k=k), CARMEL.controller.replace(T=T)) == Loop(tau, T, k)
        with_g, scaled = Loop(tau, T, k, plant_gain=g), Loop(tau, T, g * k)
        for model in MODELS:
            a, b = model.boundary(with_g), model.boundary(scaled)
            assert a.NV_critical == pytest.approx(b.NV_critical, rel=1e-12), model
            assert model.rightmost_root(0.7 * a.NV_critical, with_g) == pytest.approx(model.rightmost_root(0.7 * b.NV_critical, scaled), rel=1e-9)


def test_a_whole_period_of_dead_time_is_a_compute_delay():
    """Sampled, hold=command: D = T with d = 0 is d = 1 with D = 0 (the same delayed command; to round-off: the
    dead-time route builds its augmented blocks its own way), for NV*, ω*, the poles and T*-free verdicts."""
    rng = np.random.default_rng(7)
    for _ in range(5):
        tau, T, k, g = rng.uniform(0.05, 0.5), rng.uniform(0.02, 0.2), rng.uniform(0.5, 4.0), rng.uniform(0.5, 1.5)
        late, delayed = Loop(tau, T, k, plant_gain=g, dead_time=T), Loop(tau, T, k, plant_gain=g)
        a, b = Sampled("command", 0).boundary(late), Sampled("command", 1).boundary(delayed)
        assert a.NV_critical == pytest.approx(b.NV_critical, rel=1e-9)
        assert a.omega_critical == pytest.approx(b.omega_critical, rel=1e-9)
        z_a = np.sort_complex(Sampled("command", 0).eigenvalues(0.8 * a.NV_critical, late))
        z_b = np.sort_complex(Sampled("command", 1).eigenvalues(0.8 * b.NV_critical, delayed))
        assert np.max(np.abs(z_a - z_b)) < 1e-10


def test_kb_first_order_closed_forms_with_the_plant():
    """KB's step from eq (18) to (19), each delay to first order: e^(−sD) ≈ 1 − sD on the heading term, e^(−s(T+D)) ≈
    1 − s(T + D) on the field's. The closed forms (docs/models.md, "Plant gain and dead time") are re-derived here with
    sympy from Routh's conditions of that cubic, for the heading closed by the drive and sampled by the controller, c = 0
    and c ≠ 0: NV* (1e-12: one closed form against the crossing route), and T*, D*, k* against the loop being critical
    there (the model's NV* at T*, D*, k* equals NV to 1e-9) and against the generic searches (1e-6: their bracket is 1e-7)."""
    sp = pytest.importorskip("sympy")
    from pfm_stability.models import LoopModel
    from pfm_stability.models.dead_time import search_dead_time

    s_, tau_, gk_, h1_, hK_, c_, NV_ = sp.symbols("s tau gk h1 hK c NV", real=True)
    cubic = sp.Poly(sp.expand(tau_ * s_**3 + s_**2 + gk_ * s_ * (1 - h1_ * s_) + gk_ * (c_ * s_ + NV_) * (1 - hK_ * s_)), s_)
    a3, a2, a1, a0 = cubic.all_coeffs()
    boundary = sp.solve(sp.Eq(a2 * a1, a3 * a0), NV_)[0]  # Routh's s¹ row vanishes: NV* (a2 > 0 checked below)
    model = KBFirstOrder()
    for tau, T, k, g, D, c, sampled in ((0.3, 0.065, 2.0, 0.7, 0.05, 0.0, False), (0.2, 0.1, 1.5, 1.2, 0.03, 0.4, False),
                                        (0.4, 0.05, 3.0, 0.9, 0.02, 0.0, True), (0.25, 0.08, 1.0, 1.0, 0.1, -0.3, True)):
        loop = Loop(tau, T, k, c=c, plant_gain=g, dead_time=D, heading_sampled=sampled)
        values = {tau_: tau, gk_: g * k, h1_: D + (T if sampled else 0.0), hK_: T + D, c_: c}
        assert float(a2.subs(values)) > 0
        b = model.boundary(loop)
        assert b.NV_critical == pytest.approx(float(boundary.subs(values)), rel=1e-12)
        assert b.omega_critical == pytest.approx(math.sqrt(float(a0.subs({**values, NV_: b.NV_critical}) / a2.subs(values))), rel=1e-9)
        NV = 0.6 * b.NV_critical
        T_star, D_star, k_star = model.critical_delay(NV, loop), model.critical_dead_time(NV, loop), model.critical_gain_k(NV, loop)
        assert model.boundary(loop.with_delay(T_star)).NV_critical == pytest.approx(NV, rel=1e-9)
        assert model.boundary(loop.replace(dead_time=D_star)).NV_critical == pytest.approx(NV, rel=1e-9)
        assert T_star == pytest.approx(LoopModel.critical_delay(model, NV, loop), rel=1e-6)
        assert D_star == pytest.approx(search_dead_time(model, NV, loop), rel=1e-6)
        if math.isfinite(k_star):
            assert model.boundary(loop.replace(k=k_star)).NV_critical == pytest.approx(NV, rel=1e-9)
            assert k_star == pytest.approx(LoopModel.critical_gain_k(model, NV, loop), rel=1e-6)
    long = Loop(0.3, 0.065, 2.0, plant_gain=0.7, dead_time=0.6)  # g·k·D = 0.84 < 1, yet NV·(τ + T + D) > 1 + c at NV = 1.3
    assert model.critical_delay(1.3, long) == 0.0 and model.critical_gain_k(1.3, long) == 0.0


# ---------------------------------------------------------------- the sampled model with a fractional delay
def test_sampled_fractional_delay_equals_the_augmented_matrix_built_in_the_test():
    """Twelve random (τ, T, k, D, g, V, d), D in (0, T), (T, 2T), (2T, 3T): the model's dominant pole equals the
    eigenvalues of the closed loop built with scipy's expm in (x, θ, ω) (`test_sim_dead_time._sampled_loop`) to 1e-9,
    at three gains each; at the model's NV* the oracle's spectral radius is 1 to 1e-8 (the boundary). Two plants
    have NV* = 0 (g·k large with the delay: the steering loop alone is unstable), and the oracle agrees at NV → 0.

    Both are eigenvalues of 4–7-dimensional matrices of O(1) entries, formed differently (δ form and
    Tustin crossings against expm of the raw blocks): 1e-9 is a few hundred ulps of cond·ε.
    """
    unstable_everywhere = 0
    for case in _random_cases(12, seed=21):
        loop, pole = _loop(case), _sampled_loop(case)
        model = Sampled("command", case["d"])
        b = model.boundary(loop)
        gains = (0.3 * b.NV_critical, 0.9 * b.NV_critical, 1.4 * b.NV_critical) if b.NV_critical > 0 else (1e-3, 0.5, 2.0)
        for NV in gains:
            z = pole(NV / case["V"])
            expected = complex(math.log(abs(z)) / case["T"], abs(math.atan2(z.imag, z.real)) / case["T"])
            assert model.rightmost_root(NV, loop) == pytest.approx(expected, rel=1e-9, abs=1e-9), case
            assert model.is_stable(NV, loop) == (abs(z) < 1)
        if b.NV_critical > 0:
            assert abs(pole(b.NV_critical / case["V"])) == pytest.approx(1.0, abs=1e-8)
        else:  # g·k with the delay d·T + D destabilizes the steering loop itself: unstable at any speed
            unstable_everywhere += 1
    assert 1 <= unstable_everywhere <= 4


def test_sampled_refuses_a_dead_time_with_a_held_reference():
    """The same refusal as the simulator's (`Scenario`): one line naming both; the report exits 2 with it."""
    with pytest.raises(ValueError, match=r"^dead_time must be 0 with hold=reference for the sampled model .*; got 0\.05$"):
        Sampled("reference", 0).boundary(Loop(0.3, 0.1, 2.0, dead_time=0.05))
    with pytest.raises(ValueError, match=r"^dead_time must be at most 99999 sampling periods, 9\.9999 s with T = 0\.0001 s .*exact_delay.*; got 10\.0$"):
        Sampled("command", 1).boundary(Loop(0.3, 1e-4, 2.0, dead_time=10.0))  # more commands on their way than MAX_DELAY_STATES
    with pytest.raises(ValueError, match=r"^dead_time must be at most 63 sampling periods, .*characteristic polynomial.*; got 5\.0$"):
        Sampled("command", 1).characteristic(1.0, Loop(0.3, 0.065, 2.0, dead_time=5.0))  # a polynomial in z of degree ~80
    code, out, err = run(["report", "--L", "0.9", "--hold", "reference", "--dead-time", "0.05"])
    assert code == 2 and out == "" and err.count("\n") == 1 and "dead_time must be 0 with hold=reference" in err and "got 0.05" in err
    # D = 0 typed with a plant gain: the report's D* is not searched in the sampled model (it would probe D > 0)
    code, out, err = run(["report", "--L", "0.9", "--hold", "reference", "--dead-time", "0", "--plant-gain", "0.7", "--format", "json"])
    assert code == 0 and err == ""
    corridor = json.loads(out)["corridor"]
    assert "dead_time_critical" not in corridor["sampled"] and corridor["exact_delay"]["dead_time_critical"] > 0
    # the continuous-time models take a dead time with a held reference (the heading closed by the drive, delayed by D)
    code, out, err = run(["report", "--L", "0.9", "--hold", "reference", "--dead-time", "0.05", "--model", "exact_delay", "--format", "json"])
    assert code == 0 and json.loads(out)["corridor"]["exact_delay"]["verdict"] in ("stable", "unstable")


def test_sampled_critical_period_with_the_dead_time_fixed():
    """T* (D fixed) of the sampled model: the loop is stable just below it and unstable just above (1e-4 relative),
    for D below and above the period; and a D that the T → 0 limit (the delay loop with delay D) cannot bear gives 0."""
    model = Sampled("command", 1)
    for D in (0.03, 0.2):
        loop = Loop(0.3, 0.065, 2.0, plant_gain=0.85, dead_time=D)
        NV = 0.6 * model.boundary(loop).NV_critical
        T_star = model.critical_delay(NV, loop)
        assert 0 < T_star < 100
        assert model.is_stable(NV, loop.with_delay(T_star * (1 - 1e-4))) and not model.is_stable(NV, loop.with_delay(T_star * (1 + 1e-4)))
    long = Loop(0.3, 0.065, 2.0, dead_time=1.0)
    assert not ExactDelay().is_stable(2.0, long.with_delay(0.0)) and model.critical_delay(2.0, long) == 0.0


def test_critical_dead_time_in_every_model():
    """D* (the largest dead time tolerated, T fixed) at CARMEL's loop with g = 0.85:

    * `kb_first_order` and `exact_delay`: exact (Routh's quadratic in D; the first D at which a root of the two-delay
      quasi-polynomial reaches the axis), and the loop at D* is critical (its NV* is NV to 1e-9);
    * `sampled`: D* with d = 0 is D* with d = 1 plus one period (a compute delay is a dead time of T), 1e-6; the loop
      is stable at 0.999·D* and unstable at 1.001·D*;
    * `continuous` has no delay: ``inf``; an unstable operating point: 0.
    """
    tau, T, k, g, NV = 0.3, 0.065, 2.0, 0.85, 1.2
    loop = Loop(tau, T, k, plant_gain=g, dead_time=0.07)
    for model in (KBFirstOrder(), ExactDelay()):
        D_star = model.critical_dead_time(NV, loop)
        assert 0 < D_star < 1
        assert model.boundary(loop.replace(dead_time=D_star)).NV_critical == pytest.approx(NV, rel=1e-9)
    now, late = Sampled("command", 1).critical_dead_time(NV, loop), Sampled("command", 0).critical_dead_time(NV, loop)
    assert late == pytest.approx(now + T, rel=1e-6)
    model = Sampled("command", 1)
    assert model.is_stable(NV, loop.replace(dead_time=0.999 * now)) and not model.is_stable(NV, loop.replace(dead_time=1.001 * now))
    from pfm_stability.models import Continuous

    assert Continuous().critical_dead_time(NV, loop) == math.inf
    assert ExactDelay().critical_dead_time(4.0, loop) == 0.0 and model.critical_dead_time(4.0, loop) == 0.0


# ---------------------------------------------------------------- exact_delay against cxroots
@pytest.mark.slow
def test_exact_delay_with_g_and_d_against_the_argument_principle():
    """τs³ + s² + gk·s·e^(−sD) + gkNV·e^(−s(T+D)) written out here (D delays the whole command): cxroots counts no root
    in Re s > 0 at NV*(1 − 1e-6) and a pair at ±jω* (1e-6) at NV*(1 + 1e-6); the loop at the model's T* is critical.

    cxroots counts by the argument principle on a rectangle holding every right-half-plane root
    (|s| < R where |a(s)| > gkNV); its Newton polishing is good to ~1e-10.
    """
    cxroots = pytest.importorskip("cxroots")
    rng = np.random.default_rng(5)
    for _ in range(2):
        tau, T, k, g, D = rng.uniform(0.1, 0.5), rng.uniform(0.02, 0.2), rng.uniform(0.5, 4.0), rng.uniform(0.5, 1.5), rng.uniform(0.01, 0.3)
        loop = Loop(tau, T, k, plant_gain=g, dead_time=D)
        b = ExactDelay().boundary(loop)
        gk, delay = g * k, T + D
        R = 1.0
        while tau * R**3 - R**2 - gk * R <= 2 * gk * b.NV_critical:  # |p0(s)| > |the rest| for |s| >= R, Re s >= 0
            R *= 1.5
        for factor, expected in ((1 - 1e-6, 0), (1 + 1e-6, 2)):
            K = gk * b.NV_critical * factor
            f = lambda s: tau * s**3 + s**2 + gk * s * np.exp(-s * D) + K * np.exp(-s * delay)  # noqa: E731
            df = lambda s: 3 * tau * s**2 + 2 * s + gk * (1 - D * s) * np.exp(-s * D) - K * delay * np.exp(-s * delay)  # noqa: E731
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                roots = np.array(cxroots.Rectangle([-0.01, R], [-R, R]).roots(f, df).roots)
            right = roots[roots.real > 0]
            assert len(right) == expected
            assert np.all(np.abs(np.abs(right.imag) - b.omega_critical) < 1e-6)
        NV = 0.5 * b.NV_critical
        T_star = ExactDelay().critical_delay(NV, loop)
        assert ExactDelay().boundary(loop.with_delay(T_star)).NV_critical == pytest.approx(NV, rel=1e-6)


# ---------------------------------------------------------------- the simulator
def test_simulated_linear_regime_equals_the_sampled_model():
    """Four random plants (D below and above T, g != 1, d = 0 and 1): the VFF simulator started 1e-5 m off centre, at
    the f whose model pole has σ ≈ ∓0.15 1/s: its linear-prediction σ and ω equal the `sampled` model's dominant pole
    to 1e-6 relative (as tests/test_sim_accuracy.py for D = 0; the fit's conditioning, measured 1e-7)."""
    cases = _random_cases(4, seed=8, k_max=2.5)
    per_f = corridor_gain(PowerLaw(1.0, N_EXP, W), 1.0)
    scenarios, poles = [], []
    for i, c in enumerate(cases):
        loop, model = _loop(c), Sampled("command", c["d"])
        target = (-0.15, 0.1)[i % 2]
        found = []
        for f in np.geomspace(1e-2, 1e2, 120):
            r = model.rightmost_root(f * per_f * c["V"], loop)
            if r.imag > 1e-6 and 0.03 < abs(r.real) < 0.6:
                found.append((abs(r.real - target), float(f), r))
        _, f, root = min(found)
        poles.append(root)
        scenarios.append(_corridor(c, L=1.0, f=f, offset=1e-5, duration=max(12.0, 6 * math.pi / root.imag, 60 * c["T"])))
    for c, s, r, root in zip(cases, scenarios, run_batch(scenarios, record="offset").runs, poles):
        assert r.metrics.fit_residual < LINEAR_RESIDUAL
        sigma, omega, _ = linear_prediction(r.offset, s.loop_order(), c["T"])
        assert sigma == pytest.approx(root.real, rel=1e-6) and omega == pytest.approx(root.imag, rel=1e-6), c


@pytest.mark.slow
def test_predicted_corridor_boundary_with_g_and_d_matches_the_simulated_bisection():
    """`validate` in CARMEL's analytic corridor with a dead time and a plant gain: the `sampled` model's L* (from its
    NV* with D and g) within 3 % of the simulated bisection (bracket 1 %): two plants, the measured errors below 1 %."""
    for robot in (CARMEL.robot.replace(dead_time=0.04, plant_gain=0.8), CARMEL.robot.replace(dead_time=0.1, plant_gain=1.2)):
        v = validate_boundary("corridor", env="analytic", robot=robot, rtol=0.01, members=3)
        assert abs(v.relative_error["sampled"]) < 0.03, (robot, v.simulated_boundary, v.predicted_boundary)


# ---------------------------------------------------------------- the report
def test_report_lists_g_and_d_only_when_given():
    """The report's inputs carry D and g (after k, with their sources) only when they differ from KB's robot or were
    typed, so the recorded reports (and a file stating KB's D = 0, g = 1) keep their keys; a holonomic robot marks them
    unused."""
    plain = build_report(CARMEL.robot, CARMEL.controller, L=0.9)
    assert "dead_time" not in plain.inputs and "plant_gain" not in plain.inputs
    given = build_report(CARMEL.robot.replace(dead_time=0.07), CARMEL.controller, L=0.9, sources={"plant_gain": "user"})
    assert list(given.inputs)[list(given.inputs).index("k") + 1:][:2] == ["dead_time", "plant_gain"]
    assert given.inputs["dead_time"] == {"value": 0.07, "unit": "s", "source": "user"} and given.inputs["plant_gain"]["value"] == 1.0
    code, out, _ = run(["report", "--L", "0.9", "--dead-time", "0.07", "--format", "markdown"])
    assert code == 0 and "| D (steering plant dead time) | 0.07 | s | user |" in out and "plant gain" not in out
    code, out, _ = run(["report", "--robot", "holonomic", "--law", "velocity", "--L", "0.5", "--plant-gain", "0.8", "--format", "json"])
    assert code == 0 and json.loads(out)["inputs"]["plant_gain"]["source"] == "not used (holonomic robot)"


@pytest.mark.slow
def test_identify_then_report_uses_the_measured_plant(tmp_path):
    """A log of a plant g = 0.8, τ = 0.3 s, D = 0.1 s → ``identify --out`` → ``report --config``: its corridor V* per
    model equals the report with the same τ, T, D and g typed (to the printed digits: the same numbers either way)."""
    log = write_log(simulate(Plant(g=0.8, tau=0.3, dead_time=0.1), Recording(duration=20.0)), tmp_path, "csv")
    out = tmp_path / "robot.yaml"
    assert run(["identify", str(log), "--out", str(out)])[0] == 0
    code, filed, err = run(["report", "--config", str(out), "--L", "0.9", "--format", "json"])
    assert code == 0, err
    filed = json.loads(filed)
    typed_args = [f"--{name.replace('_', '-')}" if name != "T" else "--T" for name in ("tau", "T", "dead_time", "plant_gain")]
    values = [filed["inputs"][name]["value"] for name in ("tau", "T", "dead_time", "plant_gain")]
    assert filed["inputs"]["dead_time"]["source"] == f"config {out}"
    assert values[2] == pytest.approx(0.1, abs=0.02) and values[3] == pytest.approx(0.8, rel=0.05)
    argv = ["report", "--L", "0.9", "--format", "json"] + [x for pair in zip(typed_args, map(repr, values)) for x in pair]
    code, typed, err = run(argv)
    assert code == 0, err
    typed = json.loads(typed)
    assert filed["corridor"] == typed["corridor"]
    plain = json.loads(run(["report", "--L", "0.9", "--tau", repr(values[0]), "--T", repr(values[1]), "--format", "json"])[1])
    assert plain["corridor"]["sampled"] != filed["corridor"]["sampled"]


def test_region_maps_take_g_and_d():
    """`corridor_region` with `exact_delay` (the vectorized crossing count on arrays) and with `sampled` (the stable
    set): every point's verdict equals the scalar model's on `Loop.of` of the same robot, whose g and D it carries."""
    from pfm_stability.analysis.regions import corridor_region

    robot, controller = CARMEL.robot.replace(dead_time=0.08, plant_gain=0.75), CARMEL.controller
    L, V = np.array([0.6, 0.75, 0.9, 1.2]), np.array([0.2, 0.5, 0.8, 1.2, 1.6])
    loop = Loop.of(robot, controller)
    for model in (ExactDelay(), Sampled(controller.hold, controller.compute_delay)):
        grid = corridor_region(robot, controller, L, V, model=model.name)
        expected = np.array([[model.is_stable(float(NV), loop) for NV in row] for row in grid.NV])
        assert np.array_equal(grid.stable, expected) and expected.any() and not expected.all()


def test_report_gives_d_star_and_the_remedy_only_with_a_plant():
    """A robot with D or g: every verdict carries D* (``dead_time_critical``, the model's `critical_dead_time` on
    `Loop.of`), the table a ``D* s`` column and the footnote its meaning, and an unstable verdict whose D* is below D
    suggests lowering the dead time to D*; KB's robot has none of them (the recorded reports' keys)."""
    plain = build_report(CARMEL.robot, CARMEL.controller, L=1.1).to_dict()
    assert not any("dead_time_critical" in v for v in plain["corridor"].values())
    robot = CARMEL.robot.replace(dead_time=0.25, plant_gain=0.85)
    report = build_report(robot, CARMEL.controller, L=1.1)
    data = report.to_dict()["corridor"]
    loop = Loop.of(robot, CARMEL.controller)
    sampled = Sampled(CARMEL.controller.hold, CARMEL.controller.compute_delay)
    assert data["sampled"]["dead_time_critical"] == pytest.approx(sampled.critical_dead_time(data["sampled"]["NV"], loop), rel=1e-12)
    assert data["sampled"]["verdict"] == "unstable" and data["sampled"]["dead_time_critical"] < 0.25
    assert data["sampled"]["to_stabilize"]["dead_time"] == {"to": data["sampled"]["dead_time_critical"], "direction": "lower",
                                                            "change_percent": pytest.approx((data["sampled"]["dead_time_critical"] / 0.25 - 1) * 100)}
    assert data["exact_delay"]["stable_side"]["dead_time_critical"] == "below"
    code, out, _ = run(["report", "--L", "1.1", "--dead-time", "0.25", "--plant-gain", "0.85"])
    assert code == 0 and "D* s" in out and "lower dead_time to <= " in out and "D* is the largest dead time" in out
    code, out, _ = run(["report", "--L", "1.1"])
    assert code == 0 and "D* s" not in out and "dead time" not in out


def test_outputs_with_a_plant_validate_against_the_schema():
    """`report` (wall and corridor, D* and the dead-time remedy) and `simulate` with D and g: their JSON validates
    against the published schema (`io.schema`), the new keys included."""
    from jsonschema import Draft202012Validator

    from pfm_stability.io.schema import load_schema

    validator = Draft202012Validator(load_schema())
    for argv in (["report", "--alpha", "30", "--L", "1.1", "--dead-time", "0.25", "--plant-gain", "0.85"],
                 ["simulate", "--scenario", "corridor", "--env", "analytic", "--duration", "3", "--dead-time", "0.05", "--plant-gain", "0.8"]):
        code, out, err = run([*argv, "--format", "json"])
        assert code == 0, err
        data = json.loads(out)
        assert not list(validator.iter_errors(data)), argv
        assert data["inputs"]["dead_time"] in (0.25, 0.05) or data["inputs"]["dead_time"]["value"] == 0.25
