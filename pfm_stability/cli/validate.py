"""``pfm-stability validate``: the simulated stability boundary against every model.

    pfm-stability validate --scenario corridor --env grid --plot corridor.png
    pfm-stability validate --scenario wall --env analytic --hold reference --compute-delay 0 --format json
    pfm-stability validate --scenario corridor --parameter V --L 0.8 --sweep 200
    pfm-stability validate --engine mujoco --robot-model diffdrive --config robot.yaml --scenario corridor --parameter V --L 0.9

Bisects the boundary of a straight corridor (in L, V or f) or wall (in α, V
or f) in the simulator, compares it with each model's prediction (with the
simulated environment's own force law; in the grid also with KB's lumped law
at the grid's f_av), and checks σ and ω near it against the matching
`sampled` model. ``--engine mujoco`` runs the corridor's simulations in MuJoCo
instead: the package's VFF controller on an MJCF robot (``--robot-model``),
sensing by ray casts (docs/mujoco.md); the JSON is the same, with the engine
in ``notes``. ``--sweep N`` also simulates N random parameter sets and
reports how often each model's verdict agrees with the simulation. A
``--config`` file's ``power`` or ``grid`` law is the walls' law (with
``--env analytic``; a grid law's cell ratio in either environment), by the
rule `simulate` follows (`simulate.config_law`, docs/config.md).

JSON keys (`pfm_stability/schema/output.schema.json`): ``schema_version``,
``command`` ("validate"), ``parameter`` (the bisected one),
``simulated_boundary`` (a number, in ``unit``: L m, α deg, V m/s, f),
``predicted_boundary`` and ``relative_error`` (objects keyed by model name:
continuous, kb_first_order, pade, exact_delay, sampled; "inf" where a model
has no finite boundary), ``lumped_predicted_boundary`` /
``lumped_relative_error`` (grid), ``oscillation`` (σ, ω measured vs the
sampled model's dominant root), ``inputs`` (every parameter and where it came
from), ``notes``, ``sweep`` (with ``--sweep``), ``plot``, ``sweep_plot``, and
``timing`` (wall-clock seconds of the bisection and of the sweep: the only
values that change from run to run).

Progress goes to stderr unless ``--quiet``: one line per batch of runs, above
a status line with the elapsed time when stderr is a terminal, as plain lines
otherwise (a log of a long validation keeps them).
"""

from __future__ import annotations

from ..engines import ENGINES, ROBOT_MODELS
from .options import PADE_ORDER, add_parameter_options, describe, integer, number, output_path, resolve_parameters
from .progress import line_progress

SCENARIO_CHOICES = ("corridor", "wall")


def robot_model(text: str) -> str:
    """An argparse ``type=`` for ``--robot-model``: a shipped robot's name or an existing ``.xml`` file (checked when run)."""
    import argparse
    import os

    if text in ROBOT_MODELS or (text.lower().endswith(".xml") and os.path.isfile(text)):
        return text
    raise argparse.ArgumentTypeError(f"robot-model must be one of {', '.join(ROBOT_MODELS)} or an existing MJCF .xml file; got {text!r}")


