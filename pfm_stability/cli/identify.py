"""``pfm-stability identify``: the steering plant and the controller's period from a robot's own log.

    pfm-stability identify LOG [--out ROBOT.yaml] [--format text|json|markdown]
                               [--cmd-topic /cmd_vel] [--odom-topic /odom] [--imu-topic /imu] [--rate-source odometry|imu]
                               [--pose-topic TOPIC]

LOG is a ROS 2 bag (its directory, or a ``.db3``/``.mcap`` file), a ROS 1 ``.bag`` or a CSV
(docs/diagnose.md, "Logs"). The commanded yaw rate (``/cmd_vel``) against the achieved one (the
odometry's, or the IMU's with ``--rate-source imu``) gives the plant the data support — g·e^(−sD)/(τs + 1), a second
lag τ_a, a slew limit A on the command (`pfm_stability.analysis.plant_fit`: the smallest BIC of the four, with each
one's Ljung–Box whiteness) — with 95 % intervals; the command's stamps give the controller's period T, its jitter and missed cycles
(`pfm_stability.analysis.identification`). JSON keys (`pfm_stability/io/schema/output.schema.json`):
``schema_version``, ``command`` ("identify"), ``identified``, ``reason``, ``plant`` (``model``, ``g``, ``tau``,
``dead_time``, ``actuator_lag``, ``yaw_accel_limit``, each ``{value, low, high}`` or null, and ``identifiable``),
``controller`` (``T``, ``jitter``, ``missed``, …), ``fit`` (``quality``, ``warnings``, ``excitation``, ``models``), ``slip``
(null without a pose; else ``slip_lag`` ``{value, low, high}`` or null with its ``reason``), ``log`` (path, format,
duration, topics), ``timing``.

The slide's lag τ_s (`pfm_stability.analysis.slip_fit`) is measured from a pose that sees the base move: a bag's
``--pose-topic`` (an Odometry from a localisation, motion capture or a simulator's ground truth; wheel odometry cannot
show a slide, so the odometry's own pose is not used unless named here), a CSV's ``x, y, yaw`` columns when it has them.
``--out`` writes it as ``slip_lag`` when measured.

A log that shows nothing to identify (the command never changes, the robot does not move) is an
answer, not an error: exit 0 with ``identified`` false and the reason (the controller's period is
still measured). ``--out`` then fails (exit 2, nothing written): there is no plant to write. So it does
when the commands excite one frequency (the ``narrowband`` warning, ``plant.identifiable`` false, null
intervals): the values are then one point of a ridge of equally good plants, and a configuration file would
look certain where the log is not (docs/diagnose.md, "Identifiability"). A bad log
is one line, exit 2. Reading a bag needs the extra ``logs`` (rosbags).
"""

from __future__ import annotations

import argparse
import math
import os
import re
import time

__all__ = ["add_parser", "add_topic_options", "run", "render_text", "render_markdown", "robot_yaml", "topic", "FORMATS", "TOPICS"]

FORMATS = ("text", "json", "markdown")
_TOPIC = re.compile(r"^(~/|/)?[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z0-9_]+)*$")
"""A ROS topic name: tokens of letters, digits and underscores separated by single slashes, not starting with a digit."""


def topic(name: str):
    """An argparse ``type=`` for the topic option `name`: a ROS topic name (``/cmd_vel``, ``robot1/odom``).

    Parameters
    ----------
    name : str
        The option's name, for the error message.
    """

    def parse(text: str) -> str:
        if not _TOPIC.match(text):
            raise argparse.ArgumentTypeError(f"{name} must be a ROS topic name such as /cmd_vel (letters, digits, _ "
                                             f"and single slashes); got {text!r}")
        return text

    parse.__name__ = name
    parse.kind = "topic"  # for tests/test_cli_fuzz.py: every option has a checked type
    return parse


