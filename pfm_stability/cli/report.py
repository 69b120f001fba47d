"""``pfm-stability report``: every model's verdict for a wall and/or a corridor."""

from __future__ import annotations

from .options import PADE_ORDER, add_parameter_options, describe, number, resolve_parameters

MODEL_CHOICES = ("continuous", "kb_first_order", "pade", "exact_delay", "sampled")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "report",
        help="stability report for a wall (--alpha) and/or a corridor (--L)",
        description="Stability of the VFF robot-environment loop (Koren & Borenstein 1991) for every model.",
    )
    add_parameter_options(p)
    p.add_argument("--alpha", type=number("alpha_deg"), help=f"wall: target angle from the wall normal, {describe('alpha_deg')}")
    p.add_argument("--L", type=number("L"), help=f"corridor half-width, {describe('L')}, and more than W/2")
    p.add_argument("--model", action="append", choices=MODEL_CHOICES, help="model to include (repeatable; default: all)")
    p.add_argument("--pade-order", type=PADE_ORDER, default=3, help=f"order m of the pade model, {describe('pade_order')} (default 3)")
    p.add_argument("--format", choices=("text", "json", "markdown"), default="text")
    p.set_defaults(run=run)


def run(args) -> int:
    import json

    from ..report import build_report
    from ..render import render_markdown, render_text

    params = resolve_parameters(args)
    report = build_report(
        params.robot,
        params.controller,
        alpha_deg=args.alpha,
        L=args.L,
        models=tuple(dict.fromkeys(args.model)) if args.model else MODEL_CHOICES,
        pade_order=args.pade_order,
        sources={**params.sources, "alpha_deg": "user", "L": "user", "pade_order": "user" if args.pade_order != 3 else "default"},
    )
    if args.format == "json":
        print(json.dumps(report.to_dict(), indent=2, allow_nan=False))
    elif args.format == "markdown":
        print(render_markdown(report), end="")
    else:
        print(render_text(report), end="")
    return 0