robot_model.kind = "path"  # for tests/test_cli_fuzz.py: every option has a checked type
PARAMETER_CHOICES = ("L", "alpha", "V", "f")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "validate",
        help="bisect the simulated stability boundary and compare it with every model",
        description="Find the simulated stability boundary of a corridor or wall by bisection and compare it with the "
        "prediction of every loop model (Koren & Borenstein 1991 and the exact-delay and sampled-data models).",
    )
    p.add_argument("--scenario", required=True, choices=SCENARIO_CHOICES, help="straight corridor or wall, target at infinity")
    p.add_argument("--parameter", choices=PARAMETER_CHOICES,
                   help="parameter to bisect: L (corridor), alpha (wall), V or f (default: L for a corridor, alpha for a wall)")
    p.add_argument("--env", choices=("grid", "analytic"), default="grid", help="histogram grid (default) or analytic walls")
    add_parameter_options(p, sampled=True)
    g = p.add_argument_group("scenario")
    g.add_argument("--L", type=number("L"), help=f"corridor half-width, {describe('L')}, and more than W/2, when V or f is bisected (default 1)")
    g.add_argument("--alpha", type=number("alpha_deg"), help=f"wall angle, {describe('alpha_deg')}, when V or f is bisected (default 45)")
    b = p.add_argument_group("bisection")
    b.add_argument("--rtol", type=number("rtol"), help=f"relative width of the final bracket, {describe('rtol')} (default 1e-4 analytic, 1e-3 grid)")
    b.add_argument("--members", type=integer("members"), default=9, help=f"runs per bisection round, {describe('members')} (default 9)")
    b.add_argument("--offset", type=number("offset"), help=f"start offset from equilibrium, {describe('offset')} (default 1e-7 analytic, 0.01 grid)")
    b.add_argument("--duration", type=number("duration"),
                   help=f"simulated time per run, {describe('duration')} (default: 10 boundary periods, >= 20/30 s)")
    b.add_argument("--pade-order", type=PADE_ORDER, default=3, help=f"order m of the pade model, {describe('pade_order')} (default 3)")
    s = p.add_argument_group("random sweep")
    s.add_argument("--sweep", type=integer("sweep"), metavar="N",
                   help=f"also simulate N Latin-hypercube parameter sets, N in {describe('sweep')}, and report each model's verdict agreement")
    s.add_argument("--seed", type=integer("seed"), default=0, help=f"seed of the sweep, {describe('seed')} (default 0)")
    e = p.add_argument_group("engine")
    e.add_argument("--engine", choices=ENGINES, default="sim",
                   help="what runs the simulations: the package's simulator (default) or MuJoCo (the corridor, the VFF "
                   "controller on an MJCF robot; needs the extra 'mujoco', docs/mujoco.md)")
    e.add_argument("--robot-model", type=robot_model, metavar="NAME|FILE.xml",
                   help=f"with --engine mujoco: a shipped robot ({', '.join(ROBOT_MODELS)}; default diffdrive) or an MJCF file")
    out = p.add_argument_group("output")
    out.add_argument("--plot", type=output_path("plot"), metavar="PNG",
                     help="write the overlay: model boundary curves with simulated stable/unstable runs (a .png file)")
    out.add_argument("--no-map", action="store_true", help="with --plot: skip the 7 x 9 stability map (plot the bisection runs only)")
    out.add_argument("--sweep-plot", type=output_path("sweep-plot"), metavar="PNG", help="with --sweep: write the sweep figure (a .png file)")
    out.add_argument("--format", choices=("text", "json"), default="text")
    out.add_argument("--quiet", action="store_true",
                     help="no progress on stderr (default: a line per batch of runs, with a status line on a terminal)")
    p.set_defaults(run=run)


def _save(fig, path: str, what: str) -> None:
    from ..io.files import save_figure

    save_figure(fig, path, dpi=120, what=what)


