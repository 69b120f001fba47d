"""Map predictions checked by simulation (`pfm_stability.validation.maps`; docs/validation.md).

The predictions here are made by the test itself, independently of the map
analysis: for a corridor along a grid axis with the library's closed-form
grid law (`fields.make_law("grid")`, `criteria.analyze_corridor`, the
`sampled` model of the controller's structure); for a corridor drawn at 30°
(a staircase of cells, whose walls push harder than the axis-aligned law:
≈ 1.33×, docs/simulator.md) with N = −2 dF/dd of the staircase wall's force
summed cell by cell (`sim.vff.measured_wall_force`: a static window sum, not
a simulated run) fed to the same `sampled` model.
"""

import functools
import json
import math
from dataclasses import dataclass

import numpy as np
import pytest

from pfm_stability.analysis.criteria import analyze_corridor, loop_of
from pfm_stability.laws.fields import make_law
from pfm_stability.models import Sampled
from pfm_stability.models.verdicts import gain_margin
from pfm_stability.parameters import CARMEL, Corridor
from pfm_stability.io.serialize import dumps
from pfm_stability.sim.engine import run_batch
from pfm_stability.sim.grid import HistogramGrid
from pfm_stability.sim.vff import measured_wall_force
from pfm_stability.validation.maps import (
    CLEAR_MARGIN,
    MapValidation,
    crop_grid,
    select_segments,
    validate_map_segments,
)


@dataclass(frozen=True)
class Segment:
    """The fields of a map segment the validation reads (`pfm_stability.maps.analysis.MapSegment`)."""

    x0: float
    y0: float
    x1: float
    y1: float
    length: float
    N: float
    c: float
    V_critical: float
    margin: float
    stable: bool
    offset: float = 0.0


LENGTH = 16.0
"""Corridor length, m: 3 periods at 0.8 m/s need 2·0.8 + 3·2π/2.3·0.8 ≈ 8.2 m; 16 m gives ~6."""

OTHER = (
    CARMEL.robot.replace(V=1.0, tau=0.2, k=3.0),
    CARMEL.controller.replace(T=0.1, hold="reference", compute_delay=0, f=1.5),
)
"""Far from CARMEL: a faster robot, a faster steering loop, a servo (reference hold) without compute delay, a stronger field."""


def _prediction(robot, controller, law, N):
    """(margin, stable, V*, dominant root) of the `sampled` model of the controller's structure at N·V."""
    model = Sampled(controller.hold, controller.compute_delay)
    loop = loop_of(robot, controller)
    NV = N * robot.V
    stable = model.is_stable(NV, loop)
    boundary = model.boundary(loop)
    return gain_margin(NV, boundary, stable), stable, boundary.NV_critical / N, model.rightmost_root(NV, loop)


def _axis_N(robot, controller, law, L):
    """N of a grid corridor along an axis, from the report's route (`analyze_corridor` with the grid law)."""
    return analyze_corridor(robot, controller, Corridor(L), models=["sampled"], law=law).N


def _staircase_N(law, L, angle):
    """N = −2 dF/dd at d = L of a wall drawn at `angle` (centred difference of the cell-by-cell window sum)."""
    h = 2e-3
    F = measured_wall_force(law, np.array([L - h, L + h]), angle=angle, samples=800)
    return -2 * (F[1] - F[0]) / (2 * h)


def _corridor_map(half_widths, angle, c=0.1):
    """A frozen grid with one straight corridor per half-width (walls on cell centres when along Y) and their centre lines."""
    ux, uy = math.sin(angle), math.cos(angle)
    nx, ny = -uy, ux
    width = sum(2 * L / math.cos(angle) + 4.0 for L in half_widths) + LENGTH * abs(ux) + 4.0
    grid = HistogramGrid.centred(-2.0, width, -4.0, LENGTH * uy + 4.0, cell_size=c)
    lines, x = [], 0.0
    for L in half_widths:
        halves = round(2 * L / c)
        centre = round((x + L / math.cos(angle)) / c) * c + (c / 2 if angle == 0 and halves % 2 else 0.0)
        p0, p1 = (centre, 0.0), (centre + LENGTH * ux, LENGTH * uy)
        for s in (-L, L):
            grid.draw_segment((p0[0] - 2 * ux + s * nx, p0[1] - 2 * uy + s * ny), (p1[0] + 2 * ux + s * nx, p1[1] + 2 * uy + s * ny))
        lines.append((p0, p1))
        x = centre + L / math.cos(angle) + 4.0
    return grid.freeze(), lines


