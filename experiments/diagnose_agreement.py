"""How often ``diagnose`` gets a corridor right: the measured frequency against the truth's, the predicted verdict against
the sign of the measured growth, and — on MuJoCo robots — the predicted V* against the boundary bisected in MuJoCo
(docs/diagnose.md, "Numbers").

**The VFF simulator** (default): each run is a random corridor (even runs) or wall (odd runs) of
`tests/log_helpers.random_corridor` (the ``sampled`` model's margin beyond ±5 %), driven by the project's VFF simulator
and written as an MCAP bag with 360-beam scans, odometry at 50 Hz and 2 % dropped messages; ``diagnose`` reads it back
with the run's own k, W, f, n, τ and T.

**MuJoCo** (``--mujoco``): robots A (``diffdrive``), B (``diffdrive-filtered``: an actuator filter) and C (``skid-steer``
behind Nav2's velocity smoother, 2 rad/s², with a controller at 11 Hz ± 15 % and 20-Hz odometry ± 10 %; docs/mujoco.md).
For each robot and corridor: (1) the plant is identified as a user would — an open-loop drive of steps and a chirp
logged as a CSV, ``identify`` on the gyro's rate — at 0.8 m/s, then again at the speed of the boundary it predicts,
twice (the plant depends on the speed); (2) MuJoCo's V* is bisected (30-s runs, a 1 % bracket) from a start 1 cm and
5 cm off the centre line; (3) corridor runs at 0.85 and 1.15 times the 1-cm V* (from 5 cm off, 30 s) are logged as
bags and diagnosed with k, W, f, n, the identified plant (g, τ, D, τ_a, the slew limit, the slide τ_s) and the grid's law: the
verdicts, the measured ω (crossings, with its interval) against the ``sampled`` model's, and diagnose's ``sampled``
V* against MuJoCo's. Writes ``DIR/diagnose_mujoco.json``, ``.md`` and ``.png``.

    python experiments/diagnose_agreement.py [--runs 40] [--seed 0] [--kind both|corridor|wall]
    python experiments/diagnose_agreement.py --mujoco --out-dir DIR [--robots A B C] [--quick]
    python experiments/diagnose_agreement.py --command-path --out-dir DIR [--quick]

``--command-path``: robot C's MuJoCo V* behind a smoother whose limit never binds, a 25-ms command delay, or neither
(`run_command_path`; docs/mujoco.md, "The command path"). Writes ``DIR/command_path.json``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def check(seed: int, directory, kind: str = "corridor") -> dict:
    """One run: the measured and true ω, the measured σ, the predicted verdict and the margin."""
    from log_helpers import corridor_run
    from pfm_stability.analysis.stretches import wall_lines_batch
    from pfm_stability.io.logs import read_log
    from pfm_stability.validation.diagnose import diagnose

    path, robot, controller, geometry, margin, truth = corridor_run(seed, directory, kind=kind)
    log = read_log(path, need=("pose", "scan"), scan_reducer=wall_lines_batch, scan_batch=256)
    result = diagnose(log, robot, controller)
    s = result.judged
    row = {"seed": seed, "kind": kind, "margin": margin, "true_omega": truth.metrics.angular_frequency, "true_sigma": truth.metrics.growth_rate,
           "judged": s is not None}
    if s is not None:
        row.update(omega=s.measured.omega, sigma=s.measured.sigma, measured_stable=s.measured.stable,
                   predicted_stable=s.predicted["sampled"].stable, matching=s.matching, measured_kind=s.stretch.kind)
    else:
        row["reason"] = result.reason
    return row


# ------------------------------------------------------------------------------------------ MuJoCo robots A, B, C
K, F, N, W = 2.0, 3.0, 2.0, 0.5
OFFSETS = (0.01, 0.05)
"""The bisections' starts off the centre line (m): a small disturbance, and one the slew limit acts on."""


