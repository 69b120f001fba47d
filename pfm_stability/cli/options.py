"""Command-line options shared by the subcommands: robot, controller, preset, configuration file.

A value typed by the user overrides the configuration file's (``--config``,
docs/config.md), which overrides its preset's; `resolve_parameters` records
where every value came from so reports can mark the assumed ones.
"""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

from ..checks import check_integer, check_number, check_output_path
from ..laws.registry import (COMMANDS, LAW_NAMES, MASS, PARAMETERS, check_parameters, choice_help, choice_keys, get_law, law_help,
                             laws_for, laws_of_family, option_help, option_name, parameter_keys, takers)
from ..parameters import HOLDS, PRESETS, RANGES, ROBOT_FAMILIES, SHOWN_AS, Controller, Preset, Robot, describe_parameter, get_preset

if TYPE_CHECKING:
    from ..io.config import Config

__all__ = [
    "number",
    "check",
    "integer",
    "output_path",
    "input_file",
    "describe",
    "add_parameter_options",
    "resolve_parameters",
    "ResolvedParameters",
    "Default",
    "typed",
    "add_law_options",
    "resolve_law",
    "shipped_or_given",
    "add_family_options",
    "resolve_family",
    "ResolvedFamily",
    "add_controller_options",
    "resolve_tracker",
    "ResolvedTracker",
]

def _shown(key: str) -> str:
    """The parameter as the user knows it (`parameters.SHOWN_AS`)."""
    return SHOWN_AS.get(key, key)


def describe(key: str) -> str:
    """``RANGES[key]`` for a help text, e.g. ``(0, 100] m/s`` or ``[3, 1000]`` (integers exactly): `parameters.describe_parameter`.

    Parameters
    ----------
    key : str
        A key of ``RANGES``.
    """
    return describe_parameter(key)


def check(key: str, value) -> float:
    """`value` as a float if it lies in ``RANGES[key]``, else ValueError.

    The message is the library's (`checks.check_number`, as
    `parameters.check_parameter` words it), naming the parameter as the user
    knows it (``alpha_deg`` → ``alpha``, ``T_sampled`` → ``T``) with the range
    in the units the user typed, so every subcommand states one range per option.

    Parameters
    ----------
    key : str
        A key of ``RANGES``.
    value : object
        The value to check.
    """
    r = RANGES[key]
    return check_number(_shown(key), value, r.low, r.high, low_open=r.low_open, high_open=r.high_open, unit=r.unit)


def number(key: str):
    """An argparse ``type=`` that parses a float and checks it against ``RANGES[key]`` (`check`).

    Parameters
    ----------
    key : str
        A key of ``RANGES``.
    """

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

    Parameters
    ----------
    key : str
        A key of ``RANGES`` with an integer range.
    odd : bool, optional
        Whether the integer must be odd.
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
    """An argparse ``type=`` for an output file, checked before any work (`checks.check_output_path`).

    Parameters
    ----------
    name : str
        The option's name, for the error message.
    suffix : str, optional
        The file's required suffix.
    """

    def parse(text: str) -> str:
        try:
            return check_output_path(name, text, suffix)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = name
    parse.kind, parse.suffix = "path", suffix
    return parse


class Default(str):
    """An option's default value (a `str`, equal to the text), marking that the user did not type it.

    argparse cannot tell a typed ``--preset carmel`` from the default; a
    configuration file's value must beat only the default (`typed`).
    """


def typed(args, name: str) -> bool:
    """Whether the user gave option `name` (not None and not a `Default`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    name : str
        The option's destination name.
    """
    value = getattr(args, name, None)
    return value is not None and not isinstance(value, Default)


def input_file(name: str):
    """An argparse ``type=`` for a file to read: non-empty text; whether it can be read is the reader's to say
    (`pfm_stability.io.config.load_config`: ``config FILE: cannot read the file (…)``).

    Parameters
    ----------
    name : str
        The option's name, for the error message.
    """

    def parse(text: str) -> str:
        if not text.strip() or "\0" in text:
            raise argparse.ArgumentTypeError(f"{name} must be the path of a readable file; got {text!r}")
        return text

    parse.__name__ = name
    parse.kind = "path"  # generated like the output paths by the command-line fuzzer: none of them is a config file
    return parse


