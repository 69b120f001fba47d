"""Nav2 parameter files: the sampling period, speed and width of a ROS 2 Nav2 robot (docs/config.md).

A Nav2 parameters file (``nav2_params.yaml`` of nav2_bringup) has top-level node
names, each with ``ros__parameters``. Three values of the loop are read from it:

``T``
    1 / ``controller_server.ros__parameters.controller_frequency`` (Hz): the
    controller server computes one velocity command per period.
``V``
    The controller plugin's top speed: for each plugin of
    ``controller_server.ros__parameters.controller_plugins`` (default
    ``[FollowPath]``), in order, the first of `SPEED_KEYS` it has: DWB's
    ``max_vel_x``, then DWB's ``max_speed_xy``, Regulated Pure Pursuit's
    ``desired_linear_vel``, MPPI's ``vx_max``.
``W``
    From the local costmap (``local_costmap.local_costmap.ros__parameters``,
    else ``local_costmap.ros__parameters``, else the global costmap's): its
    ``footprint`` when it is given and not empty (Nav2 uses the footprint over
    the radius), W = max y − min y, the lateral extent; else W = 2 ×
    ``robot_radius``.

``yaw_accel_limit``, ``max_steering_rate``
    From ``velocity_smoother.ros__parameters`` when the file has that node
    (`read_velocity_smoother`; Nav2's ``nav2_velocity_smoother``, whose rule
    the simulator and the models take: docs/simulator.md): the angular entries
    (index 2 of three axes, 5 of six) of ``max_accel`` and ``max_decel`` per
    tick of ``smoothing_frequency``, and of ``max_velocity`` and
    ``min_velocity``; ``feedback`` is read and noted. A key the node does not
    give takes Nav2's default (`SMOOTHER_DEFAULTS`, from the node's source),
    and the value says so (ASSUMED).

A value not found is a note, not an error (the preset's value stays); a file
where none is found is an error. This module imports no numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from typing import TYPE_CHECKING

from ..checks import check_number
from ..parameters import RANGES
from .yaml_files import InputError, parse_yaml

if TYPE_CHECKING:
    from .yaml_files import YamlFile

__all__ = ["SPEED_KEYS", "SMOOTHER_DEFAULTS", "Nav2Value", "Nav2Values", "is_nav2", "read_nav2", "read_velocity_smoother"]

PARAMETERS = "ros__parameters"
SPEED_KEYS = ("max_vel_x", "max_speed_xy", "desired_linear_vel", "vx_max")
"""The speed keys of a controller plugin, in the order they are tried (DWB, DWB, Regulated Pure Pursuit, MPPI)."""
COSTMAPS = (("local_costmap", "local_costmap"), ("local_costmap",), ("global_costmap", "global_costmap"), ("global_costmap",))
"""Where the robot's footprint is looked for, in order."""
_FREQUENCY = (1.0 / RANGES["T"].high, 1e6)  # Hz: T = 1/f within (0, 100] s
SMOOTHER = "velocity_smoother"
SMOOTHER_DEFAULTS = {"smoothing_frequency": 20.0, "feedback": "OPEN_LOOP", "max_velocity": [0.5, 0.0, 2.5], "min_velocity": [-0.5, 0.0, -2.5],
                     "max_accel": [2.5, 0.0, 3.2], "max_decel": [-2.5, 0.0, -3.2]}
"""Nav2's defaults of the velocity smoother's keys read here (``nav2_velocity_smoother/src/velocity_smoother.cpp``,
``on_configure``): the value of a key the file's node does not give."""
FEEDBACKS = ("OPEN_LOOP", "CLOSED_LOOP")


@dataclass(frozen=True)
class Nav2Value:
    """One loop parameter read from a Nav2 file.

    Attributes
    ----------
    name : str
        ``"T"``, ``"V"`` or ``"W"``.
    value : float
        In SI units (s, m/s, m).
    key : str
        The key read, e.g. ``"controller_server.controller_frequency"``.
    given : object
        Its value in the file.
    unit : str
        Unit of `given` (``"Hz"``, ``"m/s"``, ``"m"``).
    note : str
        How `value` follows from `given` when it is not the value itself (e.g. the velocity smoother's rule).
    assumed : str or None
        Why the value is (partly) an assumption: a key the file does not give, taken at Nav2's default; None: read.
    """

    name: str
    value: float
    key: str
    given: object
    unit: str
    note: str = ""
    assumed: str | None = None

    def describe(self) -> str:
        """E.g. ``controller_server.controller_frequency = 20 Hz``."""
        given = f"{self.given:g}" if isinstance(self.given, (int, float)) else str(self.given)
        return f"{self.key} = {given}" + (f" {self.unit}" if self.unit else "") + (f" ({self.note})" if self.note else "")


