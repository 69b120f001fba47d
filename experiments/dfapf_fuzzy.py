"""The DFAPF paper's fuzzy-scheduled repulsion in the KB loop: output surfaces, total vs frozen N, corridor shift.

"Dynamic fuzzy artificial potential field" (the DFAPF paper) schedules the
repulsion gain η with a two-input Mamdani controller (obstacle bearing θ,
distance d) and the velocity gain K_V with a second one (θ, relative speed
ΔV). Its display equations are lost; the tables are data and the rest is the
reconstruction R1–R7 of docs/velocity_and_fuzzy.md. In KB's loop
(`pfm_stability.laws.fuzzy_law.FuzzyScheduledLaw`, the repulsion Ge & Cui 2000
eq 8–9 with n = 0):

1. **Output surfaces** of both controllers (the tables as printed).
2. **Wall** (ρ0 = 0.5 m, F_a = 100, α = 60°): d0, η(d0), ∂η/∂d, N with η
   frozen and the total-derivative N (η moves with d), the heading gain c,
   on a left (PM) and a right (NM) wall; beside them the speed V* below
   which CARMEL's loop (τ = 0.3 s, k = 2, T = 0.065 s) is stable with that
   N and c (exact delay and sampled: command hold, one-sample delay).
3. **Corridor** (L = 0.2 … 0.45 m, F_y = 100): the asymmetric tables move the
   equilibrium x* off the centre line.
4. **Robust bracket**: N with η frozen at the output's extremes.

    python experiments/dfapf_fuzzy.py [--out experiments/results] [--quick]

Writes ``dfapf_fuzzy.png`` (both surfaces, the equilibria marked) and
``dfapf_fuzzy.json``.
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

RHO0, ATTRACTION, ALPHA_DEG = 0.5, 100.0, 60.0
CORRIDOR_L = (0.2, 0.3, 0.4, 0.45)
PAPER_WALL = {"left": (0.43933, 34.94, -2.45, 13.459, 13.499, 0.168), "right": (0.42194, 24.06, -73.15, 11.501, 13.257, 0.403)}
PAPER_CORRIDOR = {0.2: (0.65, 955.7), 0.3: (3.46, 154.1), 0.4: (8.24, 35.87), 0.45: (8.09, 17.54)}


def speed_limits(N: float, c: float) -> dict:
    """V* (m/s) below which CARMEL's loop with gains N (1/m) and c is stable: NV*(c)/N, exact delay and sampled."""
    from pfm_stability.analysis.criteria import loop_of
    from pfm_stability.models import make_model
    from pfm_stability.parameters import CARMEL

    loop = replace(loop_of(CARMEL.robot, CARMEL.controller), c=c)
    ctrl = CARMEL.controller
    out = {}
    for name, model in (("exact_delay", make_model("exact_delay")),
                        ("sampled", make_model("sampled", hold=ctrl.hold, compute_delay=ctrl.compute_delay))):
        NV = model.boundary(loop).NV_critical
        out[name] = {"NV_critical": NV, "V_critical": NV / N}
    return out


def wall_table(law, alpha: float) -> list:
    rows = []
    for side in ("left", "right"):
        (e,) = law.wall_equilibria(alpha, side)
        rows.append({
            "side": side, "bearing_set": "PM" if side == "left" else "NM", "d0": e.x0, "eta": e.eta, "eta_d": e.eta_d,
            "N_frozen": e.N_frozen, "N_total": e.N, "total_over_frozen": e.N / e.N_frozen, "c": e.c,
            "c_plus": e.c_plus, "c_minus": e.c_minus,
            "limits_total": speed_limits(e.N, e.c), "limits_frozen_c0": speed_limits(e.N_frozen, 0.0),
            "paper": dict(zip(("d0", "eta", "eta_d", "N_frozen", "N_total", "c"), PAPER_WALL[side])),
        })
    return rows


def corridor_table(law) -> list:
    out = []
    for L in CORRIDOR_L:
        eqs = law.corridor_equilibria(L)
        e = min(eqs, key=lambda q: abs(q.x0))
        out.append({"L": L, "equilibria": len(eqs), "x0_mm": 1e3 * e.x0, "N": e.N, "N_frozen": e.N_frozen, "c": e.c,
                    "paper": {"x0_mm": PAPER_CORRIDOR[L][0], "N": PAPER_CORRIDOR[L][1]}})
    return out


