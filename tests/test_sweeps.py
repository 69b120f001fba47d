"""Parameter sweeps (`pfm_stability.sweeps`, docs/sweeps.md): specs, points, rows against `report`, engine, resume.

The verdict columns are checked against an independent route: the command
``pfm-stability report --format json`` run in-process for the same point
(scalar models, the report's own force-law route), on random rows far from
CARMEL as well as near it. The engine is checked by its invariants: the same
spec gives the same table whether run at once, interrupted and resumed, with
a chunk that fails once, or on a cluster of worker processes.
"""

from __future__ import annotations

import json
import math
import os
from itertools import pairwise

import numpy as np
import pytest
from table_helpers import read, same

from pfm_stability.cli import main
from pfm_stability.parameters import CARMEL, MODEL_NAMES
from pfm_stability.sweeps import (
    SweepError,
    SweepInterrupted,
    evaluate_chunk,
    run_sweep,
    spec_from_mapping,
)
from pfm_stability.sweeps.points import (
    axis_values,
    chunk_points,
    grid_points,
    sample_points,
    sobol_note,
)
from pfm_stability.sweeps.table import to_arrow

REL = 1e-9
"""Tolerance of NV* and margins against the report: both come from the same model equations (vectorized
closed forms against the scalar root finders), so they agree to round-off, far below 1e-9."""


def spec(**changes):
    base = {"preset": "carmel", "scenario": {"corridor": {"L": 0.9}}, "models": ["sampled", "exact_delay"],
            "grid": {"V": {"from": 0.2, "to": 1.6, "num": 5}, "T": {"from": 0.005, "to": 0.2, "num": 4, "scale": "log"}}}
    base.update(changes)
    return spec_from_mapping({k: v for k, v in base.items() if v is not None}, origin="s.yaml")


# ------------------------------------------------------------------ specs
BAD_SPECS = [
    ({"grid": {"speed": {"from": 0.2, "to": 1, "num": 2}}}, "grid.speed", "unknown parameter"),
    ({"colour": "red"}, "colour", "unknown key"),
    ({"grid": {"V": {"from": 0.2, "to": 1, "num": 2, "step": 1}}}, "grid.V.step", "unknown key"),
    ({"grid": {"V": {"from": 0.5, "to": 0.5, "num": 3}}}, "grid.V", "empty or reversed"),
    ({"grid": {"V": {"from": 0.9, "to": 0.5, "num": 3}}}, "grid.V", "empty or reversed"),
    ({"grid": {"V": {"from": 0.2, "to": 1, "num": 0}}}, "grid.V.num", "[1, "),
    ({"grid": None, "sample": {"method": "sobol", "n": 0, "ranges": {"V": [0.2, 1]}}}, "sample.n", "[1, "),
    ({"models": ["sampled", "magic"]}, "models", "magic"),
    ({"grid": None, "sample": {"method": "halton", "n": 8, "ranges": {"V": [0.2, 1]}}}, "sample.method", "halton"),
    ({"sample": {"method": "sobol", "n": 8, "ranges": {"V": [0.2, 1]}}}, "exactly one of grid", ""),
    ({"grid": None}, "exactly one of grid", ""),
    ({"grid": {"V": {"from": -1, "to": 1, "num": 3}}}, "grid.V.from", "V must be a finite number in (0, 100] m/s"),
    ({"grid": {"alpha": {"from": 10, "to": 95, "num": 3}}, "scenario": None}, "grid.alpha.to", "alpha must be"),
    ({"grid": {"T": {"from": 0, "to": 0.1, "num": 3, "scale": "log"}}}, "grid.T", "scale log needs from > 0"),
    ({"law": {"name": "power", "xi": 2}}, "law", "xi applies to khatib or gnron"),
    ({"law": {"name": "khatib"}}, "law", "goal_distance"),
    ({"law": {"name": "khatib", "goal_distance": 2}, "grid": {"f": {"from": 1, "to": 2, "num": 2}}}, "law", "f applies to power or grid"),
    ({"scenario": {"wall": {"alpha": 20}, "corridor": {"L": 1}}}, "scenario", "exactly one"),
    ({"simulate": True, "grid": {"T": {"from": 0, "to": 0.1, "num": 2}}}, "simulate", "T must be in (0, 100]"),
    ({"hold": "sometimes"}, "hold", "sometimes"),
    ({"preset": "carmel", "config": "robot.yaml"}, "preset or config", ""),
    ({"grid": {"window_cells": {"from": 3, "to": 9, "num": 3}}, "law": {"name": "grid"}}, "grid.window_cells", "odd integers"),
]


@pytest.mark.parametrize("changes, field, words", BAD_SPECS, ids=[f"{b[1]}-{i}" for i, b in enumerate(BAD_SPECS)])
def test_bad_spec_names_the_field(changes, field, words):
    """Every bad spec is one ValueError naming the spec file and the field (and what is allowed)."""
    with pytest.raises(ValueError) as info:
        spec(**changes)
    message = str(info.value)
    assert message.startswith("spec s.yaml: ") and field in message and words in message and "\n" not in message