def _segments(lines, predictions):
    return [
        Segment(*p0, *p1, LENGTH, N, 0.0, V_star, margin, bool(stable))
        for (p0, p1), (N, margin, stable, V_star, _) in zip(lines, predictions)
    ]


def _clear_half_widths(robot, controller, law):
    """The widest L (multiple of 5 cm) with margin < −20 % and the narrowest with margin > +20 %."""
    Ls = np.round(np.arange(0.5, 1.55, 0.05), 2)
    margins = [_prediction(robot, controller, law, _axis_N(robot, controller, law, L))[0] for L in Ls]
    unstable = [L for L, m in zip(Ls, margins) if m < -0.2]
    stable = [L for L, m in zip(Ls, margins) if m > 0.2]
    return float(max(unstable)), float(min(stable))


# ----------------------------------------------------------------- verdicts
@pytest.mark.parametrize("robot,controller", [(CARMEL.robot, CARMEL.controller), OTHER], ids=["carmel", "reference-hold"])
def test_clear_verdicts_agree_on_straight_and_rotated_corridors(robot, controller):
    """Corridors with the sampled model's margin < −20 % and > +20 %, along Y and drawn at 30°: every measured sign agrees.

    The half-widths are chosen by the test from the predictions (so they
    hold for any parameters); at 30° they are taken from the staircase's own
    N. A ±20 % margin in NV is ±0.1 1/s or more in σ, far beyond the
    measurement's error here (< 0.05 1/s, next test).
    """
    law = make_law("grid", robot, controller)
    L_unstable, L_stable = _clear_half_widths(robot, controller, law)
    cases = []
    for angle in (0.0, math.radians(30.0)):
        Ls = [L_unstable, L_stable]
        if angle:  # the staircase pushes harder: its own clear half-widths
            Ns = {L: _staircase_N(law, L, angle) for L in np.round(np.arange(0.5, 1.45, 0.05), 2)}
            margins = {L: _prediction(robot, controller, law, N)[0] for L, N in Ns.items()}
            Ls = [max(L for L, m in margins.items() if m < -0.2), min(L for L, m in margins.items() if m > 0.2)]
        grid, lines = _corridor_map(Ls, angle)
        N_of = (lambda L: _axis_N(robot, controller, law, L)) if angle == 0 else (lambda L: _staircase_N(law, L, angle))
        predictions = [(N, *_prediction(robot, controller, law, N)) for N in map(N_of, Ls)]
        assert [p[2] for p in predictions] == [False, True] and predictions[0][1] < -0.2 < 0.2 < predictions[1][1]
        v = validate_map_segments(grid, _segments(lines, predictions), robot, controller, cell_ratio=law.ratio, window_cells=33, count=2)
        cases += v.cases
        for c in v.cases:
            assert (c.growth_rate > 0) != c.predicted_stable, (c.reason, c.growth_rate, c.predicted_margin)  # the sign
            # along Y (the grid law exact) every case agrees; at 30° (N of the staircase: an estimate) a σ within the
            # resolution may be off the prediction by more than the resolution, a disagreement in size, not hidden
            # (the reference-hold robot's stable corridor: predicted −0.18 1/s, measured −0.035 over 15.6 s)
            assert c.outcome == "agree" or (angle and c.basis == "resolution"), (c.reason, c.growth_rate, c.predicted_margin)
    assert sorted(c.verdict or ("unstable" if c.growth_rate > 0 else "stable") for c in cases) == ["stable", "stable", "unstable", "unstable"]