@dataclass(frozen=True)
class Nav2Values:
    """What a Nav2 file gives: ``values`` (name → `Nav2Value`) and ``notes`` (what was not found).

    Attributes
    ----------
    values : dict
        Parameter name → `Nav2Value`.
    notes : tuple of str
        What was not found.
    """

    values: dict
    notes: tuple


def is_nav2(data) -> bool:
    """Whether `data` (a parsed YAML document) is a Nav2 parameters file: a node with ``ros__parameters``.

    Parameters
    ----------
    data : object
        A parsed YAML document.
    """
    if not isinstance(data, dict):
        return False
    nodes = [v for v in data.values() if isinstance(v, dict)]
    nested = [w for v in nodes for w in v.values() if isinstance(w, dict)]
    return any(PARAMETERS in node for node in nodes + nested)


def read_nav2(source: "YamlFile") -> Nav2Values:
    """T, V and W from a Nav2 parameters file (see the module's docstring for the keys).

    Parameters
    ----------
    source : io.yaml_files.YamlFile
        The parsed file (`is_nav2` of its data), named ``Nav2 <path>`` in messages.

    Raises
    ------
    ValueError
        A value of the wrong type or out of range (``"Nav2 FILE, line 12: <key> must be …"``),
        or none of the three found (the message lists what was looked for).
    """
    data, origin = source.data, source.origin
    server = _node(data, ("controller_server",))
    readers = (("T", *_period(server, source)), ("V", *_speed(server, source)), ("W", *_width(data, source)))
    values = {name: found for name, found, _ in readers if found is not None}
    notes = tuple(f"{origin}: no {looked} found; {name} is the preset's" for name, found, looked in readers if found is None)
    smoother, smoother_notes = read_velocity_smoother(source)
    values.update(smoother)
    notes += smoother_notes
    if not values:
        looked = "; ".join(f"{name}: {looked}" for name, _, looked in readers)
        raise source.error(f"none of the Nav2 keys read was found (looked for {looked})")
    return Nav2Values(values, notes)


def _node(data, path):
    """``data[path…][ros__parameters]``, or None."""
    node = data
    for name in path:
        node = node.get(name) if isinstance(node, dict) else None
    node = node.get(PARAMETERS) if isinstance(node, dict) else None
    return node if isinstance(node, dict) else None


def _period(server, source):
    key = "controller_server.controller_frequency"
    looked = f"{key} (in ros__parameters, Hz)"
    if server is None or "controller_frequency" not in server:
        return None, looked
    given = server["controller_frequency"]
    hz = _check(source, key, ("controller_server", PARAMETERS, "controller_frequency"), given, *_FREQUENCY, "Hz", low_open=False)
    return Nav2Value("T", 1.0 / hz, key, given, "Hz"), looked


def _speed(server, source):
    plugins = (server or {}).get("controller_plugins", ["FollowPath"])
    if isinstance(plugins, str):
        plugins = [plugins]
    if not isinstance(plugins, list):
        raise source.error(f"controller_server.controller_plugins must be a list of plugin names; got {plugins!r}",
                           ("controller_server", PARAMETERS, "controller_plugins"))
    looked = f"controller_server.<plugin>.{{{', '.join(SPEED_KEYS)}}} for plugins {', '.join(map(str, plugins)) or 'none'}"
    for plugin in plugins:
        params = (server or {}).get(plugin)
        for name in SPEED_KEYS if isinstance(params, dict) else ():
            if name in params:
                key = f"controller_server.{plugin}.{name}"
                r = RANGES["V"]
                value = _check(source, key, ("controller_server", PARAMETERS, plugin, name), params[name], r.low, r.high, r.unit,
                               low_open=r.low_open, high_open=r.high_open)
                return Nav2Value("V", value, key, params[name], "m/s"), looked
    return None, looked