def surfaces(controllers, n: int):
    """η over (θ, d) and K_V over (θ, ΔV) on n × n grids (θ in degrees)."""
    theta = np.linspace(-180.0, 180.0, n)
    d = np.linspace(0.0, 2.0, n)
    dv = np.linspace(-1.0, 1.0, n)
    T, D = np.meshgrid(theta, d)
    eta = controllers.eta_of(D, np.radians(T))
    T2, V2 = np.meshgrid(theta, dv)
    kv = controllers.K_V_of(V2, np.radians(T2))
    return theta, d, dv, np.asarray(eta), np.asarray(kv)


def draw(path: Path, surf, wall, corridor, bracket) -> None:
    import matplotlib.pyplot as plt

    theta, d, dv, eta, kv = surf
    fig, axes = plt.subplots(1, 3, figsize=(16, 5.2), layout="constrained")
    ax = axes[0]
    m = ax.pcolormesh(theta, d, eta, shading="auto", cmap="viridis", vmin=0, vmax=100)
    ax.contour(theta, d, eta, levels=(20, 35, 50, 65, 80), colors="w", linewidths=0.6)
    for w in wall:
        th = 90.0 if w["side"] == "left" else -90.0
        ax.plot(th, w["d0"], "o", mfc="r", mec="w", ms=8)
        ax.annotate(f"{w['side']} wall\nd0 = {w['d0']:.4f} m\neta = {w['eta']:.2f}", (th, w["d0"]), xytext=(th - 75, w["d0"] + 0.35),
                    color="w", fontsize=8.5, arrowprops={"arrowstyle": "->", "color": "w"})
    ax.axhline(RHO0, color="w", ls="--", lw=1)
    ax.text(-175, RHO0 - 0.08, "rho0 = 0.5 m", color="w", fontsize=8)
    ax.set_xlabel("obstacle bearing theta (deg, from the direction of motion)")
    ax.set_ylabel("distance d (m)")
    ax.set_title("controller 1 (Table 1): eta(theta, d)")
    fig.colorbar(m, ax=ax, label="eta")
    ax = axes[1]
    m = ax.pcolormesh(theta, dv, kv, shading="auto", cmap="magma", vmin=0, vmax=100)
    ax.set_xlabel("obstacle bearing theta (deg)")
    ax.set_ylabel("relative speed along the heading, dV (normalised)")
    ax.set_title("controller 2 (Table 2): K_V(theta, dV)")
    fig.colorbar(m, ax=ax, label="K_V")
    ax = axes[2]
    labels = [f"{w['side']} wall" for w in wall] + [f"eta = {e:.2f}\n(frozen)" for e in bracket.eta]
    frozen = [w["N_frozen"] for w in wall] + list(bracket.N)
    total = [w["N_total"] for w in wall] + [math.nan, math.nan]
    x = np.arange(len(labels))
    ax.bar(x - 0.2, frozen, 0.4, color="tab:blue", label="N, eta frozen")
    ax.bar(x + 0.2, total, 0.4, color="tab:red", label="N, total derivative")
    for i, w in enumerate(wall):
        ax.text(i + 0.2, w["N_total"] + 0.3, f"{w['N_total']:.3f}\n(+{100 * (w['total_over_frozen'] - 1):.1f} %)", ha="center", fontsize=8)
        ax.text(i - 0.2, w["N_frozen"] + 0.3, f"{w['N_frozen']:.3f}", ha="center", fontsize=8)
    for i, N in enumerate(bracket.N):
        ax.text(len(wall) + i - 0.2, N + 0.3, f"{N:.3f}", ha="center", fontsize=8)
    ax.set_xticks(x, labels, fontsize=8.5)
    ax.set_ylabel("N (1/m)")
    ax.set_ylim(0, 40)
    ax.set_title(f"wall, rho0 = {RHO0} m, F_a = {ATTRACTION:g}, alpha = {ALPHA_DEG:g} deg:\n"
                 "gain with eta frozen / moving, and the robust bracket", fontsize=10)
    txt = "corridor (F_y = 100): x*, N\n" + "\n".join(f"L = {c['L']:.2f} m: {c['x0_mm']:.2f} mm, {c['N']:.4g} 1/m" for c in corridor)
    ax.text(0.98, 0.98, txt, transform=ax.transAxes, ha="right", va="top", fontsize=8, bbox={"fc": "white", "ec": "0.6"})
    ax.legend(loc="upper left", fontsize=8)
    save_figure(fig, path)


