"""Do the map's collision courses foresee where the simulated drives collide? (docs/maps.md, "Where the drives
collided").

For every shipped map (depot, warehouse, tb3_sandbox) at CARMEL and at the small robot (``--W 0.3 --V 0.5``), the map
is analysed and driven as ``pfm-stability map MAP --validate N --seed S`` does (`validation.map_drives`), and each
drive that ended in a collision is set beside the map's prediction along its routes
(`validation.map_collisions.locate_collisions`): foreseen (a stretch with cause "collision course" within the match
distance), near a predicted weave, on a stretch called stable, or off every route. The base rate beside it is the
share of all the drives' driving time spent within the match distance of a predicted collision course: a prediction
that marked places at random would foresee about that share of the collisions.

    python experiments/collision_courses.py --out experiments/results [--drives 50] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import output_dir, write_json  # noqa: E402

MAPS = ("depot", "warehouse", "tb3_sandbox")
"""The shipped maps (`cli.map.SHIPPED_MAPS`)."""
ROBOTS = {"CARMEL": {}, "W 0.3, V 0.5": {"W": 0.3, "V": 0.5}}
"""The robots of docs/maps.md's tables: CARMEL's preset, and the small robot."""


def measure(name: str, robot_changes: dict, drives: int, seed: int) -> dict:
    """One map and robot: its collisions beside the prediction and the base rate (module docstring)."""
    import numpy as np
    from scipy.spatial import cKDTree

    from pfm_stability.cli.map import map_path
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.deciding.decide import CAUSES
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.parameters import CARMEL
    from pfm_stability.validation.map_drives import judge_drives, simulate_drives

    robot, controller = CARMEL.robot.replace(**robot_changes), CARMEL.controller
    analysis = analyze_map(load_map(map_path(name)), robot, controller, make_law("grid", robot, controller), corridors=False)
    runs = simulate_drives(analysis, drives, seed=seed)
    summary = judge_drives(runs).collisions
    pv = analysis.paths
    course = pv.cause == CAUSES.index("collision course")
    points = np.vstack([np.column_stack([d.x, d.y]) for d in runs.drives])
    share = 0.0
    if course.any() and points.size:
        tree = cKDTree(np.column_stack([pv.samples.x[course], pv.samples.y[course]]))
        share = float(np.isfinite(tree.query(points, distance_upper_bound=summary.match_distance)[0]).mean())
    return {"map": name, "drives": len(runs.drives), "collisions": len(summary.collisions), "foreseen": summary.foreseen,
            "near_weave": summary.near_weave, "elsewhere": summary.elsewhere, "off_routes": summary.off_routes,
            "match_distance": summary.match_distance, "base_rate": share,
            "collision_course_m": float(pv.spacing[course].sum()), "route_m": float(pv.spacing.sum())}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--drives", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    from tqdm import tqdm

    out = output_dir(args.out)
    rows = []
    for name in tqdm(MAPS, desc="maps"):
        for label, changes in ROBOTS.items():
            rows.append({"robot": label, **measure(name, changes, args.drives, args.seed)})
    lines = ["| map, robot | drives | collisions | foreseen | near a predicted weave | elsewhere on a route | off the routes | "
             "base rate | collision course / route length |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        share = f"{100 * r['foreseen'] / r['collisions']:.0f} %" if r["collisions"] else "n/a"
        lines.append(f"| {r['map']}, {r['robot']} | {r['drives']} | {r['collisions']} | {r['foreseen']} ({share}) | {r['near_weave']} | "
                     f"{r['elsewhere']} | {r['off_routes']} | {100 * r['base_rate']:.1f} % | {r['collision_course_m']:.1f} m / {r['route_m']:.0f} m |")
    table = "\n".join(lines) + "\n"
    (out / "collision_courses.md").write_text(table)
    write_json(out / "collision_courses.json", {"drives": args.drives, "seed": args.seed, "rows": rows})
    print(table, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
