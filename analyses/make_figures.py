"""Regenerate the figures of ``analyses/figures/`` in one command.

    python analyses/make_figures.py                 # every figure
    python analyses/make_figures.py corridor_regions wall_regions
    python analyses/make_figures.py --list
    python analyses/make_figures.py --out /tmp/figs --dpi 150

Figures (CARMEL preset: V = 0.8 m/s, τ = 0.3 s, T = 0.065 s, f = 0.8, n = 2,
W = 0.8 m, k = 2 1/s assumed, command hold with a one-sample compute delay;
Koren & Borenstein 1991, "KB"):

``corridor_regions``         (L, V) regions and L*(V), every model (KB §5.4, eq 25) — shown in the README
``wall_regions``             (V, f) regions at α = 20°, 45°, 70° and α*(V) (KB §5.3, eq 24)
``model_comparison``         NV* versus k and versus T/τ, all models and sampled structures
``kb_error_maps``            where KB's eq (20) is optimistic or conservative, over (kτ, T/τ)
``root_locus``               Padé(3) root locus of KB eq (18) with every model's crossing
``simulation_vs_prediction`` simulated boundary points on the predicted curves (analytic and grid)
``trajectories``             stable, oscillating and colliding runs drawn like KB Figs 5 and 6

The region figures shade the verdicts of the model the stability report uses
(``sampled`` with CARMEL's command hold and one-sample compute delay); every
model's boundary is drawn as a line. The notebooks in this folder draw the
same figures with short explanations.
Total run time on a 2-core machine: about a minute.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pfm_stability.analysis.criteria import loop_of  # noqa: E402
from pfm_stability.models import ExactDelay  # noqa: E402
from pfm_stability.parameters import CARMEL  # noqa: E402

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
HERE = Path(__file__).resolve().parent


def corridor_regions():
    from pfm_stability.analysis.region_panels import corridor_panels

    return corridor_panels(ROBOT, CONTROLLER).plot()


def wall_regions():
    from pfm_stability.analysis.region_panels import wall_panels

    return wall_panels(ROBOT, CONTROLLER, alphas_deg=(20.0, 45.0, 70.0)).plot()


def model_comparison():
    from pfm_stability.analysis.comparison import critical_gain_vs_delay, critical_gain_vs_k
    from pfm_stability.plots.comparison import plot_model_comparison

    return plot_model_comparison(critical_gain_vs_k(ROBOT.tau, CONTROLLER.T), critical_gain_vs_delay(ROBOT.tau, ROBOT.k))


def kb_error_maps(resolution: int = 40):
    from pfm_stability.plots.comparison import plot_kb_error_maps
    from pfm_stability.analysis.comparison import kb_error_map
    from pfm_stability.analysis.comparison import kb_error_maps as maps_of

    k_tau = np.geomspace(0.05, 20.0, resolution)
    T_over_tau = np.geomspace(0.01, 3.0, resolution)
    maps = maps_of(k_tau, T_over_tau) + [kb_error_map(k_tau, T_over_tau, ExactDelay())]
    return plot_kb_error_maps(maps, mark=(ROBOT.k * ROBOT.tau, CONTROLLER.T / ROBOT.tau))


def root_locus():
    from pfm_stability.analysis.comparison import root_locus as locus_of

    return locus_of(loop_of(ROBOT, CONTROLLER), hold=CONTROLLER.hold, compute_delay=CONTROLLER.compute_delay).plot()


def simulated_points():
    """Bisected simulated boundaries: corridor V*(L) and wall α*(V), analytic and grid (about 30 s)."""
    from pfm_stability.validation import simulated_boundary

    corridor_L = [0.6, 0.7, 0.8, 0.9, 1.0]
    wall_V = [0.4, 0.8, 1.2]
    out = {}
    for env, offset in (("analytic", 1e-6), ("grid", 1e-3)):
        out["corridor", env] = simulated_boundary("corridor", "V", 0.1, 3.0, over="L", values=corridor_L, env=env, offset=offset, duration=20.0)
        out["wall", env] = simulated_boundary("wall", "alpha", math.radians(10), math.radians(70), over="V", values=wall_V, env=env, offset=offset, duration=20.0)
    return out


def grid_law():
    """The lateral law of a straight wall of cells in the histogram grid (the simulator's own)."""
    from pfm_stability.sim import make_scenario

    return make_scenario("corridor", env="grid").effective_law()


def simulation_vs_prediction(points=None):
    from pfm_stability.analysis.region_panels import corridor_V_panel, shading_text, wall_alpha_panel
    from pfm_stability.analysis.regions import region_model
    from pfm_stability.plots.regions import region_legend

    points = simulated_points() if points is None else points
    law = grid_law()
    fig, axes = plt.subplots(2, 2, figsize=(11.5, 10.5), layout="constrained")
    for col, env in enumerate(("analytic", "grid")):
        env_law = None if env == "analytic" else law
        what = "analytic walls, KB's power law f(W/d)^n" if env == "analytic" else "histogram grid, curves with the grid's effective law"
        corridor_V_panel(ROBOT, CONTROLLER, law=env_law, resolution=200).plot(ax=axes[0, col], legend=False)
        points["corridor", env].plot(ax=axes[0, col], label="simulated boundary (bisection)")
        axes[0, col].set_title(f"Corridor, {what}\nstable below V*(L); points: simulated V* at fixed L", fontsize=9)
        wall_alpha_panel(ROBOT, CONTROLLER, law=env_law, resolution=200).plot(ax=axes[1, col], legend=False)
        points["wall", env].plot(ax=axes[1, col], label="simulated boundary (bisection)")
        axes[1, col].set_title(f"Wall, {what}\nstable above α*(V); points: simulated α* at fixed V", fontsize=9)
    region_legend(fig=fig, ncol=3)
    fig.suptitle(
        "Simulated VFF runs against every model's predicted boundary (CARMEL)\n"
        f"shaded: {shading_text(region_model(CONTROLLER), CONTROLLER)}, which is also the simulator's loop",
        fontsize=11,
    )
    return fig


def figure_legend(fig, **options):
    """One legend below the panels, each label once (a legend inside an axes could hide the target arrow)."""
    entries = {}
    for ax in fig.axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    return fig.legend(list(entries.values()), list(entries), loc="outside lower center", fontsize=8, frameon=False, **options)


def outcome(result) -> str:
    """One line: how a run ended (events, or growth rate and closest approach)."""
    if result.events:
        return "; ".join(f"{e.type.replace('_', ' ')} at {e.t:.1f} s" for e in result.events)
    m = result.metrics
    sigma = f", σ = {m.growth_rate:+.2f} 1/s" if m is not None and m.growth_rate is not None else ""
    return f"no collision in {result.t_end:.0f} s{sigma}"


TRAJECTORY_RUNS = (
    ("kb-fig6-wide", "STABLE — KB Fig 6a\nwide corridor, L = 0.9 m after the step"),
    ("kb-fig5", "OSCILLATING — KB Fig 5\nwall at α = 20° after the corner"),
    ("kb-fig6-narrow", "COLLIDING — KB Fig 6b\nnarrow corridor, L = 0.6 m after the step"),
)


def trajectories():
    from pfm_stability.sim import simulate

    fig, axes = plt.subplots(1, 3, figsize=(13, 9.0), layout="constrained", gridspec_kw=dict(width_ratios=[1, 1.8, 1]))
    for ax, (name, title) in zip(axes, TRAJECTORY_RUNS):
        result = simulate(name)
        result.plot(ax=ax, title=f"{title}\n{outcome(result)}", legend=False)
        ax.title.set_fontsize(9)
    figure_legend(fig, ncol=6)
    fig.suptitle("Simulated CARMEL runs in the histogram grid, drawn like Koren & Borenstein 1991 Figs 5 and 6 (robot every 1 s, to scale)", fontsize=11)
    return fig


FIGURES = {
    "corridor_regions": corridor_regions,
    "wall_regions": wall_regions,
    "model_comparison": model_comparison,
    "kb_error_maps": kb_error_maps,
    "root_locus": root_locus,
    "simulation_vs_prediction": simulation_vs_prediction,
    "trajectories": trajectories,
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help=f"figures to draw (default all): {', '.join(FIGURES)}")
    parser.add_argument("--out", default=str(HERE / "figures"), help="output folder (default analyses/figures)")
    parser.add_argument("--dpi", type=int, default=110)
    parser.add_argument("--list", action="store_true", help="list the figures and exit")
    args = parser.parse_args(argv)
    if args.list:
        print("\n".join(FIGURES))
        return 0
    unknown = [n for n in args.names if n not in FIGURES]
    if unknown:
        parser.error(f"unknown figure(s) {', '.join(unknown)}; known: {', '.join(FIGURES)}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in args.names or FIGURES:
        started = time.perf_counter()
        fig = FIGURES[name]()
        path = out / f"{name}.png"
        fig.savefig(path, dpi=args.dpi)
        plt.close(fig)
        print(f"wrote {path} ({time.perf_counter() - started:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