def run(out, quick: bool = False) -> dict:
    from pfm_stability.laws.fuzzy_law import FuzzyScheduledLaw

    out = output_dir(out)
    law = FuzzyScheduledLaw(RHO0, ATTRACTION)
    alpha = math.radians(ALPHA_DEG)
    wall = wall_table(law, alpha)
    corridor = corridor_table(law)
    bracket = law.robust_bracket(alpha)
    kv = law.controllers
    spot = {"K_V(dV=1, 0 deg)": float(kv.K_V_of(1.0, 0.0)), "K_V(dV=-1, 180 deg)": float(kv.K_V_of(-1.0, math.pi)),
            "K_V(dV=0.5, 90 deg)": float(kv.K_V_of(0.5, math.pi / 2))}
    surf = surfaces(law.controllers, 41 if quick else 181)
    draw(out / "dfapf_fuzzy.png", surf, wall, corridor, bracket)
    left, right = wall
    result = {
        "experiment": "DFAPF fuzzy-scheduled repulsion in the KB loop (docs/velocity_and_fuzzy.md)",
        "inputs": {"rho0": RHO0, "attraction": ATTRACTION, "alpha_deg": ALPHA_DEG, "n": 0.0, "corridor_L": list(CORRIDOR_L), "quick": quick},
        "wall": wall,
        "corridor": corridor,
        "robust_bracket": {"eta": list(bracket.eta), "N": list(bracket.N), "d0": list(bracket.d0), "paper_N": [9.147, 23.175]},
        "K_V_spot_values": spot,
        "surface_range": {"eta": [float(surf[3].min()), float(surf[3].max())], "K_V": [float(surf[4].min()), float(surf[4].max())]},
        "rows": [
            row("DFAPF wall", "N frozen / total, c (left PM, right NM)", "- (reconstruction R1-R7)",
                f"left {left['N_frozen']:.3f} / {left['N_total']:.3f}, c {left['c']:.3f}; right {right['N_frozen']:.3f} / {right['N_total']:.5f}, c {right['c']:.3f}",
                "-", f"d0 = {left['d0']:.5f} / {right['d0']:.5f} m; the right wall's moving eta adds {100 * (right['total_over_frozen'] - 1):.0f} % to N; "
                f"CARMEL V* (sampled) = {left['limits_total']['sampled']['V_critical']:.3f} / {right['limits_total']['sampled']['V_critical']:.3f} m/s"),
            row("DFAPF corridor", "x* (mm) / N (1/m) at L = 0.2 / 0.3 / 0.4 / 0.45 m", "-",
                " / ".join(f"{c['x0_mm']:.2f}, {c['N']:.4g}" for c in corridor), "-", "the asymmetric tables shift the equilibrium to the right wall"),
            row("DFAPF bracket", "N with eta frozen at the output's extremes", "-",
                f"[{bracket.N[0]:.3f}, {bracket.N[1]:.3f}] 1/m, eta in [{bracket.eta[0]:.3f}, {bracket.eta[1]:.3f}]", "-",
                "not rigorous: ignores d(eta)/dd and c"),
        ],
        "finding": (
            f"DFAPF wall (rho0 = 0.5 m, F_a = 100, alpha = 60 deg): left N = {left['N_frozen']:.3f} frozen, {left['N_total']:.3f} total; "
            f"right {right['N_frozen']:.3f} frozen, {right['N_total']:.4f} total (+{100 * (right['total_over_frozen'] - 1):.0f} %), "
            f"c = {left['c']:.3f} / {right['c']:.3f}; corridor x* = " + ", ".join(f"{c['x0_mm']:.2f}" for c in corridor)
            + f" mm; bracket N in [{bracket.N[0]:.3f}, {bracket.N[1]:.3f}]."
        ),
    }
    write_json(out / "dfapf_fuzzy.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
