"""``map --wobble TOL``: each straight segment's and route stretch's speed limit by wobble tolerance (docs/maps.md,
"Speed limits by wobble tolerance").

A straight synthetic corridor (`test_map_corridors.corridor_map`: one-cell walls on histogram cell centres at ±L) is
the straight corridor of half-width L that `analysis.wobble.corridor_wobble` models, so the segment's half-width must be
the built L and its V_tolerance ``corridor_wobble``'s for the same robot, law and L; the mask's segment zone follows it.
The same holds for a route stretch along the corridor's middle (a user's route there: its windows see no wall ahead),
and the mask's value over the stretch, read back from the PGM, follows it.
"""

from __future__ import annotations

import io
import json
import math
from dataclasses import replace

import numpy as np
import pytest
from PIL import Image

from cli_helpers import VALIDATOR, run
from test_map_corridors import ROBOT as FAST_STEERING, CONTROLLER as FAST_CONTROLLER, corridor_map
from pfm_stability.analysis.wobble import corridor_wobble
from pfm_stability.laws.fields import make_law
from pfm_stability.maps.analysis import analyze_map, judge_routes
from pfm_stability.maps.reading.occupancy import load_map
from pfm_stability.maps.deciding.outputs import speed_limits, speed_mask_pgm
from pfm_stability.maps.reading.routes import path_of
from pfm_stability.maps.deciding.stretch_speed import BISECT_STEPS, SPEED_STEP
from pfm_stability.maps.deciding.wobble_zones import V_CRITICAL_AGREEMENT, wobble_summary, with_wobble
from pfm_stability.parameters import CARMEL

pytestmark = pytest.mark.xdist_group("map_wobble")  # the `corridor` and `routed` analyses once per suite (tests/conftest.py)

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
L = 0.6
"""CARMEL (W = 0.8 m, V = 0.8 m/s) in a corridor of half-width 0.6 m: V* ≈ 0.61 m/s < V, supercritical."""
TOL = 0.1


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    """(map path, analysis without the routes) of the straight corridor along y; shared (one analysis, ~0.5 s)."""
    path, _ = corridor_map(tmp_path_factory.mktemp("wobble"), L, 1, "y")
    law = make_law("grid", ROBOT, CONTROLLER)
    return path, analyze_map(load_map(path), ROBOT, CONTROLLER, law, along_routes=False)


def _zone_percent(analysis, limits) -> int:
    """The mask's value at the cell under the segment's middle."""
    s = analysis.segments[0]
    i, j = analysis.occupancy.cell_of((s.x0 + s.x1) / 2, (s.y0 + s.y1) / 2)
    return int(limits[int(j), int(i)])


def test_segment_v_tolerance_is_corridor_wobbles_and_the_mask_follows_it(corridor):
    """The segment's L is the built half-width (to 1e-9 m: the walls are straight rows of cell centres, the fit exact up
    to round-off); its V_tolerance is ``corridor_wobble``'s for the same robot, grid law and the built L (to 1e-6 m/s:
    the same branch, the only difference L's round-off); trusted here (supercritical, harmonics small), so the mask's
    zone is floor(100·V_tolerance/V) — a different percentage from V*'s, so the check discriminates — and without the
    wobble it is V*'s as before."""
    _, analysis = corridor
    (plain,) = analysis.segments
    expected = corridor_wobble(ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER), L, TOL)
    assert expected.criticality == "supercritical" and expected.V_tolerance > expected.V_critical
    relaxed = with_wobble(analysis, TOL)
    (segment,) = relaxed.segments
    w = segment.wobble
    assert w.L == pytest.approx(L, abs=1e-9)
    assert w.V_tolerance == pytest.approx(expected.V_tolerance, abs=1e-6)
    assert w.V_limit == w.V_tolerance and w.reason is None
    assert segment.V_critical == plain.V_critical < w.V_limit < ROBOT.V  # the verdict itself unchanged
    with_tol = _zone_percent(relaxed, speed_limits(relaxed))
    without = _zone_percent(analysis, speed_limits(analysis))
    assert with_tol == math.floor(100 * expected.V_tolerance / ROBOT.V)
    assert without == math.floor(100 * plain.V_critical / ROBOT.V) < with_tol
    assert plain.wobble is None and "wobble" not in plain.to_dict()


