"""KB Fig 4: no passage between closely spaced obstacles — where CARMEL stops in front of a door, and how wide a door must be.

Koren & Borenstein 1991 §5.2: "Fig. 4 shows a mobile robot at an attempt to
pass among two closely spaced obstacles (e.g., passing through a door
frame) ... The sum of all repulsive forces points straight away from the
opening between the two obstacles. Depending on the relative magnitude of
the target-directed force F_t, the robot will either approach the opening
further, or it will turn away." KB give no numbers; this experiment supplies
them for CARMEL's lumped law (f = 0.8, n = 2, W = 0.8 m, `parameters.CARMEL`)
and for a Khatib law matched to it (ρ0 = 1.65 m, the active window's half
side, and F_r(W) = 0.8 like CARMEL's), with the model of docs/door.md: the
robot on the door's axis, target straight ahead through it, two posts (or
wall ends) each repelling from its nearest point.

* the longitudinal force F_long along the approach for a few widths, the
  smallest passable width w* bold (`door.smallest_passable_width`), each stop
  marked as trapped (the axis is laterally stable there) or turning away;
* w* for point posts, posts of radius 0.1 m and wall ends, and CARMEL's
  against the closed form w* = 2W√(4f/(3√3)) (`door.power_law_door_width`);
* the stop distance and the lateral stiffness at the stop against the width.

    python experiments/kb_fig4_door.py [--out experiments/results]

Writes ``kb_fig4_door.png`` and ``kb_fig4_door.json``.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

RHO0 = 1.65  # Khatib's influence distance: CARMEL's active window reaches (33/2)·0.1 m
WIDTHS = (1.0, 1.1, 1.2, 1.5, 2.0)  # m, drawn beside each law's w*
POST_RADIUS = 0.1  # m, for the "posts of radius" row


def khatib_law(W: float, f: float):
    """Khatib's repulsion η(1/d − 1/ρ0)/d² in units of a constant attraction, with F_r(W) = f."""
    from pfm_stability.laws.force_law import ForceLaw
    from pfm_stability.laws.potentials import khatib_force, repulsion_derivatives

    @dataclass(frozen=True)
    class KhatibLaw(ForceLaw):
        eta: float
        rho0: float
        name = "Khatib (GC2000 eq 4)"

        def force(self, d):
            return khatib_force(np.asarray(d, dtype=float), self.eta, self.rho0)

        def slope(self, d):
            return -repulsion_derivatives(np.asarray(d, dtype=float), 1.0, self.eta, self.rho0)[3]

        def with_scale(self, scale):
            return replace(self, eta=scale)

    return KhatibLaw(f * W * W / (1.0 / W - 1.0 / RHO0), RHO0)


