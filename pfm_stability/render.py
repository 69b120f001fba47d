"""Text and Markdown renderings of a `StabilityReport` (the JSON form is `to_dict`)."""

from __future__ import annotations

import math

__all__ = ["render_text", "render_markdown"]

_LABELS = {
    "V": "V (speed)",
    "tau": "tau (steering time constant)",
    "T": "T (sampling period)",
    "k": "k (steering gain)",
    "f": "f (force ratio)",
    "n": "n (repulsion exponent)",
    "W": "W (robot width)",
    "hold": "hold (sampled structure)",
    "compute_delay": "compute delay",
    "pade_order": "Pade order m",
    "alpha_deg": "alpha (target angle to wall normal)",
    "L": "L (corridor half-width)",
}

_REMEDY_UNITS = {"V": "m/s", "T": "s", "k": "1/s", "alpha_deg": "deg", "L": "m", "f": ""}
_REMEDY_NAMES = {"V": "V", "T": "T", "k": "k", "alpha_deg": "alpha", "L": "L", "f": "f"}


def _percent(x) -> str:
    """A JSON margin as a signed percentage ("-" undefined, "inf" infinite)."""
    if x is None or isinstance(x, str):
        return _num(x)
    return f"{x * 100:+.1f}%"


def _num(x, digits=4) -> str:
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:.{digits}g}"


def _rows(report):
    """Yield (scenario title, [(model, cells...)], remedies) for each scenario."""
    data = report.to_dict()
    for scenario in ("wall", "corridor"):
        if scenario not in data:
            continue
        env = data["environment"][scenario]
        if scenario == "wall":
            title = (
                f"Wall, alpha = {_num(env['alpha_deg'])} deg: equilibrium d0 = {_num(env['d0'])} m, "
                f"N = {_num(env['N'])} 1/m, NV = {_num(env['NV'])} 1/s"
            )
            header = ["model", "verdict", "margin", "NV* 1/s", "omega* rad/s", "alpha* deg", "f*", "V* m/s", "T* s", "k* 1/s"]
            keys = ["alpha_critical_deg", "f_critical", "V_critical", "T_critical", "k_critical"]
        else:
            title = f"Corridor, L = {_num(env['L'])} m: N = {_num(env['N'])} 1/m, NV = {_num(env['NV'])} 1/s"
            header = ["model", "verdict", "margin", "NV* 1/s", "omega* rad/s", "L* m", "V* m/s", "f*", "T* s", "k* 1/s"]
            keys = ["L_critical", "V_critical", "f_critical", "T_critical", "k_critical"]
        rows = []
        for name, v in data[scenario].items():
            margin = _percent(v["margin"])
            cells = [name, v["verdict"].upper() if v["verdict"] != "stable" else "stable", margin, _num(v["NV_critical"]), _num(v["omega_critical"])]
            cells += [_num(v[k]) for k in keys]
            rows.append(cells)
        fixes = {name: v["to_stabilize"] for name, v in data[scenario].items() if v["verdict"] != "stable"}
        yield title, header, rows, fixes


def _remedy_line(model: str, fix: dict) -> str:
    if not fix:
        return f"  to stabilize ({model}): no change of V, T, k, alpha, L or f alone helps; change tau or several parameters"
    parts = []
    for name, entry in fix.items():
        unit = _REMEDY_UNITS[name]
        bound = ">=" if entry["direction"] == "raise" else "<="
        change = f" ({entry['change_percent']:+.0f} %)" if "change_percent" in entry else ""
        parts.append(f"{entry['direction']} {_REMEDY_NAMES[name]} to {bound} {_num(entry['to'])}{(' ' + unit) if unit else ''}{change}")
    return f"  to stabilize ({model}), change one of: " + "; ".join(parts)


def _table(header, rows, sep="  "):
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    fmt = lambda cells: sep.join(str(c).ljust(w) if i == 0 else str(c).rjust(w) for i, (c, w) in enumerate(zip(cells, widths)))  # noqa: E731
    return [fmt(header)] + [fmt(r) for r in rows]


def render_text(report) -> str:
    """Readable plain-text report: inputs, per-model table, remedies, KB's error."""
    data = report.to_dict()
    lines = ["pfm-stability report (Koren & Borenstein 1991 robot-environment loop)", "", "Inputs"]
    for name, entry in data["inputs"].items():
        unit = f" {entry['unit']}" if entry["unit"] else ""
        mark = "  <-- " + entry["source"] if entry["source"].startswith("ASSUMED") else f"  ({entry['source']})"
        lines.append(f"  {_LABELS[name]:<38} {_num(entry['value'])}{unit}{mark}")
    lines += ["", "Models"]
    for name, entry in data["models"].items():
        options = ", ".join(f"{k}={v}" for k, v in entry.items() if k != "equation")
        lines.append(f"  {name:<15} {entry['equation']}{'  [' + options + ']' if options else ''}")
    for title, header, rows, fixes in _rows(report):
        lines += ["", title]
        lines += ["  " + line for line in _table(header, rows)]
        for model, fix in fixes.items():
            lines.append(_remedy_line(model, fix))
    lines += [
        "",
        "margin = relative distance in NV to the nearest stability boundary (NV*/NV - 1 when the stable set is (0, NV*); "
        "> 0 stable). Starred values are critical with the other inputs fixed: every V below V*, T below T* and k below k* "
        "is stable (T*, k*: where this operating point first loses stability); NV* = 0 and V* = 0 mean unstable at any speed; "
        "inf = no limit; - = undefined.",
    ]
    if report.kb_error is not None:
        e = report.kb_error
        lines += ["", f"{e.sentence()}: NV* = {_num(e.NV_kb)} vs {_num(e.NV_sampled)} 1/s."]
    return "\n".join(lines) + "\n"


def render_markdown(report) -> str:
    """The same content as `render_text`, as Markdown tables."""
    data = report.to_dict()
    lines = ["# pfm-stability report", "", "| input | value | unit | source |", "| --- | --- | --- | --- |"]
    for name, entry in data["inputs"].items():
        source = f"**{entry['source']}**" if entry["source"].startswith("ASSUMED") else entry["source"]
        lines.append(f"| {_LABELS[name]} | {_num(entry['value'])} | {entry['unit']} | {source} |")
    for title, header, rows, fixes in _rows(report):
        lines += ["", f"## {title}", "", "| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
        lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
        for model, fix in fixes.items():
            lines.append("")
            lines.append("-" + _remedy_line(model, fix)[1:])
    if report.kb_error is not None:
        e = report.kb_error
        lines += ["", f"{e.sentence()}: NV* = {_num(e.NV_kb)} vs {_num(e.NV_sampled)} 1/s."]
    return "\n".join(lines) + "\n"