def _width(data, source):
    r = RANGES["W"]
    looked = "footprint or robot_radius of local_costmap.local_costmap (or local_costmap, global_costmap)"
    for path in COSTMAPS:
        costmap = _node(data, path)
        if costmap is None:
            continue
        where = ".".join(path)
        footprint = costmap.get("footprint")
        if footprint not in (None, "", "[]", []):
            key = f"{where}.footprint"
            location = (*path, PARAMETERS, "footprint")
            ys = _footprint_ys(source, key, location, footprint)
            width = _check(source, f"{key} lateral extent (max y - min y)", location, max(ys) - min(ys), r.low, r.high, "m", low_open=r.low_open)
            return Nav2Value("W", width, key, footprint, ""), looked
        if "robot_radius" in costmap:
            key = f"{where}.robot_radius"
            radius = _check(source, key, (*path, PARAMETERS, "robot_radius"), costmap["robot_radius"], r.low / 2, r.high / 2, "m", low_open=r.low_open)
            return Nav2Value("W", 2.0 * radius, key, costmap["robot_radius"], "m"), looked
    return None, looked


def _footprint_ys(source, key, location, footprint) -> list:
    """The y of each vertex of a footprint (`_footprint_points`), m."""
    return [y for _, y in _footprint_points(source, key, location, footprint)]


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check(source, key, location, value, low, high, unit, *, low_open=True, high_open=False) -> float:
    try:
        return check_number(key, value, low, high, low_open=low_open, high_open=high_open, unit=unit)
    except ValueError as exc:
        raise source.error(str(exc), location) from None


# ------------------------------------------------------------------ the path tracker (report --controller)
@dataclass(frozen=True)
class Nav2Setting:
    """One value the path-tracking analysis reads, with where it came from.

    Attributes
    ----------
    value : object
        The value (SI units).
    source : str
        ``"Nav2 FILE: controller_server.FollowPath.lookahead_dist = 0.8"``, or ``"ASSUMED (…): why"`` for a default.
    """

    value: object
    source: str

    @property
    def assumed(self) -> bool:
        """Whether the value is an assumption (not in the file)."""
        return self.source.startswith("ASSUMED")

    def named(self, name: str, shown: str) -> str:
        """The source naming the parameter it is the value of: an assumed default as ``ASSUMED (Nav2's default
        name = shown, file): why`` (a value the file or the user gave names itself already).

        Parameters
        ----------
        name : str
            The parameter's name.
        shown : str
            Its value as text, with its unit.
        """
        head = "ASSUMED (Nav2's default, "
        if self.source.startswith(head):
            return f"ASSUMED (Nav2's default {name} = {shown}, {self.source[len(head):]}"
        return self.source


@dataclass(frozen=True)
class Nav2Tracker:
    """A Nav2 path tracker as a parameters file (or Nav2's defaults) gives it (`read_path_tracker`, `default_tracker`).

    Attributes
    ----------
    controller : str
        Its short name (`controllers.registry.CONTROLLER_NAMES`).
    plugin : str
        The pluginlib class followed (``nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController``).
    plugin_id : str
        Its name in ``controller_plugins`` (``FollowPath``).
    parameters : dict
        Every registry parameter of the controller → `Nav2Setting`.
    frequency : Nav2Setting
        ``controller_frequency``, Hz.
    costmap : dict
        ``inscribed_radius``, ``inflation_radius`` (m), ``cost_scaling_factor`` (1/m), ``resolution`` (m) → `Nav2Setting`.
    notes : tuple of str
        What the file's structure implied (a Rotation Shim's primary controller, several controller plugins).
    plugin_source : str
        Where the plugin came from (the file's key, Nav2's default, the command line).
    """

    controller: str
    plugin: str
    plugin_id: str
    parameters: dict
    frequency: Nav2Setting
    costmap: dict
    notes: tuple = ()
    plugin_source: str = "--controller"

    def values(self) -> dict:
        """Parameter name → value."""
        return {name: s.value for name, s in self.parameters.items()}

    def costmap_values(self) -> dict:
        """``inscribed_radius``, ``inflation_radius``, ``cost_scaling_factor``, ``resolution`` → value."""
        return {name: s.value for name, s in self.costmap.items()}


