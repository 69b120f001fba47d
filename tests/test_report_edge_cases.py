"""Reports that once crashed or lied: unstable at any speed (NV* = 0), defaults that contradicted
the controller, and random parameter sets far from CARMEL.

Independent oracle for the sampled loop: the ZOH discretization by scipy's matrix exponential
and numpy eigenvalues (not the model's δ form, numpy exponential or crossing polynomials).
"""

import json
import math

import numpy as np
import pytest
import scipy.linalg

from pfm_stability import CARMEL, Corridor, Wall, analyze_corridor, analyze_wall, build_report
from pfm_stability.models import MODEL_NAMES, Loop, Sampled, make_models, models_for
from pfm_stability.models.sampled import continuous_plant

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")  # a numpy warning is a silent NaN or overflow


def _sampled_stable(robot, controller, NV):
    loop = Loop(robot.tau, controller.T, robot.k)
    A, B, F0, F1 = continuous_plant(loop, controller.hold)
    n = A.shape[0]
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n:] = A, B
    E = scipy.linalg.expm(M * loop.T)
    Phi, Gamma = E[:n, :n], E[:n, n:]
    F = (F0 + loop.k * NV * F1)[None, :]
    closed = Phi - Gamma @ F if controller.compute_delay == 0 else np.block([[Phi, Gamma], [-F, np.zeros((1, 1))]])
    return bool(np.max(np.abs(np.linalg.eigvals(closed))) < 1)


def _strict_json(data):
    return json.loads(json.dumps(data, allow_nan=False), parse_constant=lambda c: pytest.fail(f"bare {c} in JSON"))


UNSTABLE_AT_ANY_SPEED = [
    dict(robot=CARMEL.robot.replace(k=12.0), controller=CARMEL.controller),
    dict(robot=CARMEL.robot, controller=CARMEL.controller.replace(T=1.0)),
    dict(robot=CARMEL.robot.replace(tau=1.07, k=6.47), controller=CARMEL.controller.replace(T=0.112)),
]


@pytest.mark.parametrize("case", UNSTABLE_AT_ANY_SPEED, ids=["k12", "T1", "tau1.07"])
def test_unstable_at_any_speed_is_a_defined_answer(case):
    """The three filed cases (command hold, compute delay 1): verdict unstable, NV* = 0, V* = 0,
    α* = 90°, wall f* = inf, L* = inf, corridor f* = 0 (no speed, angle, force ratio or width
    helps: the documented meaning of "unstable at any speed"); the only remedies are a shorter
    T or a lower k, and each of them, applied at 0.999 of its critical value, is stable by the
    independent ZOH oracle; where one is missing its critical value is 0 and the oracle finds
    the loop unstable at 1e-3 of the present value too (τ = 1.07 s: τNV > 1, unstable without
    any delay). The JSON is strict (no NaN/Infinity tokens), infinities are "inf"."""
    robot, controller = case["robot"], case["controller"]
    report = build_report(robot, controller, alpha_deg=45.0, L=0.9)
    for scenario in (report.wall, report.corridor):
        v = scenario.models["sampled"]
        assert v.verdict == "unstable" and v.NV_critical == 0.0 and v.margin == -1.0
        assert v.critical["V_critical"] == 0.0
        assert not _sampled_stable(robot, controller, scenario.NV)
    assert report.wall.models["sampled"].critical["alpha_critical_deg"] == 90.0
    assert report.wall.models["sampled"].critical["f_critical"] == math.inf
    assert report.corridor.models["sampled"].critical["L_critical"] == math.inf
    assert report.corridor.models["sampled"].critical["f_critical"] == 0.0
    for scenario, result in (("wall", report.wall), ("corridor", report.corridor)):
        fix = report.remedies[(scenario, "sampled")]
        critical = result.models["sampled"].critical
        assert set(fix) <= {"T", "k"}
        if "T" in fix:
            assert _sampled_stable(robot, controller.replace(T=0.999 * fix["T"]["to"]), result.NV)
        else:
            assert critical["T_critical"] == 0.0
            assert not _sampled_stable(robot, controller.replace(T=1e-3 * controller.T), result.NV)
        if "k" in fix:
            assert _sampled_stable(robot.replace(k=0.999 * fix["k"]["to"]), controller, result.NV)
        else:
            assert critical["k_critical"] == 0.0
            assert not _sampled_stable(robot.replace(k=1e-3 * robot.k), controller, result.NV)
    data = _strict_json(report.to_dict())
    assert data["corridor"]["sampled"]["NV_critical"] == 0.0
    assert data["corridor"]["sampled"]["L_critical"] == "inf"
    assert data["corridor"]["sampled"]["omega_critical"] is None
    assert data["kb_error"]["relative"] == "inf" and data["kb_error"]["direction"] == "optimistic"


