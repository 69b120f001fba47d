"""Targets and obstacles of the planar simulator: fixed or moving at constant velocity (docs/simulator.md).

Ge & Cui 2002 (GC2002) plan among moving obstacles towards a moving target whose
position and velocity the field knows (eq 1, 10, 14). Here each object moves at
a constant velocity from where it is at t = 0; `Wall` is the whole line through
`point` with unit `normal` pointing to the robot's side (a half-plane boundary),
`PointObstacle` a point and `Ball` a disc. `geometry` gives what the field needs
at time t: the clearance ρ_s (m), the unit vector from the obstacle to the robot
(the repulsion's direction, −n_RO of eq 10) and the `where` argument of
`velocity_laws.VelocityGatedRepulsion.evaluate`. `Pull` is a target at infinity: a constant
attraction (Koren & Borenstein's wall runs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_number

__all__ = ["Ball", "Obstacle", "PointObstacle", "Pull", "Target", "Wall", "vector"]


def vector(name: str, value, *, unit: bool = False) -> tuple:
    """A finite 2-vector (x, y) as a tuple of floats (unit: normalised, not 0); ValueError naming `name`.

    Parameters
    ----------
    name : str
        The name error messages give it.
    value : sequence of two numbers
        The vector.
    unit : bool
        Normalise it (a zero vector is then an error).
    """
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        v = np.array([math.nan])
    if v.shape != (2,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be a finite 2-vector (x, y); got {value!r}")
    if unit:
        r = math.hypot(*v)
        if not r > 0:
            raise ValueError(f"{name} must be a non-zero 2-vector (a direction); got {value!r}")
        v = v / r
    return (float(v[0]), float(v[1]))


@dataclass(frozen=True)
class Target:
    """A target at `position` (m) at t = 0, moving at constant `velocity` (m/s); the field knows both.

    Attributes
    ----------
    position : (float, float)
        Position at t = 0, m.
    velocity : (float, float)
        Constant velocity, m/s.
    """

    position: tuple
    velocity: tuple = (0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "position", vector("target position", self.position))
        object.__setattr__(self, "velocity", vector("target velocity", self.velocity))

    def at(self, t: float):
        """(p_tar, v_tar) at time t (s), numpy 2-vectors.

        Parameters
        ----------
        t : float
            Time, s.
        """
        v = np.array(self.velocity)
        return np.array(self.position) + v * t, v


@dataclass(frozen=True)
class Pull:
    """A constant attraction towards a target at infinity: `magnitude` (N) along angle `direction` (rad from +x).

    Attributes
    ----------
    magnitude : float
        The force, N.
    direction : float
        Its direction, rad from +x.
    """

    magnitude: float
    direction: float

    def __post_init__(self):
        object.__setattr__(self, "magnitude", check_number("magnitude", self.magnitude, 0.0, 1e12, high_open=False, unit="N"))
        object.__setattr__(self, "direction", check_number("direction", self.direction, -10.0, 10.0, unit="rad"))

    @property
    def unit(self) -> np.ndarray:
        """The pull's direction as a unit vector."""
        return np.array([math.cos(self.direction), math.sin(self.direction)])


class Obstacle:
    """Base class: `kind` ("wall", "point", "ball"), a constant `velocity` (m/s), and `geometry`."""

    kind = ""
    velocity: tuple

    def geometry(self, p, t: float):  # pragma: no cover - interface
        """(clearance ρ_s in m, unit vector obstacle → robot, `where` for `evaluate`) at robot position p, time t.

        Parameters
        ----------
        p : ndarray, shape (2,)
            The robot's position, m.
        t : float
            Time, s.
        """
        raise NotImplementedError


@dataclass(frozen=True)
class Wall(Obstacle):
    """A straight wall: the line through `point` (m, at t = 0) with unit `normal` towards the robot's side.

    The clearance is the signed distance (p − point(t))·normal; the robot lives where it is > 0.

    Attributes
    ----------
    point : (float, float)
        A point of the wall at t = 0, m.
    normal : (float, float)
        Unit normal towards the robot's side.
    velocity : (float, float)
        Constant velocity, m/s.
    """

    point: tuple
    normal: tuple
    velocity: tuple = (0.0, 0.0)
    kind = "wall"

    def __post_init__(self):
        object.__setattr__(self, "point", vector("wall point", self.point))
        object.__setattr__(self, "normal", vector("wall normal", self.normal, unit=True))
        object.__setattr__(self, "velocity", vector("wall velocity", self.velocity))

    def geometry(self, p, t: float):
        q = np.array(self.point) + np.array(self.velocity) * t
        n = np.array(self.normal)
        return float((p - q) @ n), n, np.array([q, n])


@dataclass(frozen=True)
class PointObstacle(Obstacle):
    """A point obstacle at `position` (m, at t = 0) moving at `velocity` (m/s).

    Attributes
    ----------
    position : (float, float)
        Position at t = 0, m.
    velocity : (float, float)
        Constant velocity, m/s.
    """

    position: tuple
    velocity: tuple = (0.0, 0.0)
    kind = "point"
    radius = 0.0

    def __post_init__(self):
        object.__setattr__(self, "position", vector("obstacle position", self.position))
        object.__setattr__(self, "velocity", vector("obstacle velocity", self.velocity))

    def geometry(self, p, t: float):
        c = np.array(self.position) + np.array(self.velocity) * t
        r = p - c
        R = math.hypot(*r)
        away = r / R if R > 0 else np.array([1.0, 0.0])
        return R - self.radius, away, c


@dataclass(frozen=True)
class Ball(Obstacle):
    """A disc of `radius` (m) centred at `position` (m, at t = 0), moving at `velocity` (m/s).

    The repulsion's tangential part uses the centre distance (the true gradient,
    docs/velocity_and_fuzzy.md), which `VelocityGatedRepulsion.evaluate` does.

    Attributes
    ----------
    position : (float, float)
        Centre at t = 0, m.
    radius : float
        Radius, m.
    velocity : (float, float)
        Constant velocity, m/s.
    """

    position: tuple
    radius: float = 0.0
    velocity: tuple = (0.0, 0.0)
    kind = "ball"

    def __post_init__(self):
        object.__setattr__(self, "position", vector("obstacle position", self.position))
        object.__setattr__(self, "radius", check_number("radius", self.radius, 0.0, 1e4, unit="m"))
        object.__setattr__(self, "velocity", vector("obstacle velocity", self.velocity))

    geometry = PointObstacle.geometry