def shipped_or_given(name: str, folder: str, shipped, kind: str) -> str:
    """The YAML file of `name`: ``pfm_stability/data/<folder>/<name>.yaml`` when `name` is in `shipped`, else `name` itself.

    Used by ``map`` (shipped maps) and ``traps`` (shipped scenes); `kind` ("map", "scene") names them in the error.
    A name with a directory or an extension is a path, left to the file's reader (which names a missing file).

    Parameters
    ----------
    name : str
        A shipped name or a file's path.
    folder : str
        The folder of ``pfm_stability/data`` holding the shipped files.
    shipped : sequence of str
        The shipped names.
    kind : str
        What they are ("map", "scene"), for the error message.

    Raises
    ------
    ValueError
        A bare name (no directory, no extension) that is neither shipped nor an existing file: one line listing the
        shipped names.
    """
    if name in shipped:
        from importlib import resources

        return str(resources.files("pfm_stability").joinpath("data", folder, f"{name}.yaml"))
    if not (os.path.dirname(name) or os.path.splitext(name)[1] or os.path.exists(name)):
        raise ValueError(f"{kind} {name!r} is neither a file nor a shipped {kind} (shipped: {', '.join(shipped)})")
    return name


PADE_ORDER = integer("pade_order")
"""``--pade-order`` values: Padé order m of the ``pade`` model."""


def add_parameter_options(parser: argparse.ArgumentParser, *, sampled: bool = False) -> None:
    """--config, --preset, --V, --tau, --T, --k, --f, --n, --W, --dead-time, --plant-gain, --hold, --compute-delay.

    With ``sampled=True`` (the simulator and the validation, which sample),
    ``--T`` takes ``RANGES["T_sampled"]``: (0, 100] s.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    sampled : bool, keyword only
        Whether the command samples (``--T`` then in (0, 100] s).
    """
    group = parser.add_argument_group("robot and controller (override the configuration file and the preset)")
    group.add_argument("--config", metavar="FILE", type=input_file("config"),
                       help="configuration file (YAML: robot, controller, law, scenario; or a Nav2 parameters file), "
                            "docs/config.md; options typed here override it")
    group.add_argument("--preset", choices=sorted(PRESETS), default=Default("carmel"),
                       help="parameter preset (default: the configuration file's, else carmel)")
    helps = {
        "V": "speed",
        "tau": "steering time constant",
        "T": "sampling period" + ("" if sampled else " (0: a continuous controller)"),
        "k": "steering gain",
        "f": "force-constant ratio F_cr/F_ct",
        "n": "repulsion exponent",
        "W": "robot width",
        "dead_time": "dead time D of the steering plant g e^(-sD)/(tau s + 1) (pfm-stability identify measures it)",
        "plant_gain": "plant gain g, achieved over commanded turning rate",
        "actuator_lag": "second lag tau_a of the drive (an actuator filter): plant g e^(-sD)/((tau s + 1)(tau_a s + 1))",
        "yaw_accel_limit": "largest rate of change of the commanded yaw rate (a velocity smoother's angular acceleration limit; "
                           "default: none)",
        "slip_lag": "lag tau_s of the course behind the heading (a base that slides sideways in a turn): "
                    "tau_s dchi/dt + chi = theta, dx/dt = V chi",
    }
    for name, text in helps.items():
        key = "T_sampled" if sampled and name == "T" else name
        group.add_argument(f"--{name.replace('_', '-')}", type=number(key), help=f"{text}, {describe(key)}")
    group.add_argument("--hold", choices=HOLDS, help="sampled structure: what is held between samples")
    group.add_argument(
        "--compute-delay", type=integer("compute_delay"), help=f"samples from measurement to actuation, {describe('compute_delay')}"
    )


_ROBOT_FIELDS = ("V", "tau", "k", "W", "dead_time", "plant_gain", "actuator_lag", "yaw_accel_limit", "slip_lag")
_CONTROLLER_FIELDS = ("f", "n", "T", "hold", "compute_delay")