def mujoco_robots() -> dict:
    """Robot → (MJCF name, controller period T in s, corridors L in m, engine options, identification drive)."""
    from pfm_stability.engines.command_path import Timing, VelocitySmoother

    nav2 = dict(smoother=VelocitySmoother(max_accel=2.0, max_decel=2.0), timing=Timing(period_jitter=0.15, odom_rate=20.0,
                                                                                        odom_jitter=0.1, seed=1))
    return {"A": ("diffdrive", 0.1, (0.9,), {}, dict(T=0.05, amplitude=0.1)),
            "B": ("diffdrive-filtered", 0.1, (0.9, 0.7), {}, dict(T=0.05, amplitude=0.1)),
            "C": ("skid-steer", 1 / 11, (0.7, 0.9), nav2, dict(T=1 / 11, amplitude=0.3))}


def identify_mujoco(name: str, options: dict, drive: dict, V: float, out_dir) -> dict:
    """Drive the robot open loop at V (steps then a chirp, 60 s), log it as a CSV and identify it (the gyro's rate)."""
    from pfm_stability.analysis.identification import identify
    from pfm_stability.engines.mujoco import EngineOptions, drive_log, write_csv_log
    from pfm_stability.io.logs import read_log

    log = drive_log("both", options=EngineOptions(robot_model=name, **options), V=V, duration=60.0, **drive)
    path = Path(out_dir) / f"{name}_V{V:.2f}_identify.csv"
    write_csv_log(log, path)
    result = identify(read_log(path, need=("command", "imu"), optional=("pose",)), "imu")
    p = result.plant
    none = lambda e: None if e is None else e.to_dict()  # noqa: E731
    return {"V": V, "model": p.model, "g": p.g.to_dict(), "tau": p.tau.to_dict(), "dead_time": p.dead_time.to_dict(),
            "actuator_lag": none(p.actuator_lag), "yaw_accel_limit": none(p.yaw_accel_limit), "r2": p.quality.r2,
            "smoother": none(p.smoother), "loop_dead_time": p.loop_dead_time,
            "slip_lag": None if result.slip is None else result.slip.slip_lag.to_dict(),
            "T": result.controller.T, "csv": path.name,
            "candidates": {m.model: {"g": m.parameters.g, "tau": m.parameters.tau, "dead_time": m.parameters.dead_time,
                                     "actuator_lag": m.parameters.actuator_lag, "bic": m.bic} for m in p.models}}


def mujoco_pair(plant: dict, T: float, V: float = 1.0):
    """The robot and controller the predictions use: the identified plant (τ_a and the slew limit when selected)."""
    from pfm_stability.parameters import Controller, Robot

    extra = {}
    if plant["actuator_lag"] is not None:
        extra["actuator_lag"] = plant["actuator_lag"]["value"]
    if plant["yaw_accel_limit"] is not None:
        extra["yaw_accel_limit"] = plant["yaw_accel_limit"]["value"]
    if plant.get("slip_lag") is not None:
        extra["slip_lag"] = max(plant["slip_lag"]["value"], 0.0)
    wait = plant["smoother"]["mean_wait"] if plant.get("smoother") else 0.0  # a small command's wait for the smoother's tick
    robot = Robot(V=V, tau=plant["tau"]["value"], k=K, W=W, plant_gain=plant["g"]["value"],
                  dead_time=max(plant["dead_time"]["value"] + wait, 0.0), **extra)
    return robot, Controller(f=F, n=N, T=T, hold="command", compute_delay=1)


def predicted_V(plant: dict, T: float, L: float) -> float:
    """The ``sampled`` model's V* with the identified plant and the grid's law."""
    from pfm_stability.validation.common import predicted_boundaries, scenario_law, validation_models

    robot, controller = mujoco_pair(plant, T)
    law = scenario_law("grid", robot, controller)
    return float(predicted_boundaries("corridor", "V", robot, controller, law, L, validation_models(controller))["sampled"])


def limited_V(robot, controller, L: float, offset: float):
    """V*(D) of the sampled loop with the identified slew limit for a start `offset` m off (the limiter's describing
    function, `analysis.disturbance`); None without a limit."""
    import math

    from pfm_stability.analysis.disturbance import corridor_disturbance
    from pfm_stability.sim.scenario import scenario_law

    if not math.isfinite(robot.yaw_accel_limit):
        return None
    V = corridor_disturbance(robot, controller, scenario_law("grid", robot, controller), L, offset).V_disturbance
    return float(V) if V is not None and math.isfinite(V) else None


