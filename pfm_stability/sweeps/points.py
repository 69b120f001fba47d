"""The points of a sweep: a full factorial grid, or a seeded Latin hypercube / Sobol sample.

Point ``i`` of a grid is the C-order (row-major) element ``i`` of the
product of its axes in the spec's order: the first axis varies slowest,
the last fastest (`numpy.unravel_index`). A chunk of a grid is therefore
computed from its index range alone (`grid_points`), without the other
points. A sample is drawn once, whole, as `scipy.stats.qmc` draws it
(``LatinHypercube(d, seed=seed)`` or ``Sobol(d, scramble=True,
seed=seed)``; `sampling.latin_hypercube`, `sampling.sobol`) and scaled to
its ranges (`sample_points`): the same seed gives the same points on every
machine. Sobol points are balanced only for
n a power of two; another n is accepted, with a note (`sobol_note`) in the
summary, instead of scipy's warning.

α is in degrees here and in the output, as on the command line.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.sampling import latin_hypercube, sobol
from .spec import Axis, SweepSpec

__all__ = ["all_points", "axis_values", "check_points", "chunk_points", "grid_points", "sample_points", "sobol_note"]


def axis_values(axis: Axis) -> np.ndarray:
    """The values of one grid axis: ``num`` values from ``from`` to ``to``, linear or log-spaced (both ends exact).

    Parameters
    ----------
    axis : Axis
        One grid axis.
    """
    if axis.num == 1:
        return np.array([axis.start])
    values = np.geomspace(axis.start, axis.stop, axis.num) if axis.scale == "log" else np.linspace(axis.start, axis.stop, axis.num)
    values[0], values[-1] = axis.start, axis.stop
    return values


def grid_points(axes, start: int, stop: int) -> dict:
    """Points ``start`` … ``stop − 1`` of the grid `axes` (C order): parameter → array.

    Parameters
    ----------
    axes : sequence of Axis
        The grid's axes.
    start, stop : int
        The first point and one past the last.
    """
    shape = tuple(a.num for a in axes)
    index = np.unravel_index(np.arange(start, stop, dtype=np.int64), shape)
    return {a.name: axis_values(a)[i] for a, i in zip(axes, index)}


def sample_points(spec: SweepSpec) -> dict:
    """Every point of the spec's sample: parameter → array of ``n`` values (seeded, reproducible).

    Parameters
    ----------
    spec : SweepSpec
        A sweep with a sample.
    """
    s = spec.sample
    draw = sobol if s.method == "sobol" else latin_hypercube  # sobol: the balance note is `sobol_note`'s
    unit = draw(s.n, len(s.ranges), s.seed)
    lows = np.array([lo for _, lo, _ in s.ranges])
    highs = np.array([hi for _, _, hi in s.ranges])
    scaled = lows + (highs - lows) * unit
    return {name: scaled[:, j] for j, (name, _, _) in enumerate(s.ranges)}


def sobol_note(spec: SweepSpec) -> str | None:
    """A note when a Sobol sample's n is not a power of two (its balance properties then do not hold), else None.

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    """
    s = spec.sample
    if s is None or s.method != "sobol" or s.n & (s.n - 1) == 0:
        return None
    below = 2 ** int(math.log2(s.n))
    return f"sobol: n = {s.n} is not a power of two; the balance properties of Sobol points need one (e.g. {below} or {2 * below})"


def all_points(spec: SweepSpec) -> dict | None:
    """A sample's points (drawn once for the whole sweep), or None for a grid (its chunks compute their own).

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    """
    return sample_points(spec) if spec.sample is not None else None


def chunk_points(spec: SweepSpec, start: int, stop: int, sample: dict | None = None) -> dict:
    """The varying parameters' values at points ``start`` … ``stop − 1``.

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    start, stop : int
        The chunk's first point and one past its last.
    sample : dict, optional
        The sample's points (`all_points`); None for a grid.
    """
    if spec.sample is None:
        return grid_points(spec.axes, start, stop)
    return {name: values[start:stop] for name, values in sample.items()}


def check_points(spec: SweepSpec, sample: dict | None = None) -> None:
    """Raise ValueError (``spec FILE: …``) if a corridor point has L <= W/2 (the robot does not fit).

    Cheap: the extremes of L and W are enough (each varies on its own axis or range).

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    sample : dict, optional
        Its sample's points (`all_points`), if already drawn.
    """
    if spec.geometry != "corridor":
        return
    values = sample if sample is not None else {a.name: axis_values(a) for a in spec.axes}
    L = values.get("L", np.array([spec.geometry_value]))
    W = values.get("W", np.array([spec.robot.W]))
    if sample is not None and "L" in values and "W" in values:
        bad = np.flatnonzero(L <= W / 2)
        worst = (float(L[bad[0]]), float(W[bad[0]])) if bad.size else None
    else:
        worst = (float(np.min(L)), float(np.max(W))) if float(np.min(L)) <= float(np.max(W)) / 2 else None
    if worst is not None:
        prefix = f"spec {spec.path}: " if spec.path else "spec: "
        raise ValueError(f"{prefix}L: the robot must fit, L > W/2; L = {worst[0]:g} m with W = {worst[1]:g} m")
