"""Ge & Cui 2002 eq (23): the 1-D free path past a ball, three readings of the velocity-gated repulsion.

S.S. Ge and Y.J. Cui, "Dynamic motion planning for mobile robots using
potential field method", Autonomous Robots 13, 2002 ("GC2002"), eq (23): a
robot on the x axis approaches a target at 0 with a ball behind it (radius
0.3 m at x = 0.8 m, so ρ_TO = 0.5 m), α_p = 0.005, α_v = 0.1, η = 0.2,
ρ0 = 2 m, start x0 = −1.5 m; a_max is not given (0.5, 1, 2 m/s² here). The
repulsion acts only while closing on the ball (eq 12) with magnitude
A: η/D² (the gradient, journal eq 19), B: η(1/D − 1/ρ0)², C: η³(1/D − 1/ρ0)²
(as printed in eq 23 and the conference form's eq 19); D = ρ_TO − x − ẋ²/(2a_max)
(docs/velocity_and_fuzzy.md). The robot is the planar simulator's point mass
(`pfm_stability.sim.planar`) with |a| ≤ a_max (the conference form's eq 22),
T = 0.01 s.

* **Stall bands** (`velocity_laws.stall_band`): where the robot rests short of
  the target (Filippov equilibria on ẋ = 0).
* **Slow and fast starts**: x(t) for each reading — a slow start stalls in the
  band, a fast one lands hard.
* **Smallest initial speed that reaches the target** against a_max, found by
  a scan of v0 and bisection; **"undefined at once"**: v0 ≥ √(2a_max(ρ_TO − x0))
  makes D ≤ 0 at the start (eq 12 undefined), checked as a simulator event.
* Without the ball the critically damped robot reaches the target iff
  v0 > ω_n|x0| = 0.15 m/s.

    python experiments/gc2002_eq23.py [--out experiments/results] [--quick]

Writes ``gc2002_eq23.png`` and ``gc2002_eq23.json``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

ALPHA_P, ALPHA_V, ETA, RHO0 = 0.005, 0.1, 0.2, 2.0
BALL_X, BALL_R, X0 = 0.8, 0.3, -1.5
RHO_TO = BALL_X - BALL_R
READINGS = (("A", "gradient"), ("B", "squared"), ("C", "paper_eq23"))
A_MAX = (0.5, 1.0, 2.0)
PAPER_BANDS = {"A": -1.5, "B": -0.90344, "C": -0.35650}
PAPER_VMIN = {"C": (0.330, 0.324, 0.322), "B": (None, 0.956, 0.781), "A": (None, None, 1.292)}


def simulate(variant: str, a_max: float, v0: float, T: float, duration: float):
    from pfm_stability.sim.movers import Ball, Target
    from pfm_stability.sim.planar import Field, PointMass, Start, World, simulate_planar
    from pfm_stability.laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion

    field = Field(VelocityAttraction(ALPHA_P, ALPHA_V), VelocityGatedRepulsion(ETA, RHO0, a_max, variant))
    world = World(Target((0.0, 0.0)), (Ball((BALL_X, 0.0), BALL_R),))
    return simulate_planar(PointMass(1.0, a_max), field, world, T=T, duration=duration, start=Start((X0, 0.0), (v0, 0.0)))


def outcome(run) -> str:
    """"lands" (reaches x = 0), "undefined" (eq 12 undefined before that) or "stalls"."""
    hit = np.flatnonzero(run.p[:, 0] >= 0.0)
    bad = run.first_event("collision_unavoidable")
    if hit.size and (bad is None or run.t[hit[0]] <= bad.time):
        return "lands"
    return "undefined" if bad is not None else "stalls"


def smallest_landing_speed(variant: str, a_max: float, T: float, duration: float, scan: int, iterations: int) -> dict:
    """The smallest v0 that reaches the target: a scan of (0, v_undefined) and bisection of the first change."""
    v_undef = math.sqrt(2 * a_max * (RHO_TO - X0))
    grid = np.linspace(0.0, v_undef, scan + 1)[1:-1]
    results = [outcome(simulate(variant, a_max, v, T, duration)) for v in grid]
    lands = [v for v, r in zip(grid, results) if r == "lands"]
    if not lands:
        return {"v_min": None, "scan": list(zip(grid.tolist(), results))}
    i = int(np.flatnonzero(np.array(results) == "lands")[0])
    lo, hi = (float(grid[i - 1]) if i else 0.0), float(grid[i])
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        if outcome(simulate(variant, a_max, mid, T, duration)) == "lands":
            hi = mid
        else:
            lo = mid
    return {"v_min": hi, "bracket": [lo, hi], "scan": list(zip(grid.tolist(), results))}


def bands() -> dict:
    from pfm_stability.laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion, stall_band

    att = VelocityAttraction(ALPHA_P, ALPHA_V)
    return {name: [list(i) for i in stall_band(VelocityGatedRepulsion(ETA, RHO0, 1.0, variant), att, RHO_TO).intervals]
            for name, variant in READINGS}


def undefined_at_once(T: float) -> list:
    """v0 at which D ≤ 0 at the start, and the simulator's event just above / no event just below it."""
    out = []
    for a_max in A_MAX:
        v = math.sqrt(2 * a_max * (RHO_TO - X0))
        above = simulate("gradient", a_max, v * 1.001, T, 2 * T).first_event("collision_unavoidable")
        below = simulate("gradient", a_max, v * 0.999, T, 2 * T).first_event("collision_unavoidable")
        out.append({"a_max": a_max, "v_undefined": v, "event_above_at": above.time if above else None, "event_below": below is not None})
    return out