def diagnose_run(name: str, options: dict, plant: dict, T: float, L: float, V: float, out_dir) -> dict:
    """A 30-s corridor run at V from 5 cm off, logged as a bag, diagnosed with the identified plant and the grid's law."""
    from log_helpers import Plant, Recording, SyntheticLog, write_ros2
    from pfm_stability.analysis.stretches import wall_lines_batch
    from pfm_stability.engines.mujoco import EngineOptions, corridor_log
    from pfm_stability.io.logs import read_log
    from pfm_stability.sim.presets import make_scenario
    from pfm_stability.sim.scenario import scenario_law
    from pfm_stability.validation.diagnose import diagnose

    robot, controller = mujoco_pair(plant, T, V)
    run = corridor_log(make_scenario("corridor", env="grid", robot=robot, controller=controller, L=L, offset=0.05, duration=30.0),
                       EngineOptions(robot_model=name, **options))
    synthetic = SyntheticLog(Plant(), Recording(T=T, scan_rate=10.0), run.cmd_t, run.cmd_wz, run.cmd_vx, run.odom_t, run.odom_wz,
                             scan_t=run.scan_t, odom_x=run.odom_x, odom_y=run.odom_y, odom_yaw=run.odom_yaw,
                             odom_vx=run.odom_vx, scan_ranges=run.scan_ranges)
    bag = Path(out_dir) / f"{name}_L{L:g}_V{V:.3f}"
    shutil.rmtree(bag, ignore_errors=True)  # a bag of an earlier run of the experiment
    bag = write_ros2(synthetic, bag, storage="mcap")
    log = read_log(bag, need=("command", "pose", "scan"), scan_reducer=wall_lines_batch, scan_batch=256)
    result = diagnose(log, robot, controller, law=scenario_law("grid", robot, controller), models=("sampled",))
    s = result.judged
    row = {"V": V, "judged": s is not None, "verdict": result.verdict, "collided": run.run.collided}
    if s is not None:
        m, p = s.measured, s.predicted["sampled"]
        f = m.frequency
        row.update(measured_stable=m.stable, predicted_stable=p.stable, sigma=m.sigma, omega=m.omega,
                   omega_interval=None if f is None or f.low is None else [f.low, f.high], omega_predicted=p.omega,
                   sigma_predicted=p.sigma, V_critical=p.V_critical, V_measured=s.V, L_measured=s.geometry,
                   limiter=None if result.limiter is None else result.limiter.to_dict())
    return row


def mujoco_case(key: str, L: float, quick: bool, out_dir) -> dict:
    """One robot in one corridor: identify at the boundary, bisect MuJoCo's V* from 1 and 5 cm, diagnose two runs."""
    from pfm_stability.engines.mujoco import EngineOptions, MujocoRuns
    from pfm_stability.validation import validate_boundary

    name, T, _, options, drive = mujoco_robots()[key]
    started = time.perf_counter()
    plant = identify_mujoco(name, options, drive, 0.8, out_dir)
    for _ in range(2):  # the plant at the speed of the boundary it predicts
        plant = identify_mujoco(name, options, drive, round(predicted_V(plant, T, L), 2), out_dir)
    robot, controller = mujoco_pair(plant, T)
    bisections = {}
    for offset in OFFSETS:
        v = validate_boundary("corridor", "V", robot=robot, controller=controller, env="grid", L=L, offset=offset,
                              duration=15.0 if quick else 30.0, rtol=0.03 if quick else 0.01, members=7,
                              runner=MujocoRuns.factory(EngineOptions(robot_model=name, **options)))
        limited = limited_V(robot, controller, L, offset)
        bisections[str(offset)] = {"V_mujoco": v.simulated_boundary, "bracket": list(v.bracket), "runs": v.runs,
                                   "sampled": v.predicted_boundary["sampled"], "error": v.relative_error["sampled"],
                                   "limited": limited, "limited_error": None if limited is None else limited / v.simulated_boundary - 1}
    V_star = bisections[str(OFFSETS[0])]["V_mujoco"]
    runs = [diagnose_run(name, options, plant, T, L, factor * V_star, out_dir) for factor in (0.85, 1.15)]
    return {"robot": key, "model": name, "L": L, "T": T, "plant": plant, "predicted_with": plant,
            "first_order_V": predicted_V({**plant, **{k: {"value": v} for k, v in plant["candidates"]["first_order"].items()
                                                       if k != "bic" and k != "actuator_lag"}, "actuator_lag": None,
                                          "yaw_accel_limit": None}, T, L) if plant["candidates"] else None,
            "without_slide_V": predicted_V({**plant, "slip_lag": None}, T, L),
            "bisections": bisections, "diagnosed": runs, "seconds": time.perf_counter() - started}


