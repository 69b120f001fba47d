"""Configuration files: a robot, its controller, a force law and a scenario in one YAML file.

``--config FILE`` on every command reads such a file (docs/config.md)::

    preset: carmel            # the base; default carmel
    robot: {V: 0.8, tau: 0.2, k: 2.0, W: 0.6}  # report also: family, mass
    controller: {T: 0.1, f: 1.0, n: 2, hold: command, compute_delay: 1}
    law: {name: grid, cell_size: 0.1, window_cells: 33}   # report also: velocity, velocity-gated, fuzzy
    scenario: {wall: {alpha: 20}, corridor: {L: 0.9}}
    assumed: {k: "why this value is an assumption"}

``robot.family`` and ``robot.mass`` (`parameters.ROBOT_FAMILIES`) and the laws of
`parameters.FAMILY_LAWS` (their parameters `parameters.FAMILY_LAW_PARAMETERS` and their
choices `parameters.FAMILY_LAW_CHOICES`: ``variant``, ``side``, ``symmetrize``) are read by
``report`` only (``--robot``, ``--mass``, ``--law velocity`` …, docs/velocity_and_fuzzy.md);
the braking deceleration ``a_max`` is a parameter of the law ``velocity-gated``, as ``--a-max`` is.

Keys are the command-line option names with underscores (``compute_delay``,
``cell_size``); units are SI, angles (α) in degrees and the steering rate in
deg/s, as on the command line. Every value is checked against
`parameters.RANGES` with the command line's message, prefixed by the file and
the key: ``config robot.yaml: robot.V must be a finite number in (0, 100] m/s;
got -1``. A Nav2 parameters file (top-level node names with ``ros__parameters``)
is recognized and read by `pfm_stability.io.nav2`.

The shipped presets (``data/presets/*.yaml``, `parameters.PRESETS`) are files of
this format. This module imports no numpy.
"""

from __future__ import annotations

import difflib
import functools
import math
import re
from dataclasses import dataclass, field, fields
from pathlib import Path

from ..checks import check_choice, check_integer, check_number
from .nav2 import is_nav2, read_nav2
from ..parameters import FAMILY_LAW_CHOICES, FAMILY_LAW_PARAMETERS, FAMILY_LAWS, FORCE_LAWS, HOLDS, HOLONOMIC_LAWS, LAW_PARAMETERS, RANGES, ROBOT_FAMILIES, Controller, Preset, Robot, get_preset

__all__ = [
    "Config",
    "load_config",
    "config_from_mapping",
    "read_yaml",
    "TOP_KEYS",
    "ROBOT_KEYS",
    "FAMILY_ROBOT_KEYS",
    "CONTROLLER_KEYS",
    "LAW_KEYS",
    "SIDES",
    "SCENARIO_KEYS",
    "DEFAULT_PRESET",
]

DEFAULT_PRESET = "carmel"
"""The base of a file without a ``preset`` key."""

ROBOT_KEYS = ("V", "tau", "k", "W", "max_steering_rate")
"""Keys of ``robot:`` (`parameters.Robot`; ``max_steering_rate`` in deg/s)."""

FAMILY_ROBOT_KEYS = ("family", "mass")
"""Keys of ``robot:`` beyond `ROBOT_KEYS`, read by ``report`` only: the loop family
(`parameters.ROBOT_FAMILIES`, ``--robot``) and the holonomic robot's mass in kg (``--mass``)."""

SIDES = FAMILY_LAW_CHOICES["fuzzy"]["side"]
"""Values of ``law.side`` (the fuzzy law's wall side, ``--side``)."""

_ALL_LAWS = FORCE_LAWS + FAMILY_LAWS
_ALL_LAW_PARAMETERS = {**LAW_PARAMETERS, **{name: (*keys, *FAMILY_LAW_CHOICES[name]) for name, keys in FAMILY_LAW_PARAMETERS.items()}}

CONTROLLER_KEYS = ("T", "f", "n", "hold", "compute_delay")
"""Keys of ``controller:`` (`parameters.Controller`)."""

