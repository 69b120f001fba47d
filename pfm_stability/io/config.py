"""Configuration files: a robot, its controller, a force law and a scenario in one YAML file.

``--config FILE`` on every command reads such a file (docs/config.md)::

    preset: carmel            # the base; default carmel
    robot: {V: 0.8, tau: 0.2, k: 2.0, W: 0.6, dead_time: 0.07, plant_gain: 0.85}  # report also: family, mass
    controller: {T: 0.1, f: 1.0, n: 2, hold: command, compute_delay: 1}
    law: {name: grid, cell_size: 0.1, window_cells: 33}   # or law: grid; report also: velocity, velocity-gated, fuzzy
    scenario: {wall: {alpha: 20}, corridor: {L: 0.9}}
    assumed: {k: "why this value is an assumption"}

``law`` is checked against the law registry (`pfm_stability.laws.registry`): its name, the
parameters and choices (``variant``, ``side``, ``symmetrize``) that law takes; a bare name
(``law: grid``) is short for ``law: {name: grid}``. ``robot.family`` and ``robot.mass``
(`parameters.ROBOT_FAMILIES`) and the laws the report builds (velocity, velocity-gated,
fuzzy) are read by ``report`` only (``--robot``, ``--mass``, ``--law velocity`` …,
docs/velocity_and_fuzzy.md); the braking deceleration ``a_max`` is a parameter of the law
``velocity-gated``, as ``--a-max`` is.

Keys are the command-line option names with underscores (``compute_delay``,
``cell_size``); units are SI, angles (α) in degrees and the steering rate in
deg/s, as on the command line. The file is read by the one YAML reader
(`pfm_stability.io.yaml_files`: ``1e-3`` is a number, a key given twice an error), and
every value is checked against `parameters.RANGES` with the command line's message,
prefixed by the file, the line and the key: ``config robot.yaml, line 2: robot.V must
be a finite number in (0, 100] m/s; got -1``. A Nav2 parameters file (top-level node
names with ``ros__parameters``) is recognized and read by `pfm_stability.io.nav2`.

The shipped presets (``data/presets/*.yaml``, `parameters.PRESETS`) are files of
this format. This module imports no numpy.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, fields, replace

from ..checks import check_choice, check_integer, check_number
from ..laws.registry import FAMILY_LAWS, FORCE_LAWS, LAW_NAMES, choice_keys, either, get_law, laws_of_family, parameter_keys, refusal
from ..parameters import HOLDS, RANGES, ROBOT_FAMILIES, Controller, Preset, Robot, get_preset
from .nav2 import is_nav2, read_nav2
from .yaml_files import YamlFile, mapping_source, read_yaml

__all__ = [
    "Config",
    "load_config",
    "config_from_mapping",
    "TOP_KEYS",
    "ROBOT_KEYS",
    "FAMILY_ROBOT_KEYS",
    "CONTROLLER_KEYS",
    "LAW_KEYS",
    "SCENARIO_KEYS",
    "DEFAULT_PRESET",
]

DEFAULT_PRESET = "carmel"
"""The base of a file without a ``preset`` key."""

ROBOT_KEYS = ("V", "tau", "k", "W", "max_steering_rate", "dead_time", "plant_gain", "actuator_lag", "yaw_accel_limit", "slip_lag")
"""Keys of ``robot:`` (`parameters.Robot`; ``max_steering_rate`` in deg/s, ``dead_time``, ``actuator_lag`` and ``slip_lag`` in s,
``plant_gain`` dimensionless, ``yaw_accel_limit`` in rad/s²: what ``pfm-stability identify --out`` writes)."""

FAMILY_ROBOT_KEYS = ("family", "mass")
"""Keys of ``robot:`` beyond `ROBOT_KEYS`, read by ``report`` only: the loop family
(`parameters.ROBOT_FAMILIES`, ``--robot``) and the holonomic robot's mass in kg (``--mass``)."""

CONTROLLER_KEYS = ("T", "f", "n", "hold", "compute_delay")
"""Keys of ``controller:`` (`parameters.Controller`)."""