def run(args) -> int:
    from .render_runs import render_validation_text

    if args.sweep_plot and not args.sweep:
        raise ValueError("sweep-plot needs --sweep N")
    if args.no_map and not args.plot:
        raise ValueError("no-map applies to --plot only")
    if args.robot_model is not None and args.engine != "mujoco":
        raise ValueError("robot-model applies to --engine mujoco only")
    if args.engine == "mujoco":
        _check_mujoco(args)
    fill = ({"corridor": "L", "wall": "alpha"}[args.scenario],) if args.parameter in ("V", "f") else ()  # the fixed geometry
    params = resolve_parameters(args, fill=fill)
    if args.scenario == "corridor" and args.L is not None and args.parameter in ("V", "f"):  # the report's words
        from ..parameters import Corridor, check_corridor_fits

        check_corridor_fits(Corridor(args.L), params.robot)
    if args.plot or args.sweep_plot:
        import matplotlib

        matplotlib.use("Agg")

    from ..io.serialize import SCHEMA_VERSION, dumps

    with line_progress("validate", quiet=args.quiet) as progress:
        validation, sweep = _work(args, params, progress)
    if args.plot:
        from ..plots.validation import plot_validation

        _save(plot_validation(validation), args.plot, "plot")
    if args.sweep_plot:
        from ..plots.validation import plot_sweep

        _save(plot_sweep(sweep), args.sweep_plot, "sweep-plot")
    if args.format == "json":
        out = {"schema_version": SCHEMA_VERSION, "command": "validate", **validation.to_dict()}
        timing = out.pop("timing")
        out["inputs"]["sources"] = params.sources
        out["sweep"] = None
        if sweep is not None:
            out["sweep"] = sweep.to_dict()
            timing["sweep_seconds"] = out["sweep"].pop("timing")["seconds"]
        out["plot"] = args.plot
        out["sweep_plot"] = args.sweep_plot
        out["timing"] = timing
        print(dumps(out))
    else:
        print(render_validation_text(validation, sweep, params.sources, args.plot, args.sweep_plot), end="")
    return 0


def _check_mujoco(args) -> None:
    """The MuJoCo engine runs the corridor in the grid with a held command, without a sweep; its extra is installed."""
    from ..extras import require

    if args.scenario != "corridor" or args.env != "grid":
        raise ValueError(f"--engine mujoco runs the corridor scenario with --env grid; got --scenario {args.scenario} --env {args.env}")
    if args.sweep:
        raise ValueError("--sweep runs the package's simulator; not with --engine mujoco")
    require("mujoco", "pfm-stability validate --engine mujoco")


def _mujoco(args, params):
    """MuJoCo's runner for the validation, after reading and driving the robot file (a bad file or a robot that cannot
    drive: one line, exit 2). The robot's τ, plant gain and dead time are the predictions' (``identify --out``)."""
    from ..engines.mujoco import EngineOptions, MujocoRuns
    from ..engines.robots import check_drives, load_robot_model

    if params.controller.hold != "command":
        raise ValueError("--engine mujoco holds the turning-rate command between samples (--hold command); got --hold reference")
    name = args.robot_model or "diffdrive"
    check_drives(load_robot_model(name).path)
    return MujocoRuns.factory(EngineOptions(robot_model=name))


def _work(args, params, progress):
    """The bisection (and the sweep): (BoundaryValidation, SweepResult or None).

    The walls' law is a --config file's ``power`` or ``grid`` law (and a grid
    law's cell ratio), by the rule `simulate` follows (`simulate.config_law`).
    """
    from ..parameters import Wall
    from ..validation import validate_boundary, verdict_sweep
    from .simulate import config_law

    law = config_law(args, params)
    runner = _mujoco(args, params) if args.engine == "mujoco" else None

    validation = validate_boundary(
        args.scenario,
        args.parameter,
        robot=params.robot,
        controller=params.controller,
        env=args.env,
        L=args.L,
        alpha=Wall.from_degrees(args.alpha).alpha if args.alpha is not None else None,  # rad, inside RANGES['alpha']
        rtol=args.rtol,
        members=args.members,
        offset=args.offset,
        duration=args.duration,
        pade_order=args.pade_order,
        window_cells=params.preset.window_cells,
        cell_size=params.preset.cell_size,
        **law,
        stability_map=(7, 9) if args.plot and not args.no_map else None,
        progress=progress,
        runner=runner,
    )
    sweep = None
    if args.sweep:
        sweep = verdict_sweep(
            args.sweep, seed=args.seed, env=args.env, robot=params.robot, controller=params.controller,
            pade_order=args.pade_order, law=law["law"], progress=progress,
        )
    return validation, sweep
