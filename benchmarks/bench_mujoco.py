"""Speed of the MuJoCo engine (docs/mujoco.md, "Numbers"): one robot's real-time factor, and the whole experiment.

1. One corridor run (L = 0.9 m, T = 0.065 s, V = 0.9 m/s, 60 s simulated) of each shipped robot with the project's
   VFF controller, ``--repeat`` times: the median real-time factor, simulated over wall seconds and over CPU seconds
   (target >= 20 on a core: on a shared machine the wall clock counts the other processes too).
2. ``experiments/mujoco_corridor.py`` as a fresh process on two workers (skipped with ``--runs-only``): its wall
   time and CPU time (target < 5 min on 2 free cores: CPU seconds / 2).

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


def real_time_factor(name: str, repeat: int) -> tuple[float, float]:
    """The median simulated-over-wall and simulated-over-CPU time of a 60-s corridor run of robot `name` (on a shared
    machine the CPU figure is what the robot gets from a core of its own)."""
    from pfm_stability.engines.mujoco import EngineOptions, run_scenario
    from pfm_stability.parameters import Controller, Robot
    from pfm_stability.sim.presets import make_scenario

    W = 0.5 if name == "diffdrive" else 0.6
    scenario = make_scenario("corridor", env="grid", robot=Robot(V=0.9, tau=0.25, k=2.0, W=W),
                             controller=Controller(f=3.0, n=2.0, T=0.065, hold="command", compute_delay=1), L=0.9, offset=0.01, duration=60.0)
    run_scenario(scenario, EngineOptions(robot_model=name))  # compile the world once
    wall, cpu = [], []
    for _ in range(repeat):
        started, used = time.perf_counter(), time.process_time()
        run_scenario(scenario, EngineOptions(robot_model=name))
        wall.append(60.0 / (time.perf_counter() - started))
        cpu.append(60.0 / (time.process_time() - used))
    return statistics.median(wall), statistics.median(cpu)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--runs-only", action="store_true", help="skip the whole experiment")
    args = parser.parse_args(argv)
    ok = True
    for name in ("diffdrive", "diffdrive-heavy"):
        rtf, cpu = real_time_factor(name, args.repeat)
        ok &= cpu >= TARGET_RTF
        print(f"{name}: {rtf:.1f}x real time by the wall clock, {cpu:.1f}x per CPU second (target >= {TARGET_RTF:g}x on a core)")
    if not args.runs_only:
        script = Path(__file__).resolve().parents[1] / "experiments" / "mujoco_corridor.py"
        import resource

        with tempfile.TemporaryDirectory() as out:
            started, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run([sys.executable, str(script), "--out-dir", out, "--workers", "2"], check=True, capture_output=True)
            seconds = time.perf_counter() - started
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        ok &= cpu / 2 < TARGET_EXPERIMENT
        print(f"experiments/mujoco_corridor.py: {seconds:.0f} s by the wall clock, {cpu:.0f} CPU seconds "
              f"({cpu / 2:.0f} s on 2 free cores; target < {TARGET_EXPERIMENT:g} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