LAW_KEYS = ("name", *parameter_keys(), *choice_keys())
"""Keys of ``law:``: the law's name (`laws.registry.LAW_NAMES`) and every law's parameters and choices
(`laws.registry.LAWS`; f and n are the controller's). ``law: grid`` is short for ``law: {name: grid}``."""

SCENARIO_KEYS = {"wall": ("alpha",), "corridor": ("L",)}
"""Keys of ``scenario:``: ``wall: {alpha: deg}`` fills ``--alpha``, ``corridor: {L: m}`` fills ``--L``."""

TOP_KEYS = ("preset", "name", "source", "robot", "controller", "law", "scenario", "assumed")
"""Top-level keys of a configuration file (docs/config.md)."""

PARAMETER_KEYS = ("V", "tau", "k", "W", "dead_time", "plant_gain", "actuator_lag", "yaw_accel_limit", "slip_lag", "f", "n", "T", "hold",
                  "compute_delay")
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
        One line naming the file, the line and the key (`io.yaml_files.InputError`): a missing or
        unreadable file, invalid YAML, a key given twice, a key that is not an option (with the allowed
        ones), a section that is not a mapping, a value of the wrong type or out of range.
    """
    document = read_yaml(path, "config")
    if is_nav2(document.data):
        return _from_nav2(replace(document, origin=f"Nav2 {path}"), str(path), preset)
    return _config(document, str(path), preset)


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
    return _config(mapping_source(data, origin), path, preset)


def _config(src: YamlFile, path: str | None, preset: str | None) -> Config:
    """The `Config` of a document (a file with its lines, or a mapping)."""
    origin = src.origin
    data = {} if src.data is None else src.data
    _check_keys(src, "the file", data, TOP_KEYS, top=True)
    base = _base(src, data, preset)
    for key in ("name", "source"):
        if key in data and not isinstance(data[key], str):
            raise src.error(f"{key} must be a text; got {data[key]!r}", key)
    robot_values = _section(src, data, "robot", ROBOT_KEYS + FAMILY_ROBOT_KEYS, _robot_value)
    family_values = {key: robot_values.pop(key) for key in FAMILY_ROBOT_KEYS if key in robot_values}
    controller_values = _section(src, data, "controller", CONTROLLER_KEYS, _controller_value)
    law = _law(src, data.get("law")) if "law" in data else None
    _check_family(src, family_values, law)
    scenario = _scenario(src, data.get("scenario")) if "scenario" in data else {}
    notes = _assumed(src, data.get("assumed")) if "assumed" in data else {}
    robot = _build(src, "robot", Robot, base.robot, robot_values)
    controller = _build(src, "controller", Controller, base.controller, controller_values)
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
def _base(src: YamlFile, data, preset) -> Preset:
    name = preset if preset is not None else data.get("preset", DEFAULT_PRESET)
    try:
        return get_preset(name)
    except ValueError as exc:
        raise src.error(str(exc), "preset") from None


def _section(src: YamlFile, data, section, keys, check) -> dict:
    """The checked values of ``data[section]`` (empty if absent)."""
    if section not in data:
        return {}
    values = data[section]
    _check_keys(src, section, values, keys, shown=_SHOWN_KEYS.get(section))
    return {key: check(src, f"{section}.{key}", key, value) for key, value in values.items()}


def _robot_value(src: YamlFile, shown, key, value):
    if key == "family":
        return _checked(src, shown, lambda: check_choice(shown, value, ROBOT_FAMILIES))
    if key == "max_steering_rate":  # deg/s in the file
        low, high = _STEERING_RATE_DEG
        return math.radians(_checked(src, shown, lambda: check_number(shown, value, low, high, unit="deg/s")))
    return _number(src, shown, key, value)


def _controller_value(src: YamlFile, shown, key, value):
    if key == "hold":
        return _checked(src, shown, lambda: check_choice(shown, value, HOLDS))
    if key == "compute_delay":
        r = RANGES["compute_delay"]
        return _checked(src, shown, lambda: check_integer(shown, value, int(r.low), int(r.high)))
    return _number(src, shown, key, value)


def _law(src: YamlFile, values) -> dict:
    """``law:`` checked against the registry: a law's name alone (``law: grid``) or a mapping with its parameters and choices."""
    if isinstance(values, str):
        values = {"name": values}
    _check_keys(src, "law", values, LAW_KEYS, must="a law's name or a mapping")
    name = values.get("name", "power")
    if name not in LAW_NAMES:  # the static laws' message, then the report's laws
        also = f" (report also takes {either(FAMILY_LAWS)}: {get_law(FAMILY_LAWS[0]).doc})"
        _checked(src, "law.name", lambda: check_choice("law.name", name, FORCE_LAWS), also)
    law = get_law(name)
    out = {"name": name}
    for key, value in values.items():
        shown = f"law.{key}"
        if key == "name":
            continue
        if not law.takes(key):
            raise src.error(str(refusal(key, f"law {name}", shown=shown)), shown)
        if key == "window_cells":
            r = RANGES[key]
            message = f"law.window_cells must be an odd integer in [{int(r.low)}, {int(r.high)}]; got {value!r}"
            checked = _checked(src, shown, lambda: check_integer(shown, value, int(r.low), int(r.high)), message=message)
            if checked % 2 == 0:
                raise src.error(message, shown)
            out[key] = checked
        elif key in law.parameters:
            out[key] = _number(src, shown, key, value)
        else:
            out[key] = _checked(src, shown, lambda: check_choice(shown, value, law.choice(key).values))
    return out


