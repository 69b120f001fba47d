"""``pfm-stability traps``: every stationary point of a 2-D scene's potential, and Ge & Cui's bounds on ξ/η.

    pfm-stability traps SCENE.yaml [--format text|json] [--plot FILE.png] [--resolution N]
    pfm-stability traps gc2000_fig4            # a scene shipped with the package

SCENE is a YAML scene file (docs/traps.md, "Scene files") or the name of a
scene shipped in ``pfm_stability/data/scenes`` (`SHIPPED_SCENES`). The text
output lists the stationary points (minima, saddles, maxima; the goal
marked), whether the goal is the global minimum, GC2000's exact and
conservative bounds k_n, k′_n for every obstacle within ρ0 of the goal, and a
one-line conclusion. JSON keys (`pfm_stability/schema/output.schema.json`):
``schema_version``, ``command`` ("traps"), ``inputs`` (the scene as read,
the resolution), ``stationary_points``, ``goal_is_global_minimum``,
``gnron_bounds``, ``conclusion``, ``plot``. A bad scene is one line naming
the field, exit status 2.
"""

from __future__ import annotations

from ..parameters import TRAPS_RESOLUTION
from .options import describe, integer, output_path, shipped_or_given

FORMATS = ("text", "json")
SHIPPED_SCENES = ("gc2000_fig3", "gc2000_fig4", "gc2000_sec6b_khatib", "gc2000_sec6b_gnron")
"""Scene files in ``pfm_stability/data/scenes`` (without ``.yaml``), usable by name."""


def add_parser(sub) -> None:
    p = sub.add_parser(
        "traps",
        help="find every stationary point (traps) of a 2-D potential field scene; Ge & Cui's bounds on xi/eta",
        description="Stationary points of the total potential of a 2-D scene (goal, circles, segments, polygons; "
        "Khatib's or Ge & Cui's goal-aware repulsion), the goal's verdict, and Ge & Cui 2000's exact and conservative "
        "bounds on xi/eta (eq 25-37) for every obstacle within rho0 of the goal.",
    )
    p.add_argument("scene", metavar="SCENE", help=f"scene YAML file, or a shipped scene: {', '.join(SHIPPED_SCENES)}")
    p.add_argument("--format", choices=FORMATS, default="text")
    p.add_argument("--plot", type=output_path("plot"), metavar="PNG",
                   help="write the potential with obstacles and stationary points (a .png file in an existing writable directory)")
    p.add_argument("--resolution", type=integer("resolution"), default=TRAPS_RESOLUTION,
                   help=f"grid points of the search along the region's longer side, {describe('resolution')} "
                   f"(default {TRAPS_RESOLUTION})")
    p.set_defaults(run=run)


def scene_path(name: str) -> str:
    """The file of `name`: a shipped scene's (by name) or `name` itself (ValueError naming the shipped scenes if neither)."""
    return shipped_or_given(name, "scenes", SHIPPED_SCENES, "scene")


def run(args) -> int:
    from .render import render_traps_text

    from ..io.serialize import dumps
    from ..laws.scene import Scene
    from ..analysis.traps import find_stationary_points

    analysis = find_stationary_points(Scene.load(scene_path(args.scene)), args.resolution)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")

        from ..io.files import save_figure
        from ..plots.traps import plot_traps

        save_figure(plot_traps(analysis), args.plot, dpi=110, what="plot")
    if args.format == "json":
        print(dumps({**analysis.to_dict(), "plot": args.plot}))
    else:
        print(render_traps_text(analysis) + (f"plot: {args.plot}\n" if args.plot else ""), end="")
    return 0
