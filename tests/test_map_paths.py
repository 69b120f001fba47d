"""Verdicts along every route of a map (`maps.deciding.paths`) and validation by driving (`validation.map_drives`).

docs/maps.md, "Verdicts along every route" and "Validation by driving". The expected values come from other
routes: the loop model's own rightmost root and `analyze_corridor` (what ``report --law grid`` prints) for a straight
corridor, numpy's eigenvalues of the model's transition matrix, closed-form test signals for the episode detector,
the geometry of the test maps for the routes, and the simulator for the validation.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from pfm_stability.analysis.criteria import analyze_corridor
from pfm_stability.laws.fields import make_law
from pfm_stability.maps.analysis import analyze_map
from pfm_stability.maps.judging.episodes import AMPLITUDE_THRESHOLD, episodes, lateral_episodes
from pfm_stability.maps.reading.occupancy import load_map
from pfm_stability.maps.judging.driven import SampledTransition
from pfm_stability.maps.deciding.decide import PATH_VERDICTS, WINDOW_PERIODS
from pfm_stability.maps.deciding.verdicts import EFOLDS
from pfm_stability.models import Loop, models_for
from pfm_stability.models.sampled import closed_loop_matrix
from pfm_stability.parameters import CARMEL, Corridor

ROBOT = CARMEL.robot.replace(W=0.4, tau=0.1, k=20.0, V=1.0)
CONTROLLER = CARMEL.controller.replace(T=0.025, f=2.0)
"""The robot of tests/test_map_corridors.py (a 25 ms loop: narrow corridors are unstable at 1 m/s, wide ones stable)."""


def write_map(directory: Path, pixels: np.ndarray, resolution: float = 0.1, name: str = "m") -> Path:
    """A map_server map (PGM + YAML) of `pixels` (row 0 at the top), origin (0, 0)."""
    Image.fromarray(np.asarray(pixels, dtype=np.uint8)).save(directory / f"{name}.pgm")
    path = directory / f"{name}.yaml"
    path.write_text(f"image: {name}.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path


def corridor(directory: Path, L: float, length: int = 200) -> Path:
    """A straight corridor along y, one-cell walls on cell centres at ±L from its axis, `length` cells long."""
    half = round(L / 0.1)
    img = np.full((length, 2 * half + 1), 254, dtype=np.uint8)
    img[:, 0] = img[:, -1] = 0
    return write_map(directory, img)


@lru_cache(maxsize=None)
def corridor_analysis(L: float, V: float, root: str):
    directory = Path(root) / f"c{L}_{V}"
    directory.mkdir(exist_ok=True)
    robot = ROBOT.replace(V=V)
    return analyze_map(load_map(corridor(directory, L)), robot, CONTROLLER, make_law("grid", robot, CONTROLLER))


SHARED_CORRIDORS = pytest.mark.xdist_group("map_corridor_0.6")
"""The tests here and in tests/test_map_driven.py that read `corridor_analysis` of the 1.2 m corridor: on one worker,
each analysis is made once (tests/conftest.py)."""


def corridors_root(tmp_path_factory) -> str:
    """The folder of `corridor_analysis`' maps: one per test session (per worker), the same for every module (the
    analyses are cached by it)."""
    folder = tmp_path_factory.getbasetemp() / "map_corridors"
    folder.mkdir(exist_ok=True)
    return str(folder)


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    return corridors_root(tmp_path_factory)


def _report(L: float):
    law = make_law("grid", ROBOT, CONTROLLER)
    return analyze_corridor(ROBOT, CONTROLLER, Corridor(L), ["sampled"], law=law)


def _model():
    return models_for(CONTROLLER, ["sampled"])[0], Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)


def test_transition_matrix_is_affine_in_the_loop_gain():
    """Φ(NV) = Φ0 + NV·Φ1 at random gains, against the model's own closed-loop matrix, to round-off (1e-12: the
    feedback row is the only one that depends on the gain, linearly); its spectral radius gives the model's root."""
    model, loop = _model()
    transition = SampledTransition.of(model, loop)
    rng = np.random.default_rng(1)
    for NV in rng.uniform(-5, 40, 6):
        Phi = np.asarray(closed_loop_matrix(loop, loop.loop_gain(float(NV)), model.hold, model.compute_delay))
        assert np.abs(transition.Phi0 + NV * transition.Phi1 - Phi).max() < 1e-12
        radius = np.abs(np.linalg.eigvals(Phi)).max()
        assert math.log(radius) / loop.T == pytest.approx(model.rightmost_root(float(NV), loop).real, abs=1e-9)


@SHARED_CORRIDORS
@pytest.mark.parametrize("L, factor", [(0.6, 0.7), (0.6, 1.4)])
def test_straight_corridor_growth_and_verdict_are_the_reports(root, L, factor):
    """In the middle of a straight corridor (more than half a window plus the active window's reach from its ends,
    where the window product covers a uniform N) the window's growth rate is the model's rightmost root at the report's N·V (the map's N is the grid
    law's to 2e-3, docs/maps.md, "Checked": σ to 2 % of |σ| + 0.01 1/s), and the verdict is the report's at that speed:
    stable below V* = NV*/N, unstable above (the speeds 0.7 and 1.4 V* leave 30 % of margin)."""
    ref = _report(L)
    V_star = ref.models["sampled"].critical["V_critical"]
    V = factor * V_star
    analysis = corridor_analysis(L, V, root)
    pv = analysis.paths
    model, loop = _model()
    middle = np.abs(pv.samples.y - 10.0) < 10.0 - pv.window / 2 - analysis.law.reach - 0.2
    assert middle.sum() > 20
    expected = model.rightmost_root(ref.N * V, loop).real
    assert np.abs(pv.window_growth[middle] - expected).max() < 0.02 * abs(expected) + 0.01
    verdict = "stable" if factor < 1 else "unstable"
    assert {PATH_VERDICTS[c] for c in pv.code[middle]} == {verdict}
    assert pv.summary()["decided_fraction"] == 1.0


def _window_efolds(N: float, V: float) -> float:
    """e-folds of the report's loop (the model's rightmost root at N·V) over the map's window of three periods
    (`paths.WINDOW_PERIODS` wavelengths at V take 3·2π/ω* s): the map's linear rule for a uniform gain."""
    model, loop = _model()
    omega = model.boundary(loop).omega_critical
    return model.rightmost_root(N * V, loop).real * WINDOW_PERIODS * 2 * math.pi / omega