def test_spec_resolves_defaults_and_digest():
    """Defaults come from the preset; the digest changes with anything that changes the table, not with key order."""
    s = spec(models=None)
    assert s.models == MODEL_NAMES and s.controller.hold == "command" and s.controller.compute_delay == 1
    assert s.geometry == "corridor" and s.geometry_value == 0.9 and s.count == 20
    assert s.input_columns == ("V", "tau", "T", "k", "f", "n", "W", "L")
    assert spec(hold="command").digest == spec().digest
    assert spec(hold="reference").digest != spec().digest
    reordered = spec_from_mapping({"grid": {"T": {"from": 0.005, "to": 0.2, "num": 4, "scale": "log"}, "V": {"from": 0.2, "to": 1.6, "num": 5}},
                                   "models": ["sampled", "exact_delay"], "scenario": {"corridor": {"L": 0.9}}})
    assert reordered.digest != spec().digest  # another axis order is another point order


# ------------------------------------------------------------------ points
def test_grid_points_order_count_and_bounds():
    """C order (first axis slowest), both ends exact, log spacing geometric; a chunk equals the slice of the whole."""
    s = spec()
    whole = grid_points(s.axes, 0, s.count)
    assert len(whole["V"]) == 20
    assert np.array_equal(whole["V"], np.repeat(np.linspace(0.2, 1.6, 5), 4))
    T = axis_values(s.axes[1])
    assert T[0] == 0.005 and T[-1] == 0.2 and np.allclose(T[1:] / T[:-1], (0.2 / 0.005) ** (1 / 3), rtol=1e-12)
    part = grid_points(s.axes, 7, 13)
    assert all(np.array_equal(part[k], whole[k][7:13]) for k in whole)


def test_latin_hypercube_and_sobol_samples():
    """Seeded and reproducible, inside the ranges, one point per stratum (LHS); Sobol n not a power of two gets a note."""
    lhs = spec(grid=None, sample={"method": "latin-hypercube", "n": 64, "seed": 3, "ranges": {"V": [0.2, 1.6], "k": [0.5, 8]}})
    a, b = sample_points(lhs), sample_points(lhs)
    other = sample_points(spec(grid=None, sample={"method": "latin-hypercube", "n": 64, "seed": 4, "ranges": {"V": [0.2, 1.6], "k": [0.5, 8]}}))
    assert np.array_equal(a["V"], b["V"]) and not np.array_equal(a["V"], other["V"])
    for name, lo, hi in lhs.sample.ranges:
        u = (a[name] - lo) / (hi - lo)
        assert u.min() >= 0 and u.max() < 1
        assert sorted(np.floor(u * 64).astype(int)) == list(range(64))  # Latin: every stratum exactly once
    sobol = spec(grid=None, sample={"method": "sobol", "n": 100, "seed": 0, "ranges": {"V": [0.2, 1.6]}})
    assert "power of two" in sobol_note(sobol) and len(sample_points(sobol)["V"]) == 100
    assert sobol_note(spec(grid=None, sample={"method": "sobol", "n": 128, "seed": 0, "ranges": {"V": [0.2, 1.6]}})) is None


# ------------------------------------------------------------------ rows against report
def report_json(capsys, argv):
    assert main(["report", "--format", "json", *argv]) == 0
    return json.loads(capsys.readouterr().out)


def _close(a, b):
    if isinstance(b, str):
        return (a == math.inf) if b == "inf" else False
    return math.isclose(a, b, rel_tol=REL, abs_tol=1e-12)


def _compare_rows(capsys, s, table, rows, extra=()):
    for i in rows:
        row = {name: table[name][i] for name in table}
        argv = ["--hold", s.controller.hold, "--compute-delay", str(s.controller.compute_delay), *extra]
        for name in ("V", "tau", "T", "k", "W") + (("f", "n") if s.law in ("power", "grid") else ()):
            argv += [f"--{name}", repr(float(row[name]))]
        geometry = "wall" if s.geometry == "wall" else "corridor"
        argv += ["--alpha" if geometry == "wall" else "--L", repr(float(row["alpha" if geometry == "wall" else "L"]))]
        for m in s.models:
            argv += ["--model", m]
        data = report_json(capsys, argv)[geometry]
        for m in s.models:
            assert row[f"{m}_verdict"] == data[m]["verdict"], (i, m, row, data[m])
            assert row[f"{m}_stable"] == data[m]["stable"]
            assert _close(row[f"{m}_NV_critical"], data[m]["NV_critical"]), (i, m, row[f"{m}_NV_critical"], data[m]["NV_critical"])
            assert _close(row[f"{m}_margin"], data[m]["margin"]), (i, m, row[f"{m}_margin"], data[m]["margin"])