@dataclass(frozen=True)
class ResolvedParameters:
    """Robot and controller after overrides, with each value's provenance.

    Attributes
    ----------
    preset : Preset
        The preset in force: ``--preset``, or the configuration file over its preset
        (`pfm_stability.io.config.Config.preset`: its grid and assumptions).
    robot : Robot
    controller : Controller
    sources : dict[str, str]
        Parameter name → "user", "preset <name>", "ASSUMED (preset <name>): why",
        "config <file>", "ASSUMED (config <file>): why" or "Nav2 <file>: key = value";
        with a configuration file's scenario also ``alpha_deg`` and ``L``.
    config : Config or None
        The ``--config`` file, if any.
    """

    preset: Preset
    robot: Robot
    controller: Controller
    sources: dict
    config: "Config | None" = None


SCENARIO_OPTIONS = {"alpha": ("wall", "alpha", "alpha_deg"), "L": ("corridor", "L", "L")}
"""Options a configuration file's ``scenario`` fills when a command takes them and the user did not type them:
option → (geometry, key, name in the sources)."""


def resolve_parameters(args, *, fill=None, notes: bool = True) -> ResolvedParameters:
    """Apply the user's overrides to the configuration file and the preset (validated by the dataclasses).

    Precedence: an option typed > ``--config FILE`` > the file's ``preset`` (or a
    typed ``--preset``) > carmel. A configuration file's ``scenario`` fills
    ``args.alpha`` / ``args.L`` where the command has them and the user typed
    none (only the options of `fill`, if given: a command whose scenario takes
    no L says so); its notes (Nav2 keys not found) go to stderr.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    fill : tuple of str, keyword only, optional
        The scenario options a configuration file may fill (None: every one the command has).
    notes : bool, keyword only
        Whether to print the file's notes (a Nav2 controller's report reads the file for its controller instead).
    """
    config = None
    if getattr(args, "config", None) is not None:
        from ..io.config import load_config

        config = load_config(args.config, preset=args.preset if typed(args, "preset") else None)
        preset = config.preset
        base_sources = config.sources
    else:
        preset = get_preset(getattr(args, "preset", "carmel"))
        base_sources = {
            name: f"ASSUMED (preset {preset.name}): {preset.assumed[name]}" if name in preset.assumed else f"preset {preset.name}"
            for name in _ROBOT_FIELDS + _CONTROLLER_FIELDS
        }
    sources = {}
    robot_changes, controller_changes = {}, {}
    for name in _ROBOT_FIELDS + _CONTROLLER_FIELDS:
        value = getattr(args, name, None)
        target = robot_changes if name in _ROBOT_FIELDS else controller_changes
        if value is not None:
            target[name] = value
            sources[name] = "user"
        else:
            sources[name] = base_sources[name]
    robot = Robot(**{**_fields(preset.robot), **robot_changes})
    controller = Controller(**{**_fields(preset.controller), **controller_changes})
    if config is not None:
        if config.family not in (None, "steering") and not hasattr(args, "robot"):
            raise ValueError(f"robot.family {config.family} of --config {config.path} is read by report only (--robot, "
                             "docs/velocity_and_fuzzy.md); this command analyses KB's steering robot: give robot.family steering or none")
        sources.update(_fill_scenario(args, config, SCENARIO_OPTIONS if fill is None else fill))
        if "max_steering_rate" in config.sources:  # a Nav2 velocity smoother's clamp (io.nav2.read_velocity_smoother)
            sources["max_steering_rate"] = config.sources["max_steering_rate"]
        for note in config.notes if notes else ():
            print(f"pfm-stability: note: {note}", file=sys.stderr)
    return ResolvedParameters(preset, robot, controller, sources, config)


def _fill_scenario(args, config, options) -> dict:
    """Set ``args.alpha`` / ``args.L`` (those of `options`) from the file's scenario where the command has them and none was typed."""
    sources = {}
    for option in options:
        geometry, key, shown = SCENARIO_OPTIONS[option]
        value = config.scenario.get(geometry, {}).get(key)
        if value is not None and hasattr(args, option) and getattr(args, option) is None:
            setattr(args, option, value)
            sources[shown] = config.sources[shown]
    return sources


def _fields(obj) -> dict:
    return {f.name: getattr(obj, f.name) for f in fields(obj)}


