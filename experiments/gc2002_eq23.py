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
T = 0.01 s; the runs are stepped together in batches (`simulate_planar_batch`).

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
LEVELS_PER_ROUND = 3
"""Bisection steps per batch of simulations (`smallest_landing_speeds`)."""
READINGS = (("A", "gradient"), ("B", "squared"), ("C", "paper_eq23"))
A_MAX = (0.5, 1.0, 2.0)
PAPER_BANDS = {"A": -1.5, "B": -0.90344, "C": -0.35650}
PAPER_VMIN = {"C": (0.330, 0.324, 0.322), "B": (None, 0.956, 0.781), "A": (None, None, 1.292)}


def member(variant: str, a_max: float, v0: float, T: float, duration: float):
    """The eq (23) run as a member of a planar batch (`pfm_stability.sim.planar.PlanarMember`)."""
    from pfm_stability.sim.movers import Ball, Target
    from pfm_stability.sim.planar import Field, PlanarMember, PointMass, Start, World
    from pfm_stability.laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion

    field = Field(VelocityAttraction(ALPHA_P, ALPHA_V), VelocityGatedRepulsion(ETA, RHO0, a_max, variant))
    world = World(Target((0.0, 0.0)), (Ball((BALL_X, 0.0), BALL_R),))
    return PlanarMember(PointMass(1.0, a_max), field, world, Start((X0, 0.0), (v0, 0.0)), T=T, duration=duration)


def simulate_all(members: list) -> list:
    """The runs of many members, stepped together (`simulate_planar_batch`)."""
    from pfm_stability.sim.planar import simulate_planar_batch

    return list(simulate_planar_batch(members).runs)


def outcome(run) -> str:
    """"lands" (reaches x = 0), "undefined" (eq 12 undefined before that) or "stalls"."""
    hit = np.flatnonzero(run.p[:, 0] >= 0.0)
    bad = run.first_event("collision_unavoidable")
    if hit.size and (bad is None or run.t[hit[0]] <= bad.time):
        return "lands"
    return "undefined" if bad is not None else "stalls"


def _subtree(lo: float, hi: float, depth: int) -> list:
    """Every midpoint `depth` steps of bisection of [lo, hi] may visit (2^depth − 1 values, computed as the bisection does)."""
    if depth == 0:
        return []
    mid = 0.5 * (lo + hi)
    return [mid] + _subtree(lo, mid, depth - 1) + _subtree(mid, hi, depth - 1)


def smallest_landing_speeds(combos: list, T: float, duration: float, scan: int, iterations: int) -> list:
    """The smallest v0 that reaches the target, for each (variant, a_max) of `combos`: a scan of
    (0, v_undefined) and `iterations` bisection steps of the first change.

    Every combination's scan is one batch of the planar simulator; the bisections advance
    together, `LEVELS_PER_ROUND` steps per batch: the batch holds every midpoint those steps
    may visit (7 per combination), and the steps then look their outcomes up — the same
    midpoints, hence the same bracket, as one step at a time, in a third of the batches.
    """
    grids = [np.linspace(0.0, math.sqrt(2 * a_max * (RHO_TO - X0)), scan + 1)[1:-1] for _, a_max in combos]
    runs = simulate_all([member(variant, a_max, float(v), T, duration) for (variant, a_max), grid in zip(combos, grids) for v in grid])
    results, brackets, out = [], [], []
    for c, grid in enumerate(grids):
        res = [outcome(r) for r in runs[c * grid.size:(c + 1) * grid.size]]
        results.append(res)
        lands = np.flatnonzero(np.array(res) == "lands")
        if lands.size == 0:
            brackets.append(None)
        else:
            i = int(lands[0])
            brackets.append([(float(grid[i - 1]) if i else 0.0), float(grid[i])])
    open_ = [c for c, b in enumerate(brackets) if b is not None]
    done = 0
    while open_ and done < iterations:
        depth = min(LEVELS_PER_ROUND, iterations - done)
        points = [_subtree(*brackets[c], depth) for c in open_]
        runs = simulate_all([member(*combos[c], v, T, duration) for c, vs in zip(open_, points) for v in vs])
        at = 0
        for c, vs in zip(open_, points):
            lands = {v: outcome(r) == "lands" for v, r in zip(vs, runs[at:at + len(vs)])}
            at += len(vs)
            for _ in range(depth):  # the bisection's own steps, each midpoint looked up
                mid = 0.5 * (brackets[c][0] + brackets[c][1])
                brackets[c][int(lands[mid])] = mid  # lands: the new upper end
        done += depth
    for grid, res, bracket in zip(grids, results, brackets):
        scan_rows = list(zip(grid.tolist(), res))
        out.append({"v_min": None, "scan": scan_rows} if bracket is None else {"v_min": bracket[1], "bracket": bracket, "scan": scan_rows})
    return out


def bands() -> dict:
    from pfm_stability.laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion, stall_band

    att = VelocityAttraction(ALPHA_P, ALPHA_V)
    return {name: [list(i) for i in stall_band(VelocityGatedRepulsion(ETA, RHO0, 1.0, variant), att, RHO_TO).intervals]
            for name, variant in READINGS}


def undefined_at_once(T: float) -> list:
    """v0 at which D ≤ 0 at the start, and the simulator's event just above / no event just below it."""
    speeds = [math.sqrt(2 * a_max * (RHO_TO - X0)) for a_max in A_MAX]
    runs = simulate_all([member("gradient", a_max, v * factor, T, 2 * T) for a_max, v in zip(A_MAX, speeds) for factor in (1.001, 0.999)])
    out = []
    for i, (a_max, v) in enumerate(zip(A_MAX, speeds)):
        above, below = (runs[2 * i + j].first_event("collision_unavoidable") for j in (0, 1))
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
    landing = smallest_landing_speeds([(variants[name], a_max) for name, a_max in combos], T, duration, 6 if quick else 12, 6 if quick else 9)
    for (name, a_max), res in zip(combos, landing):
        vmin[name][a_max] = res["v_min"]
        details.append({"reading": name, "a_max": a_max, **res})
    a_runs = 1.0
    cases = [(name, variant, kind, v0) for name, variant in READINGS
             for kind, v0 in (("slow", 0.2), ("fast", 1.0 if name != "A" else 1.9)) if not (quick and name != "C")]
    a_of = lambda name: 2.0 if name == "A" else a_runs  # noqa: E731
    simulated = simulate_all([member(variant, a_of(name), v0, T, duration) for name, variant, _, v0 in cases])
    runs = []
    for (name, _, kind, v0), r in zip(cases, simulated):
        step = max(1, r.t.size // 400)
        runs.append({"reading": name, "kind": kind, "v0": v0, "a_max": a_of(name), "outcome": outcome(r),
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
