"""``pfm-stability map``: where along a building's corridors the robot oscillates, from a ROS occupancy map.

    pfm-stability map MAP.yaml [--V 0.8 ...] [--out-dir DIR] [--validate N] [--format text|json]
    pfm-stability map depot                     # a map shipped with the package

MAP is a ROS ``map_server`` YAML file (its image beside it) or the name of a shipped
map (`SHIPPED_MAPS`). The analysis (docs/maps.md) reduces the map onto the robot's
histogram grid, finds the corridors (the medial axis of the free space) as straight
segments and decides each with the chosen loop model (default: ``sampled`` with the
controller's hold and compute delay): N, V*, margin, verdict. The text output is a
table of the worst segments and a summary; ``--format json`` prints ``map``,
``inputs``, ``segments``, ``summary``, ``warnings``, ``validation`` (null without
``--validate``: else ``agreement`` and the counts ``agreed``, ``disagreed``,
``not_measurable``, ``measured``), ``outputs``, ``timing``. A map whose scale looks
wrong for the robot (a resolution typo) is analysed with a one-line warning on
stderr, also in ``warnings``. ``--out-dir DIR`` writes ``stability.png``, ``segments.csv``,
``speed_mask.pgm`` and ``speed_mask.yaml`` (a Nav2 Speed Filter mask), all or none.
A bad map, or a name that is neither a file nor a shipped map, is one line naming the
file and the problem, exit status 2.
"""

from __future__ import annotations

import argparse

from ..laws.registry import DEFAULT_LAW, laws_for
from ..parameters import MODEL_NAMES
from .options import (add_controller_options, add_law_options, add_parameter_options, describe, input_file, integer, number,
                      refuse_vff_options, resolve_law, resolve_parameters, resolve_tracker, shipped_or_given)

FORMATS = ("text", "json")
SHIPPED_MAPS = ("depot", "warehouse", "tb3_sandbox")
"""Maps in ``pfm_stability/data/maps`` (Nav2's ``nav2_bringup``, Apache-2.0), usable by name."""
UNKNOWN_CHOICES = ("occupied", "free")


