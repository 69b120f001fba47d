"""Numbers and tables as text, shared by the renderers (`cli.render`, `cli.render_families`)."""

from __future__ import annotations

import math

__all__ = ["number", "percent", "table"]


def number(x, digits: int = 4) -> str:
    """A JSON number as text: ``digits`` significant digits, "-" undefined (None), "inf"/"-inf", strings as they are.

    Parameters
    ----------
    x : float, str or None
        A JSON number (``"inf"``, ``"-inf"``, None) or any string.
    digits : int, optional
        Significant digits.
    """
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:.{digits}g}"


def percent(x) -> str:
    """A JSON ratio as a signed percentage with one decimal ("-" undefined, "inf" infinite).

    Parameters
    ----------
    x : float, str or None
        A JSON ratio (1 = 100 %).
    """
    if x is None or isinstance(x, str):
        return number(x)
    return f"{x * 100:+.1f}%"


def table(header, rows, sep: str = "  ") -> list[str]:
    """Aligned text table: the first column left-aligned, the others right-aligned; one string per line.

    Parameters
    ----------
    header : sequence of str
        Column titles.
    rows : sequence of sequence of str
        The cells, one sequence per row.
    sep : str, optional
        Text between columns.
    """
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]

    def line(cells):
        return sep.join(str(c).ljust(w) if i == 0 else str(c).rjust(w) for i, (c, w) in enumerate(zip(cells, widths)))

    return [line(header)] + [line(r) for r in rows]
