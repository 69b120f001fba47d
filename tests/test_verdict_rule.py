"""One verdict rule (`pfm_stability.models.verdicts`): the scalar form `judge` and the array form `judge_arrays` agree,
and the report, maps and sweeps all answer with it (docs/models.md, "Verdicts and margins").

The rule, checked here on its own terms (not against itself): a gain inside the stable set (0, NV*) is stable with
margin NV*/NV − 1 > 0; outside it, unstable with the margin to the set's upper end (−1 when there is none below);
within 1e-9 of NV* "undecided"; N < 0 unstable, margin −1, V* = 0, with the divergent reason; N = 0 the heading loop's
verdict, margin inf or −1, V* inf or 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pfm_stability.models import Boundary, Loop, make_model
from pfm_stability.models.verdicts import (DIVERGENT_REASON, UNDECIDED_RTOL, critical_speed, in_stable_set, inside, judge,
                                           judge_arrays, neutral_reason)


def _boundary(NV_critical: float) -> Boundary:
    stable_set = ((0.0, NV_critical),) if NV_critical > 0 else ()
    return Boundary("test", NV_critical, None if not 0 < NV_critical < math.inf else 1.0, NV_critical, stable_set)


@pytest.mark.parametrize("seed", range(4))
def test_scalar_and_array_forms_agree(seed):
    """Random NV* (0, finite, inf) and NV (negative, 0, far, within 1e-10 of NV*): `judge` and `judge_arrays` give the
    same verdict and the same margin (exactly: the same arithmetic), and both follow the rule stated above."""
    rng = np.random.default_rng(seed)
    critical = np.concatenate([[0.0, math.inf], np.exp(rng.uniform(-3, 3, 60))])
    NV = np.concatenate([[-1.0, 0.0, 0.0], critical[2:5] * (1 + 1e-10), np.exp(rng.uniform(-4, 4, len(critical) - 6))])
    stable = np.array([inside(_boundary(c), v) if v != 0 else bool(rng.integers(2)) for c, v in zip(critical, NV)])
    verdicts, margins = judge_arrays(NV, critical, stable)
    for c, v, s, verdict, margin in zip(critical, NV, stable, verdicts, margins):
        j = judge(v, v / 0.8 if v else 0.0, _boundary(c), bool(s))
        assert (j.verdict, j.margin) == (verdict, margin)
        if v < 0:
            assert (j.verdict, j.margin, j.V_critical, j.reason) == ("unstable", -1.0, 0.0, DIVERGENT_REASON)
        elif v == 0:
            assert j.margin == (math.inf if s else -1.0) and j.reason == neutral_reason(0.0, bool(s))
            assert j.V_critical == (math.inf if s else 0.0)
        elif 0 < c < math.inf and abs(v / c - 1) <= UNDECIDED_RTOL:
            assert j.verdict == "undecided"
        else:
            assert j.verdict == ("stable" if v < c else "unstable") and j.stable == (v < c)
            assert j.margin == pytest.approx(c / v - 1 if c > 0 else -1.0)


def test_the_speed_limit_and_the_set():
    """V* = NV*/N for N > 0, 0 for N < 0, inf or 0 at N = 0; `in_stable_set` is `Boundary.contains` in arrays."""
    assert critical_speed(2.0, 3.0, True) == 1.5 and critical_speed(-1.0, 3.0, True) == 0.0
    assert critical_speed(0.0, 3.0, True) == math.inf and critical_speed(0.0, 3.0, False) == 0.0
    b = Boundary("sampled", 1.0, 2.0, 2.0, ((0.0, 1.0), (3.0, 5.0)))
    NV = np.array([-1, 0, 0.5, 1, 2, 3, 4, 5, 6], dtype=float)
    assert in_stable_set(b.stable_set, NV).tolist() == [b.contains(x) for x in NV]


def test_report_map_and_sweep_answer_with_the_one_rule(tmp_path):
    """The report's verdict (criteria), a map sample (maps.analysis.sample_verdict) and a sweep row (sweeps) give the
    same verdict, margin and V* for one corridor loop as `judge` with the model's own test."""
    from pfm_stability.analysis.criteria import analyze_corridor
    from pfm_stability.maps.analysis import sample_verdict
    from pfm_stability.parameters import CARMEL, Corridor
    from pfm_stability.sweeps import load_spec, run_sweep
    from table_helpers import read

    robot, controller = CARMEL.robot, CARMEL.controller
    analysis = analyze_corridor(robot, controller, Corridor(0.9), models=["sampled"])
    model = make_model("sampled", hold=controller.hold, compute_delay=controller.compute_delay)
    loop = Loop(robot.tau, controller.T, robot.k)
    boundary = model.boundary(loop)
    j = judge(analysis.NV, analysis.N, boundary, model.is_stable(analysis.NV, loop))
    v = analysis.models["sampled"]
    assert (v.verdict, v.margin, v.critical.V_critical) == (j.verdict, j.margin, j.V_critical)
    s = sample_verdict(analysis.N, robot.V, boundary, model.is_stable(0.0, loop))
    assert (s.verdict, s.V_critical) == (j.verdict, j.V_critical) and s.margin == pytest.approx(j.margin, rel=1e-12)
    spec = tmp_path / "spec.yaml"
    spec.write_text("preset: carmel\nscenario: {corridor: {L: 0.9}}\nmodels: [sampled]\ngrid: {V: {from: 0.8, to: 0.8, num: 1}}\n")
    run_sweep(load_spec(str(spec)), str(tmp_path / "out.parquet"), workers=1)
    row = read(tmp_path / "out.parquet").to_pylist()[0]
    assert row["sampled_verdict"] == j.verdict and row["sampled_margin"] == pytest.approx(j.margin, rel=1e-12)
