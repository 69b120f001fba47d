"""Start the speed mask of `pfm-stability map --out-dir out` for Nav2 (docs/maps.md, "The speed mask").

    ros2 launch speed_filter.launch.py params_file:=speed_filter_params.yaml mask:=out/speed_mask.yaml

A map server publishing the mask, the costmap filter info server telling the SpeedFilter
where it is and how to read it (type 1: percent), and a lifecycle manager bringing both up;
the SpeedFilter itself is a plugin of the costmap (speed_filter_params.yaml).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    params_file = LaunchConfiguration("params_file")
    mask = LaunchConfiguration("mask")
    return LaunchDescription([
        DeclareLaunchArgument("params_file", default_value="speed_filter_params.yaml"),
        DeclareLaunchArgument("mask", default_value="out/speed_mask.yaml"),
        Node(package="nav2_map_server", executable="map_server", name="filter_mask_server", output="screen",
             parameters=[params_file, {"yaml_filename": mask}]),
        Node(package="nav2_map_server", executable="costmap_filter_info_server", name="costmap_filter_info_server",
             output="screen", parameters=[params_file]),
        Node(package="nav2_lifecycle_manager", executable="lifecycle_manager", name="lifecycle_manager_costmap_filters",
             output="screen", parameters=[params_file]),
    ])