def draw(path: Path, band: dict, runs: list, vmin: dict, undefined: list, a_max_runs: float) -> None:
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(14, 5.6), layout="constrained")
    colors = {"A": "tab:blue", "B": "tab:green", "C": "tab:red"}
    for name, intervals in band.items():
        for lo, hi in intervals:
            a1.axhspan(lo, hi, xmin=0.965 - 0.03 * "ABC".index(name), xmax=0.99 - 0.03 * "ABC".index(name), color=colors[name], alpha=0.6)
    for r in runs:
        a1.plot(r["t"], r["x"], color=colors[r["reading"]], ls="-" if r["kind"] == "fast" else "--", lw=1.6,
                label=f"{r['reading']}, a_max {r['a_max']:g}, v0 = {r['v0']:g}: {r['outcome']}")
    a1.axhline(0.0, color="k", lw=1)
    a1.axhline(RHO_TO, color="0.3", lw=3)
    a1.text(0.5, RHO_TO + 0.03, "ball surface (rho_TO = 0.5 m)", fontsize=8)
    a1.text(0.5, 0.03, "target", fontsize=8)
    a1.set_xlabel("t (s)")
    a1.set_ylabel("x (m)")
    a1.set_ylim(-2.35, 0.7)
    a1.set_title(f"eq (23), a_max = {a_max_runs:g} m/s^2 (A: 2): slow starts stall in the band (bars at right: A, B, C),\nfast starts land hard", fontsize=10)
    a1.legend(fontsize=7.5, loc="lower center", ncol=2)
    a1.grid(alpha=0.3)
    a = np.linspace(0.3, 2.2, 100)
    a2.plot(a, np.sqrt(2 * a * (RHO_TO - X0)), "k-", lw=1.5, label="undefined at once: v0 = sqrt(2 a_max (rho_TO - x0))")
    a2.plot(a, np.sqrt(2 * a * abs(X0)), "k:", lw=1.2, label="saturated braking stops at the target: sqrt(2 a_max |x0|)")
    a2.axhline(0.15, color="0.5", ls="--", lw=1, label="no ball: lands iff v0 > omega_n |x0| = 0.15")
    for name, _ in READINGS:
        xs = [am for am in vmin[name] if vmin[name][am] is not None]
        a2.plot(xs, [vmin[name][am] for am in xs], "o-", color=colors[name], ms=7, label=f"{name}: smallest landing v0 (simulated)")
        paper = [(am, p) for am, p in zip(A_MAX, PAPER_VMIN[name]) if p is not None]
        a2.plot([p[0] for p in paper], [p[1] for p in paper], "x", color=colors[name], ms=9, mew=2)
    a2.plot([], [], "kx", ms=8, label="reference analysis (x)")
    for u in undefined:
        a2.plot(u["a_max"], u["v_undefined"], "ks", ms=5)
    a2.set_xlabel("a_max (m/s^2)")
    a2.set_ylabel("initial speed v0 (m/s)")
    a2.set_title("smallest initial speed that reaches the target", fontsize=10)
    a2.legend(fontsize=7.5, loc="upper left")
    a2.grid(alpha=0.3)
    save_figure(fig, path)