TOPICS = {"cmd": ("/cmd_vel", "the command (Twist or TwistStamped; default /cmd_vel)"),
          "odom": ("/odom", "the odometry (Odometry; default /odom)"),
          "imu": ("/imu", "the IMU (Imu; default /imu), read with --rate-source imu"),
          "scan": ("/scan", "the laser scans (LaserScan; default /scan)"),
          "pose": (None, "the pose the slide's lag slip_lag is measured from (Odometry of a localisation, motion capture or a "
                         "simulator's ground truth: wheel odometry cannot show a slide; default none; a CSV's x, y, yaw columns "
                         "are read when it has them)")}
"""The log's topics a command reads: option ``--KEY-topic``, its default and help."""


def add_topic_options(parser: argparse.ArgumentParser, keys) -> None:
    """Add a ``--KEY-topic`` option (`TOPICS`) to `parser` for each of `keys`.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The command's parser.
    keys : iterable of str
        Keys of `TOPICS`.
    """
    for key in keys:
        default, help_text = TOPICS[key]
        parser.add_argument(f"--{key}-topic", type=topic(f"{key}-topic"), default=default, metavar="TOPIC", help=help_text)


def add_parser(sub) -> None:
    """Add the ``identify`` subcommand to `sub` (argparse subparsers).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The command's subparsers.
    """
    from .options import output_path

    p = sub.add_parser(
        "identify",
        help="identify the steering plant (gain, lag, dead time) and the controller's period from a robot's log",
        description="Read a ROS 2 bag (directory, .db3 or .mcap), a ROS 1 .bag or a CSV; fit the yaw-rate plant the data "
        "support (g*exp(-sD)/(tau*s + 1), a second lag tau_a, a slew limit on the command: the smallest BIC) to the "
        "commanded and achieved yaw rates, with 95%% intervals, and measure the "
        "controller's period T, its jitter and missed cycles from the command's stamps (docs/diagnose.md).",
    )
    p.add_argument("log", metavar="LOG", help="a ROS 2 bag directory, a .db3 or .mcap file, a ROS 1 .bag, or a .csv")
    p.add_argument("--out", type=output_path("out", ".yaml"), metavar="ROBOT.yaml",
                   help="write the identified tau, dead_time, plant_gain (actuator_lag, yaw_accel_limit when the data show them, "
                   "slip_lag when measured from a pose) and T as a configuration file (docs/config.md)")
    p.add_argument("--format", choices=FORMATS, default="text")
    add_topic_options(p, ("cmd", "odom", "imu", "pose"))
    p.add_argument("--rate-source", choices=("odometry", "imu"), default="odometry",
                   help="where the achieved yaw rate comes from (default: odometry)")
    p.set_defaults(run=run)


def run(args) -> int:
    """Read the log, identify, write ``--out`` and print the result; returns the exit status (0).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``identify`` options.
    """
    from ..analysis.identification import identify
    from ..extras import require
    from ..io.logs import LogTopics, log_format, read_log
    from ..io.serialize import SCHEMA_VERSION, dumps

    started = time.perf_counter()
    csv = log_format(args.log) == "csv"
    if not csv:
        require("logs", "pfm-stability identify")
    topics = LogTopics(command=args.cmd_topic, odometry=args.odom_topic, imu=args.imu_topic, pose=args.pose_topic)
    pose = {"optional": ("pose",)} if csv else {"need": ("command", args.rate_source, "pose")} if args.pose_topic else {}
    log = read_log(args.log, topics, **{"need": ("command", args.rate_source), **pose})
    result = identify(log, args.rate_source)
    if args.out:
        if not result.identified:
            raise ValueError(f"nothing identified from {args.log}: {result.reason}; {args.out} not written")
        if not result.plant.identifiable:
            x = result.plant.excitation
            raise ValueError(f"g, tau and D are not separately identifiable from {args.log}: its commands excite one "
                             f"frequency (omega ~ {x.omega:.3g} rad/s); record step turns; {args.out} not written")
        from ..io.files import write_text

        write_text(args.out, robot_yaml(result), what="configuration")
    if args.format == "json":
        print(dumps({"schema_version": SCHEMA_VERSION, "command": "identify", **result.to_dict(),
                     "timing": {"seconds": time.perf_counter() - started}}))
    elif args.format == "markdown":
        print(render_markdown(result), end="")
    else:
        print(render_text(result) + (f"configuration written to {args.out}\n" if args.out else ""), end="")
    return 0


