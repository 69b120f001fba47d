"""Speed of the MuJoCo engine (docs/mujoco.md, "Numbers"): one robot's real-time factor, and the whole experiment.

1. One corridor run (L = 0.9 m, T = 0.065 s, V = 0.9 m/s, 60 s simulated) of each shipped robot with the project's
   VFF controller, ``--repeat`` times: the median real-time factor (simulated over wall seconds; target >= 20).
2. ``experiments/mujoco_corridor.py`` as a fresh process on two workers (skipped with ``--runs-only``): its wall
   time (target < 5 min on 2 cores).

    python benchmarks/bench_mujoco.py [--repeat 3] [--runs-only]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGET_RTF = 20.0
TARGET_EXPERIMENT = 300.0


def real_time_factor(name: str, repeat: int) -> float:
    """The median simulated-over-wall time of a 60-s corridor run of robot `name`."""
    from pfm_stability.engines.mujoco import EngineOptions, run_scenario
    from pfm_stability.parameters import Controller, Robot
    from pfm_stability.sim.presets import make_scenario

    W = 0.5 if name == "diffdrive" else 0.6
    scenario = make_scenario("corridor", env="grid", robot=Robot(V=0.9, tau=0.25, k=2.0, W=W),
                             controller=Controller(f=3.0, n=2.0, T=0.065, hold="command", compute_delay=1), L=0.9, offset=0.01, duration=60.0)
    run_scenario(scenario, EngineOptions(robot_model=name))  # compile the world once
    factors = []
    for _ in range(repeat):
        started = time.perf_counter()
        run_scenario(scenario, EngineOptions(robot_model=name))
        factors.append(60.0 / (time.perf_counter() - started))
    return statistics.median(factors)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--runs-only", action="store_true", help="skip the whole experiment")
    args = parser.parse_args(argv)
    ok = True
    for name in ("diffdrive", "diffdrive-heavy"):
        rtf = real_time_factor(name, args.repeat)
        ok &= rtf >= TARGET_RTF
        print(f"{name}: {rtf:.1f}x real time (target >= {TARGET_RTF:g}x)")
    if not args.runs_only:
        script = Path(__file__).resolve().parents[1] / "experiments" / "mujoco_corridor.py"
        with tempfile.TemporaryDirectory() as out:
            started = time.perf_counter()
            subprocess.run([sys.executable, str(script), "--out-dir", out, "--workers", "2"], check=True, capture_output=True)
            seconds = time.perf_counter() - started
        ok &= seconds < TARGET_EXPERIMENT
        print(f"experiments/mujoco_corridor.py: {seconds:.0f} s (target < {TARGET_EXPERIMENT:g} s on 2 cores)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