def mujoco_table(cases) -> str:
    """The Markdown table of docs/diagnose.md and docs/mujoco.md."""
    head = ("| robot | L (m) | plant identified | V* MuJoCo 1 cm | V* MuJoCo 5 cm | sampled V* (gap to 1 cm) | without the slide (gap) | "
            "with the limit V*(1 cm), "
            "V*(5 cm) (gaps) | diagnose V* at 0.85·V* (gap) | verdicts 0.85 / 1.15 | ω measured / predicted at 1.15 |")
    out = [head, "|" + " --- |" * (head.count("|") - 1)]
    for c in cases:
        p = c["plant"]
        extra = (f", τ_a {p['actuator_lag']['value']:.3f} s" if p["actuator_lag"] else "") + \
                (f", A {p['yaw_accel_limit']['value']:.2f} rad/s²" if p["yaw_accel_limit"] else "") + \
                (f"; slide τ_s {1000 * p['slip_lag']['value']:.2f} ms" if p.get("slip_lag") else "")
        plant = f"{p['model']}: g {p['g']['value']:.3f}, τ {p['tau']['value']:.3f} s, D {1000 * p['dead_time']['value']:.0f} ms{extra}"
        b1, b5 = c["bisections"][str(OFFSETS[0])], c["bisections"][str(OFFSETS[1])]
        low, high = c["diagnosed"]
        verdict = lambda r: ("—" if not r["judged"] else  # noqa: E731
                             f"{'stable' if r['measured_stable'] else 'unstable'}/{'stable' if r['predicted_stable'] else 'unstable'}")
        diag = f"{low['V_critical']:.3f} ({100 * (low['V_critical'] / b1['V_mujoco'] - 1):+.1f} %)" if low["judged"] else "—"
        omega = (f"{high['omega']:.3f} / {high['omega_predicted']:.3f} ({100 * (high['omega_predicted'] / high['omega'] - 1):+.1f} %)"
                 if high["judged"] and high["omega"] and high["omega_predicted"] else "—")
        limited = (f"{b1['limited']:.3f} ({100 * b1['limited_error']:+.1f} %), {b5['limited']:.3f} ({100 * b5['limited_error']:+.1f} %)"
                   if b1.get("limited") is not None and b5.get("limited") is not None else "—")
        out.append(f"| {c['robot']} ({c['model']}) | {c['L']:g} | {plant} | {b1['V_mujoco']:.3f} | {b5['V_mujoco']:.3f} | "
                   f"{b1['sampled']:.3f} ({100 * b1['error']:+.1f} %) | {c['without_slide_V']:.3f} "
                   f"({100 * (c['without_slide_V'] / b1['V_mujoco'] - 1):+.1f} %) | {limited} | {diag} | {verdict(low)}, {verdict(high)} | {omega} |")
    return "\n".join(out) + "\n"


