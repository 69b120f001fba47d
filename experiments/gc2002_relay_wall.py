"""Ge & Cui 2002's velocity-gated repulsion beside a wall: no equilibrium, a relay limit cycle.

S.S. Ge and Y.J. Cui, "Dynamic motion planning for mobile robots using
potential field method", Autonomous Robots 13, 2002 ("GC2002"), eq (12), (19):
the repulsion acts only while the robot closes on the obstacle. Running
parallel to a wall it exerts nothing, so KB's equilibrium d0 does not exist:
the lateral force is a relay in the heading (docs/velocity_and_fuzzy.md, "The
non-smooth verdict"). CARMEL's steering robot (V = 0.8 m/s, τ = 0.3 s, k = 2,
T = 0.065 s, command hold) beside a wall with η = 0.1, a_max = 1, F_a = 1,
α = 60° (ρ0 = 2 m), simulated (`pfm_stability.sim.planar`,
`pfm_stability.sim.cycles.wall_cycle`):

1. the limit cycle with a one-sample compute delay and without one; the rest
   band d ≤ d_s = √(η/(F_a cos α)) of a holonomic robot;
2. Khatib's static law at the same η, ρ0: its equilibrium, N, the exact-delay
   and sampled verdicts, and its simulated limit cycle;
3. a first-harmonic (describing-function) estimate of the relay's period;
4. the cycle's size against the sampling period T (does it scale ∝ T?).

    python experiments/gc2002_relay_wall.py [--out experiments/results] [--quick]

Writes ``gc2002_relay_wall.png`` (d(t), θ(t), the band; size against T) and ``gc2002_relay_wall.json``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

ETA, A_MAX, F_A, ALPHA_DEG, RHO0 = 0.1, 1.0, 1.0, 60.0, 2.0
V, TAU, K, T = 0.8, 0.3, 2.0, 0.065
PAPER = {"compute_delay_1": (0.418, 0.243, 0.524, 1.88), "compute_delay_0": (0.335, 0.099, 0.227, 1.26),
         "khatib": {"d0": 0.528, "N": 3.673, "NV": 2.94, "heading_amplitude": 0.98, "period": 3.02, "peak_to_peak": 0.66},
         "d_s": 0.4472, "first_harmonic_period": 1.04}


def robot():
    from pfm_stability.sim.planar import Steering

    return Steering(V, TAU, K, hold="command")


def wall_run(repulsion, period: float, compute_delay: int, duration: float, start_distance: float):
    """The wall run of `cycles.wall_cycle` (wall x = 0, pull F_a at α from the normal), returned whole for plotting."""
    from pfm_stability.sim.movers import Wall
    from pfm_stability.sim.planar import Field, Pull, Start, World, simulate_planar

    alpha = math.radians(ALPHA_DEG)
    field = Field(Pull(F_A, math.pi - alpha), repulsion, repulsion_scale=F_A)
    return simulate_planar(robot(), field, World(obstacles=(Wall((0.0, 0.0), (1.0, 0.0)),)), T=period, compute_delay=compute_delay,
                           duration=duration, start=Start((start_distance, 0.0), heading=math.pi / 2))


def first_harmonic_period(delay: float) -> float:
    """Period (s) where k e^(−sT_d)/(τs² + s + k) has phase −π: an ideal relay's limit cycle (describing function)."""
    from pfm_stability.numerics.solve import bisect_root

    phase = lambda w: -w * delay - math.atan2(w, K - TAU * w * w) + math.pi  # noqa: E731
    return 2 * math.pi / bisect_root(phase, 1e-6, 100.0, rtol=1e-12)


def khatib(duration: float) -> dict:
    from pfm_stability.analysis.criteria import loop_of
    from pfm_stability.laws.fields import KhatibLaw
    from pfm_stability.laws.force_law import wall_equilibria
    from pfm_stability.models import make_model
    from pfm_stability.models.loop import Loop
    from pfm_stability.sim.cycles import measure_wall_cycle
    from pfm_stability.parameters import CARMEL

    law = KhatibLaw(1.0, ETA, RHO0, 2.0, 1.0)  # η(1/d − 1/ρ0)/d² in units of F_a
    (eq,) = wall_equilibria(law, math.radians(ALPHA_DEG))
    NV = eq.N * V
    ex = make_model("exact_delay").boundary(Loop(TAU, T, K)).NV_critical
    sa = make_model("sampled", hold="command", compute_delay=1).boundary(loop_of(CARMEL.robot, CARMEL.controller)).NV_critical
    run = wall_run(law, T, 1, duration, eq.x0 + 0.02)
    cyc = measure_wall_cycle(run)
    return {"d0": eq.x0, "N": eq.N, "NV": NV, "NV_critical_exact_delay": ex, "NV_critical_sampled": sa,
            "cycle": cyc.to_dict(), "t": run.t[::2].tolist(), "d": run.p[::2, 0].tolist()}


