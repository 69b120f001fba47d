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