# ------------------------------------------------------------------------------------------ renderings
def _ms(seconds: float) -> str:
    return f"{1000 * seconds:.1f} ms"


def _lines(result) -> dict:
    """The pieces both renderings share."""
    log, c = result.log, result.controller
    return {
        "source": f"{log.path} ({log.format}, {log.duration:.1f} s): command {log.command_topic} ({log.command_stamps} times), "
                  f"rate {log.rate_topic} ({log.rate_source})",
        "T": f"{_ms(c.T)} (nominal {c.nominal:.2f} Hz, achieved {c.rate:.2f} Hz over {c.messages} commands)",
        "jitter": f"{_ms(c.p5)} to {_ms(c.p95)} (5th to 95th percentile of the intervals)",
        "missed": f"{c.missed} interval{'s' if c.missed != 1 else ''} longer than 1.5·T",
    }


_MODEL_NAMES = {"first_order": "g·e^(−sD)/(τs + 1)", "two_lags": "g·e^(−sD)/((τs + 1)(τ_a·s + 1))",
                "slew_limited": "g·e^(−sD)/(τs + 1) behind a slew limit A on the command",
                "two_lags_slew_limited": "g·e^(−sD)/((τs + 1)(τ_a·s + 1)) behind a slew limit A on the command"}
"""The plant of each model (`analysis.plant_fit.PLANT_MODELS`), as the renderings name it."""


def _plant_rows(plant) -> list[tuple[str, str, str]]:
    rows = [("g (plant gain)", plant.g, f"{plant.g.value:.4g}", lambda v: f"{v:.4g}"),
            ("τ (lag)", plant.tau, f"{plant.tau.value:.4g} s", lambda v: f"{v:.4g} s"),
            ("D (dead time)", plant.dead_time, _ms(plant.dead_time.value), _ms)]
    if plant.actuator_lag is not None:
        rows.append(("τ_a (second lag)", plant.actuator_lag, f"{plant.actuator_lag.value:.4g} s", lambda v: f"{v:.4g} s"))
    if plant.yaw_accel_limit is not None:
        rows.append(("A (slew limit)", plant.yaw_accel_limit, f"{plant.yaw_accel_limit.value:.4g} rad/s²",
                     lambda v: f"{v:.4g} rad/s²"))
    if plant.smoother is not None:
        sm = plant.smoother
        rows.append((f"smoother {sm.frequency:g} Hz", None, f"wait {_ms(sm.mean_wait)}", None))
    if not plant.identifiable:  # one point of the ridge: no interval means anything
        return [(name, value, "not identifiable") for name, _, value, _ in rows]
    return [(name, value, f"{unit(e.low)} to {unit(e.high)}" if e is not None else "the mean wait of a command for its tick: "
             f"the loop's dead time is D + wait = {_ms(plant.loop_dead_time)}") for name, e, value, unit in rows]


def _models(plant) -> list[str]:
    """One line per candidate plant: its BIC against the selected one's, its residuals' whiteness (Ljung–Box)."""
    if not plant.models:
        return []
    best = next(m for m in plant.models if m.selected).bic
    return [f"{m.model:22s} ΔBIC {m.bic - best:+10.1f}   Ljung–Box p {m.ljung_box_p:.3g}{'   selected' if m.selected else ''}"
            for m in plant.models]


def _ridge(plant) -> list[str]:
    """What a narrowband log does determine: the plant's gain and phase at the commands' frequency."""
    x = plant.excitation
    if plant.identifiable:
        return []
    return [f"the log determines the plant at ω ≈ {x.omega:.3g} rad/s only: gain {x.gain:.3g}, phase "
            f"{math.degrees(x.phase):.1f}° (any g, τ, D with these explains it as well)"]


