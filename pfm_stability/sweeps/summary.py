"""The data of a sweep's summary figure (drawn by `pfm_stability.plots.sweep`).

Two or more parameters vary: a **verdict map** over the two that vary most
(most grid values; for a sample, or a tie, the widest relative range),
coloured by the fraction of the models that call a point stable (averaged
over the other varying parameters of a grid), with each model's boundary
where its own stable fraction crosses one half; a sample is shown as its
points. With ``simulate: true`` the simulator's verdicts are marked on top.
One parameter varies: the models' **pairwise agreement** matrix (fraction of
points with equal verdicts; the simulator as one more row), since a map
needs two axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .table import read_columns

__all__ = ["MAX_MARKERS", "UNITS", "SweepFigureData", "map_axes", "summary_figure_data"]

UNITS = {"V": "m/s", "tau": "s", "T": "s", "k": "1/s", "W": "m", "alpha": "deg", "L": "m", "cell_size": "m", "rho0": "m",
         "goal_distance": "m", "delta": "m"}
"""Units of the input columns, for axis labels."""

MAX_MARKERS = 4000
"""Most points drawn as markers (sample scatter, simulated verdicts); more are thinned evenly."""


@dataclass(frozen=True)
class SweepFigureData:
    """What the summary figure shows.

    Attributes
    ----------
    kind : {"map", "agreement"}
    title : str
    models : tuple of str
    x, y : str or None
        Map axes (column names).
    x_label, y_label : str
    x_log, y_log : bool
    x_values, y_values : ndarray
        Grid: the axes' distinct values; sample: the points' coordinates.
    fraction : ndarray
        Grid: (len(y), len(x)) fraction of models stable; sample: per point.
    model_fraction : dict
        Grid only: model → (len(y), len(x)) array whose level 0.5 is its boundary: the fraction of
        points it calls stable, or, where each cell is one point, its margin + 0.5 (clipped to
        [−0.5, 10.5]: a smooth line between the grid points).
    gridded : bool
    averaged : bool
        Grid: the cells average over other varying parameters.
    sim_x, sim_y : ndarray or None
        Simulated points (thinned to `MAX_MARKERS`).
    sim_stable : ndarray or None
    labels : tuple of str
        Agreement: row/column names (the models, and "simulation").
    matrix : ndarray or None
        Agreement: fraction of points with equal verdicts.
    """

    kind: str
    title: str
    models: tuple
    x: str | None = None
    y: str | None = None
    x_label: str = ""
    y_label: str = ""
    x_log: bool = False
    y_log: bool = False
    x_values: np.ndarray | None = None
    y_values: np.ndarray | None = None
    fraction: np.ndarray | None = None
    model_fraction: dict | None = None
    gridded: bool = True
    averaged: bool = False
    sim_x: np.ndarray | None = None
    sim_y: np.ndarray | None = None
    sim_stable: np.ndarray | None = None
    labels: tuple = ()
    matrix: np.ndarray | None = None

    def plot(self, ax=None):
        """`plots.sweep.plot_sweep_summary` of this figure's data; returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; None: a new figure.
        """
        from ..plots.sweep import plot_sweep_summary

        return plot_sweep_summary(self, ax=ax)


def _label(name: str) -> str:
    unit = UNITS.get(name)
    return f"{name} ({unit})" if unit else name


def map_axes(spec) -> tuple:
    """The varying parameters by how much they vary: most grid values first, then the widest relative range, then spec order.

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    """
    if spec.sample is not None:
        spans = [(name, math.inf, (hi - lo) / (abs(hi) + abs(lo))) for name, lo, hi in spec.sample.ranges]
    else:
        spans = [(a.name, a.num, (a.stop - a.start) / (abs(a.stop) + abs(a.start) or 1.0)) for a in spec.axes if a.num > 1]
    order = sorted(range(len(spans)), key=lambda i: (-spans[i][1], -spans[i][2], i))
    return tuple(spans[i][0] for i in order)


def _log_axis(spec, name: str) -> bool:
    return any(a.name == name and a.scale == "log" for a in spec.axes)


def _title(spec) -> str:
    where = "wall" if spec.geometry == "wall" else "corridor"
    fixed = "" if spec.geometry_value is None else (f", alpha = {spec.geometry_value:g} deg" if where == "wall" else f", L = {spec.geometry_value:g} m")
    c = spec.controller
    return f"{where}{fixed}, law {spec.law}; sampled: hold {c.hold}, compute delay {c.compute_delay}"


def _thin(count: int) -> np.ndarray:
    return np.unique(np.linspace(0, count - 1, min(count, MAX_MARKERS)).astype(int)) if count else np.zeros(0, dtype=int)


def summary_figure_data(summary) -> SweepFigureData:
    """The figure's data from a finished sweep (its output file and spec).

    Parameters
    ----------
    summary : SweepSummary
        The finished sweep.
    """
    spec = summary.spec
    models = tuple(spec.models)
    axes = map_axes(spec)
    if len(axes) < 2:
        return _agreement(summary, models)
    x, y = axes[1], axes[0]  # the most varying parameter on the vertical axis, the next along x
    columns = [x, y] + [f"{m}_verdict" for m in models] + (["sim_verdict"] if spec.simulate else [])
    table = read_columns(summary.out, columns)
    xs, ys = (np.asarray(table.column(c).to_numpy(), dtype=float) for c in (x, y))
    stable = {m: np.array(table.column(f"{m}_verdict").to_pylist(), dtype=object) == "stable" for m in models}
    share = np.mean([stable[m] for m in models], axis=0)
    sim = {}
    if spec.simulate:
        verdicts = np.array(table.column("sim_verdict").to_pylist(), dtype=object)
        keep = np.flatnonzero(~np.equal(verdicts, None))
        keep = keep[_thin(keep.size)]
        sim = {"sim_x": xs[keep], "sim_y": ys[keep], "sim_stable": verdicts[keep] == "stable"}
    common = dict(kind="map", title=_title(spec), models=models, x=x, y=y, x_label=_label(x), y_label=_label(y),
                  x_log=_log_axis(spec, x), y_log=_log_axis(spec, y), **sim)
    if spec.sample is not None:
        keep = _thin(xs.size)
        return SweepFigureData(**common, x_values=xs[keep], y_values=ys[keep], fraction=share[keep], gridded=False)
    ux, ix = np.unique(xs, return_inverse=True)
    uy, iy = np.unique(ys, return_inverse=True)
    cell = iy.ravel() * ux.size + ix.ravel()
    counts = np.bincount(cell, minlength=ux.size * uy.size).reshape(uy.size, ux.size)

    def mean(values):
        return np.bincount(cell, weights=values.astype(float), minlength=ux.size * uy.size).reshape(uy.size, ux.size) / counts

    if counts.max() == 1 and counts.min() == 1:  # two parameters vary: each model's margin, whose zero is its boundary
        margins = read_columns(summary.out, [f"{m}_margin" for m in models])
        lines = {m: mean(np.clip(np.nan_to_num(margins.column(f"{m}_margin").to_numpy(), nan=-1.0), -1.0, 10.0) + 0.5) for m in models}
    else:
        lines = {m: mean(stable[m]) for m in models}
    averaged = bool(counts.max() > 1)
    if averaged:
        common["title"] += f"\naveraged over {', '.join(a for a in axes[2:])}; lines: half of those points stable"
    return SweepFigureData(**common, x_values=ux, y_values=uy, fraction=mean(share), model_fraction=lines, gridded=True,
                           averaged=averaged)


def _agreement(summary, models: tuple) -> SweepFigureData:
    s = summary.statistics
    labels = list(models)
    matrix = [[s.agreement[a][b] for b in models] for a in models]
    if s.simulation_agreement is not None:
        labels.append("simulation")
        sim_row = [s.simulation_agreement[m] for m in models]
        matrix = [row + [sim_row[i]] for i, row in enumerate(matrix)] + [sim_row + [1.0]]
    return SweepFigureData(kind="agreement", title=_title(summary.spec) + f" ({s.points} points)", models=models,
                           labels=tuple(labels), matrix=np.array(matrix, dtype=float))
