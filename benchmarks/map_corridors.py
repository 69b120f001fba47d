"""Straight corridor maps against ``report --law grid --L``: the figures of docs/maps.md, "Checked".

For each half-width L (walls one cell thick, on histogram cell centres at ±L, 30 m long, running to the map's
edge, along x and along y) the map is analysed (`pfm_stability.maps.analysis.analyze_map`, the grid law) with the
robot of the brief (W 0.4 m, τ 0.1 s, k 20 1/s, T 0.025 s, f 2, V 1 m/s) and compared with the straight-corridor
report (`criteria.analyze_corridor` with the same grid law: what ``pfm-stability report --law grid --L`` prints):

* middle N: the largest |N_i/N − 1| over the samples more than `MIDDLE` m from the segment's ends, where the
  window (±1.65 m) sees the whole wall on both sides, as the report's infinite corridor;
* middle V*: V* of those samples' mean growth rate (`maps.deciding.verdicts.critical_speed`) against the report's V*;
* segment V*: the segment's own V* (every sample judged, ends included) against the report's V*.

Prints one row per width and direction, and the largest of each column.

Usage: ``python benchmarks/map_corridors.py [--length 300]``
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from pfm_stability.analysis.criteria import analyze_corridor
from pfm_stability.laws.fields import make_law
from pfm_stability.maps.analysis import analyze_map
from pfm_stability.maps.reading.occupancy import load_map
from pfm_stability.maps.deciding.verdicts import GrowthRate, critical_speed
from pfm_stability.models import Loop, models_for
from pfm_stability.parameters import CARMEL, Corridor

ROBOT = CARMEL.robot.replace(W=0.4, tau=0.1, k=20.0, V=1.0)
CONTROLLER = CARMEL.controller.replace(T=0.025, f=2.0)
WIDTHS = (0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4, 1.6)
"""Half-widths L, m: from the narrowest where the robot fits (clearance L − c/2 > W/2) to the window's reach."""
MIDDLE = 2.0
"""Distance from a segment's ends beyond which a sample is in the middle, m (> the window's reach, 1.65 m)."""
CELL = 0.1


def corridor(directory: Path, L: float, along: str, length: int) -> Path:
    """A map of one corridor: one-cell walls with centres 2L apart running the map's whole length (cells)."""
    gap = round(2 * L / CELL)
    img = np.full((length, gap + 1), 254, dtype=np.uint8)
    img[:, 0] = img[:, -1] = 0
    Image.fromarray(img if along == "y" else img.T.copy()).save(directory / "c.pgm")
    path = directory / "c.yaml"
    path.write_text("image: c.pgm\nresolution: 0.1\norigin: [-7.3, 2.1, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path


def measure(L: float, along: str, length: int) -> dict:
    law = make_law("grid", ROBOT, CONTROLLER)
    ref = analyze_corridor(ROBOT, CONTROLLER, Corridor(L), ["sampled"], law=law)
    V_ref = ref.models["sampled"].critical["V_critical"]
    with tempfile.TemporaryDirectory() as directory:
        analysis = analyze_map(load_map(corridor(Path(directory), L, along, length)), ROBOT, CONTROLLER, law)
    (segment,) = [g for g in analysis.segments if g.length > 10]
    k = analysis.segments.index(segment)
    s = analysis.samples
    mine = np.flatnonzero(s.segment == k)
    t = np.array([segment.x1 - segment.x0, segment.y1 - segment.y0]) / segment.length
    position = (s.x[mine] - segment.x0) * t[0] + (s.y[mine] - segment.y0) * t[1]
    middle = mine[(position > MIDDLE) & (position < segment.length - MIDDLE)]
    model = models_for(CONTROLLER, ["sampled"])[0]
    loop = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
    boundary = model.boundary(loop)
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), boundary.NV_critical)
    return {
        "L": L, "along": along, "samples": int(mine.size), "middle": int(middle.size),
        "missing": int(np.sum(~np.isfinite(s.N[mine]))),
        "middle_N": float(np.nanmax(np.abs(s.N[middle] / ref.N - 1))),
        "middle_V": float(critical_speed(s.N[middle], growth, boundary.NV_critical) / V_ref - 1),
        "segment_V": float(segment.V_critical / V_ref - 1) if segment.V_critical is not None else float("nan"),
        "verdict": segment.verdict, "report_verdict": ref.models["sampled"].verdict,
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=int, default=300, help="corridor length, cells of 0.1 m (default 300: 30 m)")
    args = parser.parse_args(argv)
    rows = [measure(L, along, args.length) for along in ("x", "y") for L in WIDTHS]
    print(f"{'along':>5} {'L m':>5} {'samples':>7} {'no eq.':>6} {'middle N':>9} {'middle V*':>9} {'segment V*':>10}  verdict (report)")
    for r in rows:
        print(f"{r['along']:>5} {r['L']:5.2f} {r['samples']:7d} {r['missing']:6d} {r['middle_N']:9.1e} {r['middle_V']:+9.1e} "
              f"{r['segment_V']:+10.2%}  {r['verdict']} ({r['report_verdict']})")
    print(f"largest: middle N {max(r['middle_N'] for r in rows):.1e}, middle V* {max(abs(r['middle_V']) for r in rows):.1e}, "
          f"segment V* {max(abs(r['segment_V']) for r in rows):.2%}; samples without an equilibrium: "
          f"{sum(r['missing'] for r in rows)}; verdicts as the report: "
          f"{sum(r['verdict'] == r['report_verdict'] for r in rows)}/{len(rows)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