def run(out, quick: bool = False) -> dict:
    out = output_dir(out)
    T = 0.02 if quick else 0.01
    duration = 15.0
    band = bands()
    undefined = undefined_at_once(T)
    combos = [("C", 1.0)] if quick else [(n, a) for n, _ in READINGS for a in A_MAX]
    variants = dict(READINGS)
    vmin, details = {n: {} for n, _ in READINGS}, []
    for name, a_max in combos:
        res = smallest_landing_speed(variants[name], a_max, T, duration, 6 if quick else 12, 6 if quick else 9)
        vmin[name][a_max] = res["v_min"]
        details.append({"reading": name, "a_max": a_max, **res})
    a_runs = 1.0
    runs = []
    for name, variant in READINGS:
        for kind, v0 in (("slow", 0.2), ("fast", 1.0 if name != "A" else 1.9)):
            if quick and name != "C":
                continue
            r = simulate(variant, 2.0 if name == "A" else a_runs, v0, T, duration)
            step = max(1, r.t.size // 400)
            runs.append({"reading": name, "kind": kind, "v0": v0, "a_max": 2.0 if name == "A" else a_runs, "outcome": outcome(r),
                         "x_final": float(r.p[-1, 0]), "t": r.t[::step].tolist(), "x": r.p[::step, 0].tolist()})
    draw(out / "gc2002_eq23.png", band, runs, vmin, undefined, a_runs)

    def v(name):
        return " / ".join("none" if vmin[name].get(a, 0) is None else ("-" if a not in vmin[name] else f"{vmin[name][a]:.3f}") for a in A_MAX)

    rows = [
        row("GC2002 eq (23)", "stall band (m), readings A / B / C", "slow start stops short of the target",
            " / ".join(f"({i[0][0]:.5f}, {i[0][1]:g})" for i in band.values()), "-", "Filippov rest points on x' = 0 (velocity_laws.stall_band)"),
        row("GC2002 eq (23)", "smallest landing v0 (m/s) at a_max = 0.5 / 1 / 2: C; B; A", "fast start: hard landing",
            "-", f"C {v('C')}; B {v('B')}; A {v('A')}",
            "reference: C 0.330 / 0.324 / 0.322, B none / 0.956 / 0.781, A none / none / 1.292; saturated braking keeps D constant, "
            "so B and A also land between sqrt(2 a_max |x0|) and the undefined speed"),
        row("GC2002 eq (23)", "undefined at once (D <= 0 at the start), v0 (m/s) at a_max = 0.5 / 1 / 2", "-",
            " / ".join(f"{u['v_undefined']:.3f}" for u in undefined),
            "event at t = 0 just above, none just below" if all(u["event_above_at"] == 0.0 and not u["event_below"] for u in undefined) else "mismatch", ""),
    ]
    result = {
        "experiment": "GC2002 eq (23): 1-D free path past a ball, three readings of the repulsion (planar simulation)",
        "inputs": {"alpha_p": ALPHA_P, "alpha_v": ALPHA_V, "eta": ETA, "rho0": RHO0, "ball_x": BALL_X, "ball_radius": BALL_R, "x0": X0,
                   "rho_TO": RHO_TO, "T": T, "duration": duration, "a_max_saturation": True, "quick": quick},
        "stall_bands": band,
        "paper_band_edges": PAPER_BANDS,
        "smallest_landing_speed": {n: {str(a): v_ for a, v_ in d.items()} for n, d in vmin.items()},
        "paper_smallest_landing_speed": {n: dict(zip(map(str, A_MAX), p)) for n, p in PAPER_VMIN.items()},
        "landing_details": details,
        "undefined_at_once": undefined,
        "no_ball_threshold": 0.1 * abs(X0),
        "runs": runs,
        "rows": rows,
        "finding": ("eq (23): stall bands " + ", ".join(f"{n} ({i[0][0]:.5f}, 0)" for n, i in band.items())
                    + f"; smallest landing v0 C {v('C')}, B {v('B')}, A {v('A')} m/s at a_max 0.5 / 1 / 2; undefined at once from "
                    + " / ".join(f"{u['v_undefined']:.3f}" for u in undefined) + " m/s."),
    }
    write_json(out / "gc2002_eq23.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
