"""How often ``diagnose`` gets a synthetic corridor right: the measured frequency against the simulator's, the
predicted verdict against the sign of the measured growth (docs/diagnose.md, "Numbers").

Each run is a random corridor (even runs) or wall (odd runs) of `tests/log_helpers.random_corridor` (the ``sampled``
model's margin beyond ±5 %),
driven by the project's VFF simulator and written as an MCAP bag with 360-beam scans, odometry at 50 Hz and
2 % dropped messages; ``diagnose`` reads it back with the run's own k, W, f, n, τ and T. Run:

    python experiments/diagnose_agreement.py [--runs 40] [--seed 0] [--kind both|corridor|wall]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def check(seed: int, directory, kind: str = "corridor") -> dict:
    """One run: the measured and true ω, the measured σ, the predicted verdict and the margin."""
    from log_helpers import corridor_run
    from pfm_stability.analysis.stretches import wall_lines_batch
    from pfm_stability.io.logs import read_log
    from pfm_stability.validation.diagnose import diagnose

    path, robot, controller, geometry, margin, truth = corridor_run(seed, directory, kind=kind)
    log = read_log(path, need=("pose", "scan"), scan_reducer=wall_lines_batch, scan_batch=256)
    result = diagnose(log, robot, controller)
    s = result.judged
    row = {"seed": seed, "kind": kind, "margin": margin, "true_omega": truth.metrics.angular_frequency, "true_sigma": truth.metrics.growth_rate,
           "judged": s is not None}
    if s is not None:
        row.update(omega=s.measured.omega, sigma=s.measured.sigma, measured_stable=s.measured.stable,
                   predicted_stable=s.predicted["sampled"].stable, matching=s.matching, measured_kind=s.stretch.kind)
    else:
        row["reason"] = result.reason
    return row


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=40)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--kind", choices=("both", "corridor", "wall"), default="both")
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for i in range(args.runs):
            kind = args.kind if args.kind != "both" else ("corridor", "wall")[i % 2]
            row = check(args.seed + i, directory, kind)
            rows.append(row)
            if row["judged"]:
                err = (row["omega"] / row["true_omega"] - 1) if row["omega"] and row["true_omega"] else None
                print(f"seed {row['seed']:3d} {row['kind']:8s}: margin {100 * row['margin']:+6.1f} %, ω {row['omega'] or float('nan'):.3f} "
                      f"vs {row['true_omega'] or float('nan'):.3f} ({'—' if err is None else f'{100 * err:+.2f} %'}), "
                      f"σ {row['sigma'] if row['sigma'] is not None else float('nan'):+.4f} vs {row['true_sigma'] or float('nan'):+.4f}, "
                      f"predicted {'stable' if row['predicted_stable'] else 'unstable'}, measured {'stable' if row['measured_stable'] else 'unstable'}, "
                      f"matching {row['matching']}")
            else:
                print(f"seed {row['seed']:3d}: not judged: {row['reason']}")
    judged = [r for r in rows if r["judged"]]
    agree = sum(r["predicted_stable"] == r["measured_stable"] for r in judged)
    errors = [abs(r["omega"] / r["true_omega"] - 1) for r in judged if r["omega"] and r["true_omega"]]
    print(f"\n{len(judged)} of {len(rows)} runs judged; verdicts agree {agree}/{len(judged)} "
          f"({100 * agree / max(len(judged), 1):.1f} %); ω within 5 % of the simulator's: "
          f"{sum(e <= 0.05 for e in errors)}/{len(errors)} (largest error {100 * max(errors, default=0):.2f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