LAW_KEYS = ("name",) + tuple(dict.fromkeys(k for names in _ALL_LAW_PARAMETERS.values() for k in names if k not in ("f", "n")))
"""Keys of ``law:``: the law's name (`parameters.FORCE_LAWS`, `parameters.FAMILY_LAWS`) and the parameters of
`parameters.LAW_PARAMETERS` beyond f and n (those are the controller's), of `parameters.FAMILY_LAW_PARAMETERS`
and of `parameters.FAMILY_LAW_CHOICES` (``variant``; ``side``, ``symmetrize``)."""

SCENARIO_KEYS = {"wall": ("alpha",), "corridor": ("L",)}
"""Keys of ``scenario:``: ``wall: {alpha: deg}`` fills ``--alpha``, ``corridor: {L: m}`` fills ``--L``."""

TOP_KEYS = ("preset", "name", "source", "robot", "controller", "law", "scenario", "assumed")
"""Top-level keys of a configuration file (docs/config.md)."""

PARAMETER_KEYS = ("V", "tau", "k", "W", "f", "n", "T", "hold", "compute_delay")
"""The parameters whose provenance `Config.sources` records (as the command line's `resolve_parameters`)."""

_STEERING_RATE_DEG = (0.0, math.inf)  # deg/s, open at both ends: RANGES["max_steering_rate"] in degrees


@dataclass(frozen=True)
class Config:
    """A configuration file, resolved over its base preset.

    Attributes
    ----------
    robot : Robot
        The file's robot values over the base preset's.
    controller : Controller
        The file's controller values over the base preset's.
    law : dict or None
        ``{"name": …, <law parameter>: value, …}`` (degrees nowhere: lengths in m),
        or None if the file has no ``law``.
    scenario : dict
        E.g. ``{"wall": {"alpha": 20.0}, "corridor": {"L": 0.9}}`` (α in degrees); empty if none.
    sources : dict[str, str]
        Parameter → provenance: ``"config FILE"``, ``"ASSUMED (config FILE): why"``,
        ``"preset carmel"``, ``"ASSUMED (preset carmel): why"``, ``"Nav2 FILE: key = value unit"``;
        for every robot and controller parameter, and for each law and scenario value
        the file gives (``alpha_deg``, ``L``, as the report names them).
    path : str or None
        The file as given (None for a mapping without a file).
    preset : Preset
        The same robot and controller as a `Preset` named after the origin, with the
        base's grid (its cell size and window, or the file's grid law's) and the
        assumptions in force: what commands that take a preset use.
    notes : tuple of str
        What the file did not give that one might expect (Nav2 keys not found); not errors.
    family : str or None
        ``robot.family`` (`parameters.ROBOT_FAMILIES`), None if the file gives none; its source is
        ``sources["robot"]`` (as the report names it).
    mass : float or None
        ``robot.mass``, kg (only with ``family: holonomic``), None if the file gives none.
    """

    robot: Robot
    controller: Controller
    law: dict | None
    scenario: dict
    sources: dict
    path: str | None
    preset: Preset
    notes: tuple = field(default=())
    family: str | None = None
    mass: float | None = None


def load_config(path, *, preset: str | None = None) -> Config:
    """Read the configuration file `path` (docs/config.md), or a Nav2 parameters file.

    Parameters
    ----------
    path : str or os.PathLike
        The YAML file.
    preset : str, optional
        A base preset that overrides the file's ``preset`` key (the command
        line's ``--preset`` beats the file).

    Returns
    -------
    Config

    Raises
    ------
    ValueError
        One line naming the file and the key: a missing or unreadable file,
        invalid YAML, a key that is not an option (with the allowed ones), a
        section that is not a mapping, a value of the wrong type or out of range.
    """
    origin = f"config {path}"
    data = read_yaml(path, origin)
    if is_nav2(data):
        return _from_nav2(data, f"Nav2 {path}", str(path), preset)
    return config_from_mapping(data, origin, path=str(path), preset=preset)


