"""A sweep specification: read, check and normalize it before any work (docs/sweeps.md).

A spec is a YAML mapping (module `load_spec`) or a dict (`spec_from_mapping`)::

    preset: carmel                 # or  config: robot.yaml (relative to the spec file)
    scenario: {corridor: {L: 0.9}} # or {wall: {alpha: 20}} (degrees)
    models: [sampled, exact_delay] # default: every model
    hold: command                  # default: the preset's / config's
    compute_delay: 1
    law: {name: power}             # default: the config's law, else power
    grid: {V: {from: 0.2, to: 1.6, num: 50}, T: {from: 0.005, to: 0.2, num: 40, scale: log}}
    # or  sample: {method: latin-hypercube, n: 100000, seed: 0, ranges: {V: [0.2, 1.6]}}
    simulate: false

``law: grid`` is short for ``law: {name: grid}``; the laws, the parameters each takes and
those a sweep may vary are the law registry's (`pfm_stability.laws.registry`: the laws
``sweep`` offers). The file is read by the package's one YAML reader
(`pfm_stability.io.yaml_files`: ``1e-3`` is a number). Every error is a `ValueError` of
one line naming the spec file, the line and the field
(``spec s.yaml, line 4: grid.V.num: num must be an integer in [1, 100000000]; got 0``),
raised before anything is computed or written. Values are checked against
`parameters.RANGES` with the command line's messages (`parameters.check_parameter`;
α in degrees). The result, `SweepSpec`, is what the engine and its workers
get; `SweepSpec.digest` identifies it for resuming (the resolved robot,
controller, law, points and the package version, not the file's text).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass, field

from ..checks import check_choice, check_integer
from ..io.yaml_files import YamlFile, mapping_source, read_yaml
from ..laws.registry import DEFAULT_LAW, LAW_NAMES, check_parameters, get_law, laws_for, parameter_keys, refusal
from ..parameters import HOLDS, MODEL_NAMES, RANGES, Controller, Robot, check_parameter, get_preset, plant_not_kb
from ..version import __version__

__all__ = [
    "ENVS",
    "LAW_SWEPT",
    "SWEEP_LAWS",
    "MAX_POINTS",
    "SAMPLE_METHODS",
    "SPEC_KEYS",
    "SWEPT_PARAMETERS",
    "Axis",
    "Sample",
    "SweepSpec",
    "load_spec",
    "spec_from_mapping",
]

SPEC_KEYS = ("preset", "config", "scenario", "models", "hold", "compute_delay", "law", "grid", "sample", "simulate", "env", "pade_order")
"""Top-level keys of a spec (docs/sweeps.md, "Spec reference")."""

ROBOT_SWEPT = ("V", "tau", "k", "W")
CONTROLLER_SWEPT = ("T", "f", "n")
GEOMETRY_SWEPT = ("alpha", "L")
SWEEP_LAWS = laws_for("sweep")
"""The laws a sweep takes (the law registry's; power, the default, first)."""

LAW_SWEPT = parameter_keys(SWEEP_LAWS)
"""Law parameters a spec may fix or vary: those of `SWEEP_LAWS` (as the command line's law options)."""

SWEPT_PARAMETERS = ("V", "tau", "T", "k", "f", "n", "W") + GEOMETRY_SWEPT + LAW_SWEPT
"""Every parameter a spec may vary, in the column order of the output."""

SAMPLE_METHODS = ("latin-hypercube", "sobol")
ENVS = ("analytic", "grid")
"""Simulator environments of ``simulate: true`` (`pfm_stability.sim.presets.ENVS`; default analytic)."""

MAX_POINTS = 100_000_000
"""Most points one sweep may have (a grid's product of ``num``, a sample's ``n``)."""

_SCALES = ("linear", "log")


@dataclass(frozen=True)
class Axis:
    """One grid axis.

    Attributes
    ----------
    name : str
        Parameter (`SWEPT_PARAMETERS`); α in degrees.
    start, stop : float
        First and last value (``from``, ``to``), start < stop unless num = 1.
    num : int
        Values, >= 1.
    scale : {"linear", "log"}
    """

    name: str
    start: float
    stop: float
    num: int
    scale: str = "linear"


@dataclass(frozen=True)
class Sample:
    """A seeded sample of a box of parameters.

    Attributes
    ----------
    method : {"latin-hypercube", "sobol"}
    n : int
        Points.
    seed : int
    ranges : tuple of (str, float, float)
        (parameter, low, high), low < high, in the spec's order.
    """

    method: str
    n: int
    seed: int
    ranges: tuple


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep specification.

    Attributes
    ----------
    robot, controller : Robot, Controller
        The fixed values (preset or config; hold and compute delay as resolved).
    geometry : {"wall", "corridor"}
    geometry_value : float or None
        Fixed α (deg) or L (m); None when it varies.
    law : str
        Force law name (`SWEEP_LAWS`).
    law_parameters : dict
        Fixed law parameters (as given; defaults are `fields.make_law`'s).
    models : tuple of str
    pade_order : int
    axes : tuple of Axis
        Grid axes (empty for a sample).
    sample : Sample or None
    simulate : bool
    env : {"analytic", "grid"}
        Simulator environment when simulating.
    path : str or None
        The spec file.
    sources : dict
        Where the fixed values come from (preset / config).
    """

    robot: Robot
    controller: Controller
    geometry: str
    geometry_value: float | None
    law: str
    law_parameters: dict
    models: tuple
    pade_order: int
    axes: tuple = ()
    sample: Sample | None = None
    simulate: bool = False
    env: str = "analytic"
    path: str | None = None
    sources: dict = field(default_factory=dict)

    @property
    def varying(self) -> tuple:
        """The parameters that vary, in the spec's order."""
        if self.sample is not None:
            return tuple(name for name, _, _ in self.sample.ranges)
        return tuple(a.name for a in self.axes)

    @property
    def count(self) -> int:
        """Number of points."""
        if self.sample is not None:
            return self.sample.n
        return math.prod(a.num for a in self.axes)

    @property
    def input_columns(self) -> tuple:
        """Input columns of the output, in order: V, tau, T, k, f, n, W, alpha or L, then the law parameters that vary."""
        base = ("V", "tau", "T", "k", "f", "n", "W", "alpha" if self.geometry == "wall" else "L")
        return base + tuple(name for name in LAW_SWEPT if name in self.varying)

    def fixed_value(self, name: str) -> float:
        """The fixed value of an input column (robot, controller or geometry).

        Parameters
        ----------
        name : str
            An input column's name.
        """
        if name in ROBOT_SWEPT:
            return getattr(self.robot, name)
        if name in CONTROLLER_SWEPT:
            return getattr(self.controller, name)
        if name in GEOMETRY_SWEPT:
            return self.geometry_value
        raise KeyError(name)

    def to_dict(self) -> dict:
        """The normalized spec (what the digest covers; JSON-ready)."""
        return {
            "robot": {**{n: getattr(self.robot, n) for n in ("V", "tau", "k", "W", "max_steering_rate")},
                      **plant_not_kb(self.robot)},  # KB's plant: none (existing digests unchanged)
            "controller": {n: getattr(self.controller, n) for n in ("f", "n", "T", "hold", "compute_delay")},
            "geometry": self.geometry,
            "geometry_value": self.geometry_value,
            "law": {"name": self.law, **self.law_parameters},
            "models": list(self.models),
            "pade_order": self.pade_order,
            "grid": [{"name": a.name, "from": a.start, "to": a.stop, "num": a.num, "scale": a.scale} for a in self.axes],
            "sample": None if self.sample is None else {
                "method": self.sample.method, "n": self.sample.n, "seed": self.sample.seed,
                "ranges": {name: [lo, hi] for name, lo, hi in self.sample.ranges},
            },
            "simulate": self.simulate,
            "env": self.env,
        }

    @property
    def digest(self) -> str:
        """SHA-256 of the normalized spec and the package version: equal digests give equal tables."""
        text = json.dumps({"spec": self.to_dict(), "version": __version__}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()


class _Where:
    """Where the spec's values come from (its file with the line of every key, or a mapping), for every message:
    ``spec FILE, line N: <key>…`` (``spec FILE: …`` for a mapping given in code, ``spec: …`` without a file)."""

    def __init__(self, source: YamlFile):
        self.source = source

    def fail(self, message: str, key=None):
        raise self.source.error(message, key)

    def wrap(self, key: str, func, *args, **kwargs):
        """func(*args) with its ValueError re-raised as ``spec FILE, line N: key: message``."""
        try:
            return func(*args, **kwargs)
        except ValueError as exc:
            raise self.source.error(f"{key}: {exc}", key) from None


def _mapping(where: _Where, key: str, value, what: str = "a mapping") -> dict:
    if not isinstance(value, dict):
        where.fail(f"{key} must be {what}; got {value!r}", key)
    return value


def _known(where: _Where, key: str, data: dict, allowed) -> None:
    for name in data:
        if name not in allowed:
            where.fail(f"unknown key {key + '.' if key else ''}{name}; allowed: {', '.join(allowed)}", f"{key}.{name}" if key else name)


def _check_value(where: _Where, key: str, name: str, value) -> float:
    """A value of parameter `name` (α in degrees) against its range; integers for window_cells."""
    if name == "window_cells":
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        v = where.wrap(key, check_integer, "window_cells", value, int(RANGES["window_cells"].low), int(RANGES["window_cells"].high))
        if v % 2 == 0:
            where.fail(f"{key}: window_cells must be an odd integer; got {value!r}", key)
        return float(v)
    return where.wrap(key, check_parameter, "alpha_deg" if name == "alpha" else name, value)


def load_spec(path, *, config=None) -> SweepSpec:
    """Read and check a YAML spec file (`spec_from_mapping`); a config file it names is read relative to it.

    Parameters
    ----------
    path : str or os.PathLike
        The spec file.
    config : str or os.PathLike, optional
        A configuration file (docs/config.md) given on the command line
        (``sweep --config FILE``): it replaces the spec's own ``preset`` or
        ``config`` (the command line wins, as for every command).

    Raises
    ------
    ValueError
        Missing or unreadable file, invalid YAML, a key given twice, YAML that is not a mapping,
        or any field `spec_from_mapping` rejects, at its line.
    """
    path = os.fspath(path)
    document = read_yaml(path, "spec")
    data = document.data
    if config is not None and isinstance(data, dict):
        data = {key: value for key, value in data.items() if key not in ("preset", "config")}
        data["config"] = os.path.abspath(os.fspath(config))
    return _spec(YamlFile(data, document.origin, path, document.lines), path, os.path.dirname(os.path.abspath(path)))


def spec_from_mapping(data, *, origin: str | None = None, base_dir: str | None = None) -> SweepSpec:
    """Check a spec given as a dict and resolve its fixed values.

    Parameters
    ----------
    data : dict
        The spec (module docstring; docs/sweeps.md).
    origin : str, optional
        Its file, for messages.
    base_dir : str, optional
        Where a relative ``config:`` path is looked for (default: the working directory).

    Returns
    -------
    SweepSpec

    Raises
    ------
    ValueError
        ``spec FILE: <field>: <why>`` for the first problem found.
    """
    return _spec(mapping_source(data, f"spec {origin}" if origin else "spec"), origin, base_dir)


def _spec(source: YamlFile, origin: str | None, base_dir: str | None) -> SweepSpec:
    """The `SweepSpec` of a spec document (a file with its lines, or a mapping)."""
    where = _Where(source)
    data = _mapping(where, "the spec", source.data)
    _known(where, "", data, SPEC_KEYS)
    robot, controller, config_law, config_scenario, sources = _base(where, data, base_dir)
    hold = data.get("hold", controller.hold)
    where.wrap("hold", check_choice, "hold", hold, HOLDS)
    delay = where.wrap("compute_delay", check_integer, "compute_delay", data.get("compute_delay", controller.compute_delay), 0, 1)
    controller = controller.replace(hold=hold, compute_delay=delay)
    models = _models(where, data.get("models", list(MODEL_NAMES)))
    pade_order = where.wrap("pade_order", check_integer, "pade_order", data.get("pade_order", 3), 1, 12)
    simulate = data.get("simulate", False)
    if not isinstance(simulate, bool):
        where.fail(f"simulate must be true or false; got {simulate!r}", "simulate")
    env = data.get("env", "analytic")
    where.wrap("env", check_choice, "env", env, ENVS)
    if ("grid" in data) == ("sample" in data):
        where.fail("give exactly one of grid (a full factorial) or sample (a seeded sample)", "grid" if "grid" in data else "sample" if "sample" in data else None)
    axes, sample = (_grid(where, data["grid"]), None) if "grid" in data else ((), _sample(where, data["sample"]))
    varying = tuple(a.name for a in axes) if sample is None else tuple(r[0] for r in sample.ranges)
    law, law_parameters = _law(where, data.get("law", config_law), varying, "grid" if sample is None else "sample.ranges")
    geometry, value = _scenario(where, data.get("scenario", config_scenario), varying, "scenario" in data)
    if simulate:
        _check_simulable(where, axes, sample, controller)
        if env == "grid" and law != "grid":
            where.fail(f"env grid simulates the histogram grid, whose law is its cells: it needs law grid; got law {law} (or use env analytic)", "env")
    spec = SweepSpec(robot, controller, geometry, value, law, law_parameters, models, pade_order, axes, sample, simulate, env, origin, sources)
    if spec.count > MAX_POINTS:
        key = "grid" if sample is None else "sample.n"
        where.fail(f"{key}: {spec.count} points; at most {MAX_POINTS} per sweep", key)
    return spec


def _base(where: _Where, data: dict, base_dir):
    """Robot, controller, the config's law and scenario, and sources, from ``preset`` or ``config``."""
    if "preset" in data and "config" in data:
        where.fail("give preset or config, not both", "config")
    if "config" in data:
        from ..io.config import config_from_mapping, load_config

        given = data["config"]
        if isinstance(given, dict):
            config = where.wrap("config", config_from_mapping, given, "spec config")
        elif isinstance(given, str) and given.strip():
            path = given if os.path.isabs(given) or base_dir is None else os.path.join(base_dir, given)
            config = where.wrap("config", load_config, path)
        else:
            where.fail(f"config must be a file name or a mapping; got {given!r}", "config")
        _sweepable_robot(where, config, "law" in data)
        return config.robot, config.controller, config.law, dict(config.scenario or {}), dict(config.sources)
    preset = where.wrap("preset", get_preset, data.get("preset", "carmel"))
    sources = {name: f"preset {preset.name}" for name in ("V", "tau", "k", "W", "f", "n", "T", "hold", "compute_delay")}
    return preset.robot, preset.controller, None, {}, sources


def _sweepable_robot(where: _Where, config, own_law: bool) -> None:
    """Refuse a config's robot family other than steering, and its law that sweeps do not take (`SWEEP_LAWS`) unless
    the spec's own ``law`` replaces it: sweeps analyse KB's steering robot with the static laws (docs/config.md)."""
    others = [name for name in LAW_NAMES if name not in SWEEP_LAWS]
    why = f"sweeps analyse KB's steering robot with the laws {', '.join(SWEEP_LAWS)}; robot families and the laws " \
          f"{', '.join(others)} are report's (docs/velocity_and_fuzzy.md)"
    if config.family not in (None, "steering"):
        where.fail(f"config: robot.family {config.family} is not supported: {why}", "config")
    if config.law is not None and config.law["name"] not in SWEEP_LAWS and not own_law:
        where.fail(f"config: law.name {config.law['name']} is not supported: {why}", "config")


def _models(where: _Where, models) -> tuple:
    if isinstance(models, str):
        models = [models]
    if not isinstance(models, list) or not models:
        where.fail(f"models must be a non-empty list of {', '.join(MODEL_NAMES)}; got {models!r}", "models")
    for name in models:
        where.wrap("models", check_choice, "model", name, MODEL_NAMES)
    return tuple(dict.fromkeys(models))


def _number(where: _Where, key: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        where.fail(f"{key} must be a finite number; got {value!r}", key)
    return float(value)


def _swept(where: _Where, key: str, data) -> dict:
    """``grid`` or ``sample.ranges``: a non-empty mapping whose keys are parameters that may vary."""
    data = _mapping(where, key, data)
    if not data:
        where.fail(f"{key} must name at least one parameter", key)
    for name in data:
        if name not in SWEPT_PARAMETERS:
            where.fail(f"unknown parameter {key}.{name}; parameters that may vary: {', '.join(SWEPT_PARAMETERS)}", f"{key}.{name}")
    return data


def _grid(where: _Where, grid) -> tuple:
    axes = []
    for name, axis in _swept(where, "grid", grid).items():
        key = f"grid.{name}"
        axis = _mapping(where, key, axis)
        _known(where, key, axis, ("from", "to", "num", "scale"))
        for required in ("from", "to", "num"):
            if required not in axis:
                where.fail(f"{key}.{required} is missing", key)
        start = _check_value(where, f"{key}.from", name, _number(where, f"{key}.from", axis["from"]))
        stop = _check_value(where, f"{key}.to", name, _number(where, f"{key}.to", axis["to"]))
        num = where.wrap(f"{key}.num", check_integer, "num", axis["num"], 1, MAX_POINTS)
        scale = axis.get("scale", "linear")
        where.wrap(f"{key}.scale", check_choice, "scale", scale, _SCALES)
        if num == 1 and start != stop:
            where.fail(f"{key}: num = 1 needs from == to (one value); got from {start:g}, to {stop:g}", key)
        if num > 1 and not start < stop:
            where.fail(f"{key}: the range is empty or reversed: from must be < to when num > 1; got from {start:g}, to {stop:g}", key)
        if scale == "log" and start <= 0:
            where.fail(f"{key}: scale log needs from > 0; got {start:g}", key)
        if name == "window_cells":
            values = _axis_values(Axis(name, start, stop, num, scale))
            if any(v != round(v) or round(v) % 2 == 0 for v in values):
                where.fail(f"{key}: window_cells values must be odd integers; from {start:g} to {stop:g} in {num} steps gives others", key)
        axes.append(Axis(name, start, stop, num, scale))
    return tuple(axes)


def _axis_values(axis: Axis) -> list:
    """The values of an axis without numpy (for the checks; `points.axis_values` gives the array)."""
    if axis.num == 1:
        return [axis.start]
    if axis.scale == "log":
        lo, hi = math.log(axis.start), math.log(axis.stop)
        return [math.exp(lo + (hi - lo) * i / (axis.num - 1)) for i in range(axis.num)]
    return [axis.start + (axis.stop - axis.start) * i / (axis.num - 1) for i in range(axis.num)]


def _sample(where: _Where, sample) -> Sample:
    sample = _mapping(where, "sample", sample)
    _known(where, "sample", sample, ("method", "n", "seed", "ranges"))
    for required in ("method", "n", "ranges"):
        if required not in sample:
            where.fail(f"sample.{required} is missing", "sample")
    where.wrap("sample.method", check_choice, "method", sample["method"], SAMPLE_METHODS)
    n = where.wrap("sample.n", check_integer, "n", sample["n"], 1, MAX_POINTS)
    seed = where.wrap("sample.seed", check_integer, "seed", sample.get("seed", 0), 0, 2**63 - 1)
    out = []
    for name, bounds in _swept(where, "sample.ranges", sample["ranges"]).items():
        key = f"sample.ranges.{name}"
        if name == "window_cells":
            where.fail(f"{key}: window_cells is an odd integer and cannot be sampled; vary it in a grid", key)
        if not isinstance(bounds, list) or len(bounds) != 2:
            where.fail(f"{key} must be [low, high]; got {bounds!r}", key)
        lo = _check_value(where, f"{key}[0]", name, _number(where, f"{key}[0]", bounds[0]))
        hi = _check_value(where, f"{key}[1]", name, _number(where, f"{key}[1]", bounds[1]))
        if not lo < hi:
            where.fail(f"{key}: the range is empty or reversed: low must be < high; got [{lo:g}, {hi:g}]", key)
        out.append((name, lo, hi))
    return Sample(sample["method"], n, seed, tuple(out))


def _law(where: _Where, law, varying, varies_in: str) -> tuple[str, dict]:
    """Law name and its fixed parameters (`SWEEP_LAWS`, the registry's); a varying law parameter must be one the law takes.

    ``law: grid`` (a name) is short for ``law: {name: grid}``; `varies_in` is where the varying parameters are
    (``grid``, ``sample.ranges``), for the messages."""
    if law is None:
        law = {"name": DEFAULT_LAW["sweep"]}
    if isinstance(law, str):
        law = {"name": law}
    law = dict(_mapping(where, "law", law, "a law's name or a mapping"))
    name = law.pop("name", DEFAULT_LAW["sweep"])
    where.wrap("law.name", check_choice, "law", name, SWEEP_LAWS)
    for key in law:
        if key not in LAW_SWEPT:
            where.fail(f"unknown key law.{key}; the laws take: {', '.join(LAW_SWEPT)}", f"law.{key}")
    fixed = {key: _check_value(where, f"law.{key}", key, value) for key, value in law.items()}
    if "window_cells" in fixed:
        fixed["window_cells"] = int(fixed["window_cells"])
    for key in varying:
        if key in fixed:
            where.fail(f"law.{key} is fixed and also varies; give it in one place", f"law.{key}")
    swept = [key for key in varying if key in LAW_SWEPT or key in ("f", "n")]  # f, n: KB's laws only, as report --law says
    entry = get_law(name)
    for key, shown in [(key, f"law.{key}") for key in fixed] + [(key, f"{varies_in}.{key}") for key in swept]:
        if not entry.takes(key):
            where.fail(str(refusal(key, f"law {name}", shown=shown, laws=SWEEP_LAWS)), shown)
    where.wrap("law", check_parameters, name, list(fixed) + swept, law_shown=f"law {name}", laws=SWEEP_LAWS)
    return name, fixed


def _scenario(where: _Where, scenario, varying, given: bool) -> tuple[str, float | None]:
    """("wall" | "corridor", fixed α in degrees or L in m, or None when it varies)."""
    scenario = dict(_mapping(where, "scenario", scenario or {}))
    _known(where, "scenario", scenario, ("wall", "corridor"))
    swept = [name for name in GEOMETRY_SWEPT if name in varying]
    if len(swept) == 2:
        where.fail("alpha (a wall) and L (a corridor) cannot both vary: a sweep has one geometry", "scenario")
    kinds = list(scenario)
    if swept:
        kind = "wall" if swept[0] == "alpha" else "corridor"
        if given and kinds and kinds != [kind]:
            where.fail(f"scenario {', '.join(kinds)} contradicts the varying {swept[0]} (a {kind})", "scenario")
        return kind, None
    if len(kinds) != 1:
        where.fail("scenario must be exactly one of {wall: {alpha: DEG}} or {corridor: {L: M}} (or vary alpha or L)"
                   + (f"; got {', '.join(kinds)}" if kinds else ""), "scenario")
    kind = kinds[0]
    key, name = ("alpha", "alpha") if kind == "wall" else ("L", "L")
    values = _mapping(where, f"scenario.{kind}", scenario[kind])
    _known(where, f"scenario.{kind}", values, (key,))
    if key not in values:
        where.fail(f"scenario.{kind}.{key} is missing", f"scenario.{kind}")
    return kind, _check_value(where, f"scenario.{kind}.{key}", name, _number(where, f"scenario.{kind}.{key}", values[key]))


def _check_simulable(where: _Where, axes, sample, controller: Controller) -> None:
    """``simulate: true`` samples: T > 0 everywhere (the simulator takes every law of the analysis in env analytic)."""
    lows = [a.start for a in axes if a.name == "T"] + ([lo for name, lo, _ in sample.ranges if name == "T"] if sample else [])
    T = lows[0] if lows else controller.T
    if not T > 0:
        where.fail(f"simulate: the simulator samples, T must be in {RANGES['T_sampled'].describe()}; got T = {T:g}", "simulate")