# ------------------------------------------------------------------ force laws (the law registry)
def add_law_options(parser: argparse.ArgumentParser, laws=LAW_NAMES, default: str = "power") -> None:
    """--law (one of `laws`, `default` unless a configuration file names one) and an option for every parameter and
    choice of those laws, all as the law registry declares them (`laws.registry`: help, default, range); each applies
    to the laws that take it (`resolve_law`, `resolve_family`). The help names only `laws`.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    laws : tuple of str, optional
        The laws the command offers (`laws.registry.laws_for`).
    default : str, optional
        The command's default law.
    """
    title, text = law_help(laws, default)
    group = parser.add_argument_group(title)
    ordered = (default, *(name for name in laws if name != default))
    group.add_argument("--law", choices=ordered, default=Default(default), help=text)
    for key in parameter_keys(laws):
        kind = integer(key, odd=True) if PARAMETERS[key].odd else number(key)
        group.add_argument(option_name(key), type=kind, help=option_help(key, laws))
    for key in choice_keys(laws):
        values = get_law(takers(key, laws)[0]).choice(key).values
        group.add_argument(option_name(key), choices=values, help=choice_help(key, laws))


def _offered(args) -> tuple:
    """The laws the command offers (`registry.laws_for`), for refusals; every law for a command not in the registry."""
    command = getattr(args, "command", None)
    return laws_for(command) if command in COMMANDS else LAW_NAMES


def _typed_law_keys(args, params: ResolvedParameters) -> list:
    """The law keys typed on the command line: f and n (the controller's, which only KB's laws read), then every
    parameter and choice option of the registry the command has and the user gave, in registry order."""
    typed_fn = [key for key in ("f", "n") if params.sources.get(key) == "user"]
    return typed_fn + [key for key in (*parameter_keys(), *choice_keys()) if getattr(args, key, None) is not None]


def _law_in_force(args, params: ResolvedParameters):
    """(law, how the user named it, the configuration file's law mapping or {}) for ``--law`` or the file's law."""
    from_file = (params.config.law if params.config is not None else None) or {}
    by_user = typed(args, "law") or not from_file
    name = str(args.law) if by_user else from_file["name"]
    shown = f"--law {name}" if by_user else f"law {name} of --config {params.config.path}"
    return get_law(name), shown, from_file


def resolve_law(args, params: ResolvedParameters):
    """The static law of ``--law`` (else the configuration file's) and the sources of its parameters: (law, sources).

    A configuration file's law parameters apply when its law is the one in force;
    an option typed beats them.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    params : ResolvedParameters
        The robot and controller (`resolve_parameters`).

    Raises
    ------
    ValueError
        A law built by the report only (``law velocity of --config FILE is analysed by report only …``),
        an option the law does not take (`registry.refusal`: ``--xi applies to --law khatib or gnron,
        not to --law power``), or ``--law khatib``/``gnron`` without ``--goal-distance``.
    """
    from ..laws.fields import make_law

    law, shown, from_file = _law_in_force(args, params)
    if law.kind != "static":
        static = [name for name in _offered(args) if get_law(name).kind == "static"]
        raise ValueError(f"law {law.name} of --config {params.config.path} is analysed by report only ({law.doc}); "
                         f"this command takes --law {', '.join(static)}")
    given = {key: getattr(args, key) for key in parameter_keys() if getattr(args, key, None) is not None}
    filed = {k: v for k, v in from_file.items() if k != "name" and k not in given} if from_file.get("name") == law.name else {}
    check_parameters(law.name, _typed_law_keys(args, params) + list(filed), shown=option_name, law_shown=shown, laws=_offered(args))
    built = make_law(law.name, params.robot, params.controller, **given, **filed)
    sources = {}
    for setting in law.settings:
        key = setting.key
        sources[key] = "user" if key in given else params.config.sources[key] if key in filed else setting.source
    return built, sources


# ------------------------------------------------------------------ robot families (report)
def add_family_options(parser: argparse.ArgumentParser) -> None:
    """--robot, --mass and --no-simulate (``report`` only; the laws' options are `add_law_options`').

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The ``report`` subcommand's parser.
    """
    group = parser.add_argument_group("robot family (docs/velocity_and_fuzzy.md)")
    group.add_argument("--robot", choices=ROBOT_FAMILIES, default=Default("steering"),
                       help="loop family: KB's steering robot (default), kinematic steering (tau = 0, --k is K_s) "
                            f"or holonomic (force = acceleration; --law {' or '.join(laws_of_family('holonomic'))})")
    group.add_argument("--mass", type=number("mass"), help=f"holonomic robot mass, {describe('mass')} (default {MASS.default:g})")
    group.add_argument("--no-simulate", action="store_true",
                       help="velocity-gated: do not simulate the wall's limit cycle (the report gives the rest band only)")