def _default(source_file: str, why: str = "not in the file") -> str:
    return f"ASSUMED (Nav2's default, {source_file}): {why}"


def default_tracker(controller: str, why: str = "no Nav2 file given") -> Nav2Tracker:
    """A Nav2 controller with every parameter at Nav2's declared default, each marked ASSUMED with `why`.

    Parameters
    ----------
    controller : str
        ``rpp``, ``graceful``, ``mppi`` or ``dwb``.
    why : str
        The reason the defaults are assumed.
    """
    from ..controllers.registry import COSTMAP, SERVER, get_controller

    entry = get_controller(controller)
    parameters = {p.name: Nav2Setting(p.default, _default(entry.source, why)) for p in entry.parameters}
    server = {p.name: p for p in SERVER}
    costmap = _default_costmap({p.name: p for p in COSTMAP}, why)
    frequency = Nav2Setting(server["controller_frequency"].default, _default("nav2_controller/src/parameter_handler.cpp", why))
    return Nav2Tracker(controller, entry.plugins[0], "FollowPath", parameters, frequency, costmap)


def _default_costmap(params: dict, why: str) -> dict:
    radius = params["robot_radius"].default
    where = "nav2_costmap_2d/src/costmap_2d_ros.cpp"
    inflation = "nav2_costmap_2d/plugins/inflation_layer.cpp"
    return {
        "inscribed_radius": Nav2Setting(radius * math.cos(math.pi / 16), _default(where, f"{why}; robot_radius {radius:g} m (a 16-gon)")),
        "inflation_radius": Nav2Setting(params["inflation_radius"].default, _default(inflation, why)),
        "cost_scaling_factor": Nav2Setting(params["cost_scaling_factor"].default, _default(inflation, why)),
        "resolution": Nav2Setting(params["resolution"].default, _default(where, why)),
    }


def read_path_tracker(source: "YamlFile", controller: str | None = None) -> Nav2Tracker:
    """The path tracker of a Nav2 parameters file: ``controller_server``'s first controller plugin, its parameters,
    ``controller_frequency``, and the local costmap's inscribed radius and inflation layer (docs/config.md).

    A parameter the file does not give is Nav2's declared default (`controllers.registry`), marked ASSUMED.

    Parameters
    ----------
    source : io.yaml_files.YamlFile
        The parsed file (`is_nav2`).
    controller : str, optional
        The controller the user asked for (``--controller``): the file's plugin must be that one.

    Raises
    ------
    ValueError
        One line naming the file, the line and the key: a plugin the report does not analyse, a plugin other than
        `controller`, a parameter of the wrong type or out of range.
    """
    from ..controllers.registry import (COSTMAP, DEFAULT_PLUGIN, SERVER, SHIM_PLUGIN, controller_of_plugin, get_controller, plugin_key)

    data, origin = source.data, source.origin
    server = _node(data, ("controller_server",)) or {}
    server_keys = ("controller_server", PARAMETERS)
    ids = server.get("controller_plugins", list(SERVER[1].default))
    ids = [ids] if isinstance(ids, str) else ids
    if not (isinstance(ids, list) and ids and all(isinstance(i, str) for i in ids)):
        raise source.error(f"controller_server.controller_plugins must be a list of plugin names; got {ids!r}", (*server_keys, "controller_plugins"))
    plugin_id, notes = ids[0], []
    if len(ids) > 1:
        notes.append(f"{origin}: controller_plugins lists {', '.join(ids)}; the first, {plugin_id}, is analysed (the controller server's default)")
    node = server.get(plugin_id) if isinstance(server.get(plugin_id), dict) else {}
    keys = (*server_keys, plugin_id)
    plugin = node.get("plugin", DEFAULT_PLUGIN)
    if not isinstance(plugin, str):
        raise source.error(f"controller_server.{plugin_id}.plugin must be a plugin class name; got {plugin!r}", (*keys, "plugin"))
    plugin_source = f"{origin}: controller_server.{plugin_id}.plugin"
    if "plugin" not in node:
        notes.append(f"{origin}: controller_server.{plugin_id}.plugin not given: Nav2's default {DEFAULT_PLUGIN}")
        plugin_source = f"ASSUMED (Nav2's default, nav2_controller/include/nav2_controller/parameter_handler.hpp): {plugin_source} not in the file"
    if plugin_key(plugin) == SHIM_PLUGIN:
        node, keys, plugin = _shim_primary(source, node, keys, plugin_id)
        notes.append(f"{origin}: {plugin_id} is the Rotation Shim controller; on a straight path its primary controller {plugin} tracks")
        plugin_source = f"{origin}: controller_server.{'.'.join(keys[2:])}" + (".plugin" if keys[-1] == "primary_controller" else ".primary_controller")
    entry = controller_of_plugin(plugin)
    if entry is None:
        analysed = ", ".join(p for c in ("rpp", "graceful", "mppi", "dwb") for p in get_controller(c).plugins)
        raise source.error(f"controller_server.{plugin_id}.plugin {plugin} is not a controller the report analyses ({analysed})", (*keys, "plugin"))
    if controller is not None and entry.name != controller:
        raise source.error(f"the file's controller_server.{plugin_id}.plugin is {plugin} (--controller {entry.name}); got --controller "
                           f"{controller}: give --controller {entry.name} or auto", (*keys, "plugin"))
    parameters = {p.name: _setting(source, p, node, keys, f"controller_server.{'.'.join(keys[2:])}", entry.source) for p in entry.parameters}
    frequency = _setting(source, SERVER[0], server, server_keys, "controller_server", "nav2_controller/src/parameter_handler.cpp")
    costmap = _read_costmap(source, {p.name: p for p in COSTMAP})
    return Nav2Tracker(entry.name, plugin_key(plugin), plugin_id, parameters, frequency, costmap, tuple(notes), plugin_source)