def test_untrusted_wobble_keeps_v_star(tmp_path):
    """A fast-steering 25 ms robot (`test_map_corridors`' corridors) at L = 0.45 m: its cycle at V_tolerance is shaped
    by the steering-rate limit, the describing function is not trusted, so the mask keeps V* (and says why) while the
    JSON still gives corridor_wobble's V_tolerance (to 1e-6 m/s, as above)."""
    path, _ = corridor_map(tmp_path, 0.45, 1, "x")
    law = make_law("grid", FAST_STEERING, FAST_CONTROLLER)
    analysis = with_wobble(analyze_map(load_map(path), FAST_STEERING, FAST_CONTROLLER, law, along_routes=False), 0.05)
    (segment,) = analysis.segments
    expected = corridor_wobble(FAST_STEERING, FAST_CONTROLLER, law, 0.45, 0.05)
    assert segment.wobble.V_tolerance == pytest.approx(expected.V_tolerance, abs=1e-6)
    assert segment.wobble.V_limit == segment.V_critical and "not trusted" in segment.wobble.reason
    assert _zone_percent(analysis, speed_limits(analysis)) == math.floor(100 * segment.V_critical / FAST_STEERING.V)


def test_cli_json_gives_each_segments_wobble_and_without_it_nothing_changes(corridor):
    """``map --wobble TOL --format json``: schema-valid, each segment's ``wobble`` with corridor_wobble's V_tolerance
    (1e-6 m/s); without --wobble the same JSON but for what the wobble adds — no ``wobble`` key, and no segments (the
    straight segments are the wobble's zones; the route stretches are the map's one result set) — and a tolerance out
    of range exits 2 with one line."""
    path, _ = corridor
    args = ["map", str(path), "--preset", "carmel", "--format", "json", "--quiet"]
    code, out, err = run([*args, "--wobble", str(TOL)])
    assert code == 0, err
    data = json.loads(out)
    assert not list(VALIDATOR.iter_errors(data))
    expected = corridor_wobble(ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER), L, TOL)
    (segment,) = data["segments"]
    assert segment["wobble"]["V_tolerance"] == pytest.approx(expected.V_tolerance, abs=1e-6)
    assert segment["wobble"]["tolerance"] == TOL
    code, plain, err = run(args)
    assert code == 0, err
    plain = json.loads(plain)
    assert not list(VALIDATOR.iter_errors(plain))
    assert plain["segments"] is None and "wobble" not in plain
    strip = lambda d: {k: v for k, v in d.items() if k not in ("timing", "segments")}
    for stretch in data["paths"]["stretches"]:
        assert stretch.pop("wobble")["tolerance"] == TOL
    assert data.pop("wobble")["tolerance"] == TOL
    assert strip(data) == strip(plain)
    code, out, err = run([*args, "--wobble", "-1"])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "wobble" in err


SHORT_CELLS = 120
"""12 m corridors for the short route stretches (their analysis with the routes ~1 s)."""
LONG_CELLS = 200
"""20 m corridors for the long ones (~1.5 s)."""
SHORT_ORIGIN = (-7.3, 2.1)
ROUTE_SPAN = (3.0, 9.0)
"""The user's route along the corridor's axis, y from origin + 3 m to origin + 9 m: 3 m from the corridor's ends, so
its windows (clipped at the route's ends) see the straight corridor alone, no wall ahead."""
LONG_SPAN = (3.0, 17.0)
"""The same, 14 m, in the 20 m corridor."""
ROUTE_TOL = 0.15
"""The tolerance of the long route's stretch: CARMEL's cycle in the 0.6 m corridor reaches 0.15 m at V_tolerance ≈
0.647 m/s, faster than that stretch's V* (≈ 0.57 m/s: the loop driven along it weaves above), so the mask relaxes."""