def mujoco_figure(cases, path) -> None:
    """Left: every case's predicted V* against MuJoCo's from 1 and 5 cm; right: measured against predicted ω."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from pfm_stability.io.files import save_figure

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 5))
    labels = [f"{c['robot']} L={c['L']:g}" for c in cases]
    x = range(len(cases))
    for offset, marker in zip(OFFSETS, "os"):
        a1.scatter(x, [100 * (c["bisections"][str(OFFSETS[0])]["sampled"] / c["bisections"][str(offset)]["V_mujoco"] - 1)
                       for c in cases], marker=marker, s=50, label=f"sampled V* vs MuJoCo from {100 * offset:g} cm")
    a1.scatter(x, [100 * (c["diagnosed"][0]["V_critical"] / c["bisections"][str(OFFSETS[0])]["V_mujoco"] - 1)
                   if c["diagnosed"][0]["judged"] else float("nan") for c in cases], marker="x", s=60, c="k",
               label="diagnose's V* (run at 0.85·V*) vs MuJoCo from 1 cm")
    a1.axhspan(-3, 3, color="0.85", zorder=0, label="±3 %")
    a1.axhline(0, color="k", lw=0.8)
    a1.set_xticks(list(x), labels, rotation=30, ha="right")
    a1.set(ylabel="(predicted − MuJoCo)/MuJoCo (%)", title="corridor boundary V*: the identified plant's prediction")
    a1.legend(fontsize=8)
    for c in cases:
        for r, marker in zip(c["diagnosed"], "o^"):
            if r["judged"] and r["omega"] and r["omega_predicted"]:
                lo, hi = r["omega_interval"] or (r["omega"], r["omega"])
                a2.errorbar(r["omega"], r["omega_predicted"], xerr=[[r["omega"] - lo], [hi - r["omega"]]], fmt=marker, capsize=3,
                            label=f"{c['robot']} L={c['L']:g} at {r['V']:.2f} m/s")
    lim = a2.get_xlim()
    a2.plot(lim, lim, "k-", lw=0.8)
    a2.fill_between(lim, [0.95 * v for v in lim], [1.05 * v for v in lim], color="0.85", zorder=0)
    a2.set(xlabel="ω measured by diagnose (rad/s; bars: 95 % interval)", ylabel="ω of the sampled model (rad/s)",
           title="oscillation frequency (grey: ±5 %)")
    a2.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=110, what="figure")


def run_mujoco(out_dir, robots, quick: bool) -> int:
    """Every robot's cases (`mujoco_case`), their table, JSON and figure."""
    from pfm_stability.io.files import write_text

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cases = []
    for key in robots:
        for L in mujoco_robots()[key][2][:1 if quick else None]:
            case = mujoco_case(key, L, quick, out)
            cases.append(case)
            b = case["bisections"]
            print(f"robot {key} L={L:g}: plant {case['plant']['model']}, V* MuJoCo {b['0.01']['V_mujoco']:.3f} (1 cm), "
                  f"{b['0.05']['V_mujoco']:.3f} (5 cm); sampled {b['0.01']['sampled']:.3f} ({100 * b['0.01']['error']:+.1f} %); "
                  f"{case['seconds']:.0f} s", flush=True)
    write_text(out / "diagnose_mujoco.json", json.dumps({"cases": cases}, indent=2, default=str), what="results")
    write_text(out / "diagnose_mujoco.md", mujoco_table(cases), what="table")
    mujoco_figure(cases, out / "diagnose_mujoco.png")
    print(mujoco_table(cases))
    return 0


COMMAND_PATH_VARIANTS = ("smoother that never binds", "25-ms command delay", "neither")
"""Robot C's command path three ways (``--command-path``): Nav2's 20-Hz smoother with a limit of 1e5 rad/s², which never
binds (only its tick's wait acts), no smoother but a 25-ms command dead time (half the tick, the wait's mean), and
neither (docs/mujoco.md, "The command path")."""