def _shim_primary(source, node, keys, plugin_id):
    """(parameters node, its keys, plugin) of a Rotation Shim's primary controller: ``primary_controller: {plugin: …, …}``
    (Nav2 after Kilted: its parameters in that namespace), or ``primary_controller: "pkg::Class"`` (before: beside it)."""
    primary = node.get("primary_controller")
    if isinstance(primary, dict) and isinstance(primary.get("plugin"), str):
        return primary, (*keys, "primary_controller"), primary["plugin"]
    if isinstance(primary, str):
        return node, keys, primary
    raise source.error(f"controller_server.{plugin_id}.primary_controller must name the Rotation Shim's primary controller "
                       f"(primary_controller: {{plugin: pkg::Class}}); got {primary!r}", (*keys, "primary_controller"))


def _setting(source, parameter, node: dict, keys: tuple, shown_prefix: str, source_file: str) -> Nav2Setting:
    """A registry parameter from `node` (a critic's ``Critic.name`` nested, or an alias), checked, or its default ASSUMED."""
    for name in (parameter.name, *parameter.aliases):
        path = name.split(".")
        value = node
        for part in path:
            value = value.get(part) if isinstance(value, dict) else None
        if value is None:
            continue
        shown = f"{shown_prefix}.{name}"
        try:
            checked = parameter.check(value, shown)
        except ValueError as exc:
            raise source.error(str(exc), (*keys, *path)) from None
        given = f"{value:g}" if isinstance(value, float) else str(value).lower() if isinstance(value, bool) else str(value)
        return Nav2Setting(checked, f"{source.origin}: {shown} = {given}{' ' + parameter.unit if parameter.unit else ''}")
    return Nav2Setting(parameter.default, _default(source_file))


def _read_costmap(source, params: dict) -> dict:
    """The local costmap's inscribed radius (footprint, else robot_radius as Nav2's 16-gon), resolution, and its
    inflation layer's ``inflation_radius`` and ``cost_scaling_factor`` (the first plugin of class InflationLayer)."""
    from ..controllers.registry import INFLATION_PLUGIN, plugin_key

    out = _default_costmap(params, "not in the file")
    for path in COSTMAPS[:2]:  # the local costmap only: the controller's
        costmap = _node(source.data, path)
        if costmap is None:
            continue
        where, keys = ".".join(path), (*path, PARAMETERS)
        footprint = costmap.get("footprint")
        if footprint not in (None, "", "[]", []):
            points = _footprint_points(source, f"{where}.footprint", (*keys, "footprint"), footprint)
            out["inscribed_radius"] = Nav2Setting(_inscribed_radius(points), f"{source.origin}: {where}.footprint = {footprint} "
                                                  "(its inscribed radius)")
        elif "robot_radius" in costmap:
            radius = _setting(source, params["robot_radius"], costmap, keys, where, "").value
            out["inscribed_radius"] = Nav2Setting(radius * math.cos(math.pi / 16), f"{source.origin}: {where}.robot_radius = {radius:g} m "
                                                  "(inscribed radius of Nav2's 16-gon)")
        if "resolution" in costmap:
            out["resolution"] = _setting(source, params["resolution"], costmap, keys, where, "")
        plugins = costmap.get("plugins", [])
        for name in plugins if isinstance(plugins, list) else ():
            layer = costmap.get(name)
            if isinstance(layer, dict) and isinstance(layer.get("plugin"), str) and plugin_key(layer["plugin"]) == INFLATION_PLUGIN:
                for key in ("inflation_radius", "cost_scaling_factor"):
                    if key in layer:
                        out[key] = _setting(source, params[key], layer, (*keys, name), f"{where}.{name}", "")
                break
        break
    return out