def test_growth_rate_near_the_boundary_equals_the_sampled_root():
    """σ and ω measured on map segments near the boundary equal the `sampled` model's dominant root.

    Along Y the tolerances are those of tests/test_sim_validation.py's grid
    corridor (1e-2 1/s, 3e-2 rad/s: quantization is not in the model; a law
    off by 10 % would shift σ by ~0.1 1/s). The ± pair of runs cancels the
    response forced by the cells, so σ is that of the free oscillation. At
    30° the staircase's N is an average over a wall that is not periodic
    along its length and its force is not smooth across cell borders: σ
    measured within 0.045 1/s (0.05 allowed, half the shift of a 10 % error in N).
    """
    robot, controller = CARMEL.robot, CARMEL.controller
    law = make_law("grid", robot, controller)
    for angle, Ls, tol in ((0.0, [0.65, 0.7, 0.75], 1e-2), (math.radians(30.0), [0.8, 0.9], 5e-2)):
        grid, lines = _corridor_map(Ls, angle)
        Ns = [_axis_N(robot, controller, law, L) if angle == 0 else _staircase_N(law, L, angle) for L in Ls]
        predictions = [(N, *_prediction(robot, controller, law, N)) for N in Ns]
        v = validate_map_segments(grid, _segments(lines, predictions), robot, controller, cell_ratio=law.ratio, window_cells=33, count=len(Ls))
        for case in v.cases:
            root = predictions[case.index][4]
            # near the boundary σ may be within the validation's resolution (not counted there); σ itself is measured
            assert case.growth_rate is not None and (case.measurable or case.reason.startswith("not measurable (sigma")), case.to_dict()
            assert case.growth_rate == pytest.approx(root.real, abs=tol), (angle, Ls[case.index])
            assert case.predicted_growth_rate == pytest.approx(root.real, rel=1e-9)
            if angle == 0:
                assert case.angular_frequency == pytest.approx(root.imag, abs=3e-2)
                assert case.agree or abs(case.predicted_margin) < CLEAR_MARGIN


# ------------------------------------------------------- selection, length
def test_selection_is_seeded_and_spreads_over_the_margins():
    """`select_segments`: same seed → same choice; one segment per margin-quantile bin; both verdicts represented; clear margins preferred."""
    rng = np.random.default_rng(7)
    margins = list(np.concatenate([rng.uniform(-0.9, -0.1, 6), rng.uniform(-0.1, 0.1, 20), rng.uniform(0.1, 3.0, 74)]))
    stable = [m > 0 for m in margins]
    long_enough = [True] * len(margins)
    first = select_segments(margins, stable, long_enough, 10, seed=3)
    assert first == select_segments(margins, stable, long_enough, 10, seed=3)
    assert len({tuple(select_segments(margins, stable, long_enough, 10, seed=s)) for s in range(6)}) > 1
    chosen = [margins[i] for i in first]
    assert len(set(first)) == 10 and all(abs(m) > CLEAR_MARGIN for m in chosen)
    assert 1 <= sum(m < 0 for m in chosen) <= 2  # 6 of 80 clear segments are unstable: in proportion, at least one
    clear_stable = sorted(m for m in margins if m > CLEAR_MARGIN)
    picked = sorted(m for m in chosen if m > 0)
    for b, chunk in enumerate(np.array_split(np.array(clear_stable), len(picked))):
        assert chunk[0] <= picked[b] <= chunk[-1]  # one per quantile bin
    # fewer clear than wanted: the small margins fill in, then the too-short ones
    short = [i >= 95 for i in range(len(margins))]
    everything = select_segments(margins, stable, [not s for s in short], 100, seed=0)
    assert sorted(everything) == list(range(100))
    few = select_segments(margins, stable, [not s for s in short], 80, seed=0)
    assert not any(short[i] for i in few) and sum(abs(margins[i]) <= CLEAR_MARGIN for i in few) == 80 - sum(
        abs(m) > CLEAR_MARGIN for m, s in zip(margins, short) if not s
    )


