"""Straight corridor maps against the straight-corridor oracle (docs/maps.md, "Checked").

A map of one straight corridor — walls on histogram cell centres at ±L from its axis,
one cell thick or three, along x or along y, 30 m long, written as PGM + YAML —
must give one segment whose verdict and V* are those of the library's grid law for
that corridor: ``pfm-stability report --law grid --L L`` for one-cell walls, and for
three-cell walls the same law summed over the three rows of each wall (the window sum
is linear in the cells, and every row lies inside the window: L + 2c <= 1.5 m < 1.65 m).
The widths run from the narrowest where the robot fits (W = 0.4 m: clearance
L − c/2 > W/2, so L = 0.3 m) up to the window (1.6 m; 1.3 m for the thick walls), through
both parities of 2L/c: an axis on a cell centre and on a cell boundary (a skeleton that
runs half a cell beside the axis). These are the corridors the equilibrium search used
to miss: an equilibrium exactly on a scan point (the symmetric axis), a free band
narrower than one scan step, samples off the axis whose band did not reach it.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from cli_helpers import report_json, run
from pfm_stability.laws.fields import make_law
from pfm_stability.laws.force_law import corridor_gain
from pfm_stability.maps.analysis import analyze_map
from pfm_stability.maps.reading.occupancy import load_map
from pfm_stability.models import Loop, models_for
from pfm_stability.parameters import CARMEL

pytestmark = pytest.mark.xdist_group("map_corridors")  # `oracle` and `corridor_analysis` once per suite (tests/conftest.py)

ROBOT_OPTIONS = ["--W", "0.4", "--tau", "0.1", "--k", "20", "--T", "0.025", "--f", "2", "--V", "1"]
"""The robot of the corridors (a 25 ms loop at 1 m/s: V* of the narrow corridors lies below V, of the wide ones above)."""
ROBOT = CARMEL.robot.replace(W=0.4, tau=0.1, k=20.0, V=1.0)
CONTROLLER = CARMEL.controller.replace(T=0.025, f=2.0)
CELL = 0.1
LENGTH_CELLS = 300
"""30 m corridors."""
THIN = (0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4, 1.6)
THICK = (0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3)
ORIGIN = {"y": (-7.3, 2.1), "x": (3.4, -12.6)}
"""Map origins (m): multiples of the cell, away from 0, so that coordinates carry round-off as real maps do."""
V_TOLERANCE = 0.01
CLI_L = 0.7
"""The width at which the segment is also read from ``pfm-stability map --format json`` (one-cell and three-cell walls,
along x and y): the CLI prints the library's segment (`MapSegment.to_dict`), checked equal there."""