def law_summary(law, name: str, robot_width: float) -> dict:
    """w* for the three obstacle kinds and the passage at each width of `WIDTHS` and at w*·(1 ± 1e-6)."""
    from pfm_stability.analysis.door import door_passage, smallest_passable_width

    smallest = {
        "posts": smallest_passable_width(law, robot_width=robot_width),
        f"posts_r{POST_RADIUS:g}": smallest_passable_width(law, post_radius=POST_RADIUS, robot_width=robot_width),
        "wall-ends": smallest_passable_width(law, obstacle="wall-ends", robot_width=robot_width),
    }
    w_star = smallest["posts"]
    widths = sorted({*WIDTHS, w_star * (1 - 1e-6), w_star * (1 + 1e-6)})
    return {
        "law": name,
        "smallest_passable_width_m": smallest,
        "passages": [door_passage(law, w, robot_width=robot_width).to_dict() for w in widths],
    }


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.analysis.door import approach_force, door_passage, power_law_door_width
    from pfm_stability.laws.force_law import PowerLaw
    from pfm_stability.parameters import CARMEL

    out = output_dir(out)
    f, n, W = CARMEL.controller.f, CARMEL.controller.n, CARMEL.robot.W
    laws = {"power": PowerLaw(f, n, W), "khatib": khatib_law(W, f)}
    summary = {key: law_summary(law, law.name, W) for key, law in laws.items()}
    closed = power_law_door_width(f, n, W)
    w_power = summary["power"]["smallest_passable_width_m"]["posts"]
    w_khatib = summary["khatib"]["smallest_passable_width_m"]["posts"]

    result = {
        "experiment": "KB 1991 Fig 4 (§5.2): passage between two closely spaced obstacles, static model of docs/door.md",
        "kb": {"statement": "the robot approaches the opening further, or it turns away, depending on F_t", "numbers": None},
        "inputs": {"f": f, "n": n, "W_m": W, "khatib": {"eta": laws["khatib"].eta, "rho0_m": RHO0, "matched": "F_r(W) = f"},
                   "widths_m": list(WIDTHS), "post_radius_m": POST_RADIUS, "quick": quick},
        "closed_form_w_star_m": closed,
        "relative_error_numeric_vs_closed_form": w_power / closed - 1.0,
        "laws": summary,
        "finding": (
            f"CARMEL's law (f = {f:g}, n = {n:g}, W = {W:g} m) passes between two point posts only if they are more than "
            f"w* = {w_power:.4f} m apart (closed form {closed:.4f} m), {summary['power']['smallest_passable_width_m'][f'posts_r{POST_RADIUS:g}']:.4f} m "
            f"for posts of radius {POST_RADIUS:g} m (opening {summary['power']['smallest_passable_width_m'][f'posts_r{POST_RADIUS:g}'] - 2 * POST_RADIUS:.4f} m), "
            f"the same {summary['power']['smallest_passable_width_m']['wall-ends']:.4f} m for wall ends; "
            f"a Khatib law matched at d = W (rho0 = {RHO0:g} m) needs {w_khatib:.4f} m. Just below w* the robot is trapped on the axis; "
            f"well below it (CARMEL: stop farther than sqrt(n)*a from the gap) it slides sideways and turns away, as in KB's figure."
        ),
    }

    fig, axes = plt.subplots(2, 2, figsize=(11.0, 9.6), layout="constrained")
    s = np.linspace(0.0, 2.5, 1201)
    for col, (key, law) in enumerate(laws.items()):
        ax = axes[0, col]
        w_star = summary[key]["smallest_passable_width_m"]["posts"]
        widths = sorted({*WIDTHS, w_star})
        colors = plt.cm.viridis(np.linspace(0.0, 0.85, len(widths)))
        for w, color in zip(widths, colors):
            star = w == w_star
            ax.plot(-s, approach_force(law, w, s), color="crimson" if star else color, lw=2.6 if star else 1.4,
                    label=(f"w* = {w:.3f} m (smallest passable)" if star else f"w = {w:g} m"), zorder=3 if star else 2)
            p = door_passage(law, w * (1 - 1e-9) if star else w, robot_width=W)
            if p.stop_distance is not None and not star:
                trapped = p.at_stop == "trapped"
                ax.plot(-p.stop_distance, 0.0, "o" if trapped else "X", ms=9, mfc=color if trapped else "white", mec="black", zorder=4)
        ax.plot([], [], "o", mfc="0.5", mec="black", ms=8, ls="none", label="stop: trapped (axis laterally stable)")
        ax.plot([], [], "X", mfc="white", mec="black", ms=9, ls="none", label="stop: turns away (slides sideways)")
        ax.axhline(0.0, color="black", lw=0.8)
        ax.axvline(0.0, color="0.4", lw=0.8, ls=":")
        ax.set_xlim(-2.5, 0.05)
        ax.set_ylim(min(-0.3, float(approach_force(law, WIDTHS[0], s).min()) - 0.15), 1.12)
        ax.set_xlabel("robot position y on the door's axis, m (gap plane y = 0)")
        ax.set_ylabel("F_long / F_a (forward > 0)")
        ax.set_title(f"{'(a) CARMEL, KB power law f = 0.8, n = 2' if key == 'power' else f'(b) Khatib, rho0 = {RHO0:g} m, F_r(W) = 0.8'}\n"
                     f"two point posts at x = +-w/2; robot W = {W:g} m", fontsize=10)
        ax.legend(fontsize=8, loc="lower left")
        ax.grid(alpha=0.3)

        ax = axes[1, col]
        ws = np.linspace(W + 1e-3, w_star * (1 - 1e-9), 40 if quick else 160)
        ps = [door_passage(law, float(w), robot_width=W) for w in ws]
        stop = np.array([p.stop_distance for p in ps])
        k = np.array([p.lateral_stiffness for p in ps])
        ax.plot(ws, stop, color="black", lw=1.8, label="stop distance before the gap, m")
        ax.fill_between(ws, 0, stop, where=k > 0, color="tab:blue", alpha=0.25, label="trapped on the axis (-dF_x/dx > 0)")
        ax.fill_between(ws, 0, stop, where=k < 0, color="tab:orange", alpha=0.35, label="turns away (-dF_x/dx < 0)")
        ax.axvline(w_star, color="crimson", lw=2.0, label=f"w* = {w_star:.3f} m: passes beyond")
        ax.axvspan(w_star, w_star + 0.25, color="tab:green", alpha=0.15, label="passes (w > w*)")
        if key == "power":
            ax.plot(ws, np.sqrt(n) * ws / 2, color="0.3", lw=1.0, ls="--", label="sqrt(n)*w/2: trapped iff stop below")
        ax2 = ax.twinx()
        ax2.plot(ws, k, color="tab:purple", lw=1.2, ls="-.")
        ax2.axhline(0.0, color="tab:purple", lw=0.6, ls=":")
        ax2.set_ylabel("lateral stiffness -dF_x/dx at the stop, 1/m", color="tab:purple", fontsize=9)
        ax2.tick_params(axis="y", colors="tab:purple")
        ax.plot([], [], color="tab:purple", lw=1.2, ls="-.", label="lateral stiffness at the stop (right axis)")
        ax.set_xlim(W, w_star + 0.25)
        ax.set_ylim(0.0, 1.05 * float(np.max(stop)))
        ax.set_xlabel("door width w (post centre to post centre), m")
        ax.set_ylabel("stop distance, m")
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
        ax.grid(alpha=0.3)
    fig.suptitle("KB Fig 4: no passage between closely spaced obstacles (static: target straight ahead through the gap, "
                 "no momentum)", fontsize=11)
    save_figure(fig, out / "kb_fig4_door.png")

    sp = summary["power"]["smallest_passable_width_m"]
    sk = summary["khatib"]["smallest_passable_width_m"]
    result["rows"] = [
        row("Fig 4", "smallest passable width w* (m), CARMEL, point posts / r = 0.1 m posts / wall ends",
            "robot does not pass closely spaced obstacles (no numbers)",
            f"{sp['posts']:.4f} / {sp[f'posts_r{POST_RADIUS:g}']:.4f} / {sp['wall-ends']:.4f} (closed form {closed:.4f})", "-",
            f"static model, docs/door.md; point posts must be {100 * (sp['posts'] / W - 1):.0f} % farther apart than the robot is wide"),
        row("Fig 4", f"w* (m), Khatib rho0 = {RHO0:g} m matched at d = W", "-",
            f"{sk['posts']:.4f} / {sk[f'posts_r{POST_RADIUS:g}']:.4f} / {sk['wall-ends']:.4f}", "-", ""),
    ]
    write_json(out / "kb_fig4_door.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    sys.exit(main())
