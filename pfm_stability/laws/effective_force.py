"""The lateral force law a wall drawn into the histogram grid really produces.

Koren & Borenstein 1991 (KB) analyse a lumped law F_r/F_a = f(W/d)^n (eq 8, 13),
but the VFF method sums eq (1) over the cells of a w_s × w_s active window
centred on the robot's *cell* (KB §2). For a straight wall of cells (one cell
thick, certainty value C, cell size c) at lateral distance d from the robot
centre, the window holds the 2h + 1 wall cells of rows j_r − h … j_r + h
(h = (w_s − 1)/2), at along-wall offsets y_j = jc − s, where s ∈ [−c/2, c/2)
is the robot's position inside its cell. Averaged over s (docs/simulator.md: "averaged
over the robot's position along the wall within a cell"), the sum over cells
becomes an integral over a continuous line of length (2h + 1)c, exactly:

    F_r(d)/F_ct = ρ C Wⁿ/c · ∫_{−Y}^{Y} d / (d² + y²)^((n+1)/2) dy,   Y = (h + ½)c,
                = ρ C Wⁿ/c · d^(1−n) · B(½, n/2) · I(Y²/(d² + Y²); ½, n/2),

with ρ = F_cr/F_ct the cell force ratio and I the regularized incomplete beta
function (n = 2: 2Y/(d√(d² + Y²)), so F_r ∝ 1/d for d ≪ Y — docs/simulator.md). The
gradient is F_r′(d) = ρ C Wⁿ/c · [(1 − n)G(d)/d − 2Y/(d² + Y²)^((n+1)/2)], G
the integral. The simulator's `pfm_stability.sim.vff.measured_wall_force`
checks the closed form by summing its own eq (1) over drawn cells (this
module imports nothing from the simulator).

The window stops seeing the wall at d = (h + ½)c (the wall column leaves the
window; 1.65 m for CARMEL), where the grid force drops to 0. The general-law
root finders of `pfm_stability.analysis.criteria` need a strictly decreasing law, so
beyond this `reach` the law continues as the C¹ power-law tail
F_r(reach)(reach/d)^p, p the local exponent at `reach`; `window_force` gives
the grid's true value (0 beyond the reach). Predictions whose d0 or L exceed
`reach` describe the tail, not the grid: check ``d < law.reach``.

KB's lumped f is an output of the grid: f(d) = F_r(d)(d/W)^n (`equivalent_f`)
and f_av its mean over the window's working range (KB §4). `calibrate_cell_ratio`
returns the ρ that gives a chosen f_av (ρ enters linearly).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_integer, check_number
from .force_law import ForceLaw, PowerLaw
from ..numerics.solve import gauss_legendre

__all__ = [
    "DEFAULT_CV",
    "GridWallLaw",
    "working_range",
    "f_average",
    "calibrate_cell_ratio",
    "corridor_lateral_force",
    "check_window_cells",
]

DEFAULT_CV = 15
"""Certainty value of a drawn obstacle cell: the maximum of KB's histogram grid (docs/simulator.md)."""


def check_window_cells(window_cells) -> int:
    """Return the window side w_s after checking it is an odd integer >= 3 (KB §2: 33).

    Parameters
    ----------
    window_cells : int
        The active window's side, cells.

    Raises
    ------
    ValueError
        ``"window_cells must be an odd integer in [3, 1001]; got 32"``.
    """
    message = f"window_cells must be an odd integer in [3, 1001]; got {window_cells!r}"
    try:
        w = check_integer("window_cells", window_cells, 3, 1001)
    except ValueError:
        raise ValueError(message) from None
    if w % 2 == 0:
        raise ValueError(message)
    return w


