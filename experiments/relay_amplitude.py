"""The window-edge relay's limit cycle (`maps.deciding.relay`, docs/maps.md): predicted against simulated amplitude and frequency.

Two levels:

1. **Loop level.** The sampled loop (KB's τ, k, T, V; command/reference hold; compute delay 0/1), discretized here
   (expm of the augmented plant matrix), with the heading reference δ_k = −N_s·x_k − (|J|/2)·sign(x_k): the relay
   alone, beside a restoring smooth slope N_s = 0.6·N* and beside an anti-restoring one (−0.3·N*). CARMEL and
   seeded random robots. Predicted: the describing function 2|J|/(π(N* − N_s)) (`relay_amplitude`) at ω*; the
   previous formula 2|J|/(πN*) beside it. Simulated: the settled cycle's first harmonic and frequency; the peak
   (half the peak-to-peak) too.
2. **Map level.** CARMEL in an aisle between a one-cell wall and a solid rack (gap cells wide; the rack at the
   window's edge at the equilibrium): `maps.analysis.analyze_map`'s route verdicts (``PathVerdicts.amplitude``, the
   relay's one-jump prediction as `maps.deciding.paths` calls it), the one-jump formula with the jump merged and the slope,
   `window_cycle` (the describing function of the window's whole profile), and the VFF simulator (`sim.engine`, the
   grid law, target straight along the aisle, started 3 cm off the equilibrium): first harmonic, peak and the
   episodes' amplitude (`maps.judging.episodes.episodes`), and the frequency; and the settled first harmonic started 1, 3, 8
   and 15 cm off (the equilibrium beside a rack is stable only for small disturbances: the staircase's gain).

    python experiments/relay_amplitude.py --out experiments/results [--quick]
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

from pfm_stability.maps.deciding.relay import relay_amplitude, window_cycle, window_relay  # noqa: E402
from pfm_stability.parameters import CARMEL, HOLDS  # noqa: E402

GAPS = (24, 28, 30, 32, 34)
"""Aisle widths, cells (the free columns between the wall at column 0 and the rack)."""
STARTS = (0.01, 0.03, 0.08, 0.15)
"""Start offsets from the equilibrium, m (towards the wall): the equilibrium beside a rack is stable only for small ones."""


def sampled_loop(tau, k, T, V, hold, delay):
    """(A_d, B_d) of the sampled loop with the heading reference δ as input; states (ω, θ, x[, held command])."""
    from scipy.linalg import expm

    if hold == "command":
        A, B = np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, V, 0]]), np.array([1 / tau, 0, 0])
    else:
        A, B = np.array([[-1 / tau, -k / tau, 0], [1, 0, 0], [0, V, 0]]), np.array([k / tau, 0, 0])
    M = np.zeros((4, 4))
    M[:3, :3], M[:3, 3] = A, B
    E = expm(M * T)
    Phi, Gam = E[:3, :3], E[:3, 3]
    theta = np.array([0.0, k, 0.0]) if hold == "command" else np.zeros(3)
    gain = k if hold == "command" else 1.0
    if not delay:
        return Phi - np.outer(Gam, theta), gain * Gam
    Ad = np.zeros((4, 4))
    Ad[:3, :3], Ad[:3, 3], Ad[3, :3] = Phi, Gam, -theta
    return Ad, np.r_[0.0, 0.0, 0.0, gain]


def crossover(loop, T):
    """(ω*, N*) from the loop's frequency response x/δ at e^{jωT}: its first real negative value."""
    from scipy.optimize import brentq

    Ad, Bd = loop
    G = lambda w: np.linalg.solve(np.exp(1j * w * T) * np.eye(Ad.shape[0]) - Ad, Bd)[2]  # noqa: E731
    ws = np.linspace(1e-3, 0.999 * math.pi / T, 3000)
    g = np.array([G(w) for w in ws])
    i = np.flatnonzero((g.imag[:-1] < 0) & (g.imag[1:] >= 0) & (g.real[1:] < 0))[0]
    w = brentq(lambda w: G(w).imag, ws[i], ws[i + 1], xtol=1e-14)
    return w, -1.0 / G(w).real


