"""``pfm-stability plot KIND --out FILE.png``: pictures of the analysis.

Kinds: ``rlocus`` (root locus of the Padé loop with the critical crossings of
every model), ``gain-vs-k`` (NV* against the steering gain k for all models),
``force-law`` (the grid's effective force law against KB's lumped law).
"""

from __future__ import annotations

from .options import PADE_ORDER, add_parameter_options, check, describe, output_path, resolve_parameters

KINDS = ("rlocus", "gain-vs-k", "force-law")


def add_parser(sub) -> None:
    p = sub.add_parser("plot", help="save a plot as PNG (root locus, NV* vs k, grid force law)", description=__doc__.splitlines()[0])
    p.add_argument("kind", choices=KINDS, help="what to draw")
    p.add_argument("--out", required=True, type=output_path("out"), metavar="PNG",
                   help="output file, ending in .png, in an existing writable directory")
    p.add_argument("--pade-order", type=PADE_ORDER, default=3, metavar="M", help=f"Padé order m, {describe('pade_order')} (default 3)")
    add_parameter_options(p)
    p.set_defaults(run=run)


def _draw(kind, params, pade_order):
    """The figure of `kind`: the result computed (`analysis.comparison`), drawn by its ``.plot()``; the grid's force law."""
    robot, controller = params.robot, params.controller
    if kind == "rlocus":
        from ..analysis.comparison import root_locus
        from ..analysis.criteria import loop_of

        return root_locus(loop_of(robot, controller), pade_order=pade_order, hold=controller.hold, compute_delay=controller.compute_delay).plot()
    if kind == "gain-vs-k":
        from ..analysis.comparison import critical_gain_vs_k

        return critical_gain_vs_k(robot.tau, controller.T, pade_order=pade_order).plot()
    from ..plots.force import plot_force_summary
    from ..sim.scenario import scenario_law

    return plot_force_summary(scenario_law("grid", robot, controller, params.preset.window_cells, params.preset.cell_size))


def run(args) -> int:
    params = resolve_parameters(args)
    if args.kind == "rlocus":
        try:
            check("T_sampled", params.controller.T)
        except ValueError as exc:
            raise ValueError(f"{exc} (the root locus is drawn for the delay loop, which needs T > 0)") from None
    import matplotlib

    matplotlib.use("Agg")

    from ..io.files import save_figure

    save_figure(_draw(args.kind, params, args.pade_order), args.out, dpi=130, what="plot")
    print(f"wrote {args.out}")
    return 0