def read_yaml(path, origin: str):
    """The YAML document in `path`; ValueError ``"<origin>: …"`` if it cannot be read or parsed.

    A key given twice in one mapping is an error (plain YAML keeps the last
    silently), and ``1e-3`` is a number (YAML 1.1 reads it as text without a dot).
    """
    import yaml

    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, ValueError) as exc:  # missing, a directory, not UTF-8, a NUL in the path
        reason = getattr(exc, "strerror", None) or str(exc)
        raise ValueError(f"{origin}: cannot read the file ({reason})") from None
    try:
        return yaml.load(text, Loader=_loader())  # noqa: S506 - a SafeLoader subclass
    except _DuplicateKey as exc:
        raise ValueError(f"{origin}: {exc}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ValueError(f"{origin}: not valid YAML: {problem}{where}") from None


class _DuplicateKey(Exception):
    """A key given twice in one YAML mapping."""


@functools.cache
def _loader():
    """yaml.SafeLoader that rejects duplicate keys and reads ``1e-3`` as a float (built once, on first use)."""
    import yaml

    class Loader(yaml.SafeLoader):
        pass

    def mapping(loader, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = loader.construct_object(key_node, deep=deep)
            if key in seen:
                raise _DuplicateKey(f"{key} is given twice (line {key_node.start_mark.line + 1})")
            seen.add(key)
        return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)

    Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, mapping)
    Loader.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(r"^[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)[eE][-+]?[0-9]+$"), list("-+0123456789."))
    return Loader


def config_from_mapping(data, origin: str, *, path: str | None = None, preset: str | None = None) -> Config:
    """A `Config` from the mapping `data` of a configuration file (or embedded in another file).

    Parameters
    ----------
    data : dict or None
        The file's content (None, an empty file, takes everything from the preset).
    origin : str
        How errors and sources name it, e.g. ``"config robot.yaml"`` or ``"sweep spec.yaml: config"``.
    path : str, optional
        The file, if any (`Config.path`).
    preset : str, optional
        A base preset that overrides ``data["preset"]``.

    Raises
    ------
    ValueError
        ``"<origin>: <key> …"``: see `load_config`.
    """
    data = {} if data is None else data
    _check_keys(origin, "the file", data, TOP_KEYS, top=True)
    base = _base(origin, data, preset)
    for key in ("name", "source"):
        if key in data and not isinstance(data[key], str):
            raise ValueError(f"{origin}: {key} must be a text; got {data[key]!r}")
    robot_values = _section(origin, data, "robot", ROBOT_KEYS + FAMILY_ROBOT_KEYS, _robot_value)
    family_values = {key: robot_values.pop(key) for key in FAMILY_ROBOT_KEYS if key in robot_values}
    controller_values = _section(origin, data, "controller", CONTROLLER_KEYS, _controller_value)
    law = _law(origin, data.get("law")) if "law" in data else None
    _check_family(origin, family_values, law)
    scenario = _scenario(origin, data.get("scenario")) if "scenario" in data else {}
    notes = _assumed(origin, data.get("assumed")) if "assumed" in data else {}
    robot = _build(origin, Robot, base.robot, robot_values)
    controller = _build(origin, Controller, base.controller, controller_values)
    given = {**robot_values, **controller_values}
    sources = {}
    for name in PARAMETER_KEYS:
        if name in notes:
            sources[name] = f"ASSUMED ({origin}): {notes[name]}"
        elif name in given:
            sources[name] = origin
        elif name in base.assumed:
            sources[name] = f"ASSUMED (preset {base.name}): {base.assumed[name]}"
        else:
            sources[name] = f"preset {base.name}"
    sources.update({name: origin for name in (law or {}) if name != "name"})
    sources.update({("robot" if name == "family" else name): origin for name in family_values})
    sources.update({("alpha_deg" if name == "alpha" else name): origin for values in scenario.values() for name in values})
    assumed = {name: notes.get(name, base.assumed.get(name)) for name in PARAMETER_KEYS if sources[name].startswith("ASSUMED")}
    grid = {k: law[k] for k in ("cell_size", "window_cells") if law and k in law}
    merged = Preset(
        name=data.get("name", origin), robot=robot, controller=controller, assumed=assumed,
        source=data.get("source", base.source if not given else f"{origin} over preset {base.name}"),
        cell_size=grid.get("cell_size", base.cell_size), window_cells=grid.get("window_cells", base.window_cells),
    )
    return Config(robot, controller, law, scenario, sources, path, merged, family=family_values.get("family"), mass=family_values.get("mass"))


# ------------------------------------------------------------------ sections
def _base(origin, data, preset) -> Preset:
    name = preset if preset is not None else data.get("preset", DEFAULT_PRESET)
    try:
        return get_preset(name)
    except ValueError as exc:
        raise ValueError(f"{origin}: {exc}") from None


