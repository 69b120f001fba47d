"""Speed of the numeric linearisation of Nav2's controllers, MPPI's against its target (<= 5 s on 2 cores).

Each measurement runs as a fresh Python process (imports included), ``--repeat`` times, and the median wall and CPU
(user + system of the child) times are printed, with the ratio to ``pfm-stability report --preset carmel --alpha 20
--L 0.9`` timed the same way in the same run (the reference of every benchmark here):

* ``mppi``: ``linearize("mppi", MPPIParams(), corridor)`` with Nav2's defaults (batch 1000, 56 steps) about the centre of a
  0.6 m half-width corridor (exact costmap): 8 noise draws, each a 60-cycle warm-up and four perturbed cycles — the
  gains and their standard errors (docs/controllers.md);
* ``mppi-memory``: the same with the response over 16 cycles (the optimizer's memory, `LateralGains.memory`), 8 draws;
* ``rpp``, ``graceful``, ``dwb`` (32 draws): the others, for scale.

Run:

    python benchmarks/bench_controllers.py [--repeat 3] [--only mppi]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

TARGET_SECONDS = 5.0

CASES = {
    "mppi": "linearize('mppi', MPPIParams(), CorridorCostmap(half_width=0.6, exact=True))",
    "mppi-memory": "linearize('mppi', MPPIParams(), CorridorCostmap(half_width=0.6, exact=True), memory_cycles=16)",
    "rpp": "linearize('rpp', RPPParams(), CorridorCostmap(half_width=0.6))",
    "graceful": "linearize('graceful', GracefulParams(), CorridorCostmap(half_width=0.6))",
    "dwb": "linearize('dwb', DWBParams(), CorridorCostmap(half_width=0.6))",
}
PRELUDE = ("from pfm_stability.controllers.costmap import CorridorCostmap; from pfm_stability.controllers.linearize import linearize; from pfm_stability.controllers.mppi import MPPIParams; "
           "from pfm_stability.controllers.rpp import RPPParams; from pfm_stability.controllers.graceful import GracefulParams; "
           "from pfm_stability.controllers.dwb import DWBParams; ")
REFERENCE = [sys.executable, "-m", "pfm_stability", "report", "--preset", "carmel", "--alpha", "20", "--L", "0.9"]


def _run(command: list[str]) -> tuple[float, float]:
    """(wall seconds, CPU seconds) of `command` as a child process."""
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        os.execvp(command[0], command)
    _, status, usage = os.wait4(pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(command)} failed with status {os.waitstatus_to_exitcode(status)}")
    return time.perf_counter() - start, usage.ru_utime + usage.ru_stime


def _median(command, repeat):
    runs = [_run(command) for _ in range(repeat)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each command (the median is reported)")
    parser.add_argument("--only", choices=sorted(CASES), action="append", help="only these cases (default all)")
    args = parser.parse_args(argv)
    ref_wall, ref_cpu = _median(REFERENCE, args.repeat)
    print(f"reference: report --preset carmel --alpha 20 --L 0.9   {ref_wall:6.2f} s wall  {ref_cpu:6.2f} s CPU")
    status = 0
    for name in args.only or list(CASES):
        wall, cpu = _median([sys.executable, "-c", PRELUDE + CASES[name]], args.repeat)
        line = f"{name:12s} {wall:6.2f} s wall  {cpu:6.2f} s CPU  ratio {wall / ref_wall:5.1f}× the report"
        if name == "mppi":
            ok = wall <= TARGET_SECONDS
            line += f"   target <= {TARGET_SECONDS:g} s: {'met' if ok else 'MISSED'}"
            status |= not ok
        print(line)
    return status


if __name__ == "__main__":
    raise SystemExit(main())