@SHARED_CORRIDORS
def test_unstable_corridor_stretch_speed_is_calm_by_the_reports_loop(root):
    """The unstable stretch of a corridor driven at 1.4 V*: V* < V and margin V*/V − 1 < 0 (one answer); V* is a rung of
    the ladder where the stretch is calm, so the report's loop at the report's N (the corridor's middle) grows less than
    one e-fold over the window there (an independent route: the model's rightmost root, not the map's window product),
    and V* lies above the report's V* (no growth at all below it) less the ladder's half-step (5 % of V) and the ends'
    higher N (0.7 of it, as the corridor's last samples reach twice the middle's N, docs/maps.md, "Checked")."""
    ref = _report(0.6)
    V_star = ref.models["sampled"].critical["V_critical"]
    V = 1.4 * V_star
    pv = corridor_analysis(0.6, V, root).paths
    unstable = [s for s in pv.stretches if s.verdict == "unstable"]
    assert unstable and max(s.length for s in unstable) > 10
    worst = max(unstable, key=lambda s: s.length)
    assert worst.V_critical < V and worst.margin == pytest.approx(worst.V_critical / V - 1, rel=1e-12) and worst.margin < 0
    assert _window_efolds(ref.N, worst.V_critical) < EFOLDS
    assert 0.7 * V_star < worst.V_critical


@SHARED_CORRIDORS
def test_stable_corridor_stretch_speed_is_the_window_efold_edge(root):
    """The stable stretch of a corridor driven at 0.7 V*: V* >= V (one answer), and V* is where its worst window first
    grows one e-fold: the report's loop at the middle's N grows at most that much there (the worst window lies where N
    is highest; 2 % for the map's N against the law's and the window's discretisation), and V* lies above the report's
    V* (below it nothing grows)."""
    ref = _report(0.6)
    V_star = ref.models["sampled"].critical["V_critical"]
    V = 0.7 * V_star
    pv = corridor_analysis(0.6, V, root).paths
    stable = [s for s in pv.stretches if s.verdict == "stable"]
    longest = max(stable, key=lambda s: s.length)
    assert longest.length > 10 and longest.V_critical >= V and longest.margin >= 0
    assert V_star * (1 - 1e-6) < longest.V_critical
    assert _window_efolds(ref.N, longest.V_critical) <= EFOLDS * 1.02  # the middle grows no faster than the worst window


def test_open_hall_is_a_verdict_nothing_grows(tmp_path):
    """A 10 × 24 m hall: along its middle no wall is in the 3.3 m window, N = 0 exactly, and the answer is a verdict —
    stable, nothing grows (σ(0) = 0 with a stable heading loop; margin inf) — not "no verdict"."""
    img = np.full((240, 100), 254, dtype=np.uint8)
    img[0, :] = img[-1, :] = img[:, 0] = img[:, -1] = 0
    analysis = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER))
    pv = analysis.paths
    centre = (np.abs(pv.samples.x - 5.0) < 0.5) & (np.abs(pv.samples.y - 12.0) < 5.0)
    assert centre.sum() > 5
    assert np.all(pv.N_forward[centre] == 0) and np.all(pv.code[centre] == PATH_VERDICTS.index("stable"))
    assert pv.summary()["decided_fraction"] == 1.0
    open_stretches = [s for s in pv.stretches if s.N == 0.0]
    assert all(s.verdict == "stable" and s.cause is None and s.V_critical == math.inf and s.margin == math.inf for s in open_stretches)


@pytest.mark.parametrize("factor", [0.6, 2.0])
def test_a_carrot_too_near_makes_the_robot_weave_in_an_open_hall(tmp_path, factor):
    """Pure pursuit in the 10 × 24 m hall, no wall in the window: the robot follows a straight plan, pulled towards
    its point D = L ahead, so its only lateral gain is the goal's, N = K = 1/L (`paths._aim_stiffness`, A = 1 with
    no field): the loop is unstable once V/L passes NV* (ROBOT: NV* = 2.52 1/s, L* = V/NV* = 0.40 m). With
    V/L = 1.5 NV* the path taken is predicted unstable along its middle and the simulator's drive along it (3 cm
    off at the start, `Target.follow`) weaves in an episode there; with V/L = 0.6 NV* neither. (The factors keep
    clear of NV*: at 1.5 NV* the window's growth is 0.97 e-fold, at the verdict's one-e-fold threshold.) A path taken
    towards a point target instead has N = 1/max(D, W), D the goal's distance. N to 1e-9: a closed form, evaluated
    along another route than the loop's."""
    from pfm_stability.maps.analysis import judge_routes
    from pfm_stability.maps.reading.routes import path_of
    from pfm_stability.sim.engine import run_batch
    from pfm_stability.sim.scenario import Pose, Scenario, Target
    from pfm_stability.validation.maps import simulator_grid

    img = np.full((240, 100), 254, dtype=np.uint8)
    img[0, :] = img[-1, :] = img[:, 0] = img[:, -1] = 0
    analysis = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER))
    (model,), loop = models_for(CONTROLLER, ["sampled"]), Loop.of(ROBOT, CONTROLLER, c=0.0)
    L = ROBOT.V / (factor * model.boundary(loop).NV_critical)
    plan = [(5.0, 4.0), (5.0, 20.0)]
    judged = judge_routes(analysis, [path_of(plan, 0, "drive", goal=plan[-1], lookahead=L)], taken=True)
    middle = (judged.samples.y > 8.0) & (judged.samples.y < 16.0)
    assert np.allclose(judged.N_forward[middle], 1.0 / L, rtol=1e-9)  # the field adds nothing: no wall in the window
    # a point target instead (no plan): D is the goal's distance, at least W
    point = judge_routes(analysis, [path_of(plan, 0, "goals", goal=plan[-1])], taken=True)
    inside = (point.samples.y > 8.0) & (point.samples.y < 19.5)
    expected = 1.0 / np.maximum(20.0 - point.samples.y[inside], ROBOT.W)
    assert np.allclose(point.N_forward[inside], expected, rtol=1e-9)
    unstable = judged.code[middle] == PATH_VERDICTS.index("unstable")
    law = make_law("grid", ROBOT, CONTROLLER)
    scenario = Scenario(name="pursuit", robot=ROBOT, controller=CONTROLLER, environment=simulator_grid(analysis.grid),
                        start=Pose(5.03, 4.0, 0.0), target=Target.follow(plan, L, radius=0.3), duration=20.0,
                        cell_ratio=law.ratio, window_cells=law.window_cells)
    tr = run_batch([scenario], record="trajectory", metrics=False).runs[0].trajectory
    found, _ = episodes(tr.t, tr.x, tr.y, 2 * math.pi / model.boundary(loop).omega_critical)
    weaving = any(tr.y[np.searchsorted(tr.t, lo)] < 16.0 and tr.y[np.searchsorted(tr.t, min(hi, tr.t[-1]))] > 8.0 for lo, hi in found)
    if factor > 1:
        assert unstable.all() and weaving
    else:
        assert not unstable.any() and not found