def _section(origin, data, section, keys, check) -> dict:
    """The checked values of ``data[section]`` (empty if absent)."""
    if section not in data:
        return {}
    values = data[section]
    _check_keys(origin, section, values, keys, shown=_SHOWN_KEYS.get(section))
    return {key: check(origin, f"{section}.{key}", key, value) for key, value in values.items()}


def _robot_value(origin, shown, key, value):
    if key == "family":
        return _in_range(origin, lambda: check_choice(shown, value, ROBOT_FAMILIES))
    if key == "max_steering_rate":  # deg/s in the file
        low, high = _STEERING_RATE_DEG
        return math.radians(_in_range(origin, lambda: check_number(shown, value, low, high, unit="deg/s")))
    return _number(origin, shown, key, value)


def _controller_value(origin, shown, key, value):
    if key == "hold":
        return _in_range(origin, lambda: check_choice(shown, value, HOLDS))
    if key == "compute_delay":
        r = RANGES["compute_delay"]
        return _in_range(origin, lambda: check_integer(shown, value, int(r.low), int(r.high)))
    return _number(origin, shown, key, value)


def _law(origin, values) -> dict:
    _check_keys(origin, "law", values, LAW_KEYS)
    name = values.get("name", "power")
    if name not in FAMILY_LAWS:  # the static laws' message, then the report's laws
        also = f" (report also takes {_either(FAMILY_LAWS)}: docs/velocity_and_fuzzy.md)"
        _in_range(origin, lambda: check_choice("law.name", name, FORCE_LAWS), None, also)
    law = {"name": name}
    for key, value in values.items():
        if key == "name":
            continue
        if key not in _ALL_LAW_PARAMETERS[name]:
            takers = _either([k for k in _ALL_LAWS if key in _ALL_LAW_PARAMETERS[k]])
            raise ValueError(f"{origin}: law.{key} applies to {takers}, not to law {name}")
        if key in FAMILY_LAW_CHOICES.get(name, {}):
            law[key] = _in_range(origin, lambda: check_choice(f"law.{key}", value, FAMILY_LAW_CHOICES[name][key]))
        elif key == "window_cells":
            r = RANGES[key]
            message = f"{origin}: law.window_cells must be an odd integer in [{int(r.low)}, {int(r.high)}]; got {value!r}"
            checked = _in_range(origin, lambda: check_integer("law.window_cells", value, int(r.low), int(r.high)), message)
            if checked % 2 == 0:
                raise ValueError(message)
            law[key] = checked
        else:
            law[key] = _number(origin, f"law.{key}", key, value)
    return law


def _check_family(origin, family_values, law) -> None:
    """The file's robot family agrees with its mass and law (as ``--robot``, ``--mass`` and ``--law`` must)."""
    family = family_values.get("family", "steering")
    if "mass" in family_values and family != "holonomic":
        raise ValueError(f"{origin}: robot.mass applies to robot family holonomic (robot.family: holonomic), not to family {family}")
    if family == "holonomic" and law is not None and law["name"] not in HOLONOMIC_LAWS:
        raise ValueError(f"{origin}: robot.family holonomic takes law velocity or velocity-gated "
                         f"(a force in newtons on a mass, Ge & Cui 2002 Sec 6); got law {law['name']}")


def _either(names) -> str:
    """``a``, ``a or b``, ``a, b or c``."""
    names = list(names)
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"


def _scenario(origin, values) -> dict:
    _check_keys(origin, "scenario", values, tuple(SCENARIO_KEYS))
    out = {}
    for geometry, entries in values.items():
        _check_keys(origin, f"scenario.{geometry}", entries, SCENARIO_KEYS[geometry])
        keys = {"alpha": "alpha_deg"}
        out[geometry] = {key: _number(origin, f"scenario.{geometry}.{key}", keys.get(key, key), value) for key, value in entries.items()}
    return out


def _assumed(origin, values) -> dict:
    _check_keys(origin, "assumed", values, PARAMETER_KEYS)
    for key, why in values.items():
        if not isinstance(why, str) or not why.strip():
            raise ValueError(f"{origin}: assumed.{key} must be a text saying why the value is assumed; got {why!r}")
    return {key: " ".join(why.split()) for key, why in values.items()}


