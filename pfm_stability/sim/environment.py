"""Analytic environment: continuous walls with a chosen force law, no grid (docs/simulator.md).

KB's analysis (Koren & Borenstein 1991 §3, eq 8–9) replaces the cells of a
long wall by one lateral force F_r(d) normal to the wall. This module does
the same in the simulator, so the analysis can be validated without
quantization: each wall is a segment p0 → p1 with a free side; while the
robot's foot point lies on the segment, the wall pushes it along the
free-side normal with F_r(d)/F_ct = law(d), d the distance robot centre →
wall line. The law is any `pfm_stability.laws.force_law.ForceLaw` (KB's lumped
power law f(W/d)^n by default, or the grid's `GridWallLaw` for the grid
without its quantization). A corridor is two walls:
F_x = F_r(L + x) − F_r(L − x).

A collision is the robot disc (diameter W) touching a wall segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_number

__all__ = ["AnalyticWall", "AnalyticEnvironment", "corridor_walls"]

_LONG = 1.0e4
"""Half-length (m) used for "infinite" walls."""


@dataclass(frozen=True)
class AnalyticWall:
    """A straight wall segment that pushes with F_r(d) along its free-side normal.

    Parameters
    ----------
    p0, p1 : (float, float)
        End points, m.
    free_side : {"left", "right"}
        Side of the direction p0 → p1 where the robot travels.
    """

    p0: tuple
    p1: tuple
    free_side: str = "left"

    def __post_init__(self):
        p0 = tuple(check_number("wall point", float(v), unit="m") for v in self.p0)
        p1 = tuple(check_number("wall point", float(v), unit="m") for v in self.p1)
        if p0 == p1:
            raise ValueError("wall must have p0 != p1")
        object.__setattr__(self, "p0", p0)
        object.__setattr__(self, "p1", p1)
        check_choice("free_side", self.free_side, ("left", "right"))

    @property
    def length(self) -> float:
        return math.hypot(self.p1[0] - self.p0[0], self.p1[1] - self.p0[1])

    @property
    def unit(self) -> tuple[float, float]:
        """Unit vector p0 → p1."""
        L = self.length
        return ((self.p1[0] - self.p0[0]) / L, (self.p1[1] - self.p0[1]) / L)

    @property
    def normal(self) -> tuple[float, float]:
        """Unit normal pointing into the free side (the direction of the push)."""
        ux, uy = self.unit
        return (-uy, ux) if self.free_side == "left" else (uy, -ux)


@dataclass(frozen=True)
class AnalyticEnvironment:
    """A set of analytic walls.

    Parameters
    ----------
    walls : tuple of AnalyticWall
        May be empty (open field).
    """

    walls: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "walls", tuple(self.walls))
        for w in self.walls:
            if not isinstance(w, AnalyticWall):
                raise ValueError(f"walls must be AnalyticWall objects; got {type(w).__name__}")

    def arrays(self) -> dict:
        """Wall geometry as arrays (one entry per wall): p0x, p0y, ux, uy, nx, ny, length."""
        out = {key: [] for key in ("p0x", "p0y", "ux", "uy", "nx", "ny", "length")}
        for w in self.walls:
            ux, uy = w.unit
            nx, ny = w.normal
            for key, value in zip(out, (w.p0[0], w.p0[1], ux, uy, nx, ny, w.length)):
                out[key].append(value)
        return {key: np.array(value, dtype=float) for key, value in out.items()}

    def clearance(self, x, y) -> np.ndarray:
        """Distance from points to the nearest wall segment, m (brute force).

        Parameters
        ----------
        x, y : array_like
            Points, m.
        """
        x = np.atleast_1d(np.asarray(x, float))
        if not self.walls:
            return np.full(x.shape, math.inf)
        return segment_clearance(self.arrays(), x[:, None], np.atleast_1d(np.asarray(y, float))[:, None])


def wall_coordinates(walls: dict, px, py):
    """(s, d): position along each wall from p0 and signed distance to its line (> 0 on the free side), m."""
    rx = px - walls["p0x"]
    ry = py - walls["p0y"]
    return rx * walls["ux"] + ry * walls["uy"], rx * walls["nx"] + ry * walls["ny"]


def segment_clearance(walls: dict, px, py) -> np.ndarray:
    """Distance from each robot centre to the nearest wall segment (last axis = walls), m."""
    s, d = wall_coordinates(walls, px, py)
    along = np.maximum(np.maximum(-s, s - walls["length"]), 0.0)
    valid = walls.get("valid", True)
    dist = np.where(valid, np.hypot(along, d), math.inf)
    return np.min(dist, axis=-1)


def corridor_walls(L: float, y_from: float = -_LONG, y_to: float = _LONG, centre: float = 0.0) -> tuple:
    """The two walls of a straight corridor along Y, half-width L (m), centred on X = `centre`.

    Parameters
    ----------
    L : float
        Half-width, m.
    y_from, y_to : float
        Where the walls begin and end along Y, m.
    centre : float
        X of the corridor's axis, m.
    """
    L = check_number("L", L, 0.0, unit="m")
    return (
        AnalyticWall((centre - L, y_from), (centre - L, y_to), free_side="right"),
        AnalyticWall((centre + L, y_from), (centre + L, y_to), free_side="left"),
    )