def test_routes_run_straight_through_a_side_gap(tmp_path):
    """A 20 m corridor with a side opening at its middle (a T): the route along the corridor is one route through the
    junction (length 20 m within the cut at the map's ends, 0.5 m), the side branch its own."""
    img = np.full((200, 61), 0, dtype=np.uint8)
    img[:, 20:31] = 254  # corridor x in [2.0, 3.1) m
    img[95:106, 31:] = 254  # side branch to the right at y ~ 10 m
    analysis = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER))
    lengths = sorted(p.length for p in analysis.paths.paths)
    along = [p for p in analysis.paths.paths if abs(p.points[:, 0] - 2.55).max() < 0.2]
    assert len(along) == 1 and along[0].length == pytest.approx(20.0, abs=1.0)
    assert len(lengths) == 2


def test_episode_detector_on_closed_form_signals():
    """Growing oscillation e^{0.3 t}·sin(ω t) (from 1 cm): an episode; a decaying one: none; a constant 8 cm weave:
    an episode (above the 1.5 cm threshold); a 1 cm one: none; a single bend of the path (a step of 0.5 m): none; a
    swerve after a quiet stretch: none."""
    T, omega = 0.025, 2.0
    period = 2 * math.pi / omega
    t = np.arange(0, 30, T)
    assert lateral_episodes(t, 0.01 * np.exp(0.3 * t) * np.sin(omega * t), period)[0]
    assert not lateral_episodes(t, 0.2 * np.exp(-0.3 * t) * np.sin(omega * t), period)[0]
    assert lateral_episodes(t, 0.08 * np.sin(omega * t), period)[0]
    assert not lateral_episodes(t, 0.01 * np.sin(omega * t), period)[0]
    assert not lateral_episodes(t, 0.5 * (t > 15), period)[0]
    # a weave of 3-4 cm dying under 1 cm, then one swerve of 12 cm (turning-point amplitudes interpolated): the fitted
    # amplitude rises 1.4-1.6 e-folds over six turning points, but each side's falls before it rises: a swerve after
    # a quiet stretch, not growth
    turns = np.r_[0.0, 0.0, 0.04, 0.03, 0.006, 0.006, 0.12, 0.12, 0.01, np.zeros(31)]
    swerve = np.interp(t, period / 4 + np.arange(40) * period / 2, turns) * np.sin(omega * t)
    assert not lateral_episodes(t, swerve, period)[0]
    # in the plane: a weave about a diagonal line
    s = 1.0 * t
    x, y = s / math.sqrt(2) - 0.08 * np.sin(omega * t) / math.sqrt(2), s / math.sqrt(2) + 0.08 * np.sin(omega * t) / math.sqrt(2)
    found, amplitude = episodes(t, x, y, period)
    assert found and amplitude == pytest.approx(0.08, rel=0.1) and AMPLITUDE_THRESHOLD < 0.08


@pytest.mark.parametrize("reverse", [False, True])
def test_where_the_judged_part_is_cut_the_weave_is_not_turning(reverse):
    """The judge zeroes the first and last half period (the one-period average is not centred there); the samples next
    to those cuts are no turning points. A steady 2 cm weave judged over five of its extremes, cut a sixteenth of a
    period before the sixth (at cos(π/8) = 92 % of it, still rising), is no episode: five turning points, not the six
    of three periods (before, the cut's 1.8 cm counted as the sixth, past the 1.5 cm threshold); a quarter period more
    shows the sixth and is one. Likewise `lateral_extent`'s swing of two extremes cut before the third is 0, not the
    cut's value; with the third it holds the weave's 2 cm · sin(π/8)/(π/8) = 1.95 cm (to 1 %: the P/8 smoothing,
    `test_swing_is_the_weaves_amplitude_the_judge_sees`). Reversed in time, the cut lies just after an extreme at the
    start: the same."""
    from pfm_stability.maps.judging.episodes import lateral_extent

    T, omega = 0.025, 2.0
    period = 2 * math.pi / omega
    held = 0.02 * math.sin(math.pi / 8) / (math.pi / 8)

    def weave(extremes: int, past: float):
        t = np.arange(0.0, (2 * extremes + 3) * period / 4 + past * period + period / 2, T)
        w = 0.02 * np.sin(omega * t)
        return t, (w[::-1] if reverse else w)

    assert not lateral_episodes(*weave(5, -1 / 16), period)[0]
    assert lateral_episodes(*weave(5, 1 / 4), period)[0]
    assert lateral_extent(*weave(2, -1 / 16), period)[0].max() == 0.0
    assert lateral_extent(*weave(2, 1 / 4), period)[0].max() == pytest.approx(held, rel=0.01)


