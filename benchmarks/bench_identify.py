"""Speed and memory of ``pfm-stability identify`` and ``pfm-stability diagnose`` on a one-hour bag.

The bag (written once into a temporary directory by the tests' own helpers, `tests/log_helpers.py`):
the project's VFF simulator driving CARMEL (T = 50 ms, a plant gain of 0.85 and a dead time of
70 ms) through corridors and along walls, standing, turning in place and making step turns in the
open, block after block for an hour — commands at 20 Hz (``/cmd_vel``, Twist, 1 % dropped),
odometry at 50 Hz (pose and yaw rate), laser scans at 10 Hz with 360 beams ray-cast against the
walls: 72 000 commands, 180 000 odometry messages and 36 000 scans, about 190 MB. Each command
runs as a fresh process on one core (``taskset`` when available), ``--repeat`` times: ``identify``,
then ``diagnose`` with k, W, f and n from a configuration file (τ, T, D and g identified from the
same log, so ``diagnose`` includes the identification), and as the reference of the same run, reading the bag alone
with what ``diagnose`` reads (commands, odometry, pose, the scans reduced as they stream). The median wall time, the
median CPU time (user + system of the child: what the run costs on a shared machine), each command's CPU time over
the reading's (the ratio holds on a loaded machine where the seconds do not) and the largest peak resident memory
(``ru_maxrss``) are printed against the target: identify + diagnose within 10 s (docs/diagnose.md, "Numbers"). Run:

    python benchmarks/bench_identify.py [--repeat 3] [--storage mcap|sqlite3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

TARGET_SECONDS = 10.0
HOUR = 3600.0
READ = ("from pfm_stability.analysis.stretches import wall_lines_batch; from pfm_stability.io.logs import read_log; "
        "read_log({bag!r}, need=('command', 'odometry', 'pose', 'scan'), scan_reducer=wall_lines_batch, scan_batch=256)")
"""The reference: what diagnose reads, read alone (its own process, like the commands)."""


def write_bag(directory: Path, storage: str) -> Path:
    """The one-hour bag under `directory` (written once: reused when already there)."""
    from log_helpers import Leg, drive, write_ros2
    from pfm_stability.parameters import CARMEL

    path = directory / f"hour_{storage}"
    if path.exists():
        return path
    robot = CARMEL.robot.replace(dead_time=0.07, plant_gain=0.85)
    controller = CARMEL.controller.replace(T=0.05)
    legs, total, i = [], 0.0, 0
    while total < HOUR:
        block = [Leg("corridor", 50.0, L=0.9 if i % 2 else 1.2), Leg("still", 3.0), Leg("turn", 4.0, rate=0.5),
                 Leg("wall", 50.0, offset=0.1), Leg("turn", 4.0, rate=-0.5), Leg("steps", 20.0), Leg("still", 3.0)]
        legs += block
        total += sum(leg.duration for leg in block)
        i += 1
    log = drive(legs, robot, controller, seed=7, drop=0.01)
    return write_ros2(log.log, path, storage=storage)


def write_config(directory: Path) -> Path:
    """What no log shows (docs/diagnose.md): CARMEL's k, W, f and n."""
    path = directory / "robot.yaml"
    path.write_text("robot: {k: 2.0, W: 0.8}\ncontroller: {f: 0.8, n: 2}\n")
    return path


def _run(command: list[str]) -> tuple[float, float, int]:
    """(wall seconds, CPU seconds, peak RSS in kB) of `command` as a child process."""
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        os.execvp(command[0], command)
    _, status, usage = os.wait4(pid, 0)
    seconds = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(command)} failed with status {os.waitstatus_to_exitcode(status)}")
    return seconds, usage.ru_utime + usage.ru_stime, int(usage.ru_maxrss)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of the command (the median is reported)")
    parser.add_argument("--storage", choices=("mcap", "sqlite3"), default="mcap")
    parser.add_argument("--keep", metavar="DIR", help="write (or reuse) the bag in DIR instead of a temporary directory")
    args = parser.parse_args(argv)
    directory = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="bench_identify_"))
    directory.mkdir(parents=True, exist_ok=True)
    try:
        start = time.perf_counter()
        bag = write_bag(directory, args.storage)
        size = sum(f.stat().st_size for f in bag.iterdir()) / 1e6
        print(f"bag {bag} ({size:.0f} MB) ready in {time.perf_counter() - start:.1f} s")
        config = write_config(directory)
        read = [sys.executable, "-c", READ.format(bag=str(bag))]
        cpu_of = {}
        for name, command in (("reading the bag", read),
                              ("identify", [sys.executable, "-m", "pfm_stability", "identify", str(bag), "--format", "json"]),
                              ("diagnose", [sys.executable, "-m", "pfm_stability", "diagnose", str(bag), "--format", "json",
                                            "--config", str(config)])):
            if shutil.which("taskset"):
                command = ["taskset", "-c", "0", *command]
            runs = [_run(command) for _ in range(args.repeat)]
            seconds = statistics.median(w for w, _, _ in runs)
            cpu_of[name] = cpu = statistics.median(c for _, c, _ in runs)
            peak_mb = max(r for _, _, r in runs) / 1024
            ratio = "" if name == "reading the bag" else f", {cpu / cpu_of['reading the bag']:.2f}× the reading's CPU"
            print(f"{name} on one hour ({args.storage}): median {seconds:.2f} s wall, {cpu:.2f} s CPU over {args.repeat} runs"
                  f"{ratio}; peak RSS {peak_mb:.0f} MB")
        both = cpu_of["identify"] + cpu_of["diagnose"]
        ok = both <= TARGET_SECONDS
        print(f"identify + diagnose: {both:.2f} s CPU, {both / cpu_of['reading the bag']:.2f}× reading the bag "
              f"(target ≤ {TARGET_SECONDS:.0f} s on one core) {'ok' if ok else 'TOO SLOW'}")
        return 0 if ok else 1
    finally:
        if not args.keep:
            shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
