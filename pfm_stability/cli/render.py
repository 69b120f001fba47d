"""Text, Markdown and LaTeX renderings of what the commands print (JSON is `serialize.dumps`).

One module for every human-readable rendering, with the number formatters
they share:

* ``report``: `render_text` and `render_markdown` of a `StabilityReport`: each
  geometry's section chosen by its result's type (a steering loop's
  `WallAnalysis`/`CorridorAnalysis` here; a holonomic or non-smooth scene in
  `render_families`), the numbers taken from its JSON form
  (`StabilityReport.to_dict`), so the text says exactly what the JSON says;
* ``derive``: `render_derivation_text` (sympy's pretty printer) and
  `render_derivation_latex` (one ``equation*`` per step) of
  `pfm_stability.analysis.derivation.derivation`;
* ``traps``, ``map``, ``sweep``: their summaries.

The renderings of simulated runs (``simulate``, ``validate``) are in `render_runs`.

Nothing heavy is imported at module level: sympy only inside the derivation
renderers.
"""

from __future__ import annotations

import functools
import math
import textwrap

from ..parameters import KB_PLANT, RANGES, SHOWN_AS
from .formatting import number, percent, table

__all__ = [
    "number",
    "percent",
    "table",
    "render_text",
    "render_markdown",
    "render_derivation_text",
    "render_derivation_latex",
    "render_traps_text",
    "render_map_text",
    "render_door_text",
    "render_parameter_sweep_text",
]


# ------------------------------------------------------------------ report
_LABELS = {
    "V": "V (speed)",
    "tau": "tau (steering time constant)",
    "T": "T (sampling period)",
    "k": "k (steering gain)",
    "dead_time": "D (steering plant dead time)",
    "plant_gain": "g (steering plant gain)",
    "actuator_lag": "tau_a (drive's second lag)",
    "slip_lag": "tau_s (course's lag)",
    "yaw_accel_limit": "R (drive's yaw accel limit)",
    "max_steering_rate": "omega_max (steering-rate limit)",
    "f": "f (force ratio)",
    "n": "n (repulsion exponent)",
    "W": "W (robot width)",
    "hold": "hold (sampled structure)",
    "compute_delay": "compute delay",
    "pade_order": "Pade order m",
    "alpha_deg": "alpha (target angle to wall normal)",
    "L": "L (corridor half-width)",
    "cell_ratio": "cell ratio F_cr/F_ct (grid)",
    "cell_size": "cell size (grid)",
    "window_cells": "window side (grid)",
    "xi": "xi (attractive scaling factor)",
    "eta": "eta (repulsive scaling factor)",
    "rho0": "rho0 (influence distance)",
    "attraction_exponent": "m (attraction exponent)",
    "goal_exponent": "n (goal exponent)",
    "goal_distance": "rho_g (goal distance, frozen)",
    "delta": "delta (surface offset, eq 40)",
}

_COLUMNS = {
    "wall": (["alpha* deg", "f*", "V* m/s", "T* s", "k* 1/s"], ["alpha_critical_deg", "f_critical", "V_critical", "T_critical", "k_critical"]),
    "corridor": (["L* m", "V* m/s", "f*", "T* s", "k* 1/s"], ["L_critical", "V_critical", "f_critical", "T_critical", "k_critical"]),
}
"""Per geometry: the table's critical-value columns and their JSON keys (`criteria.WallCritical`, `CorridorCritical`)."""

_FIELD_COLUMNS = (["eta*", "rho0* m", "xi*"], ["eta_critical", "rho0_critical", "xi_critical"])
"""Khatib's and the goal-aware law: the law's parameters in place of f* (docs/fields.md)."""

_SIDES = {
    "wall": {"NV_critical": "below", "alpha_critical_deg": "above", "f_critical": "above", "V_critical": "below", "T_critical": "below",
             "k_critical": "below", "dead_time_critical": "below"},
    "corridor": {"NV_critical": "below", "L_critical": "above", "f_critical": "below", "V_critical": "below", "T_critical": "below",
                 "k_critical": "below", "dead_time_critical": "below"},
}
"""The stable side of each starred column that the footnote names (docs/models.md, "Critical values"); a column whose
JSON ``stable_side`` differs anywhere (the nearest change of a law that is not monotone; η*, ρ0*, ξ* always) shows
each value as "<= x" or ">= x" instead."""

_FOOTNOTE = (
    "margin = relative distance in NV to the nearest stability boundary (NV*/NV - 1 when the stable set is (0, NV*); "
    "> 0 stable). Starred values are critical with the other inputs fixed; the loop is stable below NV*, V*, T* and k* "
    "(T*, k*: where this operating point first loses stability), above alpha* and L*, above a wall's f* and below a corridor's f*. "
    "A value shown as <= x or >= x is stable just below or just above x, the nearest value at which the verdict changes "
    "(a law that is not monotone, docs/fields.md). NV* = 0 and V* = 0 mean unstable at any speed; L* = 0: stable in every "
    "corridor the robot fits in; inf = no limit; - = undefined."
)


def _scenarios(report, data: dict):
    """Yield (title, header, rows, remedies, notes) of each geometry, by its result's type (`_sections_of`), with the values
    of the report's JSON form `data`."""
    for geometry, result in report.scenes():
        verdicts = {k: v for k, v in data[geometry].items() if k not in ("wobble", "disturbance")} if data.get(geometry) is not None else None
        yield from _sections_of(result)(result, data["environment"][geometry], verdicts, report)


def _sections_of(result):
    """The function yielding a result's sections, by the result's type: a steering loop's here (`_steering_sections`), another
    family's in `render_families` (imported for the families only)."""
    steering = _steering_sections()
    if type(result) in steering:
        return steering[type(result)]
    from .render_families import SECTIONS

    return SECTIONS[type(result)]


@functools.cache
def _steering_sections() -> dict:
    """`WallAnalysis` and `CorridorAnalysis` → their sections (built on first use: a report has loaded the types by then)."""
    from ..analysis.criteria import CorridorAnalysis, WallAnalysis

    return {WallAnalysis: _wall_sections, CorridorAnalysis: _corridor_sections}


