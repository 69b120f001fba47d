"""``pfm-stability simulate``: run a scenario in the VFF simulator, report events, metrics and predictions.

    pfm-stability simulate --scenario kb-fig6-narrow --plot fig6b.png
    pfm-stability simulate --scenario corridor --env analytic --L 0.9 --format json

JSON keys (`pfm_stability/schema/output.schema.json`): ``schema_version``,
``command`` ("simulate"), ``events`` (list of {type, t, x, y}; type ∈
collision, target_reached, trapped; t in s: a collision's first touch on the
path between samples), ``metrics`` (growth_rate σ 1/s, angular_frequency ω
rad/s, oscillating, stable, amplitude, method, …), ``t_end`` (s, the last
sample: the duration, or the first sample at or after the event that stopped
the run), ``steps``, ``min_clearance`` (m), ``prediction`` (the
`sampled` model with the run's own force law and KB's criterion, for corridor
and wall geometries; null otherwise), ``inputs`` (every parameter, where it
came from, and the scenario's documented choices), ``plot``, and ``timing``
(wall-clock ``seconds`` and samples per second ``rate``: the only values
that change from run to run). Infinite numbers are the strings "inf"/"-inf",
undefined ones null.

A progress bar of the simulated samples is drawn on stderr when stderr is a
terminal (``--quiet``: never).
"""

from __future__ import annotations

from ..laws.registry import laws_for
from .options import add_parameter_options, describe, integer, number, output_path, resolve_parameters
from .progress import step_progress

SCENARIO_CHOICES = ("straight", "corridor", "wall", "kb-fig3", "kb-fig5", "kb-fig6-wide", "kb-fig6-narrow")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="simulate a scenario (VFF on a histogram grid, or analytic walls) and measure oscillation",
        description="Simulate the VFF controller on a CARMEL-like robot (Koren & Borenstein 1991): "
        "events, oscillation metrics (growth rate and angular frequency of the lateral offset), model predictions, "
        "and a trajectory plot like KB's figures.",
    )
    p.add_argument("--scenario", required=True, choices=SCENARIO_CHOICES, help="scenario preset")
    p.add_argument("--env", choices=("grid", "analytic"), default="grid", help="histogram grid (default) or analytic walls")
    add_parameter_options(p, sampled=True)
    g = p.add_argument_group("scenario")
    g.add_argument("--L", type=number("L"), help=f"corridor: half-width, {describe('L')}, and more than W/2 (default 1)")
    g.add_argument("--alpha", type=number("alpha_deg"), help=f"wall: target angle from the wall normal, {describe('alpha_deg')} (default 45)")
    g.add_argument("--offset", type=number("offset"),
                   help=f"corridor/wall: start offset from equilibrium, {describe('offset')}, with the robot inside the corridor "
                   "(|offset| < L - W/2, - c/2 in the grid) or clear of the wall (default 0.02)")
    g.add_argument("--duration", type=number("duration"), help=f"simulated time, {describe('duration')} (default per scenario)")
    g.add_argument("--cell-ratio", type=number("cell_ratio"), help=f"grid: F_cr/F_ct per cell, {describe('cell_ratio')} (default: calibrated to f_av = f)")
    g.add_argument("--law", choices=laws_for("simulate"), help="analytic: KB's lumped power law (default) or the grid's effective law")
    g.add_argument("--window-cells", type=integer("window_cells", odd=True),
                   help=f"grid: active window side, odd, {describe('window_cells')} (default: the preset's, 33)")
    g.add_argument("--cell-size", type=number("cell_size"), help=f"grid: cell size, {describe('cell_size')} (default: the preset's, 0.1)")
    g.add_argument("--speed-law", action="store_true", help="use the VFF speed law V(1 - |cos phi|)")
    g.add_argument("--seed", type=integer("seed"), help=f"seed of the random start jitter, {describe('seed')}")
    g.add_argument("--jitter", type=number("start_jitter"), default=0.0,
                   help=f"standard deviation of a random lateral start offset, {describe('start_jitter')} (default 0)")
    out = p.add_argument_group("output")
    out.add_argument("--plot", type=output_path("plot"), metavar="PNG",
                     help="write a trajectory plot drawn like KB's figures (a .png file in an existing writable directory)")
    out.add_argument("--format", choices=("text", "json"), default="text")
    out.add_argument("--trajectory", action="store_true", help="json: include every sample of the trajectory")
    out.add_argument("--quiet", action="store_true", help="no progress bar on stderr (shown only when stderr is a terminal)")
    p.set_defaults(run=run)


