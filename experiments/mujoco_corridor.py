"""Corridor stability of the project's VFF controller on MuJoCo robots, against every loop model (docs/mujoco.md).

    python experiments/mujoco_corridor.py [--out-dir DIR] [--quick] [--workers 2]

For each shipped robot (``diffdrive``, ``diffdrive-heavy``):

1. **Identify** its steering plant as a user would: drive it open loop with a small yaw-rate command
   (0.1 rad/s steps, then a chirp; `engines.mujoco.drive_log`), write the log as a CSV
   (``DIR/<robot>_V<speed>_identify.csv``, docs/diagnose.md) and run the package's identification on it
   (`analysis.identification.identify`, the gyro's rate): g, τ, D. The plant depends on the speed
   (the gain falls from 0.88 at 0.5 m/s to 0.76 at 1.2 m/s for ``diffdrive``), so it is identified at
   0.8 m/s, then again at the speed of the boundary that plant predicts, twice (`identify_at_boundary`).
2. **Predict and bisect** V* in corridors L ∈ {0.7, 0.9, 1.2} m with T ∈ {0.065, 0.1} s (k = 2 1/s,
   f = 3, n = 2, command hold, one sample of compute delay): `validation.validate_boundary` with the
   MuJoCo runner (`engines.mujoco.MujocoRuns`) bisects MuJoCo's V* and sets every model's prediction
   beside it, the models given the identified plant (`Robot.plant_gain`, `Robot.dead_time`, τ).
3. **Explain the largest gap** of the ``sampled`` model by runs that each remove one effect: the
   wheel motors' torque limit (rate limit), the casters' friction (caster drag; the plant
   re-identified), the ray-cast sensing (the drawn grid instead), and MuJoCo's plant altogether (the
   package's own simulator with the identified first-order plant: what is left is the lag not being
   first order).

Writes ``DIR/mujoco_corridor.json`` (``cases: [{robot, L, T, V_mujoco, predicted: {model: V}, relative_error,
…}]``, ``identification``, ``ablation``, ``kb_error``), ``DIR/mujoco_corridor.md`` (the table) and
``DIR/mujoco_corridor.png``, ``DIR/mujoco_robots.png`` (each robot's straight run and yaw-rate step
response). ``--quick``: one robot, one corridor, one T, no ablation. Deterministic: the same table twice.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path
from concurrent.futures import ProcessPoolExecutor

ROBOTS = {"diffdrive": 0.5, "diffdrive-heavy": 0.6}
"""Robot → its width W (m), the controller's W (KB eq 1)."""
CORRIDORS = (0.7, 0.9, 1.2)
PERIODS = (0.065, 0.1)
K, F, N = 2.0, 3.0, 2.0
IDENTIFY = dict(profile="both", V=0.8, T=0.05, amplitude=0.1, duration=60.0)
IDENTIFY_ROUNDS = 2
"""Identifications at the predicted boundary's speed after the first at 0.8 m/s (`identify_at_boundary`)."""
BISECTION = dict(rtol=0.01, members=7)
MODELS = ("continuous", "kb_first_order", "pade", "exact_delay", "sampled")


def identify_robot(name: str, out_dir: str, options: dict | None = None, V: float = 0.8) -> dict:
    """Drive at V (m/s), log as CSV with the base's pose, identify: {g, tau, dead_time, slip_lag (value, low, high; the
    slide's, None when not measured), r2, warnings, csv, V}."""
    from pfm_stability.analysis.identification import identify
    from pfm_stability.engines.mujoco import EngineOptions, drive_log, write_csv_log
    from pfm_stability.io.logs import read_log

    opts = EngineOptions(robot_model=name, **(options or {}))
    log = drive_log(options=opts, **{**IDENTIFY, "V": V})
    suffix = "" if not options else "_" + "_".join(f"{k}{v}" for k, v in sorted(options.items()))
    path = os.path.join(out_dir, f"{name}{suffix}_V{V:.2f}_identify.csv")
    write_csv_log(log, path)
    result = identify(read_log(path, need=("command", "imu"), optional=("pose",)), "imu")
    if not result.identified:
        raise RuntimeError(f"{name}: nothing identified: {result.reason}")
    p = result.plant
    return {"g": p.g.to_dict(), "tau": p.tau.to_dict(), "dead_time": p.dead_time.to_dict(), "r2": p.quality.r2,
            "slip_lag": None if result.slip is None else result.slip.slip_lag.to_dict(),
            "warnings": [w.kind for w in p.warnings], "csv": os.path.basename(path), "T": result.controller.T, "V": V}