def _check_family(src: YamlFile, family_values, law) -> None:
    """The file's robot family agrees with its mass and law (as ``--robot``, ``--mass`` and ``--law`` must)."""
    family = family_values.get("family", "steering")
    if "mass" in family_values and family != "holonomic":
        raise src.error(f"robot.mass applies to robot family holonomic (robot.family: holonomic), not to family {family}", "robot.mass")
    if law is not None and law["name"] not in laws_of_family(family):
        raise src.error(f"robot.family {family} takes law {either(laws_of_family(family))} "
                        f"(a force in newtons on a mass, Ge & Cui 2002 Sec 6); got law {law['name']}", "robot.family")


def _scenario(src: YamlFile, values) -> dict:
    _check_keys(src, "scenario", values, tuple(SCENARIO_KEYS))
    out = {}
    for geometry, entries in values.items():
        _check_keys(src, f"scenario.{geometry}", entries, SCENARIO_KEYS[geometry])
        keys = {"alpha": "alpha_deg"}
        out[geometry] = {key: _number(src, f"scenario.{geometry}.{key}", keys.get(key, key), value) for key, value in entries.items()}
    return out


def _assumed(src: YamlFile, values) -> dict:
    _check_keys(src, "assumed", values, PARAMETER_KEYS)
    for key, why in values.items():
        if not isinstance(why, str) or not why.strip():
            raise src.error(f"assumed.{key} must be a text saying why the value is assumed; got {why!r}", f"assumed.{key}")
    return {key: " ".join(why.split()) for key, why in values.items()}


def _build(src: YamlFile, section: str, cls, base, values):
    """``cls`` with the base's fields and the file's values (checked again by the dataclass)."""
    try:
        return cls(**{**{f.name: getattr(base, f.name) for f in fields(base)}, **values})
    except ValueError as exc:
        raise src.error(str(exc), section) from None


# ------------------------------------------------------------------ checks
def _number(src: YamlFile, shown, key, value) -> float:
    """`value` in ``RANGES[key]``, with the command line's message for `shown` (``robot.V``)."""
    r = RANGES[key]
    return _checked(src, shown, lambda: check_number(shown, value, r.low, r.high, low_open=r.low_open, high_open=r.high_open, unit=r.unit))


def _checked(src: YamlFile, key: str, check, suffix: str = "", *, message: str | None = None):
    """``check()``, its ValueError (or `message`) raised as the file's error about `key`."""
    try:
        return check()
    except ValueError as exc:
        raise src.error(message or f"{exc}{suffix}", key) from None


