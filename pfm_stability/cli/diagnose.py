"""``pfm-stability diagnose``: why the robot oscillates, from its own log.

    pfm-stability diagnose LOG [--config ROBOT.yaml] [--k K --W W --f F --n N …] [--plot PNG]
                               [--format text|json|markdown] [--cmd-topic /cmd_vel] [--odom-topic /odom] [--scan-topic /scan]

LOG is a ROS 2 bag (its directory, or a ``.db3``/``.mcap`` file) or a ROS 1 ``.bag`` with the scans and the
odometry (docs/diagnose.md). The stretches where the robot drove along a wall or through a corridor are found
from the scans in the odometry's frame (`pfm_stability.analysis.stretches`); on each the lateral oscillation
is measured and set against every loop model's prediction (`pfm_stability.validation.diagnose`). k, W, f and n
cannot come from a log: ``--config`` (or the options) must give them; τ and T come from the same log
(`pfm_stability.analysis.identification`) unless given, and with them D and g unless given. The law is KB's power
law, or the grid's law when the configuration says ``law: grid`` (another is refused). JSON keys (`pfm_stability/io/schema/output.schema.json`,
``$defs/diagnose``): ``verdict``, ``reason``, ``measured`` (``omega``, ``sigma``, ``amplitude``, ``stretch``),
``predicted.<model>`` (``stable``, ``V_critical``, ``margin``, ``omega``, ``sigma`` …), ``matching_model``,
``margin``, ``critical`` (V*, T*, k*), ``remedies``, ``stretches`` (each with its own), ``parameters``,
``identification``, ``log``, ``timing``.

A log without a wall in view, or without anything to judge, is an answer (exit 0, ``verdict`` "nothing to
diagnose" and why); a bad log or a missing parameter is one line, exit 2.
"""

from __future__ import annotations

import math
import time

from .identify import FORMATS, add_topic_options

__all__ = ["add_parser", "run", "render_text", "render_markdown", "parameters_table"]

SCAN_BATCH = 256
"""Scans reduced at once (`analysis.stretches.wall_lines_batch`): at most this many are held."""

_KEYS = {"k": "robot.k", "W": "robot.W", "f": "controller.f", "n": "controller.n", "tau": "robot.tau", "T": "controller.T"}
"""Parameter → its key in a configuration file (docs/config.md)."""


DIAGNOSE_LAWS = ("power", "grid")
"""The lateral laws diagnose predicts with: KB's power law, or the law a histogram grid's cells exert (a VFF controller
on a real grid, docs/simulator.md), from the configuration's ``law`` (its ``cell_ratio``, ``cell_size``, ``window_cells``)."""


def _law(law: dict, robot, controller):
    """The configuration's law built for the robot (None: KB's power law, `diagnose`'s default).

    Parameters
    ----------
    law : dict
        The configuration's ``law`` mapping (``name`` and the law's parameters), or empty.
    robot, controller : Robot, Controller
        The robot (W) and controller (f, n) the law is built for.
    """
    if not law or law.get("name") == "power":
        return None
    from ..laws.fields import make_law

    return make_law(law["name"], robot, controller, **{k: v for k, v in law.items() if k != "name"})


def add_parser(sub) -> None:
    """Add the ``diagnose`` subcommand to `sub`.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The command's subparsers.
    """
    from .options import add_parameter_options, output_path

    p = sub.add_parser(
        "diagnose",
        help="why the robot oscillates, from its own log: the oscillation measured along walls and in corridors against every model",
        description="Read a ROS 2 bag (directory, .db3 or .mcap) or a ROS 1 .bag with the scans and the odometry; find "
        "the stretches along a wall or through a corridor, measure the lateral oscillation there and predict it with "
        "every loop model from the identified plant and the user's k, W, f, n (docs/diagnose.md).",
    )
    p.add_argument("log", metavar="LOG", help="a ROS 2 bag directory, a .db3 or .mcap file, or a ROS 1 .bag")
    p.add_argument("--format", choices=FORMATS, default="text")
    p.add_argument("--plot", type=output_path("plot", ".png"), metavar="PNG",
                   help="draw the lateral offsets with the predicted envelopes, the walls seen and the stretches judged")
    add_topic_options(p, ("cmd", "odom", "scan"))
    add_parameter_options(p)
    p.set_defaults(run=run)