def _out_dir(text: str) -> str:
    from ..checks import check_output_dir

    try:
        return check_output_dir("out-dir", text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


_out_dir.kind = "directory"  # for the command-line fuzzer (tests/test_cli_fuzz.py)


def add_parser(sub) -> None:
    p = sub.add_parser(
        "map",
        help="stability along every corridor of a ROS occupancy map; a Nav2 speed mask",
        description="Reads a ROS map_server map (YAML + image), computes the VFF repulsion of its histogram grid, finds "
        "the corridors (medial axis of the free space) and says along each straight segment whether the robot oscillates "
        "at its speed V and the fastest stable speed V* (docs/maps.md).",
    )
    p.add_argument("map", metavar="MAP", help=f"map_server YAML file, or a shipped map: {', '.join(SHIPPED_MAPS)}")
    add_parameter_options(p)
    add_law_options(p, laws_for("map"), default=DEFAULT_LAW["map"])  # a Default: a --config FILE's law beats it (`options.typed`)
    add_controller_options(p)  # --controller rpp: Nav2's Regulated Pure Pursuit along the routes (maps.deciding.tracking)
    p.add_argument("--model", choices=MODEL_NAMES, default="sampled",
                   help="loop model of the verdicts (default sampled, with the controller's hold and compute delay)")
    p.add_argument("--out-dir", type=_out_dir, metavar="DIR",
                   help="write stability.png, segments.csv, speed_mask.pgm and speed_mask.yaml here (created if missing)")
    p.add_argument("--validate", type=integer("validate"), metavar="N",
                   help=f"simulate the robot along N segments and compare with the verdicts, {describe('validate')}")
    p.add_argument("--unknown", choices=UNKNOWN_CHOICES, default="occupied", help="how unknown map cells count (default occupied)")
    p.add_argument("--min-length", type=number("min_length"), metavar="M",
                   help=f"shortest segment analysed, {describe('min_length')} (default the larger of 1 m and 1.25 W)")
    p.add_argument("--seed", type=integer("seed"), default=0, help=f"seed of the --validate selection, {describe('seed')} (default 0)")
    p.add_argument("--route", type=input_file("route"), action="append", metavar="FILE",
                   help="also judge your own route: a Nav2 path (nav_msgs/Path as YAML), waypoints in YAML, or a CSV of x,y (m); repeatable")
    p.add_argument("--goals", type=input_file("goals"), metavar="FILE",
                   help="drive the simulated robot between these goals (YAML or CSV of x,y, m) and judge the paths it takes")
    p.add_argument("--dilate-upstream", type=number("dilate_upstream"), metavar="A_MAX",
                   help="with --out-dir: extend each unstable route stretch's slow zone of the speed mask by the braking distance "
                   f"(V^2 - V*^2)/(2 A_MAX) along its route, both ways (Nav2's speed filter slows the robot only inside a zone), "
                   f"A_MAX {describe('dilate_upstream')}")
    p.add_argument("--wobble", type=number("wobble"), metavar="TOL",
                   help="the speed mask's zones (segments and route stretches) at V_tolerance, the fastest speed whose wobble stays "
                   f"under TOL (docs/wobble.md), instead of V* where the describing function is trusted; TOL {describe('wobble')}")
    p.add_argument("--format", choices=FORMATS, default="text")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(run=run)


def map_path(name: str) -> str:
    """The YAML file of `name`: a shipped map's (by name) or `name` itself (ValueError naming the shipped maps if neither)."""
    return shipped_or_given(name, "maps", SHIPPED_MAPS, "map")


def _validate(analysis, count: int, seed: int, progress):
    from ..laws.effective_force import GridWallLaw

    if not isinstance(analysis.law, GridWallLaw):
        raise ValueError("validate needs --law grid: the simulator senses the map through its histogram grid")
    from ..validation.maps import simulator_grid, validate_map_segments

    law = analysis.law
    return validate_map_segments(simulator_grid(analysis.grid), analysis.segments, analysis.robot, analysis.controller,
                                 cell_ratio=law.ratio, window_cells=law.window_cells, count=count, seed=seed, progress=progress)


def _user_routes(files) -> list:
    """The routes of every ``--route FILE`` (`maps.reading.user_routes.read_routes`)."""
    from ..maps.reading.user_routes import read_routes

    routes = []
    for name in files:
        routes += read_routes(name, len(routes))
    return routes


def _with_goals(analysis, goals_file: str, progress):
    """The analysis with the paths the simulated robot takes between the goals of ``--goals FILE``."""
    from ..maps.analysis import add_routes
    from ..maps.reading.user_routes import read_points
    from ..validation.map_drives import goal_routes

    return add_routes(analysis, goal_routes(analysis, read_points(goals_file)[0], progress))


def _drive(analysis, count: int, seed: int, progress):
    """Validation by driving (`validation.map_drives.drive_map`): recall and precision of the routes' unstable stretches."""
    from ..validation.map_drives import drive_map

    return drive_map(analysis, count, seed=seed, progress=progress)


def _write_outputs(analysis, out_dir: str, drives=None, a_max=None) -> dict:
    """The files of ``--out-dir``, all or none (`files.atomic_directory`): the result set's picture and CSV (the routes'
    stretches, with the drives' episodes; the segments with the power law) and the speed mask."""
    import os

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..io.files import atomic_directory, open_new
    from ..maps.deciding.outputs import MASK_FILES, ROUTE_FILES, SEGMENT_FILES, routes_csv, segments_csv, speed_mask_pgm, speed_mask_yaml
    from ..plots.map import plot_map_stability
    from ..plots.map_routes import plot_route_verdicts

    by_route = analysis.paths is not None
    names = (ROUTE_FILES if by_route else SEGMENT_FILES) + MASK_FILES
    picture, table = names[:2]
    with atomic_directory(out_dir, names, what="map outputs") as paths:
        fig = plot_route_verdicts(analysis, drives) if by_route else plot_map_stability(analysis)
        try:
            with open_new(paths[picture], "wb") as fh:
                fig.savefig(fh, format="png", dpi=110)
        finally:
            plt.close(fig)
        for name, content in ((table, (routes_csv if by_route else segments_csv)(analysis).encode("utf-8")),
                              ("speed_mask.pgm", speed_mask_pgm(analysis, a_max)),
                              ("speed_mask.yaml", speed_mask_yaml(analysis.occupancy).encode("utf-8"))):
            with open_new(paths[name], "wb") as fh:
                fh.write(content)
    return {name: os.path.join(out_dir, name) for name in names}


def run(args) -> int:
    import sys
    import time

    from ..extras import require

    require("maps", "pfm-stability map")

    from ..maps.analysis import analyze_map, check_map_law
    from ..maps.reading.occupancy import load_map
    from ..io.serialize import dumps
    from .progress import line_progress
    from .render import render_map_text

    started = time.perf_counter()
    if str(args.controller) not in ("vff", "auto", *TRACKING_CONTROLLERS):
        raise ValueError(f"--controller {args.controller}: map decides --controller vff or {', '.join(TRACKING_CONTROLLERS)} along a map's "
                         "routes (docs/maps.md, \"Nav2's controllers along a map\")")
    params = resolve_parameters(args, notes=str(args.controller) == "vff")
    path = resolve_tracker(args, params)
    if path is not None:
        return _run_tracking(args, path, started)
    law, _ = resolve_law(args, params)
    check_map_law(law)  # the law resolved: typed, or named by --config FILE
    occupancy = load_map(map_path(args.map))
    with line_progress("map", quiet=args.quiet) as progress:
        routes = _user_routes(args.route or ())
        analysis = analyze_map(occupancy, params.robot, params.controller, law, model=args.model, unknown=args.unknown,
                               corridors=args.wobble is not None,  # the wobble reads the segments too (maps.deciding.wobble_zones)
                               cell_size=args.cell_size, min_length=args.min_length, progress=progress,
                               warn=lambda line: print(f"pfm-stability: warning: {line}", file=sys.stderr, flush=True), routes=routes)
        if args.goals:
            analysis = _with_goals(analysis, args.goals, progress)
        if args.wobble is not None:
            from ..maps.deciding.wobble_zones import with_wobble

            analysis = with_wobble(analysis, args.wobble)
            if progress is not None:
                progress("wobble done")
        drives = _drive(analysis, args.validate, args.seed, progress) if args.validate and analysis.paths is not None else None
        validation = drives if drives is not None else (_validate(analysis, args.validate, args.seed, progress)
                                                         if args.validate and analysis.segments else None)
        outputs = _write_outputs(analysis, args.out_dir, drives, args.dilate_upstream) if args.out_dir else None
    data = {
        **analysis.to_dict(),
        "validation": ({"kind": "drives" if drives is not None else "segments", **validation.to_dict()}
                       if validation is not None else None),
        "outputs": outputs,
        "timing": {"seconds": time.perf_counter() - started, **{f"{k}_seconds": v for k, v in analysis.timing.items()}},
    }
    if args.wobble is not None:
        from ..maps.deciding.wobble_zones import wobble_summary

        data["wobble"] = wobble_summary(analysis, args.wobble).to_dict()
    if args.format == "json":
        print(dumps({"schema_version": _schema_version(), "command": "map", **data}))
    else:
        print(render_map_text(data), end="")
    return 0


TRACKING_CONTROLLERS = ("rpp",)
"""The Nav2 controllers ``map --controller`` decides (`maps.deciding.tracking.MAP_CONTROLLERS`; numpy-free here for the refusal)."""
_VFF_ONLY = ("validate", "wobble", "goals", "min_length")
"""``map`` options of the VFF analysis alone (refused with a Nav2 controller, `_run_tracking`); ``--seed`` too when typed."""


def _run_tracking(args, path, started: float) -> int:
    """``map --controller rpp``: the controller along every route (`maps.deciding.tracking.analyze_map_tracking`), its outputs."""
    import sys
    import time

    from ..extras import require

    given = [(f"--{key.replace('_', '-')}", getattr(args, key, None) is not None) for key in _VFF_ONLY] + [("--seed", args.seed != 0)]
    refuse_vff_options(args, path, given, keep=("cell_size",))
    if path.tracker.controller not in TRACKING_CONTROLLERS:
        raise ValueError(f"--controller auto found {path.tracker.controller} in the Nav2 file: map decides --controller vff or "
                         f"{', '.join(TRACKING_CONTROLLERS)} along a map's routes")
    require("maps", "pfm-stability map")
    from ..io.serialize import dumps
    from ..maps.reading.occupancy import load_map
    from ..maps.deciding.tracking import analyze_map_tracking
    from .progress import line_progress
    from .render import render_map_tracking_text

    occupancy = load_map(map_path(args.map))
    with line_progress("map", quiet=args.quiet) as progress:
        analysis = analyze_map_tracking(occupancy, path.robot, path.controller, path.tracker, model=args.model, unknown=args.unknown,
                                        cell_size=args.cell_size if args.cell_size is not None else 0.1, routes=_user_routes(args.route or ()),
                                        progress=progress, warn=lambda line: print(f"pfm-stability: warning: {line}", file=sys.stderr, flush=True))
        outputs = _write_tracking_outputs(analysis, args.out_dir, args.dilate_upstream) if args.out_dir else None
    data = {**analysis.to_dict(), "validation": None, "outputs": outputs,
            "timing": {"seconds": time.perf_counter() - started, **{f"{k}_seconds": v for k, v in analysis.timing.items()}}}
    if args.format == "json":
        print(dumps({"schema_version": _schema_version(), "command": "map", **data}))
    else:
        print(render_map_tracking_text(data), end="")
    return 0


def _tracking_picture(analysis) -> bytes:
    """``routes.png`` of ``map --controller`` (`plots.map_routes.plot_tracking_verdicts`), PNG bytes."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..plots.map_routes import plot_tracking_verdicts

    fig = plot_tracking_verdicts(analysis)
    try:
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=110)
        return buffer.getvalue()
    finally:
        plt.close(fig)


def _write_tracking_outputs(analysis, out_dir: str, a_max=None) -> dict:
    """The files of ``map --controller --out-dir``, all or none (`files.atomic_directory`): ``routes.png``, ``routes.csv``, the speed mask
    (`maps.deciding.outputs`) and the ZoneParameterFilter's mask and parameters (`maps.deciding.zone_filter`)."""
    import os

    from ..io.files import atomic_directory, open_new
    from ..maps.deciding.outputs import MASK_FILES, speed_mask_pgm, speed_mask_yaml, tracking_csv
    from ..maps.deciding.zone_filter import ZONE_FILES, zone_mask_pgm, zone_mask_yaml, zone_params_yaml

    contents = {"routes.png": _tracking_picture(analysis), "routes.csv": tracking_csv(analysis).encode("utf-8"),
                MASK_FILES[0]: speed_mask_pgm(analysis, a_max),
                MASK_FILES[1]: speed_mask_yaml(analysis.occupancy).encode("utf-8"), ZONE_FILES[0]: zone_mask_pgm(analysis),
                ZONE_FILES[1]: zone_mask_yaml(analysis.occupancy).encode("utf-8"), ZONE_FILES[2]: zone_params_yaml(analysis).encode("utf-8")}
    with atomic_directory(out_dir, tuple(contents), what="map outputs") as paths:
        for name, content in contents.items():
            with open_new(paths[name], "wb") as fh:
                fh.write(content)
    return {name: os.path.join(out_dir, name) for name in contents}


def _schema_version() -> str:
    from ..io.serialize import SCHEMA_VERSION

    return SCHEMA_VERSION