def test_short_and_unpredicted_segments_are_reported_not_counted():
    """A segment shorter than 2 end margins + 3 periods is reported as not measurable and is not in the agreement;
    a segment without a prediction (open area: margin None) is never chosen."""
    robot, controller = CARMEL.robot, CARMEL.controller
    law = make_law("grid", robot, controller)
    grid, lines = _corridor_map([0.8], 0.0)
    N = _axis_N(robot, controller, law, 0.8)
    margin, stable, V_star, _ = _prediction(robot, controller, law, N)
    (x0, y0), (x1, y1) = lines[0]
    segments = [
        Segment(x0, y0, x1, y1, LENGTH, N, 0.0, V_star, margin, stable),
        Segment(x0, 2.0, x0, 6.0, 4.0, N, 0.0, V_star, margin, stable),
        Segment(x0, 6.0, x0, 9.0, 3.0, N, 0.0, V_star, None, None),
    ]
    v = validate_map_segments(grid, segments, robot, controller, cell_ratio=law.ratio, window_cells=33, count=3)
    assert isinstance(v, MapValidation) and sorted(c.index for c in v.cases) == [0, 1]
    short = next(c for c in v.cases if c.index == 1)
    assert not short.measurable and short.agree is None and "too short" in short.reason and short.required_length > 4.0
    assert short.outcome == "not measurable"
    assert (v.measured, v.agreed, v.disagreed, v.not_measurable, v.agreement) == (1, 1, 0, 1, 1.0)
    text = dumps(v.to_dict())
    assert json.loads(text)["cases"][0]["predicted_verdict"] in ("stable", "unstable") and "NaN" not in text


def _gain_with_growth(robot, controller, sigma):
    """The N (1/m) whose `sampled` dominant root at N·V has real part `sigma` (1/s), above the boundary (brentq)."""
    from scipy.optimize import brentq

    model, loop = Sampled(controller.hold, controller.compute_delay), loop_of(robot, controller)
    N_star = model.boundary(loop).NV_critical / robot.V
    return brentq(lambda N: model.rightmost_root(N * robot.V, loop).real - sigma, N_star, 20 * N_star, xtol=1e-12)


def test_a_growth_the_run_would_have_seen_and_did_not_is_a_disagreement():
    """Every case is agree, disagree or not measurable, and "not measurable" is never agreement (docs/maps.md, "Validation").

    Constructed: two corridors at L = 0.7 m, where the `sampled` model's root is σ = −0.017 1/s (2.6 % inside the
    boundary: the ± runs' difference neither grows nor decays measurably over the ~19 s run, whose resolution is
    max(0.02, 1/19.5 s) = 0.05 1/s), and one at L = 0.9 m (margin +33 %, σ −0.20 1/s: a decay it resolves). Segment A
    claims the gain whose root grows at σ = +0.9 1/s on the first corridor: the run would have shown that growth and
    measures ≈ 0, so A disagrees (it used to be set aside, and the summary read "1 of 1 agree"). Segment B claims the
    corridor's own gain (σ −0.017): the prediction is within the resolution too, the run decides nothing, B is not
    measurable. C agrees. Expected: 1 agree, 1 disagree, 1 not measurable, agreement 1 of 2; the JSON and the CLI's
    summary line state all three counts.
    """
    from pfm_stability.cli.render import render_map_text
    from pfm_stability.validation.maps import resolution

    robot, controller = CARMEL.robot, CARMEL.controller
    law = make_law("grid", robot, controller)
    grid, lines = _corridor_map([0.7, 0.7, 0.9], 0.0)
    N_true, N_stable = _axis_N(robot, controller, law, 0.7), _axis_N(robot, controller, law, 0.9)
    N_claimed = _gain_with_growth(robot, controller, 0.9)
    predictions = [(N, *_prediction(robot, controller, law, N)) for N in (N_claimed, N_true, N_stable)]
    assert predictions[0][4].real == pytest.approx(0.9, abs=1e-9) and abs(predictions[1][4].real) < 0.02
    v = validate_map_segments(grid, _segments(lines, predictions), robot, controller, cell_ratio=law.ratio, window_cells=33, count=3)
    cases = {c.index: c for c in v.cases}
    a, b, c = cases[0], cases[1], cases[2]
    duration = (LENGTH - 0.4) * 1.0 / robot.V  # the run's span, s (the record ends when the target's finish is reached)
    assert abs(a.growth_rate) < resolution(duration) and abs(b.growth_rate) < resolution(duration)  # both ≈ 0
    assert (a.outcome, a.agree, a.verdict, a.basis) == ("disagree", False, None, "resolution") and "+0.9 1/s not seen" in a.reason
    assert (b.outcome, b.agree) == ("not measurable", None) and b.reason.startswith("not measurable (sigma within resolution)")
    assert (c.outcome, c.verdict) == ("agree", "stable")
    assert (v.agreed, v.disagreed, v.not_measurable, v.measured, v.agreement) == (1, 1, 1, 2, 0.5)
    data = json.loads(dumps(v.to_dict()))
    assert (data["agreed"], data["disagreed"], data["not_measurable"], data["measured"]) == (1, 1, 1, 2)
    assert sorted(case["outcome"] for case in data["cases"]) == ["agree", "disagree", "not measurable"]
    text = render_map_text({"map": {"name": "m", "width": 1, "height": 1, "resolution": 0.1, "origin": [0, 0, 0]},
                            "inputs": {"grid_cells": [1, 1], "cell_size": 0.1, "unknown": "occupied", "V": 0.8, "W": 0.5, "tau": 0.3,
                                       "k": 2, "T": 0.065, "law": "grid", "model": "sampled", "hold": "command", "compute_delay": 1},
                            "NV_critical": 1.0, "segments": [], "validation": data,
                            "summary": {"segments": 0, "route_length_m": 0.0, "unstable_length_m": 0.0, "V_critical_min": None, "verdicts": {}}})
    assert "validation: 3 simulated segments: 1 agree, 1 disagree, 1 not measurable; agreement 50.0% of the 2 measured" in text