def test_swing_is_the_weaves_amplitude_the_judge_sees():
    """`swing` (a disagreement's simulated amplitude): a 5 cm weave about a diagonal line is held at its amplitude
    smoothed over P/8 as the episodes' judge smooths it, 5 cm · sin(π/8)/(π/8) = 4.87 cm (a moving average of a
    sinusoid over 1/8 of its period), to 1 % (the step T = P/126: the discrete average and the sampled peak); a bend
    of the path (a 90° arc of 2 m radius), whose distance from its own one-period average reaches centimetres, is
    no swing (0); zeros for a run shorter than two periods. `lateral_extent`'s swing of the same weave as a lateral signal
    agrees."""
    from pfm_stability.maps.judging.episodes import lateral_extent, swing

    T, omega = 0.025, 2.0
    period = 2 * math.pi / omega
    t = np.arange(0, 30, T)
    s, w = 1.0 * t, 0.05 * np.sin(omega * t)
    x, y = (s - w) / math.sqrt(2), (s + w) / math.sqrt(2)
    expected = 0.05 * math.sin(math.pi / 8) / (math.pi / 8)
    assert swing(t, x, y, period).max() == pytest.approx(expected, rel=0.01)
    assert lateral_extent(t, w, period)[0].max() == pytest.approx(expected, rel=0.01)
    n = int(round(period / T))
    assert not swing(t[:n], x[:n], y[:n], period).any()
    # a straight run, a quarter circle of radius 2 m, a straight run (1 m/s)
    heading = np.clip((t - 10.0) / (math.pi / 2 * 2.0), 0.0, 1.0) * math.pi / 2
    bx, by = np.cumsum(np.cos(heading)) * T, np.cumsum(np.sin(heading)) * T
    from pfm_stability.maps.judging.episodes import oscillation

    assert np.abs(oscillation(t, bx, by, period)[0]).max() > 0.015  # the bend is off its average by more than the threshold
    assert not swing(t, bx, by, period).any()


def test_excursion_is_how_far_the_loop_strays_however_irregular():
    """`lateral_extent`'s excursion (the driven loop's confirmation of a relay cycle): a steady 5 cm sinusoid about a line strays
    5 cm from its one-period average at every sample (the moving average of a whole period of a sinusoid is 0; within
    half a period either side lies a peak) to 1 % (the sampled peak at T = P/126). A weave too slow for
    a swing (half periods of 1.2 P: none held) of 20 cm still strays, by what its one-period average does
    not follow: (1 − sin(π/2.4)/(π/2.4))·20 cm = 5.2 cm, past the threshold (down to 97 % of it between the residual's
    peaks, which a one-period window can miss by 0.1 P; 1 % for the discrete average). Zeros for a run shorter than two
    periods."""
    from pfm_stability.maps.judging.episodes import lateral_extent

    T, omega = 0.025, 2.0
    period = 2 * math.pi / omega
    t = np.arange(0, 30, T)
    n = int(round(period / T))
    inner = slice(n, t.size - n)
    steady = lateral_extent(t, 0.05 * np.sin(omega * t), period)[1]
    assert steady[inner] == pytest.approx(np.full(steady[inner].size, 0.05), rel=0.01)
    slow = 0.2 * np.sin(omega / 2.4 * t)
    swing, strays = lateral_extent(t, slow, period)
    assert not swing.any()
    expected = (1 - math.sin(math.pi / 2.4) / (math.pi / 2.4)) * 0.2
    far = slice(2 * n, t.size - 2 * n)  # a period from either end: the average and the maximum each reach half a period
    strays = strays[far]
    # the residual's peaks are 1.2 P apart: a window of one period misses the nearest by up to 0.1 P, cos(2π·0.1/2.4)
    low = math.cos(2 * math.pi * 0.1 / 2.4)
    assert (strays >= 0.99 * low * expected).all() and (strays <= 1.01 * expected).all()
    assert expected > AMPLITUDE_THRESHOLD
    assert not np.any(lateral_extent(t[:n], slow[:n], period))


@pytest.mark.slow
@SHARED_CORRIDORS
def test_driving_finds_the_unstable_corridor_and_nothing_in_the_stable_one(root, monkeypatch):
    """Validation by driving on two corridors: at 1.4 V* the simulator's drives oscillate and the unstable stretches
    along their paths recall >= 90 % of the episodes' length with >= 90 % precision, and the predicted weave has the
    simulated one's size; at 0.7 V* no drive oscillates,
    nothing is predicted unstable, and recall and precision are undefined (None: nothing to measure), not counted as
    agreement, and all the length driven is predicted stable (specificity 100 %, of each kind of drive too); each figure lies in its 95 %
    interval over the drives, whose per-drive lengths add up to it. (Recall and precision are 100 % here: along the
    drives' own paths the loop is driven as the robot drove them and judged on its track in the plane, as the
    simulator's drives are — docs/maps.md, "Paths taken".)"""
    from pfm_stability.validation import map_drives
    from pfm_stability.validation.map_drives import drive_map

    sums, interval = [], map_drives._interval
    monkeypatch.setattr(map_drives, "_interval", lambda part, whole, rng: sums.append((part.sum(), whole.sum())) or interval(part, whole, rng))
    V_star = _report(0.6).models["sampled"].critical["V_critical"]
    unstable = drive_map(corridor_analysis(0.6, 1.4 * V_star, root), 6, seed=1)
    # the interval resamples the drives' own lengths: they add up to the figures' (sums of the same lengths in another order)
    L = unstable.lengths
    figures = (L["episode_recalled"], L["episode"], L["predicted_unstable_matched"], L["predicted_unstable_driven"])
    assert [v for pair in sums for v in pair] == pytest.approx(figures, rel=1e-12)
    assert unstable.counts["episodes"] > 0
    assert unstable.recall >= 0.9 and unstable.precision >= 0.9, (unstable.lengths, unstable.disagreements)
    false_alarms = [d for d in unstable.disagreements if d.kind == "false alarm"]
    assert unstable.lengths["false_alarm_swinging"] <= sum(d.length for d in false_alarms) + 1e-9
    assert all(d.simulated_amplitude >= 0 and d.predicted_amplitude >= 0 for d in unstable.disagreements)
    for figure, (lo, hi) in ((unstable.recall, unstable.recall_interval), (unstable.precision, unstable.precision_interval)):
        assert 0.0 <= lo <= figure <= hi <= 1.0
    # the weaves' size where either passes the threshold: the loop and the simulator hold the same rate-limited cycle,
    # so their ratio's quartiles lie within 15 % of 1 (measured 0.93, 0.98, 1.00: the grid's ripple and the drives'
    # ends move single samples) and nearly all the length within a factor 2 (measured 98 %)
    assert unstable.wobble.length > 0 and unstable.wobble.within >= 0.9, unstable.wobble
    assert all(0.85 <= q <= 1.15 for q in unstable.wobble.ratio_quartiles), unstable.wobble
    stable = drive_map(corridor_analysis(0.6, 0.7 * V_star, root), 6, seed=1)
    assert stable.counts["episodes"] == 0 and stable.lengths["predicted_unstable_driven"] == 0
    assert stable.wobble.length == 0.0 and stable.wobble.within is None  # neither weaves past the threshold: no figure
    assert stable.recall is None and stable.precision is None
    assert stable.specificity == pytest.approx(1.0, rel=1e-12) and stable.specificity_interval == pytest.approx((1.0, 1.0))
    assert stable.recall_interval is None and stable.precision_interval is None
    # the same figures per kind of drive: each kind's specificity is its own lengths' ratio; in the stable corridor 1
    for drives, expected in ((unstable, None), (stable, 1.0)):
        for kind in drives.by_kind.values():
            L = kind["lengths"]
            if L["quiet_driven"] == 0:  # every metre of this kind's driving near an episode: no figure
                assert kind["specificity"] is None and expected is None
                continue
            assert kind["specificity"] == pytest.approx(L["quiet_predicted_stable"] / L["quiet_driven"], rel=1e-12)
            assert 0.0 <= kind["specificity"] <= 1.0 and (expected is None or kind["specificity"] == pytest.approx(expected))


