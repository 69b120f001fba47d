"""The law registry: every lateral force law declared once, with everything the user may give it.

Each `Law` names its parameters (`Setting`: default, and the provenance a report gives a
default), its choice-valued parameters (`Choice`: ``variant``, ``side``, ``symmetrize``),
the controller's parameters it reads (``f``, ``n``), the robot families that take it, the
commands that offer it and its documentation. Each numeric parameter is declared once
(`PARAMETERS`: its meaning, its range ``parameters.RANGES[key]`` with the unit, whether it
is an odd integer). Everything else reads this table:

* the command line: ``report --law`` and ``map --law`` with their law options
  (`pfm_stability.cli.options.add_law_options`: one option per parameter, its help
  and range from here), ``simulate --law``;
* configuration files' ``law:`` (`pfm_stability.io.config`), sweep specs' ``law:`` and the
  law parameters a sweep may vary (`pfm_stability.sweeps.spec`);
* the builders: `pfm_stability.laws.fields.make_law` (the static laws, with the defaults
  here) and the report's family laws (through the views at the end of this module);
* the refusal of a parameter the law in force does not take, worded in one place
  (`refusal`), and of a law without its required parameter (`check_parameters`).

The commands (`COMMANDS`): ``report`` (every law), ``map`` (the laws a map can give: no
goal), ``sweep`` (the static laws, which the vectorized models take) and ``simulate``
(``simulate --env analytic --law``, and ``validate`` through a configuration file: the
simulator's analytic walls). Every law may be a configuration file's ``law``; the
commands other than ``report`` refuse the ones they do not offer.

numpy-free, so the command line can build its options at start-up (docs/fields.md,
"Command line"; docs/config.md; docs/sweeps.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..parameters import RANGES, ROBOT_FAMILIES, describe_parameter

__all__ = [
    "COMMANDS",
    "DEFAULT_LAW",
    "Parameter",
    "PARAMETERS",
    "Setting",
    "Choice",
    "Law",
    "LAWS",
    "LAW_NAMES",
    "MASS",
    "get_law",
    "laws_for",
    "laws_of_family",
    "parameter_keys",
    "choice_keys",
    "takers",
    "either",
    "option_name",
    "refusal",
    "check_parameters",
    "option_help",
    "choice_help",
    "law_help",
    "FORCE_LAWS",
    "FAMILY_LAWS",
    "HOLONOMIC_LAWS",
    "MAP_LAWS",
    "LAW_PARAMETERS",
    "FAMILY_LAW_PARAMETERS",
    "FAMILY_LAW_CHOICES",
    "FAMILY_CHOICE_DEFAULTS",
    "FAMILY_DEFAULTS",
]

COMMANDS = ("report", "map", "sweep", "simulate")
"""Where a law is named besides a configuration file: ``report --law``, ``map --law``, a sweep spec's
``law``, and ``simulate --env analytic --law`` (``validate``: a configuration file's law, by the same rule)."""

DEFAULT_LAW = {"report": "power", "map": "grid", "sweep": "power", "simulate": "power"}
"""Each command's law when none is named: KB's power law, except on a map (its histogram grid's window sum)."""


@dataclass(frozen=True)
class Parameter:
    """A numeric law parameter as the user gives it.

    Attributes
    ----------
    key : str
        The name in files (``goal_distance``) and in `parameters.RANGES`; the option is ``--goal-distance``.
    text : str
        What it is, for help texts (ASCII: symbols spelt out).
    odd : bool
        An odd integer (``window_cells``), else a float.
    """

    key: str
    text: str
    odd: bool = False

    @property
    def option(self) -> str:
        """The command-line option, ``--goal-distance``."""
        return option_name(self.key)

    @property
    def range(self):
        """``parameters.RANGES[key]``: the allowed values and the unit."""
        return RANGES[self.key]


PARAMETERS = {p.key: p for p in (
    Parameter("cell_ratio", "force ratio F_cr/F_ct per cell"),
    Parameter("cell_size", "cell size"),
    Parameter("window_cells", "active window side, odd", odd=True),
    Parameter("xi", "attractive scaling factor xi"),
    Parameter("eta", "repulsive scaling factor eta"),
    Parameter("rho0", "influence distance rho0"),
    Parameter("attraction_exponent", "attraction exponent m: U_att = xi rho_g^m / 2 (GC2000 eq 1), F_a = m alpha_p rho_g^(m-1)"),
    Parameter("goal_exponent", "n of the goal factor rho_g^n of the repulsion (GC2000 eq 8)"),
    Parameter("goal_distance", "the frozen distance to the goal rho_g"),
    Parameter("delta", "surface offset delta of Ge & Cui eq (40)"),
    Parameter("alpha_p", "position gain alpha_p; F_a = m alpha_p rho_g^(m-1)"),
    Parameter("alpha_v", "velocity gain alpha_v of GC2002 eq 1"),
    Parameter("velocity_exponent", "n of alpha_v |de/dt|^n"),
    Parameter("a_max", "braking deceleration a_max of GC2002 eq 11"),
)}
"""Every numeric law parameter, in the order options, inputs and columns list them."""


@dataclass(frozen=True)
class Setting:
    """How one law takes one parameter of `PARAMETERS`.

    Attributes
    ----------
    key : str
        The parameter.
    default : float or None
        Its value when not given; None when the law computes it (``cell_ratio``) or needs it (`required`).
    source : str
        The report's provenance of the default, e.g. ``"default (KB §2)"``; empty when required.
    required : bool
        The law cannot be built without it (the goal distance of Ge & Cui 2000's laws).
    default_text : str
        How help texts state a computed default (``cell_ratio``); empty otherwise.
    """

    key: str
    default: float | None
    source: str = ""
    required: bool = False
    default_text: str = ""

    def shown_default(self) -> str:
        """The default as help texts state it: ``default 0.1``, ``required`` or the computed default's text."""
        if self.required:
            return "required"
        return self.default_text or f"default {self.default:g}"


@dataclass(frozen=True)
class Choice:
    """A choice-valued law parameter (``--variant``, ``--side``, ``--symmetrize``).

    Attributes
    ----------
    key : str
        The name in files; the option is ``--<key>``.
    values : tuple of str
        The allowed values, as the user spells them.
    default : str
    text : str
        What it chooses, for help texts.
    """

    key: str
    values: tuple
    default: str
    text: str

    @property
    def source(self) -> str:
        """The report's provenance of the default, ``default (gradient)``."""
        return f"default ({self.default})"


@dataclass(frozen=True)
class Law:
    """A lateral force law and everything the user may give it.

    Attributes
    ----------
    name : str
        ``--law`` and ``law.name``.
    title : str
        How ``--law``'s help names it.
    kind : {"static", "family"}
        ``static``: a `force_law.ForceLaw` of the distance, built by `fields.make_law` and analysed by every
        steering command; ``family``: a velocity or fuzzy law built by the report (docs/velocity_and_fuzzy.md).
    settings : tuple of Setting
        Its own parameters, in the order its inputs list them.
    choices : tuple of Choice
    controller : tuple of str
        The controller's parameters it reads (``f``, ``n``: KB's laws); typing them for another law is refused.
    families : tuple of str
        The robot families (`parameters.ROBOT_FAMILIES`) that take it.
    commands : tuple of str
        The commands of `COMMANDS` that offer it.
    doc : str
        Its documentation.
    """

    name: str
    title: str
    kind: str
    settings: tuple = ()
    choices: tuple = ()
    controller: tuple = ()
    families: tuple = ("steering", "kinematic")
    commands: tuple = ("report",)
    doc: str = "docs/fields.md"

    @property
    def parameters(self) -> tuple:
        """Its own parameters' keys (`settings`), in order."""
        return tuple(s.key for s in self.settings)

    def takes(self, key: str) -> bool:
        """Whether `key` (a parameter, a choice, ``f`` or ``n``) is one the law takes.

        Parameters
        ----------
        key : str
            A parameter, a choice, ``f`` or ``n``.
        """
        return key in self.parameters or key in self.controller or any(c.key == key for c in self.choices)

    def setting(self, key: str) -> Setting:
        """The `Setting` of parameter `key` (KeyError if the law does not take it).

        Parameters
        ----------
        key : str
            The parameter's key (`PARAMETERS`).
        """
        for setting in self.settings:
            if setting.key == key:
                return setting
        raise KeyError(key)

    def choice(self, key: str) -> Choice:
        """The `Choice` `key` (KeyError if the law has no such choice).

        Parameters
        ----------
        key : str
            The choice's key.
        """
        for choice in self.choices:
            if choice.key == key:
                return choice
        raise KeyError(key)

    def defaults(self) -> dict:
        """Parameter → default, for the parameters that have one."""
        return {s.key: s.default for s in self.settings if s.default is not None}


_GRID = "default (KB §2)"
_GC2000 = "default (Ge & Cui 2000 Sec VI)"
_GC2002 = "default (docs/velocity_and_fuzzy.md)"
_VELOCITY_DOC = "docs/velocity_and_fuzzy.md"


def _gc2000(*keys) -> tuple:
    """Settings of Ge & Cui 2000's laws (Sec VI: xi = 1, eta = 0.1, rho0 = 0.8 m, m = n = 2; delta = 0, eq 8)."""
    table = {
        "xi": Setting("xi", 1.0, _GC2000), "eta": Setting("eta", 0.1, _GC2000), "rho0": Setting("rho0", 0.8, _GC2000),
        "attraction_exponent": Setting("attraction_exponent", 2.0, _GC2000),
        "goal_exponent": Setting("goal_exponent", 2.0, _GC2000),
        "goal_distance": Setting("goal_distance", None, required=True),
        "delta": Setting("delta", 0.0, "default (0: Ge & Cui eq 8)"),
    }
    return tuple(table[k] for k in keys)


def _gc2002(*keys) -> tuple:
    """Settings of the family laws (docs/velocity_and_fuzzy.md): F_a = 1 N (alpha_p = 0.5, m = 2, rho_g = 1 m),
    alpha_v = 0.1 and n = 2 (Ge & Cui 2002 Sec 6), eta and rho0 as GC2000, a_max = 1 m/s^2, no goal factor (n = 0)."""
    table = {"alpha_p": 0.5, "alpha_v": 0.1, "attraction_exponent": 2.0, "velocity_exponent": 2.0, "eta": 0.1, "rho0": 0.8,
             "a_max": 1.0, "goal_distance": 1.0, "goal_exponent": 0.0}
    return tuple(Setting(k, table[k], _GC2002) for k in keys)


LAWS = (
    Law("power", "KB's power law f(W/d)^n", "static", controller=("f", "n"), commands=COMMANDS),
    Law("grid", "the histogram grid's law", "static", controller=("f", "n"), commands=COMMANDS, settings=(
        Setting("cell_ratio", None, "calibrated so that f_av = f (KB §4)", default_text="default: calibrated so that f_av = f, KB §4"),
        Setting("cell_size", 0.1, _GRID), Setting("window_cells", 33, _GRID))),
    Law("khatib", "Khatib's repulsion", "static", commands=("report", "sweep"),
        settings=_gc2000("xi", "eta", "rho0", "attraction_exponent", "goal_distance")),
    Law("gnron", "Ge & Cui's goal-aware repulsion (gnron)", "static", commands=("report", "sweep"),
        settings=_gc2000("xi", "eta", "rho0", "attraction_exponent", "goal_exponent", "goal_distance", "delta")),
    Law("velocity", "Ge & Cui 2002's velocity attraction with Khatib's repulsion", "family", families=ROBOT_FAMILIES, doc=_VELOCITY_DOC,
        settings=_gc2002("alpha_p", "alpha_v", "attraction_exponent", "velocity_exponent", "eta", "rho0", "goal_distance")),
    Law("velocity-gated", "Ge & Cui 2002's velocity-gated repulsion", "family", families=ROBOT_FAMILIES, doc=_VELOCITY_DOC,
        settings=_gc2002("alpha_p", "attraction_exponent", "eta", "rho0", "a_max", "goal_distance"),
        choices=(Choice("variant", ("gradient", "squared", "paper-eq23"), "gradient",
                        "the repulsion's magnitude: gradient eta/D^2 (Ge & Cui 2002 eq 12, 19), squared eta(1/D - 1/rho0)^2, "
                        "or paper-eq23 eta^3(1/D - 1/rho0)^2 (eq 23 as printed)"),)),
    Law("fuzzy", "the DFAPF fuzzy-scheduled repulsion", "family", doc=_VELOCITY_DOC,
        settings=_gc2002("alpha_p", "attraction_exponent", "rho0", "goal_exponent", "goal_distance"),
        choices=(Choice("side", ("left", "right"), "left", "the wall's side (the DFAPF tables are asymmetric)"),
                 Choice("symmetrize", ("none", "negative", "positive"), "none",
                        "make the DFAPF tables left-right symmetric by copying the rows of negative (obstacle on the right) "
                        "or positive bearings onto the others (none: the tables as printed)"))),
)
"""Every law, in the order help texts and messages list them (docs/fields.md, docs/velocity_and_fuzzy.md)."""

LAW_NAMES = tuple(law.name for law in LAWS)
"""The names of `LAWS`: what a configuration file's ``law.name`` may be."""

_BY_NAME = {law.name: law for law in LAWS}

MASS = Setting("mass", 1.0, "default (1 kg)")
"""The holonomic robot's mass (``--mass``, ``robot.mass``, kg): a robot family's parameter, not a law's,
declared beside the laws that put a force on it (``velocity``, ``velocity-gated``)."""


def get_law(name: str) -> Law:
    """The `Law` called `name`; ValueError ``law must be one of power, grid, …; got 'x'`` for another.

    Parameters
    ----------
    name : str
        The law's name.
    """
    if name not in _BY_NAME:
        raise ValueError(f"law must be one of {', '.join(LAW_NAMES)}; got {name!r}")
    return _BY_NAME[name]


def laws_for(command: str) -> tuple:
    """The names of the laws `command` (of `COMMANDS`) offers, its default (`DEFAULT_LAW`) first, then in table order.

    Parameters
    ----------
    command : str
        A command (`COMMANDS`).
    """
    offered = [law.name for law in LAWS if command in law.commands]
    default = DEFAULT_LAW[command]
    return (default, *(name for name in offered if name != default))


def laws_of_family(family: str) -> tuple:
    """The names of the laws a robot family (`parameters.ROBOT_FAMILIES`) takes, in table order.

    Parameters
    ----------
    family : str
        A robot family (`parameters.ROBOT_FAMILIES`).
    """
    return tuple(law.name for law in LAWS if family in law.families)


def parameter_keys(laws=LAW_NAMES) -> tuple:
    """The keys of `PARAMETERS` that any of `laws` (names) takes, in `PARAMETERS` order.

    Parameters
    ----------
    laws : tuple of str, optional
        The laws' names considered; default all (`LAW_NAMES`).
    """
    entries = [_BY_NAME[name] for name in laws]
    return tuple(key for key in PARAMETERS if any(key in law.parameters for law in entries))


def choice_keys(laws=LAW_NAMES) -> tuple:
    """The choices any of `laws` (names) has, in table order.

    Parameters
    ----------
    laws : tuple of str, optional
        The laws' names considered; default all (`LAW_NAMES`).
    """
    return tuple(dict.fromkeys(c.key for name in laws for c in _BY_NAME[name].choices))


def takers(key: str, laws=LAW_NAMES) -> tuple:
    """The names of `laws` that take `key` (a parameter, a choice, ``f`` or ``n``), in table order.

    Parameters
    ----------
    key : str
        A parameter, a choice, ``f`` or ``n``.
    laws : tuple of str, optional
        The laws' names considered; default all (`LAW_NAMES`).
    """
    return tuple(name for name in LAW_NAMES if name in laws and _BY_NAME[name].takes(key))


def either(names) -> str:
    """``a``, ``a or b``, ``a, b or c``.

    Parameters
    ----------
    names : sequence of str
        The names joined.
    """
    names = list(names)
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"


def option_name(key: str) -> str:
    """The command-line option of a parameter: ``goal_distance`` → ``--goal-distance``.

    Parameters
    ----------
    key : str
        The parameter's key.
    """
    return "--" + key.replace("_", "-")


def refusal(key: str, law_shown: str, *, shown: str | None = None, laws=LAW_NAMES) -> ValueError:
    """The one message for a parameter given to a law that does not take it.

    ``<shown> applies to <the laws of `laws` that take it>, not to <law_shown>`` (a name no law takes:
    ``<shown> is not a parameter of any law …, given to <law_shown>``). On the command line
    (`shown` an option) the laws are named as options: ``--xi applies to --law khatib or gnron, not to
    --law power``; in files and the library by name: ``law.xi applies to khatib or gnron, not to law power``.

    Parameters
    ----------
    key : str
        The parameter, choice, ``f`` or ``n``.
    law_shown : str
        The law in force as the user named it: ``--law power``, ``law power``, ``law khatib of --config FILE``.
    shown : str, optional
        The parameter as the user gave it (``--xi``, ``law.xi``); default `key`.
    laws : tuple of str
        The laws the context offers (a command's, or all).

    Returns
    -------
    ValueError
        To be raised by the caller.
    """
    shown = shown or key
    laws_taking = takers(key, laws) or takers(key)
    if not laws_taking:  # a name no law declares: a typo, not a parameter of another law
        return ValueError(f"{shown} is not a parameter of any law (see the laws in docs/fields.md and docs/velocity_and_fuzzy.md), "
                          f"given to {law_shown}")
    return ValueError(f"{shown} applies to {'--law ' if shown.startswith('--') else ''}{either(laws_taking)}, not to {law_shown}")


def check_parameters(name: str, given, *, shown=None, law_shown: str | None = None, laws=LAW_NAMES, required: bool = True) -> Law:
    """The `Law` `name` after checking it takes every key of `given` (and, if `required`, gets the parameters it requires).

    Parameters
    ----------
    name : str
        The law (`LAW_NAMES`).
    given : iterable of str
        The keys given (parameters, choices, ``f``, ``n``).
    shown : callable, optional
        How the context names a key (``option_name`` on the command line, ``law.<key>`` in a file); default the key.
    law_shown : str, optional
        How the context names the law; default ``law <name>``.
    laws : tuple of str
        The laws the context offers, named by a refusal.
    required : bool
        Whether `given` must hold the law's required parameters (False: more may come from elsewhere).

    Raises
    ------
    ValueError
        An unknown law; a key the law does not take (`refusal`); a required parameter missing
        (``--law khatib needs --goal-distance: the frozen distance to the goal rho_g, [0.001, 10000] m (docs/fields.md)``).
    """
    law = get_law(name)
    shown = shown or (lambda key: key)
    law_shown = law_shown or f"law {name}"
    given = list(given)
    for key in given:
        if not law.takes(key):
            raise refusal(key, law_shown, shown=shown(key), laws=laws)
    for setting in law.settings if required else ():
        if setting.required and setting.key not in given:
            p = PARAMETERS[setting.key]
            raise ValueError(f"{law_shown} needs {shown(setting.key)}: {p.text}, {p.range.describe()} ({law.doc})")
    return law


def _names_for_help(names) -> str:
    return "/".join(names)


def option_help(key: str, laws=LAW_NAMES) -> str:
    """The help of a parameter's option among `laws`: who takes it, what it is, the defaults and the range.

    E.g. ``khatib/gnron: repulsive scaling factor eta (default 0.1), [1e-06, 1e+06]``; defaults that differ
    between the laws are given per law (``required for khatib, gnron; default 1 for velocity, …``).

    Parameters
    ----------
    key : str
        The parameter's key (`PARAMETERS`).
    laws : tuple of str, optional
        The laws' names considered; default all (`LAW_NAMES`).
    """
    p = PARAMETERS[key]
    names = takers(key, laws)
    groups = {}
    for name in names:
        groups.setdefault(_BY_NAME[name].setting(key).shown_default(), []).append(name)
    if len(groups) == 1:
        defaults = next(iter(groups))
    else:
        parts, after_default = [], False
        for text, group in groups.items():
            numeric = text.startswith("default ")
            parts.append(f"{text[len('default '):] if numeric and after_default else text} for {', '.join(group)}")
            after_default = numeric
        defaults = "; ".join(parts)
    return f"{_names_for_help(names)}: {p.text} ({defaults}), {describe_parameter(key)}"


def choice_help(key: str, laws=LAW_NAMES) -> str:
    """The help of a choice's option: who takes it, what it chooses, its default.

    Parameters
    ----------
    key : str
        The choice's key.
    laws : tuple of str, optional
        The laws' names considered; default all (`LAW_NAMES`).
    """
    names = takers(key, laws)
    choice = _BY_NAME[names[0]].choice(key)
    return f"{_names_for_help(names)}: {choice.text} (default {choice.default})"


def law_help(laws, default: str) -> tuple:
    """(group title, ``--law`` help) for a command offering `laws` with `default`.

    The laws documented where the default is are named by their titles, the others by name with their documentation:
    ``lateral force law: KB's power law f(W/d)^n (default, …), … or …; velocity, velocity-gated, fuzzy: docs/velocity_and_fuzzy.md``.

    Parameters
    ----------
    laws : tuple of str
        The laws' names the command offers.
    default : str
        The command's default law.
    """
    main = _BY_NAME[default].doc
    here = [law for law in LAWS if law.name in laws and law.doc == main]
    named = [law.title + (" (default, unless the configuration file names one)" if law.name == default else "") for law in here]
    elsewhere = {}
    for law in LAWS:
        if law.name in laws and law.doc != main:
            elsewhere.setdefault(law.doc, []).append(law.name)
    extra = "".join(f"; {', '.join(names)}: {doc}" for doc, names in elsewhere.items())
    return f"force law ({main})", f"lateral force law: {either(named)}{extra}"


# ------------------------------------------------------------------ views of the table
# For the report's modules, which name the laws by kind; computed from `LAWS`, never edited.
FORCE_LAWS = tuple(law.name for law in LAWS if law.kind == "static")
"""The static laws (`fields.make_law`): power, grid, khatib, gnron."""

FAMILY_LAWS = tuple(law.name for law in LAWS if law.kind == "family")
"""The laws the report builds (`report.families.make_family_law`): velocity, velocity-gated, fuzzy."""

HOLONOMIC_LAWS = laws_of_family("holonomic")
"""The laws a holonomic robot takes: forces in newtons on a mass (Ge & Cui 2002 §6)."""

MAP_LAWS = laws_for("map")
"""The laws ``pfm-stability map`` takes, its default (grid) first."""

LAW_PARAMETERS = {law.name: (*law.controller, *law.parameters) for law in LAWS if law.kind == "static"}
"""Static law → the parameters it takes, ``f`` and ``n`` (the controller's) first."""

FAMILY_LAW_PARAMETERS = {law.name: law.parameters for law in LAWS if law.kind == "family"}
"""Family law → its parameters."""

FAMILY_LAW_CHOICES = {law.name: {c.key: c.values for c in law.choices} for law in LAWS if law.kind == "family"}
"""Family law → its choices and their values."""

FAMILY_CHOICE_DEFAULTS = {c.key: c.default for law in LAWS for c in law.choices}
"""Choice → its default."""

FAMILY_DEFAULTS = {**{s.key: s.default for law in LAWS if law.kind == "family" for s in law.settings}, MASS.key: MASS.default}
"""Parameter of the family laws (and the holonomic robot's mass) → its default (one per key: `tests/test_law_registry.py`)."""