def test_cropped_grid_gives_the_same_run():
    """`crop_grid` keeps every cell a window sees: a run on the crop equals the run on the whole grid sample for sample
(to 1e-9 m: the crop's cell centres are computed from another origin, a round-off of 1e-16 m)."""
    from pfm_stability.sim.scenario import MeasureAxis, Pose, Scenario, Target

    grid, lines = _corridor_map([0.6, 0.9], math.radians(30.0))
    (x0, y0), _ = lines[1]  # L = 0.9 m: stable, a run to the finish
    local = crop_grid(grid, x0 - 4.0, x0 + 8.0, -1.0, 12.0)
    assert local.frozen and local.shape[0] < grid.shape[0]

    a = math.radians(30.0)
    start = Pose(x0 + math.sin(a) - 0.03 * math.cos(a), y0 + math.cos(a) + 0.03 * math.sin(a), a)

    def run(env):
        return Scenario("crop", CARMEL.robot, CARMEL.controller, env, start, Target.direction(a, finish=6.0), 10.0,
                        cell_ratio=0.003, measure=MeasureAxis((x0, y0), a))

    whole, crop = run_batch([run(grid), run(local)], record="offset").runs
    assert whole.offset.size == crop.offset.size > 100
    np.testing.assert_allclose(crop.offset, whole.offset, rtol=0, atol=1e-9)  # cell centres differ by round-off (1e-16 m)


# --------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "change,name",
    [
        ({"count": 0}, "count"),
        ({"count": -3}, "count"),
        ({"count": True}, "count"),
        ({"segments": []}, "segments"),
        ({"grid": "unfrozen"}, "grid"),
        ({"grid": np.zeros((10, 10))}, "grid"),
        ({"cell_ratio": 0.0}, "cell_ratio"),
        ({"window_cells": 32}, "window_cells"),
        ({"seed": -1}, "seed"),
    ],
)
def test_bad_arguments_raise_naming_the_argument(change, name):
    """Bad arguments raise ValueError naming the argument (nothing is simulated)."""
    grid = HistogramGrid(0, 0, 5, 5).freeze()
    segment = Segment(1.0, 1.0, 1.0, 4.0, 3.0, 2.0, 0.0, 1.0, 0.2, True)
    args = {"grid": grid, "segments": [segment], "cell_ratio": 0.003, "window_cells": 33, "count": 1, "seed": 0}
    args.update(change)
    if isinstance(args["grid"], str):
        args["grid"] = HistogramGrid(0, 0, 5, 5)
    with pytest.raises(ValueError, match=f"^{name} "):
        validate_map_segments(
            args["grid"], args["segments"], CARMEL.robot, CARMEL.controller,
            cell_ratio=args["cell_ratio"], window_cells=args["window_cells"], count=args["count"], seed=args["seed"],
        )


