"""The lookahead per zone: a Nav2 ZoneParameterFilter mask and its parameters file (``map --controller rpp --out-dir``;
docs/maps.md, "Nav2's controllers along a map").

Format per PR #6104 of ros-navigation/navigation2 ("[costmap_filters] Add ZoneParameterFilter", merged as commit
ea95cc394, 2026-08-11), as read in ``nav2_costmap_2d/plugins/costmap_filters/zone_parameter_filter.cpp`` and
``filter_values.hpp`` of the repository's snapshot at commit a3a97043 (2026-08-21):

* the plugin ``nav2_costmap_2d::ZoneParameterFilter`` in a costmap's ``filters``, with ``filter_info_topic``;
  ``states`` (names), each state ``<state>.id`` (the mask value that selects it, 1 … 255; 0 resets) and
  ``<state>.setpoints`` (names), each setpoint ``{node, parameter, value}``; ``nominal_defaults`` (names), each
  ``nominal_defaults.<name>`` ``{node, parameter, value}``: the values restored in state 0 (and for a parameter the
  next state does not set); ``state_event_topic`` (default ``zone_filter_state``);
* the mask is a ``nav_msgs/OccupancyGrid`` (a ``filter_mask_server``'s map): a cell's value is the state, <0 (unknown)
  leaves the state unchanged; the ``costmap_filter_info_server`` has ``type: 4`` (``ZONE_PARAMETER_FILTER``),
  ``base: 0.0``, ``multiplier: 1.0`` (others are ignored with a warning).

The mask's cells hold 0 (the file's lookahead) except within W/2 of each stretch with a zone lookahead
(`maps.deciding.tracking.TrackingStretch.zone_lookahead`), which hold the state of that lookahead; the states are numbered
1 … n by increasing lookahead (a cell covered by two zones takes the longer). The OccupancyGrid's values are
0 … 100 (map_server's scale mode), so at most `MAX_STATES` states: the lookaheads are rounded up to a coarser step
until they fit. The PGM is written in the speed mask's scale mode (`outputs.percent_to_pixel`: the value read back is
the state, exactly). The nominal default is the Nav2 file's (or Nav2's declared) value of the lookahead parameter.
Nav2's docs page for the filter was not in the docs snapshot read (docs.nav2.org 9d30140, 2026-07-22); the YAML's
dotted key ``nominal_defaults.<name>`` is this tool's way to give the entries of a list that shares their name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .outputs import percent_to_pixel, speed_mask_yaml, stamp_stretch

__all__ = ["FORMAT_SOURCE", "MAX_STATES", "ZONE_FILES", "ZoneState", "zone_mask", "zone_mask_pgm", "zone_mask_yaml", "zone_params_yaml",
           "zone_states"]

FORMAT_SOURCE = ("format per PR #6104 (ros-navigation/navigation2, merged as ea95cc394 on 2026-08-11) as of the snapshot "
                 "a3a97043 (2026-08-21): nav2_costmap_2d/plugins/costmap_filters/zone_parameter_filter.cpp, loadStateConfig")
"""Where the format was read (written into the parameters file)."""
MAX_STATES = 100
"""Most states a mask carries: an OccupancyGrid's values are 0 … 100."""
ZONE_FILES = ("zone_mask.pgm", "zone_mask.yaml", "zone_params.yaml")
"""What ``--out-dir`` receives for a Nav2 controller besides the speed mask."""
NODE = "controller_server"
"""The node whose parameter the states set."""


@dataclass(frozen=True)
class ZoneState:
    """One state of the ZoneParameterFilter: the mask value and the lookahead it sets.

    Attributes
    ----------
    id : int
        The mask value, 1 … `MAX_STATES`.
    lookahead : float
        m.
    """

    id: int
    lookahead: float

    @property
    def name(self) -> str:
        """The state's name in the parameters file."""
        return f"lookahead_{self.id}"


def _zone_values(analysis) -> list:
    """Each stretch's zone lookahead, rounded up to a step at which at most `MAX_STATES` distinct values remain (m; None:
    no zone)."""
    values = [s.zone_lookahead for s in analysis.paths.stretches]
    cap = analysis.tracker.values()["max_lookahead_dist"]
    step = 0.01
    while len({v for v in values if v is not None}) > MAX_STATES:
        step *= 2.0
        values = [None if v is None else min(math.ceil(round(v / step, 9)) * step, cap) for v in values]
    return values


