"""Reading a map (docs/maps.md, "Where each part lives"): the ROS occupancy map as Nav2 reads it (`occupancy`), its
histogram grid and the VFF window sum (`field`), the routes — the skeleton's and the user's (`routes`, `user_routes`)
— the global plan a drive follows (`planner`), and where the robot's disc meets an obstacle across a route
(`contact`). Nothing here decides stability."""

__all__ = []