def short_corridor(directory, half_width: float, cells: int = SHORT_CELLS, span: tuple = ROUTE_SPAN):
    """(YAML path, the user's route along the axis) of a corridor along y, `cells` long, one-cell walls on cell centres
    at ±half_width."""
    gap = round(2 * half_width / 0.1)
    img = np.full((cells, gap + 1), 254, dtype=np.uint8)
    img[:, 0] = img[:, gap] = 0
    Image.fromarray(img).save(directory / "short.pgm")
    path = directory / "short.yaml"
    path.write_text(f"image: short.pgm\nresolution: 0.1\norigin: [{SHORT_ORIGIN[0]}, {SHORT_ORIGIN[1]}, 0.0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    axis = SHORT_ORIGIN[0] + (gap / 2 + 0.5) * 0.1
    return path, path_of([(axis, SHORT_ORIGIN[1] + span[0]), (axis, SHORT_ORIGIN[1] + span[1])])


@pytest.fixture(scope="module")
def routed(tmp_path_factory):
    """(map path, route file, analysis with the skeleton's route and the user's) of the long corridor; shared."""
    directory = tmp_path_factory.mktemp("routed")
    path, route = short_corridor(directory, L, LONG_CELLS, LONG_SPAN)
    csv = directory / "route.csv"
    csv.write_text("".join(f"{float(x)!r},{float(y)!r}\n" for x, y in route.points))
    return path, csv, analyze_map(load_map(path), ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER), routes=[route])


def _pgm_percent(analysis, x: float, y: float, a_max: float | None = None) -> int:
    """The speed limit (% of V) Nav2 reads from the mask's PGM (upstream dilation `a_max`) at (x, y): the image read back
    by PIL, row 0 at the top, and map_server's scale mode rint(100·(255 − v)/255) (written out here, not the library's
    `pixel_to_percent`)."""
    image = np.asarray(Image.open(io.BytesIO(speed_mask_pgm(analysis, a_max))))
    occupancy = analysis.occupancy
    i = int(math.floor((x - occupancy.origin[0]) / occupancy.resolution))
    j = int(math.floor((y - occupancy.origin[1]) / occupancy.resolution))
    return int(np.rint(100 * (255 - int(image[image.shape[0] - 1 - j, i])) / 255))


def test_route_stretch_v_tolerance_is_corridor_wobbles_and_the_mask_follows_it(routed):
    """The user's 14 m route along the corridor's middle: its unstable stretch's L is the built half-width (1e-9 m,
    straight rows of cell centres) and its V_tolerance ``corridor_wobble``'s for the same robot, grid law and L (1e-6
    m/s: the same branch), trusted (reason None); its speed of zero growth NV*/N is the straight corridor's V* to
    `V_CRITICAL_AGREEMENT`, and its V* lies below V_tolerance (the loop driven along it weaves from ≈ 0.58 m/s). The
    mask, written as the PGM and read back, holds floor(100·V_tolerance/V) over the stretch (with only that route's
    zones: the segment and the skeleton's route would cover the same cells), and floor(100·V*/V) without the wobble —
    two different percentages. The skeleton's route runs the corridor's whole length: its worst window sees the map's
    end (a wall ahead raises N), its NV*/N is off the straight corridor's by more than the agreement, so it keeps V*
    with that reason."""
    _, _, analysis = routed
    expected = corridor_wobble(ROBOT, CONTROLLER, make_law("grid", ROBOT, CONTROLLER), L, ROUTE_TOL)
    relaxed = with_wobble(analysis, ROUTE_TOL)
    skeleton, own = [[s for s in relaxed.paths.stretches if s.route == r] for r in (0, 1)]
    (unstable,) = [s for s in own if s.verdict == "unstable"]
    w = unstable.wobble
    assert w.L == pytest.approx(L, abs=1e-9)
    assert w.V_tolerance == pytest.approx(expected.V_tolerance, abs=1e-6)
    assert w.V_limit == w.V_tolerance and w.reason is None and w.kept is None
    assert analysis.NV_critical / unstable.N == pytest.approx(expected.V_critical, rel=V_CRITICAL_AGREEMENT)
    assert unstable.V_critical < w.V_tolerance
    (whole,) = skeleton
    assert whole.verdict == "unstable" and abs(analysis.NV_critical / whole.N / expected.V_critical - 1) > V_CRITICAL_AGREEMENT
    assert whole.wobble.kept == "not a straight corridor" and whole.wobble.V_limit == whole.V_critical
    route = analysis.paths.paths[1]
    alone = replace(analysis, segments=(), paths=judge_routes(analysis, [route]))
    middle = ((unstable.x0 + unstable.x1) / 2, (unstable.y0 + unstable.y1) / 2)
    assert _pgm_percent(with_wobble(alone, ROUTE_TOL), *middle) == math.floor(100 * expected.V_tolerance / ROBOT.V)
    assert _pgm_percent(alone, *middle) == math.floor(100 * unstable.V_critical / ROBOT.V) < math.floor(100 * expected.V_tolerance / ROBOT.V)
    assert "wobble" not in analysis.paths.stretches[0].to_dict() and "wobble" in relaxed.paths.stretches[0].to_dict()


