"""The shipped Nav2 speed-filter parameters and launch example (pfm_stability/data/nav2, docs/maps.md "The speed mask").

The keys are checked against a table written from Nav2's documentation (docs.nav2.org, "Costmap Filters" →
"Speed Filter" parameters of nav2_costmap_2d::SpeedFilter, and the parameters of nav2_map_server's
costmap_filter_info_server and map_server): a key Nav2 does not read would be silently ignored by it.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import yaml

NAV2 = Path(str(resources.files("pfm_stability").joinpath("data", "nav2")))

DOCUMENTED = {
    # nav2_map_server costmap_filter_info_server: type (0 keepout/preferred lanes, 1 speed limit in percent,
    # 2 speed limit in absolute values, 3 binary), filter_info_topic, mask_topic, base, multiplier
    "costmap_filter_info_server": {"use_sim_time", "type", "filter_info_topic", "mask_topic", "base", "multiplier"},
    # nav2_map_server map_server serving the mask
    "filter_mask_server": {"use_sim_time", "frame_id", "topic_name", "yaml_filename"},
    # nav2_lifecycle_manager
    "lifecycle_manager_costmap_filters": {"use_sim_time", "autostart", "node_names"},
    # nav2_costmap_2d::SpeedFilter (a costmap filter plugin)
    "speed_filter": {"plugin", "enabled", "filter_info_topic", "speed_limit_topic"},
    # nav2_controller controller_server
    "controller_server": {"speed_limit_topic"},
}
"""Each node's (or plugin's) parameters used here, as Nav2 documents them."""


def test_speed_filter_parameters_use_only_documented_keys():
    """Every parameter of the shipped file is one Nav2 documents for its node; the filter reads percentages
    (type 1) as the mask holds them (base 0, multiplier 1), and the topics the three parts share agree."""
    doc = yaml.safe_load((NAV2 / "speed_filter_params.yaml").read_text())
    nodes = {name: doc[name]["ros__parameters"] for name in ("costmap_filter_info_server", "filter_mask_server",
                                                             "lifecycle_manager_costmap_filters", "controller_server")}
    costmap = doc["global_costmap"]["global_costmap"]["ros__parameters"]
    nodes["speed_filter"] = costmap["speed_filter"]
    for name, params in nodes.items():
        assert set(params) <= DOCUMENTED[name], (name, set(params) - DOCUMENTED[name])
    info, mask, speed = nodes["costmap_filter_info_server"], nodes["filter_mask_server"], nodes["speed_filter"]
    assert info["type"] == 1 and info["base"] == 0.0 and info["multiplier"] == 1.0
    assert info["mask_topic"] == mask["topic_name"] and info["filter_info_topic"] == speed["filter_info_topic"]
    assert speed["plugin"] == "nav2_costmap_2d::SpeedFilter" and "speed_filter" in costmap["filters"]
    assert speed["speed_limit_topic"] == nodes["controller_server"]["speed_limit_topic"]
    assert set(nodes["lifecycle_manager_costmap_filters"]["node_names"]) == {"filter_mask_server", "costmap_filter_info_server"}


def test_launch_example_starts_the_nodes_the_parameters_name():
    """The launch example (ROS 2 XML launch) starts the parameter file's nodes — the mask server (nav2_map_server's
    map_server), the costmap_filter_info_server, the lifecycle manager — each reading that file."""
    import xml.etree.ElementTree as ET

    root = ET.parse(NAV2 / "speed_filter.launch.xml").getroot()
    nodes = {n.get("name"): (n.get("pkg"), n.get("exec")) for n in root.iter("node")}
    assert nodes == {"filter_mask_server": ("nav2_map_server", "map_server"),
                     "costmap_filter_info_server": ("nav2_map_server", "costmap_filter_info_server"),
                     "lifecycle_manager_costmap_filters": ("nav2_lifecycle_manager", "lifecycle_manager")}
    assert all(any(p.get("from") == "$(var params_file)" for p in n.iter("param")) for n in root.iter("node"))
