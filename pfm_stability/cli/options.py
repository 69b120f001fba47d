"""Command-line options shared by the subcommands: robot, controller, preset.

A value typed by the user overrides the preset's; `resolve_parameters` records
where every value came from so reports can mark the assumed ones.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, fields

from ..checks import check_integer, check_number, check_output_path
from ..parameters import FIELD_DEFAULTS, FORCE_LAWS, HOLDS, LAW_PARAMETERS, PRESETS, RANGES, SHOWN_AS, Controller, Preset, Robot, get_preset

__all__ = [
    "number",
    "check",
    "integer",
    "output_path",
    "describe",
    "add_parameter_options",
    "resolve_parameters",
    "ResolvedParameters",
    "LAW_OPTIONS",
    "add_law_options",
    "resolve_law",
]

def _shown(key: str) -> str:
    """The parameter as the user knows it (`parameters.SHOWN_AS`)."""
    return SHOWN_AS.get(key, key)


def describe(key: str) -> str:
    """``RANGES[key]`` for a help text, e.g. ``(0, 100] m/s`` or ``[3, 1000]`` (integers exactly)."""
    r = RANGES[key]
    if isinstance(r.low, int) and isinstance(r.high, int):
        return f"[{r.low}, {r.high}]" + (f" {r.unit}" if r.unit else "")
    return r.describe()


def check(key: str, value) -> float:
    """`value` as a float if it lies in ``RANGES[key]``, else ValueError.

    The message is the library's (`checks.check_number`, as
    `parameters.check_parameter` words it), naming the parameter as the user
    knows it (``alpha_deg`` → ``alpha``, ``T_sampled`` → ``T``) with the range
    in the units the user typed, so every subcommand states one range per option.
    """
    r = RANGES[key]
    return check_number(_shown(key), value, r.low, r.high, low_open=r.low_open, high_open=r.high_open, unit=r.unit)


def number(key: str):
    """An argparse ``type=`` that parses a float and checks it against ``RANGES[key]`` (`check`)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = text
        try:
            return check(key, value)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = _shown(key)
    parse.kind, parse.range_key = "number", key  # for tests that generate values of every option
    return parse


def integer(key: str, *, odd: bool = False):
    """An argparse ``type=`` for an integer in the closed range ``RANGES[key]`` (odd if asked).

    Message: ``"<key> must be an [odd ]integer in [low, high]; got '<text>'"``,
    as `checks.check_integer` (and `effective_force.check_window_cells`) word it.
    """
    r = RANGES[key]
    low, high = int(r.low), int(r.high)
    shown = _shown(key)
    message = f"{shown} must be an {'odd ' if odd else ''}integer in [{low}, {high}]; got {{!r}}"

    def parse(text: str) -> int:
        try:
            value = check_integer(shown, int(text), low, high)
        except ValueError:
            raise argparse.ArgumentTypeError(message.format(text)) from None
        if odd and value % 2 == 0:
            raise argparse.ArgumentTypeError(message.format(text))
        return value

    parse.__name__ = shown
    parse.kind, parse.range_key, parse.odd = "integer", key, odd
    return parse


def output_path(name: str, suffix: str = ".png"):
    """An argparse ``type=`` for an output file, checked before any work (`checks.check_output_path`)."""

    def parse(text: str) -> str:
        try:
            return check_output_path(name, text, suffix)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = name
    parse.kind, parse.suffix = "path", suffix
    return parse


PADE_ORDER = integer("pade_order")
"""``--pade-order`` values: Padé order m of the ``pade`` model."""


