"""Ge & Cui 2002's velocity attraction on a holonomic robot: delay margins T* of the corridor loop.

S.S. Ge and Y.J. Cui, "Dynamic motion planning for mobile robots using
potential field method", Autonomous Robots 13, 2002 ("GC2002"), drive a
point mass by force = acceleration (§6; its conference form §V). Beside an
obstacle the lateral motion is s² + (c_h s + κ)e^(−sT) = 0 with
c_h = 2α_v/m the damping of the velocity attraction and κ the field's
stiffness (docs/models.md, "Robot loop families"; docs/velocity_and_fuzzy.md):

1. **T* table**, three cases and three models (pure delay, zero-order hold,
   ZOH + one-sample compute delay): the tracking gains (α_p = 0.005,
   α_v = 0.1), the conference's (α_p = 0.0008, α_v = 0.04), and a Khatib
   corridor (η = 0.3, ρ0 = 2 m, L = 0.5 m: κ = 24 s⁻²) with α_v = 0.1.
2. **At the conference's T = 0.1 s** the corridor loop's rightmost roots
   (α_v = 0: undamped, and 0.1) and the α_v window of the ZOH loop.
3. **T* against α_v** for the three models (the figure); with the planar
   simulator (`pfm_stability.sim.planar`: point mass between the corridor's walls)
   the growth rate σ of runs at a few points beside the sampled models' rightmost roots.

    python experiments/gc2002_holonomic_corridor.py [--out experiments/results] [--quick]

Writes ``gc2002_holonomic_corridor.png`` and ``gc2002_holonomic_corridor.json``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

ETA, RHO0, L_HALF, RHO_G = 0.3, 2.0, 0.5, 3.0
T_CONF = 0.1
MODELS = (("exact_delay", "pure delay", {}), ("sampled_zoh", "ZOH", {"compute_delay": 0}), ("sampled_zoh_delay", "ZOH + 1-sample delay", {"compute_delay": 1}))
PAPER_TSTAR = {
    "tracking": (6.474, 10.0, 4.26),
    "conference tracking": (16.19, 25.0, 10.65),
    "Khatib corridor": (8.33e-3, 16.7e-3, 5.55e-3),
}


def models() -> dict:
    from pfm_stability.models import make_model

    return {key: make_model("exact_delay" if key == "exact_delay" else "sampled", **opts) for key, _, opts in MODELS}


def corridor_kappa(alpha_v: float) -> tuple:
    """(κ, c_h) of the Khatib corridor (η = 0.3, ρ0 = 2 m, L = 0.5 m) at its centre, m_rob = 1."""
    from pfm_stability.laws.fields import KhatibLaw
    from pfm_stability.laws.velocity_laws import VelocityAttraction

    att = VelocityAttraction(0.005, alpha_v)
    Fa = att.position_force(RHO_G)
    law = KhatibLaw(Fa / RHO_G, ETA, RHO0, 2.0, RHO_G)  # in units of F_a (ξ = F_a/ρ_g for m = 2)
    (mid,) = [g for g in att.holonomic_corridor_gains(law, L_HALF, RHO_G) if g.x0 == 0.0]
    return mid.kappa, mid.c_h


def tstar_table(ms: dict) -> list:
    from pfm_stability.models.holonomic import HolonomicLoop
    from pfm_stability.laws.velocity_laws import VelocityAttraction

    cases = []
    for name, alpha_p, alpha_v in (("tracking", 0.005, 0.1), ("conference tracking", 0.0008, 0.04)):
        a = VelocityAttraction(alpha_p, alpha_v)
        cases.append((name, {"alpha_p": alpha_p, "alpha_v": alpha_v}, 2 * alpha_p, 2 * alpha_v, a.damping_ratio()))
    kappa, c_h = corridor_kappa(0.1)
    cases.append(("Khatib corridor", {"eta": ETA, "rho0": RHO0, "L": L_HALF, "alpha_v": 0.1}, kappa, c_h, c_h / (2 * np.sqrt(kappa))))
    out = []
    for name, inputs, kappa, c_h, zeta in cases:
        loop = HolonomicLoop(T_CONF, c_h)
        tstar = {key: ms[key].critical_delay(kappa, loop) for key, _, _ in MODELS}
        omega = ms["exact_delay"].boundary(HolonomicLoop(tstar["exact_delay"], c_h)).omega_critical
        out.append({"case": name, "inputs": inputs, "kappa": kappa, "c_h": c_h, "zeta": zeta, "T_star": tstar,
                    "omega_exact_delay": omega, "paper_T_star": dict(zip((k for k, _, _ in MODELS), PAPER_TSTAR[name]))})
    return out


def at_conference_period(ms: dict) -> dict:
    from pfm_stability.models.holonomic import HolonomicLoop

    kappa, c_h = corridor_kappa(0.1)
    roots = {}
    for alpha_v in (0.0, 0.1):
        r = ms["exact_delay"].rightmost_root(kappa, HolonomicLoop(T_CONF, 2 * alpha_v))
        roots[f"alpha_v={alpha_v:g}"] = {"real": r.real, "imag": abs(r.imag)}
    window = ms["sampled_zoh"].damping_range(kappa, HolonomicLoop(T_CONF, c_h))
    window_delay = ms["sampled_zoh_delay"].damping_range(kappa, HolonomicLoop(T_CONF, c_h))
    return {
        "T": T_CONF, "kappa": kappa, "rightmost_root_exact_delay": roots,
        "c_h_window_zoh": [list(w) for w in window], "alpha_v_window_zoh": [[lo / 2, hi / 2] for lo, hi in window],
        "alpha_v_window_zoh_delay": [[lo / 2, hi / 2] for lo, hi in window_delay],
        "closed_form_window_zoh": [kappa * T_CONF / 4, 1 / T_CONF],
    }


def tstar_curves(ms: dict, n: int) -> dict:
    from pfm_stability.models.holonomic import HolonomicLoop

    kappa, _ = corridor_kappa(0.1)
    alpha_v = np.geomspace(0.01, 30.0, n)
    curves = {key: [ms[key].critical_delay(kappa, HolonomicLoop(T_CONF, 2 * a)) for a in alpha_v] for key, _, _ in MODELS}
    return {"kappa": kappa, "alpha_v": alpha_v.tolist(), **curves}


SIM_POINTS = (  # (model, alpha_v, T): stable and unstable points on both sides of the curves
    ("sampled_zoh", 0.1, 0.01), ("sampled_zoh", 0.1, 0.025), ("sampled_zoh", 1.0, 0.1),
    ("sampled_zoh_delay", 0.1, 0.004), ("sampled_zoh_delay", 1.0, 0.1), ("sampled_zoh_delay", 3.0, 0.1),
)


def simulated_points(ms: dict, quick: bool) -> list:
    """σ of the planar simulator's point mass between the corridor's walls beside the sampled model's rightmost root.

    The target sits on the centre line at the start's height, so the robot moves only
    across the corridor: m ẍ = F_x(x) − 2α_v ẋ, with the target's pull adding 2α_p to κ.
    """
    from pfm_stability.laws.fields import KhatibLaw
    from pfm_stability.models.holonomic import HolonomicLoop
    from pfm_stability.sim.cycles import lateral_metrics
    from pfm_stability.sim.movers import Target, Wall
    from pfm_stability.sim.planar import Field, PlanarMember, PointMass, Start, World, simulate_planar_batch
    from pfm_stability.laws.velocity_laws import VelocityAttraction

    law = KhatibLaw(1.0, ETA, RHO0, 2.0, 1.0)  # η(1/d − 1/ρ0)/d² newtons with repulsion_scale 1
    world = World(Target((0.0, 0.0)), (Wall((-L_HALF, 0.0), (1.0, 0.0)), Wall((L_HALF, 0.0), (-1.0, 0.0))))
    robot = PointMass(1.0)
    points, members = [], []
    for key, alpha_v, T in (SIM_POINTS[:1] + SIM_POINTS[4:5] if quick else SIM_POINTS):
        kappa = corridor_kappa(alpha_v)[0] + 2 * 0.005
        compute_delay = 1 if key == "sampled_zoh_delay" else 0
        root = ms[key].rightmost_root(kappa, HolonomicLoop(T, 2 * alpha_v))
        duration = max(8.0, 300 * T)
        if root.real > 0:
            duration = min(duration, 5.0 / root.real)  # growth e^5 from 0.1 mm: 15 mm, before the walls make it non-linear
        points.append((key, alpha_v, T, kappa, root))
        members.append(PlanarMember(robot, Field(VelocityAttraction(0.005, alpha_v), law), world, Start((1e-4, 0.0)), T=T,
                                    duration=duration, compute_delay=compute_delay))
    out = []
    for (key, alpha_v, T, kappa, root), run in zip(points, simulate_planar_batch(members).runs):  # one batch
        m = lateral_metrics(run, (1.0, 0.0), robot=robot)
        out.append({"model": key, "alpha_v": alpha_v, "T": T, "kappa": kappa, "predicted_sigma": root.real, "predicted_omega": abs(root.imag),
                    "simulated_sigma": m.growth_rate, "simulated_omega": m.angular_frequency, "method": m.method, "collided": run.collision,
                    "T_star": ms[key].critical_delay(kappa, HolonomicLoop(T, 2 * alpha_v))})
    return out


def draw(path: Path, curves: dict, table: list, conf: dict, sim: list) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.4, 5.8), layout="constrained")
    a = curves["alpha_v"]
    colors = {"exact_delay": "tab:blue", "sampled_zoh": "tab:green", "sampled_zoh_delay": "tab:red"}
    for key, label, _ in MODELS:
        T = np.asarray(curves[key], dtype=float)
        ax.loglog(a, 1e3 * T, color=colors[key], lw=2, label=f"T*, {label}")
    corridor = next(r for r in table if r["case"] == "Khatib corridor")
    for key, _, _ in MODELS:
        ax.plot(0.1, 1e3 * corridor["T_star"][key], "o", color=colors[key], ms=7, mec="k")
    ax.axhline(1e3 * T_CONF, color="0.3", ls=":", lw=1.2, label=f"conference sampling T = {T_CONF:g} s")
    for lo, hi in conf["alpha_v_window_zoh"]:
        ax.axvspan(lo, hi, color="tab:green", alpha=0.1, label=f"ZOH stable at T = 0.1 s: alpha_v in ({lo:.2g}, {hi:.3g})")
    ax.annotate(f"alpha_v = 0.1 (zeta = {corridor['zeta']:.4f}):\n" + ", ".join(f"{1e3 * corridor['T_star'][k]:.3g}" for k, _, _ in MODELS) + " ms",
                (0.1, 1e3 * corridor["T_star"]["exact_delay"]), xytext=(0.013, 120), fontsize=9, arrowprops={"arrowstyle": "->"},
                bbox={"fc": "white", "ec": "0.6"})
    for p in sim:
        marker = "x" if p["simulated_sigma"] > 0 else "o"
        ax.plot(p["alpha_v"], 1e3 * p["T"], marker, color=colors[p["model"]], mfc="none", ms=9, mew=1.8)
    if sim:
        ax.plot([], [], "kx", ms=8, label="simulated: oscillation grows")
        ax.plot([], [], "ko", mfc="none", ms=8, label="simulated: decays")
    ax.set_xlabel("velocity gain alpha_v (c_h = 2 alpha_v, m_rob = 1)")
    ax.set_ylabel("critical delay / period T* (ms)")
    ax.set_title("GC2002 holonomic robot in a Khatib corridor (eta = 0.3, rho0 = 2 m, L = 0.5 m: kappa = 24 1/s^2):\n"
                 "stable below each curve; the tracking gains' damping is far too small for an obstacle's stiffness", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right", fontsize=8.5)
    save_figure(fig, path)


def run(out, quick: bool = False) -> dict:
    out = output_dir(out)
    ms = models()
    table = tstar_table(ms)
    conf = at_conference_period(ms)
    curves = tstar_curves(ms, 40 if quick else 200)
    sim = simulated_points(ms, quick)
    draw(out / "gc2002_holonomic_corridor.png", curves, table, conf, sim)
    fmt = {"tracking": lambda t: f"{t:.4g} s", "conference tracking": lambda t: f"{t:.4g} s", "Khatib corridor": lambda t: f"{1e3 * t:.3g} ms"}
    rows = [
        row(f"GC2002 holonomic, {r['case']}", "T*: pure delay / ZOH / ZOH + 1 sample",
            " / ".join(fmt[r["case"]](t) for t in r["paper_T_star"].values()) + " (analysis of eq 33)",
            " / ".join(fmt[r["case"]](r["T_star"][k]) for k, _, _ in MODELS), "-",
            f"kappa = {r['kappa']:.4g} 1/s^2, c_h = {r['c_h']:.3g} 1/s, zeta = {r['zeta']:.4g}")
        for r in table
    ]
    roots = conf["rightmost_root_exact_delay"]
    rows.append(row("GC2002 holonomic corridor, T = 0.1 s", "rightmost root (alpha_v = 0 / 0.1); ZOH alpha_v window", "-",
                    " / ".join(f"{r['real']:+.3f} ± {r['imag']:.3f}j" for r in roots.values())
                    + "; " + ", ".join(f"({lo:.3g}, {hi:.3g})" for lo, hi in conf["alpha_v_window_zoh"]),
                    "; ".join(f"{p['model']} alpha_v = {p['alpha_v']:g}, T = {1e3 * p['T']:.3g} ms: sigma {p['simulated_sigma']:+.3f} (predicted {p['predicted_sigma']:+.3f})" for p in sim) or "-",
                    "unstable at the conference's T with the tracking gains"))
    corridor = table[-1]
    result = {
        "experiment": "GC2002 velocity attraction on a holonomic robot: delay margins (docs/models.md, Robot loop families)",
        "inputs": {"eta": ETA, "rho0": RHO0, "L": L_HALF, "T_conference": T_CONF, "mass": 1.0, "quick": quick},
        "table": table,
        "conference_period": conf,
        "curves": curves,
        "simulated": sim,
        "rows": rows,
        "finding": (
            f"Khatib corridor kappa = {corridor['kappa']:.4g}, alpha_v = 0.1: T* = "
            + " / ".join(f"{1e3 * corridor['T_star'][k]:.3g}" for k, _, _ in MODELS)
            + " ms (pure delay / ZOH / ZOH + 1 sample); at T = 0.1 s rightmost roots "
            + ", ".join(f"{r['real']:+.3f} ± {r['imag']:.3f}j" for r in roots.values())
            + "; ZOH stable for alpha_v in " + ", ".join(f"({lo:.3g}, {hi:.3g})" for lo, hi in conf["alpha_v_window_zoh"]) + "."
        ),
    }
    write_json(out / "gc2002_holonomic_corridor.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
