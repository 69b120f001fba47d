"""``pfm-stability simulate``: run a scenario in the VFF simulator, report events, metrics and predictions.

    pfm-stability simulate --scenario kb-fig6-narrow --plot fig6b.png
    pfm-stability simulate --scenario corridor --env analytic --L 0.9 --format json

JSON keys: ``events`` (list of {type, t, x, y}; type ∈ collision,
target_reached, trapped; t in s), ``metrics`` (growth_rate σ 1/s,
angular_frequency ω rad/s, oscillating, stable, amplitude, method, …),
``prediction`` (the `sampled` model with the run's own force law and KB's
criterion, for corridor and wall geometries; null otherwise), ``inputs``
(every parameter, where it came from, and the scenario's documented choices).
"""

from __future__ import annotations


from .options import add_parameter_options, integer, number, resolve_parameters

SCENARIO_CHOICES = ("straight", "corridor", "wall", "kb-fig3", "kb-fig5", "kb-fig6-wide", "kb-fig6-narrow")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="simulate a scenario (VFF on a histogram grid, or analytic walls) and measure oscillation",
        description="Simulate the VFF controller on a CARMEL-like robot (Koren & Borenstein 1991): "
        "events, oscillation metrics (DESIGN §6), model predictions, and a trajectory plot like KB's figures.",
    )
    p.add_argument("--scenario", required=True, choices=SCENARIO_CHOICES, help="scenario preset")
    p.add_argument("--env", choices=("grid", "analytic"), default="grid", help="histogram grid (default) or analytic walls")
    add_parameter_options(p)
    g = p.add_argument_group("scenario")
    g.add_argument("--L", type=number("L"), help="corridor: half-width, m, in (W/2, 1e4]")
    g.add_argument("--alpha", type=number("alpha_deg"), help="wall: target angle from the wall normal, deg, in (0, 90)")
    g.add_argument("--offset", type=number("offset", unit="m"), help="corridor/wall: start offset from equilibrium, m")
    g.add_argument("--duration", type=number("duration", 0.0, 1e6, unit="s"), help="simulated time, s")
    g.add_argument("--cell-ratio", type=number("cell_ratio", 0.0), help="grid: F_cr/F_ct per cell (default: calibrated to f_av = f)")
    g.add_argument("--law", choices=("power", "grid"), help="analytic: KB's lumped power law (default) or the grid's effective law")
    g.add_argument("--window-cells", type=integer("window_cells", -10**6, 10**6), default=33, help="grid: active window side, odd >= 3 (33)")
    g.add_argument("--cell-size", type=number("cell_size", 0.0, unit="m"), default=0.1, help="grid: cell size, m (0.1)")
    g.add_argument("--speed-law", action="store_true", help="use the VFF speed law V(1 - |cos phi|)")
    g.add_argument("--seed", type=integer("seed", 0, 2**63 - 1), help="seed of the random start jitter")
    g.add_argument("--jitter", type=number("start_jitter", 0.0, low_open=False, unit="m"), default=0.0, help="std of a random lateral start offset, m")
    out = p.add_argument_group("output")
    out.add_argument("--plot", metavar="PNG", help="write a trajectory plot drawn like KB's figures")
    out.add_argument("--format", choices=("text", "json"), default="text")
    out.add_argument("--trajectory", action="store_true", help="json: include every sample of the trajectory")
    p.set_defaults(run=run)


def _build(args, params):
    import math

    from ..sim.presets import make_scenario

    return make_scenario(
        args.scenario,
        robot=params.robot,
        controller=params.controller,
        env=args.env,
        L=args.L,
        alpha=math.radians(args.alpha) if args.alpha is not None else None,
        offset=args.offset,
        duration=args.duration,
        cell_ratio=args.cell_ratio,
        law=args.law,
        window_cells=args.window_cells,
        cell_size=args.cell_size,
        speed_law=args.speed_law,
        seed=args.seed,
        start_jitter=args.jitter,
    )


def _plot(result, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..plots.trajectory import plot_trajectory

    fig = plot_trajectory(result)
    try:
        fig.savefig(path, dpi=120)
    except OSError as exc:
        raise ValueError(f"plot: cannot write {path}: {exc.strerror or exc}") from None
    finally:
        plt.close(fig)


def run(args) -> int:
    import json

    from ..sim.api import simulate
    from ..sim.predict import predict

    params = resolve_parameters(args)
    scenario = _build(args, params)
    result = simulate(scenario)
    prediction = predict(scenario)
    if args.plot:
        _plot(result, args.plot)
    out = result.to_dict(trajectory=args.trajectory)
    out["prediction"] = prediction.to_dict() if prediction is not None else None
    out["inputs"]["sources"] = params.sources
    out["plot"] = args.plot
    if args.format == "json":
        print(json.dumps(out, indent=2, allow_nan=False, default=_json_default))
    else:
        print(render_text(result, prediction, args.plot), end="")
    return 0


def _json_default(value):
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot serialize {type(value).__name__}")


def _fmt(value, unit="", digits=4):
    return "undefined" if value is None else f"{value:+.{digits}g}{' ' + unit if unit else ''}"


def render_text(result, prediction, plot_path=None) -> str:
    """The human-readable report of one run."""
    s, m = result.scenario, result.metrics
    r, c = s.robot, s.controller
    lines = [
        f"scenario {s.name} ({s.env}), {s.duration:g} s simulated, {result.steps} samples of T = {c.T:g} s",
        f"  robot: V = {r.V:g} m/s, tau = {r.tau:g} s, k = {r.k:g} 1/s, W = {r.W:g} m; "
        f"controller: f = {c.f:g}, n = {c.n:g}, hold = {c.hold}, compute_delay = {c.compute_delay}",
        "events:",
    ]
    lines += [f"  {e.type} at t = {e.t:.3f} s (x = {e.x:.3f} m, y = {e.y:.3f} m)" for e in result.events] or [
        f"  none (ran {result.t_end:.3f} s)"
    ]
    if result.min_clearance is not None:
        lines.append(f"  closest approach: {result.min_clearance * 100:.3g} cm between the robot disc and an obstacle")
    lines += [
        f"metrics (DESIGN §6, {m.turning_points} turning points, method {m.method}):",
        f"  growth rate sigma = {_fmt(m.growth_rate, '1/s')}, angular frequency omega = {_fmt(m.angular_frequency, 'rad/s')}",
        f"  oscillating: {'yes' if m.oscillating else 'no'}; stable: {'yes' if m.stable else 'no'}; "
        f"limit cycle: {'amplitude %.3g m' % m.amplitude if m.limit_cycle else 'no'}",
    ]
    if m.reason:
        lines.append(f"  ({m.reason})")
    if prediction is not None:
        unit = "m" if prediction.kind == "corridor" else "deg"
        label = "L" if prediction.kind == "corridor" else "alpha"
        lines.append(f"prediction ({prediction.kind}, {label} = {prediction.value:g} {unit}):")
        for p in (prediction.matching, prediction.kb):
            lines.append(
                f"  {p.model:15s} {p.verdict:9s} sigma = {p.growth_rate:+.4g} 1/s, omega = {p.angular_frequency:.4g} rad/s, "
                f"{label}* = {p.critical:.4g} {unit}  [{p.law}]"
            )
    lines.append("notes:")
    lines += [f"  {key}: {value}" for key, value in s.notes.items()]
    if plot_path:
        lines.append(f"plot: {plot_path}")
    return "\n".join(lines) + "\n"
