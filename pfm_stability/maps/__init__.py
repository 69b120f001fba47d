"""Real occupancy maps: where along a building's corridors a VFF robot oscillates (docs/maps.md).

Three parts, each its own package (docs/maps.md, "Where each part lives"): `reading` a map (the occupancy map as
Nav2 reads it, its histogram grid and VFF field, the routes, the planner, where the robot's disc meets an obstacle),
`deciding` it (equilibria, the verdict rule, the stretches and their V*, the outputs, Nav2's RPP along the routes)
and `judging` a lateral motion (the oscillation episode and its thresholds, the loop driven along a route). `analysis` runs them in order: `analyze_map`.
"""

from .analysis import MapAnalysis, MapSegment, analyze_map
from .reading.occupancy import OccupancyMap, load_map

__all__ = ["MapAnalysis", "MapSegment", "OccupancyMap", "analyze_map", "load_map"]