def test_the_interval_over_the_drives_is_the_ratios_resampling_spread():
    """`map_drives._interval`, the 95 % interval of a figure Σpart/Σwhole over the drives resampled: for 400 drives
    (lengths 1-3 m, 70 % of each one's length agreeing, or none) it is the delta method's R ± 1.96·SE,
    SE = √Σ(part − R·whole)² / Σwhole, to 10 % of its half-width (2000 resamples: the percentiles' own scatter is a
    few %, and the bootstrap's skew at n = 400 about as much); drives that all agree give a point; a drive with
    nothing to measure changes nothing."""
    from pfm_stability.validation.map_drives import _interval

    rng = np.random.default_rng(3)
    whole = rng.uniform(1.0, 3.0, 400)
    part = whole * (rng.random(400) < 0.7)
    R = part.sum() / whole.sum()
    half = 1.96 * math.sqrt(((part - R * whole) ** 2).sum()) / whole.sum()
    lo, hi = _interval(part, whole, np.random.default_rng(0))
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.1) and (lo + hi) / 2 == pytest.approx(R, abs=0.1 * half)
    assert _interval(whole, whole, np.random.default_rng(0)) == pytest.approx((1.0, 1.0), abs=1e-12)
    padded = _interval(np.append(part, 0.0), np.append(whole, 0.0), np.random.default_rng(0))
    assert padded == pytest.approx((lo, hi), abs=0.2 * half)


def test_user_routes_read_nav2_paths_waypoints_and_csv(tmp_path):
    """A Nav2 nav_msgs/Path echoed as YAML, waypoints as pairs and as mappings, several routes, and a CSV with a header:
    the points as written (m); a bad point is one line naming the file and the point."""
    from pfm_stability.maps.reading.user_routes import read_points, read_routes

    (tmp_path / "plan.yaml").write_text("header: {frame_id: map}\nposes:\n  - header: {frame_id: map}\n    pose:\n"
                                        "      position: {x: 1.0, y: 2.0, z: 0.0}\n      orientation: {w: 1.0}\n"
                                        "  - pose: {position: {x: 4.0, y: 6.0, z: 0.0}}\n")
    (route,) = read_routes(tmp_path / "plan.yaml")
    assert route.points.tolist() == [[1.0, 2.0], [4.0, 6.0]] and route.length == pytest.approx(5.0) and route.source == "path"
    (tmp_path / "wp.yaml").write_text("routes:\n  - [[0, 0], [3, 4]]\n  - [{x: 1, y: 1}, {x: 1, y: 3}]\n")
    assert [r.length for r in read_routes(tmp_path / "wp.yaml")] == pytest.approx([5.0, 2.0])
    (tmp_path / "r.csv").write_text("x,y\n0,0\n0,2.5\n")
    assert read_points(tmp_path / "r.csv")[0].tolist() == [[0.0, 0.0], [0.0, 2.5]]
    (tmp_path / "bad.yaml").write_text("waypoints:\n  - [0, 0]\n  - [1, nan]\n")
    with pytest.raises(ValueError, match=r"route file bad.yaml, point 2: a point must be"):
        read_routes(tmp_path / "bad.yaml")


@SHARED_CORRIDORS
def test_a_users_route_along_an_unstable_corridor_is_judged_unstable(root):
    """A waypoint route drawn by the user along the unstable corridor's axis (x = 0.65 m) is judged like the skeleton's
    route there: unstable at 1.4 V*, over most of its length (its ends within the window of the corridor's ends aside)."""
    from pfm_stability.maps.analysis import add_routes
    from pfm_stability.maps.reading.routes import path_of

    V_star = _report(0.6).models["sampled"].critical["V_critical"]
    analysis = add_routes(corridor_analysis(0.6, 1.4 * V_star, root), [path_of([[0.65, 3.0], [0.65, 17.0]], 0, "waypoints")])
    pv = analysis.paths
    mine = pv.samples.segment == len(pv.paths) - 1
    assert pv.paths[-1].source == "waypoints"
    assert np.mean(pv.code[mine] == PATH_VERDICTS.index("unstable")) > 0.8


def slam_hall(directory: Path, seed: int = 0) -> Path:
    """A SLAM-like map of a 20 × 15 m hall at 0.05 m/pixel: walls one pixel thin with unknown space behind them (a
    lidar sees a wall's face only), two thin partitions leaving a 0.8 m corridor and a 1.5 m passage, a row of posts,
    speckle noise (0.2 % of free pixels occupied or unknown) and a ragged unknown border."""
    rng = np.random.default_rng(seed)
    r = 0.05
    h, w = int(17 / r), int(22 / r)
    img = np.full((h, w), 205, dtype=np.uint8)  # unknown
    x0, y0 = int(1 / r), int(1 / r)
    hall = np.s_[y0:y0 + int(15 / r), x0:x0 + int(20 / r)]
    img[hall] = 254
    img[y0, x0:x0 + int(20 / r)] = img[y0 + int(15 / r) - 1, x0:x0 + int(20 / r)] = 0
    img[y0:y0 + int(15 / r), x0] = img[y0:y0 + int(15 / r), x0 + int(20 / r) - 1] = 0
    # a thin partition at x = 6 m with unknown behind it (its far side unseen), leaving a 0.8 m corridor along the wall
    px = x0 + int(6 / r)
    img[y0 + int(0.8 / r):y0 + int(10 / r), px] = 0
    img[y0 + int(0.8 / r):y0 + int(10 / r), px + 1:px + 6] = 205
    # a second partition at x = 13 m, a 1.5 m passage at its top
    qx = x0 + int(13 / r)
    img[y0 + int(1.5 / r):y0 + int(13.5 / r), qx] = 0
    for k in range(6):  # a row of posts
        cy, cx = y0 + int((3 + 2 * k) / r), x0 + int(17 / r)
        img[cy - 2:cy + 2, cx - 2:cx + 2] = 0
    free = img == 254
    noise = rng.random(img.shape) < 0.002
    img[free & noise & (rng.random(img.shape) < 0.5)] = 0
    img[free & noise & (img == 254)] = 205
    return write_map(directory, img[::-1].copy(), resolution=r, name="hall")