def _quality(q) -> str:
    white = "white" if q.white else f"not white ({100 * q.outside:.0f} % of lags 1–20 outside the band)"
    return (f"R² {q.r2:.4f}, NRMSE {q.nrmse:.3f}, residuals {white} (lag-1 autocorrelation {q.lag1:+.3f}); "
            f"{q.samples} samples in {q.windows} window{'s' if q.windows != 1 else ''} ({q.excited:.1f} s), "
            f"bias {q.bias:+.2g} rad/s")


def _slide_rows(slip) -> list[tuple[str, str, str]]:
    """(name, value, 95 % interval) of the slide's lag and the pose's heading offset."""
    lag, offset = slip.slip_lag, slip.misalignment
    ms = lambda v: f"{1000 * v:.2f} ms"  # noqa: E731 - a slide is a few ms: 10 µs shows its interval
    return [("τ_s (slip lag)", ms(lag.value), f"{ms(lag.low)} to {ms(lag.high)}"),
            ("heading offset", f"{1000 * offset.value:.3g} mrad", f"{1000 * offset.low:.3g} to {1000 * offset.high:.3g} mrad")]


def _slide_fit(slip) -> str:
    return (f"{slip.samples} samples moving at {slip.speed:.3g} m/s (median), yaw rate varying by {slip.turn:.3g} rad/s; "
            f"R² {slip.r2:.3f}; the lag's own lag mattered by at most {100 * slip.lag_bias:.2g} % (corrected)")


def _slide_text(result) -> list[str]:
    """The slide's lines of the text output: none without a pose."""
    if not result.has_pose:
        return []
    source = f"slide (the course's lag behind the heading, from the pose {result.log.pose_topic})"
    if result.slip is None:
        return ["", f"{source}: not measured — {result.slip_reason}"]
    return (["", f"{source}, 95 % intervals"] + [f"  {name:17s} {value:>14s}   [{interval}]" for name, value, interval in
                                                _slide_rows(result.slip)] + [f"  {_slide_fit(result.slip)}"])


def _slide_markdown(result) -> list[str]:
    """The slide's lines of the Markdown output: none without a pose."""
    if not result.has_pose:
        return []
    if result.slip is None:
        return [f"**Slide not measured** (pose {result.log.pose_topic}): {result.slip_reason}.", ""]
    out = [f"| slide, from the pose {result.log.pose_topic} | value | 95 % interval |", "| --- | --- | --- |"]
    return out + [f"| {name} | {value} | {interval} |" for name, value, interval in _slide_rows(result.slip)] + \
        ["", f"Slide fit: {_slide_fit(result.slip)}.", ""]


def render_text(result) -> str:
    """The text output of ``identify`` (an `Identification`).

    Parameters
    ----------
    result : Identification
        What `identify` found.
    """
    parts = _lines(result)
    out = [f"log: {parts['source']}", "", f"controller (from {result.log.command_topic})",
           f"  T       {parts['T']}", f"  jitter  {parts['jitter']}", f"  missed  {parts['missed']}", ""]
    if not result.identified:
        return "\n".join(out + [f"plant: not identified — {result.reason}"] + _slide_text(result) + [""])
    plant = result.plant
    out.append(f"plant {_MODEL_NAMES[plant.model]}, 95 % intervals")
    out += [f"  {name:17s} {value:>14s}   [{interval}]" for name, value, interval in _plant_rows(plant)]
    out += [f"  {line}" for line in _ridge(plant)]
    if plant.models:
        out += ["", f"which plant (the same {plant.models[0].samples} samples; the smallest BIC is selected):"]
        out += [f"  {line}" for line in _models(plant)]
    out += ["", f"fit: {_quality(plant.quality)}"]
    out += [f"warning ({w.kind}): {w.message}" for w in plant.warnings] or ["warnings: none"]
    return "\n".join(out + _slide_text(result) + [""])


