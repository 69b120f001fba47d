"""The virtual force field controller (Koren & Borenstein 1991 §2, eq 1–5).

Forces are in units of the target force constant F_ct, so the attraction
(eq 3) is a unit vector and the repulsion of an active cell (eq 1) is

    F_ij/F_ct = ρ · C_ij · Wⁿ/dⁿ · (p − c_ij)/d,     ρ = F_cr/F_ct,

pointing **from the cell towards the robot** (repulsion). KB's eq (1) as
printed has the unit vector (x_i − x_0, y_i − y_0)/d, from the robot to the
cell; their text ("each active cell exerts a virtual repulsive force") and
eq (9) need the repulsive sign, which is what is implemented here.

Angles follow the `sampled` model (docs/theory.md, notation): X lateral, Y forward, a
direction is measured from +Y towards +X, so a heading θ moves the robot by
(V sin θ, V cos θ) (KB eq 14) and δ = atan2(R_x, R_y) is the direction of the
resultant R (eq 4). The steering-rate command is u = k·wrap(δ − θ) (eq 5),
wrap giving the shortest rotational difference in [−π, π).

`measured_wall_force` sums this window over a wall drawn into a grid: the
check of the closed-form grid law `pfm_stability.laws.effective_force.GridWallLaw`
(docs/simulator.md, grid quantization), and the force of walls that are not
along a grid axis (a staircase of cells), whose equilibrium distance
`measured_equilibrium` finds.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..numerics.solve import gauss_legendre
from .grid import HistogramGrid

__all__ = [
    "wrap_angle",
    "direction_of",
    "cell_repulsion",
    "window_repulsion",
    "measured_wall_force",
    "measured_equilibrium",
    "steering_command",
    "vff_speed",
]


def wrap_angle(a):
    """Shortest rotational equivalent of `a` (rad), in [−π, π).

    Parameters
    ----------
    a : array_like
        Angles, rad.
    """
    return np.mod(np.asarray(a, dtype=float) + math.pi, 2 * math.pi) - math.pi


def direction_of(fx, fy):
    """Direction (rad, from +Y towards +X) of the vector (fx, fy); 0 for the zero vector.

    Parameters
    ----------
    fx, fy : array_like
        The vector's components.
    """
    return np.arctan2(fx, fy)


def cell_repulsion(px, py, ox, oy, ocv, n):
    """Σ_cells C·(p − c)/|p − c|^(n+1) over the last axis (KB eq 1–2 without ρWⁿ), 1/m^n.

    Parameters
    ----------
    px, py : ndarray, shape (B, 1) or broadcastable
        Robot centres, m.
    ox, oy, ocv : ndarray, shape (B, K)
        Cell centres (m) and certainty values of each robot's active cells
        (padding cells have C = 0 and lie far away).
    n : float or ndarray, shape (B, 1)
        Exponent of eq (1); n = 2 (KB's choice) uses a faster path.

    Returns
    -------
    (fx, fy) : ndarray, shape (B,)
    """
    dx = px - ox
    dy = py - oy
    d2 = dx * dx
    d2 += dy * dy
    if np.isscalar(n) and n == 2.0:
        weight = np.sqrt(d2)
        weight *= d2
        np.divide(ocv, weight, out=weight)
    else:
        weight = d2 ** (-(np.asarray(n) + 1.0) / 2.0)
        weight *= ocv
    return np.einsum("bk,bk->b", weight, dx), np.einsum("bk,bk->b", weight, dy)


def window_repulsion(grid, px, py, *, ratio, n, W, window_cells=33):
    """Repulsion F_r/F_ct of a grid's active window at points (KB eq 1–2).

    A convenience for single evaluations (force-law checks, plots): compiles
    the grid's window table (`pfm_stability.sim.window`) and sums the
    occupied cells of each point's window.

    Parameters
    ----------
    grid : HistogramGrid
    px, py : array_like
        Robot centres, m.
    ratio : float
        Cell force ratio ρ = F_cr/F_ct.
    n : float
        Exponent.
    W : float
        Robot width, m.
    window_cells : int
        Window side w_s (odd).

    Returns
    -------
    (fx, fy) : ndarray
        Components of the repulsion, in units of F_ct.
    """
    from .window import compile_window_table

    table = compile_window_table(grid, window_cells)
    px = np.atleast_1d(np.asarray(px, dtype=float))
    py = np.atleast_1d(np.asarray(py, dtype=float))
    g = table.grids[0]
    i = np.floor((px - g.x_min) / g.cell_size).astype(np.int64) + g.pad
    j = np.floor((py - g.y_min) / g.cell_size).astype(np.int64) + g.pad
    inside = (i >= 0) & (i < g.nx_padded) & (j >= 0) & (j < g.ny_padded)
    row = np.where(inside, table.row_of_cell[np.where(inside, i * g.ny_padded + j, 0)], 0)
    fx, fy = cell_repulsion(px[:, None], py[:, None], table.wx[row], table.wy[row], table.wcv[row], n)
    scale = ratio * W**n
    return scale * fx, scale * fy


def measured_wall_force(law, d, angle: float = 0.0, nodes: int = 24, samples: int = 400) -> np.ndarray:
    """F_r(d)/F_ct summed cell by cell by the simulator's VFF (KB eq 1–2), averaged along the wall.

    A one-cell-thick wall through the origin is drawn into a `HistogramGrid`
    (`HistogramGrid.draw_segment`) and the robot sits at distance d from its
    line on the wall's left side; the component of the window sum along that
    normal is averaged over the robot's position along the wall.

    * ``angle = 0`` (a wall along Y, cell centres on x = 0): the sum is smooth
      in the robot's position inside its cell, so Gauss–Legendre with `nodes`
      nodes over one cell gives the exact average — the check of the closed
      form of `GridWallLaw`.
    * other angles (a staircase of cells): the mean over `samples` positions
      spread evenly over 2 m along the wall (the staircase is not periodic in
      general); it is stronger than the axis-aligned law (≈ 1.33× at 30°,
      more cells per metre of wall).

    Parameters
    ----------
    law : GridWallLaw
        Cell ratio, exponent, width, cell size, window and CV.
    d : array_like
        Distances robot centre → wall line, m, in (0, reach].
    angle : float
        Wall direction, rad from +Y towards +X.
    nodes, samples : int
        Quadrature nodes per cell (angle 0) or sample positions (otherwise).

    Returns
    -------
    ndarray
        F_r/F_ct pushing away from the wall (positive).
    """
    c, h = law.cell_size, law.window_cells // 2
    d = np.atleast_1d(np.asarray(d, dtype=float))
    span = (h + 2) * c + float(np.max(d)) + 1.0
    grid = HistogramGrid.centred(-span, span, -span, span, cell_size=c)
    ux, uy = math.sin(angle), math.cos(angle)
    nx, ny = -uy, ux  # left of the wall direction
    reach = span - c
    grid.draw_segment((-reach * ux, -reach * uy), (reach * ux, reach * uy), cv=law.cv)
    if angle == 0.0:
        x, w = gauss_legendre(nodes)
        along, weights = x * c / 2, w / 2  # the cell centred on y = 0
    else:
        along = np.linspace(-1.0, 1.0, samples, endpoint=False)
        weights = np.full(samples, 1.0 / samples)
    px = d[:, None] * nx + along[None, :] * ux
    py = d[:, None] * ny + along[None, :] * uy
    fx, fy = window_repulsion(grid, px.ravel(), py.ravel(), ratio=law.ratio, n=law.n, W=law.W, window_cells=law.window_cells)
    normal = (fx * nx + fy * ny).reshape(d.size, along.size)
    return normal @ weights


@lru_cache(maxsize=16)
def measured_equilibrium(law, angle: float, force: float) -> float:
    """d0 (m) where a wall drawn at `angle` (rad from +Y) pushes with `force` (F_r/F_ct).

    `measured_wall_force` on a 5 mm grid of d from W/2 + c to the window's
    reach, interpolated linearly at the first sample that pushes less than
    `force` (KB eq 22–23 for a drawn wall, e.g. the 30° staircase of
    ``kb-fig5``).

    Raises
    ------
    ValueError
        If the drawn wall never pushes that hard inside the window.
    """
    d = np.arange(law.W / 2 + law.cell_size, law.reach, 0.005)
    F = measured_wall_force(law, d, angle=angle)
    below = np.flatnonzero(F < force)
    if below.size == 0 or below[0] == 0:
        raise ValueError(f"the drawn wall never pushes with {force:g} F_ct inside the window (d in [{d[0]:g}, {d[-1]:g}] m)")
    i = below[0]  # first crossing: linear interpolation between the bracketing samples
    return float(d[i - 1] + (d[i] - d[i - 1]) * (F[i - 1] - force) / (F[i - 1] - F[i]))


def steering_command(delta, theta, k, max_rate):
    """u = k·wrap(δ − θ) (KB eq 5), clipped to ±max_rate (rad/s).

    Parameters
    ----------
    delta : array_like
        Direction δ of the resultant force, rad.
    theta : array_like
        Heading θ, rad.
    k : array_like
        Steering gain, 1/s.
    max_rate : array_like
        Rate limit, rad/s.
    """
    return np.clip(k * wrap_angle(delta - theta), -max_rate, max_rate)


def vff_speed(V_max, fx, fy, theta):
    """The VFF speed law V = V_max(1 − |cos φ|), m/s.

    φ is the angle between the repulsive resultant (fx, fy) and the travel
    direction θ; with no repulsion the robot travels at V_max.

    Parameters
    ----------
    V_max : float
        Top speed, m/s.
    fx, fy : array_like
        The repulsive resultant.
    theta : array_like
        Travel direction θ, rad (from +Y towards +X).
    """
    norm = np.hypot(fx, fy)
    cos_phi = np.where(norm > 0, (fx * np.sin(theta) + fy * np.cos(theta)) / np.where(norm > 0, norm, 1.0), 0.0)
    return V_max * (1.0 - np.abs(cos_phi))