def run(args) -> int:
    """Read the log, identify what the user did not give, diagnose and print; returns the exit status (0).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    """
    from ..analysis.identification import identify
    from ..extras import require
    from ..io.logs import LogTopics, log_format
    from ..io.serialize import SCHEMA_VERSION, dumps
    from ..validation.diagnose import complete_from_log, diagnose, missing_parameters, needs_identification
    from .options import resolve_parameters, typed

    started = time.perf_counter()
    if log_format(args.log) == "csv":
        raise ValueError(f"{args.log}: diagnose needs the scans and the odometry's pose, which a CSV log does not hold; give a ROS bag")
    params = resolve_parameters(args)
    missing = () if typed(args, "preset") else missing_parameters(params.sources)
    if missing:
        raise ValueError(f"diagnose needs {', '.join(missing)}, which a log cannot show (the steering gain, the robot's width, "
                         f"the law): give {', '.join(_KEYS[m] for m in missing)} in --config ROBOT.yaml "
                         f"(or {' '.join('--' + m for m in missing)})")
    law = (params.config.law if params.config is not None else None) or {}
    if law and law.get("name") not in DIAGNOSE_LAWS:
        raise ValueError(f"diagnose predicts with KB's power law f(W/d)^n or the histogram grid's law (law: power or grid); "
                         f"law {law.get('name')} of --config {params.config.path} is not one it takes")
    require("logs", "pfm-stability diagnose")
    to_identify = needs_identification(params.sources)
    topics = LogTopics(command=args.cmd_topic, odometry=args.odom_topic, scan=args.scan_topic)
    need = ("command", "odometry", "pose", "scan") if to_identify else ("pose", "scan")
    log = _read(args.log, topics, need, want_commands=not to_identify and math.isfinite(params.robot.yaw_accel_limit))
    # the odometry's pose shows a slide when it sees the base move (a simulator's, a localised one); a wheel odometry's
    # shows none, and its interval holds 0 (docs/diagnose.md, "The slide")
    identification = identify(log, "odometry") if to_identify else None
    robot, controller, sources = complete_from_log(params.robot, params.controller, params.sources, identification)
    result = diagnose(log, robot, controller, law=_law(law, robot, controller))
    if result.judged is not None:
        sources["V"] = f"measured on stretch {result.worst} (the odometry's forward speed)"
    if args.plot:
        result.plot(args.plot)
    info = {"path": log.path, "format": log.format, "duration": log.duration,
            "topics": {"odometry": topics.odometry, "scan": topics.scan, **({"command": topics.command} if to_identify else {})}}
    if args.format == "json":
        print(dumps({"schema_version": SCHEMA_VERSION, "command": "diagnose", **result.to_dict(),
                     "parameters": parameters_table(result, sources),
                     "identification": None if identification is None else identification.to_dict(),
                     "log": info, "timing": {"seconds": time.perf_counter() - started}}))
    elif args.format == "markdown":
        print(render_markdown(result, sources, info), end="")
    else:
        print(render_text(result, sources, info) + (f"figure written to {args.plot}\n" if args.plot else ""), end="")
    return 0


def _read(path, topics, need, *, want_commands: bool):
    """The log with `need`, and its commands too when `want_commands` and the log has them (a slew limit given in the
    configuration is set against them: `validation.diagnose.Limiter`)."""
    from ..analysis.stretches import wall_lines_batch
    from ..io.logs import LogError, read_log

    if want_commands:
        try:
            return read_log(path, topics, need=("command", *need), scan_reducer=wall_lines_batch, scan_batch=SCAN_BATCH)
        except LogError as exc:
            if f"command topic {topics.command}" not in str(exc):
                raise
    return read_log(path, topics, need=need, scan_reducer=wall_lines_batch, scan_batch=SCAN_BATCH)


def parameters_table(result, sources: dict) -> dict:
    """Parameter → {value, unit, source} of the robot and controller predicted with (V: the judged stretch's).

    Parameters
    ----------
    result : validation.diagnose.Diagnosis
        The diagnosis.
    sources : dict
        Parameter → provenance.
    """
    from ..parameters import RANGES

    r, c = result.robot, result.controller
    values = {"V": r.V, "tau": r.tau, "dead_time": r.dead_time, "plant_gain": r.plant_gain, "actuator_lag": r.actuator_lag,
              "yaw_accel_limit": r.yaw_accel_limit, "slip_lag": r.slip_lag, "k": r.k, "W": r.W, "T": c.T, "f": c.f, "n": c.n, "hold": c.hold,
              "compute_delay": c.compute_delay}
    from ..io.serialize import json_number

    return {name: {"value": json_number(value) if isinstance(value, float) else value,
                   "unit": RANGES[name].unit if name in RANGES else "", "source": sources.get(name, "")}
            for name, value in values.items()}


# ------------------------------------------------------------------------------------------ renderings
def _num(x, fmt: str = ".3g", unit: str = "") -> str:
    if x is None:
        return "—"
    if x == float("inf"):
        return "∞"
    return f"{x:{fmt}}{(' ' + unit) if unit else ''}"


def _where(s) -> str:
    st = s.stretch
    geo = f"L = {_num(s.geometry, '.3f', 'm')}" if st.kind == "corridor" else f"d0 = {_num(s.geometry, '.3f', 'm')}"
    extra = f", α = {_num(s.alpha_deg, '.1f', '°')}" if s.alpha_deg is not None else ""
    return f"stretch {st.index}: {st.kind}, {st.start:.1f}–{st.end:.1f} s ({st.duration:.1f} s), {geo}{extra}, V = {_num(s.V, '.3f', 'm/s')}"