@pytest.mark.parametrize("unknown", ["occupied", "free"])
def test_slam_like_hall_is_decided_along_nine_tenths_of_its_routes(tmp_path, unknown):
    """The SLAM-like hall (no real maps of another building ship), at CARMEL's preset and at a small robot: at least
    90 % of its route length gets a verdict under either reading of unknown cells (the brief's bar), and what does not
    is named by reason in the summary."""
    occupancy = load_map(slam_hall(tmp_path))
    for robot in (CARMEL.robot, CARMEL.robot.replace(W=0.3, V=0.5)):
        law = make_law("grid", robot, CARMEL.controller)
        summary = analyze_map(occupancy, robot, CARMEL.controller, law, unknown=unknown).paths.summary()
        assert summary["route_length_m"] > 15 and summary["decided_fraction"] >= 0.9, summary
        assert set(summary["unjudged_length_m"]) == {"wall ahead both ways", "inside an obstacle", "wall ahead"}


def test_cli_judges_a_route_file_and_goals_and_refuses_a_bad_one(tmp_path):
    """``map --route FILE --goals FILE`` on a corridor: the JSON's routes hold the skeleton's, the user's (source
    "path") and the simulated drive between the goals (source "goals"), every one decided; a route file with one
    point is exit 2 with one line naming it."""
    from cli_helpers import run
    import json

    yaml_map = corridor(tmp_path, 0.6)
    (tmp_path / "plan.yaml").write_text("poses:\n  - pose: {position: {x: 0.65, y: 3.0}}\n  - pose: {position: {x: 0.65, y: 15.0}}\n")
    (tmp_path / "goals.csv").write_text("x,y\n0.65,2.0\n0.65,12.0\n")
    options = ["--W", "0.4", "--tau", "0.1", "--k", "20", "--T", "0.025", "--f", "2", "--V", "0.5", "--quiet", "--format", "json"]
    code, out, err = run(["map", str(yaml_map), "--route", str(tmp_path / "plan.yaml"), "--goals", str(tmp_path / "goals.csv"), *options])
    assert code == 0, err
    paths = json.loads(out)["paths"]
    assert [r["source"] for r in paths["routes"]] == ["skeleton", "path", "goals"]
    assert paths["summary"]["decided_fraction"] == 1.0
    (tmp_path / "one.yaml").write_text("waypoints: [[0.65, 3.0]]\n")
    code, out, err = run(["map", str(yaml_map), "--route", str(tmp_path / "one.yaml"), *options])
    assert code == 2 and out == "" and err.strip().count("\n") == 0 and "one.yaml" in err


def test_goals_round_a_corner_are_reached_along_the_plan(tmp_path):
    """Two goals in the two arms of an L-shaped corridor 1.2 m wide between one-cell walls (ROBOT at 0.5 m/s, stable
    there): the robot follows the skeleton's plan between them (`goal_routes`), so the path it took turns the corner
    and ends within the target's 0.3 m of the second goal (plus a cell, the path's spacing, and the period's
    averaging, V·P/4); the goal's
    distance and lookahead ride with the path, for its verdicts. The straight line between the goals crosses the
    corner's wall. A goal the skeleton does not reach (beyond the L's wall) is driven at straight."""
    from pfm_stability.validation.map_drives import goal_routes

    img = np.full((120, 120), 254, dtype=np.uint8)  # row 0 at the top: cell centres at y = 12 − (row + 0.5)·0.1
    img[107, 10:82] = img[119, 10:95] = 0  # the arm along x: walls at y = 1.25 and 0.05 m
    img[10:108, 82] = img[10:120, 94] = 0  # the arm along y: walls at x = 8.25 and 9.45 m
    img[107:120, 10] = img[10, 82:95] = 0  # its ends
    robot = ROBOT.replace(V=0.5)
    analysis = analyze_map(load_map(write_map(tmp_path, img)), robot, CONTROLLER, make_law("grid", robot, CONTROLLER))
    start, goal = np.array([3.0, 0.65]), np.array([8.85, 9.0])
    (route,) = goal_routes(analysis, [start, goal])
    assert route.source == "goals" and route.goal == (8.85, 9.0) and route.lookahead == 2.0
    period = 2 * math.pi / models_for(CONTROLLER, ["sampled"])[0].boundary(Loop.of(robot, CONTROLLER, c=0.0)).omega_critical
    assert np.hypot(*(route.points[-1] - goal)) < 0.3 + analysis.grid.cell_size + robot.V * period / 4
    assert route.points[:, 1].max() > 8.0 and route.points[:, 0].min() < 3.1  # from the first arm up the second
    # a goal outside the L (the free space beyond its one-cell wall): the skeleton does not join them, the robot
    # goes straight at it (a point target: no lookahead) and stops at the wall
    (straight,) = goal_routes(analysis, [start, np.array([3.0, 3.0])])
    assert straight.goal == (3.0, 3.0) and straight.lookahead == math.inf
    assert straight.points[:, 1].max() < 1.25