@pytest.mark.parametrize("cause", ["relay", "forced weave", "collision course"])
def test_relay_weave_and_collision_stretches_keep_v_star(routed, cause):
    """A stretch whose cause is "relay" (the window-edge relay), "forced weave" or "collision course" is not a Hopf
    cycle of the straight corridor: the same stretch as above, its cause replaced, keeps its V* (exactly: nothing is
    computed) and says why, and the mask over it holds floor(100·V*/V)."""
    _, _, analysis = routed
    route = analysis.paths.paths[1]
    pv = judge_routes(analysis, [route])
    stretches = tuple(replace(s, cause=cause) if s.verdict == "unstable" else s for s in pv.stretches)
    alone = replace(analysis, segments=(), paths=replace(pv, stretches=stretches))
    relaxed = with_wobble(alone, ROUTE_TOL)
    (unstable,) = [s for s in relaxed.paths.stretches if s.verdict == "unstable"]
    assert unstable.wobble.V_limit == unstable.V_critical and unstable.wobble.kept == cause
    assert "not a Hopf cycle" in unstable.wobble.reason and unstable.wobble.V_tolerance is None
    middle = ((unstable.x0 + unstable.x1) / 2, (unstable.y0 + unstable.y1) / 2)
    assert _pgm_percent(relaxed, *middle) == math.floor(100 * unstable.V_critical / ROBOT.V)


def test_summary_counts_the_zones(routed):
    """`wobble_summary`: the zones (unstable, 0 < V* < V) at V_tolerance and those that kept V*, by reason, counted and measured
    here from the stretches themselves; the unstable fraction is the user's unstable stretch over every unstable
    stretch's length; the mask's range runs from the skeleton's kept V* to V_tolerance."""
    _, _, analysis = routed
    relaxed = with_wobble(analysis, ROUTE_TOL)
    summary = wobble_summary(relaxed, ROUTE_TOL)
    stretches = relaxed.paths.stretches
    zoned = [s for s in stretches if s.verdict == "unstable" and 0 < s.V_critical < ROBOT.V]  # a zone where a speed limit helps
    relaxed_zones = [s for s in zoned if s.wobble.kept is None]
    kept = {}
    for s in zoned:
        if s.wobble.kept is not None:
            kept[s.wobble.kept] = kept.get(s.wobble.kept, 0) + 1
    assert relaxed_zones and kept == {"not a straight corridor": 1}
    assert summary.segments == {"V_tolerance": 1, "kept": {}}
    assert summary.stretches == {"V_tolerance": len(relaxed_zones), "kept": kept}
    unstable = [s for s in stretches if s.verdict == "unstable"]
    assert summary.unstable_length_m == pytest.approx(sum(s.length for s in unstable), rel=1e-12)
    assert summary.unstable_fraction == pytest.approx(sum(s.length for s in unstable if s.route == 1) / summary.unstable_length_m, rel=1e-12)
    # the segment's and the stretch's V_tolerance solve one branch at an L measured along two code paths: equal to round-off
    assert summary.V_limit_min == pytest.approx(min(s.V_critical for s in stretches), rel=1e-9)
    assert summary.V_limit_max == pytest.approx(max(s.wobble.V_limit for s in zoned), rel=1e-9)


