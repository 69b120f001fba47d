"""What every Nav2 controller of `pfm_stability.controllers` reads and returns (docs/controllers.md).

A controller's decision is a function of the robot's state (pose and measured velocity, ROS conventions: x
forward along the plan, y to the left, yaw counter-clockwise, rad), the global plan (`controllers.plan.Plan`),
the local costmap (`controllers.costmap`) and its parameters; it returns a `Command` (the ``cmd_vel`` twist).
Controllers that keep state between cycles in Nav2 (MPPI's control sequence, DWB's oscillation flags) take it
as ``memory`` and hand the next cycle's back in `Command.memory`: the function stays pure, and a caller that
drops the memory restarts the controller as Nav2's ``reset()`` does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..checks import check_number

__all__ = ["RobotState", "Command", "NoValidControl", "normalize_angle", "controller_module", "default_params"]


@dataclass(frozen=True)
class RobotState:
    """The robot's pose and measured velocity, as the controller server hands them to a controller.

    Attributes
    ----------
    x, y : float
        Position in the costmap's global frame, m.
    yaw : float
        Heading, rad (counter-clockwise from the x axis).
    v : float
        Measured forward speed (odometry's ``linear.x``), m/s.
    w : float
        Measured yaw rate (odometry's ``angular.z``), rad/s.
    """

    x: float
    y: float
    yaw: float
    v: float = 0.0
    w: float = 0.0

    def __post_init__(self):
        for name in ("x", "y", "yaw", "v", "w"):
            object.__setattr__(self, name, check_number(name, getattr(self, name)))

    def replace(self, **changes) -> "RobotState":
        """A copy with some fields changed.

        Parameters
        ----------
        **changes
            Field values (m, rad, m/s, rad/s).
        """
        return RobotState(**{**self.__dict__, **changes})


@dataclass(frozen=True)
class Command:
    """A controller's decision for one cycle: the ``cmd_vel`` twist, and its state for the next cycle.

    Attributes
    ----------
    v : float
        Forward speed, m/s.
    w : float
        Yaw rate, rad/s.
    memory : object, optional
        What the controller keeps until its next cycle (None for a stateless controller).
    """

    v: float
    w: float
    memory: Any = None


class NoValidControl(RuntimeError):
    """The controller found no command (Nav2's ``nav2_core::NoValidControl``): every trajectory collides."""


def normalize_angle(angle):
    """An angle wrapped to [−π, π), rad (``angles::normalize_angle``; arrays element-wise).

    Parameters
    ----------
    angle : float or ndarray
        Radians.
    """
    a = np.asarray(angle)
    wrapped = np.mod(a + math.pi, 2.0 * math.pi) - math.pi
    return float(wrapped) if np.ndim(wrapped) == 0 else wrapped


_PARAMS = {"rpp": "RPPParams", "graceful": "GracefulParams", "mppi": "MPPIParams", "dwb": "DWBParams"}
"""Each Nav2 controller's parameters class, in its module."""


def controller_module(name: str):
    """The module of a Nav2 controller (its ``command``, parameters class, ``with_speed``, ``LINEARIZATION_STEPS``).

    Parameters
    ----------
    name : str
        One of `controllers.registry.NAV2_CONTROLLERS`.
    """
    import importlib

    from .registry import NAV2_CONTROLLERS

    if name not in NAV2_CONTROLLERS:
        raise ValueError(f"controller must be one of {', '.join(NAV2_CONTROLLERS)}; got {name!r}")
    return importlib.import_module(f"{__package__}.{name}")


def default_params(name: str):
    """A Nav2 controller's parameters with Nav2's defaults.

    Parameters
    ----------
    name : str
        One of `controllers.registry.NAV2_CONTROLLERS`.
    """
    return getattr(controller_module(name), _PARAMS[name])()
