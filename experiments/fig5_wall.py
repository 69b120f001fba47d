"""KB Fig 5: a discontinuity in the wall at α = 20° makes CARMEL oscillate; above α* it settles.

Koren & Borenstein 1991 §5.3: "CARMEL was forced to travel alongside a wall
… a discontinuity in the wall (at α = 20°) caused the robot to enter into
oscillatory and unstable motion", when condition (24) is not met.

Three parts, all in the histogram grid with KB's CARMEL (f_av = 0.8, command
hold, one-sample compute delay, k = 2 1/s assumed):

1. **KB's run** (``kb-fig5`` preset): a wall followed at α = 50° turns 30°
   towards the robot, so that the second section is met at α = 20°.
2. **The same wall above α\\***: the target direction is turned 20° so that
   the sections are met at 70° and 40° (> α*): the robot follows the corner
   and settles.
3. **α\\* itself**: every model's prediction with the grid's effective law
   (`GridWallLaw`) and with KB's lumped law at f_av = 0.8, against the
   simulated boundary bisected in α on a straight grid wall
   (`validate_boundary`).

    python experiments/fig5_wall.py [--out experiments/results]

Writes ``fig5.png`` (both runs drawn like KB's figure), ``fig5_boundary.png``
(model boundaries over simulated runs) and ``fig5.json``.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import boundary_row, output_dir, row, run_summary, save_figure, script_main, share_limits, write_json  # noqa: E402

KB_ALPHA = 20.0
"""deg: KB's discontinuity."""
ABOVE_ALPHA = 40.0
"""deg: the companion run, above the grid's α* ≈ 33°."""
TURN = 30.0
"""deg: the kb-fig5 wall turns 30° at the corner (section 1 is met at α + 30°)."""


