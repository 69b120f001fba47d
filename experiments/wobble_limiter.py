"""The wobble with the drive's yaw acceleration limit: describing functions before and after the limiter's (docs/wobble.md).

A seeded set of corridor robots — half with a velocity smoother limiting the commanded yaw rate's change (R from 1 to
6 rad/s²), half without; fast and slow motors, steering-rate limits from 60 to 200°/s, dead times, both compute
delays, the power and the grid's law, corridors from 0.25 to 0.8 m of play — each simulated at a speed past V* from a
start at 5 % of the clearance (the batched VFF simulator with the smoother, `validation.wobble.simulate_wobbles`).
Where the simulator settles on a steady cycle clear of the walls (a "cycle" below), three predictions of
`report --wobble`:

* **before**: what `report --wobble` gave before the limiter was modelled: the robot's limit left out, and a cycle
  where the steering-rate limit shapes the heading refused (the branch without its heading-limited companion);
* **after**: with the limiter's describing function on the command (`analysis.wobble.limited_branch`) and, where the
  steering-rate limit of a held command shapes the heading, that limit as the heading's rate limit
  (`analysis.wobble.reported_cycle`);

each either a number (a trusted cycle, `analysis.wobble.trusted_cycle`) or "not given" (with the reason). The table
counts the cycles each gives a number for and how many of those are within 15 % of the simulated amplitude. The same
for the 30 random robots of experiments/wobble_amplitude.py (no limit) at 1.05–1.5·V*.

Then the boundary for a start of a given size (`report --disturbance`): V*(D) predicted by the branch
(`analysis.disturbance.disturbance_speed`) against the simulator's, bisected to 1 % (`validation.disturbance`), for
CARMEL with a 2 rad/s² smoother in the 0.9 m corridor and for a skid-steer-like robot (11 Hz, a period of compute
delay, 40 ms dead time, 2 rad/s²) in a narrow corridor (0.35 m of play).

    python experiments/wobble_limiter.py --out experiments/results [--quick]
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import output_dir, row, save_figure, script_main, write_json  # noqa: E402

from pfm_stability.analysis.wobble import THIRD_HARMONIC_LIMIT, corridor_branch, corridor_wobble  # noqa: E402
from pfm_stability.parameters import CARMEL  # noqa: E402
from pfm_stability.validation.disturbance import disturbance_boundary  # noqa: E402
from pfm_stability.parameters import Controller, Robot  # noqa: E402
from pfm_stability.validation.wobble import WobbleCase, case_law, simulate_wobbles  # noqa: E402

TOLERANCE = 0.15
"""Within this fraction of the simulated amplitude counts as right (the issue's bar)."""


def robots(count: int, seed: int = 41) -> list:
    """`count` corridor robots (Robot, Controller, L, law, V/V*): every other one with a yaw acceleration limit."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        W = rng.uniform(0.4, 0.8)
        limited = i % 2 == 1
        hold = "command" if limited or i % 4 == 0 else "reference"
        robot = Robot(V=1.0, tau=rng.uniform(0.05, 0.5), k=rng.uniform(1.0, 4.0), W=W, max_steering_rate=math.radians(rng.uniform(60.0, 200.0)),
                      yaw_accel_limit=rng.uniform(1.0, 6.0) if limited else math.inf,
                      dead_time=float(rng.choice([0.0, rng.uniform(0.01, 0.08)])) if hold == "command" else 0.0, plant_gain=rng.uniform(0.8, 1.2))
        controller = Controller(f=rng.uniform(0.5, 3.0), n=float(rng.choice([1.0, 2.0, 3.0])), T=rng.uniform(0.03, 0.1), hold=hold,
                                compute_delay=int(rng.integers(0, 2)))
        out.append((robot, controller, W / 2 + rng.uniform(0.25, 0.8), ("power", "grid")[i % 3 == 0], rng.uniform(1.03, 1.4)))
    return out


BEFORE_RATE_HARMONIC_LIMIT = 0.02
"""The one rate-harmonic limit of `report --wobble` before (both holds)."""


def _before(branch, V: float) -> dict:
    """What `report --wobble` said before the limiter was modelled, from the branch without the limit: 0 below V*, None on a
    subcritical branch past its fold, at a wall, or where the third harmonic passed 0.1 or the rate limit's 0.02; else the
    stable cycle's amplitude (the rules of `analysis.wobble._wobble_at` then)."""
    stable = [c for c in branch.cycles_at(V) if c.stable]
    out = {"amplitude": None, "omega": None, "third_harmonic": None, "rate_harmonic": None, "limiter": None}
    if branch.criticality == "subcritical" and V > branch.fold_speed:
        return {**out, "reason": "subcritical"}
    if V <= branch.V_critical:
        return {**out, "amplitude": 0.0, "reason": "below V*"}
    if not stable:
        return {**out, "reason": "wall"}
    c = stable[0]
    out.update(third_harmonic=c.third_harmonic, rate_harmonic=c.rate_harmonic)
    if not c.third_harmonic <= THIRD_HARMONIC_LIMIT:
        return {**out, "reason": "strong harmonics"}
    if not c.rate_harmonic <= BEFORE_RATE_HARMONIC_LIMIT:
        return {**out, "reason": "the steering-rate limit shapes the heading"}
    return {**out, "amplitude": c.amplitude, "omega": c.omega, "reason": None}


def _prediction(wobble) -> dict:
    return {"amplitude": wobble.amplitude if wobble.amplitude else None, "omega": wobble.omega, "reason": wobble.reason,
            "third_harmonic": wobble.third_harmonic, "rate_harmonic": wobble.rate_harmonic,
            "limiter": list(wobble.limiter) if wobble.limiter is not None else None}


def earlier_robots(count: int) -> list:
    """The random robots of experiments/wobble_amplitude.py (none with a yaw acceleration limit) at 1.05, 1.2, 1.35, 1.5·V*."""
    from wobble_amplitude import SPEED_RATIOS, random_robots

    return [(robot, controller, L, law, ratio) for robot, controller, L, law in random_robots(count) for ratio in SPEED_RATIOS]


def check(members) -> dict:
    """Simulate every robot at its speed and predict its wobble before and after the limiter's describing function."""
    cases, meta = [], []
    for robot, controller, L, law_name, ratio in members:
        law = case_law(WobbleCase(robot, controller, L, 0.0, 1.0, law=law_name))
        try:
            branch = corridor_branch(robot, controller, law, L)
        except ValueError:
            continue
        V = ratio * branch.V_critical
        fast = robot.replace(V=V)
        before = _before(corridor_branch(robot.replace(yaw_accel_limit=math.inf), controller, law, L), V)
        after = corridor_wobble(fast, controller, law, L)
        duration = float(np.clip(60 * 2 * math.pi / branch.omega_critical, 60.0, 240.0))
        cases.append(WobbleCase(fast, controller, L, 0.05 * branch.clearance, duration, law=law_name))
        meta.append({"tau": robot.tau, "k": robot.k, "W": robot.W, "max_steering_rate_deg": math.degrees(robot.max_steering_rate),
                     "yaw_accel_limit": robot.yaw_accel_limit if math.isfinite(robot.yaw_accel_limit) else None,
                     "dead_time": robot.dead_time, "plant_gain": robot.plant_gain, "f": controller.f, "n": controller.n, "T": controller.T,
                     "hold": controller.hold, "compute_delay": controller.compute_delay, "L": L, "law": law_name, "ratio": ratio, "V": V,
                     "clearance": branch.clearance, "before": before, "after": _prediction(after)})
    measured = simulate_wobbles(cases)
    for m, item in zip(measured, meta):
        item["simulated"] = {"amplitude": m.amplitude, "omega": m.omega, "collided": m.collided, "steady": m.steady}
        item["cycle"] = bool(not m.collided and m.steady and m.amplitude > 0.002)
        item["before"]["amplitude"] = item["before"]["amplitude"] or None
        for key in ("before", "after"):
            p = item[key]
            p["error"] = (p["amplitude"] / m.amplitude - 1.0) if item["cycle"] and p["amplitude"] else None
    return {"cases": meta}


def summary(cases) -> dict:
    """Counts of the cycles: given a number, within `TOLERANCE`, before and after; and the ones not given before."""
    cycles = [c for c in cases if c["cycle"]]
    out = {"cycles": len(cycles), "limited_cycles": sum(c["yaw_accel_limit"] is not None for c in cycles)}
    for key in ("before", "after"):
        given = [c for c in cycles if c[key]["amplitude"] is not None]
        out[key] = {"given": len(given), "within": sum(abs(c[key]["error"]) <= TOLERANCE for c in given)}
    unreliable = [c for c in cycles if c["before"]["amplitude"] is None]
    out["unreliable_before"] = len(unreliable)
    out["unreliable_given_after"] = sum(c["after"]["amplitude"] is not None for c in unreliable)
    out["unreliable_within_after"] = sum(c["after"]["amplitude"] is not None and abs(c["after"]["error"]) <= TOLERANCE for c in unreliable)
    return out


NARROW = (Robot(V=1.0, tau=0.2, k=3.0, W=0.5, max_steering_rate=math.radians(150.0), dead_time=0.04, plant_gain=0.9, yaw_accel_limit=2.0),
          Controller(f=1.0, n=2.0, T=1 / 11, hold="command", compute_delay=1), 0.6)
DISTURBANCE_SETS = (("CARMEL, 2 rad/s², L = 0.9 m", CARMEL.robot.replace(yaw_accel_limit=2.0), CARMEL.controller, 0.9, (0.01, 0.05, 0.1, 0.15, 0.2, 0.3)),
                    ("skid-steer-like, 2 rad/s², L = 0.6 m", *NARROW, (0.01, 0.03, 0.05, 0.1)))


def disturbance_check(quick: bool) -> list:
    """V*(D) predicted and simulated for every start of `DISTURBANCE_SETS`."""
    out = []
    for name, robot, controller, L, starts in DISTURBANCE_SETS:
        for D in starts[:2] if quick else starts:
            b = disturbance_boundary(D, robot=robot, controller=controller, L=L, members=7, rtol=0.01)
            out.append({"set": name, **b.to_dict()})
    return out


def _figure(cases, path, boundaries=()):
    import matplotlib.pyplot as plt

    cycles = [c for c in cases if c["cycle"]]
    fig, axes = plt.subplots(1, 3, figsize=(17, 5.2))
    for ax, key in zip(axes, ("before", "after")):
        for limited, colour, label in ((False, "C0", "no yaw acceleration limit"), (True, "C3", "with a yaw acceleration limit")):
            pick = [c for c in cycles if (c["yaw_accel_limit"] is not None) == limited]
            given = [c for c in pick if c[key]["amplitude"] is not None]
            missing = [c for c in pick if c[key]["amplitude"] is None]
            ax.plot([c["simulated"]["amplitude"] / c["clearance"] for c in given], [c[key]["amplitude"] / c["clearance"] for c in given], "o",
                    color=colour, mfc="none", label=f"{label}: given")
            ax.plot([c["simulated"]["amplitude"] / c["clearance"] for c in missing], [0.02] * len(missing), "x", color=colour,
                    label=f"{label}: not given")
        line = np.array([0.0, 1.0])
        ax.plot(line, line, "k-", lw=0.8)
        ax.fill_between(line, line * (1 - TOLERANCE), line * (1 + TOLERANCE), color="0.9")
        ax.set(title=f"{key} the limiter's describing function", xlabel="simulated amplitude / (L - W/2)",
               ylabel="report --wobble amplitude / (L - W/2)  (x: not given)", xlim=(0, 1), ylim=(0, 1))
        ax.legend(fontsize=7, loc="upper left")
    ax = axes[2]
    for (name, *_), marker in zip(DISTURBANCE_SETS, ("o", "s")):
        pick = [b for b in boundaries if b["set"] == name]
        ax.plot([b["disturbance"] for b in pick], [b["predicted"] / b["V_critical"] for b in pick], "-", marker=marker, mfc="none",
                label=f"{name}: describing function")
        ax.errorbar([b["disturbance"] for b in pick], [b["simulated"] / b["V_critical"] for b in pick],
                    yerr=[[(b["simulated"] - b["lo"]) / b["V_critical"] for b in pick], [(b["hi"] - b["simulated"]) / b["V_critical"] for b in pick]],
                    fmt=marker, color="k", ms=4, label=f"{name}: simulated (bisected)")
    ax.set(title="the speed at or below which a start of D settles", xlabel="start D, m", ylabel="V*(D) / V* (linear)", ylim=(0, 1.1))
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    save_figure(fig, path)


def run(out, quick: bool = False) -> dict:
    out = output_dir(out)
    started = time.perf_counter()
    result = check(robots(10 if quick else 44))
    earlier = check(earlier_robots(3 if quick else 30))
    s, e = summary(result["cases"]), summary(earlier["cases"])
    boundaries = disturbance_check(quick)
    _figure(result["cases"] + earlier["cases"], out / "wobble_limiter.png", boundaries)
    describe = lambda s: (f"{s['cycles']} simulated cycles ({s['limited_cycles']} with a limit): a number for {s['before']['given']} before "
                          f"({s['before']['within']} within {100 * TOLERANCE:.0f} %), {s['after']['given']} after ({s['after']['within']} "
                          f"within); of the {s['unreliable_before']} not given before, {s['unreliable_given_after']} given after, "
                          f"{s['unreliable_within_after']} within {100 * TOLERANCE:.0f} %")
    worst = max(abs(b["error"]) for b in boundaries)
    finding = (f"this set: {describe(s)}; wobble_amplitude.py's robots: {describe(e)}; V*(D) of {len(boundaries)} starts within "
               f"{100 * worst:.1f} % of the simulator; {time.perf_counter() - started:.0f} s")
    result.update({"summary": s, "earlier": earlier, "earlier_summary": e, "boundaries": boundaries, "finding": finding,
                   "rows": [row("wobble_limiter", "report --wobble with the yaw acceleration limit", "-",
                                f"{s['after']['given']} of {s['cycles']} cycles given", f"{s['after']['within']} within 15 %", finding)]})
    write_json(out / "wobble_limiter.json", result)
    return result


def main(argv=None) -> int:
    return script_main(run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