def _wall_sections(wall, env: dict, verdicts: dict, report):
    """A steering loop beside a wall: one table per equilibrium (the fuzzy law's frozen gains under each, `render_families`)."""
    equilibria = env["equilibria"]
    for i, e in enumerate(equilibria):
        which = f", equilibrium {i + 1} of {len(equilibria)}: d0" if len(equilibria) > 1 else ": equilibrium d0"
        title = (
            f"Wall, alpha = {number(env['alpha_deg'])} deg{which} = {number(e['d0'])} m, "
            f"N = {number(e['N'])} 1/m, NV = {number(e['NV'])} 1/s"
        )
        notes = _reason_lines(e["models"])
        if report.schedule is not None:
            from .render_families import equilibrium_notes

            notes += equilibrium_notes(e)
        yield (title, *_verdict_table("wall", e["models"], wall.equilibria[i].models), notes)


def _corridor_sections(corridor, env: dict, verdicts: dict, report):
    """A steering loop in a corridor: one table, the notes on the finite goal and the equilibria off the centre line."""
    title = f"Corridor, L = {number(env['L'])} m: N = {number(env['N'])} 1/m, NV = {number(env['NV'])} 1/s"
    yield (title, *_verdict_table("corridor", verdicts, corridor.models), _reason_lines(verdicts) + _corridor_notes(env))


def _reason_lines(verdicts: dict) -> list[str]:
    """One line per distinct reason (N < 0, N = 0): the models giving it ("every model") and their verdict."""
    lines = []
    for reason in sorted({v["reason"] for v in verdicts.values() if "reason" in v}):
        names = [name for name, v in verdicts.items() if v.get("reason") == reason]
        labels = "/".join(sorted({verdicts[name]["verdict"] for name in names}))
        lines.append(f"  {'every model' if len(names) == len(verdicts) else ', '.join(names)}: {labels} ({reason})")
    return lines


def _verdict_table(scenario: str, verdicts: dict, models: dict):
    """(header, rows, remedies) of one geometry's verdicts (their JSON form; `models` the `ModelVerdict`s); a starred value
    whose stable side the footnote does not name as "<= x"/">= x"."""
    columns, keys = _COLUMNS[scenario]
    critical = next(iter(models.values())).critical if models else {}
    if models and "f_critical" not in critical:  # a law with its own parameters in place of f (none: velocity, fuzzy)
        at = keys.index("f_critical")
        own = _FIELD_COLUMNS if "eta_critical" in critical else ([], [])
        columns = columns[:at] + own[0] + columns[at + 1:]
        keys = keys[:at] + own[1] + keys[at + 1:]
    if "dead_time_critical" in critical:  # a robot with a dead time or a plant gain: D* (docs/models.md)
        columns, keys = columns + ["D* s"], keys + ["dead_time_critical"]
    header = ["model", "verdict", "margin", "NV* 1/s", "omega* rad/s"] + columns
    named = _SIDES[scenario]
    marked = {k for k in ["NV_critical", *keys] if any(v.get("stable_side", {}).get(k) not in (None, named.get(k)) for v in verdicts.values())}
    rows = []
    for name, v in verdicts.items():
        cells = [name, v["verdict"].upper() if v["verdict"] != "stable" else "stable", percent(v["margin"])]
        cells += [_starred(v, k, k in marked) for k in ["NV_critical", "omega_critical", *keys]]
        rows.append(cells)
    fixes = {name: (v["to_stabilize"], "eta_critical" in v) for name, v in verdicts.items()
             if v["verdict"] != "stable" and not (v["verdict"] == "undecided" and "reason" in v)}  # no model decides it: the reason says so
    return header, rows, fixes


def _starred(verdict: dict, key: str, marked: bool) -> str:
    """A critical value as text; in a `marked` column with its stable side: "<= x" (stable below) or ">= x" (above)."""
    value, side = verdict.get(key), verdict.get("stable_side", {}).get(key)
    if not marked or side is None or isinstance(value, str):  # "inf": no limit
        return number(value)
    return f"{'<=' if side == 'below' else '>='} {number(value)}"


def _value(value) -> str:
    """An input's value as text: a number by `number`, true/false for a Nav2 switch."""
    return str(value).lower() if isinstance(value, bool) else number(value)


def _label(name: str) -> str:
    """An input's label (`_LABELS`, or the robot families' `render_families.FAMILY_LABELS`)."""
    if name in _LABELS:
        return _LABELS[name]
    from .render_families import FAMILY_LABELS

    return FAMILY_LABELS.get(name, name)


def _tail(report, data: dict) -> list[str]:
    """The families' closing lines (the fuzzy law's robust bracket, target tracking), when the report has them."""
    if report.tracking is None and (report.schedule is None or report.schedule.bracket is None):
        return []
    from .render_families import family_tail

    return family_tail(report, data)


def _wobble_lines(data: dict) -> list[str]:
    """``report --wobble``: each geometry's limit cycle past V*, its criticality and the speed for the tolerance (docs/wobble.md)."""
    lines = []
    for geometry, title in (("wall", "beside the wall (biased describing function"), ("corridor", "in the corridor (describing functions")):
        w = (data.get(geometry) or {}).get("wobble")
        if w is None:
            continue
        lines += ([""] if lines else []) + [f"Wobble {title}; docs/wobble.md)"]
        if w["criticality"] is None:
            lines.append(f"  not predicted: {w['reason']}")
            continue
        if w["amplitude"] is not None and w["amplitude"] > 0:
            lines.append(f"  limit cycle: lateral amplitude {number(w['amplitude'])} m, heading {number(w['heading_amplitude'])} rad, "
                         f"omega {number(w['omega'])} rad/s")
        elif w["amplitude"] == 0:
            lines.append(f"  no limit cycle ({w['reason']})")
        else:
            lines.append(f"  amplitude not given: {w['reason']}")
        if w["reaches_wall"]:
            lines.append("  the wobble reaches a wall: the robot collides")
        fold = f", cycles from V_fold = {number(w['V_fold'])} m/s" if w["criticality"] == "subcritical" else ""
        lines.append(f"  Hopf at V* = {number(w['V_critical'])} m/s: {w['criticality']}{fold}")
        lines.append(f"  fastest speed whose wobble stays under {number(w['tolerance'])} m: V_tolerance = {number(w['V_tolerance'])} m/s")
        lines.append(f"  method: {w['method']}")
    return lines