def _footprint_points(source, key, location, footprint) -> list:
    """A footprint's vertices [(x, y), …] (a list, or Nav2's string ``"[[x, y], …]"``), m."""
    error = source.error(f"{key} must be a polygon [[x, y], ...] of at least 3 points of finite numbers (m); got {footprint!r}", location)
    points = footprint
    if isinstance(footprint, str):
        try:
            points = parse_yaml(footprint)
        except InputError:
            raise error from None
    if not isinstance(points, list) or len(points) < 3:
        raise error
    if not all(isinstance(p, list) and len(p) == 2 and all(_finite(c) for c in p) for p in points):
        raise error
    return [(float(x), float(y)) for x, y in points]


def _inscribed_radius(points: list) -> float:
    """The footprint's inscribed radius as Nav2 computes it (``footprint.cpp``, ``calculateMinAndMaxDistances``): the
    smallest distance from the robot's centre to a vertex or an edge, m."""
    def to_edge(x0, y0, x1, y1):
        dx, dy = x1 - x0, y1 - y0
        t = -(x0 * dx + y0 * dy) / (dx * dx + dy * dy) if dx or dy else 0.0
        t = min(max(t, 0.0), 1.0)
        return math.hypot(x0 + t * dx, y0 + t * dy)

    edges = zip(points, points[1:] + points[:1])
    return min(min(math.hypot(x0, y0), to_edge(x0, y0, x1, y1)) for (x0, y0), (x1, y1) in edges)