def _measured(m) -> str:
    if m.sigma is None:
        return f"no oscillation (the offset settles; largest swing {_num(m.amplitude, '.3g', 'm')})"
    return (f"ω = {_num(m.omega, '.3f', 'rad/s')}{_omega_interval(m.frequency)}, σ = {m.sigma:+.3g} 1/s, "
            f"amplitude {_num(m.amplitude, '.3g', 'm')} ({'growing' if m.sigma > 0 else 'decaying'}; "
            f"{m.turning_points} turning points, {m.method})")


def _omega_interval(f) -> str:
    """ω's 95 % interval and the periods it rests on, or why it has none (`analysis.frequency`)."""
    if f is None or f.omega is None:
        return " (no zero crossings to time: the estimator's turning points)"
    dropped = f", {f.dropped} transient crossing{'s' if f.dropped != 1 else ''} dropped" if f.dropped else ""
    if f.few_periods:
        return f" (too few periods for an interval: {f.periods:.1f} established{dropped})"
    return f" [{_num(f.low, '.3f')} to {_num(f.high, '.3f')}] over {f.periods:.1f} periods{dropped}"


def _rows(s) -> list[tuple]:
    return [(p.model, p.verdict, f"{100 * p.margin:+.1f} %", _num(p.V_critical, '.3g'), _num(p.T_critical, '.3g'), _num(p.k_critical, '.3g'),
             _num(p.omega, '.3f'), "—" if p.sigma is None else f"{p.sigma:+.3g}", "yes" if p.matches else "no")
            for p in s.predicted.values()]


_HEAD = ("model", "verdict", "margin", "V* m/s", "T* s", "k* 1/s", "ω rad/s", "σ 1/s", "matches")


def _remedies(remedies: dict) -> list[str]:
    out = []
    for name, r in remedies.items():
        change = f" ({r['change_percent']:+.1f} %)" if "change_percent" in r else ""
        out.append(f"{r['direction']} {name} to {_num(r['to'], '.4g')}{change}")
    return out


def render_text(result, sources: dict, info: dict) -> str:
    """The text output of ``diagnose``.

    Parameters
    ----------
    result : validation.diagnose.Diagnosis
        The diagnosis.
    sources : dict
        Parameter → provenance.
    info : dict
        The log's path, format, duration and topics.
    """
    out = [f"log: {info['path']} ({info['format']}, {info['duration']:.1f} s)", f"verdict: {result.verdict} — {result.reason}", ""]
    if result.limiter is not None:
        out[-1:-1] = [f"slew limit: {result.limiter.note}"]
    table = parameters_table(result, sources)
    out.append("parameters: " + ", ".join(f"{k} = {_num(v['value'], '.4g') if isinstance(v['value'], float) else v['value']}"
                                           f" ({v['source']})" for k, v in table.items()))
    for s in result.stretches:
        out += ["", _where(s)]
        if not s.judged:
            out.append(f"  not judged: {s.reason}")
            continue
        out.append(f"  measured: {_measured(s.measured)}")
        widths = [max(len(str(r[i])) for r in [_HEAD, *_rows(s)]) for i in range(len(_HEAD))]
        for row in [_HEAD, *_rows(s)]:
            out.append("  " + "  ".join(str(v).ljust(w) for v, w in zip(row, widths)))
        out.append(f"  matching model: {s.matching or 'none'}; margin {_num(s.margin and 100 * s.margin, '+.1f', '%')}")
        if s.remedies:
            out.append("  to stabilize: " + "; ".join(_remedies(s.remedies)))
    return "\n".join(out + [""])


def render_markdown(result, sources: dict, info: dict) -> str:
    """The Markdown output of ``diagnose``.

    Parameters
    ----------
    result : validation.diagnose.Diagnosis
        The diagnosis.
    sources : dict
        Parameter → provenance.
    info : dict
        The log's path, format, duration and topics.
    """
    out = ["## Diagnosis from the log", "", f"Log: {info['path']} ({info['format']}, {info['duration']:.1f} s).", "",
           f"**Verdict: {result.verdict}** — {result.reason}.", ""]
    if result.limiter is not None:
        out += [f"Slew limit: {result.limiter.note}.", ""]
    out += ["| parameter | value | source |", "| --- | --- | --- |"]
    for name, v in parameters_table(result, sources).items():
        value = _num(v["value"], ".4g") if isinstance(v["value"], float) else v["value"]
        out.append(f"| {name} | {value} {v['unit']} | {v['source']} |")
    for s in result.stretches:
        out += ["", f"### {_where(s)[0].upper()}{_where(s)[1:]}", ""]
        if not s.judged:
            out.append(f"Not judged: {s.reason}.")
            continue
        out += [f"Measured: {_measured(s.measured)}.", "", "| " + " | ".join(_HEAD) + " |", "|" + " --- |" * len(_HEAD)]
        out += ["| " + " | ".join(str(v) for v in row) + " |" for row in _rows(s)]
        out += ["", f"Matching model: {s.matching or 'none'}."]
        if s.remedies:
            out += ["", "To stabilize: " + "; ".join(_remedies(s.remedies)) + "."]
    return "\n".join(out + [""])
