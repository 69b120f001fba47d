"""Wobble amplitude past V*: the describing function's limit cycle against the batched VFF simulator (docs/wobble.md).

Two parts:

1. **CARMEL's amplitude against V/V*** in the 0.9 m corridor (L = 0.9 m) — continuous walls with KB's power law,
   continuous walls with the grid's averaged law, and the histogram grid itself; command and reference hold (one sample
   of compute delay, CARMEL's preset); every speed started small (0.02 m) and large (0.8 of the clearance L − W/2),
   so that hysteresis would show. The sampled loop's harmonic-balance branch is drawn over it.
2. **Random corridor robots** (seeded): τ, k, T, f, n ∈ {1, 2, 3}, W, L, the steering-rate limit, the hold and the
   compute delay drawn at random, half with the power law and half with the grid's law (continuous walls), each at
   V = 1.05, 1.2, 1.35 and 1.5·V* started small. Where the describing function predicts a trusted cycle inside the
   corridor and the run did not collide, the amplitude and frequency errors; everywhere, whether both say "cycle" or
   both say "reaches the wall". For every subcritical robot, two runs between the fold and V*: started at 0.7 and 1.3
   times the unstable cycle's amplitude, the first must decay and the second grow (or collide).

Each run lasts 12/σ (σ the sampled model's growth rate at that speed; 60 to 600 s) and is measured over its last 30 %.

    python experiments/wobble_amplitude.py --out experiments/results [--quick]
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

from pfm_stability.analysis.wobble import corridor_branch, trusted_cycle  # noqa: E402
from pfm_stability.laws.force_law import corridor_gain  # noqa: E402
from pfm_stability.models import make_model  # noqa: E402
from pfm_stability.models.loop import Loop  # noqa: E402
from pfm_stability.parameters import CARMEL, Controller, Robot  # noqa: E402
from pfm_stability.validation.wobble import WobbleCase, case_law, simulate_wobbles  # noqa: E402

L_CARMEL = 0.9
SPEED_RATIOS = (1.05, 1.2, 1.35, 1.5)
AMPLITUDE_TOLERANCE = 0.15
FREQUENCY_TOLERANCE = 0.05


def _duration(robot, controller, law, L, V) -> float:
    """12/|σ|, σ the sampled loop's growth rate at V, within [60, 600] s."""
    model = make_model("sampled", hold=controller.hold, compute_delay=controller.compute_delay)
    sigma = model.rightmost_root(corridor_gain(law, L) * V, Loop(robot.tau, controller.T, robot.k)).real
    return float(np.clip(12.0 / abs(sigma), 60.0, 600.0)) if sigma != 0 else 600.0


