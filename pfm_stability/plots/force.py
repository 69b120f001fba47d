"""The grid's effective force law against KB's lumped law (docs/simulator.md, grid quantization).

`plot_force_laws` draws F_r(d)/F_ct of a straight wall in the histogram grid
(`GridWallLaw`: the window sum of KB eq 1, averaged along the wall) against
KB's lumped law f(W/d)^n (eq 8, 13) on log–log axes, with the window's
working range and reach; the grid with ρ·C = f (each cell as strong as KB's
lumped wall) shows how much harder the cells push before calibration.
`plot_equivalent_f` draws KB's equivalent f(d) = F_r(d)(d/W)^n with its mean
f_av over the working range, and the local exponent −dF′/F.
"""

from __future__ import annotations

import numpy as np

from ..laws.effective_force import GridWallLaw, f_average, working_range
from ..laws.force_law import PowerLaw
from .common import figure_and_axes

__all__ = ["plot_force_laws", "plot_equivalent_f", "plot_force_summary"]


def _distances(law: GridWallLaw, d):
    if d is not None:
        return np.asarray(d, dtype=float)
    lo = law.W / 2 - law.cell_size
    return np.linspace(max(lo, law.cell_size), law.reach * 1.25, 400)


def _shade_range(ax, law: GridWallLaw):
    lo, hi = working_range(law.W, law.cell_size, law.window_cells)
    ax.axvspan(lo, hi, color="0.9", zorder=0, label=f"working range {lo:.2f}–{hi:.2f} m")
    ax.axvline(law.reach, color="0.5", ls=":", lw=1)


def plot_force_laws(law: GridWallLaw, lumped: PowerLaw | None = None, ax=None, d=None):
    """F_r(d)/F_ct of the grid wall against KB's lumped law (log–log).

    Parameters
    ----------
    law : GridWallLaw
        The grid wall (cell ratio ρ, n, W, cells, window).
    lumped : PowerLaw, optional
        KB's law; default f = the grid's f_av (KB §4).
    ax : matplotlib Axes, optional
    d : array_like, optional
        Distances, m.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax)
    d = _distances(law, d)
    lumped = lumped if lumped is not None else law.lumped()
    _shade_range(ax, law)
    ax.loglog(d, law.window_force(d), color="C0", lw=2, label=f"grid wall, F_cr/F_ct = {law.ratio:.3g} (C = {law.cv})")
    ax.loglog(d, law.force(d), color="C0", lw=1, ls="--", label="grid law's C¹ tail beyond the window (for root finders)")
    raw = law.with_scale(lumped.f / law.cv)
    ax.loglog(d, raw.window_force(d), color="C2", lw=1, label=f"grid wall with ρ·C = f = {lumped.f:.3g} (uncalibrated)")
    ax.loglog(d, lumped.force(d), color="C1", lw=2, label=f"KB lumped f(W/d)^n, f = {lumped.f:.3g}, n = {lumped.n:g}")
    from matplotlib.ticker import FixedLocator, NullFormatter, ScalarFormatter

    ticks = [t for t in (0.2, 0.3, 0.4, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0) if d.min() <= t <= d.max()]
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("distance robot centre → wall cells d (m)")
    ax.set_ylabel("lateral repulsion F_r / F_ct")
    ax.set_title("Effective force of a wall in the VFF window vs KB's lumped law", fontsize=10)
    ax.set_ylim(bottom=max(1e-3, float(np.min(law.force(d))) / 3))
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    return fig


def plot_equivalent_f(law: GridWallLaw, ax=None, d=None):
    """KB's equivalent f(d) = F_r(d)(d/W)^n of the grid wall, its f_av, and the local exponent.

    Parameters
    ----------
    law : GridWallLaw
        The grid wall.
    ax : matplotlib Axes, optional
        Axes to draw on; None: a new figure.
    d : array_like, optional
        Distances, m (default 400 from about W/2 to 1.25 times the window's reach; those beyond the reach are dropped).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax)
    lo, hi = working_range(law.W, law.cell_size, law.window_cells)
    d = _distances(law, d)
    d = d[d <= law.reach]
    _shade_range(ax, law)
    f_av = f_average(law)
    ax.plot(d, law.equivalent_f(d, law.n, law.W), color="C0", lw=2, label="equivalent f(d) = F_r(d)(d/W)^n")
    ax.hlines(f_av, lo, hi, color="C0", ls="--", label=f"f_av = {f_av:.3g}")
    ax.set_xlabel("distance robot centre → wall cells d (m)")
    ax.set_ylabel("KB's f (lumped ratio)", color="C0")
    twin = ax.twinx()
    twin.plot(d, law.local_exponent(d), color="C3", lw=1.5, label="local exponent −dF′/F")
    twin.axhline(law.n, color="C3", ls=":", lw=1, label=f"KB's lumped n = {law.n:g}")
    twin.set_ylabel("local exponent", color="C3")
    lines = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="upper left")
    ax.set_title("Grid wall in KB's lumped form: f(d) and local exponent", fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    return fig


def plot_force_summary(law: GridWallLaw, lumped: PowerLaw | None = None):
    """Both panels side by side; returns the figure.

    Parameters
    ----------
    law : GridWallLaw
        The grid wall.
    lumped : PowerLaw, optional
        KB's law; default f = the grid's f_av (KB §4), as `plot_force_laws`.
    """
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.3), layout="constrained")
    plot_force_laws(law, lumped, ax=a)
    plot_equivalent_f(law, ax=b)
    return fig