def identify_at_boundary(name: str, L: float, T: float, out_dir: str, options: dict | None = None, rounds: int = IDENTIFY_ROUNDS) -> dict:
    """The plant identified at the speed of the predicted boundary: identify at 0.8 m/s, predict V* (`sampled`),
    identify again at that speed, `rounds` times (the plant's gain and lag depend on the speed; docs/mujoco.md)."""
    from pfm_stability.validation.common import predicted_boundaries, scenario_law, validation_models

    plant = identify_robot(name, out_dir, options, IDENTIFY["V"])
    for _ in range(rounds):
        robot, controller = predicted_pair(name, plant, T)
        law = scenario_law("grid", robot, controller)
        V = predicted_boundaries("corridor", "V", robot, controller, law, L, validation_models(controller))["sampled"]
        plant = identify_robot(name, out_dir, options, round(V, 2))
    return plant


def predicted_pair(name: str, plant: dict, T: float, slide: bool = True):
    """The predictions' robot (the identified τ, plant gain g, dead time D and, with `slide`, the slide's τ_s; the
    controller's k) and controller. The package's simulator takes no slide (its robot goes where it points)."""
    from pfm_stability.parameters import Controller, Robot

    slip = plant.get("slip_lag")
    robot = Robot(V=1.0, tau=plant["tau"]["value"], k=K, W=ROBOTS[name], plant_gain=plant["g"]["value"],
                  dead_time=max(plant["dead_time"]["value"], 0.0), slip_lag=max(slip["value"], 0.0) if slip and slide else 0.0)
    return robot, Controller(f=F, n=N, T=T, hold="command", compute_delay=1)


def bisect_case(name: str, plant: dict | None, L: float, T: float, duration: float | None, engine: dict | None = None,
                simulator: bool = False, out_dir: str = ".") -> dict:
    """MuJoCo's V* (or, with `simulator`, the package simulator's) and every model's prediction for one corridor; the
    plant identified at the predicted boundary's speed when `plant` is None."""
    from pfm_stability.engines.mujoco import EngineOptions, MujocoRuns
    from pfm_stability.validation import validate_boundary

    if plant is None:
        plant = identify_at_boundary(name, L, T, out_dir, {k: v for k, v in (engine or {}).items() if k == "caster_friction"})
    robot, controller = predicted_pair(name, plant, T, slide=not simulator)
    runner = None if simulator else MujocoRuns.factory(EngineOptions(robot_model=name, **(engine or {})))
    started = time.perf_counter()
    v = validate_boundary("corridor", "V", robot=robot, controller=controller, env="grid", L=L, duration=duration, runner=runner, **BISECTION)
    return {
        "robot": name, "L": L, "T": T, "V_mujoco": v.simulated_boundary, "bracket": list(v.bracket),
        "predicted": {m: v.predicted_boundary[m] for m in MODELS},
        "relative_error": {m: v.relative_error[m] for m in MODELS},
        "runs": v.runs, "duration": v.inputs["duration"], "seconds": time.perf_counter() - started,
        "engine": "sim" if simulator else {k: ("inf" if v == math.inf else v) for k, v in (engine or {}).items()},
        "plant": plant,
    }