@pytest.mark.slow
def test_thin_slam_walls_with_unknown_behind_the_simulation_sides_with_unknown_free(tmp_path):
    """The --unknown evidence (docs/maps.md, "Map files"): a 0.8 m corridor whose walls are one pixel thin (0.05 m) with
    unknown space behind them, as SLAM draws a wall it saw from one side. Read with unknown = occupied the walls are
    1 m thick and N is several times larger, so V* several times smaller, than with unknown = free. The robot's own
    grid fills from its sensors (only the faces), so the simulator on the thin-wall grid is the judge: driven at the
    geometric mean of the two V* (unstable by the occupied reading), it does not oscillate (no episode), as
    unknown = free predicts. (Measured: V* 0.074 m/s occupied, 0.29 m/s free — the latter from the windows at the
    map's ends, where the truncated walls raise N; at 1.3 × 0.29 m/s the drives show no episode either.)"""
    from pfm_stability.validation.map_drives import drive_map

    r = 0.05
    img = np.full((400, 56), 205, dtype=np.uint8)  # 20 m long; x: 1 m unknown, wall, 0.8 m free, wall, 1 m unknown
    img[:, 20] = img[:, 36] = 0
    img[:, 21:36] = 254
    occupancy = load_map(write_map(tmp_path, img, resolution=r))
    V_star = {}
    for unknown in ("occupied", "free"):
        robot = ROBOT.replace(V=0.5)
        analysis = analyze_map(occupancy, robot, CONTROLLER, make_law("grid", robot, CONTROLLER), unknown=unknown)
        V_star[unknown] = min(s.V_critical for s in analysis.paths.stretches if s.V_critical is not None and s.length > 5)
    assert V_star["free"] > 2 * V_star["occupied"]
    V = math.sqrt(V_star["free"] * V_star["occupied"])
    robot = ROBOT.replace(V=V)
    thin = analyze_map(occupancy, robot, CONTROLLER, make_law("grid", robot, CONTROLLER), unknown="free")
    judged = drive_map(thin, 4, seed=2)
    assert judged.counts["episodes"] == 0, judged.counts


def _rack_grid(law, rack_column: int, width: int = 60, length: int = 200):
    """A histogram grid `width` × `length` cells (c = law.cell_size) with one solid rack: every cell from column
    `rack_column` to the grid's right edge occupied (certainty law.cv)."""
    from pfm_stability.maps.reading.field import HistogramMap

    cv = np.zeros((width, length), dtype=np.int16)
    cv[rack_column:, :] = law.cv
    return HistogramMap(0.0, 0.0, law.cell_size, cv)


def test_window_edge_relay_where_a_rack_enters_the_window():
    """`maps.deciding.relay.window_relay` on a route along y with a solid rack on its +x side (CARMEL's grid law, window 33
    cells, c = 0.1 m). With the path 16 cells (h) from the rack's first column the window gains that column when the
    robot moves one cell towards it: F_n falls by the column's force (restoring: a relay). Expected size, by hand:
    the force of one column of 33 cells at 16.5 cells' lateral distance, Σ ρ·W^n·cv·dx/(dx² + dy²)^((n+1)/2) over the
    window's rows (dy = b·c, b = −16 … 16), within 10 % (the robot's position within its cell shifts dx and dy by up
    to half a cell, averaged over the cell along t). F_n is 0 on the far side of that boundary and pushes the robot
    back on the rack's side: the net force changes sign across the jump. A path 5 cells from the rack (F_n pushes
    it away on both sides: no sign change) and a path with no rack within reach have no relay."""
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.deciding.relay import window_relay

    law = make_law("grid", CARMEL.robot, CARMEL.controller)
    h, c = law.window_cells // 2, law.cell_size
    grid = _rack_grid(law, 40)
    y = np.full(3, 10.05)
    t = (np.zeros(3), np.ones(3))
    x = np.array([(40 - h - 0.5 + 0.125) * c, (40 - 5 + 0.5) * c, (40 - h - 8 + 0.5) * c])  # the 1st 3/8 cell from the edge
    relay, jump = window_relay(grid, law, x, y, *t, np.zeros(3))
    assert relay.tolist() == [True, False, False]
    assert jump[0] == pytest.approx(_column_force(law, h), rel=0.1)
    assert jump[1:].tolist() == [0.0, 0.0]
    # the mirror image (rack on the −x side, entering when the robot moves along −x): the same relay
    mirror = _rack_grid(law, 40)
    from pfm_stability.maps.reading.field import HistogramMap

    mirror = HistogramMap(0.0, 0.0, c, np.ascontiguousarray(mirror.cv[::-1]))
    relay, jump_m = window_relay(mirror, law, 60 * c - x[:1], y[:1], *(v[:1] for v in t), np.zeros(1))
    assert relay.tolist() == [True] and jump_m[0] == pytest.approx(jump[0], rel=1e-6)


def test_a_relay_stands_only_where_the_loop_driven_through_the_profile_strays_as_far(tmp_path, monkeypatch):
    """The window-edge relay with the sampled model (`maps.deciding.paths`, docs/maps.md): the describing function of one jump
    is an estimate of the cycle; the loop driven through the whole profile (`decide.driven_loops`) is run there too, and the
    relay stands only where that loop strays as far from its one-period average (its excursion) as well. In a 3 m
    aisle between a one-cell wall and a solid rack (the test robot; the equilibrium at the window's edge, a restoring
    jump on every sample of the skeleton's route), the describing function alone predicts a relay cycle past the
    threshold on every sample: with the driven loop's excursion replaced by 1 m those are the relay samples, with 0
    none remain. The real driven loop strays less than the threshold there, so the route is stable — and the VFF
    simulator agrees: four drives along the aisle find no episode (their largest weave held a period is under 2 cm)."""
    import pfm_stability.maps.deciding.decide as decide
    from pfm_stability.maps.analysis import judge_routes
    from pfm_stability.validation.map_drives import drive_map

    gap = 30  # free cells between the wall (column 0) and the rack
    pixels = np.full((200, 1 + gap + 20), 254, dtype=np.uint8)
    pixels[:, 0] = 0
    pixels[:, 1 + gap:] = 0
    analysis = analyze_map(load_map(write_map(tmp_path, pixels)), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER))
    routes = analysis.paths.paths
    real = decide.driven_loops

    def swinging(value):
        def driven(*args):
            return [replace(loop, excursion=np.full_like(loop.excursion, value)) for loop in real(*args)]
        return driven

    monkeypatch.setattr(decide, "driven_loops", swinging(1.0))
    alone = judge_routes(analysis, routes)
    assert alone.relay.all() and alone.relay.size > 100
    monkeypatch.setattr(decide, "driven_loops", swinging(0.0))
    assert not judge_routes(analysis, routes).relay.any()
    monkeypatch.setattr(decide, "driven_loops", real)
    pv = analysis.paths
    assert not pv.relay.any() and (pv.code == PATH_VERDICTS.index("stable")).all()
    drives = drive_map(analysis, 4, seed=0)
    assert drives.counts["episodes"] == 0 and max(d.max_amplitude for d in drives.drives) < 0.02