def corridor_map(directory: Path, L: float, thickness: int, along: str) -> tuple[Path, float]:
    """(YAML path, axis coordinate across the corridor, m): walls of `thickness` cells with their inner rows on cell
    centres at ±L from the axis, running the map's whole length along `along`; nothing else on the map."""
    gap = round(2 * L / CELL)  # cells between the inner rows' centres
    width = gap + 2 * thickness - 1
    img = np.full((LENGTH_CELLS, width), 254, dtype=np.uint8)
    img[:, :thickness] = 0
    img[:, thickness - 1 + gap:] = 0
    across = ORIGIN[along][0 if along == "y" else 1] + (thickness - 1 + gap / 2 + 0.5) * CELL
    if along == "x":  # image rows are y (row 0 on top): the corridor's axis is a row
        img = img.T.copy()
        across = ORIGIN[along][1] + (width - 1 - (thickness - 1 + gap / 2) + 0.5) * CELL
    Image.fromarray(img).save(directory / "corridor.pgm")
    path = directory / "corridor.yaml"
    ox, oy = ORIGIN[along]
    path.write_text(f"image: corridor.pgm\nresolution: {CELL}\norigin: [{ox}, {oy}, 0.0]\nnegate: 0\n"
                    "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path, across


@lru_cache(maxsize=None)
def oracle(L: float, thickness: int) -> tuple[float, str]:
    """(V* m/s, verdict) of the straight corridor by the library's grid law: ``report --law grid --L`` for one-cell
    walls; for thicker ones N = Σ −2P′(L + i·c) over the rows (`force_law.corridor_gain`), V* = NV*/N with NV* of
    the controller's `sampled` model, the verdict from the model's own eigenvalue test at N·V."""
    if thickness == 1:
        sampled = report_json([*ROBOT_OPTIONS, "--law", "grid", "--L", str(L), "--model", "sampled"])["corridor"]["sampled"]
        return sampled["V_critical"], sampled["verdict"]
    law = make_law("grid", ROBOT, CONTROLLER)
    N = sum(corridor_gain(law, L + i * CELL) for i in range(thickness))
    model = models_for(CONTROLLER, ["sampled"])[0]
    loop = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
    return model.boundary(loop).NV_critical / N, "stable" if model.is_stable(N * ROBOT.V, loop) else "unstable"


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    return str(tmp_path_factory.mktemp("corridors"))


@lru_cache(maxsize=None)
def corridor_analysis(root: str, L: float, thickness: int, along: str):
    """(map YAML path, axis coordinate across the corridor (m), `analyze_map` of it with the straight segments alone):
    once per corridor, for both tests below (the routes' verdicts, ``along_routes``, are read by neither; the
    segments do not depend on them)."""
    directory = Path(root) / f"{L}_{thickness}_{along}"
    directory.mkdir()
    path, axis = corridor_map(directory, L, thickness, along)
    law = make_law("grid", ROBOT, CONTROLLER)
    return path, axis, analyze_map(load_map(path), ROBOT, CONTROLLER, law, along_routes=False)


@pytest.mark.parametrize("along", ["x", "y"])
@pytest.mark.parametrize("thickness, L", [(1, L) for L in THIN] + [(3, L) for L in THICK])
def test_straight_corridor_segment_matches_the_grid_law(root, along, thickness, L):
    """One segment, with the oracle's verdict and its V* to 1 % (measured: up to 0.7 %, at the narrowest widths), and
    an equilibrium at every sample.

    What the 1 % allows for: the segment is judged whole, ends included. The walls stop at the map's edge, so over
    the last metre the window sees a truncated wall (less lateral force, and an along-track force that changes the
    forward force 1 ± F_r·t); the segment's mean growth rate counts those samples too (docs/maps.md, "Checked"). Away
    from the ends the samples' N equals the oracle's to 5e-4 (the next test).

    The segment is the library's (`analyze_map` with the straight segments alone: the routes' verdicts are not read
    here, and the CLI spends most of its time on them); at L = `CLI_L` the JSON of ``pfm-stability map`` is read too:
    it carries no segments, its result set is the routes' stretches."""
    V_star, verdict = oracle(L, thickness)
    path, axis, analysis = corridor_analysis(root, L, thickness, along)
    segments = [s.to_dict() for s in analysis.segments]
    if L == CLI_L:
        code, out, err = run(["map", str(path), *ROBOT_OPTIONS, "--format", "json", "--quiet"])
        assert code == 0, err
        data = json.loads(out)  # the CLI's one result set is the routes' stretches (docs/maps.md, "One answer per stretch")
        assert data["segments"] is None and data["summary"] == data["paths"]["summary"]
    assert len(segments) == 1, [(s["verdict"], s["length"]) for s in segments]
    (segment,) = segments
    assert segment["length"] > 25.0
    assert segment["verdict"] == verdict, segment
    assert segment["V_critical"] == pytest.approx(V_star, rel=V_TOLERANCE)
    # every sample has an equilibrium, but for up to 3 at each end of a thick-walled one, where the wall ahead
    # pushes back at least as hard as the attraction pulls (F_t <= 0: no equilibrium)
    assert segment["samples"] - segment["analysed"] <= (0 if thickness == 1 else 6)


@pytest.mark.parametrize("along", ["x", "y"])
@pytest.mark.parametrize("L", [0.3, 0.35, 0.4, 0.45, 1.05])
def test_middle_of_the_corridor_is_on_the_axis_with_the_grid_laws_N(root, along, L):
    """Away from the ends (> 2 m, beyond the window's 1.65 m reach) every sample finds the equilibrium, on the
    corridor's axis, with the N of ``report --law grid --L`` to 5e-4 (measured: 2e-4, `python benchmarks/map_corridors.py`).

    N: the map averages the window sum over the robot's position along the segment within one cell by 4 Gauss–Legendre
    nodes; the law integrates the same average in closed form. Where a cell boundary (a row entering or leaving the
    window, 16 cells ahead or behind) falls inside that interval the 4-node rule is off by up to 2e-4. Axis: to 1e-5 m;
    the segment is tilted by up to ~3e-3 rad (the skeleton beside an axis on a cell boundary), which moves the root
    along its tilted normal by ~1e-6 m; a root missed or found in the wrong cell is off by centimetres.

    The analysis is the previous test's where the widths coincide (`corridor_analysis`).
    """
    path, axis, analysis = corridor_analysis(root, L, 1, along)
    s = analysis.samples
    (segment,) = analysis.segments
    t = np.array([segment.x1 - segment.x0, segment.y1 - segment.y0]) / segment.length
    along_axis = (s.x - segment.x0) * t[0] + (s.y - segment.y0) * t[1]
    middle = (along_axis > 2.0) & (along_axis < segment.length - 2.0)
    assert middle.sum() > 200 and np.isfinite(s.N[middle]).all()
    across = (s.x - s.offset * t[1]) if along == "y" else (s.y + s.offset * t[0])  # the equilibrium point's coordinate
    assert np.abs(across[middle] - axis).max() < 1e-5
    N = report_json([*ROBOT_OPTIONS, "--law", "grid", "--L", str(L), "--model", "sampled"])["corridor"]["sampled"]["NV"] / ROBOT.V
    assert np.abs(s.N[middle] / N - 1).max() < 5e-4


def test_a_corridor_the_robot_does_not_fit_has_no_route(tmp_path):
    """L = 0.25 m: the clearance L − c/2 = 0.2 m is W/2, the robot does not fit: "no route long enough", exit 2."""
    path, _ = corridor_map(tmp_path, 0.25, 1, "y")
    code, out, err = run(["map", str(path), *ROBOT_OPTIONS, "--quiet"])
    assert code == 2 and "no route long enough" in err and len(err.strip().splitlines()) == 1