def test_library_defaults_follow_the_controller():
    """Without a model list the analyses build every model, `sampled` with the controller's hold and
    compute delay (CARMEL: command, 1 → the 0.9 m corridor oscillates); a `Sampled` that
    contradicts the controller is refused."""
    result = analyze_corridor(CARMEL.robot, CARMEL.controller, Corridor(0.9))
    assert list(result.models) == list(MODEL_NAMES)
    assert result.models["sampled"].verdict == "unstable"
    loop = Loop(CARMEL.robot.tau, CARMEL.controller.T, CARMEL.robot.k)
    assert result.models["sampled"].NV_critical == Sampled("command", 1).boundary(loop).NV_critical
    assert not _sampled_stable(CARMEL.robot, CARMEL.controller, result.NV)
    with pytest.raises(ValueError, match=r"contradicts the controller \(hold='command', compute_delay=1\)"):
        analyze_wall(CARMEL.robot, CARMEL.controller, Wall.from_degrees(45), [Sampled("reference", 0)])
    assert [m for m in make_models(controller=CARMEL.controller) if m.name == "sampled"] == [Sampled("command", 1)]
    with pytest.raises(ValueError, match="come from the controller"):
        make_models(controller=CARMEL.controller, hold="reference")
    assert models_for(CARMEL.controller, ["sampled"]) == [Sampled("command", 1)]


def test_kb_error_without_a_value_has_no_direction():
    """τ = 0 and T = 0: both KB's and the sampled NV* are infinite; the relative error is undefined
    (null) and the JSON carries no `direction`."""
    report = build_report(CARMEL.robot.replace(tau=0.0), CARMEL.controller.replace(T=0.0), L=0.9)
    data = _strict_json(report.to_dict())
    assert data["kb_error"]["relative"] is None and "direction" not in data["kb_error"]


def _random_sets(count, seed):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        robot = CARMEL.robot.replace(V=rng.uniform(0.2, 1.6), tau=rng.uniform(0.0, 1.2), k=np.exp(rng.uniform(np.log(0.5), np.log(20.0))), W=rng.uniform(0.3, 1.0))
        controller = CARMEL.controller.replace(
            f=rng.uniform(0.2, 3.0), n=rng.uniform(1.0, 3.0), T=rng.uniform(0.005, 0.6),
            hold=str(rng.choice(["command", "reference"])), compute_delay=int(rng.integers(0, 2)),
        )
        yield robot, controller, rng.uniform(5.0, 85.0), robot.W / 2 + rng.uniform(0.05, 2.0)


@pytest.mark.parametrize("seed", range(4))
def test_random_paper_range_sets_give_consistent_reports(seed):
    """10 random sets per seed over the paper's ranges (7 % of such sets used to crash): every
    report is built, strict JSON, and for every model the verdict agrees with the sign of the
    margin and with the stable set; the sampled verdict agrees with the independent ZOH oracle."""
    for robot, controller, alpha_deg, L in _random_sets(10, seed):
        report = build_report(robot, controller, alpha_deg=alpha_deg, L=L)
        _strict_json(report.to_dict())
        for scenario in (report.wall, report.corridor):
            for v in scenario.models.values():
                if v.verdict == "undecided":
                    continue
                assert (v.margin > 0) == (v.verdict == "stable")
            sampled = scenario.models["sampled"]
            if sampled.verdict != "undecided":
                assert (sampled.verdict == "stable") == _sampled_stable(robot, controller, scenario.NV)
