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

__all__ = ["SPEED_KEYS", "Nav2Value", "Nav2Values", "is_nav2", "read_nav2"]

PARAMETERS = "ros__parameters"
SPEED_KEYS = ("max_vel_x", "max_speed_xy", "desired_linear_vel", "vx_max")
"""The speed keys of a controller plugin, in the order they are tried (DWB, DWB, Regulated Pure Pursuit, MPPI)."""
COSTMAPS = (("local_costmap", "local_costmap"), ("local_costmap",), ("global_costmap", "global_costmap"), ("global_costmap",))
"""Where the robot's footprint is looked for, in order."""
_FREQUENCY = (1.0 / RANGES["T"].high, 1e6)  # Hz: T = 1/f within (0, 100] s


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
    """

    name: str
    value: float
    key: str
    given: object
    unit: str

    def describe(self) -> str:
        """E.g. ``controller_server.controller_frequency = 20 Hz``."""
        given = f"{self.given:g}" if isinstance(self.given, (int, float)) else str(self.given)
        return f"{self.key} = {given}" + (f" {self.unit}" if self.unit else "")


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
    """The y of each vertex of a footprint (a list, or Nav2's string ``"[[x, y], …]"``, read by the file rule), m."""
    error = source.error(f"{key} must be a polygon [[x, y], ...] of at least 3 points of finite numbers (m); got {footprint!r}", location)
    points = footprint
    if isinstance(footprint, str):
        try:
            points = parse_yaml(footprint)
        except InputError:
            raise error from None
    if not isinstance(points, list) or len(points) < 3:
        raise error
    ys = []
    for point in points:
        if not (isinstance(point, list) and len(point) == 2 and all(_finite(c) for c in point)):
            raise error
        ys.append(float(point[1]))
    return ys


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check(source, key, location, value, low, high, unit, *, low_open=True, high_open=False) -> float:
    try:
        return check_number(key, value, low, high, low_open=low_open, high_open=high_open, unit=unit)
    except ValueError as exc:
        raise source.error(str(exc), location) from None