def _disturbance_lines(data: dict) -> list[str]:
    """``report --disturbance D``: what a start of D does in each geometry, V*(D) against V*, the criticality; with a yaw
    acceleration limit and no ``--disturbance``, one line saying the verdicts are those of small starts (docs/wobble.md)."""
    limit = (data.get("inputs", {}).get("yaw_accel_limit") or {}).get("value")
    lines = []
    for geometry, where in (("wall", "beside the wall, off its equilibrium"), ("corridor", "in the corridor, off the centre line")):
        d = (data.get(geometry) or {}).get("disturbance")
        if d is None:
            continue
        lines += ([""] if lines else []) + [f"Disturbance {where}: a start {number(d['disturbance'])} m off (docs/wobble.md)"]
        if d["V_disturbance"] is None:
            lines.append(f"  not predicted: {d['reason']}")
            continue
        lines.append(f"  small starts (the linear verdict): settle at or below V* = {number(d['V_critical'])} m/s")
        lines.append(f"  a start of {number(d['disturbance'])} m settles at or below V*(D) = {number(d['V_disturbance'])} m/s")
        V = data["inputs"]["V"]["value"]
        at = f"  at V = {number(V)} m/s (its oscillation starts at {number(d['start_amplitude'])} m): "
        if d["settles"]:
            lines.append(at + "it settles")
        elif d["reaches_wall"]:
            lines.append(at + "it grows until the robot touches a wall")
        elif d["amplitude"] is not None:
            lines.append(at + f"it ends on a limit cycle of {number(d['amplitude'])} m at omega {number(d['omega'])} rad/s")
        else:
            lines.append(at + f"it does not settle; {d['reason']}")
        below = (f"; cycles exist below V* from V_fold = {number(d['V_fold'])} m/s: a large enough start grows where a small one "
                 "settles") if d["cycles_below_critical"] else ""
        lines.append(f"  Hopf at V*: {d['criticality']}{below}")
        if d["yaw_accel_limit"] != "inf":
            lag = f" (at that cycle |N| = {number(d['limiter_gain'])}, lag {number(d['limiter_lag'])} rad)" if d["limiter_gain"] is not None else ""
            lines.append(f"  the drive's yaw acceleration limit {number(d['yaw_accel_limit'])} rad/s^2: linear while a command changes by "
                         f"less than R*T a period, a lag beyond{lag}")
        lines.append(f"  method: {d['method']}")
    if limit is not None and not lines:
        lines += ["The drive's yaw acceleration limit (docs/wobble.md)",
                  f"  R = {number(limit)} rad/s^2 is not in these linear verdicts: they hold for small disturbances (the limiter passes "
                  "every command that changes by less than R*T a period); --disturbance D gives the speed for a start of D m"]
    return lines


def _corridor_notes(env: dict) -> list[str]:
    """The corridor's lines beyond the table: the finite-goal gain, equilibria off the centre line."""
    notes = []
    if "N_finite_goal" in env:
        notes.append(f"  with a finite goal straight ahead N would be {number(env['N_finite_goal'])} 1/m (N + 1/rho_g; not used: the goal direction is frozen)")
    others = [e for e in env.get("equilibria", []) if e["x0"] != 0]
    if others:
        notes.append("  other lateral equilibria: " + "; ".join(f"x0 = {number(e['x0'])} m, N = {number(e['N'])} 1/m" for e in others))
    return notes


def _remedy_line(model: str, fix) -> str:
    fix, field = fix if isinstance(fix, tuple) else (fix, False)
    if not fix:
        which = "alpha, L, eta, rho0 or xi" if field else "alpha, L or f"
        return f"  to stabilize ({model}): no change of V, T, k, {which} alone helps; change tau or several parameters"
    parts = []
    for name, entry in fix.items():
        unit = RANGES[name].unit
        bound = ">=" if entry["direction"] == "raise" else "<="
        change = f" ({entry['change_percent']:+.0f} %)" if "change_percent" in entry else ""
        parts.append(f"{entry['direction']} {SHOWN_AS.get(name, name)} to {bound} {number(entry['to'])}{(' ' + unit) if unit else ''}{change}")
    return f"  to stabilize ({model}), change one of: " + "; ".join(parts)


def _law_line(data: dict) -> list[str]:
    """The force law, when it is not KB's power law (docs/fields.md)."""
    law = data.get("law")
    if not law or law["name"] == "power":
        return []
    return ["", f"Force law: {law['description']}" + (f" (law {law['name']})" if law["name"] else "")]


def _footnote(report) -> list[str]:
    """What margin and the starred values mean: in the report's loop gain, NV (steering robots) or kappa (holonomic); none
    without a model."""
    if not report.models:
        return []
    if report.family.name == "holonomic":
        from .render_families import HOLONOMIC_FOOTNOTE

        return ["", HOLONOMIC_FOOTNOTE]
    if any(report.inputs[name]["value"] != kb for name, kb in KB_PLANT.items() if name in report.inputs):  # D* (`criteria._plant_given`)
        return ["", _FOOTNOTE + " " + _PLANT_FOOTNOTE]
    return ["", _FOOTNOTE]


_PLANT_FOOTNOTE = (
    "With the steering plant's dead time D and gain g (docs/models.md, \"Plant gain and dead time\"): the loop's steering gain is "
    "g*k, and D delays the whole command (the heading term by D, the field's by T + D: the equations above); T* is the "
    "controller's period with D fixed, k* is in the controller's k, and D* is the largest dead time this operating point "
    "tolerates with T fixed (stable below it)."
)


def _kb_error_line(report) -> list[str]:
    """KB's error: one line per loop the tables decide (`report.kb_errors`: more than one where the heading gain differs between
    the geometries)."""
    errors = report.kb_errors
    return ([""] if errors else []) + [f"{e.sentence()}: NV* = {number(e.NV_kb)} vs {number(e.NV_sampled)} 1/s." for e in errors]