# ------------------------------------------------------------------ the velocity smoother
def read_velocity_smoother(source: "YamlFile") -> tuple:
    """(values, notes): ``yaw_accel_limit`` and ``max_steering_rate`` from the velocity smoother's node, or ({}, ()) without it.

    Nav2's smoother (``applyConstraints``) moves its output each tick of its timer by at most ``max_accel/f`` while the
    command's magnitude grows with its sign, and by ``|max_decel|/f`` otherwise (f = ``smoothing_frequency``; the timer
    runs every ⌊1000/f⌋ ms, so the slope is (a/f)/(⌊1000/f⌋ ms)). A yaw oscillation decelerates towards zero and
    accelerates away from it each half period, so the ramp from one peak to the other takes as long as at the harmonic
    mean of the two slopes: that is R = ``yaw_accel_limit`` (the accelerating slope when they are equal). The command is
    clamped to [``min_velocity``, ``max_velocity``] first: ``max_steering_rate`` is the smaller of the two angular
    magnitudes. ``feedback: CLOSED_LOOP`` is noted (the models and the simulator take the open-loop rule).

    Parameters
    ----------
    source : io.yaml_files.YamlFile
        The parsed Nav2 file.

    Returns
    -------
    (dict, tuple of str)
        Parameter name → `Nav2Value`, and the notes.

    Raises
    ------
    ValueError
        A key of the wrong shape or out of Nav2's own range (a positive deceleration, lists of different lengths, …), or a
        smoother that cannot turn (angular acceleration or velocity limit 0), naming the key.
    """
    node = _node(source.data, (SMOOTHER,))
    if node is None:
        return {}, ()
    read = {key: node.get(key, default) for key, default in SMOOTHER_DEFAULTS.items()}
    missing = [key for key in SMOOTHER_DEFAULTS if key not in node]
    assumed = f"{', '.join(f'{SMOOTHER}.{k}' for k in missing)} not given: Nav2's default" if missing else None
    where = lambda key: (SMOOTHER, PARAMETERS, key)
    frequency = _check(source, f"{SMOOTHER}.smoothing_frequency", where("smoothing_frequency"), read["smoothing_frequency"], 0.0, 1000.0, "Hz")
    feedback = read["feedback"]
    if feedback not in FEEDBACKS:
        raise source.error(f"{SMOOTHER}.feedback must be one of {', '.join(FEEDBACKS)}; got {feedback!r}", where("feedback"))
    lists = {key: _axes(source, key, read[key], where(key)) for key in ("max_velocity", "min_velocity", "max_accel", "max_decel")}
    if len({len(v) for v in lists.values()}) != 1:
        raise source.error(f"{SMOOTHER}.max_velocity, min_velocity, max_accel and max_decel must have the same size (3 or 6); got "
                           + ", ".join(f"{k} {len(v)}" for k, v in lists.items()), (SMOOTHER, PARAMETERS))
    yaw = 2 if len(lists["max_accel"]) == 3 else 5
    accel, decel = lists["max_accel"][yaw], lists["max_decel"][yaw]
    top, bottom = lists["max_velocity"][yaw], lists["min_velocity"][yaw]
    for key, value, sign in (("max_accel", accel, 1), ("max_decel", decel, -1), ("max_velocity", top, 1), ("min_velocity", bottom, -1)):
        if not sign * value > 0:
            raise source.error(f"{SMOOTHER}.{key}[{yaw}] must be {'> 0' if sign > 0 else '< 0'} for a robot that turns; got {value!r}", where(key))
    tick = math.floor(1000.0 / frequency)  # ms, Nav2's timer (std::chrono::milliseconds of an int)
    if tick < 1:
        raise source.error(f"{SMOOTHER}.smoothing_frequency must be at most 1000 Hz (Nav2's timer runs every ⌊1000/f⌋ ms); got {frequency:g}",
                           where("smoothing_frequency"))
    slope = lambda a: a * 1000.0 / (frequency * tick)  # (a/f) per tick of tick ms
    up, down = slope(accel), slope(-decel)
    R = up if up == down else 2.0 * up * down / (up + down)
    rule = (f"per tick of smoothing_frequency {frequency:g} Hz ({tick} ms)" + ("" if up == down else
            f"; accelerating {up:.4g}, decelerating {down:.4g} rad/s^2: their harmonic mean"))
    if feedback == "CLOSED_LOOP":
        rule += "; feedback CLOSED_LOOP taken as OPEN_LOOP (docs/config.md)"
    values = {
        "yaw_accel_limit": Nav2Value("yaw_accel_limit", _in_range(source, "yaw_accel_limit", R, where("max_accel")),
                                     f"{SMOOTHER}.max_accel[{yaw}], max_decel[{yaw}]", f"{accel:g}, {decel:g}", "rad/s^2", rule, assumed),
        "max_steering_rate": Nav2Value("max_steering_rate", min(top, -bottom), f"{SMOOTHER}.max_velocity[{yaw}], min_velocity[{yaw}]",
                                       f"{top:g}, {bottom:g}", "rad/s", "the smaller magnitude", assumed),
    }
    notes = () if feedback == "OPEN_LOOP" else (
        f"{source.origin}: {SMOOTHER}.feedback is CLOSED_LOOP; the models and the simulator take the open-loop rule (the change from "
        "the smoother's last output), while a closed-loop smoother limits the change from the measured yaw rate, harder behind a "
        "lagged base",)
    return values, notes


def _axes(source, key, value, location) -> list:
    """A smoother list of 3 (x, y, θ) or 6 (x, y, z, roll, pitch, yaw) finite numbers."""
    if not (isinstance(value, list) and len(value) in (3, 6) and all(_finite(v) for v in value)):
        raise source.error(f"{SMOOTHER}.{key} must be a list of 3 or 6 finite numbers (Nav2's axes); got {value!r}", location)
    return [float(v) for v in value]


def _in_range(source, name, value, location) -> float:
    r = RANGES[name]
    return _check(source, f"{SMOOTHER} {name}", location, value, r.low, r.high, r.unit, low_open=r.low_open, high_open=r.high_open)
