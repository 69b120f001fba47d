"""Speed and memory of ``pfm-stability identify`` on a one-hour bag.

The bag (written once into a temporary directory by the tests' own simulated robot,
`tests/log_helpers.py`): commands at 20 Hz (``/cmd_vel``, Twist, with jitter and dropped
messages), odometry at 50 Hz, laser scans at 10 Hz with 360 beams — 216 000 commands and
odometry messages and 36 000 scans, about 100 MB. The command runs as a fresh process on
one core (``taskset`` when available), ``--repeat`` times; the median wall time and the
largest peak resident memory (``ru_maxrss`` of the child) are printed against the targets
(docs/diagnose.md, "Numbers"). Run:

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


def write_bag(directory: Path, storage: str) -> Path:
    """The one-hour bag under `directory` (written once: reused when already there)."""
    from log_helpers import Plant, Recording, simulate, write_ros2

    path = directory / f"hour_{storage}"
    if path.exists():
        return path
    log = simulate(Plant(g=0.85, tau=0.25, dead_time=0.07),
                   Recording(T=0.05, jitter=0.05, drop=0.01, duration=HOUR, scan_rate=10.0, beams=360, seed=7))
    return write_ros2(log, path, storage=storage)


def _run(command: list[str]) -> tuple[float, int]:
    """(wall seconds, peak RSS in kB) of `command` as a child process."""
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
    return seconds, int(usage.ru_maxrss)


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
        command = [sys.executable, "-m", "pfm_stability", "identify", str(bag), "--format", "json"]
        if shutil.which("taskset"):
            command = ["taskset", "-c", "0", *command]
        runs = [_run(command) for _ in range(args.repeat)]
        seconds = statistics.median(s for s, _ in runs)
        peak_mb = max(r for _, r in runs) / 1024
        ok = seconds <= TARGET_SECONDS
        print(f"identify on one hour ({args.storage}): median {seconds:.2f} s over {args.repeat} runs "
              f"(target ≤ {TARGET_SECONDS:.0f} s on one core) {'ok' if ok else 'TOO SLOW'}; peak RSS {peak_mb:.0f} MB")
        return 0 if ok else 1
    finally:
        if not args.keep:
            shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
