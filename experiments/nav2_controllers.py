"""Nav2's controllers in the simulator against their linearised loops (docs/controllers.md, "What was measured").

    python experiments/nav2_controllers.py [--out-dir DIR] [--quick]

1. **Gains**: every controller linearised with Nav2's defaults about the centre of a 0.6 m half-width corridor (grid
   and exact costmap) and in free space: V, k_y, k_θ with standard errors, NV, the bias ω on the centre line.
2. **RPP and Graceful**: V* (and RPP's L*) of the real algorithm bisected in the simulator (`validation.controllers`)
   beside the sampled model's prediction with the linearised gains, on random robots (τ, g, D, compute delay); RPP's
   pure-delay limit V·D/L at a short period; what the plan's resolution (a pose every 5 cm, Nav2's planners) does.
3. **MPPI**: D* (the largest dead time that stays stable) bisected for several noise seeds, beside the prediction
   with the one-step (static) gains and with the controller's impulse response over 16 cycles (its memory).
4. **DWB**: D* for several placements of the costmap's cells, beside the static prediction (mean ± one standard error).

Writes ``DIR/nav2_controllers.json``, ``DIR/nav2_controllers.md`` (the tables) and ``DIR/nav2_controllers.png`` (MPPI's
impulse response; each case's predicted against simulated boundary). ``--quick``: one case each. Deterministic.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import DEFAULT_OUT, output_dir, save_figure, write_json  # noqa: E402

from pfm_stability.controllers.registry import NAV2_CONTROLLERS as CONTROLLER_NAMES

from pfm_stability.controllers.costmap import CorridorCostmap

from pfm_stability.controllers.base import default_params

from pfm_stability.controllers.linearize import linearize  # noqa: E402
from pfm_stability.controllers import graceful, rpp  # noqa: E402
from pfm_stability.parameters import Robot  # noqa: E402
from pfm_stability.sim.tracking import TrackingScenario  # noqa: E402
from pfm_stability.validation.controllers import boundary_check, prediction_spread, predicted_boundary, simulated_boundary  # noqa: E402

CORRIDOR = 0.6
"""Half-width of the corridor the gains and the MPPI/DWB boundaries are measured in, m."""


def _gains_table(quick: bool):
    rows = []
    for name in CONTROLLER_NAMES:
        for label, cm in (("grid", CorridorCostmap(half_width=CORRIDOR)), ("exact", CorridorCostmap(half_width=CORRIDOR, exact=True)),
                          ("free", CorridorCostmap())):
            if quick and label != "grid":
                continue
            g = linearize(name, default_params(name), cm)
            rows.append(dict(g.to_dict(), costmap=label))
    return rows


def _robot(r, V=1.0):
    return Robot(V=V, tau=float(r.uniform(0.0, 0.3)), k=1.0, W=0.4, dead_time=float(r.uniform(0.05, 0.2)),
                 plant_gain=float(r.uniform(0.7, 1.3)), max_steering_rate=20.0)


def _rpp_graceful(quick: bool):
    cases = []
    for seed in range(1 if quick else 4):
        r = np.random.default_rng(100 + seed)
        robot, d = _robot(r), int(r.integers(0, 2))
        for name, params in (("rpp", rpp.RPPParams(use_regulated_linear_velocity_scaling=False)),
                             ("graceful", graceful.GracefulParams(v_angular_max=20.0))):
            s = TrackingScenario(name, robot, 0.05, params=params, spacing=0.01, duration=15.0, offset=0.003, compute_delay=d)
            b = boundary_check(s, "V", 0.2, 5.0, members=5, rtol=2e-3, around=1.5)
            cases.append(dict(case=f"{name} V*", robot=robot.__dict__, compute_delay=d, **b.to_dict()))
        s = TrackingScenario("rpp", robot.replace(V=0.8), 0.05, spacing=0.01, duration=15.0, offset=0.003, compute_delay=d,
                             costmap=CorridorCostmap(half_width=1.0))
        b = boundary_check(s, "lookahead_dist", 0.05, 3.0, members=5, rtol=2e-3, around=1.5)
        cases.append(dict(case="rpp L* (corridor 1 m)", robot=robot.replace(V=0.8).__dict__, compute_delay=d, **b.to_dict()))
    return cases


def _rpp_pure_delay_and_resolution(quick: bool):
    """V·D/L at T = 5 ms without lag (the continuous limit 0.5205), and V* with a pose every 5 cm against every 5 mm."""
    out = {}
    robot = Robot(V=1.0, tau=0.0, k=1.0, W=0.4, dead_time=0.2, max_steering_rate=50.0)
    params = rpp.RPPParams(lookahead_dist=0.6, use_regulated_linear_velocity_scaling=False)
    s = TrackingScenario("rpp", robot, 0.005, params=params, spacing=0.001, duration=12.0, offset=0.002)
    b = boundary_check(s, "V", 1.0, 2.5, members=5, rtol=1e-3)
    out["pure_delay"] = dict(V_D_over_L_simulated=b.simulated * 0.2 / 0.6, V_D_over_L_predicted=b.predicted * 0.2 / 0.6,
                             continuous_limit=0.5205, T=0.005, **b.to_dict())
    robot = Robot(V=1.0, tau=0.15, k=1.0, W=0.4, dead_time=0.1, max_steering_rate=20.0)
    res = []
    for spacing in ((0.05,) if quick else (0.05, 0.02, 0.005)):
        s = TrackingScenario("rpp", robot, 0.05, params=params, spacing=spacing, duration=15.0, offset=0.003)
        bracket, runs = simulated_boundary(s, "V", 0.5, 3.0, members=5, rtol=2e-3)
        res.append(dict(spacing=spacing, V_simulated=0.5 * (bracket.lo + bracket.hi), runs=runs))
    out["resolution"] = dict(predicted=predicted_boundary(s, "V", 0.5, 3.0), cases=res)
    return out


def _mppi(quick: bool):
    cm = CorridorCostmap(half_width=CORRIDOR, exact=True)
    robot = Robot(V=0.5, tau=0.1, k=1.0, W=0.4, dead_time=0.3, max_steering_rate=3.0)
    cases = []
    for seed in range(1 if quick else 4):
        s = TrackingScenario("mppi", robot, 0.05, costmap=cm, duration=20.0, offset=0.01, seed=seed)
        bracket, runs = simulated_boundary(s, "dead_time", 0.25, 0.62, members=5, rtol=0.01)
        cases.append(dict(seed=seed, D_simulated=0.5 * (bracket.lo + bracket.hi), lo=bracket.lo, hi=bracket.hi, runs=runs,
                          D_memory_same_seed=predicted_boundary(s, "dead_time", 0.0, 3.0, prediction="memory", draws=1, seed=seed, rtol=1e-3),
                          D_static_same_seed=predicted_boundary(s, "dead_time", 0.0, 3.0, prediction="sampled", draws=1, seed=seed, rtol=1e-3)))
    draws = 2 if quick else 8
    spread = {p: prediction_spread(s, "dead_time", 0.0, 3.0, prediction=p, draws=draws, seed=1000).to_dict() for p in ("sampled", "memory")}
    g = linearize("mppi", s.controller_params(), cm, memory_cycles=16, draws=draws, seed=1000)
    return dict(cases=cases, spread=spread, impulse=g.memory.to_dict(), gains=g.to_dict())


def _dwb(quick: bool):
    robot = Robot(V=0.26, tau=0.1, k=1.0, W=0.4, dead_time=0.3, max_steering_rate=3.0)
    cases = []
    for i, lattice in enumerate(((0.01, 0.013),) if quick else ((0.01, 0.013), (0.02, -0.017), (-0.005, 0.004))):
        s = TrackingScenario("dwb", robot, 0.05, costmap=CorridorCostmap(half_width=CORRIDOR, lattice=lattice), duration=25.0, offset=0.05)
        try:
            bracket, runs = simulated_boundary(s, "dead_time", 0.2, 1.2, members=5, rtol=0.01)
            sim = dict(D_simulated=0.5 * (bracket.lo + bracket.hi), lo=bracket.lo, hi=bracket.hi, runs=runs)
        except ValueError as e:
            sim = dict(D_simulated=None, note=str(e))
        cases.append(dict(lattice=lattice, **sim))
    s = TrackingScenario("dwb", robot, 0.05, costmap=CorridorCostmap(half_width=CORRIDOR))
    mean = predicted_boundary(s, "dead_time", 0.0, 3.0, rtol=1e-3)
    partial = [predicted_boundary(s, "dead_time", 0.0, 3.0, shift=shift, rtol=1e-3) - mean for shift in ((1.0, 0.0), (0.0, 1.0))]
    se = float(np.hypot(*partial))  # the gains' standard errors propagated, k_y and k_θ independent
    return dict(cases=cases, predicted=mean, predicted_se=se, gains=linearize("dwb", s.controller_params(), s.costmap).to_dict())


def _markdown(data) -> str:
    lines = ["| controller | costmap | V (m/s) | k_y (1/(m s)) | k_θ (1/s) | NV (1/s) | ω on the line (rad/s) |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for g in data["gains"]:
        lines.append(f"| {g['controller']} | {g['costmap']} | {g['V']:.3f} | {g['k_y']:.3f} ± {g['k_y_se']:.3f} | "
                     f"{g['k_theta']:.3f} ± {g['k_theta_se']:.3f} | {g['NV']:.3f} | {g['w0']:+.4f} ± {g['w0_se']:.4f} |")
    lines += ["", "| case | predicted | simulated | error |", "| --- | --- | --- | --- |"]
    for c in data["rpp_graceful"]:
        lines.append(f"| {c['case']} (τ {c['robot']['tau']:.3f}, g {c['robot']['plant_gain']:.2f}, D {c['robot']['dead_time']:.3f}, d {c['compute_delay']}) "
                     f"| {c['predicted']:.4f} | {c['simulated']:.4f} | {100 * c['relative_error']:+.2f} % |")
    pd = data["rpp_limits"]["pure_delay"]
    lines.append(f"| rpp V·D/L, τ = 0, T = 5 ms (continuous limit 0.5205) | {pd['V_D_over_L_predicted']:.4f} | {pd['V_D_over_L_simulated']:.4f} | "
                 f"{100 * pd['relative_error']:+.2f} % |")
    res = data["rpp_limits"]["resolution"]
    for c in res["cases"]:
        lines.append(f"| rpp V*, plan pose every {100 * c['spacing']:g} cm | {res['predicted']:.4f} | {c['V_simulated']:.4f} | "
                     f"{100 * (c['V_simulated'] / res['predicted'] - 1):+.2f} % |")
    m = data["mppi"]
    lines += ["", "| MPPI seed | D* simulated (s) | memory, same seed | static, same seed |", "| --- | --- | --- | --- |"]
    for c in m["cases"]:
        lines.append(f"| {c['seed']} | {c['D_simulated']:.3f} | {c['D_memory_same_seed']:.3f} | {c['D_static_same_seed']:.3f} |")
    for p in ("memory", "sampled"):
        lines.append(f"| {p} prediction over draws | | {m['spread'][p]['mean']:.3f} ± {m['spread'][p]['se']:.3f} | |")
    d = data["dwb"]
    lines += ["", "| DWB lattice (m) | D* simulated (s) | static prediction ± se (s) |", "| --- | --- | --- |"]
    for c in d["cases"]:
        sim = f"{c['D_simulated']:.3f}" if c.get("D_simulated") is not None else c.get("note", "")
        lines.append(f"| {c['lattice']} | {sim} | {d['predicted']:.3f} ± {d['predicted_se']:.3f} |")
    return "\n".join(lines) + "\n"


def _figure(data, path):
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.2))
    imp = data["mppi"]["impulse"]
    j = np.arange(len(imp["y"]))
    a.errorbar(j, imp["y"], yerr=imp["y_se"], marker="o", label="−∂ω_j/∂e_y (1/(m s))")
    a.errorbar(j, imp["theta"], yerr=imp["theta_se"], marker="s", label="−∂ω_j/∂e_θ (1/s)")
    a.axhline(0, color="0.6", lw=0.8)
    a.set_xlabel("cycles after the perturbation")
    a.set_title("MPPI's response to a one-cycle pose error (its memory)")
    a.legend()
    groups = [("RPP V*, L*", [(c["predicted"], c["simulated"]) for c in data["rpp_graceful"] if c["case"].startswith("rpp")]),
              ("Graceful V*", [(c["predicted"], c["simulated"]) for c in data["rpp_graceful"] if c["case"].startswith("graceful")]),
              ("MPPI D*, memory", [(c["D_memory_same_seed"], c["D_simulated"]) for c in data["mppi"]["cases"]]),
              ("MPPI D*, static gains", [(c["D_static_same_seed"], c["D_simulated"]) for c in data["mppi"]["cases"]]),
              ("DWB D*, static gains", [(data["dwb"]["predicted"], c["D_simulated"]) for c in data["dwb"]["cases"] if c.get("D_simulated")])]
    b.axvspan(0.98, 1.02, color="0.88", zorder=0, label="±2 %")
    b.axvline(1.0, color="k", lw=0.8, zorder=1)
    for i, (label, pairs) in enumerate(groups):
        if pairs:
            ratio = np.array([sim / pred for pred, sim in pairs])
            b.scatter(ratio, i + np.linspace(-0.2, 0.2, ratio.size), zorder=3, s=25)
    b.set_yticks(range(len(groups)), [g[0] for g in groups])
    b.invert_yaxis()
    b.set_xlabel("simulated boundary / predicted boundary (each case)")
    b.set_title("the real algorithms against their linearised loops")
    b.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    save_figure(fig, path)


def redraw(out) -> None:
    """Draw the figure again from a written JSON (no runs)."""
    import json

    out = Path(out)
    data = json.loads((out / "nav2_controllers.json").read_text())
    data["dwb"]["predicted"] = float(data["dwb"]["predicted"])
    _figure(data, out / "nav2_controllers.png")


def run(out, quick: bool = False) -> dict:
    """All four parts (module docstring); returns the JSON written."""
    out = output_dir(out)
    started = time.perf_counter()
    data = dict(gains=_gains_table(quick), rpp_graceful=_rpp_graceful(quick), rpp_limits=_rpp_pure_delay_and_resolution(quick),
                mppi=_mppi(quick), dwb=_dwb(quick))
    data["seconds"] = time.perf_counter() - started
    write_json(out / "nav2_controllers.json", data)
    (out / "nav2_controllers.md").write_text(_markdown(data))
    _figure(data, out / "nav2_controllers.png")
    return data


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", default=str(DEFAULT_OUT))
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    data = run(args.out_dir, quick=args.quick)
    print(_markdown(data))
    print(f"{data['seconds']:.0f} s")


if __name__ == "__main__":
    main()
