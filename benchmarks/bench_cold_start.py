"""Cold-start speed of the main job (issue 2): the report against `import control`.

Target: ``pfm-stability report --preset carmel --alpha 20 --L 0.9`` takes at
most half the time of ``python -c "import control"`` on the same machine. Both
commands run as fresh processes, interleaved, ``--repeat`` times each; the
medians and their ratio are printed. Run:

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


def _wall_time(command) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="runs of each command (median is reported)")
    args = parser.parse_args(argv)
    _wall_time(REPORT)  # compile bytecode once, as an installed package would have
    _wall_time(REFERENCE)
    report, reference = [], []
    for _ in range(args.repeat):
        report.append(_wall_time(REPORT))
        reference.append(_wall_time(REFERENCE))
    r, c = statistics.median(report), statistics.median(reference)
    print(f"pfm-stability report (carmel, alpha 20, L 0.9): median {r:.3f} s over {args.repeat} runs")
    print(f"python -c 'import control':                    median {c:.3f} s over {args.repeat} runs")
    print(f"ratio report / import control = {r / c:.2f}  (target <= 0.50)")
    return 0 if r / c <= 0.5 else 1


if __name__ == "__main__":
    sys.exit(main())
