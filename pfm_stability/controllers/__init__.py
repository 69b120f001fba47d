"""Nav2's path-tracking controllers as the algorithms Nav2 runs (docs/controllers.md).

Each controller is one module with a frozen parameters dataclass (Nav2's parameter names and declared defaults,
the source file cited) and one decision per control cycle,

    command(state, plan, costmap, params, rng=None, memory=None) -> Command(v, w, memory)

a pure, seeded function of the robot's pose and measured velocity (`RobotState`), the global plan (`Plan`), the
local costmap (`CorridorCostmap`: a straight corridor's walls with Nav2's inflation, as a grid of cells or as
the exact function) and the parameters; what Nav2 keeps between cycles goes in and out as ``memory``.

=========  ==================================================  ============================================
name       module                                              Nav2 package
=========  ==================================================  ============================================
rpp        `controllers.rpp` (Regulated Pure Pursuit)          nav2_regulated_pure_pursuit_controller
graceful   `controllers.graceful` (smooth control law)         nav2_graceful_controller
mppi       `controllers.mppi` (Model Predictive Path Integral)  nav2_mppi_controller
dwb        `controllers.dwb` (Dynamic Window, critics)         nav2_dwb_controller (dwb_core, dwb_plugins, dwb_critics)
=========  ==================================================  ============================================

`controllers.linearize` turns any of them into the lateral gains of a linear steering loop about a straight plan
(k_y, k_θ and the measured yaw rate's share, with their sampling uncertainty). The package is numpy only and
sits beside `laws` (level 2, docs/architecture.md): the simulator drives these functions, the loop models
never see them.
"""

from __future__ import annotations

import importlib

from .base import Command, NoValidControl, RobotState, normalize_angle
from .costmap import CorridorCostmap, Inflation, Window
from .linearize import LateralGains, configure, equilibrium_speed, linearize
from .plan import LocalPlan, Plan, local_plan, lookahead_point, straight_plan, to_robot_frame

__all__ = [
    "CONTROLLER_NAMES",
    "Command",
    "CorridorCostmap",
    "Inflation",
    "LateralGains",
    "LocalPlan",
    "NoValidControl",
    "Plan",
    "RobotState",
    "Window",
    "configure",
    "controller_module",
    "default_params",
    "equilibrium_speed",
    "linearize",
    "local_plan",
    "lookahead_point",
    "normalize_angle",
    "straight_plan",
    "to_robot_frame",
]

CONTROLLER_NAMES = ("rpp", "graceful", "mppi", "dwb")
"""The Nav2 controllers modelled, by their short names (one module each)."""

_PARAMS = {"rpp": "RPPParams", "graceful": "GracefulParams", "mppi": "MPPIParams", "dwb": "DWBParams"}


def controller_module(name: str):
    """The module of a controller (its ``command``, parameters class, ``with_speed``, ``LINEARIZATION_STEPS``).

    Parameters
    ----------
    name : str
        One of `CONTROLLER_NAMES`.
    """
    if name not in CONTROLLER_NAMES:
        raise ValueError(f"controller must be one of {', '.join(CONTROLLER_NAMES)}; got {name!r}")
    return importlib.import_module(f"{__name__}.{name}")


def default_params(name: str):
    """A controller's parameters with Nav2's defaults.

    Parameters
    ----------
    name : str
        One of `CONTROLLER_NAMES`.
    """
    return getattr(controller_module(name), _PARAMS[name])()