def robot_figure(names, plants, path):
    """Each robot's straight run (lateral drift) and a yaw-rate step (MuJoCo against the identified first-order plant)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import mujoco
    import numpy as np

    from pfm_stability.engines.robots import corridor_world, heading, load_robot_model, place
    from pfm_stability.io.files import save_figure

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    for name in names:
        robot = load_robot_model(name)
        model = corridor_world(robot.path, math.inf, 0.0, 0.0)
        data = mujoco.MjData(model)
        base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
        place(model, data, robot, 0.0, 0.0, 0.0, 0.8)
        t, x = [], []
        for _ in range(100):
            mujoco.mj_step(model, data, nstep=100)
            t.append(data.time)
            x.append(1000 * data.xpos[base][0])
        a1.plot(t, x, label=f"{name}: {data.xpos[base][1]:.2f} m in {data.time:.0f} s")
        place(model, data, robot, 0.0, 0.0, 0.0, 0.8)
        step = 0.1
        left, right = robot.wheel_speeds(0.8, -step)  # θ̇ = −ψ̇: a counter-clockwise yaw rate of `step`
        data.ctrl[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "left")] = left
        data.ctrl[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "right")] = right
        ts, wz = [0.0], [0.0]
        for _ in range(300):
            mujoco.mj_step(model, data, nstep=5)
            ts.append(data.time)
            wz.append(float(data.qvel[model.jnt_dofadr[model.body_jntadr[base]] + 5]))
        p = plants[name]
        g, tau, D = p["g"]["value"], p["tau"]["value"], max(p["dead_time"]["value"], 0.0)
        ts = np.asarray(ts)
        fit = np.where(ts > D, g * step * (1 - np.exp(-(ts - D) / tau)), 0.0)
        line = a2.plot(ts, np.asarray(wz) / step, label=f"{name} (MuJoCo)")[0]
        a2.plot(ts, fit / step, "--", color=line.get_color(), label=f"identified g={g:.3f}, τ={tau:.3f} s")
    a1.set(xlabel="t (s)", ylabel="lateral drift (mm)", title="straight run at 0.8 m/s (drift: round-off)")
    a1.legend(fontsize=8)
    a2.set(xlabel="t (s)", ylabel="yaw rate / command", title="yaw-rate step of 0.1 rad/s at 0.8 m/s")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, dpi=110, what="figure")


def corridor_figure(cases, path):
    """Every model's V* against MuJoCo's (y = x ± 10 %), and the sampled model's gap per case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from pfm_stability.io.files import save_figure

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5.2), gridspec_kw={"width_ratios": [1, 1.4]})
    v = np.array([c["V_mujoco"] for c in cases])
    markers = dict(zip(MODELS, "o^sdv"))
    low, high = 0.8 * v.min(), 1.25 * max(max(c["predicted"].values()) for c in cases)
    line = np.geomspace(low, high, 50)
    a1.fill_between(line, 0.9 * line, 1.1 * line, color="0.85", label="±10 %", zorder=0)
    a1.plot(line, line, "k-", lw=0.8, zorder=1)
    for m in MODELS:
        a1.scatter(v, [c["predicted"][m] for c in cases], marker=markers[m], label=m, alpha=0.85, zorder=3,
                   s=45 if m == "sampled" else 30, edgecolors="k" if m == "sampled" else "none")
    a1.set(xscale="log", yscale="log", xlim=(low, high), ylim=(low, high), xlabel="V* bisected in MuJoCo (m/s)",
           ylabel="predicted V* (m/s)", title="corridor boundary: every model against MuJoCo")
    a1.legend(fontsize=8, loc="upper left")
    labels = [f"{'heavy' if 'heavy' in c['robot'] else 'light'} L={c['L']:g} T={c['T']:g}" for c in cases]
    x = np.arange(len(cases))
    width = 0.8 / len(MODELS)
    for i, m in enumerate(MODELS):
        a2.bar(x + (i - 2) * width, [100 * c["relative_error"][m] for c in cases], width, label=m)
    a2.axhspan(-10, 10, color="0.85", zorder=0)
    a2.axhline(0, color="k", lw=0.8)
    a2.set_xticks(x, labels, fontsize=8, rotation=40, ha="right")
    a2.set(ylabel="(predicted − MuJoCo)/MuJoCo (%)", title="each model's gap (grey: ±10 %)")
    a2.legend(fontsize=8, ncol=3)
    fig.tight_layout()
    save_figure(fig, path, dpi=110, what="figure")


def table(cases) -> str:
    rows = ["| robot | L (m) | T (s) | V* MuJoCo (m/s) | " + " | ".join(f"{m} V* (gap)" for m in MODELS) + " |",
            "| --- | --- | --- | --- | " + " | ".join("---" for _ in MODELS) + " |"]
    for c in cases:
        cells = [f"{c['predicted'][m]:.3f} ({100 * c['relative_error'][m]:+.1f} %)" for m in MODELS]
        rows.append(f"| {c['robot']} | {c['L']:g} | {c['T']:g} | {c['V_mujoco']:.3f} | " + " | ".join(cells) + " |")
    return "\n".join(rows) + "\n"


