"""``pfm-stability derive``: the Koren & Borenstein derivation, eq (5) → (25), step by step.

Prints every step of `pfm_stability.analysis.derivation.derivation` as plain text
(sympy's pretty printer) or as LaTeX (one ``equation*`` per step, tagged with
KB's equation number; renderers in `pfm_stability.cli.render`), for KB's
power law or a general force law F_r(d) (docs/theory.md). sympy is imported
only when the command runs, so the CLI starts fast.
"""

from __future__ import annotations

from ..parameters import DERIVATION_LAWS as LAWS
from .options import PADE_ORDER, describe

FORMATS = ("text", "latex")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "derive",
        help="print the symbolic derivation of Koren & Borenstein's eq (5)-(25)",
        description="Derive the robot-environment equation and its stability conditions "
        "(Koren & Borenstein 1991, eq 5-25) with sympy, misprints corrected.",
    )
    p.add_argument("--format", choices=FORMATS, default="text", help="plain text (default) or LaTeX")
    p.add_argument(
        "--law",
        choices=LAWS,
        default="power",
        help="force law: KB's power law F_r = f F_a W^n/d^n (default) or a general F_r(d)",
    )
    p.add_argument("--pade-order", type=PADE_ORDER, default=2, help=f"order m of the Pade form of (18) shown, {describe('pade_order')} (default 2)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..analysis.derivation import derivation
    from .render import render_derivation_latex, render_derivation_text

    steps = derivation(args.law, pade_order=args.pade_order)
    render = render_derivation_latex if args.format == "latex" else render_derivation_text
    print(render(steps, args.law), end="")
    return 0