@dataclass(frozen=True)
class ResolvedFamily:
    """The report's robot family and law after the options.

    Attributes
    ----------
    family : str
        `parameters.ROBOT_FAMILIES`.
    law : ForceLaw or family_report.FamilyLaw
    mass : float
        kg: ``--mass``, else the ``--config`` file's ``robot.mass`` (holonomic), else 1.
    sources : dict
        Provenance of the law's parameters, the robot family and the mass.
    """

    family: str
    law: object
    mass: float
    sources: dict


def resolve_family(args, params: ResolvedParameters) -> ResolvedFamily:
    """``--robot``, ``--law`` and their options: a static law through `resolve_law`, a law the report builds here.

    Precedence as `resolve_parameters`: an option typed > the ``--config`` file's
    ``robot.family``, ``robot.mass`` and ``law`` (docs/config.md) > the defaults.
    The file's mass applies when its family (holonomic) is the one in force, its
    law's parameters and choices (``variant``, ``side``, ``symmetrize``) when its law is the one in force.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    params : ResolvedParameters
        The robot and controller (`resolve_parameters`).

    Raises
    ------
    ValueError
        An option the law or the robot family does not take (`registry.refusal`: ``--alpha-p applies to
        --law velocity, velocity-gated or fuzzy, not to --law power``; ``--mass applies
        to --robot holonomic``), or a value out of range.
    """
    config = params.config
    filed_family = config.family if config is not None else None
    by_user = typed(args, "robot") or filed_family is None
    family = str(args.robot) if by_user else filed_family
    robot_shown = f"--robot {family}" if by_user else f"robot family {family} of --config {config.path}"
    sources = {"robot": "user" if typed(args, "robot") else config.sources["robot"] if filed_family is not None else "default"}
    if args.mass is not None and family != "holonomic":
        raise ValueError(f"--mass applies to --robot holonomic, not to {robot_shown}")
    filed_mass = config.mass if config is not None and family == "holonomic" and args.mass is None else None
    mass = args.mass if args.mass is not None else filed_mass if filed_mass is not None else MASS.default
    sources["mass"] = "user" if args.mass is not None else config.sources["mass"] if filed_mass is not None else MASS.source
    law, law_shown, from_file = _law_in_force(args, params)
    if family not in law.families:
        raise ValueError(f"{robot_shown} takes --law {' or '.join(laws_of_family(family))} (a force in newtons on a mass, "
                         f"Ge & Cui 2002 Sec 6); got {law_shown}")
    check_parameters(law.name, _typed_law_keys(args, params), shown=option_name, law_shown=law_shown, laws=_offered(args), required=False)
    if law.kind == "static":
        built, law_sources = resolve_law(args, params)
        return ResolvedFamily(family, built, mass, {**sources, **law_sources})
    from ..report.families import make_family_law

    given = {k: getattr(args, k) for k in law.parameters if getattr(args, k, None) is not None}
    # the file's law parameters and choices (checked against the law by `config`) where it is the law in force and no option is typed
    filed_law = from_file if from_file.get("name") == law.name else {}
    filed = {k: v for k, v in filed_law.items() if k in law.parameters and k not in given}
    choices = {}
    for choice in law.choices:
        key = choice.key
        if getattr(args, key, None) is not None:
            choices[key], sources[key] = getattr(args, key), "user"
        elif key in filed_law:
            choices[key], sources[key] = filed_law[key], config.sources[key]
        else:
            sources[key] = choice.source
    built = make_family_law(law.name, choices, **given, **filed)
    sources.update({s.key: "user" if s.key in given else config.sources[s.key] if s.key in filed else s.source for s in law.settings})
    return ResolvedFamily(family, built, mass, sources)