def _call(job):
    fn, args, kwargs = job
    return fn(*args, **kwargs)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", default=str(Path(__file__).resolve().parent / "results"), help="output folder (default: experiments/results)")
    parser.add_argument("--quick", action="store_true", help="one robot, one corridor, one T, no ablation")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    args = parser.parse_args(argv)
    os.makedirs(args.out_dir, exist_ok=True)
    started = time.perf_counter()
    names = ["diffdrive"] if args.quick else list(ROBOTS)
    corridors, periods = ((0.9,), (0.065,)) if args.quick else (CORRIDORS, PERIODS)
    duration = 20.0 if args.quick else None
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        jobs = [(bisect_case, (n, None, L, T, duration), {"out_dir": args.out_dir}) for n in names for L in corridors for T in periods]
        cases = list(pool.map(_call, jobs))
        for c in cases:
            p = c["plant"]
            print(f"{c['robot']} L={c['L']} T={c['T']}: plant at {p['V']:.2f} m/s g = {p['g']['value']:.4f}, tau = {p['tau']['value']:.4f} s, "
                  f"D = {1000 * p['dead_time']['value']:.1f} ms; V* MuJoCo {c['V_mujoco']:.3f}, sampled {c['predicted']['sampled']:.3f} "
                  f"({100 * c['relative_error']['sampled']:+.1f} %), {c['runs']} runs, {c['seconds']:.0f} s", file=sys.stderr)
        ablation = None
        if not args.quick:
            worst = max(cases, key=lambda c: abs(c["relative_error"]["sampled"]))
            n, L, T, plant = worst["robot"], worst["L"], worst["T"], worst["plant"]
            jobs = [
                (bisect_case, (n, plant, L, T, duration), {"engine": {"torque_limit": math.inf}}),
                (bisect_case, (n, None, L, T, duration), {"engine": {"caster_friction": 0.0}, "out_dir": args.out_dir}),
                (bisect_case, (n, plant, L, T, duration), {"engine": {"sensing": "drawn"}}),
                (bisect_case, (n, plant, L, T, duration), {"simulator": True}),
            ]
            effects = ("rate limit (no torque limit)", "caster drag (frictionless casters, plant re-identified)",
                       "sensing (the drawn grid instead of ray casts)", "lag not first order (the package's simulator with the identified first-order plant)")
            runs = list(pool.map(_call, jobs))
            ablation = {"case": {"robot": n, "L": L, "T": T, "sampled_gap": worst["relative_error"]["sampled"]},
                        "frictionless_plant": runs[1]["plant"],
                        "runs": [{"removed": e, "V": r["V_mujoco"], "sampled": r["predicted"]["sampled"],
                                  "sampled_gap": r["relative_error"]["sampled"]} for e, r in zip(effects, runs)]}
            for r in ablation["runs"]:
                print(f"  without {r['removed']}: V* {r['V']:.3f}, sampled {r['sampled']:.3f} ({100 * r['sampled_gap']:+.1f} %)", file=sys.stderr)
    kb = [c["relative_error"]["kb_first_order"] for c in cases]
    out = {
        "identification": {f"{c['robot']} L={c['L']:g} T={c['T']:g}": c["plant"] for c in cases}, "controller": {"k": K, "f": F, "n": N, "hold": "command", "compute_delay": 1},
        "bisection": BISECTION, "cases": cases, "ablation": ablation,
        "kb_error": {"min": min(kb), "max": max(kb), "mean": sum(kb) / len(kb)},
        "sampled_within_10_percent": all(abs(c["relative_error"]["sampled"]) <= 0.10 for c in cases),
        "seconds": time.perf_counter() - started,
    }
    from pfm_stability.io.files import write_text

    write_text(os.path.join(args.out_dir, "mujoco_corridor.json"), json.dumps(out, indent=1, default=float) + "\n")
    text = table(cases)
    write_text(os.path.join(args.out_dir, "mujoco_corridor.md"), text)
    corridor_figure(cases, os.path.join(args.out_dir, "mujoco_corridor.png"))
    robot_figure(names, {n: identify_robot(n, args.out_dir) for n in names}, os.path.join(args.out_dir, "mujoco_robots.png"))
    print(text, end="")
    print(f"KB's criterion (kb_first_order) against MuJoCo: {100 * out['kb_error']['min']:+.1f} % to {100 * out['kb_error']['max']:+.1f} %; "
          f"sampled within 10 % in every case: {out['sampled_within_10_percent']}; {out['seconds']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