def test_text_output_shows_the_wobble_block(routed):
    """``map --route FILE --wobble TOL`` (text): a short block with the tolerance, the segments and the route stretches at
    V_tolerance (counts and length, from the library's own analysis of the same map, `test_summary_counts_the_zones`)
    and the mask's range; without --wobble no such block."""
    path, csv, analysis = routed
    summary = wobble_summary(with_wobble(analysis, ROUTE_TOL), ROUTE_TOL)
    args = ["map", str(path), "--preset", "carmel", "--route", str(csv), "--quiet"]
    code, out, err = run([*args, "--wobble", str(ROUTE_TOL)])
    assert code == 0, err
    block = out[out.index("wobble tolerance"):].splitlines()
    assert block[0].startswith(f"wobble tolerance {ROUTE_TOL:g} m")
    assert block[1] == "  segments: 1 of 1 with a zone at V_tolerance"
    total = summary.stretches["V_tolerance"] + sum(summary.stretches["kept"].values())
    assert block[2].startswith(f"  route stretches: {summary.stretches['V_tolerance']} of {total} with a zone at V_tolerance "
                               f"({summary.route_length_m['V_tolerance']:.1f} m; {100 * summary.unstable_fraction:.1f}% of the "
                               f"{summary.unstable_length_m:.1f} m unstable)")
    assert "not a straight corridor" in block[2]
    assert block[3].startswith("  mask limits: ") and len(block) == 4
    code, plain, err = run(args)
    assert code == 0, err
    assert "wobble" not in plain


def _growth_edge(robot, N: float, length: float) -> float:
    """The speed (m/s) at which a disturbance gains one e-fold over `length` m of a uniform gain N (1/m):
    σ(N·v)·length/v = 1, σ the real part of the sampled model's rightmost root (`LoopModel.rightmost_root`, the
    characteristic polynomial's roots: not the map's product of transition matrices), by brentq between the zero-growth
    speed and 10 V."""
    from scipy.optimize import brentq
    from pfm_stability.models import Loop, models_for

    (model,) = models_for(CONTROLLER, ["sampled"])
    loop = Loop.of(robot, CONTROLLER, c=0.0)
    V_zero = model.boundary(loop).NV_critical / N
    return brentq(lambda v: model.rightmost_root(N * v, loop).real * length / v - 1.0, V_zero * (1 + 1e-9), 10 * robot.V, xtol=1e-9)


def test_a_short_stretch_keeps_its_v_star_above_v_tolerance(tmp_path):
    """The user's 6 m route in the 12 m corridor: a growth too slow to reach an e-fold in 6 m is no weave, so the
    stretch's V* is the speed at which its growth reaches one e-fold over its length — the run of growing windows, the
    whole route (`decide.run_efolds`) — which an independent route finds from the sampled model's roots
    (`_growth_edge`, N the stretch's): V* lies at most the rule's last bisection step (SPEED_STEP·V/2^BISECT_STEPS,
    `stretch_speed`) below it,
    and above the straight corridor's zero-growth V* (1e-9 m/s: brentq's tolerance). That V* is above V_tolerance (0.1 m), so the wobble, which only
    relaxes the mask, keeps it ("V* above V_tolerance")."""
    path, route = short_corridor(tmp_path, L)
    law = make_law("grid", ROBOT, CONTROLLER)
    analysis = with_wobble(analyze_map(load_map(path), ROBOT, CONTROLLER, law, routes=[route]), TOL)
    expected = corridor_wobble(ROBOT, CONTROLLER, law, L, TOL)
    (own,) = [s for s in analysis.paths.stretches if s.route == 1]
    assert own.verdict == "unstable" and own.cause == "growth"
    edge = _growth_edge(ROBOT, own.N, own.length)
    assert edge - SPEED_STEP * ROBOT.V / 2**BISECT_STEPS - 1e-9 <= own.V_critical <= edge + 1e-9
    assert own.V_critical > expected.V_critical * (1 + V_CRITICAL_AGREEMENT)
    assert own.wobble.V_tolerance == pytest.approx(expected.V_tolerance, abs=1e-6) and own.wobble.V_tolerance < own.V_critical
    assert own.wobble.kept == "V* above V_tolerance" and own.wobble.V_limit == own.V_critical