# ------------------------------------------------------------------ path-tracking controllers (report --controller)
def add_controller_options(parser: argparse.ArgumentParser) -> None:
    """--controller, --param, --k-theta, --k-y, --k-theta-se and --k-y-se (``report`` only; docs/path_tracking.md).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The ``report`` subcommand's parser.
    """
    from ..controllers.registry import CONTROLLER_NAMES, DEFAULT_CONTROLLER

    group = parser.add_argument_group("path-tracking controller (docs/path_tracking.md)")
    group.add_argument("--controller", choices=(*CONTROLLER_NAMES, "auto"), default=Default(DEFAULT_CONTROLLER),
                       help="the loop analysed: vff (the VFF force law, default) or a Nav2 controller tracking a straight path "
                            "(--L: a corridor): rpp, graceful, mppi, dwb, or auto (the --config Nav2 file's FollowPath plugin); "
                            "--V is its cruising speed")
    group.add_argument("--param", action="append", metavar="NAME=VALUE", type=nav2_parameter,
                       help="a Nav2 parameter of the controller, e.g. lookahead_dist=0.8 (repeatable; overrides the --config file)")
    group.add_argument("--k-theta", type=number("k_theta"),
                       help=f"mppi, dwb: the measured gain k_theta = -d omega/d e_theta at --V, {describe('k_theta')}")
    group.add_argument("--k-y", type=number("k_y"), help=f"mppi, dwb: the measured gain k_y = -d omega/d e_y at --V, {describe('k_y')}")
    group.add_argument("--k-theta-se", type=number("k_theta_se"), help=f"its standard error, {describe('k_theta_se')} (default 0)")
    group.add_argument("--k-y-se", type=number("k_y_se"), help=f"its standard error, {describe('k_y_se')} (default 0)")


def refuse_vff_options(args, path, given=(), keep=()) -> None:
    """ValueError naming the first option that applies only to ``--controller vff`` the user gave with a Nav2 controller:
    ``--law``, ``--robot``, ``--mass``, the VFF gains ``--k``, ``--f``, ``--n``, ``--W`` (`path.sources` says who gave them),
    every law parameter and choice, and the command's own `given` ((option, given) pairs).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    path : ResolvedTracker
        The controller (`resolve_tracker`).
    given : sequence of (str, bool)
        More VFF-only options of the command, and whether each was given.
    keep : sequence of str
        Keys among the law parameters and the VFF values that the command reads with a Nav2 controller too.
    """
    options = [("--law", typed(args, "law")), ("--robot", typed(args, "robot")), ("--mass", getattr(args, "mass", None) is not None)]
    options += [(f"--{key.replace('_', '-')}", path.sources.get(key) == "user") for key in ("k", "f", "n", "W") if key not in keep]
    options += [(option_name(key), getattr(args, key, None) is not None) for key in (*parameter_keys(), *choice_keys()) if key not in keep]
    for option, was_given in (*options, *given):
        if was_given:
            raise ValueError(f"{option} applies to --controller vff (the VFF loop), not to --controller {path.tracker.controller} "
                             "(its gains are its own law's, docs/path_tracking.md)")


def nav2_parameter(text: str) -> tuple:
    """An argparse ``type=`` for ``--param NAME=VALUE``: (name, value parsed by the YAML rule); the controller checks both
    (`resolve_tracker`, the registry's ranges).

    Parameters
    ----------
    text : str
        ``NAME=VALUE``.
    """
    key, sep, raw = text.partition("=")
    if not sep or not key.strip() or not raw.strip():
        raise argparse.ArgumentTypeError(f"--param must be NAME=VALUE (a Nav2 parameter of the controller); got {text!r}")
    from ..io.yaml_files import InputError, parse_yaml

    try:
        value = parse_yaml(raw.strip())
    except InputError:
        value = raw.strip()
    return key.strip(), value


nav2_parameter.kind = "nav2_param"  # the command-line fuzzer draws NAME=VALUE of the registry


@dataclass(frozen=True)
class ResolvedTracker:
    """A Nav2 controller of ``report --controller`` after the options.

    Attributes
    ----------
    tracker : io.nav2.Nav2Tracker
        The controller with its parameters (the ``--config`` Nav2 file's, Nav2's defaults, ``--param``).
    gains : analysis.path_laws.MeasuredGains or None
        MPPI's or DWB's measured gains.
    robot, controller : Robot, Controller
        With V the controller's cruising speed and T its period unless typed.
    sources : dict
        The provenance of every robot and controller value and of the controller's name.
    """

    tracker: object
    gains: object
    robot: Robot
    controller: Controller
    sources: dict