@functools.lru_cache(maxsize=None)
def _shipped(name: str, V: float):
    """(analysis, robot, controller, law) of a shipped map with the validation robot of benchmarks/validate_maps.py at V;
    computed once per worker (depot at 0.3 m/s is read by two tests, grouped on one worker: tests/conftest.py)."""
    from pathlib import Path

    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.reading.occupancy import load_map

    maps = Path(__file__).resolve().parent.parent / "pfm_stability" / "data" / "maps"
    robot = CARMEL.robot.replace(W=0.4, tau=0.1, k=20.0, V=V)
    controller = CARMEL.controller.replace(T=0.025, f=2.0)
    law = make_law("grid", robot, controller, cell_size=0.1, window_cells=33)
    return analyze_map(load_map(maps / f"{name}.yaml"), robot, controller, law, along_routes=False), robot, controller, law


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
@pytest.mark.xdist_group("map_validation_shipped")
def test_shipped_maps_clear_segments_agree_at_least_85_percent():
    """>= 85 % of >= 18 clear (|margin| > 10 %) measured segments of the shipped maps agree with the simulator.

    A subset of `python benchmarks/validate_maps.py` (which prints the full figure: depot, warehouse and
    tb3_sandbox at V = 0.2, 0.3, 0.4 m/s): depot and warehouse at the three speeds, every segment with a
    verdict (tb3_sandbox adds no clear measured segment). Each case is an independent check: the VFF
    simulator driving the map's own histogram grid against the loop model's verdict from the mean growth
    rate. Measured: 16/18 = 89 %, all predicted stable (the shipped maps' predicted-unstable pieces are too short to
    measure). A measured case is one that agrees or disagrees (`MapCase.outcome`): a σ within the run's resolution
    that the predicted σ̄ lies outside of is a disagreement (warehouse #20 at 0.4 m/s, predicted −0.60 1/s, measured
    −0.03), not set aside. The bar (85 %, 18) is docs/maps.md's; one more disagreement (15/18 = 83 %), or one
    measured segment fewer, fails it.
    """
    from pfm_stability.validation.maps import simulator_grid

    clear = []
    for name, V in ((name, V) for name in ("depot", "warehouse") for V in (0.2, 0.3, 0.4)):
        analysis, robot, controller, law = _shipped(name, V)
        count = sum(1 for s in analysis.segments if s.margin is not None and s.stable is not None)
        v = validate_map_segments(simulator_grid(analysis.grid), analysis.segments, robot, controller, cell_ratio=law.ratio,
                                  window_cells=law.window_cells, count=max(count, 1), seed=0)
        clear += [c for c in v.cases if c.agree is not None and abs(c.predicted_margin) > CLEAR_MARGIN]
    agreed = sum(1 for c in clear if c.agree)
    assert len(clear) >= 18, f"only {len(clear)} clear measured segments"
    assert agreed >= 0.85 * len(clear), f"{agreed}/{len(clear)} agree"


@pytest.mark.xdist_group("map_validation_shipped")
def test_end_effect_and_judged_part_follow_the_along_track_force():
    """The judged part is the longest run with |F_r·t| <= the end fraction, and no judged sample exceeds it.

    Independent route: the samples' F_r·t recomputed from the analysis' `Samples` for each segment; a
    segment whose run is shorter than a wavelength must say "end effect". Exact comparisons: the same
    arrays, thresholds applied by hand.
    """
    from pfm_stability.maps.deciding.verdicts import END_FRACTION, judged_run

    assert judged_run(np.array([0.9, 0.1, np.nan, -0.2, 0.7, 0.0]), 0.5) == (1, 4)
    assert judged_run(np.array([0.9, 0.8]), 0.5) == (0, 0)
    analysis, robot, *_ = _shipped("depot", 0.3)
    S = analysis.samples
    for k, s in enumerate(analysis.segments):
        if s.judged_from is None:
            continue
        mine = np.flatnonzero(S.segment == k)
        spacing = s.length / mine.size
        first, stop = round(s.judged_from / spacing), round(s.judged_to / spacing)
        assert not (np.abs(S.along[mine[first:stop]]) > END_FRACTION).any()
        if s.verdict == "end effect":
            assert s.judged_to - s.judged_from < s.wavelength