def render_text(report) -> str:
    """Readable plain-text report: inputs, per-model table, remedies, KB's error.

    Parameters
    ----------
    report : StabilityReport
        The report.
    """
    data = report.to_dict()
    title = "pfm-stability report (Koren & Borenstein 1991 robot-environment loop)" if report.path is None else _path_title(data)
    lines = [title, "", "Inputs"]
    for name, entry in data["inputs"].items():
        unit = f" {entry['unit']}" if entry["unit"] else ""
        mark = "  <-- " + entry["source"] if entry["source"].startswith("ASSUMED") else f"  ({entry['source']})"
        label = _path_label(name) if report.path is not None else _label(name)
        lines.append(f"  {label:<38} {_value(entry['value'])}{unit}{mark}")
    lines += _law_line(data)
    lines += ["", "Models"] + ([] if data["models"] else ["  none: the law has no smooth equilibrium, so no linear model applies"])
    for name, entry in data["models"].items():
        options = ", ".join(f"{k}={v}" for k, v in entry.items() if k != "equation")
        lines.append(f"  {name:<15} {entry['equation']}{'  [' + options + ']' if options else ''}")
    if report.path is not None:
        lines.append(f"  {_path_substitution(data)}")
        for title, header, rows, fixes, notes in _path_sections(data):
            lines += ["", title, *notes]
            lines += ["  " + line for line in table(header, rows)] if header else []
            lines += [_path_remedy_line(model, fix, data) for model, fix in fixes.items()]
        lines += ["", *_path_footnote(data)]
        return "\n".join(lines) + "\n"
    for title, header, rows, fixes, notes in _scenarios(report, data):
        lines += ["", title]
        lines += ["  " + line for line in table(header, rows)]
        lines += notes
        for model, fix in fixes.items():
            lines.append(_remedy_line(model, fix))
    lines += _tail(report, data)
    wobble = _wobble_lines(data)
    lines += ["", *wobble] if wobble else []
    disturbance = _disturbance_lines(data)
    lines += ["", *disturbance] if disturbance else []
    if data.get("door"):
        lines += ["", *render_door_text(data["door"]).rstrip("\n").splitlines()]
    lines += _footnote(report)
    lines += _kb_error_line(report)
    return "\n".join(lines) + "\n"


def render_door_text(passage) -> str:
    """The door passage (KB Fig 4; a `door.DoorPassage` or its `to_dict()`): geometry, verdict, stop, lateral stiffness, smallest width.

    Parameters
    ----------
    passage : DoorPassage or dict
        The door analysis or its JSON form.
    """
    d = passage.to_dict() if hasattr(passage, "to_dict") else passage
    g = d["geometry"]
    kind = "two posts" if g["obstacle"] == "posts" else "two wall ends"
    radius = "radius" if g["obstacle"] == "posts" else "half-thickness"
    lines = [
        f"Door (KB 1991 Fig 4, docs/door.md): {kind} {number(g['width'])} m apart (centre to centre), {radius} {number(g['post_radius'])} m; "
        f"opening {number(g['opening'])} m, robot {number(g['robot_width'])} m wide",
        f"  law: {d['law']}" + (" (with a goal-directed part)" if d["goal_force"] else ""),
        f"  peak push back from the gap: {number(d['peak_repulsion'])} F_a, {number(d['peak_distance'])} m before it; "
        f"margin (min forward force) {number(d['margin'])} F_a",
    ]
    if d["passes"]:
        lines.append("  verdict: passes (the force along the axis points forward all the way to the gap)")
    else:
        what = {
            "trapped": "trapped on the axis (a local minimum in front of the door)",
            "turns away": "slides off the axis and turns away (KB Fig 4)",
            "neutral": "laterally neutral",
        }[d["at_stop"]]
        lines.append(f"  verdict: STOPS {number(d['stop_distance'])} m before the gap plane; lateral stiffness "
                     f"{number(d['lateral_stiffness'])} 1/m there: {what}")
    if d.get("smallest_passable_width") is not None:
        lines.append(f"  smallest passable width: {number(d['smallest_passable_width'])} m")
    lines.append("  static analysis: " + ("the steering loop in the gap (a corridor of half-width opening/2) is not checked" if d["passes"]
                                           else "a moving robot may still pass by momentum"))
    return "\n".join(lines) + "\n"