_PLANT_ASSUMED = {
    "tau": "the robot's steering lag is not in a Nav2 file; this is the preset's (measure yours: pfm-stability identify, docs/diagnose.md)",
    "dead_time": "the latency from cmd_vel to the robot's turning is not in a Nav2 file; this is the preset's (measure yours: "
                 "pfm-stability identify, docs/diagnose.md)",
    "plant_gain": "the turning the drive delivers per commanded yaw rate is not in a Nav2 file; this is the preset's (pfm-stability identify)",
    "actuator_lag": "a second lag of the drive is not in a Nav2 file; this is the preset's (pfm-stability identify)",
    "slip_lag": "whether the base slides sideways in a turn is not in a Nav2 file; this is the preset's (pfm-stability identify)",
    "hold": "the base holds the last cmd_vel between controller cycles",
    "compute_delay": "the controller server publishes a command as soon as it is computed: 0 samples (the computation time is part of "
                     "the dead time D)",
}
"""Why a plant or structure value of a Nav2 controller's report that came from a preset is an assumption."""


def resolve_tracker(args, params: ResolvedParameters) -> ResolvedTracker | None:
    """``--controller`` and its options: None for ``vff``; else the controller, its parameters and the robot it drives.

    The controller's parameters: ``--param`` > the ``--config`` Nav2 file (``controller_server``'s first controller
    plugin, `io.nav2.read_path_tracker`) > Nav2's declared defaults (ASSUMED). V: ``--V`` > the controller's speed
    parameter; T: ``--T`` > the file's ``controller_frequency`` > Nav2's 20 Hz. The plant and the structure a preset
    gave are marked ASSUMED (`_PLANT_ASSUMED`; the compute delay 0 samples).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    params : ResolvedParameters
        The robot and controller (`resolve_parameters`).

    Raises
    ------
    ValueError
        An option the controller does not take, an unknown ``--param`` or a value out of its range, ``auto``
        without a Nav2 file, MPPI or DWB without ``--k-theta`` and ``--k-y``.
    """
    from ..controllers.registry import NAV2_CONTROLLERS, get_controller

    name = str(getattr(args, "controller", "vff"))
    extras = [opt for opt, value in (("--param", args.param), *((f"--{k.replace('_', '-')}", getattr(args, k)) for k in _GAINS))
              if value is not None]
    if name == "vff":
        if extras:
            raise ValueError(f"{extras[0]} applies to --controller {', '.join(NAV2_CONTROLLERS)}, not to --controller vff")
        return None
    tracker = _tracker_of(args, params, name)
    entry = get_controller(tracker.controller)
    given = [f"--{k.replace('_', '-')}" for k in _GAINS if getattr(args, k) is not None]
    if entry.linearisation == "closed form" and given:
        raise ValueError(f"{given[0]} applies to --controller mppi or dwb (numeric gains); --controller {tracker.controller} "
                         "has a closed-form linearisation")
    tracker = _with_params(tracker, entry, args.param or [])
    robot, controller, sources, tracker = _tracker_robot(args, params, tracker, entry)
    gains = _gains(args, tracker, robot.V, controller.T) if entry.linearisation == "numeric" else None
    sources["controller"] = "user" if name != "auto" else f"auto: {tracker.plugin_id}.plugin of --config {params.config.path}"
    return ResolvedTracker(tracker, gains, robot, controller, sources)


def _tracker_of(args, params: ResolvedParameters, name: str):
    """The controller from the ``--config`` Nav2 file (its plugin must be `name`, unless ``auto``), else Nav2's defaults."""
    from ..io.nav2 import default_tracker, is_nav2, read_path_tracker
    from ..io.yaml_files import read_yaml

    if params.config is not None and params.config.path is not None:
        document = read_yaml(params.config.path, "config")
        if is_nav2(document.data):
            from dataclasses import replace

            return read_path_tracker(replace(document, origin=f"Nav2 {params.config.path}"), None if name == "auto" else name)
    if name == "auto":
        raise ValueError("--controller auto takes the controller from a Nav2 parameters file: give --config nav2_params.yaml")
    return default_tracker(name, "no Nav2 file given" if params.config is None else f"--config {params.config.path} is no Nav2 file")