def run_command_path(out_dir, quick: bool) -> int:
    """Robot C's MuJoCo V* (L = 0.7 m, a 1-cm start, 30-s runs, a 1 % bracket; its controller's timing, its
    identified τ 0.132 s and g 0.296 for the predictions beside it) with each of `COMMAND_PATH_VARIANTS`: a smoother
    whose limit never binds is a wait. Writes ``DIR/command_path.json``."""
    from pfm_stability.engines.command_path import VelocitySmoother
    from pfm_stability.engines.mujoco import EngineOptions, MujocoRuns
    from pfm_stability.io.files import write_text
    from pfm_stability.parameters import Controller, Robot
    from pfm_stability.validation import validate_boundary

    name, T, _, options, _ = mujoco_robots()["C"]
    engines = dict(zip(COMMAND_PATH_VARIANTS, (dict(smoother=VelocitySmoother(max_accel=1e5, max_decel=1e5)),
                                               dict(command_delay=0.025), {})))
    robot = Robot(V=1.0, tau=0.132, k=K, W=W, plant_gain=0.296)
    controller = Controller(f=F, n=N, T=T, hold="command", compute_delay=1)
    results = {}
    for key, engine in engines.items():
        v = validate_boundary("corridor", "V", robot=robot, controller=controller, env="grid", L=0.7, offset=0.01,
                              duration=15.0 if quick else 30.0, rtol=0.03 if quick else 0.01, members=7,
                              runner=MujocoRuns.factory(EngineOptions(robot_model=name, timing=options["timing"], **engine)))
        results[key] = {"V_mujoco": v.simulated_boundary, "bracket": list(v.bracket), "runs": v.runs}
        print(f"robot C, {key}: V* MuJoCo {v.simulated_boundary:.3f} m/s [{v.bracket[0]:.3f}, {v.bracket[1]:.3f}]", flush=True)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "command_path.json", json.dumps({"robot": "C", "model": name, "L": 0.7, "offset": 0.01, "T": T,
                                                      "results": results}, indent=2), what="results")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=40)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--kind", choices=("both", "corridor", "wall"), default="both")
    parser.add_argument("--mujoco", action="store_true", help="the MuJoCo robots A, B, C instead of the VFF simulator")
    parser.add_argument("--out-dir", default="out/diagnose_mujoco")
    parser.add_argument("--robots", nargs="+", choices=("A", "B", "C"), default=["A", "B", "C"])
    parser.add_argument("--quick", action="store_true", help="MuJoCo: one corridor per robot, 15-s runs, a 3 % bracket")
    parser.add_argument("--command-path", action="store_true",
                        help="MuJoCo: robot C behind a smoother that never binds, a 25-ms delay, or neither")
    args = parser.parse_args(argv)
    if args.command_path:
        return run_command_path(args.out_dir, args.quick)
    if args.mujoco:
        return run_mujoco(args.out_dir, args.robots, args.quick)
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for i in range(args.runs):
            kind = args.kind if args.kind != "both" else ("corridor", "wall")[i % 2]
            row = check(args.seed + i, directory, kind)
            rows.append(row)
            if row["judged"]:
                err = (row["omega"] / row["true_omega"] - 1) if row["omega"] and row["true_omega"] else None
                print(f"seed {row['seed']:3d} {row['kind']:8s}: margin {100 * row['margin']:+6.1f} %, ω {row['omega'] or float('nan'):.3f} "
                      f"vs {row['true_omega'] or float('nan'):.3f} ({'—' if err is None else f'{100 * err:+.2f} %'}), "
                      f"σ {row['sigma'] if row['sigma'] is not None else float('nan'):+.4f} vs {row['true_sigma'] or float('nan'):+.4f}, "
                      f"predicted {'stable' if row['predicted_stable'] else 'unstable'}, measured {'stable' if row['measured_stable'] else 'unstable'}, "
                      f"matching {row['matching']}")
            else:
                print(f"seed {row['seed']:3d}: not judged: {row['reason']}")
    judged = [r for r in rows if r["judged"]]
    agree = sum(r["predicted_stable"] == r["measured_stable"] for r in judged)
    errors = [abs(r["omega"] / r["true_omega"] - 1) for r in judged if r["omega"] and r["true_omega"]]
    print(f"\n{len(judged)} of {len(rows)} runs judged; verdicts agree {agree}/{len(judged)} "
          f"({100 * agree / max(len(judged), 1):.1f} %); ω within 5 % of the simulator's: "
          f"{sum(e <= 0.05 for e in errors)}/{len(errors)} (largest error {100 * max(errors, default=0):.2f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
