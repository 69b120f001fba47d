"""Ge & Cui 2000's goal-aware repulsion in the KB loop: corridor and wall gains against the distance to the goal.

S.S. Ge and Y.J. Cui, "New potential functions for mobile robot path
planning", IEEE T-RA 16(5), 2000 ("GC2000"), put in Koren & Borenstein's
loop (docs/fields.md), the goal direction frozen as KB's α:

1. **Corridor** (L = 0.4 m, Sec VI gains ξ = 1, η = 0.1, ρ0 = 0.8 m,
   m = n = 2): N of Khatib's law (eq 3–4) and of the goal-aware law (eq 8–11)
   against ρ_g, τNV at CARMEL's τ = 0.3 s, V = 0.8 m/s, the crossover
   ρ_g* = √(1 + 2ηc(L)²/ξ) where the two are equal, and N + 1/ρ_g, the gain
   with a finite goal straight ahead (not in the report's N).
2. **Wall** (same gains, ρ_g = 2 and 5 m, α = 30°, 60°, 80°): the equilibrium
   d0 and N of both laws.
3. **Three equilibria** (n = 0.5, ξ = η = 1, ρ0 = 0.8 m, ρ_g = 0.02 m,
   α = 60°): d0, N and the `sampled` model's verdict at each (CARMEL).

    python experiments/gc2000_corridor.py [--out experiments/results] [--quick]

Writes ``gc2000_corridor.png`` (N against ρ_g, both laws, the crossover and
the stability limits marked) and ``gc2000_corridor.json``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

L = 0.4
SEC6 = (1.0, 0.1, 0.8, 2.0)  # ξ, η, ρ0, m (GC2000 Sec VI)
TABLE_RHO_G = (0.5, 1.0, 2.0, 5.0, 10.0)


def laws(rho_g):
    from pfm_stability.laws.fields import GnronLaw, KhatibLaw

    xi, eta, rho0, m = SEC6
    return KhatibLaw(xi, eta, rho0, m, rho_g), GnronLaw(xi, eta, rho0, m, 2.0, rho_g)


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.analysis.criteria import analyze_wall, loop_of
    from pfm_stability.laws.fields import GnronLaw, finite_goal_gain
    from pfm_stability.laws.force_law import corridor_gain, wall_equilibria
    from pfm_stability.models import Sampled
    from pfm_stability.parameters import CARMEL, Wall

    out = output_dir(out)
    robot, controller = CARMEL.robot, CARMEL.controller
    tau_V = robot.tau * robot.V
    xi, eta, rho0, _ = SEC6
    c = 1 / L - 1 / rho0
    crossover = math.sqrt(1 + 2 * eta * c**2 / xi)
    NV_sampled = Sampled(controller.hold, controller.compute_delay).boundary(loop_of(robot, controller)).NV_critical

    corridor = []
    for rho_g in sorted(TABLE_RHO_G + (crossover,)):
        k, g = laws(rho_g)
        Nk, Ng = corridor_gain(k, L), corridor_gain(g, L)
        corridor.append({"rho_g": rho_g, "N_khatib": Nk, "N_goal_aware": Ng, "tau_NV_khatib": tau_V * Nk, "tau_NV_goal_aware": tau_V * Ng,
                         "N_finite_goal_khatib": finite_goal_gain(k, Nk), "N_finite_goal_goal_aware": finite_goal_gain(g, Ng)})
    wall = []
    for rho_g in (2.0, 5.0):
        for alpha_deg in (30.0, 60.0, 80.0):
            k, g = laws(rho_g)
            (ek,), (eg,) = wall_equilibria(k, math.radians(alpha_deg)), wall_equilibria(g, math.radians(alpha_deg))
            wall.append({"rho_g": rho_g, "alpha_deg": alpha_deg, "d0_khatib": ek.d0, "N_khatib": ek.N, "d0_goal_aware": eg.d0, "N_goal_aware": eg.N})
    three_law = GnronLaw(1.0, 1.0, 0.8, 2.0, 0.5, 0.02)
    analysis = analyze_wall(robot, controller, Wall.from_degrees(60.0), models=("sampled",), law=three_law)
    three = [{"d0": e.d0, "N": e.N, "c": e.c, "sampled": e.models["sampled"].verdict, "reason": e.models["sampled"].reason}
             for e in analysis.equilibria]

    rho = np.geomspace(0.2, 20.0, 60 if quick else 400)
    Nk = np.array([corridor_gain(laws(r)[0], L) for r in rho])
    Ng = np.array([corridor_gain(laws(r)[1], L) for r in rho])
    N_cross = corridor_gain(laws(crossover)[0], L)

    fig, ax = plt.subplots(figsize=(7.6, 5.4), layout="constrained")
    ax.loglog(rho, Nk, color="tab:blue", lw=2, label="Khatib (GC2000 eq 3-4)")
    ax.loglog(rho, Ng, color="tab:red", lw=2, label="goal-aware, n = 2 (eq 8-11)")
    ax.loglog(rho, Nk + 1 / rho, color="tab:blue", lw=1, ls="--", label="Khatib + 1/rho_g (finite goal ahead)")
    ax.loglog(rho, Ng + 1 / rho, color="tab:red", lw=1, ls="--", label="goal-aware + 1/rho_g (finite goal ahead)")
    ax.axhline(1 / tau_V, color="0.3", lw=1.2, ls=":", label="stability limit, continuous model: NV = 1/tau")
    ax.axhline(NV_sampled / robot.V, color="0.3", lw=1.2, ls="-.", label=f"stability limit, sampled model (CARMEL): NV* = {NV_sampled:.3g} 1/s")
    ax.plot([crossover], [N_cross], "ko", ms=7, zorder=5)
    ax.annotate(f"crossover rho_g* = {crossover:.4f} m\nN = {N_cross:.4g} 1/m (both laws)", (crossover, N_cross), xytext=(0.23, 0.75),
                arrowprops={"arrowstyle": "->"}, fontsize=10, bbox={"boxstyle": "round", "fc": "white", "ec": "0.6"})
    for r in TABLE_RHO_G:
        ax.plot([r, r], [corridor_gain(laws(r)[0], L), corridor_gain(laws(r)[1], L)], "k.", ms=4)
    ax.set_xlabel("distance to the goal rho_g (m), frozen")
    ax.set_ylabel("corridor gain N (1/m), L = 0.4 m")
    ax.set_title("GC2000 Sec VI gains (xi = 1, eta = 0.1, rho0 = 0.8 m, m = n = 2) in the KB loop:\n"
                 "corridor gain N against the goal distance; unstable above a limit at V = 0.8 m/s", fontsize=11)
    ax.set_ylim(0.5, 1500)
    secondary = ax.secondary_yaxis("right", functions=(lambda N: tau_V * N, lambda t: t / tau_V))
    secondary.set_ylabel("tau N V  (tau = 0.3 s, V = 0.8 m/s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper center", fontsize=8.5, framealpha=0.95)
    save_figure(fig, out / "gc2000_corridor.png")

    at = {r["rho_g"]: r for r in corridor}
    result = {
        "experiment": "Ge & Cui 2000 goal-aware repulsion in the KB loop: corridor and wall gains (docs/fields.md)",
        "inputs": {"L": L, "xi": xi, "eta": eta, "rho0": rho0, "m": 2.0, "n": 2.0, "tau": robot.tau, "V": robot.V, "quick": quick},
        "corridor": corridor,
        "crossover": {"rho_g": crossover, "N": N_cross, "formula": "sqrt(1 + 2 eta c(L)^2 / xi), c = 1/L - 1/rho0"},
        "wall": wall,
        "three_equilibria": {"law": three_law.parameters(), "alpha_deg": 60.0, "equilibria": three},
        "NV_critical_sampled": NV_sampled,
        "rows": [
            row("GC2000 corridor", "N (1/m) at rho_g = 0.5 / 2 / 10 m, Khatib vs goal-aware", "-",
                " / ".join(f"{at[r]['N_khatib']:.4g} vs {at[r]['N_goal_aware']:.4g}" for r in (0.5, 2.0, 10.0)), "-",
                f"crossover rho_g* = {crossover:.4f} m; goal-aware N grows like rho_g^n far from the goal"),
            row("GC2000 wall", "three equilibria, n = 0.5, rho_g = 0.02 m, alpha = 60 deg", "-",
                "; ".join(f"d0 = {e['d0']:.5f} m, N = {e['N']:+.5g}: {e['sampled']}" for e in three), "-",
                "the middle one has N < 0: unstable in every model"),
        ],
        "finding": (
            f"Corridor L = 0.4 m: Khatib's N falls as 1/rho_g (31.25 to 1.5625 1/m from rho_g = 0.5 to 10 m), the goal-aware "
            f"N grows (5.952 to 119.05 1/m); they cross at rho_g* = {crossover:.4f} m. Wall, n = 0.5, rho_g = 0.02 m, "
            f"alpha = 60 deg: three equilibria, d0 = " + ", ".join(f"{e['d0']:.5f}" for e in three) + " m, N = "
            + ", ".join(f"{e['N']:+.5g}" for e in three) + " 1/m; the middle one (N < 0) is unstable in every model."
        ),
    }
    write_json(out / "gc2000_corridor.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