# ------------------------------------------------------------ short records (the fallback fit)
def _record(sigma, omega, periods, T=0.025, seed=None, noise=0.0):
    """(x, duration): 0.03 m·e^(σt)·cos(ωt + 0.3) plus a decaying real mode 0.01 m·e^(−3t) over `periods` periods,
    sampled every T; with `noise`, seeded Gaussian noise of that standard deviation (m)."""
    t = np.arange(0.0, periods * 2 * math.pi / omega, T)
    x = 0.03 * np.exp(sigma * t) * np.cos(omega * t + 0.3) + 0.01 * np.exp(-3.0 * t)
    if noise:
        x = x + np.random.default_rng(seed).normal(0.0, noise, t.size)
    return x, float(t[-1])


@pytest.mark.parametrize("seed", range(4))
def test_short_record_fit_reads_the_sign_and_rate_of_one_period(seed):
    """`short_record_fit` on 1–1.5 periods of a damped or growing oscillation plus a real mode (an order-3 linear
    recurrence, fitted at order 3): σ and ω to 1e-6 (the record is an exact recurrence: only round-off remains),
    random σ of both signs and ω far from CARMEL's.
    `resolved(..., fitted=True)` counts it although it spans less than one e-fold (the peaks' rule would not)."""
    from pfm_stability.validation.maps import (
        FIT_RESOLUTION,
        MIN_EFOLDS,
        resolved,
        short_record_fit,
    )

    rng = np.random.default_rng(seed)
    sigma = float(rng.choice([-1, 1]) * rng.uniform(0.1, 0.6))
    omega = float(rng.uniform(2.0, 15.0))
    x, duration = _record(sigma, omega, float(rng.uniform(1.0, 1.5)))
    fit = short_record_fit(x, 3, 0.025)
    assert fit is not None and fit[2] < 1e-6
    assert fit[0] == pytest.approx(sigma, abs=1e-6) and fit[1] == pytest.approx(omega, abs=1e-6)
    assert resolved(fit[0], duration, fitted=True) and abs(fit[0]) >= FIT_RESOLUTION
    if abs(sigma) * duration < MIN_EFOLDS:
        assert not resolved(fit[0], duration)  # the peaks' rule needs one e-fold; the fit does not


def test_short_record_fit_refuses_noisy_drifting_and_unresolved_records():
    """A record with noise of 3 % of its amplitude (fit residual ~1e-2, over `SHORT_RESIDUAL` = 1e-3) → None; a
    monotone drift (no oscillating root: nothing to read from a short record) → None; a fitted |σ| below
    `FIT_RESOLUTION` is not resolved however long the run, one at it is."""
    from pfm_stability.sim.metrics import linear_prediction
    from pfm_stability.validation.maps import (
        FIT_RESOLUTION,
        SHORT_RESIDUAL,
        resolved,
        short_record_fit,
    )

    noisy, _ = _record(-0.3, 6.0, 1.2, seed=1, noise=1e-3)
    assert linear_prediction(noisy, 3, 0.025)[2] > SHORT_RESIDUAL  # the premise: the fit itself is poor
    assert short_record_fit(noisy, 3, 0.025) is None
    t = np.arange(0.0, 1.0, 0.025)
    assert short_record_fit(0.03 * np.exp(-2.0 * t) + 0.01 * np.exp(-5.0 * t), 3, 0.025) is None
    assert not resolved(0.9 * FIT_RESOLUTION, 1e3, fitted=True) and not resolved(-0.9 * FIT_RESOLUTION, 1e3, fitted=True)
    assert resolved(FIT_RESOLUTION, 0.1, fitted=True) and resolved(-FIT_RESOLUTION, 0.1, fitted=True)