@dataclass(frozen=True)
class GridWallLaw(ForceLaw):
    """Effective F_r(d)/F_ct of a straight one-cell-thick wall in the histogram grid.

    The sum of KB eq (1) over the wall cells inside the active window, averaged
    over the robot's position along the wall within its cell (module docstring).

    Parameters
    ----------
    ratio : float
        Cell force ratio ρ = F_cr/F_ct, > 0 (KB eq 1, 3). This is the law's `scale`.
    n : float
        Repulsion exponent of eq (1), > 0.
    W : float
        Robot width, m, > 0 (eq 1).
    cell_size : float
        Cell side c, m, > 0 (KB §2: 0.1 m).
    window_cells : int
        Window side w_s, odd, >= 3 (KB §2: 33).
    cv : int
        Certainty value C of the wall cells, >= 1 (default 15).
    """

    ratio: float
    n: float
    W: float
    cell_size: float = 0.1
    window_cells: int = 33
    cv: int = DEFAULT_CV
    name = "grid wall (VFF window sum, KB eq 1)"
    monotone = True  # decreasing on its whole domain (the tail beyond the reach too), no goal part
    key = "grid"

    def __post_init__(self):
        object.__setattr__(self, "ratio", check_number("cell_ratio", self.ratio, 0.0))
        object.__setattr__(self, "n", check_number("n", self.n, 0.0, 10.0, high_open=False))
        object.__setattr__(self, "W", check_number("W", self.W, 0.0, unit="m"))
        object.__setattr__(self, "cell_size", check_number("cell_size", self.cell_size, 0.0, unit="m"))
        object.__setattr__(self, "window_cells", check_window_cells(self.window_cells))
        object.__setattr__(self, "cv", check_integer("cv", self.cv, 1, 32767))

    # ------------------------------------------------------------ geometry
    @property
    def scale(self) -> float:
        """ρ = F_cr/F_ct."""
        return self.ratio

    @property
    def half_length(self) -> float:
        """Y = (h + ½)c, m: half the wall length the window sees."""
        return (self.window_cells // 2 + 0.5) * self.cell_size

    @property
    def reach(self) -> float:
        """Largest d at which the wall column is inside the window, m: (h + ½)c."""
        return (self.window_cells // 2 + 0.5) * self.cell_size

    def _prefactor(self) -> float:
        return self.ratio * self.cv * self.W**self.n / self.cell_size

    # ------------------------------------------------------- inside reach
    def _integral(self, d):
        """G(d) = ∫_{−Y}^{Y} d/(d² + y²)^((n+1)/2) dy (1/m^(n−1))."""
        from scipy.special import beta, betainc

        Y = self.half_length
        n = self.n
        return d ** (1.0 - n) * beta(0.5, n / 2) * betainc(0.5, n / 2, Y * Y / (d * d + Y * Y))

    def _window_force(self, d):
        return self._prefactor() * self._integral(d)

    def _window_slope(self, d):
        Y = self.half_length
        n = self.n
        r2 = d * d + Y * Y
        return self._prefactor() * ((1.0 - n) * self._integral(d) / d - 2.0 * Y / r2 ** ((n + 1) / 2))

    def _tail_exponent(self) -> float:
        R = self.reach
        return float(-R * self._window_slope(R) / self._window_force(R))

    # ------------------------------------------------------- ForceLaw API
    def force(self, d):
        """F_r(d)/F_ct: the window sum for d <= `reach`, the C¹ tail beyond.

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        d = np.asarray(d, dtype=float)
        R = self.reach
        inside = self._window_force(np.minimum(d, R))
        tail = self._window_force(R) * (R / np.maximum(d, R)) ** self._tail_exponent()
        return np.where(d <= R, inside, tail)

    def slope(self, d):
        """dF_r/dd, 1/m (negative everywhere).

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        d = np.asarray(d, dtype=float)
        R = self.reach
        inside = self._window_slope(np.minimum(d, R))
        p = self._tail_exponent()
        tail = -p * self._window_force(R) * R**p / np.maximum(d, R) ** (p + 1)
        return np.where(d <= R, inside, tail)

    def window_force(self, d):
        """The grid's true averaged force: `force` for d <= `reach`, 0 beyond.

        Parameters
        ----------
        d : float or ndarray
            Distance to the wall, m.
        """
        d = np.asarray(d, dtype=float)
        return np.where(d <= self.reach, self._window_force(np.minimum(d, self.reach)), 0.0)

    def with_scale(self, scale: float) -> "GridWallLaw":
        """The same wall with cell ratio ρ = `scale`.

        Parameters
        ----------
        scale : float
            Cell ratio ρ = F_cr/F_ct.
        """
        return GridWallLaw(scale, self.n, self.W, self.cell_size, self.window_cells, self.cv)

    def parameters(self) -> dict:
        """The grid's parameters by name (`parameters.RANGES` keys), for the report."""
        return {"cell_ratio": self.ratio, "n": self.n, "W": self.W, "cell_size": self.cell_size, "window_cells": self.window_cells, "cv": self.cv}

    def domain(self) -> tuple[float, float]:
        """(1e-9 m, inf): defined for every d > 0 (the tail beyond `reach`)."""
        return (1e-9, math.inf)

    def lumped_f(self) -> float:
        """KB's f_av of this grid (`f_average`): the user's f, of which the cell ratio is the calibration (KB §4).

        f_av ∝ ρ, so a critical cell ratio ρ* stands for f* = ρ*·f_av/ρ (docs/simulator.md).
        """
        return f_average(self)

    def lumped(self, f: float | None = None) -> PowerLaw:
        """KB's lumped law with this law's n and W and f (default: `lumped_f`, the grid's f_av).

        Parameters
        ----------
        f : float, optional
            KB's f; default `lumped_f`.
        """
        return PowerLaw(self.lumped_f() if f is None else f, self.n, self.W)


def working_range(W: float, cell_size: float = 0.1, window_cells: int = 33) -> tuple[float, float]:
    """Distances at which a wall acts on a robot that does not touch it, m.

    From contact, d = (W + c)/2 (robot disc touching the wall cells), to the
    window's reach (h + ½)c. KB's f_av (§4) is the mean of f(d) over this range.

    Parameters
    ----------
    W : float
        Robot width, m.
    cell_size : float, optional
        Grid cell size, m.
    window_cells : int, optional
        Active window side, cells.
    """
    lo = (W + cell_size) / 2
    hi = (check_window_cells(window_cells) // 2 + 0.5) * cell_size
    if not lo < hi:
        raise ValueError(
            f"W must be a finite number in (0, {2 * hi - cell_size:g}) m for a {window_cells}-cell window "
            f"of {cell_size:g} m cells (the robot must fit inside the window); got {W!r}"
        )
    return lo, hi


def f_average(law: GridWallLaw, d_range: tuple[float, float] | None = None, points: int = 64) -> float:
    """KB's f_av: mean of f(d) = F_r(d)(d/W)^n over `d_range` (KB §4).

    Parameters
    ----------
    law : GridWallLaw
    d_range : (float, float), optional
        m; default `working_range` of the law's window.
    points : int
        Gauss–Legendre nodes of the mean (f(d) is smooth: 64 nodes are exact to
        round-off, checked against 256 in the tests).
    """
    lo, hi = d_range if d_range is not None else working_range(law.W, law.cell_size, law.window_cells)
    x, w = gauss_legendre(points)
    d = lo + (hi - lo) * (x + 1) / 2
    return float(np.sum(w * law.equivalent_f(d, law.n, law.W)) / 2)


def calibrate_cell_ratio(
    f_av: float,
    n: float,
    W: float,
    cell_size: float = 0.1,
    window_cells: int = 33,
    cv: int = DEFAULT_CV,
    d_range: tuple[float, float] | None = None,
) -> float:
    """Cell ratio ρ = F_cr/F_ct for which the grid's f_av equals `f_av` (KB §4).

    The force is proportional to ρ, so ρ = f_av / f_av(ρ = 1). KB calibrated
    CARMEL by the head-on run of their Fig 3 and report f_av = 0.8; this
    function is how the ``kb-*`` presets turn that f into a cell ratio.

    Parameters
    ----------
    f_av : float
        Target lumped ratio, > 0.
    n, W, cell_size, window_cells, cv
        As in `GridWallLaw`.
    d_range : (float, float), optional
        Averaging range, m (default `working_range`).
    """
    f_av = check_number("f", f_av, 0.0)
    unit = GridWallLaw(1.0, n, W, cell_size, window_cells, cv)
    return f_av / f_average(unit, d_range)


def corridor_lateral_force(law: ForceLaw, L: float, x):
    """Lateral F_x/F_ct at offset x (m, towards the right wall) in a corridor of half-width L.

    F_x = F_r(L + x) − F_r(L − x) (the left wall pushes right, the right wall
    left); linearized, F_x ≈ 2F_r′(L)·x = −N·F_ct·x (docs/theory.md).

    Parameters
    ----------
    law : ForceLaw
        The wall's law.
    L : float
        Corridor half-width, m.
    x : float or ndarray
        Offset from the middle, m, towards the right wall.
    """
    x = np.asarray(x, dtype=float)
    return law.force(L + x) - law.force(L - x)
