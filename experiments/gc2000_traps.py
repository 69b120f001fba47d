"""Ge & Cui 2000 (GNRON): the trap of Khatib's repulsion near the goal, and the goal-aware repulsion that removes it.

S.S. Ge and Y.J. Cui, "New potential functions for mobile robot path
planning", IEEE T-RA 16(5), 2000 ("GC2000"; docs/traps.md). Reproduced:

1. **Fig 2** (eq 6–7): 1-D, goal at 0, a point obstacle at x = 0.5, ξ = η = 1,
   ρ0 = 2, Khatib's law: the robot is trapped at x = −0.5.
2. **Fig 3 / Fig 4** (eq 8, m = n = 2): a circle of radius 0.5 about (1, 0),
   goal at the origin, ξ = 1, η = 1 (no local minimum; a saddle at (2.5, 0)) and
   η = 25 (a minimum at (−1.08, 0)), by the 2-D search of every stationary
   point (`pfm_stability.analysis.traps`) on the shipped scenes.
3. **Fig 6**: the 1-D case with ξ = η = 1, ρ0 = 2 and n = 0.5, 1, 2, 3: a
   minimum at x ≈ −0.355 for n = 0.5 only.
4. **Sec IV**: k₂ of eq (29) at r = 0.5, ρ0 = 2 (closed form against the
   scanned sup of eq 28), k_n and k′_n of eq (34)/(37) for n = 0.5, 1, 3, 4,
   and the sharpness of k₂ (ξ/η = 0.999 k₂: a minimum–maximum pair on the ray;
   1.001 k₂: none).
5. **Sec VI.B**: goal (8, 8.7), obstacle edge 0.2 below it, ξ = 1, η = 0.1,
   ρ0 = 0.8: Khatib's law traps the robot at y = 9.00; the goal-aware law
   (ξ/η = 10 > k₂(0.2, 0.8)) does not — on the 1-D vertical model and on a
   2-D scene with one wide rectangle (the paper's rectangles are not published).

The 1-D cases (a point obstacle) are not scenes — a circle of radius → 0 is
not a valid obstacle — so they use the distance functions of
`pfm_stability.laws.potentials` directly: `ray_stationary_points` on the ray from
the goal away from the obstacle (ρ = ρ_g + r), and the potential on the whole
line for the plots.

    python experiments/gc2000_traps.py [--out experiments/results] [--quick]

Writes ``gc2000_1d.png`` (Figs 2 and 6, sharpness), ``gc2000_fig3.png``,
``gc2000_fig4.png``, ``gc2000_sec6b_khatib.png``, ``gc2000_sec6b_gnron.png``
and ``gc2000_traps.json``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

SCENES = Path(__file__).resolve().parents[1] / "pfm_stability" / "data" / "scenes"


def line_potential(x, x_obs, xi, eta, rho0, n):
    """U on the 1-D line of GC2000 Fig 1: goal at 0, point obstacle at x_obs > 0, robot at x < x_obs (eq 6–8)."""
    from pfm_stability.laws.potentials import attraction_potential, gnron_potential

    x = np.asarray(x, dtype=float)
    return attraction_potential(np.abs(x), xi, 2) + gnron_potential(x_obs - x, np.abs(x), eta, rho0, n)


def one_d(x_obs, xi, eta, rho0, n):
    """Stationary points of the 1-D model on both sides of the goal, as x (m) and kind."""
    from pfm_stability.laws.potentials import ray_stationary_points

    behind = [{"x": -rg, "kind": kind} for rg, kind in ray_stationary_points(x_obs, xi, eta, rho0, n)]
    x = np.linspace(1e-6, x_obs - 1e-6, 20001)  # between goal and obstacle (GC2000 Sec IV: none there)
    du = np.gradient(line_potential(x, x_obs, xi, eta, rho0, n), x)
    between = [{"x": float(x[i]), "kind": "sign change"} for i in np.flatnonzero(np.sign(du[:-1]) != np.sign(du[1:]))]
    return sorted(behind, key=lambda p: p["x"]) + between


def _scene(name, resolution):
    from pfm_stability.laws.scene import Scene
    from pfm_stability.analysis.traps import find_stationary_points

    return find_stationary_points(Scene.load(SCENES / f"{name}.yaml"), resolution)


def _points(analysis):
    return [p.to_dict() for p in analysis.stationary_points]


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.plots.traps import plot_traps
    from pfm_stability.laws.potentials import bound_integrand, k2_closed_form, k_conservative, k_exact, ray_force, ray_stationary_points, rho_m

    out = output_dir(out)
    resolution = 41 if quick else 121
    result = {"experiment": "Ge & Cui 2000: GNRON traps and the bounds on xi/eta", "inputs": {"quick": quick, "resolution": resolution}}

    # Fig 2 and Fig 6: 1-D
    fig2 = one_d(0.5, 1.0, 1.0, 2.0, 0.0)
    fig6 = {n: one_d(0.5, 1.0, 1.0, 2.0, n) for n in (0.5, 1.0, 2.0, 3.0)}
    result["fig2"] = {"setup": "1-D, goal 0, point obstacle at 0.5, xi = eta = 1, rho0 = 2, n = 0", "paper": "trapped at x = -0.5",
                      "stationary_points": fig2, "U_min": float(line_potential(-0.5, 0.5, 1, 1, 2, 0)),
                      "U_goal": float(line_potential(0.0, 0.5, 1, 1, 2, 0))}
    result["fig6"] = {"setup": "1-D, goal 0, point obstacle at 0.5, xi = eta = 1, rho0 = 2, m = 2",
                      "paper": "local minimum at x = -0.355 for n = 0.5", "stationary_points": {str(n): v for n, v in fig6.items()}}

    # Sec IV: the bounds
    k2 = k2_closed_form(0.5, 2.0)
    s = np.sqrt(1 + 3 * 2.0 / 0.5)
    bounds = {str(n): {"rho_m": rho_m(0.5, 2.0, n), "k_exact": k_exact(0.5, 2.0, n), "k_conservative": k_conservative(0.5, 2.0, n)}
              for n in (0.5, 1.0, 2.0, 3.0, 4.0)}
    sharp = {f"{c:g} k2": ray_stationary_points(0.5, c * k2, 1.0, 2.0, 2.0) for c in (0.999, 1.001)}
    rho = np.linspace(rho_m(0.5, 2.0, 2.0), 2.0, 200001)[1:-1]  # eq (28) by brute force, against the closed form (29)
    result["sec4"] = {"k2_eq29": k2, "k2_scanned_sup": float(np.max(bound_integrand(rho, 0.5, 2.0, 2.0))), "rho_star": 3 * 2.0 / (1 + s),
                      "eta_star": 1 / k2, "bounds_r0.5_rho0_2": bounds,
                      "sharpness": {key: [{"rho_g": rg, "kind": kind} for rg, kind in v] for key, v in sharp.items()}}

    # Figs 3, 4 and Sec VI.B: 2-D scenes
    fig3, fig4 = _scene("gc2000_fig3", resolution), _scene("gc2000_fig4", resolution)
    sec6 = {law: _scene(f"gc2000_sec6b_{law}", resolution) for law in ("khatib", "gnron")}
    result["fig3"] = {"paper": "no local minimum", "conclusion": fig3.conclusion, "stationary_points": _points(fig3),
                      "bounds": [b.to_dict() for b in fig3.gnron_bounds]}
    result["fig4"] = {"paper": "local minimum at (-1.08, 0)", "conclusion": fig4.conclusion, "stationary_points": _points(fig4),
                      "bounds": [b.to_dict() for b in fig4.gnron_bounds]}
    vertical = {"khatib": ray_stationary_points(0.2, 1.0, 0.1, 0.8, 0.0), "gnron": ray_stationary_points(0.2, 1.0, 0.1, 0.8, 2.0)}
    result["sec6b"] = {
        "paper": "conventional: trapped at (8.04, 9.00); new method reaches the goal",
        "vertical_model": {law: [{"y": 8.7 + rg, "kind": kind} for rg, kind in v] for law, v in vertical.items()},
        "k2_r0.2_rho0_0.8": k2_closed_form(0.2, 0.8),
        "scenes": {law: {"conclusion": a.conclusion, "stationary_points": _points(a)} for law, a in sec6.items()},
    }

    trap4 = fig4.traps[0]
    saddle4 = next(p for p in fig4.stationary_points if p.kind == "saddle" and p.x < 0)
    fig6_min = next(p["x"] for p in fig6[0.5] if p["kind"] == "minimum")
    fig6_max = next(p["x"] for p in fig6[0.5] if p["kind"] == "maximum")
    trap6 = sec6["khatib"].traps[0]
    result["finding"] = (
        f"Fig 2: trap at x = {fig2[0]['x']:.7f}; Fig 3: {fig3.conclusion}; Fig 4: {fig4.conclusion} "
        f"(eigenvalues {trap4.hessian_eigenvalues[0]:.4f}, {trap4.hessian_eigenvalues[1]:.4f}); Fig 6 n = 0.5: minimum at "
        f"{fig6_min:.6f}; k2(0.5, 2) = {k2:.10f}; Sec VI.B: Khatib trap at y = {trap6.y:.4f}, goal-aware: {sec6['gnron'].conclusion}."
    )

    # figures
    fig, axes = plt.subplots(1, 3, figsize=(15.0, 4.6), layout="constrained")
    x = np.linspace(-2.0, 0.49, 2000)
    ax = axes[0]
    ax.plot(x, line_potential(x, 0.5, 1, 1, 2, 0), color="k", label="U_total (Khatib, n = 0)")
    ax.plot(fig2[0]["x"], line_potential(fig2[0]["x"], 0.5, 1, 1, 2, 0), "o", color="#d62728", label=f"trap x = {fig2[0]['x']:.4f}")
    ax.axvline(0, color="gold", lw=1.5, label="goal")
    ax.set(title="GC2000 Fig 2: Khatib's repulsion traps the robot\nbefore the goal (point obstacle at x = 0.5)", xlabel="x (m)",
           ylabel="U", ylim=(0, 4))
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[1]
    for n, color in zip((0.5, 1.0, 2.0, 3.0), ("#d62728", "#ff7f0e", "#2ca02c", "#1f77b4")):
        ax.plot(x, line_potential(x, 0.5, 1, 1, 2, n), color=color, label=f"n = {n:g}")
        for p in fig6[n]:
            ax.plot(p["x"], line_potential(p["x"], 0.5, 1, 1, 2, n), "o" if p["kind"] == "minimum" else "^", color=color, mec="k")
    ax.annotate(f"minimum {fig6_min:.4f}\n(paper -0.355)", (fig6_min, line_potential(fig6_min, 0.5, 1, 1, 2, 0.5)), xytext=(-1.9, 0.9),
                fontsize=8, arrowprops=dict(arrowstyle="->"))
    ax.annotate(f"maximum {fig6_max:.4f}", (fig6_max, line_potential(fig6_max, 0.5, 1, 1, 2, 0.5)), xytext=(-0.9, 0.55), fontsize=8,
                arrowprops=dict(arrowstyle="->"))
    ax.set(title="GC2000 Fig 6: goal-aware repulsion, xi = eta = 1,\nrho0 = 2 (o minimum, ^ maximum)", xlabel="x (m)", ylabel="U",
           ylim=(0, 1.2))
    ax.legend(fontsize=8, loc="upper right")
    ax = axes[2]
    rg = np.linspace(0.72, 0.88, 2000)
    for c, color in ((0.999, "#d62728"), (1.0, "k"), (1.001, "#1f77b4")):
        ax.plot(rg, ray_force(rg, 0.5, c * k2, 1.0, 2.0, 2.0), color=color, label=f"xi/eta = {c:g} k2")
    for r_g, kind in sharp["0.999 k2"]:
        ax.plot(r_g, 0.0, "o" if kind == "minimum" else "^", color="#d62728", mec="k")
    ax.axhline(0, color="0.5", lw=0.8)
    ax.set(title=f"Sec IV: k2(0.5, 2) = {k2:.6f} (eq 29) is sharp:\ndU/drho_g on the ray (> 0: pulled to the goal)",
           xlabel="rho_g (m)", ylabel="dU/drho_g", ylim=(-1e-4, 4e-4))
    ax.legend(fontsize=8, loc="upper center")
    save_figure(fig, out / "gc2000_1d.png")
    save_figure(plot_traps(fig3, title=f"GC2000 Fig 3 (scene gc2000_fig3)\n{fig3.conclusion}"), out / "gc2000_fig3.png")
    save_figure(plot_traps(fig4, title=f"GC2000 Fig 4 (scene gc2000_fig4, eta = 25)\n{fig4.conclusion}"), out / "gc2000_fig4.png")
    for law in ("khatib", "gnron"):
        title = f"GC2000 Sec VI.B (scene gc2000_sec6b_{law})\n{sec6[law].scene.law.describe()}\n{sec6[law].conclusion}"
        save_figure(plot_traps(sec6[law], title=title), out / f"gc2000_sec6b_{law}.png")

    b = bounds
    result["rows"] = [
        row("GC2000 Fig 2", "1-D trap, Khatib's law (x)", "-0.5", f"{fig2[0]['x']:.7f} (ray model)", "-", "U_min = 0.25 < U(goal) = 1.125"),
        row("GC2000 Fig 3", "stationary points, xi = eta = 1", "no local minimum", "-", fig3.conclusion,
            "saddle at (" + ", ".join(f"{p.x:.6g}, {p.y:.6g}" for p in fig3.stationary_points if p.kind == "saddle") + ")"),
        row("GC2000 Fig 4", "local minimum, eta = 25", "(-1.08, 0)", "-",
            f"({trap4.x:.6f}, {trap4.y:.6g}), eigenvalues ({trap4.hessian_eigenvalues[0]:.4f}, {trap4.hessian_eigenvalues[1]:.4f})",
            f"saddle at ({saddle4.x:.6f}, {saddle4.y:.6g})"),
        row("GC2000 Fig 6", "1-D minimum / maximum, n = 0.5", "-0.355 / -", f"{fig6_min:.6f} / {fig6_max:.6f}", "-",
            "n = 1, 2, 3: " + ("none" if not any(fig6[n] for n in (1.0, 2.0, 3.0)) else "some")),
        row("GC2000 eq (29)", "k2(r = 0.5, rho0 = 2)", "formula", f"{k2:.10f} at rho* = {3 * 2.0 / (1 + s):.5f}",
            f"{result['sec4']['k2_scanned_sup']:.10f} (scanned sup of eq 28)", "eta* = 1/k2 = " + f"{1 / k2:.4f}"),
        row("GC2000 eq (34)/(37)", "rho_m, k_n, k'_n at r = 0.5, rho0 = 2", "formulas",
            "; ".join(f"n = {n}: {b[n]['rho_m']:.6f}, {b[n]['k_exact']:.6g}, {b[n]['k_conservative']:.6g}" for n in ("0.5", "1.0", "3.0", "4.0")),
            "-", "k'_n >= k_n"),
        row("GC2000 Sec IV", "sharpness of k2", "accurate lower bound",
            f"0.999 k2: {' + '.join(k for _, k in sharp['0.999 k2'])} at rho_g = "
            + ", ".join(f"{r:.3f}" for r, _ in sharp["0.999 k2"]) + f"; 1.001 k2: {'none' if not sharp['1.001 k2'] else 'some'}", "-", ""),
        row("GC2000 Sec VI.B", "conventional trap (y)", "(8.04, 9.00)", f"y = {8.7 + vertical['khatib'][0][0]:.4f} (vertical model)",
            f"({trap6.x:.4g}, {trap6.y:.4f}) (2-D scene)", "x = 8.04 needs the unpublished rectangle corner"),
        row("GC2000 Sec VI.B", "goal-aware law, xi/eta = 10", "reaches the goal", f"k2(0.2, 0.8) = {k2_closed_form(0.2, 0.8):.6f} < 10; "
            f"ray: {'no stationary point' if not vertical['gnron'] else 'stationary points'}", sec6["gnron"].conclusion, ""),
    ]
    write_json(out / "gc2000_traps.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    sys.exit(main())
