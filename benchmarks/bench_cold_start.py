"""Cold-start speed of the main job: the report against `import control`, idle and on a busy machine.

Targets: ``pfm-stability report --preset carmel --alpha 20 --L 0.9`` takes at
most half the time of ``python -c "import control"`` on an idle machine, and at
most 0.4 of it while two CPU-bound processes run (a busy 2-core machine: BLAS
threads that spin on small eigenvalue problems would make the report 3–5×
slower; the CLI keeps them to one thread). Both commands run as fresh
processes, interleaved, ``--repeat`` times each in each condition; the medians
and their ratios are printed (ratios, not seconds: they compare like with like
on whatever machine runs them). Run:

    python benchmarks/bench_cold_start.py [--repeat 9]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

REPORT = [sys.executable, "-m", "pfm_stability", "report", "--preset", "carmel", "--alpha", "20", "--L", "0.9"]
REFERENCE = [sys.executable, "-c", "import control"]
BURNER = [sys.executable, "-c", "while True: pass"]
TARGETS = {"idle": 0.5, "two CPU-bound processes": 0.4}


def _wall_time(command) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def _medians(repeat: int) -> tuple[float, float]:
    report, reference = [], []
    for _ in range(repeat):
        report.append(_wall_time(REPORT))
        reference.append(_wall_time(REFERENCE))
    return statistics.median(report), statistics.median(reference)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="runs of each command per condition (median is reported)")
    args = parser.parse_args(argv)
    _wall_time(REPORT)  # compile bytecode once, as an installed package would have
    _wall_time(REFERENCE)
    ok = True
    for condition, target in TARGETS.items():
        burners = [subprocess.Popen(BURNER) for _ in range(2)] if condition != "idle" else []
        try:
            r, c = _medians(args.repeat)
        finally:
            for p in burners:
                p.kill()
                p.wait()
        ratio = r / c
        ok &= ratio <= target
        print(f"{condition}:")
        print(f"  pfm-stability report (carmel, alpha 20, L 0.9): median {r:.3f} s over {args.repeat} runs")
        print(f"  python -c 'import control':                    median {c:.3f} s over {args.repeat} runs")
        print(f"  ratio report / import control = {ratio:.2f}  (target <= {target:.2f})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
