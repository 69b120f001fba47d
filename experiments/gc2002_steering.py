"""Ge & Cui 2002's velocity attraction on a steering robot: a heading gain c, not damping.

On KB's steering robot (S.S. Ge and Y.J. Cui, "Dynamic motion planning for
mobile robots using potential field method", Autonomous Robots 13, 2002,
"GC2002", §7 and eq 1, 7–9) the velocity part of the attraction,
−2α_v·v, lowers the forward force and turns with the heading: with
q = 2α_vV/(F_a sin α), N = N_KB/(1 − q) and c = q/(1 − q) in the loop
τs³ + s² + ks + k(cs + NV)e^(−sT) = 0 (docs/velocity_and_fuzzy.md,
docs/models.md "Robot loop families"):

1. **Critical N_KB·V against q** (CARMEL τ = 0.3 s, k = 2 1/s, T = 0.065 s,
   exact delay) and NV* against c; the continuous boundary τN_KB·V = 1 is
   the same for every q.
2. **Kinematic steering** (GC2002 §7, τ = 0, K_s = 2, NV = 2): the delay margin T*.
3. **Simulation** (`pfm_stability.sim.planar`: the steering robot, command hold,
   one-sample compute delay, in a Khatib corridor, L = 0.5 m, η = 0.03125,
   ρ0 = 2 m, so N_KB·V = 2.0): growth rate σ of the lateral offset at q = 0
   and q = 0.5 against the `sampled` model's rightmost root.

    python experiments/gc2002_steering.py [--out experiments/results] [--quick]

Writes ``gc2002_steering.png`` and ``gc2002_steering.json``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

TAU, K, T, V = 0.3, 2.0, 0.065, 0.8
Q_TABLE = (0.0, 0.1, 0.2, 0.5)
C_TABLE = (0.0, 0.1, 0.25, 0.5, 1.0)
PAPER_NKBV = (2.76787, 2.73476, 2.69319, 2.46532)
PAPER_NV = (2.76787, 3.01188, 3.36649, 3.92682, 4.93063)
PAPER_KINEMATIC = (0.575307, 1.57230)
SIM_ETA, SIM_RHO0, SIM_L, SIM_RHO_G = 0.03125, 2.0, 0.5, 1.0e4
SIM_Q = (0.0, 0.5)


def steering_table() -> dict:
    from pfm_stability.models import make_model
    from pfm_stability.models.loop import Loop

    ex = make_model("exact_delay")
    by_q = []
    for q in Q_TABLE:
        c = q / (1 - q)
        b = ex.boundary(Loop(TAU, T, K, c=c))
        by_q.append({"q": q, "c": c, "NV_critical": b.NV_critical, "N_KB_V_critical": b.NV_critical * (1 - q), "omega": b.omega_critical})
    by_c = [{"c": c, "NV_critical": ex.boundary(Loop(TAU, T, K, c=c)).NV_critical} for c in C_TABLE]
    return {"by_q": by_q, "by_c": by_c}


def kinematic() -> dict:
    from pfm_stability.models import make_model
    from pfm_stability.models.holonomic import kinematic_loop

    ex = make_model("exact_delay")
    tstar = ex.critical_delay(2.0, kinematic_loop(2.0, 0.1))
    b = ex.boundary(kinematic_loop(2.0, tstar * (1 - 1e-9)))
    return {"K_s": 2.0, "NV": 2.0, "T_star": tstar, "omega": b.omega_critical}


def curve(n: int) -> dict:
    """N_KB·V* against q for the exact-delay and sampled (command hold, 1-sample delay) models."""
    from pfm_stability.models import make_model
    from pfm_stability.models.loop import Loop

    ex, sa = make_model("exact_delay"), make_model("sampled", hold="command", compute_delay=1)
    q = np.linspace(0.0, 0.8, n)
    out = {"q": q.tolist(), "exact_delay": [], "sampled": []}
    for qi in q:
        loop = Loop(TAU, T, K, c=qi / (1 - qi))
        out["exact_delay"].append(ex.boundary(loop).NV_critical * (1 - qi))
        out["sampled"].append(sa.boundary(loop).NV_critical * (1 - qi))
    return out


def corridor_member(q: float, duration: float):
    """The steering robot (CARMEL, command hold, 1-sample delay) in the Khatib corridor with velocity attraction q:
    (robot, its `PlanarMember`)."""
    from pfm_stability.laws.fields import KhatibLaw
    from pfm_stability.sim.movers import Target, Wall
    from pfm_stability.sim.planar import Field, PlanarMember, Start, Steering, World
    from pfm_stability.laws.velocity_laws import VelocityAttraction

    F_a = 1.0
    attraction = VelocityAttraction(F_a / (2 * SIM_RHO_G), q * F_a / (2 * V))  # F_a = 2α_pρ_g, q = 2α_vV/F_a
    law = KhatibLaw(1.0, SIM_ETA, SIM_RHO0, 2.0, 1.0)  # η(1/d − 1/ρ0)/d² in units of F_a
    world = World(Target((0.0, SIM_RHO_G)), (Wall((-SIM_L, 0.0), (1.0, 0.0)), Wall((SIM_L, 0.0), (-1.0, 0.0))))
    robot = Steering(V, TAU, K, hold="command")
    return robot, PlanarMember(robot, Field(attraction, law, repulsion_scale=F_a), world, Start((0.01, 0.0), heading=math.pi / 2),
                               T=T, duration=duration, compute_delay=1)


def simulated(quick: bool) -> list:
    from pfm_stability.laws.fields import KhatibLaw
    from pfm_stability.laws.force_law import corridor_gain
    from pfm_stability.models import make_model
    from pfm_stability.models.loop import Loop
    from pfm_stability.sim.cycles import lateral_metrics
    from pfm_stability.sim.planar import simulate_planar_batch

    N_kb = corridor_gain(KhatibLaw(1.0, SIM_ETA, SIM_RHO0, 2.0, 1.0), SIM_L) + 1.0 / SIM_RHO_G  # the finite goal adds 1/ρ_g
    sa = make_model("sampled", hold="command", compute_delay=1)
    out = []
    cases = [corridor_member(q, 12.0 if quick else 16.0) for q in SIM_Q]
    runs = simulate_planar_batch([member for _, member in cases]).runs  # every q in one batch
    for q, (robot, _), run in zip(SIM_Q, cases, runs):
        c = q / (1 - q)
        loop = Loop(TAU, T, K, c=c)
        root = sa.rightmost_root(N_kb / (1 - q) * V, loop)
        m = lateral_metrics(run, (1.0, 0.0), robot=robot)
        out.append({"q": q, "c": c, "N_KB_V": N_kb * V, "NV": N_kb / (1 - q) * V,
                    "NV_critical_sampled": sa.boundary(loop).NV_critical,
                    "predicted_sigma": root.real, "predicted_omega": abs(root.imag),
                    "simulated_sigma": m.growth_rate, "simulated_omega": m.angular_frequency, "method": m.method,
                    "collided": run.collision, "t": run.t.tolist()[:: 2], "x": run.p[::2, 0].tolist()})
    return out


def draw(path: Path, table: dict, curves: dict, sims: list) -> None:
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(14, 5.4), layout="constrained")
    a1.plot(curves["q"], curves["exact_delay"], color="tab:blue", lw=2, label="exact delay T = 65 ms")
    a1.plot(curves["q"], curves["sampled"], color="tab:red", lw=2, label="sampled: command hold + 1-sample delay")
    a1.axhline(1 / TAU, color="0.3", ls=":", label="continuous (T = 0): tau N_KB V = 1, every q")
    for r in table["by_q"]:
        a1.plot(r["q"], r["N_KB_V_critical"], "o", color="tab:blue", mec="k")
        a1.annotate(f"{r['N_KB_V_critical']:.5f}", (r["q"], r["N_KB_V_critical"]), xytext=(4, 6), textcoords="offset points", fontsize=8)
    if sims:
        a1.axhline(sims[0]["N_KB_V"], color="tab:green", ls="--", lw=1, label=f"simulated corridor: N_KB V = {sims[0]['N_KB_V']:.3f}")
    a1.set_xlabel("q = 2 alpha_v V / (F_a sin alpha)   (c = q/(1 - q))")
    a1.set_ylabel("critical N_KB V (1/s)")
    a1.set_ylim(0, 3.6)
    a1.set_title("CARMEL (tau = 0.3 s, k = 2, T = 65 ms): the velocity attraction\nis a heading gain c; with a delay it lowers the boundary", fontsize=10)
    a1.legend(fontsize=8.5, loc="lower left")
    a1.grid(alpha=0.3)
    for s, color in zip(sims, ("tab:blue", "tab:red")):
        a2.plot(s["t"], 100 * np.asarray(s["x"]), color=color, lw=1.4,
                label=f"q = {s['q']:g} (c = {s['c']:g}, NV = {s['NV']:.2f}): sigma sim {s['simulated_sigma']:+.3f}, "
                f"model {s['predicted_sigma']:+.3f} 1/s")
        t, x = np.asarray(s["t"]), 100 * np.abs(np.asarray(s["x"]))
        early = (t >= 2.0) & (t <= 5.0)
        i = np.flatnonzero(early)[np.argmax(x[early])]  # anchor the envelope on the first full swing
        envelope = x[i] * np.exp(s["predicted_sigma"] * (t - t[i]))
        a2.plot(t, envelope, color=color, ls=":", lw=1)
        a2.plot(t, -envelope, color=color, ls=":", lw=1)
    a2.set_ylim(-8, 8)
    a2.set_xlabel("t (s)")
    a2.set_ylabel("lateral offset x (cm)")
    a2.set_title("planar simulation, Khatib corridor L = 0.5 m (N_KB V = 2.0): stable at q = 0,\n"
                 "oscillating at q = 0.5 (dotted: envelope exp(sigma t) of the sampled model)", fontsize=10)
    a2.legend(fontsize=8, loc="upper left")
    a2.grid(alpha=0.3)
    save_figure(fig, path)


def run(out, quick: bool = False) -> dict:
    out = output_dir(out)
    table = steering_table()
    kin = kinematic()
    curves = curve(17 if quick else 81)
    sims = simulated(quick)
    draw(out / "gc2002_steering.png", table, curves, sims)
    for r, p in zip(table["by_q"], PAPER_NKBV):
        r["paper"] = p
    for r, p in zip(table["by_c"], PAPER_NV):
        r["paper"] = p
    kin["paper"] = {"T_star": PAPER_KINEMATIC[0], "omega": PAPER_KINEMATIC[1]}
    rows = [
        row("GC2002 steering", "critical N_KB V at q = 0 / 0.1 / 0.2 / 0.5 (exact delay, CARMEL)", "- (analysis of eq 7-9 in KB's loop)",
            " / ".join(f"{r['N_KB_V_critical']:.5f}" for r in table["by_q"]), "-",
            "NV* = " + ", ".join(f"{r['NV_critical']:.5f}" for r in table["by_c"]) + " for c = 0, 0.1, 0.25, 0.5, 1"),
        row("GC2002 §7 kinematic", "T* (K_s = 2, NV = 2, c = 0)", "-", f"{kin['T_star']:.6f} s (omega = {kin['omega']:.5f})", "-", ""),
    ]
    if sims:
        rows.append(row("GC2002 steering, corridor", "sigma (1/s) at q = 0 / 0.5, N_KB V = 2.0, sampled (held command, 1-sample delay)", "-",
                        " / ".join(f"{s['predicted_sigma']:+.3f}" for s in sims),
                        " / ".join(f"{s['simulated_sigma']:+.3f}" for s in sims), "q = 0.5 turns a stable corridor unstable"))
    result = {
        "experiment": "GC2002 velocity attraction on KB's steering robot: heading gain c (docs/velocity_and_fuzzy.md)",
        "inputs": {"tau": TAU, "k": K, "T": T, "V": V, "sim": {"eta": SIM_ETA, "rho0": SIM_RHO0, "L": SIM_L, "rho_g": SIM_RHO_G,
                                                                 "hold": "command", "compute_delay": 1}, "quick": quick},
        "table": table, "kinematic": kin, "curve": curves, "simulated": sims, "rows": rows,
        "finding": ("Critical N_KB V (exact delay) = " + ", ".join(f"{r['N_KB_V_critical']:.5f}" for r in table["by_q"])
                    + f" for q = 0, 0.1, 0.2, 0.5; kinematic T* = {kin['T_star']:.6f} s; corridor sigma "
                    + ", ".join(f"q = {s['q']:g}: sim {s['simulated_sigma']:+.3f} vs model {s['predicted_sigma']:+.3f}" for s in sims) + "."),
    }
    write_json(out / "gc2002_steering.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