def run(out, quick: bool = False) -> dict:
    import matplotlib.pyplot as plt

    from pfm_stability.sim.cycles import measure_wall_cycle
    from pfm_stability.sim.planar import simulate_planar_batch, wall_member
    from pfm_stability.laws.velocity_laws import VelocityGatedRepulsion

    out = output_dir(out)
    duration = 30.0 if quick else 60.0
    rep = VelocityGatedRepulsion(ETA, RHO0, A_MAX)
    alpha = math.radians(ALPHA_DEG)
    band = rep.non_smooth_wall(F_A, alpha)
    kh = khatib(duration)
    harmonic = {"T_d_1.5T": first_harmonic_period(1.5 * T), "T_d_0.5T": first_harmonic_period(0.5 * T)}
    sweep_T = (0.02, 0.065, 0.13) if quick else (0.01, 0.02, 0.04, 0.065, 0.1, 0.13)
    # one batch: the two delays at T (kept whole for the plots) and the sweep of T
    members = [wall_member(rep, F_A, alpha, robot(), T=T, compute_delay=cd, duration=duration) for cd in (1, 0)]
    members += [wall_member(rep, F_A, alpha, robot(), T=Ti, compute_delay=1, duration=max(duration, 40 * Ti)) for Ti in sweep_T]
    simulated = simulate_planar_batch(members).runs
    runs = dict(zip((1, 0), simulated[:2]))
    cycles = {cd: measure_wall_cycle(r).to_dict() for cd, r in runs.items()}
    sweep = []
    for Ti, r in zip(sweep_T, simulated[2:]):
        c = measure_wall_cycle(r)
        sweep.append({"T": Ti, **c.to_dict(), "peak_to_peak_over_T": c.peak_to_peak / Ti,
                      "heading_amplitude_over_T": (c.heading_amplitude or 0.0) / Ti})

    fig, axes = plt.subplots(1, 3, figsize=(17, 5.2), layout="constrained")
    a1, a2, a3 = axes
    colors = {1: "tab:red", 0: "tab:blue"}
    for cd, r in runs.items():
        c = cycles[cd]
        a1.plot(r.t, r.p[:, 0], color=colors[cd], lw=1.2,
                label=f"gated, compute delay {cd}: mean {c['mean_distance']:.3f} m, p-p {c['peak_to_peak']:.3f} m, period {c['period']:.2f} s")
        a2.plot(r.t, r.theta - math.pi / 2, color=colors[cd], lw=1.2, label=f"gated, compute delay {cd}: amplitude {c['heading_amplitude']:.3f} rad")
    a1.plot(kh["t"], kh["d"], color="0.4", lw=1, ls="--", label=f"Khatib law (d0 = {kh['d0']:.3f} m): p-p {kh['cycle']['peak_to_peak']:.2f} m")
    a1.axhspan(0, band.d_s, color="tab:green", alpha=0.12, label=f"holonomic rest band d <= d_s = {band.d_s:.4f} m")
    a1.set_xlabel("t (s)")
    a1.set_ylabel("distance to the wall d (m)")
    a1.set_ylim(0, 1.0)
    a1.set_title(f"CARMEL (command hold, T = {T} s) beside a velocity-gated wall\n(eta = {ETA}, a_max = {A_MAX:g}, F_a = {F_A:g}, "
                 f"alpha = {ALPHA_DEG:g} deg): d(t)", fontsize=9)
    a1.legend(fontsize=7, loc="upper right")
    a1.grid(alpha=0.3)
    a2.axhline(0, color="k", lw=0.8)
    a2.set_xlabel("t (s)")
    a2.set_ylabel("heading from the wall's direction (rad, + away)")
    a2.set_xlim(duration - 10, duration)
    a2.set_title("relay in the sign of the heading: no equilibrium, a limit cycle (last 10 s)", fontsize=9)
    a2.legend(fontsize=7.5, loc="upper right")
    a2.grid(alpha=0.3)
    Ts = np.array([s["T"] for s in sweep])
    a3.loglog(Ts, [s["peak_to_peak"] for s in sweep], "o-", color="tab:red", label="lateral peak-to-peak (m)")
    a3.loglog(Ts, [s["heading_amplitude"] for s in sweep], "s-", color="tab:purple", label="heading amplitude (rad)")
    a3.loglog(Ts, [s["period"] or math.nan for s in sweep], "^-", color="tab:gray", label="period (s)")
    ref = sweep[len(sweep) // 2]
    a3.loglog(Ts, ref["peak_to_peak"] * Ts / ref["T"], "k:", lw=1, label="proportional to T")
    a3.loglog(Ts, ref["peak_to_peak"] * (Ts / ref["T"]) ** 2, "k--", lw=1, label="proportional to T^2")
    a3.set_xlabel("sampling period T (s), compute delay 1")
    a3.set_title("size of the relay cycle against T", fontsize=9)
    a3.legend(fontsize=7.5)
    a3.grid(True, which="both", alpha=0.3)
    save_figure(fig, out / "gc2002_relay_wall.png")

    slope_p2p = float(np.polyfit(np.log(Ts[:3]), np.log([s["peak_to_peak"] for s in sweep[:3]]), 1)[0])
    slope_heading = float(np.polyfit(np.log(Ts[:3]), np.log([s["heading_amplitude"] for s in sweep[:3]]), 1)[0])
    c1, c0 = cycles[1], cycles[0]

    def cyc(c):
        return f"mean {c['mean_distance']:.3f} m, p-p {c['peak_to_peak']:.3f} m, {c['heading_amplitude']:.3f} rad, {c['period']:.2f} s"

    rows = [
        row("GC2002 eq (12) wall", "relay cycle, compute delay 1 / 0 (CARMEL, held command)", "- (non-smooth: no linear verdict)",
            f"no equilibrium; band d_s = {band.d_s:.4f} m", f"{cyc(c1)} / {cyc(c0)}",
            "reference: 0.418, 0.243, 0.524, 1.88 / 0.335, 0.099, 0.227, 1.26; our delay-1 cycle matches the reference's delay-0 row"),
        row("GC2002 eq (12) wall", "Khatib law, same eta and rho0", "-",
            f"d0 = {kh['d0']:.3f} m, N = {kh['N']:.3f}, NV = {kh['NV']:.2f} > {kh['NV_critical_exact_delay']:.3f} (exact delay), "
            f"{kh['NV_critical_sampled']:.3f} (sampled): unstable",
            f"limit cycle {kh['cycle']['heading_amplitude']:.2f} rad, {kh['cycle']['period']:.2f} s, p-p {kh['cycle']['peak_to_peak']:.2f} m",
            "reference: 0.98 rad, 3.02 s, 0.66 m (a larger cycle, as for the gated wall)"),
        row("GC2002 eq (12) wall", "relay period: first harmonic vs simulated; size vs T", "-",
            f"{harmonic['T_d_1.5T']:.2f} s (T_d = 1.5T)", f"{c1['period']:.2f} s",
            f"p-p ~ T^{slope_p2p:.2f}, heading ~ T^{slope_heading:.2f} for T <= {Ts[2]:g} s"),
    ]
    result = {
        "experiment": "GC2002 velocity-gated repulsion beside a wall: relay limit cycle (docs/velocity_and_fuzzy.md)",
        "inputs": {"eta": ETA, "a_max": A_MAX, "F_a": F_A, "alpha_deg": ALPHA_DEG, "rho0": RHO0, "V": V, "tau": TAU, "k": K, "T": T,
                   "hold": "command", "duration": duration, "quick": quick},
        "band": {"d_s": band.d_s, "verdict": band.verdict, "friction": band.friction},
        "cycles": {f"compute_delay_{cd}": c for cd, c in cycles.items()},
        "khatib": {k: v for k, v in kh.items() if k not in ("t", "d")},
        "first_harmonic_period": harmonic,
        "sweep_T": sweep,
        "scaling_exponents_small_T": {"peak_to_peak": slope_p2p, "heading_amplitude": slope_heading},
        "paper": PAPER,
        "rows": rows,
        "finding": (f"Velocity-gated wall: no equilibrium (band d_s = {band.d_s:.4f} m); relay cycle with compute delay 1: {cyc(c1)}; "
                    f"without: {cyc(c0)}; Khatib law: d0 = {kh['d0']:.3f}, N = {kh['N']:.3f}, cycle {kh['cycle']['heading_amplitude']:.2f} rad, "
                    f"{kh['cycle']['period']:.2f} s; first harmonic {harmonic['T_d_1.5T']:.2f} s; p-p ~ T^{slope_p2p:.2f}."),
    }
    write_json(out / "gc2002_relay_wall.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
