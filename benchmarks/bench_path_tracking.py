"""Cold-start speed of the path-tracking report against the VFF report, in the same run.

Target (docs/path_tracking.md): ``pfm-stability report --controller rpp …`` — every model's verdict, ρ*, V*, L*, D* and
T* of Regulated Pure Pursuit with a dead time — takes at most 0.5 s cold. Machines differ, so the ratio to the VFF
report of the cold-start benchmark (``report --preset carmel --alpha 20 --L 0.9``, itself about 0.5 s on an idle
2-core machine) is printed beside the seconds; both commands run as fresh processes, interleaved, ``--repeat`` times,
and the medians are compared. Cases: the README's example (RPP's defaults, 364 ms of dead time), and a Nav2 file's RPP in
a corridor with a lag (the cost heuristic regulating V). Run:

    python benchmarks/bench_path_tracking.py [--repeat 9]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VFF = [sys.executable, "-m", "pfm_stability", "report", "--preset", "carmel", "--alpha", "20", "--L", "0.9"]
CASES = {
    "RPP defaults, D = 0.364 s": [sys.executable, "-m", "pfm_stability", "report", "--controller", "rpp", "--dead-time", "0.364", "--tau", "0"],
    "RPP of a Nav2 file in a corridor": [sys.executable, "-m", "pfm_stability", "report", "--controller", "rpp", "--config",
                                         str(ROOT / "tests" / "data" / "nav2_rpp_params.yaml"), "--L", "0.5", "--dead-time", "0.2",
                                         "--tau", "0.1"],
}
TARGET_SECONDS = 0.5


def _wall_time(command) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="runs of each command (the median is reported)")
    args = parser.parse_args(argv)
    for command in (VFF, *CASES.values()):
        _wall_time(command)  # compile bytecode once, as an installed package would have
    ok = True
    for name, command in CASES.items():
        path, vff = [], []
        for _ in range(args.repeat):
            path.append(_wall_time(command))
            vff.append(_wall_time(VFF))
        p, v = statistics.median(path), statistics.median(vff)
        ok &= p <= TARGET_SECONDS
        print(f"{name}:")
        print(f"  path-tracking report: median {p:.3f} s over {args.repeat} runs (target <= {TARGET_SECONDS:.1f} s)")
        print(f"  VFF report (carmel, alpha 20, L 0.9): median {v:.3f} s")
        print(f"  ratio path / VFF = {p / v:.2f}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
