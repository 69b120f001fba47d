"""``pfm-stability report``: every model's verdict for a wall and/or a corridor, with any force law (``--law``, docs/fields.md)."""

from __future__ import annotations

from ..laws.registry import FAMILY_LAWS, FORCE_LAWS
from ..parameters import DOOR_OBSTACLES, MODEL_NAMES, Wall
from .options import PADE_ORDER, add_family_options, add_law_options, add_parameter_options, describe, number, resolve_family, resolve_parameters

FORMATS = ("text", "json", "markdown")
DEFAULT_PADE_ORDER = 3


def add_parser(sub) -> None:
    p = sub.add_parser(
        "report",
        help="stability report for a wall (--alpha) and/or a corridor (--L)",
        description="Stability of the VFF robot-environment loop (Koren & Borenstein 1991) for every model.",
    )
    add_parameter_options(p)
    add_law_options(p, FORCE_LAWS + FAMILY_LAWS)
    add_family_options(p)
    p.add_argument("--alpha", type=number("alpha_deg"), help=f"wall: target angle from the wall normal, {describe('alpha_deg')}")
    p.add_argument("--L", type=number("L"), help=f"corridor half-width, {describe('L')}, and more than W/2")
    p.add_argument("--door", type=number("door"), metavar="WIDTH",
                   help=f"door (KB Fig 4; docs/door.md): distance between the posts' centres or the wall ends, {describe('door')}")
    p.add_argument("--door-obstacle", choices=DOOR_OBSTACLES, default="posts", help="what bounds the door (default posts)")
    p.add_argument("--post-radius", type=number("post_radius"), default=0.0,
                   help=f"post radius, or the walls' half-thickness, {describe('post_radius')} (default 0)")
    p.add_argument("--model", action="append", choices=MODEL_NAMES, help="model to include (repeatable; default: all)")
    p.add_argument(
        "--pade-order", type=PADE_ORDER, default=DEFAULT_PADE_ORDER,
        help=f"order m of the pade model, {describe('pade_order')} (default {DEFAULT_PADE_ORDER})",
    )
    p.add_argument("--format", choices=FORMATS, default="text")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..io.serialize import dumps
    from .render import render_markdown, render_text

    params = resolve_parameters(args)
    chosen = resolve_family(args, params)
    if _family(args, chosen):
        report = _family_report(args, params, chosen)
    else:
        report = _steering_report(args, params, chosen.law, chosen.sources)
    if args.format == "json":
        print(dumps(report.to_dict()))
    elif args.format == "markdown":
        print(render_markdown(report), end="")
    else:
        print(render_text(report), end="")
    return 0


def _family(args, chosen) -> bool:
    """Whether the report is another robot family's or a law of `parameters.FAMILY_LAWS` (else KB's report, unchanged)."""
    return chosen.family != "steering" or getattr(chosen.law, "name", None) in FAMILY_LAWS  # the law in force: typed or the file's


def _family_report(args, params, chosen):
    """`family_report.build_family_report` for ``--robot``/``--law``, the non-smooth wall's cycle simulated unless ``--no-simulate``."""
    from ..report.families import FamilyLaw, build_family_report

    if args.door is not None:
        raise ValueError(f"--door applies to --robot steering with a static law (power, grid, khatib, gnron), "
                         f"not to --robot {chosen.family} --law {getattr(chosen.law, 'name', None) or args.law}")
    sources = {"alpha_deg": "user", "L": "user", **params.sources, **chosen.sources,
               "pade_order": "user" if args.pade_order != DEFAULT_PADE_ORDER else "default"}
    report = build_family_report(
        params.robot, params.controller, family=chosen.family, law=chosen.law, alpha_deg=args.alpha, L=args.L,
        models=tuple(dict.fromkeys(args.model)) if args.model else MODEL_NAMES, pade_order=args.pade_order, mass=chosen.mass, sources=sources,
    )
    if isinstance(chosen.law, FamilyLaw) and chosen.law.name == "velocity-gated" and not args.no_simulate:
        from ..validation.non_smooth import fill_cycles

        report = fill_cycles(report, chosen.family, params.robot, params.controller, chosen.law, mass=chosen.mass)
    return report


def _steering_report(args, params, law, law_sources):
    """KB's steering robot with a static law: `report.build_report`, exactly as before the robot families."""
    from ..report.stability import build_report

    return build_report(
        params.robot,
        params.controller,
        alpha=Wall.from_degrees(args.alpha).alpha if args.alpha is not None else None,  # degrees in, radians on
        L=args.L,
        models=tuple(dict.fromkeys(args.model)) if args.model else MODEL_NAMES,
        pade_order=args.pade_order,
        sources={
            "alpha_deg": "user", "L": "user", **params.sources, **law_sources,  # a --config scenario names its file
            "pade_order": "user" if args.pade_order != DEFAULT_PADE_ORDER else "default",
        },
        law=law,
        door=args.door,
        door_obstacle=args.door_obstacle,
        post_radius=args.post_radius,
    )