def render_markdown(result) -> str:
    """The Markdown output of ``identify`` (an `Identification`).

    Parameters
    ----------
    result : Identification
        What `identify` found.
    """
    parts = _lines(result)
    out = ["## Identified from the log", "", f"Log: {parts['source']}.", "", "| controller | |", "| --- | --- |",
           f"| T | {parts['T']} |", f"| jitter | {parts['jitter']} |", f"| missed | {parts['missed']} |", ""]
    if not result.identified:
        return "\n".join(out + [f"**Plant not identified:** {result.reason}.", ""] + _slide_markdown(result))
    plant = result.plant
    out += [f"| plant {_MODEL_NAMES[plant.model]} | value | 95 % interval |", "| --- | --- | --- |"]
    out += [f"| {name} | {value} | {interval} |" for name, value, interval in _plant_rows(plant)]
    out += [f"\n{line[0].upper()}{line[1:]}." for line in _ridge(plant)]
    if plant.models:
        best = next(m for m in plant.models if m.selected).bic
        out += ["", "| candidate | ΔBIC | Ljung–Box p | |", "| --- | --- | --- | --- |"]
        out += [f"| {m.model} | {m.bic - best:+.1f} | {m.ljung_box_p:.3g} | {'selected' if m.selected else ''} |" for m in plant.models]
    out += ["", f"Fit: {_quality(plant.quality)}.", ""]
    out += [f"- **{w.kind}**: {w.message}" for w in plant.warnings] or ["No warnings: the model explains the data."]
    return "\n".join(out + [""] + _slide_markdown(result))


def robot_yaml(result) -> str:
    """The configuration file ``--out`` writes: ``robot: {tau, dead_time, plant_gain}`` (and ``actuator_lag``,
    ``yaw_accel_limit`` when the selected plant has them, ``slip_lag`` when measured from a pose), ``controller: {T}``,
    commented.

    Parameters
    ----------
    result : Identification
        What `identify` found (identified: its plant is written).
    """
    plant, c, log = result.plant, result.controller, result.log
    name = os.path.basename(os.path.normpath(log.path))
    D = max(plant.loop_dead_time, 0.0)
    wait = "" if plant.smoother is None else f"; with the smoother's mean wait of {1000 * plant.smoother.mean_wait:.1f} ms"
    lines = [
        f"# Identified by `pfm-stability identify` from {name} ({log.duration:.0f} s;",
        f"# command {log.command_topic}, rate {log.rate_topic}). 95 % intervals in the comments.",
        "# Add the steering gain k, the force ratio f, the exponent n, the width W, the speed V",
        "# and the law (docs/config.md) before using it with `pfm-stability report --config`.",
        "robot:",
        f"  tau: {plant.tau.value:.6g}          # s, steering lag, identified from {name} ({plant.tau.low:.4g} to {plant.tau.high:.4g})",
        f"  dead_time: {D:.6g}    # s, identified from {name} ({plant.dead_time.low:.4g} to {plant.dead_time.high:.4g}{wait})",
        f"  plant_gain: {plant.g.value:.6g}   # -, achieved/commanded yaw rate, identified from {name} "
        f"({plant.g.low:.4g} to {plant.g.high:.4g})",
    ]
    if plant.actuator_lag is not None:
        e = plant.actuator_lag
        lines.append(f"  actuator_lag: {e.value:.6g}   # s, second lag of the drive, identified from {name} ({e.low:.4g} to {e.high:.4g})")
    if plant.yaw_accel_limit is not None:
        e = plant.yaw_accel_limit
        lines.append(f"  yaw_accel_limit: {e.value:.6g}   # rad/s^2, slew limit on the commanded yaw rate, identified from {name} "
                     f"({e.low:.4g} to {e.high:.4g})")
    if result.slip is not None:
        e = result.slip.slip_lag
        lines.append(f"  slip_lag: {max(e.value, 0.0):.6g}   # s, lag of the course behind the heading (the base's slide), "
                     f"identified from the pose {log.pose_topic} of {name} ({e.low:.4g} to {e.high:.4g})")
    lines += [
        "controller:",
        f"  T: {c.T:.6g}            # s, median period of {log.command_topic} in {name} "
        f"(jitter {1000 * c.p5:.1f} to {1000 * c.p95:.1f} ms, {c.missed} missed)",
    ]
    return "\n".join(lines) + "\n"
