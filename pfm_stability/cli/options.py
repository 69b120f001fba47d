"""Command-line options shared by the subcommands: robot, controller, preset.

A value typed by the user overrides the preset's; `resolve_parameters` records
where every value came from so reports can mark the assumed ones.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, fields

from ..checks import check_integer, check_number
from ..parameters import HOLDS, PRESETS, RANGES, Controller, Preset, Robot, check_parameter, get_preset

__all__ = ["number", "integer", "add_parameter_options", "resolve_parameters", "ResolvedParameters"]


def number(name: str, *bounds, **options):
    """An argparse ``type=`` that parses a float and checks it against ``RANGES[name]``.

    The message on failure is the library's (`parameters.check_parameter`),
    so the CLI and the library name the parameter and its range the same way.
    A parameter without an entry in ``RANGES`` gives its bounds here, as
    `checks.check_number` takes them (``low, high, low_open=…, unit=…``).
    """
    check = (lambda value: check_number(name, value, *bounds, **options)) if bounds or options else (lambda value: check_parameter(name, value))

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = text
        try:
            return check(value)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = name
    return parse


def integer(name: str, low: int, high: int):
    """An argparse ``type=`` for an integer in [low, high], with the library's message."""

    def parse(text: str) -> int:
        try:
            return check_integer(name, int(text), low, high)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be an integer in [{low}, {high}]; got {text!r}") from None

    parse.__name__ = name
    return parse


PADE_ORDER = integer("pade_order", 1, 12)
"""``--pade-order`` values: Padé order m of the ``pade`` model."""


def add_parameter_options(parser: argparse.ArgumentParser) -> None:
    """--preset, --V, --tau, --T, --k, --f, --n, --W, --hold, --compute-delay."""
    group = parser.add_argument_group("robot and controller (override the preset)")
    group.add_argument("--preset", choices=sorted(PRESETS), default="carmel", help="parameter preset (default: carmel)")
    helps = {
        "V": "speed",
        "tau": "steering time constant",
        "T": "sampling period",
        "k": "steering gain",
        "f": "force-constant ratio F_cr/F_ct",
        "n": "repulsion exponent",
        "W": "robot width",
    }
    for name, text in helps.items():
        group.add_argument(f"--{name}", type=number(name), help=f"{text}, {RANGES[name].describe()}")
    group.add_argument("--hold", choices=HOLDS, help="sampled structure: what is held between samples")
    group.add_argument("--compute-delay", type=integer("compute_delay", 0, 1), help="samples from measurement to actuation (0 or 1)")


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
