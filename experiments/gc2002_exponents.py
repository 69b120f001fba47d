"""Ge & Cui 2002 Figs 10–12: exponents m and n of the attraction, and hard landing, simulated.

S.S. Ge and Y.J. Cui, "Dynamic motion planning for mobile robots using
potential field method", Autonomous Robots 13, 2002 ("GC2002"), vary the
exponents of U_att = α_p‖e‖^m + α_v‖ė‖ⁿ (eq 1, 7–9) in the Fig 8 scene (target
from (10, 10) m at (0.1, −0.05) m/s, robot from (1, 1) m at rest). With m or
n ≠ 2 the error dynamics are non-linear, so only the planar simulator
(`pfm_stability.sim.planar`, point mass, T = 0.01 s) answers:

* **Fig 10** n = 2, α_p = 0.005, α_v = 0.2, m = 1.5, 2, 3: larger m closes the
  first metres faster, but is weak near the target (‖e‖^(m−1) → 0);
* **Fig 11** m = 2, n = 1.5, 2, 3: n = 1.5 crawls (over-damped), n = 3 is quick and
  oscillates;
* **Fig 12** m = 1, n = 2, α_p = 0.05, α_v = 0.4: hard landing at the closing
  speed α_p/(2α_v) = 0.0625 m/s (`VelocityAttraction.hard_landing_speed`).

Counted: the first time ‖e‖ ≤ 1 m, 0.1 m and 1 mm, ‖e(400 s)‖, the sign changes
of e_x (oscillation).

    python experiments/gc2002_exponents.py [--out experiments/results] [--quick]

Writes ``gc2002_exponents.png`` and ``gc2002_exponents.json``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

TARGET_P, TARGET_V, ROBOT_P = (10.0, 10.0), (0.1, -0.05), (1.0, 1.0)
# (figure, label, alpha_p, alpha_v, m, n, duration of the full run, duration of the quick run or None to skip)
CASES = (
    ("Fig 10", "m = 1.5", 0.005, 0.2, 1.5, 2.0, 400.0, None),
    ("Fig 10", "m = 2", 0.005, 0.2, 2.0, 2.0, 400.0, None),
    ("Fig 10", "m = 3", 0.005, 0.2, 3.0, 2.0, 400.0, 10.0),
    ("Fig 11", "n = 1.5", 0.005, 0.2, 2.0, 1.5, 400.0, None),
    ("Fig 11", "n = 3", 0.005, 0.2, 2.0, 3.0, 400.0, 50.0),
    ("Fig 12", "m = 1 (hard landing)", 0.05, 0.4, 1.0, 2.0, 400.0, 210.0),
)
PAPER = {  # the papers' claims with the reference numbers of the analysis (docs/velocity_and_fuzzy.md)
    "m = 1.5": {"t_1m": 274.6, "t_0.1m": 344.7, "sign_changes": 10},
    "m = 2": {"t_1m": 98.0, "t_0.1m": 183.9},
    "m = 3": {"t_1m": 6.3, "t_0.1m": 248.0},
    "n = 1.5": {"e_400": 1.9},
    "n = 3": {"t_1m": 39.1, "sign_changes": 12},
    "m = 1 (hard landing)": {"closing_speed": 0.0625, "t_1mm": 205.60},
}


def simulate(cases, T) -> list:
    """Every (alpha_p, alpha_v, m, n, duration) of `cases` in one planar batch: [(t, e, ė)]."""
    from pfm_stability.sim.movers import Target
    from pfm_stability.sim.planar import Field, PlanarMember, PointMass, Start, World, simulate_planar_batch
    from pfm_stability.laws.velocity_laws import VelocityAttraction

    members = [PlanarMember(PointMass(1.0), Field(VelocityAttraction(alpha_p, alpha_v, m, n)), World(Target(TARGET_P, TARGET_V)),
                            Start(ROBOT_P), T=T, duration=duration) for alpha_p, alpha_v, m, n, duration in cases]
    out = []
    for run in simulate_planar_batch(members).runs:
        e = np.asarray(TARGET_P) + run.t[:, None] * np.asarray(TARGET_V) - run.p
        de = np.asarray(TARGET_V) - run.v
        out.append((run.t, e, de))
    return out


def measures(t, e, de) -> dict:
    r = np.hypot(*e.T)

    def first(level):
        hit = np.flatnonzero(r <= level)
        return float(t[hit[0]]) if hit.size else None

    out = {"t_1m": first(1.0), "t_0.1m": first(0.1), "t_1mm": first(1e-3), "e_final": float(r[-1]), "t_final": float(t[-1]),
           "sign_changes": int(np.count_nonzero(np.diff(np.sign(e[:, 0])) != 0))}
    far = r > 0.05  # closing speed while still approaching (before the final chatter at the target)
    if np.any(far):
        closing = -(np.sum(e * de, axis=1) / np.maximum(r, 1e-12))  # −d‖e‖/dt = −e·ė/‖e‖
        out["closing_speed_late"] = float(closing[far][-1])
    return out


def _s(t) -> str:
    return "never" if t is None else f"{t:.2f} s"


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.laws.velocity_laws import VelocityAttraction

    out = output_dir(out)
    T = 0.04 if quick else 0.01
    results, curves = [], []
    cases = [c for c in CASES if (c[7] if quick else c[6]) is not None]
    runs = simulate([(ap, av, m, n, short if quick else full) for _, _, ap, av, m, n, full, short in cases], T)
    for (fig_name, label, ap, av, m, n, full, short), (t, e, de) in zip(cases, runs):
        res = {"figure": fig_name, "label": label, "alpha_p": ap, "alpha_v": av, "m": m, "n": n, "T": T, **measures(t, e, de),
               "paper": PAPER[label]}
        if m == 1.0:
            res["closing_speed_theory"] = VelocityAttraction(ap, av, m, n).hard_landing_speed()
        results.append(res)
        step = max(1, len(t) // 2000)
        curves.append((fig_name, label, t[::step], np.hypot(*e[::step].T)))

    fig, axes = plt.subplots(1, 3, figsize=(16, 5.0), layout="constrained")
    for ax, name, title in zip(axes, ("Fig 10", "Fig 11", "Fig 12"),
                               ("Fig 10: n = 2, alpha_p = 0.005, alpha_v = 0.2", "Fig 11: m = 2, alpha_p = 0.005, alpha_v = 0.2",
                                "Fig 12: m = 1, n = 2, alpha_p = 0.05, alpha_v = 0.4 (hard landing)")):
        for fig_name, label, t, r in curves:
            if fig_name == name:
                ax.semilogy(t, np.maximum(r, 1e-5), lw=1.6, label=label)
        for level in (1.0, 0.1):
            ax.axhline(level, color="0.5", ls=":", lw=1)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("||e|| (m)")
        ax.set_ylim(1e-4, 30)
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=9, loc="lower left")
    hard = next((r for r in results if r["m"] == 1.0), None)
    if hard is not None:
        axes[2].text(0.97, 0.97, f"closing speed {hard.get('closing_speed_late', float('nan')):.4f} m/s "
                     f"(alpha_p/(2 alpha_v) = {hard['closing_speed_theory']:.4f})\n||e|| = 1 mm at {hard['t_1mm']:.2f} s",
                     transform=axes[2].transAxes, ha="right", va="top", fontsize=9, bbox={"fc": "white", "ec": "0.6"})
    fig.suptitle(f"GC2002: exponents of the attraction (planar simulation, point mass, T = {T:g} s; Fig 8's scene)", fontsize=11)
    save_figure(fig, out / "gc2002_exponents.png")

    by = {r["label"]: r for r in results}

    def fmt(label, key, digits=1):
        v = by.get(label, {}).get(key)
        return "-" if v is None else f"{v:.{digits}f}"

    rows = [
        row("GC2002 Fig 10", "first ||e|| <= 1 m / 0.1 m (s), m = 1.5, 2, 3", "larger m: error decreases faster", "-",
            "; ".join(f"{lab}: {fmt(lab, 't_1m')} / {fmt(lab, 't_0.1m')}" for lab in ("m = 1.5", "m = 2", "m = 3")),
            f"large m is weak near the target; m = 1.5: {by.get('m = 1.5', {}).get('sign_changes', '-')} sign changes of e_x"),
        row("GC2002 Fig 11", "n = 1.5: ||e(400 s)||; n = 3: first ||e|| <= 1 m, sign changes", "larger n is quicker; n = 3 oscillates", "-",
            f"n = 1.5: {fmt('n = 1.5', 'e_final', 2)} m; n = 3: {fmt('n = 3', 't_1m')} s, {by.get('n = 3', {}).get('sign_changes', '-')} sign changes", ""),
    ]
    if hard is not None:
        rows.append(row("GC2002 Fig 12", "hard landing m = 1: closing speed, ||e|| = 1 mm", "velocity differs from the target's",
                        f"alpha_p/(2 alpha_v) = {hard['closing_speed_theory']:.4f} m/s",
                        f"{hard.get('closing_speed_late', float('nan')):.4f} m/s, 1 mm at {hard['t_1mm']:.2f} s", ""))
    result = {
        "experiment": "GC2002 Figs 10-12: exponents of the attraction, planar simulation",
        "inputs": {"target_position": TARGET_P, "target_velocity": TARGET_V, "robot_position": ROBOT_P, "T": T, "quick": quick},
        "cases": results,
        "rows": rows,
        "finding": "; ".join(f"{r['label']}: 1 m at {_s(r['t_1m'])}, 0.1 m at {_s(r['t_0.1m'])}, ||e(end)|| = {r['e_final']:.3g} m, "
                             f"{r['sign_changes']} sign changes" for r in results) + ".",
    }
    write_json(out / "gc2002_exponents.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
