"""``pfm-stability report``: every model's verdict for a wall and/or a corridor (and a door), for every robot family (``--robot``)
and force law (``--law``, docs/fields.md, docs/velocity_and_fuzzy.md): `report.stability.build_report`, rendered."""

from __future__ import annotations

from ..laws.registry import FAMILY_LAWS, FORCE_LAWS
from ..parameters import DOOR_OBSTACLES, MODEL_NAMES
from .options import (PADE_ORDER, add_controller_options, refuse_vff_options, add_family_options, add_law_options, add_parameter_options, describe, number,
                      resolve_family, resolve_parameters, resolve_tracker)

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
    add_controller_options(p)
    p.add_argument("--alpha", type=number("alpha_deg"), help=f"wall: target angle from the wall normal, {describe('alpha_deg')}")
    p.add_argument("--L", type=number("L"), help=f"corridor half-width, {describe('L')}, and more than W/2")
    p.add_argument("--door", type=number("door"), metavar="WIDTH",
                   help=f"door (KB Fig 4; docs/door.md): distance between the posts' centres or the wall ends, {describe('door')}")
    p.add_argument("--door-obstacle", choices=DOOR_OBSTACLES, default="posts", help="what bounds the door (default posts)")
    p.add_argument("--post-radius", type=number("post_radius"), default=0.0,
                   help=f"post radius, or the walls' half-thickness, {describe('post_radius')} (default 0)")
    p.add_argument("--wobble", type=number("wobble"), nargs="?", const=True, default=None, metavar="TOL",
                   help=f"corridor: the limit cycle past V* by describing functions (docs/wobble.md) and the fastest speed whose "
                        f"wobble stays under TOL, {describe('wobble')} (default a tenth of L - W/2)")
    p.add_argument("--disturbance", type=number("disturbance"), default=None, metavar="D",
                   help=f"a start D m off the equilibrium (corridor and/or wall): the speed at or below which it settles, the cycle "
                        f"it grows into past it, sub- or supercritical, with the drive's --yaw-accel-limit (docs/wobble.md), "
                        f"{describe('disturbance')}")
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

    params = resolve_parameters(args, notes=str(args.controller) == "vff")  # a Nav2 controller's notes are its report's
    path = resolve_tracker(args, params)
    if path is not None:
        report = _path_report(args, path)
    else:
        report = _vff_report(args, params)
    if args.format == "json":
        print(dumps(report.to_dict()))
    elif args.format == "markdown":
        print(render_markdown(report), end="")
    else:
        print(render_text(report), end="")
    return 0


def _path_report(args, path):
    """A Nav2 controller's report (`report.stability.build_report` with its ``tracker``; docs/path_tracking.md)."""
    from ..report.stability import build_report

    refuse_vff_options(args, path)
    return build_report(
        path.robot, path.controller, alpha_deg=args.alpha, L=args.L, door=args.door, wobble=args.wobble,
        models=tuple(dict.fromkeys(args.model)) if args.model else MODEL_NAMES, pade_order=args.pade_order,
        sources={"L": "user", **path.sources, "pade_order": "user" if args.pade_order != DEFAULT_PADE_ORDER else "default"},
        tracker=path.tracker, gains=path.gains,
    )


def _vff_report(args, params):
    """Today's report: the VFF loop for the robot family and law of the options."""
    from ..report.stability import build_report

    chosen = resolve_family(args, params)
    return build_report(
        params.robot,
        params.controller,
        family=chosen.family,
        law=chosen.law,
        alpha_deg=args.alpha,
        L=args.L,
        models=tuple(dict.fromkeys(args.model)) if args.model else MODEL_NAMES,
        pade_order=args.pade_order,
        mass=chosen.mass,
        sources={
            "alpha_deg": "user", "L": "user", **params.sources, **chosen.sources,  # a --config scenario names its file
            "pade_order": "user" if args.pade_order != DEFAULT_PADE_ORDER else "default",
        },
        door=args.door,
        door_obstacle=args.door_obstacle,
        post_radius=args.post_radius,
        simulate_cycle=None if args.no_simulate else _simulated_cycle,
        wobble=args.wobble,
        disturbance=args.disturbance,
    )


def _simulated_cycle(*args, **kwargs) -> dict:
    """`validation.non_smooth.simulated_cycle`, imported only when a non-smooth wall asks for its cycle."""
    from ..validation.non_smooth import simulated_cycle

    return simulated_cycle(*args, **kwargs)
