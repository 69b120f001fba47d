"""Speed of ``pfm-stability map warehouse --validate 50`` (docs/maps.md, "Validation by driving").

Runs the command as a user would (CARMEL's preset, 50 drives, JSON), and prints the wall-clock seconds, the
CPU seconds of the process (user + system: what a busy machine does not hide), the analysis' stages, the
drives' seconds, and recall / precision. Bar: <= 2 min on a 2-core machine.

Usage: ``python benchmarks/bench_map_drives.py [--map warehouse] [--drives 50] [--W 0.3 --V 0.5]``
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="warehouse")
    parser.add_argument("--drives", type=int, default=50)
    parser.add_argument("--W", type=float)
    parser.add_argument("--V", type=float)
    args = parser.parse_args()
    robot = (["--W", str(args.W)] if args.W else []) + (["--V", str(args.V)] if args.V else [])
    argv = [sys.executable, "-m", "pfm_stability", "map", args.map, *robot, "--validate", str(args.drives), "--quiet", "--format", "json"]
    started = time.perf_counter()
    out = subprocess.run(argv, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - started
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    data = json.loads(out.stdout)
    drives = data["validation"]  # kind "drives": the map's one validation
    print(f"{args.map} --validate {args.drives}: {wall:.1f} s wall, {usage.ru_utime + usage.ru_stime:.1f} s CPU, "
          f"peak {usage.ru_maxrss / 1024:.0f} MB")
    print("stages: " + ", ".join(f"{k} {v:.2f} s" for k, v in data["timing"].items()))
    print(f"drives: {drives['timing']['seconds']:.1f} s; recall {drives['recall']}, precision {drives['precision']}, "
          f"specificity {drives.get('specificity')}; "
          f"{drives['counts']}")


if __name__ == "__main__":
    main()