def _build(origin, cls, base, values):
    """``cls`` with the base's fields and the file's values (checked again by the dataclass)."""
    try:
        return cls(**{**{f.name: getattr(base, f.name) for f in fields(base)}, **values})
    except ValueError as exc:
        raise ValueError(f"{origin}: {exc}") from None


# ------------------------------------------------------------------ checks
def _number(origin, shown, key, value) -> float:
    """`value` in ``RANGES[key]``, with the command line's message for `shown` (``robot.V``)."""
    r = RANGES[key]
    return _in_range(origin, lambda: check_number(shown, value, r.low, r.high, low_open=r.low_open, high_open=r.high_open, unit=r.unit))


def _in_range(origin, check, message=None, suffix=""):
    try:
        return check()
    except ValueError as exc:
        raise ValueError(message or f"{origin}: {exc}{suffix}") from None


_SHOWN_KEYS = {"robot": ROBOT_KEYS}
"""Keys a section's "must be a mapping" message lists when it takes more (``robot``: the family keys are report's)."""

_SECTION_KEYS = {"robot": ROBOT_KEYS + FAMILY_ROBOT_KEYS, "controller": CONTROLLER_KEYS, "law": LAW_KEYS}


def _check_keys(origin, section, values, allowed, top=False, shown=None) -> None:
    """ValueError unless `values` is a mapping whose keys are all in `allowed` ("did you mean" for near misses
    and for a key of another section, ``robot.a_max`` → ``law.a_max``); `shown` the keys a shape error lists."""
    if not isinstance(values, dict):
        what = "the file" if top else section
        got = type(values).__name__ if top else repr(values)
        raise ValueError(f"{origin}: {what} must be a mapping of key: value with keys {', '.join(shown or allowed)}; got {got}")
    for key in values:
        if key not in allowed:
            label = str(key) if top else f"{section}.{key}"
            elsewhere = [other for other, keys in _SECTION_KEYS.items() if other != section and key in keys and section in _SECTION_KEYS]
            hint = f" (did you mean {elsewhere[0]}.{key}?)" if elsewhere else _did_you_mean(key, allowed)
            taken = "the file takes" if top else f"{section} takes"
            raise ValueError(f"{origin}: {label} is not a key{hint}; {taken} {', '.join(allowed)}")


def _did_you_mean(key, allowed) -> str:
    text = str(key)
    folded = {a.lower().replace("-", "_"): a for a in allowed}
    exact = folded.get(text.lower().replace("-", "_"))
    match = [exact] if exact else difflib.get_close_matches(text, allowed, n=1, cutoff=0.6)
    return f" (did you mean {match[0]}?)" if match else ""


# ------------------------------------------------------------------ Nav2
NAV2_ASSUMED = {
    "tau": "a Nav2 file does not give the steering lag; this is the preset's robot's (measure yours: docs/config.md)",
    "f": "a Nav2 file has no VFF force ratio; this is the preset's",
    "n": "a Nav2 file has no repulsion exponent; this is the preset's",
}
"""Why a loop parameter a Nav2 file cannot give is an assumption (marked ASSUMED in the report)."""

def _from_nav2(data, origin, path, preset) -> Config:
    """A `Config` from a Nav2 parameters file: T, V and W where found, everything else from the preset."""
    base = _base(origin, {}, preset)
    found = read_nav2(data, origin)
    robot = _build(origin, Robot, base.robot, {k: v.value for k, v in found.values.items() if k in ROBOT_KEYS})
    controller = _build(origin, Controller, base.controller, {k: v.value for k, v in found.values.items() if k in CONTROLLER_KEYS})
    sources, assumed = {}, {}
    for name in PARAMETER_KEYS:
        if name in found.values:
            sources[name] = f"{origin}: {found.values[name].describe()}"
            continue
        assumed[name] = base.assumed.get(name) or NAV2_ASSUMED.get(name, f"not found in the Nav2 file: the preset {base.name}'s value")
        sources[name] = f"ASSUMED (preset {base.name}): {assumed[name]}"
    merged = Preset(
        name=origin, robot=robot, controller=controller, assumed=assumed,
        source=f"{origin} over preset {base.name}", cell_size=base.cell_size, window_cells=base.window_cells,
    )
    return Config(robot, controller, None, {}, sources, path, merged, notes=found.notes)