def _columns(s, start=0, stop=None):
    stop = s.count if stop is None else stop
    points = chunk_points(s, start, stop, sample_points(s)) if s.sample is not None else None
    c = evaluate_chunk(s, start, stop, points)
    return dict(zip(c.names, c.arrays))


@pytest.mark.parametrize("hold, delay, geometry", [("command", 1, "alpha"), ("reference", 0, "alpha"), ("reference", 1, "L"), ("command", 0, "L")])
def test_rows_agree_with_report_far_from_carmel(capsys, hold, delay, geometry):
    """Random wall and corridor points over wide ranges (τ, T, k, f, n, W over decades), every model, every sampled
    structure: verdict, NV*, margin as `report` gives them for the same point."""
    ranges = {"V": [0.05, 5], "tau": [0.0, 2.0], "T": [0.001, 0.5], "k": [0.1, 30], "f": [0.05, 20], "n": [0.5, 4], "W": [0.2, 1.0]}
    ranges[geometry] = [3, 87] if geometry == "alpha" else [0.6, 4.0]
    s = spec(models=list(MODEL_NAMES), hold=hold, compute_delay=delay, scenario=None, grid=None,
             sample={"method": "latin-hypercube", "n": 400, "seed": 11 + delay, "ranges": ranges})
    table = _columns(s)
    rng = np.random.default_rng(5 + delay)
    rows = rng.choice(s.count, 6, replace=False)
    assert {v for m in s.models for v in table[f"{m}_verdict"]} >= {"stable", "unstable"}  # both kinds of rows exist
    _compare_rows(capsys, s, table, rows)


def test_corridor_rows_of_a_field_law_agree_with_report(capsys):
    """Khatib's law varying rho0 in a corridor (N by the report's scalar route, cached): rows as `report --law khatib`,
    including N = 0 beyond the influence distance (stable, margin inf, with the reason)."""
    s = spec(law={"name": "khatib", "goal_distance": 5.0}, models=["sampled", "kb_first_order"],
             grid={"rho0": {"from": 0.3, "to": 2.0, "num": 3}, "V": {"from": 0.3, "to": 1.5, "num": 3}}, scenario={"corridor": {"L": 1.0}})
    table = _columns(s)
    assert table["N"][0] == 0.0 and table["reason"][0].startswith("N = 0") and table["sampled_margin"][0] == math.inf
    assert np.all(table["N"][3:] > 0) and all(r is None for r in table["reason"][3:])
    for i in (0, 4, 8):
        _compare_rows(capsys, s, table, [i], extra=["--law", "khatib", "--goal-distance", "5", "--rho0", repr(float(table["rho0"][i]))])


def test_point_beyond_the_models_has_a_reason_not_a_crash(capsys):
    """A wall at alpha = 1e-6 deg with n = 0.01 gives N*V ~ 1e15 1/s, beyond what the models represent: no verdict
    (null), NaN margin, the reason — where `report` refuses the same point with the same words — and the other rows intact."""
    s = spec(scenario={"wall": {"alpha": 1e-6}}, models=["sampled"], grid={"n": {"from": 0.01, "to": 2.0, "num": 2}})
    table = _columns(s)
    assert table["sampled_verdict"][0] is None and math.isnan(table["sampled_margin"][0]) and table["NV"][0] > 1e12
    assert "exceeds what the loop models represent" in table["reason"][0]
    assert table["sampled_verdict"][1] == "unstable" and table["reason"][1] is None
    assert main(["report", "--alpha", "1e-6", "--n", "0.01", "--model", "sampled"]) == 2
    assert "exceeds what the loop models represent" in capsys.readouterr().err


@pytest.mark.parametrize("model", MODEL_NAMES)
def test_once_per_loop_equals_loop_verdicts_at_every_point(model):
    """`model_answers` (boundary once per distinct loop, points near it at their own NV) gives exactly what
    `loop_verdicts` gives point by point, on a grid with few loops and NVs spread across and onto the boundaries."""
    from pfm_stability.sweeps.evaluate import model_answers
    from pfm_stability.vectorized import loop_verdicts

    rng = np.random.default_rng(7)
    loops = np.column_stack([rng.uniform(0, 1.5, 12), rng.uniform(0.002, 0.4, 12), rng.uniform(0.2, 12, 12)])
    tau, T, k = (np.repeat(loops[:, j], 60) for j in range(3))
    for hold, delay in (("command", 1), ("reference", 0)):
        options = {"hold": hold, "compute_delay": delay, "pade_order": 3}
        star = np.repeat(np.asarray(loop_verdicts(model, loops[:, 0], loops[:, 1], loops[:, 2], 1.0, **options).NV_critical), 60)
        scale = np.where(np.isfinite(star) & (star > 0), star, 1.0)
        NV = scale * np.tile(np.r_[np.geomspace(0.05, 20, 56), 1 - 1e-7, 1 + 1e-12, 1.0, 1 + 1e-3], 12)
        got = model_answers(model, tau, T, k, NV, **options)
        direct = loop_verdicts(model, tau, T, k, NV, **options)
        assert np.array_equal(got[0], direct.stable) and list(got[1]) == list(direct.verdict)
        assert np.array_equal(got[2], direct.NV_critical)
        assert np.allclose(got[3], direct.margin, rtol=1e-15, atol=0, equal_nan=True)  # the same division