def render_markdown(report) -> str:
    """The same content as `render_text`, as Markdown tables.

    Parameters
    ----------
    report : StabilityReport
        The report.
    """
    data = report.to_dict()
    lines = ["# pfm-stability report" + ("" if report.path is None else f": {_path_title(data)[len('pfm-stability report: '):]}"), "",
             "| input | value | unit | source |", "| --- | --- | --- | --- |"]
    for name, entry in data["inputs"].items():
        source = f"**{entry['source']}**" if entry["source"].startswith("ASSUMED") else entry["source"]
        lines.append(f"| {_path_label(name) if report.path is not None else _label(name)} | {_value(entry['value'])} | {entry['unit']} | {source} |")
    if report.path is not None:
        lines += ["", "## Models", "", *(f"- {name}: `{entry['equation']}`" for name, entry in data["models"].items()), f"- {_path_substitution(data)}"]
        for title, header, rows, fixes, notes in _path_sections(data):
            lines += ["", f"## {title}", "", *(f"- {note.strip()}" for note in notes)]
            if header:  # a section of notes only (the memory, MPPI's model delay) has no table
                lines += ["", "| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
                lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
            lines += ["", *("-" + _path_remedy_line(model, fix, data)[1:] for model, fix in fixes.items())] if fixes else []
        lines += ["", *_path_footnote(data)]
        return "\n".join(lines) + "\n"
    lines += _law_line(data)
    for title, header, rows, fixes, notes in _scenarios(report, data):
        lines += ["", f"## {title}", "", "| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
        lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
        lines += ["", *(note.strip() for note in notes)] if notes else []
        for model, fix in fixes.items():
            lines.append("")
            lines.append("-" + _remedy_line(model, fix)[1:])
    lines += _tail(report, data)
    for line in _wobble_lines(data) + _disturbance_lines(data):
        lines += ["", f"## {line}", ""] if line and not line.startswith(" ") else ([f"- {line.strip()}"] if line else [])
    if data.get("door"):
        lines += ["", "## Door", "", "```", *render_door_text(data["door"]).rstrip("\n").splitlines(), "```"]
    lines += _footnote(report)
    lines += _kb_error_line(report)
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ report --controller (docs/path_tracking.md)
_PATH_TITLES = {"rpp": "Regulated Pure Pursuit", "graceful": "the Graceful controller", "mppi": "MPPI", "dwb": "DWB"}

_PATH_COLUMNS = (("(V/L)* 1/s", "ratio_critical"), ("V* m/s", "V_critical"), ("L* m", "lookahead_critical"),
                 ("t_la* s", "lookahead_time_critical"), ("D* s", "dead_time_critical"), ("T* s", "T_critical"),
                 ("NV* 1/s", "NV_critical"), ("omega* rad/s", "omega_critical"))
"""The path-tracking table's critical-value columns and their JSON keys (a column every model leaves undefined is left out)."""


def _path_label(name: str) -> str:
    """A path-tracking report's input label: the loop's own (`_LABELS`), the cruising speed, or Nav2's parameter name."""
    return "V (cruising speed)" if name == "V" else _LABELS.get(name, name)


def _path_title(data: dict) -> str:
    env = data["environment"]["path"]
    where = f"in a corridor of half-width L = {number(env['L_corridor'])} m" if env["L_corridor"] is not None else "on a straight path"
    return f"pfm-stability report: Nav2's {_PATH_TITLES[env['controller']]} tracking {where} (docs/path_tracking.md)"


def _path_substitution(data: dict) -> str:
    """The line after the models' equations: what k and NV are for this controller."""
    env = data["environment"]["path"]
    law = env["law"]
    forms = {"rpp": "k = k_theta = 2 V/L, NV = k_y V/k_theta = V/L (the carrot's curvature 2 y_L/L^2 times V)",
             "graceful": "k = k_theta = V (1 + k_phi + k_delta)/L, NV = V (1 + k_phi)(1 + k_delta)/(L (1 + k_phi + k_delta)) "
                         "(the smooth control law about the motion target)"}
    form = forms.get(env["controller"], "k = k_theta, NV = k_y V/k_theta (the measured gains)")
    return f"with omega = -k_theta e_theta - k_y e_y: {form}; the heading is sampled by the controller (delayed T + D)"


def _path_sections(data: dict):
    """Yield (title, header, rows, remedies, notes) of the path-tracking table, from the report's JSON form."""
    env, verdicts = data["environment"]["path"], data["path"]
    law = env["law"]
    lookahead = f", L = {number(law['L'])} m (V/L = {number(law['ratio'])} 1/s)" if law["L"] is not None else ""
    regulated = f" (regulated from {number(law['V_set'])})" if law["V"] != law["V_set"] else ""
    title = (f"Lateral loop: V = {number(law['V'])} m/s{regulated}{lookahead}: k_theta = {number(law['k_theta'])} 1/s, "
             f"k_y = {number(law['k_y'])} 1/(m s); NV = {number(law['NV'])} 1/s")
    notes = [f"  {note}" for note in env["notes"]]
    if "k_theta_se" in law and (law["k_theta_se"] or law["k_y_se"]):
        notes.append(f"  gains' standard errors: k_theta +- {number(law['k_theta_se'])} 1/s, k_y +- {number(law['k_y_se'])} 1/(m s) "
                     "(the verdict over +-2 of them: column 'over gains')")
    notes += _reason_lines(verdicts)
    columns = [(head, key) for head, key in _PATH_COLUMNS if any(v.get(key) is not None for v in verdicts.values())]
    ranged = any("margin_range" in v for v in verdicts.values())
    header = ["model", "verdict", "margin"] + (["over gains"] if ranged else []) + [head for head, _ in columns]
    rows = []
    for name, v in verdicts.items():
        cells = [name, v["verdict"].upper() if v["verdict"] != "stable" else "stable", percent(v["margin"])]
        if ranged:
            low, high = v.get("margin_range", (None, None))
            cells.append(f"{v.get('verdict_range')} ({percent(low)} .. {percent(high)})" if low is not None else "-")
        cells += [number(v.get(key)) for _, key in columns]
        rows.append(cells)
    fixes = {name: v["to_stabilize"] for name, v in verdicts.items() if v["verdict"] != "stable"}
    yield title, header, rows, fixes, notes
    memory = env.get("memory")
    if memory is not None:
        static = verdicts.get("sampled", {}).get("dead_time_critical")
        versus = f" (with the one-step gains alone: {number(static)} s)" if static is not None else ""
        yield ("With the controller's memory (sampled)", [], [], {}, [
            f"  the {memory['cycles']}-cycle response to a pose error closes the sampled loop: "
            f"{'stable' if memory['stable'] else 'UNSTABLE'}, largest pole |z| = {number(memory['spectral_radius'])} "
            f"(sigma = {number(memory['growth_rate'])} 1/s); D* = {number(memory['dead_time_critical'])} s{versus}",
            "  (the table's models see the first cycle's gains; this loop is the one the simulated controller closes, "
            "docs/path_tracking.md)"])
    delay = env.get("model_delay")
    if delay is not None:
        yield ("MPPI's model delay", [], [], {}, [
            f"  set model_delay_wz (and model_delay_vx) to {number(delay['recommended'])} s = {delay['steps']} x model_dt "
            f"{number(delay['model_dt'])} s: the latency D + d T = {number(delay['latency'])} s rounded as MPPI rounds it "
            f"(now {number(delay['current'])} s; model_dt should be the controller's period)"])


def _path_remedy_line(model: str, fix: dict, data: dict) -> str:
    """One model's remedies in Nav2's names and units (`report.path.path_remedies`)."""
    if not fix:
        return f"  to stabilize ({model}): no single change of the speed, the lookahead, D or T helps; change several"
    from ..controllers.registry import get_controller

    controller = get_controller(data["environment"]["path"]["controller"])
    parts = []
    for name, entry in fix.items():
        unit = RANGES[name].unit if name in RANGES else controller.parameter(name).unit
        bound = ">=" if entry["direction"] == "raise" else "<="
        change = f" ({entry['change_percent']:+.0f} %)" if "change_percent" in entry else ""
        extra = f" (controller_frequency >= {number(1.0 / entry['to'])} Hz)" if name == "T" else ""
        parts.append(f"{entry['direction']} {name} to {bound} {number(entry['to'])}{(' ' + unit) if unit else ''}{change}{extra}")
    return f"  to stabilize ({model}), change one of: " + "; ".join(parts)


def _path_footnote(data: dict) -> list[str]:
    env = data["environment"]["path"]
    measured = env["controller"] in ("mppi", "dwb")
    margin = ("margin = NV*/NV - 1 with the measured gains held (how much V may grow)" if measured else
              "margin = (V/L)*/(V/L) - 1: how much the speed over the lookahead may grow before the first loss of stability")
    return [margin + ". Starred values are critical with the other inputs fixed: stable below (V/L)*, V* (the cruising speed, "
            "the regulated speed and lookahead moving with it), D* (the robot's dead time, T fixed) and T* (the controller's period, "
            "D fixed); above L* (the lookahead that steers) and t_la* (lookahead_time, velocity-scaled). inf = no limit; "
            "0 = none stable; - = undefined. The loop's plant is g e^(-sD)/((tau s + 1)(tau_a s + 1)); docs/path_tracking.md."]


# ---------------------------------------------------------------- derivation
def _derivation_heading(law: str) -> str:
    return f"Koren & Borenstein 1991, eq (5)-(25), derived with sympy ({law} force law)"


def render_derivation_text(steps, law: str) -> str:
    """Steps as plain text: a numbered heading, the pretty-printed result, the explanation.

    Parameters
    ----------
    steps : sequence of Step
        The derivation (`analysis.derivation`).
    law : str
        The law derived, named in the heading.
    """
    import sympy as sp

    lines = [
        _derivation_heading(law) + ".",
        "Misprints corrected: see `pydoc pfm_stability.analysis.derivation`.",
        "",
    ]
    for index, step in enumerate(steps, 1):
        lines.append(f"{index:2d}. KB ({step.equation}) {step.title}")
        lines.append(textwrap.indent(sp.pretty(step.expr, order="none", use_unicode=True, num_columns=76), "    "))
        lines.extend(textwrap.wrap(step.explanation, 76, initial_indent="    ", subsequent_indent="    "))
        lines.append("")
    return "\n".join(lines)


def render_derivation_latex(steps, law: str) -> str:
    """Steps as a LaTeX fragment (amsmath): a paragraph and an ``equation*`` per step.

    Parameters
    ----------
    steps : sequence of Step
        The derivation (`analysis.derivation`).
    law : str
        The law derived, named in the heading.
    """
    import sympy as sp

    lines = [f"% {_derivation_heading(law)}; needs amsmath.", ""]
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


# ------------------------------------------------------------------ traps
def _or_dash(x) -> str:
    return "-" if x is None else f"{x:.6g}"


def render_traps_text(analysis) -> str:
    """The text output: stationary points, goal verdict, bounds and the conclusion.

    Parameters
    ----------
    analysis : TrapAnalysis
        The scene's stationary points and bounds.
    """
    scene = analysis.scene
    lines = [f"law: {scene.law.describe()}", f"goal: ({scene.goal[0]:g}, {scene.goal[1]:g}); {len(scene.obstacles)} obstacle(s); "
             f"region [{scene.region[0][0]:g}, {scene.region[1][0]:g}] x [{scene.region[0][1]:g}, {scene.region[1][1]:g}] m; "
             f"search grid {analysis.resolution} points", "", "stationary points:",
             f"  {'x (m)':>12} {'y (m)':>12}  {'kind':<10} {'U':>12}  Hessian eigenvalues"]
    for p in analysis.stationary_points:
        eig = "not C2 there" if p.hessian_eigenvalues is None else ", ".join(f"{v:.6g}" for v in p.hessian_eigenvalues)
        lines.append(f"  {p.x:>12.6g} {p.y:>12.6g}  {p.kind:<10} {p.potential:>12.6g}  {eig}{'   <- goal' if p.goal else ''}")
    if not analysis.stationary_points:
        lines.append("  (none)")
    goal = next((p for p in analysis.stationary_points if p.goal), None)
    if analysis.goal_is_global_minimum:
        verdict = "the global minimum (no minimum found lies lower)"
    elif goal is not None:
        verdict = "a local minimum, but a trap lies lower" if goal.kind == "minimum" else f"a {goal.kind}, NOT a minimum"
    else:
        verdict = "NOT a stationary point: the repulsion of an obstacle within rho0 moves the minimum off it"
    lines += ["", f"goal: {verdict}", ""]
    if analysis.gnron_bounds:
        lines += ["Ge & Cui 2000 bounds on xi/eta (no stationary point on the goal-obstacle ray iff xi/eta > k_n):",
                  f"  {'obstacle':<14} {'r (m)':>10} {'k_n exact':>12} {'k_n conserv.':>13} {'xi/eta':>10}  satisfied"]
        for b in analysis.gnron_bounds:
            lines.append(f"  {f'{b.index} {b.kind}':<14} {b.r:>10.6g} {_or_dash(b.k_exact):>12} {_or_dash(b.k_conservative):>13} {b.ratio:>10.6g}  "
                         f"{'yes' if b.satisfied else 'no'}{f'  ({b.reason})' if b.reason else ''}")
    else:
        lines.append(f"no obstacle within rho0 = {scene.law.rho0:g} m of the goal: Ge & Cui's bound puts no condition on xi/eta")
    lines += ["", f"conclusion: {analysis.conclusion}"]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ sweep (pfm-stability sweep)
def _share(x) -> str:
    """A fraction as a percentage with one decimal ("-" when undefined)."""
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.1f} %"


def render_parameter_sweep_text(summary, plot=None) -> str:
    """``pfm-stability sweep``'s summary: points, time, rate, each model's stable fraction, the agreement matrix, where the output went.

    Parameters
    ----------
    summary : SweepSummary
        The sweep's statistics and specification.
    plot : str, optional
        Path of the summary figure written, if any.
    """
    s = summary.statistics
    spec = summary.spec
    models = list(s.agreement)
    varying = ", ".join(spec.varying)
    lines = [
        f"sweep {spec.path or ''}: {summary.points} points ({varying} vary; {spec.geometry}, law {spec.law}), "
        f"{summary.chunks} chunk(s) of <= {summary.chunk_size} on {summary.scheduler}"
        + (f", {summary.reused_chunks} reused from an interrupted run" if summary.reused_chunks else ""),
        f"  {summary.seconds:.2f} s, {summary.rate:,.0f} points/s",
        "",
        "stable fraction (verdict \"stable\"; undecided = within 1e-9 of a boundary):",
    ]
    rows = [[m, _share(s.stable_fraction[m]), str(s.undecided[m])] for m in models]
    if s.simulation_agreement is not None:
        rows.append(["simulation", _share(s.stable_fraction.get("sim")), "-"])
    lines += ["  " + line for line in table(["model", "stable", "undecided"], rows)]
    if len(models) > 1:
        lines += ["", "agreement of the verdicts (fraction of points):"]
        lines += ["  " + line for line in table(["", *models], [[a, *(_share(s.agreement[a][b]) for b in models)] for a in models])]
    if s.simulation_agreement is not None:
        lines += ["", "simulated verdict (sign of sigma) agrees with:"]
        lines += ["  " + line for line in table(["model", "agreement"], [[m, _share(v)] for m, v in s.simulation_agreement.items()])]
    if s.without_verdict:
        lines += ["", f"{s.without_verdict} point(s) without a verdict: see the reason column"]
    lines += [f"note: {note}" for note in summary.notes]
    lines += ["", f"table: {summary.out} ({summary.format}, one row per point)"]
    if plot:
        lines.append(f"plot: {plot}")
    return "\n".join(lines) + "\n"


MAP_ROWS = 15
"""Segments listed by ``pfm-stability map`` (the worst first)."""


def render_map_tracking_text(data: dict) -> str:
    """``pfm-stability map --controller rpp``: the map, the robot and controller, the free-space reference, the unstable
    stretches (smallest margin first) with the lookahead a zone sets, the summary, the outputs.

    Parameters
    ----------
    data : dict
        The analysis's JSON form (`maps.deciding.tracking.MapTracking.to_dict`, outputs and timing).
    """
    m, i, t = data["map"], data["inputs"], data["tracking"]
    ref = data["tracking_verdict"]
    pv = data["paths"]
    s = pv["summary"]
    lines = [f"map {m['name']}: {m['width']} x {m['height']} cells of {m['resolution']:g} m; routes on a grid of {i['cell_size']:g} m "
             f"(unknown = {i['unknown']})",
             f"controller {data['controller']} at max_linear_vel V = {i['V']:g} m/s, lookahead {t['law']['L']:g} m; plant tau = {i['tau']:g} s, "
             f"D = {i['dead_time']:g} s, g = {i['plant_gain']:g}; T = {i['T']:g} s; model {i['model']}: (V/L)* = {number(ref['ratio_critical'])} 1/s",
             f"free space: {ref['verdict']}, margin {percent(ref['margin'])}, V* = {number(ref['V_critical'])} m/s, "
             f"L* = {number(ref['lookahead_critical'])} m, D* = {number(ref['dead_time_critical'])} s, T* = {number(ref['T_critical'])} s", ""]
    unstable = sorted((x for x in pv["stretches"] if x["verdict"] == "unstable"), key=lambda x: x["margin"])
    if unstable:
        lines.append(f"{'route':>5} {'from m':>7} {'to m':>7} {'margin':>8} {'V* m/s':>7} {'L* m':>6} {'V m/s':>6} {'L_c m':>6} {'kappa':>6}"
                     f"  zone {pv['lookahead_parameter']}")
        for x in unstable[:MAP_ROWS]:
            zone = "-" if x["zone_lookahead"] is None else f"{x['zone_lookahead']:g} m"
            lines.append(f"{x['route']:>5} {x['start']:>7.2f} {x['stop']:>7.2f} {percent(x['margin']):>8} {number(x['V_critical']):>7} "
                         f"{number(x['lookahead_critical']):>6} {x['V']:>6.3g} {x['half_width']:>6.3g} {x['curvature']:>6.3g}  {zone}")
        if len(unstable) > MAP_ROWS:
            lines.append(f"... {len(unstable) - MAP_ROWS} more unstable stretches (--format json, --out-dir: routes.csv)")
    counts = ", ".join(f"{n} {v}" for v, n in s["stretches"].items() if n)
    lines += [f"{s['routes']} routes, {s['route_length_m']:.1f} m: {s['unstable_length_m']:.1f} m unstable, {s['stable_length_m']:.1f} m stable, "
              f"{s['unjudged_length_m']['no room']:.1f} m no room; stretches: {counts}; slowest V* {number(s['V_critical_min'])} m/s; "
              f"{s['lookahead_zones']} unstable stretches a longer lookahead fixes; {s['decisions']} corridors decided"]
    for name, path in (data.get("outputs") or {}).items():
        lines.append(f"{name}: {path}")
    return "\n".join(lines) + "\n"


def render_map_text(data: dict) -> str:
    """``pfm-stability map``: the map, the robot, the one result set (the routes' unstable stretches, slowest V* first,
    and their summary; the segments with the power law), the validation, the outputs.

    Parameters
    ----------
    data : dict
        The map analysis's JSON form.
    """
    m, i = data["map"], data["inputs"]
    lines = [
        f"map {m['name']}: {m['width']} x {m['height']} cells of {m['resolution']:g} m, origin {m['origin'][:2]}; "
        f"histogram grid {i['grid_cells'][0]} x {i['grid_cells'][1]} cells of {i['cell_size']:g} m (unknown = {i['unknown']})",
        f"robot V = {i['V']:g} m/s, W = {i['W']:g} m, tau = {i['tau']:g} s, k = {i['k']:g} 1/s, T = {i['T']:g} s; "
        f"law {i['law']}; model {i['model']} (hold {i['hold']}, compute delay {i['compute_delay']}): NV* = {number(data['NV_critical'])} 1/s",
        "",
    ]
    lines += _map_stretch_lines(data) if data.get("paths") else _map_segment_lines(data)
    v = data.get("validation")
    if v is not None and v.get("kind") == "drives":
        lines += _map_drive_lines(v)
    elif v is not None:
        share = f"{percent(v['agreement'])[1:]} of the {v['measured']} measured" if v.get("agreement") is not None else "- (none measured)"
        lines.append(f"validation: {len(v['cases'])} simulated segments: {v['agreed']} agree, {v['disagreed']} disagree, "
                     f"{v['not_measurable']} not measurable; agreement {share}")
    lines += _map_wobble_lines(data.get("wobble"), i["V"])
    for name, path in (data.get("outputs") or {}).items():
        lines.append(f"{name}: {path}")
    return "\n".join(lines) + "\n"


def _map_stretch_lines(data: dict) -> list[str]:
    """The routes' unstable stretches (slowest V* first: cause, V*, margin, predicted weave) and their summary."""
    V, p = data["inputs"]["V"], data["paths"]["summary"]
    unstable = sorted((s for s in data["paths"]["stretches"] if s["verdict"] == "unstable"), key=lambda s: (s["V_critical"], -s["length"]))
    rows = [[f"({s['x0']:.1f}, {s['y0']:.1f}) -> ({s['x1']:.1f}, {s['y1']:.1f})", f"{s['length']:.1f}", s["cause"], number(s["V_critical"]),
             percent(s["margin"]), f"{100 * s['amplitude']:.1f}"] for s in unstable[:MAP_ROWS]]
    lines = []
    if rows:
        lines.append(f"slowest {len(rows)} of {len(unstable)} unstable route stretches (V* = the speed to slow to, margin = V*/V - 1, "
                     f"weave = the predicted lateral oscillation):")
        lines += ["  " + line for line in table(["stretch (m)", "length m", "cause", "V* m/s", "margin", "weave cm"], rows)]
        lines.append("")
    unjudged = ", ".join(f"{length:.1f} m {reason}" for reason, length in p["unjudged_length_m"].items() if length > 0)
    causes = ", ".join(f"{length:.1f} m {cause}" for cause, length in p["unstable_length_by_cause_m"].items() if length > 0)
    lines.append(f"routes: {p['routes']} routes, {p['route_length_m']:.1f} m: {percent(p['decided_fraction'])[1:]} decided; "
                 f"unstable {p['unstable_length_m']:.1f} m" + (f" ({causes})" if causes else "") + f", stable {p['stable_length_m']:.1f} m"
                 + (f"; no verdict: {unjudged}" if unjudged else ""))
    lines.append(f"slowest V* = {number(p['V_critical_min'])} m/s" + (f" -> the robot weaves somewhere at V = {V:g} m/s"
                                                                      if p["unstable_length_m"] > 0 else f" -> calm everywhere at V = {V:g} m/s"))
    return lines


def _map_segment_lines(data: dict) -> list[str]:
    """The corridor segments (the power law's result set): the worst, lowest margin first, and their summary."""
    i, s = data["inputs"], data["summary"]
    decided = [g for g in data["segments"] if g["margin"] is not None]
    decided.sort(key=lambda g: (g["margin"] if not isinstance(g["margin"], str) else math.inf))
    rows = [[f"({g['x0']:.1f}, {g['y0']:.1f}) -> ({g['x1']:.1f}, {g['y1']:.1f})", f"{g['length']:.1f}", number(g["N"]),
             number(g["V_critical"]), percent(g["margin"]), g["verdict"]] for g in decided[:MAP_ROWS]]
    lines = []
    if rows:
        lines.append(f"worst {len(rows)} of {len(decided)} segments with a verdict (margin = NV*/NV - 1):")
        lines += ["  " + line for line in table(["segment (m)", "length m", "N 1/m", "V* m/s", "margin", "verdict"], rows)]
    counts = ", ".join(f"{n} {v}" for v, n in s["verdicts"].items() if n)
    lines += [
        "",
        f"{s['segments']} segments, {s['route_length_m']:.1f} m of routes: {counts}",
        f"unstable: {s['unstable_length_m']:.1f} m; slowest V* = {number(s['V_critical_min'])} m/s"
        + (f" -> the robot oscillates somewhere at V = {i['V']:g} m/s" if s["unstable_length_m"] > 0 else f" -> stable everywhere at V = {i['V']:g} m/s"),
    ]
    return lines


def _map_drive_lines(d: dict) -> list[str]:
    """The validation by driving: recall, precision, specificity with their intervals, lengths, the wobble's agreement."""
    lines = []
    share = {k: (percent(d[k])[1:] + _interval_text(d.get(f"{k}_interval")) if d.get(k) is not None else "n/a (nothing to measure)")
             for k in ("recall", "precision", "specificity")}
    lines.append(f"validation by driving: {d['counts']['drives']} drives, {d['counts']['episodes']} oscillation episodes; "
                 f"recall {share['recall']}, precision {share['precision']}, specificity {share['specificity']} "
                 f"(of {d['lengths']['quiet_driven']:.1f} m driven with a verdict and without an episode, the share predicted stable) by length along the paths driven "
                 f"({d['lengths']['drive_paths_driven']:.1f} m measured, {d['lengths']['drive_paths_unmeasured']:.1f} m passed "
                 f"only in a drive's last three periods, not measurable; {d['lengths']['driven']:.1f} of {d['lengths']['route']:.1f} m "
                 f"of route covered); {len(d['disagreements'])} disagreements"
                 + (f" (false alarms where a drive wove past {100 * d['inputs']['amplitude_threshold']:.1f} cm for a period, "
                    f"not {d['inputs']['episode_periods']}: {d['lengths']['false_alarm_swinging']:.1f} m)"
                    if d['lengths'].get('false_alarm_swinging') else ""))
    c = d.get("collisions")
    if c and c["count"]:  # where the drives met an obstacle, beside the map's prediction
        lines.append(f"  collisions: {c['count']} drives met an obstacle; {c['foreseen']} within {c['match_distance']:g} m of a "
                     f"predicted collision course, {c['near_weave']} more near a predicted weave, {c['elsewhere']} elsewhere on a route, "
                     f"{c['off_routes']} off every route "
                     f"(where: validation.collisions in the JSON; X on routes.png)")
    w = d.get("wobble")
    if w and w.get("within") is not None:  # how big the predicted weave is against the simulated one
        q = ", ".join(f"{v:.2f}" if isinstance(v, (int, float)) else str(v) for v in w["ratio_quartiles"])
        lines.append(f"  wobble: where either wove past {100 * d['inputs']['amplitude_threshold']:.1f} cm for a period "
                     f"({w['length']:.1f} m), the predicted weave is within a factor {w['factor']:g} of the simulated on "
                     f"{percent(w['within'])[1:]} of it (predicted/simulated quartiles {q})")
    return lines


def _interval_text(interval) -> str:
    """`` (95 %: lo–hi %)`` of a validation figure's interval over the choice of drives, or nothing."""
    return f" (95 %: {100 * interval[0]:.0f}–{100 * interval[1]:.0f} % over the drives)" if interval else ""


def _map_wobble_lines(w: dict | None, V: float) -> list[str]:
    """``map --wobble TOL``: how many zones (segments, route stretches) the mask drives at V_tolerance instead of V*, why
    the others keep V*, and the range of the mask's limits (`maps.deciding.wobble_zones.WobbleSummary`; docs/maps.md)."""
    if w is None:
        return []
    kept = lambda counts, unit="": ", ".join(f"{n:.1f} m {why}" if unit else f"{n} {why}" for why, n in counts["kept"].items())
    seg, st, length = w["segments"], w["stretches"], w["route_length_m"]
    lines = [f"wobble tolerance {number(w['tolerance'])} m (docs/maps.md): zones with V* < V at V_tolerance where trusted, else V*:",
             f"  segments: {seg['V_tolerance']} of {seg['V_tolerance'] + sum(seg['kept'].values())} with a zone at V_tolerance"
             + (f"; V* kept: {kept(seg)}" if seg["kept"] else "")]
    total = st["V_tolerance"] + sum(st["kept"].values())
    if total:
        share = f"; {percent(w['unstable_fraction'])[1:]} of the {w['unstable_length_m']:.1f} m unstable" if w["unstable_fraction"] is not None else ""
        lines.append(f"  route stretches: {st['V_tolerance']} of {total} with a zone at V_tolerance ({length['V_tolerance']:.1f} m{share})"
                     + (f"; V* kept: {kept(length, 'm')}" if length["kept"] else ""))
    span = lambda lo, hi: (f"{number(lo)} .. {number(hi)} m/s ({math.floor(100 * lo / V)} .. {math.floor(100 * hi / V)} % of V)"
                           if lo is not None else "none")
    lines.append(f"  mask limits: {span(w['V_limit_min'], w['V_limit_max'])}; at V* alone {span(w['V_critical_min'], w['V_critical_max'])}")
    return lines

