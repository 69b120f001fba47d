"""Simulation against prediction over many parameter sets (docs/validation.md): the numbers behind the tests.

1. **Analytic boundaries**: for each reference set (`REFERENCE_SETS`: KB's
   CARMEL, a fast and a slow robot), each sampled structure (hold command or
   reference, compute delay 0 or 1) and each geometry (corridor: L, KB eq 25;
   wall: α, eq 24), the boundary bisected in the simulator with continuous
   walls (KB's lumped law) against every model (`validate_boundary`), and σ, ω
   at the boundary and 3 % either side against the `sampled` dominant root.
2. **Grid boundaries**: the same in the VFF histogram grid with the grid's
   effective law (`GridWallLaw`) for each reference set (corridor in L, wall
   in α) and CARMEL's corridor in V; KB's lumped law at f_av beside it.
3. **Random sweeps**: 200 Latin-hypercube parameter sets in each environment
   (`verdict_sweep`): agreement of the sign of the simulated σ with `sampled`,
   and how often ``kb_first_order`` (KB eq 20) and ``exact_delay`` (eq 18)
   give the wrong verdict for the sampled robot.

    python experiments/validation_summary.py [--out experiments/results]

Writes ``validation_summary.json``, ``validation_errors.png`` (each model's
boundary error), ``sweep.png`` and ``sweep_grid.png``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import output_dir, parse_args, row, save_figure, write_json  # noqa: E402

STRUCTURES = (("command", 0), ("command", 1), ("reference", 0), ("reference", 1))


def _case(name, v) -> dict:
    freq = [abs(c.frequency_error) for c in v.oscillation if c.frequency_error is not None]
    sigma = [abs(c.growth_rate_error) for c in v.oscillation if c.growth_rate_error is not None]
    return {
        "set": name,
        "scenario": v.scenario,
        "env": v.env,
        "parameter": v.parameter,
        "unit": v.unit,
        "hold": v.inputs["hold"],
        "compute_delay": v.inputs["compute_delay"],
        "simulated_boundary": v.simulated_boundary,
        "bracket": list(v.bracket),
        "predicted_boundary": v.predicted_boundary,
        "relative_error": v.relative_error,
        "lumped_predicted_boundary": v.lumped_predicted_boundary,
        "lumped_relative_error": v.lumped_relative_error,
        "max_frequency_error": max(freq) if freq else None,
        "max_growth_rate_error": max(sigma) if sigma else None,
        "oscillation_checks": [c.to_dict() for c in v.oscillation],
        "runs": v.runs,
    }


def _progress(line):
    print(f"  {line}", file=sys.stderr, flush=True)


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.plots.validation import plot_relative_errors, plot_sweep
    from pfm_stability.validation import REFERENCE_SETS, validate_boundary, verdict_sweep

    out = output_dir(out)
    sets = {"carmel": REFERENCE_SETS["carmel"]} if quick else REFERENCE_SETS
    structures = STRUCTURES[1:2] if quick else STRUCTURES

    analytic, analytic_v = [], []
    for name, (robot, controller) in sets.items():
        for hold, delay in structures:
            c = controller.replace(hold=hold, compute_delay=delay)
            for scenario in ("corridor", "wall"):
                v = validate_boundary(scenario, robot=robot, controller=c, env="analytic", rtol=1e-3)
                analytic.append(_case(name, v))
                if name == "carmel":
                    analytic_v.append(v)
        _progress(f"analytic boundaries: {name} done")

    grid, grid_v = [], []
    # (set, scenario, parameter, fixed geometry). The slow robot's grid boundaries in L and alpha lie where
    # it cannot be simulated (L* = 0.49 m is narrower than the narrowest corridor it fits in, 0.5 m with walls
    # on cell centres; at alpha* = 36.6 deg its weak repulsion, f = 0.5, puts d0 against the wall), so its
    # corridor and wall are bisected in V at L = 0.6 m and alpha = 60 deg.
    grid_cases = [("carmel", "corridor", "L", {}), ("carmel", "wall", "alpha", {})]
    if not quick:
        grid_cases += [
            ("carmel", "corridor", "V", {"L": 0.8}), ("fast", "corridor", "L", {}), ("fast", "wall", "alpha", {}),
            ("slow", "corridor", "V", {"L": 0.6}), ("slow", "wall", "V", {"alpha": math.radians(60.0)}),
        ]
    for name, scenario, parameter, geometry in grid_cases:
        robot, controller = sets[name]
        v = validate_boundary(scenario, parameter, robot=robot, controller=controller, env="grid", **geometry)
        grid.append(_case(name, v))
        grid_v.append(v)
        _progress(f"grid boundary: {name} {scenario} {v.parameter} done")

    count = 40 if quick else 200
    sweeps = {env: verdict_sweep(count, seed=0, env=env) for env in (("analytic",) if quick else ("analytic", "grid"))}
    _progress("sweeps done")

    fig, axes = plt.subplots(2, 1, figsize=(11.0, 9.0), layout="constrained")
    plot_relative_errors(analytic_v, [f"{v.scenario} {v.parameter}\n{v.inputs['hold']}, cd={v.inputs['compute_delay']}" for v in analytic_v], ax=axes[0])
    axes[0].set_title("analytic walls (KB's lumped law), CARMEL, every sampled structure: each model's boundary error", fontsize=9)
    plot_relative_errors(grid_v, [f"{c['set']}: {c['scenario']} {c['parameter']}\n{c['hold']}, cd={c['compute_delay']}" for c in grid], ax=axes[1])
    axes[1].set_title("histogram grid (models fed the grid's effective law; hatched: KB's lumped law at f_av)", fontsize=9)
    save_figure(fig, out / "validation_errors.png")
    for env, sweep in sweeps.items():
        save_figure(plot_sweep(sweep), out / ("sweep.png" if env == "analytic" else f"sweep_{env}.png"))

    def worst(cases, key="relative_error", model="sampled"):
        return max(abs(c[key][model]) for c in cases)

    def span(cases, model, key="relative_error"):
        values = [100 * c[key][model] for c in cases if c[key] and c[key][model] is not None]
        return f"{min(values):+.1f} to {max(values):+.1f} %"

    result = {
        "experiment": "validation summary: simulated boundaries, oscillation and random sweeps against the models",
        "inputs": {"quick": quick, "sets": list(sets), "structures": [list(s) for s in structures], "sweep_count": count, "sweep_seed": 0},
        "analytic_boundaries": analytic,
        "grid_boundaries": grid,
        "sweeps": {env: s.to_dict() for env, s in sweeps.items()},
        "summary": {
            "analytic_max_relative_error_sampled": worst(analytic),
            "analytic_max_frequency_error": max(c["max_frequency_error"] for c in analytic),
            "grid_max_relative_error_sampled": worst(grid),
            "grid_max_frequency_error": max(c["max_frequency_error"] for c in grid),
            "sweep_agreement": {env: s.agreement for env, s in sweeps.items()},
            "sweep_wrong_verdict_rate": {env: s.wrong_verdict_rate for env, s in sweeps.items()},
        },
    }
    n_a, n_g = len(analytic), len(grid)
    rows = [
        row("Validation", f"analytic boundary, {len(sets)} sets x {len(structures)} structures x corridor/wall ({n_a})",
            "-", "sampled model", "bisected (rtol 1e-3, sigma interpolated)",
            f"max |error| sampled {worst(analytic):.1e} (bar 1 %); kb_first_order {span(analytic, 'kb_first_order')}, "
            f"exact_delay {span(analytic, 'exact_delay')}"),
        row("Validation", f"omega near the analytic boundary ({3 * n_a} runs)", "-", "sampled dominant root", "linear-prediction fit",
            f"max |error| {result['summary']['analytic_max_frequency_error']:.1e} (bar 5 %)"),
        row("Validation", f"grid boundary, GridWallLaw ({n_g})", "-", "sampled, grid law", "bisected in the grid",
            f"max |error| sampled {100 * worst(grid):.2f} % (bar 5 %); KB's lumped kb_first_order {span(grid, 'kb_first_order', 'lumped_relative_error')}"),
        row("Validation", f"omega near the grid boundary ({3 * n_g} runs)", "-", "sampled dominant root", "peaks",
            f"max |error| {100 * result['summary']['grid_max_frequency_error']:.2f} % (bar 5 %)"),
    ]
    for env, s in sweeps.items():
        rate = s.wrong_verdict_rate
        rows.append(row("Validation", f"random sweep, {s.count} sets ({env})", "-", "sampled verdict", "sign of sigma",
                        f"agreement {100 * s.agreement:.1f} % of {s.included} (bar 98 %); wrong verdicts: kb_first_order "
                        f"{100 * rate['kb_first_order']:.1f} %, exact_delay {100 * rate['exact_delay']:.1f} %, continuous {100 * rate['continuous']:.1f} %"))
    result["rows"] = rows
    result["finding"] = "; ".join(f"{r['quantity']}: {r['note']}" for r in rows)
    write_json(out / "validation_summary.json", result)
    return result


def main(argv=None) -> int:
    args = parse_args(__doc__.splitlines()[0], argv)
    result = run(args.out, quick=args.quick)
    for r in result["rows"]:
        print(f"{r['quantity']}: {r['note']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
