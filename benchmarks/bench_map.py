"""End-to-end speed of ``pfm-stability map`` on the warehouse map (docs/maps.md).

The shipped warehouse map (1006 × 1674 = 1.7 M cells at 0.03 m) is read, reduced onto CARMEL's 0.1 m histogram
grid, its routes found, every route stretch decided with its V* and every output written (stability.png,
routes.csv, the speed mask), as ``pfm-stability map warehouse --out-dir DIR`` does; with ``--segments`` the
straight corridor segments are decided too (the CLI decides them for ``--wobble`` alone). Prints the wall and CPU
seconds, seconds per million map cells, the share of each stage and the peak resident memory
(``resource.getrusage``), and the CLI command itself timed as a fresh process (its imports included).
Bar: <= 10 s and <= 2 GB on a 2-core machine.

Usage: ``python benchmarks/bench_map.py [--map warehouse] [--repeat 3] [--segments]``
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def run_once(name: str, segments: bool = False) -> dict:
    from pfm_stability.cli.map import _write_outputs, map_path
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.parameters import CARMEL

    robot, controller = CARMEL.robot, CARMEL.controller
    cpu = time.process_time()
    started = time.perf_counter()
    occupancy = load_map(map_path(name))
    read = time.perf_counter() - started
    analysis = analyze_map(occupancy, robot, controller, make_law("grid", robot, controller), corridors=segments)
    clock = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        _write_outputs(analysis, os.path.join(out, "result"))
    stages = {"read": read, **analysis.timing, "outputs": time.perf_counter() - clock}
    return {"seconds": time.perf_counter() - started, "cpu": time.process_time() - cpu, "stages": stages, "cells": occupancy.width * occupancy.height,
            "segments": len(analysis.segments), "stretches": len(analysis.paths.stretches) if analysis.paths is not None else 0}


def _cli_seconds(name: str, segments: bool) -> float:
    """Wall seconds of the CLI command as a fresh process."""
    import subprocess

    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "pfm_stability", "map", name, "--out-dir", out, "--quiet", *(["--wobble", "0.05"] if segments else [])]
        started = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        return time.perf_counter() - started


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="warehouse")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--segments", action="store_true", help="decide the straight corridor segments too (as --wobble does)")
    args = parser.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    runs = [run_once(args.map, args.segments) for _ in range(args.repeat)]
    best = min(runs, key=lambda r: r["seconds"])
    cells = best["cells"]
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux
    print(f"map {args.map}: {cells / 1e6:.2f} M cells, {best['stretches']} route stretches, {best['segments']} segments")
    print(f"end to end: best {best['seconds']:.2f} s of {args.repeat} (first, with imports: {runs[0]['seconds']:.2f} s); "
          f"{best['seconds'] / (cells / 1e6):.2f} s per million map cells; CPU {best['cpu']:.2f} s (user + system of this process: "
          f"what a busy machine does not hide)")
    for stage, seconds in best["stages"].items():
        print(f"  {stage:<11} {seconds:6.2f} s  {100 * seconds / best['seconds']:5.1f} %")
    print(f"peak RSS: {peak:.0f} MB")
    command = _cli_seconds(args.map, args.segments)
    print(f"the CLI as a fresh process (pfm-stability map {args.map} --out-dir DIR --quiet{' --wobble 0.05' if args.segments else ''}): "
          f"{command:.2f} s")
    ok = max(best["seconds"], command) <= 10.0 and peak <= 2048
    print("within the bar (<= 10 s, <= 2 GB)" if ok else "OVER the bar (<= 10 s, <= 2 GB)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