def test_loop_groups_skip_grouping_only_where_most_loops_are_distinct():
    """`loop_groups`: None (no grouping: every point to `loop_verdicts`) exactly when more than half the points
    have a loop of their own — a random sample of T, or of τ and k with T fixed; otherwise `distinct_rows`' groups.
    The count of distinct loops is checked independently with numpy.unique over the rows. Exact integers."""
    from pfm_stability.sweeps.evaluate import distinct_rows, loop_groups

    rng = np.random.default_rng(11)
    n = 1000
    grid_T = np.repeat(rng.uniform(0.01, 0.2, 40), n // 40)
    fixed = np.full(n, 0.5)
    cases = {
        "random T": (fixed, rng.uniform(0.01, 0.2, n), np.full(n, 2.0)),
        "random tau and k": (rng.uniform(0, 1, n), np.full(n, 0.05), rng.uniform(0.2, 10, n)),
        "grid of 40 T": (fixed, grid_T, np.full(n, 2.0)),
        "501 loops of pairs": (np.r_[np.repeat(rng.uniform(0, 1, 499), 2), 0.1, 0.2], np.full(n, 0.05), np.full(n, 2.0)),
        "500 loops of pairs": (np.repeat(rng.uniform(0, 1, 500), 2), np.full(n, 0.05), np.full(n, 2.0)),
    }
    for name, (tau, T, k) in cases.items():
        distinct = len(np.unique(np.column_stack([tau, T, k]), axis=0))
        groups = loop_groups(tau, T, k)
        assert (groups is None) == (2 * distinct > n), name
        if groups is not None:
            first, inverse = groups
            want_first, want_inverse = distinct_rows(tau, T, k)
            assert np.array_equal(first, want_first) and np.array_equal(inverse, want_inverse) and len(first) == distinct, name


def test_goal_aware_wall_rows_agree_with_report(capsys):
    """Ge & Cui's goal-aware law at a wall with three equilibria (the report's JSON-schema case): the nearest one's verdicts."""
    s = spec(law={"name": "gnron", "goal_distance": 0.02, "goal_exponent": 0.5, "eta": 1.0}, models=["sampled", "exact_delay"],
             scenario={"wall": {"alpha": 60}}, grid={"V": {"from": 0.3, "to": 1.2, "num": 2}})
    table = _columns(s)
    _compare_rows(capsys, s, table, [0, 1], extra=["--law", "gnron", "--goal-distance", "0.02", "--goal-exponent", "0.5", "--eta", "1"])


def test_simulated_field_law_agrees_with_sampled():
    """simulate with Khatib's law at a wall (analytic walls exerting that law): the sign of σ follows `sampled` on both sides
    of its boundary (margins +3.1, +0.55, -0.05, -0.31: σ is clearly non-zero at each)."""
    s = spec(law={"name": "khatib", "goal_distance": 3.0, "eta": 0.5}, models=["sampled"], simulate=True,
             scenario={"wall": {"alpha": 75}}, grid={"V": {"from": 0.2, "to": 1.2, "num": 4}})
    table = _columns(s)
    assert list(table["sim_verdict"]) == list(table["sampled_verdict"]) == ["stable", "stable", "unstable", "unstable"]
    assert np.all(np.sign(table["sim_sigma"]) == np.where(table["sampled_stable"], -1, 1)) and list(table["sim_basis"]) == ["growth_rate"] * 4


def test_config_file_gives_the_fixed_values(tmp_path):
    """`config:` names a configuration file relative to the spec (docs/config.md); the spec's own keys override it."""
    from pfm_stability.sweeps import load_spec

    (tmp_path / "robot.yaml").write_text("robot: {V: 0.5, k: 3}\ncontroller: {T: 0.05, hold: reference}\nscenario: {wall: {alpha: 25}}\n")
    (tmp_path / "s.yaml").write_text("config: robot.yaml\ncompute_delay: 0\nmodels: [sampled]\ngrid: {tau: {from: 0.1, to: 0.6, num: 3}}\n")
    s = load_spec(tmp_path / "s.yaml")
    assert (s.robot.V, s.robot.k, s.controller.T, s.controller.hold, s.controller.compute_delay) == (0.5, 3.0, 0.05, "reference", 0)
    assert (s.geometry, s.geometry_value) == ("wall", 25.0)
    (tmp_path / "bad.yaml").write_text("config: missing.yaml\ngrid: {tau: {from: 0.1, to: 0.6, num: 3}}\n")
    with pytest.raises(ValueError, match=r"bad.yaml, line \d+: config: .*missing.yaml"):
        load_spec(tmp_path / "bad.yaml")


def _plant_columns(robot, models, grid, controller=None, simulate=False):
    """The sweep's columns for CARMEL's preset with `robot` and `controller` changed (an embedded config), 0.9 m corridor."""
    config = {"preset": "carmel", "robot": robot, **({"controller": controller} if controller else {})}
    return _columns(spec_from_mapping({"config": config, "scenario": {"corridor": {"L": 0.9}}, "models": models, "grid": grid,
                                       "simulate": simulate}, origin="s.yaml"))


def test_a_plant_gain_enters_every_model_as_the_steering_gain_g_times_k():
    """A config's plant gain g (as `identify --out` writes it; docs/models.md, "Plant gain and dead time") makes the
    loop's steering gain g·k: the sweep at k = 3 1/s, g = 0.4 (every point the scalar model, no array route) gives every
    model's NV*, verdict and margin of KB's plant at k = 1.2 1/s (the array routes: another code path), NV* to 1e-12
    relative (closed forms and the same polynomials: measured 5e-15), over V and T."""
    grid = {"V": {"from": 0.2, "to": 1.6, "num": 5}, "T": {"from": 0.02, "to": 0.2, "num": 3}}
    plant = _plant_columns({"k": 3.0, "plant_gain": 0.4}, list(MODEL_NAMES), grid)
    kb = _plant_columns({"k": 1.2}, list(MODEL_NAMES), grid)
    for m in MODEL_NAMES:
        np.testing.assert_allclose(plant[f"{m}_NV_critical"], kb[f"{m}_NV_critical"], rtol=1e-12)
        np.testing.assert_allclose(plant[f"{m}_margin"], kb[f"{m}_margin"], rtol=1e-10, atol=1e-12)
        assert list(plant[f"{m}_verdict"]) == list(kb[f"{m}_verdict"])
    assert 0 < sum(v == "stable" for v in plant["sampled_verdict"]) < len(plant["sampled_verdict"])  # both verdicts met


def test_a_dead_time_delays_the_continuous_models_and_the_sampled_model_agrees_with_the_simulator():
    """A dead time D delays the whole command (the heading term by D, the field's by T + D; `continuous` has none): at
    T = 0.05 s and D = 0.07 s every model's column is the scalar model's on that loop (NV* to 1e-12), and the delay
    models' NV* lie below KB's plant's at T = 0.12 s (the heading term's delay costs too). The sampled model carries the
    commands on their way (its period stays T): with D = 0.12 s and g = 0.8 its verdict is the simulator's (the sweep's
    own sim column: the growth of the lateral motion, `validation.sweep`) at every point, among them V = 0.64 m/s,
    unstable with that plant and stable with KB's (NV = 1.80 1/s, NV* 1.57 against 2.33 1/s)."""
    from pfm_stability.models import Loop, make_model

    plant = _plant_columns({"dead_time": 0.07}, list(MODEL_NAMES), {"V": {"from": 0.2, "to": 1.6, "num": 5}}, {"T": 0.05})
    kb = _plant_columns({}, list(MODEL_NAMES), {"V": {"from": 0.2, "to": 1.6, "num": 5}}, {"T": 0.12})
    loop = Loop(CARMEL.robot.tau, 0.05, CARMEL.robot.k, dead_time=0.07)
    for m in ("continuous", "kb_first_order", "pade", "exact_delay"):
        scalar = make_model(m, hold=CARMEL.controller.hold, compute_delay=CARMEL.controller.compute_delay).boundary(loop).NV_critical
        np.testing.assert_allclose(plant[f"{m}_NV_critical"], scalar, rtol=1e-12)
        if m != "continuous":
            assert np.all(plant[f"{m}_NV_critical"] < kb[f"{m}_NV_critical"])
    grid = {"V": {"from": 0.3, "to": 2.0, "num": 6}}
    plant = _plant_columns({"dead_time": 0.12, "plant_gain": 0.8}, ["sampled"], grid, {"T": 0.05}, simulate=True)
    kb = _plant_columns({}, ["sampled"], grid, {"T": 0.05})
    assert list(plant["sampled_verdict"]) == list(plant["sim_verdict"])
    assert plant["sampled_verdict"][1] == "unstable" and kb["sampled_verdict"][1] == "stable"
    assert plant["sampled_NV_critical"][0] == pytest.approx(1.5732, rel=1e-4) and kb["sampled_NV_critical"][0] == pytest.approx(2.3345, rel=1e-4)


def test_a_plant_is_part_of_the_sweeps_digest_and_kb_s_plant_leaves_it_as_it_was(tmp_path):
    """`--resume` reuses parts only of the same sweep: a plant gain or dead time changes the digest; KB's plant (g = 1,
    D = 0, given or not) adds nothing to the normalized spec, so the digests of sweeps without one are unchanged."""
    base = {"scenario": {"wall": {"alpha": 40}}, "models": ["sampled"], "grid": {"V": {"from": 0.2, "to": 1.2, "num": 3}}}
    plain = spec_from_mapping({**base, "config": {"preset": "carmel", "robot": {"dead_time": 0, "plant_gain": 1}}})
    assert plain.digest == spec_from_mapping({**base, "preset": "carmel"}).digest
    assert "dead_time" not in plain.to_dict()["robot"] and "plant_gain" not in plain.to_dict()["robot"]
    digests = {spec_from_mapping({**base, "config": {"preset": "carmel", "robot": robot}}).digest
               for robot in ({"dead_time": 0.05}, {"plant_gain": 0.85}, {"dead_time": 0.05, "plant_gain": 0.85})}
    assert len(digests) == 3 and plain.digest not in digests
    # the command line: a robot file as `identify --out` writes it, given with --config, sweeps (exit 0)
    (tmp_path / "robot.yaml").write_text("robot: {tau: 0.15, dead_time: 0.05, plant_gain: 0.9}\ncontroller: {T: 0.1}\n")
    (tmp_path / "s.yaml").write_text("scenario: {wall: {alpha: 40}}\nmodels: [sampled]\ngrid: {V: {from: 0.2, to: 1.2, num: 3}}\n")
    out = tmp_path / "t.parquet"
    assert main(["sweep", str(tmp_path / "s.yaml"), "--config", str(tmp_path / "robot.yaml"), "--out", str(out), "--quiet"]) == 0
    import pyarrow.parquet as pq

    robot = json.loads(pq.read_table(out).schema.metadata[b"pfm_stability.spec"])["robot"]
    assert (robot["dead_time"], robot["plant_gain"]) == (0.05, 0.9)


# ------------------------------------------------------------------ engine
def test_resume_after_interruption_and_retry_give_the_same_table(tmp_path):
    """Interrupted after 2 of 5 chunks and resumed (2 reused), or with a chunk failing once: the table of an uninterrupted run."""
    s = spec(grid={"V": {"from": 0.2, "to": 1.6, "num": 9}, "k": {"from": 0.5, "to": 6, "num": 5}}, models=["sampled", "pade"])
    whole = tmp_path / "whole.parquet"
    run_sweep(s, whole, chunk_size=10, workers=2)
    out = tmp_path / "resumed.parquet"
    with pytest.raises(SweepInterrupted):
        run_sweep(s, out, chunk_size=10, stop_after_chunks=2)
    parts = sorted(os.listdir(f"{out}.parts"))
    assert parts == ["chunk-00000.parquet", "chunk-00001.parquet", "manifest.json"] and not out.exists()
    with pytest.raises(ValueError, match="different sweep"):
        run_sweep(spec(grid={"V": {"from": 0.2, "to": 1.6, "num": 9}}), out, resume=True)
    summary = run_sweep(s, out, resume=True)
    assert summary.reused_chunks == 2 and summary.chunks == 5 and not os.path.exists(f"{out}.parts")
    assert same(read(out), read(whole))
    retried = tmp_path / "retried.parquet"
    run_sweep(s, retried, chunk_size=10, fail_once=(3,))
    assert same(read(retried), read(whole))
    assert read(whole).column("point").to_pylist() == list(range(45))


@pytest.mark.parametrize("count, size", [(2000, 50), (45, 10), (7, 10), (1, 1), (101, 3), (100, 50)])
def test_chunk_plan_covers_every_point_once_with_a_fine_tail(count, size):
    """plan_chunks: consecutive ranges covering 0..count once, at most `size` each; with fine_tail (simulation
    sweeps) the last TAIL_CHUNKS·size points are in chunks of ceil(size/4) (so 2 workers finish within a small
    chunk of each other), the rest unchanged. Exact integers: no tolerance."""
    from pfm_stability.sweeps.engine import TAIL_CHUNKS, plan_chunks

    for fine in (False, True):
        plan = plan_chunks(count, size, fine_tail=fine)
        assert [c[0] for c in plan] == list(range(len(plan)))
        assert plan[0][1] == 0 and plan[-1][2] == count
        assert all(a[2] == b[1] for a, b in pairwise(plan)) and all(0 < stop - start <= size for _, start, stop in plan)
    coarse, fine = plan_chunks(count, size), plan_chunks(count, size, fine_tail=True)
    tail = min(count, TAIL_CHUNKS * size)
    small = -(-size // 4)
    assert all(stop - start <= small for _, start, stop in fine if start >= count - tail)
    assert [c for c in fine if c[2] <= count - tail] == [c for c in coarse if c[2] <= count - tail]


def test_default_chunk_size_shares_a_vectorized_sweep_over_the_workers():
    """Without simulation ⌈points/workers⌉ within [VECTOR_MIN_CHUNK, VECTOR_CHUNK] (every thread gets work), with
    simulation SIMULATION_CHUNK of the environment (that the table does not depend on the chunks: the resume test). Exact integers."""
    from pfm_stability.sweeps.engine import (
        SIMULATION_CHUNK,
        VECTOR_CHUNK,
        VECTOR_MIN_CHUNK,
        default_chunk_size,
    )

    def sized(n, simulate=False):
        return spec(grid=None, simulate=simulate, sample={"method": "sobol", "n": n, "seed": 0, "ranges": {"T": [0.01, 0.2]}})

    assert default_chunk_size(sized(200_000), 2) == 100_000 and default_chunk_size(sized(200_001), 2) == 100_001
    assert default_chunk_size(sized(5_000_000), 2) == VECTOR_CHUNK and default_chunk_size(sized(900), 2) == VECTOR_MIN_CHUNK
    assert default_chunk_size(sized(200_000, simulate=True), 2) == SIMULATION_CHUNK["analytic"] == 200
    grid_env = spec(grid=None, simulate=True, env="grid", law={"name": "grid"}, scenario={"wall": {"alpha": 40}},
                    sample={"method": "sobol", "n": 64, "seed": 0, "ranges": {"T": [0.01, 0.2]}})
    assert default_chunk_size(grid_env, 2) == SIMULATION_CHUNK["grid"] == 50


def test_local_schedulers_start_the_chunks_in_index_order(tmp_path, monkeypatch):
    """Dask's local schedulers start chunk 0 first and the last chunk last (`engine._local_key`), so that a
    simulation sweep's full chunks run before its fine tail: on one thread the chunks run in exactly that order.
    (Plain keys ("chunk", i) ran 9, 8, …, 2, 11, 10, 1, 0 for 12 chunks: `dask.order` sorts them as text.)"""
    from pfm_stability.sweeps import engine

    started, real = [], engine.evaluate_task

    def recording(spec, index, *args):
        started.append(index)
        return real(spec, index, *args)

    monkeypatch.setattr(engine, "evaluate_task", recording)
    s = spec(grid={"V": {"from": 0.2, "to": 1.6, "num": 5}, "T": {"from": 0.01, "to": 0.2, "num": 23}})
    summary = run_sweep(s, tmp_path / "t.parquet", chunk_size=5, workers=1)
    assert summary.chunks == 23 and started == list(range(23))


def test_a_worker_process_that_dies_is_a_sweep_error(tmp_path, monkeypatch):
    """A simulation sweep's worker process that ends without an answer (as one killed for memory would) gives
    `SweepError` saying so and how to go on (the CLI: exit 1 and that line), not the pool's traceback."""
    from pfm_stability.sweeps import engine

    def die(*args):  # pickled by value (cloudpickle): runs in the worker process
        import os

        os._exit(9)

    monkeypatch.setattr(engine, "_local_task", die)
    s = spec(simulate=True, models=["sampled"], scenario={"wall": {"alpha": 40}}, grid=None,
             sample={"method": "latin-hypercube", "n": 2, "seed": 1, "ranges": {"V": [0.3, 1.5]}})
    with pytest.raises(SweepError, match="a worker process died without an answer .* rerun with --resume"):
        run_sweep(s, tmp_path / "t.parquet", chunk_size=1, workers=1)
    assert not (tmp_path / "t.parquet").exists()


def test_failing_chunk_is_named_and_parts_are_kept(tmp_path, monkeypatch):
    """A chunk that fails on every attempt: SweepError naming it and the error; the other chunks stay for --resume."""
    from pfm_stability.sweeps import engine

    real = engine.evaluate_chunk

    def broken(spec, start, stop, sample=None):
        if start == 10:
            raise RuntimeError("disk on fire")
        return real(spec, start, stop, sample)

    monkeypatch.setattr(engine, "evaluate_chunk", broken)
    out = tmp_path / "t.parquet"
    with pytest.raises(SweepError, match=r"chunk 1 \(points 10-19\) failed after 2 retries: RuntimeError: disk on fire"):
        run_sweep(spec(), out, chunk_size=10, workers=1)
    assert not out.exists() and os.path.exists(f"{out}.parts/chunk-00000.parquet")


def test_bad_inputs_before_any_work(tmp_path):
    """Corridor narrower than the robot, bad output path or scheduler: ValueError and nothing written."""
    with pytest.raises(ValueError, match="L > W/2"):
        run_sweep(spec(grid={"L": {"from": 0.3, "to": 1.0, "num": 3}}, scenario=None), tmp_path / "a.parquet")
    with pytest.raises(ValueError, match="out must be a writable file path ending in .parquet or .csv"):
        run_sweep(spec(), tmp_path / "missing" / "a.parquet")
    with pytest.raises(ValueError, match="scheduler must be an address"):
        run_sweep(spec(), tmp_path / "a.parquet", scheduler="localhost")
    assert os.listdir(tmp_path) == []


def test_csv_output_has_the_same_rows(tmp_path):
    """A .csv output holds the Parquet table's rows (infinities as inf, nulls empty)."""
    import pyarrow.csv as pcsv

    s = spec(scenario={"corridor": {"L": 5.0}}, models=["continuous", "sampled"])  # wide corridor: margins, some inf-free
    run_sweep(s, tmp_path / "t.parquet")
    run_sweep(s, tmp_path / "t.csv")
    a, b = read(tmp_path / "t.parquet"), pcsv.read_csv(tmp_path / "t.csv")
    assert b.num_rows == a.num_rows == 20 and b.column_names == a.column_names
    assert np.allclose(b.column("sampled_margin").to_numpy(), a.column("sampled_margin").to_numpy(), rtol=1e-15)
    assert b.column("sampled_verdict").to_pylist() == a.column("sampled_verdict").to_pylist()


@pytest.fixture(scope="module")
def cluster():
    """A LocalCluster of 2 worker processes (threads_per_worker=1), as a remote scheduler would be used."""
    import logging

    from distributed import LocalCluster

    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR)
    yield c
    c.close()


@pytest.mark.xdist_group("sweeps_cluster")  # one LocalCluster per suite (tests/conftest.py)
def test_cluster_table_equals_local_table(tmp_path, cluster):
    """The same spec on local threads and on a cluster of worker processes gives identical tables (pyarrow equality)."""
    s = spec(grid=None, models=["sampled", "exact_delay", "pade"], sample={"method": "sobol", "n": 64, "seed": 2,
             "ranges": {"V": [0.2, 1.6], "T": [0.005, 0.2], "tau": [0.05, 1.0]}})
    run_sweep(s, tmp_path / "local.parquet", chunk_size=16)
    summary = run_sweep(s, tmp_path / "cluster.parquet", chunk_size=16, scheduler=cluster.scheduler_address)
    assert summary.scheduler == cluster.scheduler_address
    assert same(read(tmp_path / "cluster.parquet"), read(tmp_path / "local.parquet"))


@pytest.mark.xdist_group("sweeps_cluster")  # one LocalCluster per suite (tests/conftest.py)
def test_simulation_on_cluster_with_retry_agrees_with_sampled(tmp_path, cluster):
    """simulate: true on the cluster, a chunk failing once (retried by Dask): the table equals the in-process
    evaluation, and away from the boundary (|margin| > 5 %) the simulated sign of σ agrees with `sampled`."""
    s = spec(simulate=True, models=["sampled"], scenario={"wall": {"alpha": 40}}, grid=None,
             sample={"method": "latin-hypercube", "n": 6, "seed": 1, "ranges": {"V": [0.3, 1.5], "T": [0.02, 0.15]}})
    out = tmp_path / "sim.parquet"
    run_sweep(s, out, chunk_size=3, scheduler=cluster.scheduler_address, fail_once=(1,))
    table = read(out)
    assert same(table, to_arrow(evaluate_chunk(s, 0, 6, sample_points(s))))
    rows = table.to_pylist()
    assert all(r["sim_verdict"] in ("stable", "unstable") and (not math.isnan(r["sim_sigma"]) or r["sim_basis"] != "growth_rate") for r in rows)
    far = [r for r in rows if abs(r["sampled_margin"]) > 0.05]
    assert far and all(r["sim_verdict"] == r["sampled_verdict"] for r in far)


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
@pytest.mark.xdist_group("sweeps_cluster")  # one LocalCluster per suite (tests/conftest.py)
def test_simulation_on_local_processes_equals_cluster_and_in_process(tmp_path, cluster):
    """simulate: true without a scheduler runs on Dask's local worker processes (no cluster): the table equals the
    cluster's and the in-process evaluation (pyarrow equality), a chunk failing once in a worker process is retried
    there, and the progress callback sees every point once, in this process."""
    s = spec(simulate=True, models=["sampled"], scenario={"wall": {"alpha": 40}}, grid=None,
             sample={"method": "latin-hypercube", "n": 6, "seed": 1, "ranges": {"V": [0.3, 1.5], "T": [0.02, 0.15]}})
    seen = []
    local = run_sweep(s, tmp_path / "local.parquet", chunk_size=3, workers=2, fail_once=(0,),
                      progress=lambda points, total, chunks, total_chunks: seen.append((points, chunks)))
    run_sweep(s, tmp_path / "cluster.parquet", chunk_size=3, scheduler=cluster.scheduler_address)
    assert local.scheduler == "local processes (2)" and local.chunks == 6  # the fine tail: chunks of ceil(3/4) = 1
    assert seen[0] == (0, 0) and seen[-1] == (6, 6) and [c for _, c in seen] == list(range(7))
    assert same(read(tmp_path / "local.parquet"), read(tmp_path / "cluster.parquet"))
    assert same(read(tmp_path / "local.parquet"), to_arrow(evaluate_chunk(s, 0, 6, sample_points(s))))