def settled_cycle(x, dt):
    """(first harmonic, half peak-to-peak, ω) of the last half of x (uniform step dt): whole periods between upward
    crossings of the mean."""
    x = np.asarray(x[x.size // 2:], dtype=float)
    r = x - x.mean()
    up = np.flatnonzero((r[:-1] < 0) & (r[1:] >= 0))
    if up.size < 3:
        return float("nan"), float(np.ptp(x) / 2), float("nan")
    period = (up[-1] - up[0]) / (up.size - 1)
    seg = r[up[0]:up[-1]]
    a1 = 2 * abs(np.mean(seg * np.exp(-2j * math.pi * np.arange(seg.size) / period)))
    return float(a1), float(np.ptp(seg) / 2), 2 * math.pi / (period * dt)


def loop_case(tau, k, T, V, hold, delay, fraction, J=0.1):
    """One loop-level run: the relay ±J/2 beside the smooth slope fraction·N*."""
    loop = sampled_loop(tau, k, T, V, hold, delay)
    w0, N0 = crossover(loop, T)
    Ns = fraction * N0
    A = float(relay_amplitude(J, N0, Ns))
    Ad, Bd = loop
    z = np.zeros(Ad.shape[0])
    z[2] = 1.2 * A
    steps = int(80 * 2 * math.pi / w0 / T)
    x = np.empty(steps)
    for i in range(steps):
        x[i] = z[2]
        z = Ad @ z + Bd * (-Ns * z[2] - 0.5 * J * np.sign(z[2]))
    a1, peak, w = settled_cycle(x, T)
    return {"tau": tau, "k": k, "T": T, "V": V, "hold": hold, "compute_delay": delay, "N_smooth_over_N_critical": fraction,
            "N_critical": N0, "omega_critical": w0, "half_period_samples": math.pi / (w0 * T),
            "predicted": A, "previous": float(relay_amplitude(J, N0)), "first_harmonic": a1, "peak": peak, "omega": w,
            "error": a1 / A - 1, "previous_error": a1 / float(relay_amplitude(J, N0)) - 1, "omega_error": w / w0 - 1}


def loop_level(quick: bool):
    """CARMEL's four sampled structures and seeded random robots, three slopes each."""
    robot, controller = CARMEL.robot, CARMEL.controller
    robots = [("CARMEL", robot.tau, robot.k, controller.T, robot.V, hold, delay) for hold in HOLDS for delay in (0, 1)]
    rng = np.random.default_rng(2031)
    for i in range(4 if quick else 12):
        tau, k, T, V = rng.uniform(0.05, 0.5), rng.uniform(1, 5), rng.uniform(0.02, 0.15), rng.uniform(0.3, 1.5)
        robots.append((f"random {i}", tau, k, T, V, HOLDS[i % 2], (i // 2) % 2))
    out = []
    for name, tau, k, T, V, hold, delay in robots:
        for fraction in (0.0, 0.6, -0.3):
            out.append({"robot": name, **loop_case(tau, k, T, V, hold, delay, fraction)})
    return out


def _map_file(directory: Path, gap: int, length: int) -> Path:
    from PIL import Image

    img = np.full((length, gap + 12), 254, np.uint8)
    img[:, 0] = 0
    img[:, gap + 1:] = 0
    Image.fromarray(img).save(directory / f"aisle{gap}.pgm")
    path = directory / f"aisle{gap}.yaml"
    path.write_text(f"image: aisle{gap}.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path


def map_level(gaps, length: int = 500):
    """Per aisle: the map's predictions at its middle and the VFF simulator's cycle."""
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.judging.episodes import episodes
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.maps.deciding.decide import path_samples
    from pfm_stability.models import make_model
    from pfm_stability.models.loop import Loop
    from pfm_stability.sim.engine import run_batch
    from pfm_stability.sim.scenario import Pose, Scenario, Target
    from pfm_stability.validation.maps import simulator_grid

    robot, controller = CARMEL.robot, CARMEL.controller
    law = make_law("grid", robot, controller)
    boundary = make_model("sampled", hold=controller.hold, compute_delay=controller.compute_delay).boundary(Loop.of(robot, controller))
    N0, w0 = boundary.NV_critical / robot.V, boundary.omega_critical
    rows, traces = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        for gap in gaps:
            analysis = analyze_map(load_map(_map_file(Path(tmp), gap, length)), robot, controller, law)
            pv = analysis.paths
            x, y, tx, ty, _, _, _ = path_samples(pv.paths, analysis.grid.cell_size)
            mid = np.flatnonzero(np.abs(pv.py - length * 0.05) < 5.0)
            off = np.nan_to_num(pv.samples.offset[mid])
            found, jump = window_relay(analysis.grid, law, x[mid], y[mid], tx[mid], ty[mid], off)
            N_s = np.nan_to_num(np.fmax(pv.N_forward[mid], pv.N_reverse[mid]))
            one = relay_amplitude(jump, N0, N_s)
            profile = np.where(found, window_cycle(analysis.grid, law, x[mid], y[mid], tx[mid], ty[mid], off, N0), 0.0)  # as paths.py would
            x0 = float(np.median(pv.px[mid]))
            scenarios = [Scenario(name=f"aisle {gap}, start {start:+.2f} m", robot=robot, controller=controller,
                                  environment=simulator_grid(analysis.grid), start=Pose(x0 + start, 2.0, 0.0), target=Target.direction(0.0),
                                  duration=55.0, cell_ratio=law.ratio, window_cells=law.window_cells) for start in STARTS]
            runs = run_batch(scenarios, record="trajectory", metrics=False).runs
            by_start = {}
            for start, result in zip(STARTS, runs):
                keep = result.trajectory.t > 15.0
                by_start[start] = settled_cycle(result.trajectory.x[keep], float(np.median(np.diff(result.trajectory.t))))[0]
            tr = runs[STARTS.index(0.03)].trajectory
            keep = tr.t > 15.0
            dt = float(np.median(np.diff(tr.t)))
            a1, peak, w = settled_cycle(tr.x[keep], dt)
            _, judged = episodes(tr.t, tr.x, tr.y, 2 * math.pi / w0)
            traces[gap] = (tr.t, tr.x, x0)
            rows.append({"gap_cells": gap, "equilibrium_x": x0, "relay_fraction": float(pv.relay[mid].mean()),
                         "jump": float(np.median(jump[found])) if found.any() else 0.0, "N_smooth": float(np.median(N_s)),
                         "predicted_paths": float(np.median(pv.amplitude[mid])), "predicted_one_jump": float(np.median(one)),
                         "predicted_profile": float(np.median(profile)), "first_harmonic": a1, "peak": peak,
                         "episodes_amplitude": judged, "omega": w, "omega_critical": w0, "mean_x": float(tr.x[keep].mean()),
                         "first_harmonic_by_start": {f"{k:+.2f}": (v if v > 1e-4 else 0.0) for k, v in by_start.items()}})
    return rows, traces


def _print(loop_rows, map_rows) -> None:
    print("loop level: first harmonic of the settled cycle against the describing function (|J| = 0.1)")
    print(f"{'robot':10s} {'hold':9s} d {'Ns/N*':>5s} {'m*':>5s} {'DF new':>8s} {'DF old':>8s} {'sim a1':>8s} {'peak':>8s} "
          f"{'err new':>8s} {'err old':>8s} {'ω/ω*':>6s}")
    for r in loop_rows:
        print(f"{r['robot']:10s} {r['hold']:9s} {r['compute_delay']} {r['N_smooth_over_N_critical']:+5.1f} {r['half_period_samples']:5.1f} "
              f"{r['predicted']:8.4f} {r['previous']:8.4f} {r['first_harmonic']:8.4f} {r['peak']:8.4f} {100 * r['error']:+7.1f}% "
              f"{100 * r['previous_error']:+7.1f}% {1 + r['omega_error']:6.3f}")
    print("\nmap level: CARMEL in an aisle (wall | gap cells | rack), amplitudes in m")
    print(f"{'gap':>4s} {'x_eq':>6s} {'J':>6s} {'N_s':>6s} {'paths.py':>9s} {'one jump':>9s} {'profile':>8s} {'sim a1':>7s} "
          f"{'peak':>7s} {'episodes':>9s} {'ω/ω*':>6s}")
    for r in map_rows:
        print(f"{r['gap_cells']:4d} {r['equilibrium_x']:6.3f} {r['jump']:6.3f} {r['N_smooth']:6.3f} {r['predicted_paths']:9.4f} "
              f"{r['predicted_one_jump']:9.4f} {r['predicted_profile']:8.4f} {r['first_harmonic']:7.4f} {r['peak']:7.4f} "
              f"{r['episodes_amplitude']:9.4f} {r['omega'] / r['omega_critical']:6.3f}")
    print("\nmap level: the simulator's settled first harmonic (m) against the start offset from the equilibrium (m)")
    for r in map_rows:
        print(f"{r['gap_cells']:4d} " + "  ".join(f"{k}: {v:.3f}" for k, v in r["first_harmonic_by_start"].items()))


def _figure(loop_rows, map_rows, traces, out: Path) -> Path:
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.5))
    for fraction, marker in ((0.0, "o"), (0.6, "s"), (-0.3, "^")):
        sel = [r for r in loop_rows if r["N_smooth_over_N_critical"] == fraction]
        a.scatter([r["half_period_samples"] for r in sel], [100 * r["error"] for r in sel], marker=marker,
                  label=f"2|J|/(π(N* − N_s)), N_s = {fraction:+.1f} N*")
        if fraction == 0.6:
            a.scatter([r["half_period_samples"] for r in sel], [100 * r["previous_error"] for r in sel], marker="x", color="0.4",
                      label="2|J|/(πN*) with N_s = 0.6 N*")
    a.axhline(0, color="k", lw=0.8)
    a.set_xlabel("samples per half-period at ω*")
    a.set_ylabel("simulated first harmonic / predicted − 1, %")
    a.set_title("loop level: sampled loop with a relay")
    a.legend(fontsize=7)
    gap = 32 if 32 in traces else next(iter(traces))
    t, x, x0 = traces[gap]
    r = next(r for r in map_rows if r["gap_cells"] == gap)
    b.plot(t, x, lw=0.8, label="VFF simulator")
    for key, style, label in (("predicted_paths", ":", "paths.py: 2|J|/(πN*)"), ("predicted_one_jump", "--", "2|J|/(π(N* − N_s))"),
                              ("predicted_profile", "-", "window_cycle (whole profile)")):
        for sign in (1, -1):
            b.axhline(r["mean_x"] + sign * r[key], ls=style, color="C3" if key == "predicted_profile" else "0.4", lw=1.0,
                      label=label if sign == 1 else None)
    b.set_xlabel("t, s")
    b.set_ylabel("x across the aisle, m (lines: mean ± predicted)")
    b.set_title(f"map level: CARMEL, {gap}-cell aisle (wall | rack)")
    lo, hi = b.get_ylim()
    b.set_ylim(lo - 0.45 * (hi - lo), hi)  # room for the legend under the trace
    b.legend(fontsize=7, loc="lower right", ncol=2)
    fig.tight_layout()
    return save_figure(fig, out / "relay_amplitude.png")


def run(out, quick: bool = False) -> dict:
    out = output_dir(out)
    loop_rows = loop_level(quick)
    map_rows, traces = map_level(GAPS[2:4] if quick else GAPS)
    _print(loop_rows, map_rows)
    _figure(loop_rows, map_rows, traces, out)
    carmel = [r for r in loop_rows if r["robot"] == "CARMEL" and r["N_smooth_over_N_critical"] >= 0]
    worst = max(abs(r["error"]) for r in carmel)
    aisle = next((r for r in map_rows if r["gap_cells"] == 32), map_rows[0])
    finding = (f"relay at CARMEL: first harmonic within {100 * worst:.1f} % of 2|J|/(π(N* − N_s)) (N_s >= 0); "
               f"aisle {aisle['gap_cells']} cells: simulator {aisle['first_harmonic']:.3f} m, window_cycle {aisle['predicted_profile']:.3f} m, "
               f"paths.py {aisle['predicted_paths']:.3f} m")
    result = {"finding": finding, "loop": loop_rows, "map": map_rows,
              "rows": [row("relay_amplitude", "relay cycle, sampled loop (CARMEL, 4 structures)", "-", "2|J|/(π(N* − N_s))",
                           f"within {100 * worst:.1f} %", "first harmonic; N_s = 0 and 0.6 N*"),
                       row("relay_amplitude", f"aisle of {aisle['gap_cells']} cells beside a rack", "-",
                           f"window_cycle {aisle['predicted_profile']:.3f} m (paths.py {aisle['predicted_paths']:.3f} m)",
                           f"{aisle['first_harmonic']:.3f} m", "VFF simulator, grid law")]}
    write_json(out / "relay_amplitude.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