def above_scenario(alpha_deg: float = ABOVE_ALPHA):
    """``kb-fig5`` with the target turned so that the second section is met at `alpha_deg`.

    Same walls (section 1 drawn at 30° to Y, a staircase of cells; section 2
    along +Y from the corner at (0, 4) m); the start is 5 m before the corner
    at the equilibrium distance of section 1 (α + 30°) measured on the drawn
    staircase (`pfm_stability.sim.vff.measured_equilibrium`), like the preset's.
    """
    from pfm_stability.sim import Pose, Target, make_scenario
    from pfm_stability.sim.vff import measured_equilibrium

    base = make_scenario("kb-fig5")
    law = base.effective_law()
    d0 = measured_equilibrium(law, math.radians(TURN), math.cos(math.radians(alpha_deg + TURN)))
    turn, along = math.radians(TURN), 5.0
    start = Pose(-along * math.sin(turn) - d0 * math.cos(turn), 4.0 - along * math.cos(turn) + d0 * math.sin(turn), turn)
    notes = dict(base.notes)
    notes["geometry"] = (
        f"kb-fig5 walls; target at infinity {90 - alpha_deg:g} deg right of +Y: alpha = {alpha_deg + TURN:g} deg on "
        f"section 1, {alpha_deg:g} deg on section 2"
    )
    notes["start"] = f"5 m before the corner at the section-1 equilibrium d0 = {d0:.3f} m (measured on the 30-deg staircase)"
    return dataclasses.replace(
        base, target=Target.direction(math.pi / 2 - math.radians(alpha_deg)), start=start,
        analysis={"kind": "wall", "alpha": math.radians(alpha_deg)}, notes=notes,
    )


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.plots.trajectory import plot_trajectory
    from pfm_stability.plots.validation import plot_validation
    from pfm_stability.sim import make_scenario, simulate
    from pfm_stability.validation import predict, validate_boundary

    out = output_dir(out)
    kb_scenario = make_scenario("kb-fig5")
    high_scenario = above_scenario()
    runs = {"kb": simulate(kb_scenario), "above": simulate(high_scenario)}
    predictions = {"kb": predict(kb_scenario), "above": predict(high_scenario)}
    v = validate_boundary("wall", "alpha", env="grid", rtol=1e-2 if quick else 1e-3, stability_map=None if quick else (7, 9))

    result = {
        "experiment": "KB 1991 Fig 5: oscillation along a wall below alpha*",
        "kb": {"alpha_deg": KB_ALPHA, "outcome": "oscillatory and unstable motion", "condition": "eq (24) not met"},
        "inputs": {**v.inputs, "quick": quick, "kb_run": kb_scenario.notes, "above_run": high_scenario.notes},
        "runs": {key: run_summary(runs[key], predictions[key], "alpha_deg") for key in runs},
        "alpha_critical_deg": {
            "simulated": v.simulated_boundary,
            "bracket": list(v.bracket),
            "predicted_grid_law": v.predicted_boundary,
            "relative_error_grid_law": v.relative_error,
            "predicted_lumped_law": v.lumped_predicted_boundary,
            "relative_error_lumped_law": v.lumped_relative_error,
            "oscillation_checks": [c.to_dict() for c in v.oscillation],
        },
    }
    kb_run, high_run = runs["kb"], runs["above"]
    result["finding"] = (
        f"alpha* = {v.simulated_boundary:.2f} deg simulated vs {v.predicted_boundary['sampled']:.2f} deg sampled "
        f"({100 * v.relative_error['sampled']:+.2f} %); KB's eq (24) with f_av = 0.8 predicts "
        f"{v.lumped_predicted_boundary['kb_first_order']:.2f} deg. At alpha = 20 deg the robot "
        + (f"oscillates and collides at {kb_run.events[0].t:.1f} s" if kb_run.collided else "oscillates")
        + f"; at alpha = {ABOVE_ALPHA:g} deg it settles (sigma = {high_run.metrics.growth_rate:+.3f} 1/s, "
        f"sampled {predictions['above'].matching.growth_rate:+.3f} 1/s)."
    )

    fig, axes = plt.subplots(1, 2, figsize=(11.0, 8.6), layout="constrained")
    p_kb, p_hi = predictions["kb"].matching, predictions["above"].matching
    titles = [
        f"(a) KB's run: discontinuity at alpha = {KB_ALPHA:g} deg < alpha* = {v.simulated_boundary:.1f} deg\n"
        f"sampled model sigma = {p_kb.growth_rate:+.2f} 1/s; "
        + (f"collides at {kb_run.events[0].t:.1f} s" if kb_run.collided else "oscillates"),
        f"(b) same wall, target turned: alpha = {ABOVE_ALPHA:g} deg > alpha*\n"
        f"sigma = {high_run.metrics.growth_rate:+.3f} 1/s (sampled {p_hi.growth_rate:+.3f}); settles",
    ]
    for ax, r, title in zip(axes, (kb_run, high_run), titles):
        plot_trajectory(r, ax=ax, title=title)
    share_limits(axes, (kb_run, high_run))
    fig.suptitle("KB Fig 5: CARMEL along a wall of grid cells (circles: robot every 1 s, to scale; f_av = 0.8, T = 65 ms)", fontsize=10)
    save_figure(fig, out / "fig5.png")
    save_figure(plot_validation(v), out / "fig5_boundary.png")

    result["rows"] = [
        boundary_row("Fig 5", "alpha* (deg), straight grid wall", "eq (24) violated at 20", v, 2, f"{v.simulated_boundary:.2f}"),
        row("Fig 5", "run with the discontinuity at alpha = 20 deg", "oscillatory, unstable",
            f"unstable, sigma = {p_kb.growth_rate:+.3f} 1/s",
            (f"oscillates, collides at {kb_run.events[0].t:.1f} s" if kb_run.collided else
             f"sigma = {kb_run.metrics.growth_rate}"), "growth too fast to fit sigma before the collision"),
        row("Fig 5", f"same wall at alpha = {ABOVE_ALPHA:g} deg", "-",
            f"stable, sigma = {p_hi.growth_rate:+.3f} 1/s", f"settles, sigma = {high_run.metrics.growth_rate:+.3f} 1/s", ""),
    ]
    write_json(out / "fig5.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    sys.exit(main())
