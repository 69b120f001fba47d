"""``pfm-stability validate``: the simulated stability boundary against every model.

    pfm-stability validate --scenario corridor --env grid --plot corridor.png
    pfm-stability validate --scenario wall --env analytic --hold reference --compute-delay 0 --format json
    pfm-stability validate --scenario corridor --parameter V --L 0.8 --sweep 200

Bisects the boundary of a straight corridor (in L, V or f) or wall (in α, V
or f) in the simulator, compares it with each model's prediction (with the
simulated environment's own force law; in the grid also with KB's lumped law
at the grid's f_av), and checks σ and ω near it against the matching
`sampled` model. ``--sweep N`` also simulates N random parameter sets and
reports how often each model's verdict agrees with the simulation.

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

from .options import PADE_ORDER, add_parameter_options, describe, integer, number, output_path, resolve_parameters
from .progress import line_progress
from .simulate import json_default

SCENARIO_CHOICES = ("corridor", "wall")
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
    import matplotlib.pyplot as plt

    try:
        fig.savefig(path, dpi=120)
    except OSError as exc:  # checked before the work; this is a race or a full disk
        raise ValueError(f"{what} must be a writable file path ending in .png; got {path!r} ({exc.strerror or exc})") from None
    finally:
        plt.close(fig)


def run(args) -> int:
    import json

    if args.sweep_plot and not args.sweep:
        raise ValueError("sweep-plot needs --sweep N")
    if args.no_map and not args.plot:
        raise ValueError("no-map applies to --plot only")
    params = resolve_parameters(args)
    if args.scenario == "corridor" and args.L is not None and args.parameter in ("V", "f"):  # the report's words
        from ..parameters import Corridor, check_corridor_fits

        check_corridor_fits(Corridor(args.L), params.robot)
    if args.plot or args.sweep_plot:
        import matplotlib

        matplotlib.use("Agg")

    from ..serialize import SCHEMA_VERSION

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
        print(json.dumps(out, indent=2, allow_nan=False, default=json_default))
    else:
        print(render_text(validation, sweep, params.sources, args.plot, args.sweep_plot), end="")
    return 0


def _work(args, params, progress):
    """The bisection (and the sweep): (BoundaryValidation, SweepResult or None)."""
    from ..parameters import Wall
    from ..validation import validate_boundary, verdict_sweep

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
        stability_map=(7, 9) if args.plot and not args.no_map else None,
        progress=progress,
    )
    sweep = None
    if args.sweep:
        sweep = verdict_sweep(
            args.sweep, seed=args.seed, env=args.env, robot=params.robot, controller=params.controller,
            pade_order=args.pade_order, progress=progress,
        )
    return validation, sweep


def _num(value, digits=5):
    import math

    if value is None or not math.isfinite(value):
        return "none" if value is None or value > 0 else "0"
    return f"{value:.{digits}g}"


def _pct(value):
    return "      -" if value is None else f"{100 * value:+7.2f} %"


def render_text(v, sweep=None, sources=None, plot=None, sweep_plot=None) -> str:
    """Human-readable validation report: boundaries, errors, oscillation checks, sweep."""
    i = v.inputs
    unit = f" {v.unit}" if v.unit else ""
    name = {"L": "L*", "alpha": "alpha*", "V": "V*", "f": "f*"}[v.parameter]
    head = f"{name} ({v.unit})" if v.unit else name
    assumed = [k for k, s in (sources or {}).items() if str(s).startswith("ASSUMED")]
    fixed = f", L = {i['L']:g} m" if i.get("L") is not None else (f", alpha = {i['alpha_deg']:g} deg" if i.get("alpha_deg") is not None else "")
    lines = [
        f"validate {v.scenario} ({v.env}{fixed}): bisecting {v.parameter}",
        f"  robot: V = {i['V']:g} m/s, tau = {i['tau']:g} s, k = {i['k']:g} 1/s, W = {i['W']:g} m; controller: f = {i['f']:g}, "
        f"n = {i['n']:g}, T = {i['T']:g} s, hold = {i['hold']}, compute_delay = {i['compute_delay']}",
    ]
    if assumed:
        lines.append(f"  assumed by the preset: {', '.join(assumed)} (see --format json inputs.sources)")
    lines += [
        f"simulated boundary: {name} = {_num(v.simulated_boundary, 6)}{unit} (stable {'above' if v.stable_above else 'below'}; "
        f"bracket [{_num(v.bracket[0], 6)}, {_num(v.bracket[1], 6)}]{unit}; {v.runs} runs in {v.seconds:.1f} s)",
        f"predicted boundary, law: {v.law}" + (f"   | KB's lumped law, f_av = {i['f_av']:.4g}" if v.lumped_predicted_boundary else ""),
        f"  {'model':16s} {head:>12s} {'rel. error':>10s}" + (f"   | {head:>12s} {'rel. error':>10s}" if v.lumped_predicted_boundary else ""),
    ]
    for model, value in v.predicted_boundary.items():
        row = f"  {model:16s} {_num(value):>12s} {_pct(v.relative_error[model]):>10s}"
        if v.lumped_predicted_boundary:
            row += f"   | {_num(v.lumped_predicted_boundary[model]):>12s} {_pct(v.lumped_relative_error[model]):>10s}"
        lines.append(row)
    lines.append("oscillation near the boundary (measured vs the sampled model's dominant root):")
    for c in v.oscillation:
        s = "undefined" if c.growth_rate is None else f"{c.growth_rate:+.4f}"
        w = "undefined" if c.angular_frequency is None else f"{c.angular_frequency:.4f}"
        fe = "" if c.frequency_error is None else f", {100 * c.frequency_error:+.3f} %"
        lines.append(
            f"  {v.parameter} = {c.value:.6g}{unit}: sigma = {s} 1/s (model {c.predicted_growth_rate:+.4f}), "
            f"omega = {w} rad/s (model {c.predicted_angular_frequency:.4f}{fe}) [{c.method}]"
        )
    if sweep is not None:
        lines += render_sweep(sweep).splitlines()
    lines.append("notes:")
    lines += [f"  {key}: {value}" for key, value in v.notes.items()]
    if plot:
        lines.append(f"plot: {plot}")
    if sweep_plot:
        lines.append(f"sweep plot: {sweep_plot}")
    return "\n".join(lines) + "\n"


def render_sweep(sweep) -> str:
    """The sweep's agreement, each model's wrong-verdict rate, and every disagreement."""
    lines = [
        f"random sweep: {sweep.count} Latin-hypercube sets ({sweep.env}, seed {sweep.seed}), {sweep.included} outside "
        f"+-{100 * sweep.exclude:g} % of the sampled boundary (in NV), {sweep.seconds:.1f} s",
        f"  simulated sign of sigma agrees with sampled on {100 * sweep.agreement:.2f} % ({len(sweep.disagreements)} disagreements)",
        "  wrong verdicts for the sampled robot (model stable but robot oscillates / model unstable but robot stable):",
    ]
    for model, rate in sweep.wrong_verdict_rate.items():
        w = sweep.wrong_verdicts[model]
        lines.append(f"    {model:16s} {100 * rate:6.2f} %  ({w['stable_but_unstable']} / {w['unstable_but_stable']})")
    if sweep.disagreements:
        lines.append("  disagreements:")
        lines += [f"    {p.describe()}" for p in sweep.disagreements]
    return "\n".join(lines) + "\n"