def config_law(args, params) -> dict:
    """The simulated walls' law options, ``{"law": …, "cell_ratio": …}``: typed, else a --config file's, else None.

    The one rule of `simulate` and `validate`: ``--law`` (where the command has
    it) beats the file's ``law.name`` when that is ``power`` or ``grid``
    (``khatib`` and ``gnron`` are analysed by `report` only), which applies to
    ``--env analytic`` (the grid's law is its cells); a ``grid`` law's
    ``cell_ratio`` applies to the grid and to ``--env analytic`` with the grid's
    law, unless ``--cell-ratio`` is typed. `sim.scenario_law` turns them into
    the law (docs/config.md, precedence).
    """
    law = (params.config.law if params.config is not None else None) or {}
    if law.get("name") not in laws_for("simulate"):
        law = {}
    typed_law, typed_ratio = getattr(args, "law", None), getattr(args, "cell_ratio", None)
    out = {
        "law": typed_law if typed_law is not None else (law.get("name") if law and args.env == "analytic" else None),
        "cell_ratio": typed_ratio,
    }
    if out["cell_ratio"] is None and law.get("name") == "grid" and (args.env == "grid" or out["law"] == "grid"):
        out["cell_ratio"] = law.get("cell_ratio")
    return out


def _law_options(args, params) -> dict:
    """--law, --cell-ratio (`config_law`), --window-cells, --cell-size: typed, else the configuration's grid."""
    return {
        **config_law(args, params),
        "window_cells": args.window_cells if args.window_cells is not None else params.preset.window_cells,
        "cell_size": args.cell_size if args.cell_size is not None else params.preset.cell_size,
    }


def _build(args, params):
    from ..parameters import Wall
    from ..sim.presets import make_scenario

    return make_scenario(
        args.scenario,
        robot=params.robot,
        controller=params.controller,
        env=args.env,
        L=args.L,
        alpha=Wall.from_degrees(args.alpha).alpha if args.alpha is not None else None,  # rad, inside RANGES['alpha']
        offset=args.offset,
        duration=args.duration,
        **_law_options(args, params),
        speed_law=args.speed_law,
        seed=args.seed,
        start_jitter=args.jitter,
    )


def _plot(result, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")

    from ..io.files import save_figure
    from ..plots.trajectory import plot_trajectory

    save_figure(plot_trajectory(result), path, dpi=120, what="plot")


def run(args) -> int:
    from .render_runs import render_simulation_text

    import time

    from ..parameters import Corridor, check_corridor_fits
    from ..io.serialize import SCHEMA_VERSION, dumps, json_number
    from ..sim.api import simulate
    from ..validation.predict import predict

    params = resolve_parameters(args, fill={"corridor": ("L",), "wall": ("alpha",)}.get(args.scenario, ()))
    if args.scenario == "corridor" and args.L is not None:  # the report's words for a robot wider than the corridor
        check_corridor_fits(Corridor(args.L), params.robot)
    scenario = _build(args, params)
    started = time.perf_counter()
    with step_progress("simulate", quiet=args.quiet) as progress:
        result = simulate(scenario, progress=progress)
    seconds = time.perf_counter() - started
    prediction = predict(scenario)
    if args.plot:
        _plot(result, args.plot)
    if args.format == "json":
        out = {"schema_version": SCHEMA_VERSION, "command": "simulate", **result.to_dict(trajectory=args.trajectory)}
        out["prediction"] = prediction.to_dict() if prediction is not None else None
        out["inputs"]["sources"] = params.sources
        out["plot"] = args.plot
        out["timing"] = {"seconds": json_number(seconds), "rate": json_number(result.steps / seconds if seconds > 0 else None)}
        print(dumps(out))
    else:
        print(render_simulation_text(result, prediction, args.plot), end="")
    return 0