def add_parameter_options(parser: argparse.ArgumentParser, *, sampled: bool = False) -> None:
    """--preset, --V, --tau, --T, --k, --f, --n, --W, --hold, --compute-delay.

    With ``sampled=True`` (the simulator and the validation, which sample),
    ``--T`` takes ``RANGES["T_sampled"]``: (0, 100] s.
    """
    group = parser.add_argument_group("robot and controller (override the preset)")
    group.add_argument("--preset", choices=sorted(PRESETS), default="carmel", help="parameter preset (default: carmel)")
    helps = {
        "V": "speed",
        "tau": "steering time constant",
        "T": "sampling period" + ("" if sampled else " (0: a continuous controller)"),
        "k": "steering gain",
        "f": "force-constant ratio F_cr/F_ct",
        "n": "repulsion exponent",
        "W": "robot width",
    }
    for name, text in helps.items():
        key = "T_sampled" if sampled and name == "T" else name
        group.add_argument(f"--{name}", type=number(key), help=f"{text}, {describe(key)}")
    group.add_argument("--hold", choices=HOLDS, help="sampled structure: what is held between samples")
    group.add_argument(
        "--compute-delay", type=integer("compute_delay"), help=f"samples from measurement to actuation, {describe('compute_delay')}"
    )


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


# ------------------------------------------------------------------ force laws
LAW_OPTIONS = {
    "cell_ratio": "grid: force ratio F_cr/F_ct per cell (default: calibrated so that f_av = f, KB §4)",
    "cell_size": "grid: cell size (default 0.1)",
    "window_cells": "grid: active window side, odd (default 33)",
    "xi": "khatib/gnron: attractive scaling factor xi (default 1)",
    "eta": "khatib/gnron: repulsive scaling factor eta (default 0.1)",
    "rho0": "khatib/gnron: influence distance rho0 (default 0.8)",
    "attraction_exponent": "khatib/gnron: m of U_att = xi rho_g^m / 2 (default 2)",
    "goal_exponent": "gnron: n of the goal-aware repulsion U_rep rho_g^n (default 2)",
    "goal_distance": "khatib/gnron: the frozen distance to the goal rho_g (required)",
    "delta": "gnron: surface offset delta of Ge & Cui eq (40) (default 0)",
}
"""The law options (`parameters.RANGES` keys) and their help, as ``--cell-ratio`` … ``--delta`` (docs/fields.md)."""

_FIELD_SOURCE = "default (Ge & Cui 2000 Sec VI)"


def _option(name: str) -> str:
    return "--" + name.replace("_", "-")


def add_law_options(parser: argparse.ArgumentParser) -> None:
    """--law and the options of the laws (`LAW_OPTIONS`); each applies to the laws of `parameters.LAW_PARAMETERS` only."""
    group = parser.add_argument_group("force law (docs/fields.md)")
    group.add_argument("--law", choices=FORCE_LAWS, default="power",
                       help="lateral force law: KB's power law f(W/d)^n (default), the histogram grid's law, "
                            "Khatib's repulsion or Ge & Cui's goal-aware repulsion (gnron)")
    for name, text in LAW_OPTIONS.items():
        kind = integer(name, odd=True) if name == "window_cells" else number(name)
        group.add_argument(_option(name), type=kind, help=f"{text}, {describe(name)}")


def resolve_law(args, params: ResolvedParameters):
    """The law of ``--law`` and the sources of its parameters: (law, sources).

    Raises
    ------
    ValueError
        An option the law does not take (``--xi applies to khatib or gnron, not to --law power``),
        or ``--law khatib``/``gnron`` without ``--goal-distance``.
    """
    from ..fields import check_law_parameters, make_law

    given = {name: getattr(args, name) for name in LAW_OPTIONS if getattr(args, name, None) is not None}
    typed = [name for name in ("f", "n") if params.sources.get(name) == "user"]
    check_law_parameters(args.law, typed + list(given), _option, f"--law {args.law}")
    law = make_law(args.law, params.robot, params.controller, **given)
    sources = {}
    for name in LAW_PARAMETERS[args.law]:
        if name in ("f", "n"):
            continue
        if name in given:
            sources[name] = "user"
        elif name == "cell_ratio":
            sources[name] = "calibrated so that f_av = f (KB §4)"
        else:
            sources[name] = "default (0: Ge & Cui eq 8)" if name == "delta" else _FIELD_SOURCE if name in FIELD_DEFAULTS else "default (KB §2)"
    return law, sources

