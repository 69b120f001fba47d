"""``map --wobble TOL``: each straight segment's speed limit by wobble tolerance (docs/maps.md, "Speed limits by wobble
tolerance").

A straight synthetic corridor (`test_map_corridors.corridor_map`: one-cell walls on histogram cell centres at ±L) is
the straight corridor of half-width L that `analysis.wobble.corridor_wobble` models, so the segment's half-width must be
the built L and its V_tolerance ``corridor_wobble``'s for the same robot, law and L; the mask's segment zone follows it.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_helpers import VALIDATOR, run
from test_map_corridors import ROBOT as FAST_STEERING, CONTROLLER as FAST_CONTROLLER, corridor_map
from pfm_stability.analysis.wobble import corridor_wobble
from pfm_stability.laws.fields import make_law
from pfm_stability.maps.analysis import analyze_map
from pfm_stability.maps.occupancy import load_map
from pfm_stability.maps.outputs import speed_limits
from pfm_stability.maps.wobble import with_wobble
from pfm_stability.parameters import CARMEL

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
    (1e-6 m/s); without --wobble the same JSON as before, no ``wobble`` key (the recorded answers replay unchanged);
    a tolerance out of range exits 2 with one line."""
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
    assert "wobble" not in plain["segments"][0]
    strip = lambda d: {k: v for k, v in d.items() if k != "timing"}
    data["segments"][0].pop("wobble")
    assert strip(data) == strip(plain)
    code, out, err = run([*args, "--wobble", "-1"])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "wobble" in err
