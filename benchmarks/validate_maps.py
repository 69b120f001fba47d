"""Map predictions against simulation on the shipped maps (docs/maps.md, "Validation"; docs/validation.md).

For each of ``depot``, ``warehouse`` and ``tb3_sandbox`` (pfm_stability/data/maps):
analyse the map (`pfm_stability.maps.analysis.analyze_map`, the grid law) with the
robot of `ROBOTS`, and simulate every segment with a verdict
(`pfm_stability.validation.maps.validate_map_segments`). Prints per map the agreement
over the measured segments (agree or disagree: `MapCase.outcome`) with |margin| > 10 %
(the promise: >= 85 % over >= 18 such segments on the three maps together), the counts
of every outcome, and every disagreement with the numbers
needed to diagnose it: the segment's effective N (N_eff, the uniform gain with its mean
growth rate), its largest single-sample N and median, the predicted and measured σ,
the run's end event, and the predicted and measured equilibrium offsets.

The robots (`VARIANTS`): a TurtleBot-size robot (W 0.4 m; 0.2 m in tb3_sandbox) with
CARMEL's sampled structure (command hold, one-sample compute delay), a fast steering
loop (τ 0.1 s, k 20 1/s) and a 25 ms cycle, so that the oscillation's wavelength
2πV/ω* (0.1–0.2 m) fits three times into the judged parts of the maps' straight pieces
(1–2.5 m, less the stretches at aisle ends where the corridor model does not hold;
0.5–0.7 m in tb3_sandbox), each map driven at V = 0.2, 0.3 and 0.4 m/s (the same
segment at three speeds: three predictions, since N_eff, V* and the margin depend on
V). The cell ratio f = 2 puts V* of the corridors on both sides of V (the predicted-unstable
segments are all too short to measure: docs/maps.md, "Validation").

Usage: ``python benchmarks/validate_maps.py [--maps depot warehouse] [--seed 0] [--end-fraction 0.5] [--json out.json]``
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from pfm_stability.laws.fields import make_law
from pfm_stability.maps.analysis import analyze_map
from pfm_stability.maps.deciding.verdicts import END_FRACTION, TAPER_SLOPE
from pfm_stability.maps.reading.occupancy import load_map
from pfm_stability.parameters import CARMEL
from pfm_stability.io.serialize import dumps
from pfm_stability.validation.maps import CLEAR_MARGIN, simulator_grid, validate_map_segments

MAPS = Path(__file__).resolve().parent.parent / "pfm_stability" / "data" / "maps"

ROBOT = dict(W=0.4, tau=0.1, k=20.0, T=0.025, f=2.0, cell_size=0.1, window=33, min_length=None)
"""The validation robot: W m, τ s, k 1/s, T s, f, histogram cell size m, window cells, shortest segment m (None: default)."""

SPEEDS = (0.2, 0.3, 0.4)
"""Speeds each map is driven at, m/s."""

ROBOTS = {
    "depot": ROBOT,
    "warehouse": ROBOT,
    "tb3_sandbox": dict(ROBOT, W=0.2, min_length=0.5),
}
"""Robot per map (tb3_sandbox's pieces are narrow and short)."""

VARIANTS = tuple((name, dict(p, V=V)) for name, p in ROBOTS.items() for V in SPEEDS)
"""(map, robot) of every validation: each map at each of `SPEEDS`."""


def analysed(name: str, p: dict):
    """(analysis, robot, controller, law) of shipped map `name` with the robot `p` (`ROBOTS`)."""
    robot = CARMEL.robot.replace(W=p["W"], tau=p["tau"], k=p["k"], V=p["V"])
    controller = CARMEL.controller.replace(T=p["T"], f=p["f"])
    law = make_law("grid", robot, controller, cell_size=p["cell_size"], window_cells=p.get("window", 33))
    analysis = analyze_map(load_map(MAPS / f"{name}.yaml"), robot, controller, law, min_length=p["min_length"], along_routes=False,
                           end_fraction=p.get("end_fraction", END_FRACTION), taper_slope=p.get("taper_slope", TAPER_SLOPE))
    return analysis, robot, controller, law


def validate(name: str, p: dict, seed: int = 0, count: int | None = None):
    """(analysis, MapValidation) of shipped map `name`: `count` segments (default every one with a verdict)."""
    analysis, robot, controller, law = analysed(name, p)
    predicted = [s for s in analysis.segments if s.margin is not None and s.stable is not None]
    v = validate_map_segments(simulator_grid(analysis.grid), analysis.segments, robot, controller, cell_ratio=law.ratio,
                              window_cells=law.window_cells, count=count or max(1, len(predicted)), seed=seed)
    return analysis, v


def clear_cases(v) -> list:
    """The measured cases (agree or disagree: `MapCase.outcome`) with |predicted margin| > `CLEAR_MARGIN` (the ones the
    promise counts)."""
    return [c for c in v.cases if c.agree is not None and abs(c.predicted_margin) > CLEAR_MARGIN]


def run_map(name: str, p: dict, seed: int) -> dict:
    started = time.perf_counter()
    analysis, v = validate(name, p, seed)
    segments = analysis.segments
    clear = clear_cases(v)
    agreed = sum(1 for c in clear if c.agree)
    counts = analysis.summary()["verdicts"]
    print(f"\n{name} [V={p['V']} W={p['W']} tau={p['tau']} k={p['k']} T={p['T']} f={p['f']} c={p['cell_size']} "
          f"end fraction {p.get('end_fraction', END_FRACTION)}] "
          f"{len(segments)} segments ({', '.join(f'{n} {k}' for k, n in counts.items() if n)}); "
          f"{time.perf_counter() - started:.1f} s, of which simulation {v.seconds:.1f} s")
    print(f"  measurable with |margin| > {CLEAR_MARGIN:g}: {len(clear)} "
          f"({sum(c.predicted_stable for c in clear)} predicted stable), agree {agreed}"
          + (f" ({agreed / len(clear):.0%})" if clear else ""))
    print(f"  all simulated: {v.agreed} agree, {v.disagreed} disagree, {v.not_measurable} not measurable")
    short = [c for c in v.cases if c.agree is None]
    if short:
        print(f"  not measurable: {len(short)} (e.g. {short[0].reason})")
    samples = analysis.samples
    for c in v.cases:
        if c.agree is not False:
            continue
        s = segments[c.index]
        mine = samples.N[samples.segment == c.index]
        mine = mine[np.isfinite(mine)]
        median_N = float(np.median(mine)) if mine.size else math.nan
        print(f"  DISAGREE #{c.index} ({c.x0:.2f},{c.y0:.2f})->({c.x1:.2f},{c.y1:.2f}) {c.length:.2f} m: predicted "
              f"{c.predicted_verdict} margin {c.predicted_margin:+.2f}, N_eff = {c.N:.3g} over {s.stretch} samples "
              f"(N_max {s.N_max:.3g}, median {median_N:.3g}), sigma predicted {c.predicted_growth_rate:.3g} measured "
              f"{c.growth_rate} ({c.method}, {c.event}{', within resolution' if c.basis == 'resolution' else ''}); offset predicted {c.predicted_offset:+.3f} measured {c.measured_offset}")
    return {"map": name, "robot": p, "clear": len(clear), "agreed": agreed, "validation": v.to_dict()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", nargs="+", default=list(ROBOTS), choices=list(ROBOTS))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--end-fraction", type=float, default=END_FRACTION,
                        help=f"largest |F_r.t| of a judged sample, units of F_ct (default {END_FRACTION})")
    parser.add_argument("--json", help="write every case here")
    args = parser.parse_args(argv)
    out = [run_map(name, dict(p, end_fraction=args.end_fraction), args.seed) for name, p in VARIANTS if name in args.maps]
    clear = sum(r["clear"] for r in out)
    agreed = sum(r["agreed"] for r in out)
    print(f"\nall maps ({len(out)} map x speed variants, end fraction {args.end_fraction:g}): {agreed}/{clear} measurable segments with |margin| > {CLEAR_MARGIN:g} agree"
          + (f" ({agreed / clear:.0%})" if clear else ""))
    if args.json:
        Path(args.json).write_text(dumps(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
