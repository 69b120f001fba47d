"""Speed of ``pfm-stability map --controller rpp`` on the warehouse map, against the VFF map in the same process (docs/maps.md,
"Nav2's controllers along a map").

Both runs go through the CLI in this process (``cli.main``: the map read, the routes found, every stretch decided, every
output written to a temporary ``--out-dir``); RPP at Nav2's defaults and the given ``--V``, the VFF map at CARMEL's
preset. Prints the best wall seconds of each over ``--repeat`` runs and their ratio. Bar: RPP <= 10 s on a 2-core
machine.

Usage: ``python benchmarks/bench_map_controller.py [--map warehouse] [--V 0.5] [--repeat 2]``
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def run_once(argv) -> float:
    """Wall seconds of ``pfm-stability map ARGV --out-dir TMP --quiet`` in this process."""
    from pfm_stability.cli import main

    with tempfile.TemporaryDirectory() as out, contextlib.redirect_stdout(io.StringIO()):
        started = time.perf_counter()
        code = main(["map", *argv, "--out-dir", os.path.join(out, "result"), "--quiet"])
        seconds = time.perf_counter() - started
    if code != 0:
        raise SystemExit(f"pfm-stability map {' '.join(argv)} exited {code}")
    return seconds


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="warehouse")
    parser.add_argument("--V", default="0.5", help="RPP's max_linear_vel, m/s")
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    rpp = [run_once([args.map, "--controller", "rpp", "--V", args.V]) for _ in range(args.repeat)]
    vff = [run_once([args.map]) for _ in range(args.repeat)]
    print(f"map {args.map} --controller rpp --V {args.V}: best {min(rpp):.2f} s of {args.repeat} (first, with imports: {rpp[0]:.2f} s)")
    print(f"map {args.map} (VFF, CARMEL): best {min(vff):.2f} s of {args.repeat}")
    print(f"ratio rpp/vff: {min(rpp) / min(vff):.2f}; bar: rpp <= 10 s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