_GAINS = ("k_theta", "k_y", "k_theta_se", "k_y_se")
"""The measured gains' options (``--k-theta`` …)."""


def _with_params(tracker, entry, given: list):
    """The tracker with each ``--param NAME=VALUE`` (`nav2_parameter`) set: the registry's check; the speed is ``--V``."""
    from dataclasses import replace

    from ..io.nav2 import Nav2Setting

    parameters = dict(tracker.parameters)
    for key, value in given:
        parameter = entry.parameter(key)
        if parameter.name == entry.speed:
            raise ValueError(f"--param {key}: the cruising speed is --V (m/s)")
        parameters[parameter.name] = Nav2Setting(parameter.check(value, f"--param {parameter.name}"), "user")
    return replace(tracker, parameters=parameters)


def _tracker_robot(args, params: ResolvedParameters, tracker, entry) -> tuple:
    """(robot, controller, sources, tracker): V the controller's speed and T its period unless typed; the preset's plant
    and structure ASSUMED (`_PLANT_ASSUMED`)."""
    from dataclasses import replace

    from ..io.nav2 import Nav2Setting

    sources = dict(params.sources)
    robot, controller = params.robot, params.controller
    speed = tracker.parameters[entry.speed]
    if sources["V"] == "user":
        tracker = replace(tracker, parameters={**tracker.parameters, entry.speed: Nav2Setting(robot.V, "user")})
    else:
        if not speed.value > 0:
            raise ValueError(f"--controller {entry.name}: {entry.speed} is {speed.value:g} m/s ({speed.source}); give the cruising speed, --V")
        robot, sources["V"] = robot.replace(V=speed.value), speed.named(entry.speed, f"{speed.value:g} m/s")
    if not (sources["T"] == "user" or sources["T"].startswith("Nav2 ")):
        frequency = tracker.frequency
        controller = replace(controller, T=1.0 / frequency.value)
        sources["T"] = frequency.named("controller_frequency", f"{frequency.value:g} Hz")
    for name, why in _PLANT_ASSUMED.items():
        preset = _preset_of(sources.get(name, ""))
        if preset is not None:
            sources[name] = f"ASSUMED (preset {preset}): {why}"
            if name == "compute_delay":
                controller = replace(controller, compute_delay=0)
    return robot, controller, sources, tracker


def _preset_of(source: str) -> str | None:
    """The preset a value came from (``"preset carmel"``, ``"ASSUMED (preset carmel): why"``), or None."""
    for head in ("preset ", "ASSUMED (preset "):
        if source.startswith(head):
            return source[len(head):].split(")")[0].split()[0]
    return None


def _gains(args, tracker, V: float, T: float):
    """MPPI's or DWB's `MeasuredGains`: from ``--k-theta`` and ``--k-y`` (and their standard errors) when typed, else
    measured from the algorithm with the file's parameters about the corridor's centre line (`MeasuredGains.measure`:
    seeded, its response over `analysis.path_laws.MEMORY_CYCLES` cycles; a note on stderr, it takes seconds)."""
    from ..analysis.path_laws import MEMORY_CYCLES, MeasuredGains

    controller = tracker.controller
    if (args.k_theta is None) != (args.k_y is None):
        raise ValueError(f"--controller {controller}: give both --k-theta and --k-y, or neither (then they are measured from the "
                         "algorithm, docs/path_tracking.md)")
    if args.k_theta is not None:
        return MeasuredGains(controller, args.k_theta, args.k_y, V, args.k_theta_se or 0.0, args.k_y_se or 0.0)
    if args.k_theta_se is not None or args.k_y_se is not None:
        raise ValueError("--k-theta-se and --k-y-se go with --k-theta and --k-y (measured gains carry their own standard errors)")
    print(f"pfm-stability: note: measuring {controller}'s gains from its algorithm about the centre line (seeded, "
          f"{MEMORY_CYCLES} cycles of its response)", file=sys.stderr)
    given = {name: setting.value for name, setting in tracker.parameters.items() if not setting.assumed}
    return MeasuredGains.measure(controller, given, tracker.costmap_values(), V=V, T=T, half_width=getattr(args, "L", None))