@pytest.mark.parametrize("draw", range(3))
def test_random_robots_route_stretch_follows_corridor_wobble(tmp_path, draw):
    """Random robots (seeded: tau 0.15–0.5 s, k 1.5–3 1/s, W 0.5–0.8 m, V 1.2 m/s, CARMEL's controller) in a corridor of
    random half-width: the user's route along the middle gets ``corridor_wobble``'s V_tolerance (1e-6 m/s, the same
    branch) where the mask draws its zone, trusted exactly when ``corridor_wobble`` says supercritical with small
    harmonics at V = V_tolerance and V_tolerance is above the stretch's V*; a subcritical branch keeps V*
    ("subcritical"); a stretch with V* >= V is stable and has no zone ("no zone")."""
    from pfm_stability.analysis.wobble import RATE_HARMONIC_LIMIT, THIRD_HARMONIC_LIMIT

    rng = np.random.default_rng(7)
    for _ in range(draw + 1):
        tau, k, W = rng.uniform(0.15, 0.5), rng.uniform(1.5, 3.0), rng.uniform(0.5, 0.8)
        half_width = round(rng.uniform(W / 2 + 0.2, 0.9), 1)
    robot = ROBOT.replace(tau=tau, k=k, W=W, V=1.2)
    path, route = short_corridor(tmp_path, half_width)
    law = make_law("grid", robot, CONTROLLER)
    analysis = with_wobble(analyze_map(load_map(path), robot, CONTROLLER, law, routes=[route]), 0.05)
    expected = corridor_wobble(robot, CONTROLLER, law, half_width, 0.05)
    (own,) = [s for s in analysis.paths.stretches if s.route == 1]
    w = own.wobble
    if not own.V_critical < robot.V:
        assert own.verdict == "stable" and w.kept == "no zone" and w.V_limit == own.V_critical
        return
    assert own.verdict == "unstable"
    if own.cause != "growth":  # a forced weave, a relay: not the corridor's Hopf cycle
        assert w.kept == own.cause and w.V_limit == own.V_critical
        return
    assert w.V_tolerance == pytest.approx(expected.V_tolerance, abs=1e-6) and w.criticality == expected.criticality
    at = corridor_wobble(robot.replace(V=expected.V_tolerance), CONTROLLER, law, half_width, 0.05)  # the cycle at V_tolerance
    trusted = (expected.criticality == "supercritical" and at.third_harmonic is not None and at.third_harmonic <= THIRD_HARMONIC_LIMIT
               and at.rate_harmonic <= RATE_HARMONIC_LIMIT)
    if trusted and expected.V_tolerance > own.V_critical:
        assert w.V_limit == pytest.approx(expected.V_tolerance, abs=1e-6) and w.kept is None
    elif trusted:
        assert w.V_limit == own.V_critical and w.kept == "V* above V_tolerance"
    else:
        assert w.V_limit == own.V_critical and w.kept == ("subcritical" if expected.criticality == "subcritical" else "not trusted")


def test_upstream_dilation_brakes_to_v_limit(routed):
    """``--dilate-upstream A_MAX`` with the wobble: a stretch's zone reaches the braking distance (V² − V_limit²)/(2·A_MAX)
    beyond its ends (the closed form, `outputs.upstream_distance`), plus W/2 around the route. The unstable stretch of
    the user's route is cut to 0.5 m in the route's middle (the mask reads only its place, V* and wobble), A_MAX =
    0.1 m/s²: braking to V_tolerance takes ~0.1 m less than to V*, so a cell centre between the two zone ends is
    outside the zone with the wobble (100 %) and inside without it."""
    _, _, analysis = routed
    route = analysis.paths.paths[1]
    pv = judge_routes(analysis, [route])
    (unstable,) = [s for s in pv.stretches if s.verdict == "unstable"]
    cut = replace(unstable, start=2.0, stop=2.5)
    alone = replace(analysis, segments=(), paths=replace(pv, stretches=(cut,)))
    relaxed = with_wobble(alone, ROUTE_TOL)
    V_limit = relaxed.paths.stretches[0].wobble.V_limit
    assert V_limit > cut.V_critical
    a_max, V, half = 0.1, ROBOT.V, ROBOT.W / 2
    ends = [cut.stop + (V * V - v * v) / (2 * a_max) + half for v in (V_limit, cut.V_critical)]
    y0 = route.points[0][1]
    centres = [float(c) for c in SHORT_ORIGIN[1] + (np.arange(SHORT_CELLS) + 0.5) * 0.1 if ends[0] + 0.01 < c - y0 < ends[1] - 0.01]
    assert centres
    for analysed, inside in ((relaxed, False), (alone, True)):
        assert (_pgm_percent(analysed, route.points[0][0], centres[0], a_max) < 100) == inside
