"""Nav2's path-tracking controllers as the algorithms Nav2 runs, and their registry (docs/controllers.md, docs/path_tracking.md).

Each controller is one module with a frozen parameters dataclass (Nav2's parameter names and declared defaults,
the source file cited) and one decision per control cycle,

    command(state, plan, costmap, params, rng=None, memory=None) -> Command(v, w, memory)

a pure, seeded function of the robot's pose and measured velocity (`base.RobotState`), the global plan (`plan.Plan`),
the local costmap (`costmap.CorridorCostmap`: a straight corridor's walls with Nav2's inflation, as a grid of cells or
as the exact function) and the parameters; what Nav2 keeps between cycles goes in and out as ``memory``.

=========  ==================================================  ============================================
name       module                                              Nav2 package
=========  ==================================================  ============================================
rpp        `controllers.rpp` (Regulated Pure Pursuit)          nav2_regulated_pure_pursuit_controller
graceful   `controllers.graceful` (smooth control law)         nav2_graceful_controller
mppi       `controllers.mppi` (Model Predictive Path Integral)  nav2_mppi_controller
dwb        `controllers.dwb` (Dynamic Window, critics)         nav2_dwb_controller (dwb_core, dwb_plugins, dwb_critics)
=========  ==================================================  ============================================

`controllers.linearize` turns any of them into the lateral gains of a linear steering loop about a straight plan
(k_y, k_θ and the measured yaw rate's share, with their sampling uncertainty). `controllers.registry` (numpy-free,
level 0) declares every controller's names, plugins and parameters once, so that the command line reads it without
loading numpy. The algorithms are numpy only and sit beside `laws` (level 2, docs/architecture.md): the simulator
drives them, the loop models never see them.

Nothing is imported here: import the module you need (``from pfm_stability.controllers.linearize import linearize``).
"""

__all__ = []