def zone_states(analysis) -> tuple:
    """The states (`ZoneState`), by increasing lookahead.

    Parameters
    ----------
    analysis : MapTracking
        ``map --controller`` (`maps.deciding.tracking.analyze_map_tracking`).
    """
    distinct = sorted({v for v in _zone_values(analysis) if v is not None})
    return tuple(ZoneState(k + 1, float(v)) for k, v in enumerate(distinct))


def zone_mask(analysis) -> np.ndarray:
    """The state per map cell (int, shape (height, width), row 0 at y = origin): 0, or the state of the longest zone
    lookahead among the stretches within W/2 of the cell.

    Parameters
    ----------
    analysis : MapTracking
    """
    occupancy, pv = analysis.occupancy, analysis.paths
    ids = {s.lookahead: s.id for s in zone_states(analysis)}
    mask = np.zeros(occupancy.values.shape, dtype=np.int64)
    for stretch, value in zip(pv.stretches, _zone_values(analysis)):
        if value is not None:
            stamp_stretch(mask, occupancy, pv.paths[stretch.route].points, stretch, 0.0, analysis.robot.W / 2, ids[float(value)], np.maximum)
    return mask


def zone_mask_pgm(analysis) -> bytes:
    """The zone mask as a binary PGM (P5, row 0 at the top), read in scale mode (`zone_mask_yaml`): each pixel's value
    reads back as its state.

    Parameters
    ----------
    analysis : MapTracking
    """
    pixels = percent_to_pixel(zone_mask(analysis))[::-1]
    height, width = pixels.shape
    return f"P5\n{width} {height}\n255\n".encode("ascii") + np.ascontiguousarray(pixels).tobytes()


def zone_mask_yaml(occupancy) -> str:
    """The zone mask's map_server YAML (the speed mask's: scale mode, thresholds that make the mapping exact).

    Parameters
    ----------
    occupancy : OccupancyMap
    """
    return speed_mask_yaml(occupancy, image=ZONE_FILES[0])


def zone_params_yaml(analysis) -> str:
    """The ZoneParameterFilter's parameters (module docstring): the filter in the local costmap, its states, the nominal
    default, the filter mask server and the costmap filter info server.

    Parameters
    ----------
    analysis : MapTracking
    """
    tracker = analysis.tracker
    parameter = f"{tracker.plugin_id}.{analysis.paths.lookahead_parameter}"
    nominal = tracker.values()[analysis.paths.lookahead_parameter]
    states = zone_states(analysis)
    lines = [f"# Nav2 ZoneParameterFilter: the lookahead per zone for {tracker.controller} ({parameter}), pfm-stability map",
             f"# {FORMAT_SOURCE}.",
             "# Mask values: 0 = the nominal lookahead; each state's id selects it (zone_mask.pgm, scale mode).",
             "local_costmap:", "  local_costmap:", "    ros__parameters:", '      filters: ["zone_params"]', "      zone_params:",
             '        plugin: "nav2_costmap_2d::ZoneParameterFilter"', "        enabled: true",
             '        filter_info_topic: "/zone_filter_info"', '        state_event_topic: "zone_filter_state"',
             f"        states: [{', '.join(repr(s.name).replace(chr(39), chr(34)) for s in states)}]"]
    for s in states:
        lines += [f"        {s.name}:", f"          id: {s.id}", '          setpoints: ["lookahead"]',
                  f'          lookahead: {{node: "{NODE}", parameter: "{parameter}", value: {s.lookahead:.4g}}}']
    lines += ['        nominal_defaults: ["lookahead"]',
              f'        nominal_defaults.lookahead: {{node: "{NODE}", parameter: "{parameter}", value: {float(nominal):.6g}}}',
              "zone_filter_mask_server:", "  ros__parameters:", '    topic_name: "/zone_filter_mask"',
              f'    yaml_filename: "{ZONE_FILES[1]}"', "zone_costmap_filter_info_server:", "  ros__parameters:",
              "    type: 4                      # ZONE_PARAMETER_FILTER", '    filter_info_topic: "/zone_filter_info"',
              '    mask_topic: "/zone_filter_mask"', "    base: 0.0", "    multiplier: 1.0"]
    return "\n".join(lines) + "\n"