def _column_force(law, h):
    """F_r/F_ct of one column of cells (certainty law.cv) at (h + 0.5) cells across, rows −h … h (the law's scale
    ρ·W^n, `maps.reading.field.window_kernels`' weights), by hand."""
    c = law.cell_size
    dx, dy = (h + 0.5) * c, np.arange(-h, h + 1) * c
    return float(law.ratio * law.W**law.n * law.cv * np.sum(dx / (dx * dx + dy * dy) ** ((law.n + 1) / 2)))


@SHARED_CORRIDORS
def test_a_direction_never_driven_is_never_the_worse_one(root):
    """A path taken is driven one way: its reverse direction is stopped at every sample (N_reverse nan), so each
    sample's window growth is the forward direction's and every stretch's direction is forward. Along the middle of
    the 1.2 m corridor's axis (uniform N, no end in the window) the window's growth equals the sampled loop's own
    growth rate log ρ(Φ(k·N·V))/T (`models.sampled.closed_loop_matrix`'s eigenvalues, an independent route from the
    window's renormalized product): to 1e-9 1/s (measured 5e-14: round-off over the window's 128 steps), at a speed
    far inside the boundary and one near it. (A window with no step once counted as 0 e-folds, "no growth", and
    won over the decaying forward direction: growth 0, N 0, V* = V, and the relay judged with the force of a
    direction never driven — a bookstore drive's weave missed.)"""
    from pfm_stability.maps.analysis import judge_routes
    from pfm_stability.maps.reading.routes import path_of

    for V in (0.5, 0.9):
        analysis = corridor_analysis(0.6, V, root)
        pv = judge_routes(analysis, [path_of([[0.65, 6.0], [0.65, 14.0]], 0, "drive")], taken=True)
        assert np.isnan(pv.N_reverse).all()
        assert pv.stretches and all(s.direction == "forward" for s in pv.stretches if s.verdict in ("stable", "unstable"))
        middle = (pv.samples.y > 8.0) & (pv.samples.y < 12.0)
        loop = Loop.of(ROBOT.replace(V=V), CONTROLLER)
        own = [np.log(np.abs(np.linalg.eigvals(closed_loop_matrix(loop, ROBOT.k * N * V, CONTROLLER.hold,
                                                                     CONTROLLER.compute_delay))).max()) / CONTROLLER.T
               for N in pv.N_forward[middle]]
        assert middle.sum() > 20 and np.allclose(pv.window_growth[middle], own, rtol=0, atol=1e-9)
        assert (pv.window_growth[middle] < 0).all()


def test_a_path_taken_is_linearized_at_itself_away_from_the_equilibrium(root):
    """`judge_routes(..., taken=True)` (a path the robot drove, held there by its goal): along the 1.2 m corridor
    (axis x = 0.65 m, equilibrium on it by symmetry), a path 0.3 m off the axis — farther than W/2 = 0.2 m (ROBOT) —
    is linearized at its own points (the linearization point is the path point, to 1e-12 m), while the same path judged as a route keeps the axis' equilibrium (its linearization point within a cell of
    x = 0.65 m); a path 0.1 m off (within W/2) keeps it too."""
    from pfm_stability.maps.analysis import judge_routes
    from pfm_stability.maps.reading.routes import path_of

    analysis = corridor_analysis(0.6, 0.5, root)
    assert ROBOT.W / 2 == pytest.approx(0.2)
    far, near = path_of([[0.95, 6.0], [0.95, 14.0]], 0, "drive"), path_of([[0.75, 6.0], [0.75, 14.0]], 1, "drive")
    taken = judge_routes(analysis, [far, near], taken=True)
    as_route = judge_routes(analysis, [far], taken=False)
    mine = taken.samples.segment == 0
    assert np.allclose(taken.px[mine], 0.95, atol=1e-12)
    assert np.allclose(as_route.px, 0.65, atol=0.1)
    assert np.allclose(taken.px[~mine], 0.65, atol=0.1)


def test_a_predicted_stretch_the_drive_ended_in_is_not_measured():
    """`map_drives._cut_short`: of the predicted-unstable stretches along a drive's own path (samples 1 m apart), those
    that reach a sample passed only in the drive's last three periods lose the samples within `reach` before the first
    such sample (matched or not); a stretch ending one sample before them keeps all; samples without a verdict (a wall
    ahead) between two stretches join them; no unstable sample, nothing."""
    from pfm_stability.validation.map_drives import _cut_short

    path = np.arange(100, 120)  # the drive's own path: samples 100..119 of the scored set, in order
    arc = np.zeros(130)
    arc[path] = np.arange(20.0)  # m
    unstable = np.zeros(130, dtype=bool)
    unstable[[103, 104, 105, 106, 110, 111, 112, 113, 114, 117, 118, 119]] = True
    none = np.zeros(130, dtype=bool)
    everything = math.inf
    assert _cut_short(path, arc, unstable, none, np.array([112, 113]), everything).tolist() == [110, 111, 112, 113, 114]
    assert _cut_short(path, arc, unstable, none, np.array([112, 113]), 1.0).tolist() == [111, 112, 113, 114]
    assert _cut_short(path, arc, unstable, none, np.array([107, 108, 109]), everything).tolist() == []
    assert _cut_short(path, arc, unstable, none, np.array([106, 119]), everything).tolist() == [103, 104, 105, 106, 117, 118, 119]
    assert _cut_short(path, arc, none, none, np.array([112]), everything).size == 0
    wall_ahead = none.copy()
    wall_ahead[[107, 108, 109]] = True  # joins 103-106 to 110-114
    assert _cut_short(path, arc, unstable, wall_ahead, np.array([113]), everything).tolist() == [103, 104, 105, 106, 110, 111, 112, 113, 114]
    assert _cut_short(path, arc, unstable, wall_ahead, np.array([113]), 4.0).tolist() == [110, 111, 112, 113, 114]
