"""KB Fig 3: calibrate the force ratio so that CARMEL just barely avoids a 40 × 40 cm obstacle head-on.

Koren & Borenstein 1991 §4: "This experiment was performed to define the
relative strength of the repulsive force … such that the robot would just
barely avoid the obstacle when approaching it head-on, at maximum speed"
(0.8 m/s), and "With the experiment of Fig. 3, we determined f_av = 0.8".

Here the same procedure runs in the simulator (``kb-fig3`` preset: a 4 × 4
cell obstacle 4.45 m ahead, 5 cm beside the start–target line; CARMEL with
command hold and a one-sample compute delay): `barely_avoiding_ratio` finds
the smallest cell ratio ρ = F_cr/F_ct with which the run avoids the obstacle,
and the grid's f_av (KB's lumped f averaged over the window's working range,
`f_average`) is compared with KB's 0.8. Then the run is repeated with the
ratio that gives f_av = 0.8 (`calibrate_cell_ratio` through
`pfm_stability.sim.scenario_law`, what every ``kb-*`` preset uses).

Finding: KB's procedure gives ρ = 0.00837, f_av = 2.15 — and f(d) of that
grid ranges from 1.09 (robot touching the wall) to 2.93 (window edge), never
0.8; with f_av = 0.8 (ρ = 0.00311) the head-on run collides. On this model
KB's two statements cannot both hold: their f_av averaging is not given, and
CARMEL's real obstacle CVs, sensor-ring width and steering response may
differ from the preset's (CV 15, W = 0.8 m, 120°/s, τ = 0.3 s).

    python experiments/fig3_calibration.py [--out experiments/results]

Writes ``fig3.png`` (both runs drawn like KB's figure: filled cells, the
robot every second to scale) and ``fig3.json``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

KB_F_AV = 0.8
"""KB §4: "we determined f_av = 0.8"."""


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.laws.effective_force import f_average, working_range
    from pfm_stability.parameters import CARMEL
    from pfm_stability.plots.trajectory import plot_trajectory
    from pfm_stability.sim import barely_avoiding_ratio, scenario_law, simulate

    out = output_dir(out)
    robot, controller = CARMEL.robot, CARMEL.controller
    n, W, c, w = controller.n, robot.W, CARMEL.cell_size, CARMEL.window_cells
    members, rounds = (12, 2) if quick else (24, 3)
    rho_kb_procedure = barely_avoiding_ratio(robot, controller, window_cells=w, cell_size=c, members=members, rounds=rounds)
    rho_f08 = scenario_law("grid", robot, controller.replace(f=KB_F_AV), w, c).ratio  # calibrated: f_av = 0.8
    law = scenario_law("grid", robot, controller, w, c, cell_ratio=rho_kb_procedure)
    f_av = f_average(law)
    lo, hi = working_range(W, c, w)
    d = np.linspace(lo, hi, 121)
    f_of_d = law.equivalent_f(d, n, W)

    runs = {
        "kb_procedure": simulate("kb-fig3", cell_ratio=rho_kb_procedure),
        "f_av_0.8": simulate("kb-fig3", cell_ratio=rho_f08),
    }

    def outcome(r):
        e = r.events[0] if r.events else None
        return {
            "event": e.type if e else None,
            "t": e.t if e else r.t_end,
            "collided": r.collided,
            "min_clearance_m": r.min_clearance,
        }

    result = {
        "experiment": "KB 1991 Fig 3: force-ratio calibration by a head-on run",
        "kb": {"f_av": KB_F_AV, "V": robot.V, "obstacle": "approx. 40 x 40 cm", "statement": "just barely avoid the obstacle head-on at maximum speed"},
        "inputs": {
            "V": robot.V, "tau": robot.tau, "k": robot.k, "W": W, "T": controller.T, "n": n, "hold": controller.hold,
            "compute_delay": controller.compute_delay, "cell_size": c, "window_cells": w, "cv": law.cv,
            "bisection": {"members": members, "rounds": rounds}, "quick": quick,
            "geometry": runs["kb_procedure"].scenario.notes["geometry"],
        },
        "kb_procedure": {
            "cell_ratio": rho_kb_procedure,
            "f_av": f_av,
            "f_av_relative_to_kb": f_av / KB_F_AV - 1.0,
            "f_of_d_range": [float(f_of_d.min()), float(f_of_d.max())],
            "averaging_range_m": [lo, hi],
            **outcome(runs["kb_procedure"]),
        },
        "f_av_0.8": {"cell_ratio": rho_f08, "f_av": f_average(scenario_law("grid", robot, controller, w, c, cell_ratio=rho_f08)), **outcome(runs["f_av_0.8"])},
        "finding": (
            f"KB's procedure (smallest ratio that avoids the obstacle) gives F_cr/F_ct = {rho_kb_procedure:.4g}, "
            f"f_av = {f_av:.3g} (KB: {KB_F_AV}); f(d) of that grid spans {f_of_d.min():.3g}-{f_of_d.max():.3g} over "
            f"d = {lo:g}-{hi:g} m, never {KB_F_AV}. With f_av = {KB_F_AV} (F_cr/F_ct = {rho_f08:.4g}) the run collides at "
            f"t = {outcome(runs['f_av_0.8'])['t']:.2f} s."
        ),
    }

    fig, axes = plt.subplots(1, 2, figsize=(8.4, 8.2), layout="constrained")
    titles = {
        "kb_procedure": f"KB's procedure: F_cr/F_ct = {rho_kb_procedure:.4g} (f_av = {f_av:.3g})\n"
        f"just avoids, closest {100 * runs['kb_procedure'].min_clearance:.2g} cm",
        "f_av_0.8": f"KB's f_av = 0.8: F_cr/F_ct = {rho_f08:.4g}\n"
        + (f"collides at {runs['f_av_0.8'].events[0].t:.1f} s" if runs["f_av_0.8"].collided else "avoids"),
    }
    for ax, (key, r) in zip(axes, runs.items()):
        plot_trajectory(r, ax=ax, title=titles[key])
        ax.set_xlim(-2.5, 2.5)
    fig.suptitle("KB Fig 3: CARMEL approaches a 40 x 40 cm obstacle head-on at 0.8 m/s (circles: robot every 1 s, to scale)", fontsize=10)
    save_figure(fig, out / "fig3.png")

    result["rows"] = [
        row("Fig 3", "f_av that just avoids the obstacle", f"{KB_F_AV}", "-", f"{f_av:.3g} (F_cr/F_ct = {rho_kb_procedure:.4g})",
            f"{100 * (f_av / KB_F_AV - 1):+.0f} % vs KB; f(d) spans {f_of_d.min():.2f}-{f_of_d.max():.2f}, never 0.8"),
        row("Fig 3", "head-on run with f_av = 0.8", "avoids (by construction)", "-",
            f"collides at {runs['f_av_0.8'].events[0].t:.2f} s" if runs["f_av_0.8"].collided else "avoids",
            f"F_cr/F_ct = {rho_f08:.4g}: too weak for this run"),
    ]
    write_json(out / "fig3.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    sys.exit(main())
