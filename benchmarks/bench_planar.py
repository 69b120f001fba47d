"""Benchmark of the batched planar simulator against the former scalar stepper (docs/simulator.md, "Planar robots").

    python benchmarks/bench_planar.py [--robot steering|mass] [--sizes 1 10 100 1000] [--duration 20] [--repeat 3]

Scenario: GC2002's velocity-gated wall (`sim.planar.wall_member`: η = 0.1, ρ0 = 2 m,
a_max = 1 m/s², pull F_a = 1 at α from the wall normal), the robot KB's steering robot
(command hold, τ = 0.3 s, T = 0.065 s, one sample of compute delay; V in 0.6–1.0 m/s,
k in 1.5–2.5 1/s) or a point mass with |a| ≤ 1 m/s²; α in 40°–70°, drawn from a fixed
seed. The runs are relay limit cycles (gate events every few samples) or rests in the
Filippov band. One robot-step is one sampling period of one member.

Printed per batch size: the stepping rate of `simulate_planar_batch` (best of `--repeat`;
the loop alone, `PlanarBatch.seconds`, and with the batch's set-up and the runs' assembly),
and its ratio to the former scalar stepper (`tests/planar_oracle.py`, the per-robot loop
the simulator had before it was batched) timed in the same run on the first members.
Target: >= 1e6 robot-steps/s in batches of 1,000.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from pfm_stability.laws.velocity_laws import VelocityGatedRepulsion
from pfm_stability.sim.planar import PointMass, Steering, simulate_planar_batch, wall_member

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from planar_oracle import simulate_scalar  # noqa: E402

REPULSION = VelocityGatedRepulsion(0.1, 2.0, 1.0)


def members(count: int, robot: str, duration: float, seed: int = 0) -> list:
    """`count` wall runs with parameters drawn from `seed` (module docstring)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        if robot == "steering":
            r = Steering(float(rng.uniform(0.6, 1.0)), 0.3, float(rng.uniform(1.5, 2.5)), hold="command")
        else:
            r = PointMass(1.0, 1.0)
        out.append(wall_member(REPULSION, 1.0, math.radians(float(rng.uniform(40.0, 70.0))), r, T=0.065, compute_delay=1, duration=duration))
    return out


def scalar_rate(batch: list) -> tuple:
    """Robot-steps per second (wall, CPU) of the former scalar stepper on `batch`."""
    steps, started, cpu = 0, time.perf_counter(), time.process_time()
    for m in batch:
        run = simulate_scalar(m.robot, m.field, m.world, T=m.T, compute_delay=m.compute_delay, duration=m.duration,
                              start=m.start, on_collision=m.on_collision)
        steps += run.t.size - 1
    return steps / (time.perf_counter() - started), steps / (time.process_time() - cpu)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=("steering", "mass"), default="steering")
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 10, 100, 1000])
    parser.add_argument("--duration", type=float, default=20.0, help="simulated seconds per member")
    parser.add_argument("--scalar-members", type=int, default=3, help="members run by the former scalar stepper")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)

    reference, reference_cpu = scalar_rate(members(args.scalar_members, args.robot, args.duration))
    print(f"velocity-gated wall, {args.robot} robot, T = 0.065 s, compute delay 1, {args.duration:g} s per member")
    print(f"former scalar stepper: {reference:12,.0f} robot-steps/s wall, {reference_cpu:,.0f} per CPU-second ({args.scalar_members} members)")
    print("robot-steps/s: the stepping loop (wall clock), the whole call with set-up and the runs' assembly (wall clock, and per")
    print("CPU-second of this process: the figure least disturbed by other work on the machine); x scalar: ratio of the CPU rates")
    print(f"{'batch':>6} {'loop':>12} {'whole call':>12} {'per CPU-s':>12} {'x scalar':>9}")
    for size in args.sizes:
        batch = members(size, args.robot, args.duration)
        best = None
        for _ in range(args.repeat):
            started, cpu = time.perf_counter(), time.process_time()
            result = simulate_planar_batch(batch)
            total, cpu = time.perf_counter() - started, time.process_time() - cpu
            if best is None or cpu < best[2]:
                best = (result, total, cpu)
        result, total, cpu = best
        rate_cpu = result.robot_steps / cpu
        print(f"{size:>6} {result.robot_steps / result.seconds:>12,.0f} {result.robot_steps / total:>12,.0f} {rate_cpu:>12,.0f} "
              f"{rate_cpu / reference_cpu:>9.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