def random_robots(count: int, seed: int = 2027) -> list:
    """`count` random corridor robots: (Robot, Controller, L, law name)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        W = rng.uniform(0.4, 0.9)
        robot = Robot(V=1.0, tau=rng.uniform(0.1, 0.5), k=rng.uniform(1.0, 4.0), W=W,
                      max_steering_rate=math.radians(rng.uniform(90.0, 240.0)))
        controller = Controller(f=rng.uniform(0.5, 3.0), n=float(rng.choice([1.0, 2.0, 3.0])), T=rng.uniform(0.02, 0.1),
                                hold=("command", "reference")[i % 2], compute_delay=int(rng.integers(0, 2)))
        out.append((robot, controller, W / 2 + rng.uniform(0.3, 1.2), ("power", "grid")[(i // 2) % 2]))
    return out


def carmel_curves(ratios, quick: bool) -> dict:
    """Part 1: predicted branches and simulated amplitudes (small and large starts) for CARMEL."""
    settings = [("analytic", "power"), ("analytic", "grid"), ("grid", "grid")]
    holds = ("command", "reference")
    cases, keys, branches = [], [], {}
    for env, law_name in settings:
        for hold in holds:
            controller = CARMEL.controller.replace(hold=hold)
            probe = WobbleCase(CARMEL.robot, controller, L_CARMEL, 0.0, 1.0, env=env, law=law_name)
            law = case_law(probe)
            branch = corridor_branch(CARMEL.robot, controller, law, L_CARMEL)
            branches[(env, law_name, hold)] = branch
            large = 0.8 * (branch.clearance - (0.05 if env == "grid" else 0.0))
            for ratio in ratios:
                V = ratio * branch.V_critical
                robot = CARMEL.robot.replace(V=V)
                duration = _duration(robot, controller, law, L_CARMEL, V)
                for start in (0.02, large):
                    cases.append(WobbleCase(robot, controller, L_CARMEL, start, duration, env=env, law=law_name))
                    keys.append((env, law_name, hold, ratio, start))
    measured = simulate_wobbles(cases)
    curves = {}
    for (env, law_name, hold, ratio, start), m in zip(keys, measured):
        curves.setdefault((env, law_name, hold), []).append(
            {"ratio": ratio, "start": start, "amplitude": m.amplitude, "omega": m.omega, "collided": m.collided, "steady": m.steady})
    return {"branches": branches, "curves": curves}


def random_check(count: int, ratios) -> dict:
    """Part 2: the random robots against the simulator."""
    robots = random_robots(count)
    cases, meta = [], []
    sub_cases, sub_meta = [], []
    for index, (robot, controller, L, law_name) in enumerate(robots):
        law = case_law(WobbleCase(robot, controller, L, 0.0, 1.0, law=law_name))
        branch = corridor_branch(robot, controller, law, L)
        for ratio in ratios:
            V = ratio * branch.V_critical
            stable = [c for c in branch.cycles_at(V) if c.stable]
            cases.append(WobbleCase(robot.replace(V=V), controller, L, 0.05 * branch.clearance,
                                    _duration(robot, controller, law, L, V), law=law_name))
            meta.append((index, ratio, branch, stable[0] if stable else None))
        if branch.criticality == "subcritical" and branch.fold_speed < branch.V_critical:
            V = 0.5 * (branch.fold_speed + branch.V_critical)
            unstable = [c for c in branch.cycles_at(V) if not c.stable]
            if unstable:
                A_u = unstable[0].amplitude
                for factor in (0.7, 1.3):
                    start = min(factor * A_u, 0.95 * branch.clearance)
                    sub_cases.append(WobbleCase(robot.replace(V=V), controller, L, start, _duration(robot, controller, law, L, V),
                                                law=law_name))
                    sub_meta.append((index, factor, A_u, start))
    measured = simulate_wobbles(cases + sub_cases)
    rows = []
    for (index, ratio, branch, cycle), m, case in zip(meta, measured, cases):
        robot, controller, L, law_name = robots[index]
        predicted_wall = cycle is None
        trusted = cycle is not None and trusted_cycle(cycle) and branch.criticality == "supercritical"
        compared = cycle is not None and not m.collided and m.amplitude > 0
        rows.append({
            "robot": index, "ratio": ratio, "hold": controller.hold, "compute_delay": controller.compute_delay, "law": law_name,
            "criticality": branch.criticality, "V": case.robot.V, "clearance": branch.clearance,
            "predicted_amplitude": None if cycle is None else cycle.amplitude,
            "predicted_omega": None if cycle is None else cycle.omega,
            "third_harmonic": None if cycle is None else cycle.third_harmonic,
            "rate_gain": None if cycle is None else cycle.rate_gain,
            "rate_harmonic": None if cycle is None else cycle.rate_harmonic,
            "trusted": trusted, "predicted_wall": predicted_wall,
            "simulated_amplitude": m.amplitude, "simulated_omega": m.omega, "collided": m.collided, "steady": m.steady,
            "amplitude_error": (cycle.amplitude / m.amplitude - 1) if compared else None,
            "omega_error": (cycle.omega / m.omega - 1) if compared and m.omega else None,
        })
    sub_rows = []
    for (index, factor, A_u, start), m in zip(sub_meta, measured[len(cases):]):
        grew = m.collided or m.amplitude > start
        sub_rows.append({"robot": index, "start_factor": factor, "unstable_amplitude": A_u, "start": start,
                         "final_amplitude": m.amplitude, "collided": m.collided,
                         "as_predicted": (not m.collided and m.amplitude < 0.5 * start) if factor < 1 else grew})
    return {"rows": rows, "subcritical": sub_rows,
            "robots": [{"tau": r.tau, "k": r.k, "W": r.W, "max_steering_rate_deg": math.degrees(r.max_steering_rate), "f": c.f,
                        "n": c.n, "T": c.T, "hold": c.hold, "compute_delay": c.compute_delay, "L": L, "law": law}
                       for r, c, L, law in robots]}


def _figure(carmel, check, path):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 9))
    titles = {("analytic", "power"): "continuous walls, power law", ("analytic", "grid"): "continuous walls, grid law",
              ("grid", "grid"): "histogram grid"}
    for ax, (key, title) in zip(axes[0], titles.items()):
        for hold, colour in (("command", "C0"), ("reference", "C1")):
            branch = carmel["branches"][key + (hold,)]
            ok = np.isfinite(branch.speeds)
            ax.plot(branch.speeds[ok] / branch.V_critical, branch.amplitudes[ok], "-", color=colour, label=f"DF, {hold} hold")
            for point in carmel["curves"][key + (hold,)]:
                small = point["start"] == 0.02
                y = branch.clearance if point["collided"] else point["amplitude"]
                marker = ("o" if small else "x") if not point["collided"] else ("v" if small else "1")
                ax.plot(point["ratio"], y, marker, color=colour, mfc="none" if small else colour, ms=7)
            ax.axhline(branch.clearance, color="0.5", lw=0.8, ls=":")
        ax.plot([], [], "ko", mfc="none", label="simulated, small start")
        ax.plot([], [], "kx", label="simulated, large start")
        ax.plot([], [], "kv", mfc="none", label="collided (drawn at L − W/2)")
        ax.set(title=f"CARMEL, L = {L_CARMEL} m: {title}", xlabel="V / V* (sampled loop)", ylabel="lateral amplitude, m",
               xlim=(0.85, 1.55), ylim=(0, 0.55))
        ax.legend(fontsize=7, loc="upper left")
    rows = check["rows"]
    compared = [r for r in rows if r["amplitude_error"] is not None and r["trusted"]]
    ax = axes[1][0]
    for law, marker in (("power", "o"), ("grid", "s")):
        for hold, colour in (("command", "C0"), ("reference", "C1")):
            pick = [r for r in compared if r["law"] == law and r["hold"] == hold]
            ax.plot([r["simulated_amplitude"] / r["clearance"] for r in pick], [r["predicted_amplitude"] / r["clearance"] for r in pick],
                    marker, color=colour, mfc="none", label=f"{law} law, {hold} hold")
    line = np.array([0, 1])
    ax.plot(line, line, "k-", lw=0.8)
    ax.fill_between(line, line * (1 - AMPLITUDE_TOLERANCE), line * (1 + AMPLITUDE_TOLERANCE), color="0.9")
    ax.set(title=f"{len(check['robots'])} random robots: amplitude / (L − W/2)", xlabel="simulated", ylabel="describing function",
           xlim=(0, 1), ylim=(0, 1))
    ax.legend(fontsize=7)
    ax = axes[1][1]
    ax.plot([r["ratio"] for r in compared], [100 * r["amplitude_error"] for r in compared], "o", mfc="none", label="amplitude")
    ax.plot([r["ratio"] for r in compared], [100 * r["omega_error"] for r in compared], "x", label="frequency")
    for tol in (AMPLITUDE_TOLERANCE, -AMPLITUDE_TOLERANCE):
        ax.axhline(100 * tol, color="C0", ls=":")
    for tol in (FREQUENCY_TOLERANCE, -FREQUENCY_TOLERANCE):
        ax.axhline(100 * tol, color="C1", ls=":")
    ax.set(title="error of the describing function, %", xlabel="V / V*", ylabel="predicted / simulated − 1, %")
    ax.legend(fontsize=7)
    ax = axes[1][2]
    categories = {
        "cycle: both": sum(1 for r in rows if not r["predicted_wall"] and not r["collided"]),
        "wall: both": sum(1 for r in rows if r["predicted_wall"] and r["collided"]),
        "DF cycle\n(not trusted),\nsim wall": sum(1 for r in rows if not r["predicted_wall"] and r["collided"] and not r["trusted"]),
        "DF cycle\n(trusted),\nsim wall": sum(1 for r in rows if not r["predicted_wall"] and r["collided"] and r["trusted"]),
        "DF wall,\nsim cycle": sum(1 for r in rows if r["predicted_wall"] and not r["collided"]),
    }
    bars = ax.bar(range(len(categories)), list(categories.values()), color=["C2", "C2", "0.6", "C3", "C3"])
    ax.bar_label(bars)
    ax.set_xticks(range(len(categories)), list(categories), fontsize=8)
    sub = check["subcritical"]
    ax.set(title=f"cycle or wall, {len(rows)} runs\nsubcritical starts as predicted: {sum(r['as_predicted'] for r in sub)}/{len(sub)}",
           ylabel="runs")
    fig.tight_layout()
    save_figure(fig, path)


def run(out, quick: bool = False) -> dict:
    out = output_dir(out)
    started = time.perf_counter()
    ratios = (0.95, 1.05, 1.2, 1.35, 1.5) if quick else (0.9, 0.95, 1.02, 1.05, 1.1, 1.2, 1.3, 1.4, 1.5)
    carmel = carmel_curves(ratios, quick)
    check = random_check(6 if quick else 30, SPEED_RATIOS[::2] if quick else SPEED_RATIOS)
    _figure(carmel, check, out / "wobble_amplitude.png")
    rows = check["rows"]
    compared = [r for r in rows if r["amplitude_error"] is not None and r["trusted"]]
    worst_A = max((abs(r["amplitude_error"]) for r in compared), default=math.nan)
    worst_w = max((abs(r["omega_error"]) for r in compared if r["omega_error"] is not None), default=math.nan)
    agree = sum(1 for r in rows if r["predicted_wall"] == r["collided"])
    sub = check["subcritical"]
    finding = (f"{len(compared)} trusted cycles of {len(check['robots'])} random robots: amplitude within {100 * worst_A:.1f} %, "
               f"frequency within {100 * worst_w:.1f} %; cycle-or-wall agrees in {agree}/{len(rows)} runs; subcritical starts as "
               f"predicted {sum(r['as_predicted'] for r in sub)}/{len(sub)}; {time.perf_counter() - started:.0f} s")
    carmel_json = {f"{env}/{law}/{hold}": {
        "V_critical": carmel["branches"][(env, law, hold)].V_critical,
        "criticality": carmel["branches"][(env, law, hold)].criticality,
        "runs": points} for (env, law, hold), points in carmel["curves"].items()}
    nominal = [c for c in carmel["branches"][("analytic", "power", "command")].cycles_at(CARMEL.robot.V) if c.stable]
    result = {
        "finding": finding, "carmel": carmel_json, "random": check,
        "rows": [row("wobble_amplitude", "CARMEL cycle at 0.8 m/s, L = 0.9 m", "-",
                     f"{nominal[0].amplitude:.3f} m at {nominal[0].omega:.2f} rad/s" if nominal else "none", "see wobble_amplitude.json",
                     "sampled loop, command hold, compute delay 1"),
                 row("wobble_amplitude", "random robots, V = 1.05-1.5 V*", "-", f"{len(compared)} trusted cycles",
                     f"amplitude within {100 * worst_A:.1f} %, frequency {100 * worst_w:.1f} %", finding)],
    }
    write_json(out / "wobble_amplitude.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
