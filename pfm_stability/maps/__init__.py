"""Real occupancy maps: where along a building's corridors a VFF robot oscillates (docs/maps.md).

`occupancy` reads a ROS ``map_server`` map exactly as Nav2 does; `field` reduces it
onto the robot's histogram grid and computes the VFF repulsion; `routes` finds the
corridors (the medial axis of the free space) as straight segments; `analysis`
decides every segment with the loop models (N, c, V*, margin, verdict); `outputs`
writes segments.csv and a Nav2 Speed Filter mask.
"""

from .analysis import MapAnalysis, MapSegment, analyze_map
from .occupancy import OccupancyMap, load_map

__all__ = ["MapAnalysis", "MapSegment", "OccupancyMap", "analyze_map", "load_map"]
