"""Command-line options shared by the subcommands: robot, controller, preset.

A value typed by the user overrides the preset's; `resolve_parameters` records
where every value came from so reports can mark the assumed ones.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, fields

from ..checks import check_number
from ..parameters import HOLDS, PRESETS, Controller, Preset, Robot, get_preset

__all__ = ["number", "add_parameter_options", "resolve_parameters", "ResolvedParameters"]


def number(name: str, low: float = -math.inf, high: float = math.inf, *, low_open=True, high_open=True, unit="", scale=1.0):
    """An argparse ``type=`` that parses a float and checks its range.

    The message on failure is the library's (`checks.check_number`), so the
    CLI and the library name the parameter and its range the same way.
    ``scale`` converts the checked value (e.g. degrees → radians is left to
    the caller; 1 by default).
    """

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = text
        try:
            return check_number(name, value, low, high, low_open=low_open, high_open=high_open, unit=unit) * scale
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = name
    return parse


def add_parameter_options(parser: argparse.ArgumentParser) -> None:
    """--preset, --V, --tau, --T, --k, --f, --n, --W, --hold, --compute-delay."""
    group = parser.add_argument_group("robot and controller (override the preset)")
    group.add_argument("--preset", choices=sorted(PRESETS), default="carmel", help="parameter preset (default: carmel)")
    group.add_argument("--V", type=number("V", 0.0, unit="m/s"), help="speed, m/s (> 0)")
    group.add_argument("--tau", type=number("tau", 0.0, low_open=False, unit="s"), help="steering time constant, s (>= 0)")
    group.add_argument("--T", type=number("T", 0.0, low_open=False, unit="s"), help="sampling period, s (>= 0)")
    group.add_argument("--k", type=number("k", 0.0, unit="1/s"), help="steering gain, 1/s (> 0)")
    group.add_argument("--f", type=number("f", 0.0), help="force-constant ratio F_cr/F_ct (> 0)")
    group.add_argument("--n", type=number("n", 0.0, 10.0, high_open=False), help="repulsion exponent (0 < n <= 10)")
    group.add_argument("--W", type=number("W", 0.0, unit="m"), help="robot width, m (> 0)")
    group.add_argument("--hold", choices=HOLDS, help="sampled structure: what is held between samples")
    group.add_argument("--compute-delay", type=_compute_delay, help="samples from measurement to actuation (0 or 1)")


def _compute_delay(text: str) -> int:
    if text.strip() in ("0", "1"):
        return int(text)
    raise argparse.ArgumentTypeError(f"compute_delay must be an integer in [0, 1]; got {text!r}")


_ROBOT_FIELDS = ("V", "tau", "k", "W")
_CONTROLLER_FIELDS = ("f", "n", "T", "hold", "compute_delay")


@dataclass(frozen=True)
class ResolvedParameters:
    """Robot and controller after overrides, with each value's provenance.

    Attributes
    ----------
    preset : Preset
    robot : Robot
    controller : Controller
    sources : dict[str, str]
        Parameter name → "user", "preset <name>" or "ASSUMED (preset <name>): why".
    """

    preset: Preset
    robot: Robot
    controller: Controller
    sources: dict


def resolve_parameters(args) -> ResolvedParameters:
    """Apply the user's overrides to the preset (validated by the dataclasses)."""
    preset = get_preset(args.preset)
    sources = {}
    robot_changes, controller_changes = {}, {}
    for name in _ROBOT_FIELDS + _CONTROLLER_FIELDS:
        value = getattr(args, name, None)
        target = robot_changes if name in _ROBOT_FIELDS else controller_changes
        if value is not None:
            target[name] = value
            sources[name] = "user"
        elif name in preset.assumed:
            sources[name] = f"ASSUMED (preset {preset.name}): {preset.assumed[name]}"
        else:
            sources[name] = f"preset {preset.name}"
    robot = Robot(**{**_fields(preset.robot), **robot_changes})
    controller = Controller(**{**_fields(preset.controller), **controller_changes})
    return ResolvedParameters(preset, robot, controller, sources)


def _fields(obj) -> dict:
    return {f.name: getattr(obj, f.name) for f in fields(obj)}