_SHOWN_KEYS = {"robot": ROBOT_KEYS}
"""Keys a section's "must be a mapping" message lists when it takes more (``robot``: the family keys are report's)."""

_SECTION_KEYS = {"robot": ROBOT_KEYS + FAMILY_ROBOT_KEYS, "controller": CONTROLLER_KEYS, "law": LAW_KEYS}


def _check_keys(src: YamlFile, section, values, allowed, top=False, shown=None, must="a mapping") -> None:
    """ValueError unless `values` is a mapping whose keys are all in `allowed` ("did you mean" for near misses
    and for a key of another section, ``robot.a_max`` → ``law.a_max``); `shown` the keys a shape error lists,
    `must` what the section must be."""
    if not isinstance(values, dict):
        what = "the file" if top else section
        got = type(values).__name__ if top else repr(values)
        raise src.error(f"{what} must be {must} of key: value with keys {', '.join(shown or allowed)}; got {got}", None if top else section)
    for key in values:
        if key not in allowed:
            label = str(key) if top else f"{section}.{key}"
            elsewhere = [other for other, keys in _SECTION_KEYS.items() if other != section and key in keys and section in _SECTION_KEYS]
            hint = f" (did you mean {elsewhere[0]}.{key}?)" if elsewhere else _did_you_mean(key, allowed)
            taken = "the file takes" if top else f"{section} takes"
            raise src.error(f"{label} is not a key{hint}; {taken} {', '.join(allowed)}", label)


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
    "dead_time": "a Nav2 file does not give the steering plant's dead time; this is the preset's (measure yours: pfm-stability identify, docs/diagnose.md)",
    "plant_gain": "a Nav2 file does not give the steering plant's gain; this is the preset's (measure yours: pfm-stability identify, docs/diagnose.md)",
    "actuator_lag": "a Nav2 file does not give the drive's second lag; this is the preset's (measure yours: pfm-stability identify, docs/diagnose.md)",
    "yaw_accel_limit": "no velocity_smoother node in the Nav2 file; this is the preset's (none unless it gives one)",
    "slip_lag": "a Nav2 file does not say whether the base slides sideways in a turn; this is the preset's (measure yours: "
                "pfm-stability identify with a pose that sees the base move, docs/diagnose.md)",
}
"""Why a loop parameter a Nav2 file cannot give is an assumption (marked ASSUMED in the report)."""

def _from_nav2(src: YamlFile, path: str, preset) -> Config:
    """A `Config` from a Nav2 parameters file: T, V and W where found, everything else from the preset."""
    origin = src.origin
    base = _base(src, {}, preset)
    found = read_nav2(src)
    robot = _build(src, "robot", Robot, base.robot, {k: v.value for k, v in found.values.items() if k in ROBOT_KEYS or k == "max_steering_rate"})
    controller = _build(src, "controller", Controller, base.controller, {k: v.value for k, v in found.values.items() if k in CONTROLLER_KEYS})
    sources, assumed = {}, {}
    for name in PARAMETER_KEYS:
        if name in found.values:
            value = found.values[name]
            sources[name] = f"ASSUMED ({origin}): {value.describe()}; {value.assumed}" if value.assumed else f"{origin}: {value.describe()}"
            if value.assumed:
                assumed[name] = value.assumed
            continue
        assumed[name] = base.assumed.get(name) or NAV2_ASSUMED.get(name, f"not found in the Nav2 file: the preset {base.name}'s value")
        sources[name] = f"ASSUMED (preset {base.name}): {assumed[name]}"
    if "max_steering_rate" in found.values:  # a velocity smoother's clamp: shown beside its yaw acceleration limit
        value = found.values["max_steering_rate"]
        sources["max_steering_rate"] = f"ASSUMED ({origin}): {value.describe()}; {value.assumed}" if value.assumed else f"{origin}: {value.describe()}"
    merged = Preset(
        name=origin, robot=robot, controller=controller, assumed=assumed,
        source=f"{origin} over preset {base.name}", cell_size=base.cell_size, window_cells=base.window_cells,
    )
    return Config(robot, controller, None, {}, sources, path, merged, notes=found.notes)
