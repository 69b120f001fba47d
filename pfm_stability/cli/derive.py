"""``pfm-stability derive``: the Koren & Borenstein derivation, eq (5) → (25), step by step.

Prints every step of `pfm_stability.derivation.derivation` as plain text
(sympy's pretty printer) or as LaTeX (one ``equation*`` per step, tagged with
KB's equation number), for KB's power law or a general force law F_r(d).
sympy is imported only when the command runs, so the CLI starts fast.
"""

from __future__ import annotations

import textwrap

from .options import PADE_ORDER, describe

FORMATS = ("text", "latex")
LAWS = ("power", "general")  # = pfm_stability.derivation.LAWS (not imported: it imports sympy)


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
    from ..derivation import derivation

    steps = derivation(args.law, pade_order=args.pade_order)
    render = render_latex if args.format == "latex" else render_text
    print(render(steps, args.law), end="")
    return 0


def render_text(steps, law: str) -> str:
    """Steps as plain text: a numbered heading, the pretty-printed result, the explanation."""
    import sympy as sp

    lines = [
        f"Koren & Borenstein 1991, eq (5)-(25), derived with sympy ({law} force law).",
        "Misprints corrected: see `pydoc pfm_stability.derivation`.",
        "",
    ]
    for number, step in enumerate(steps, 1):
        lines.append(f"{number:2d}. KB ({step.equation}) {step.title}")
        lines.append(textwrap.indent(sp.pretty(step.expr, order="none", use_unicode=True, num_columns=76), "    "))
        lines.extend(textwrap.wrap(step.explanation, 76, initial_indent="    ", subsequent_indent="    "))
        lines.append("")
    return "\n".join(lines)


def render_latex(steps, law: str) -> str:
    """Steps as a LaTeX fragment (amsmath): a paragraph and an ``equation*`` per step."""
    import sympy as sp

    lines = [
        f"% Koren & Borenstein 1991, eq (5)-(25), derived with sympy ({law} force law); needs amsmath.",
        "",
    ]
    for step in steps:
        lines.append(rf"\paragraph{{{_latex_text(step.title)}}} {_latex_text(step.explanation)}")
        lines.append(r"\begin{equation*}")
        lines.append(f"  {sp.latex(step.expr, order='none')} \\tag{{{step.equation}}}")
        lines.append(r"\end{equation*}")
        lines.append("")
    return "\n".join(lines)


_LATEX_SPECIALS = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}


def _latex_text(text: str) -> str:
    """Escape LaTeX's special characters in running text."""
    return "".join(_LATEX_SPECIALS.get(ch, ch) for ch in text)
