"""One chunk of points → one column table: inputs, N, NV, every model's verdict, the simulation.

For each point (docs/sweeps.md, "Columns"):

* **N** — KB's power law in arrays (`force_law.power_law_wall_gain`, eq 11
  at the equilibrium of eq 23; `power_law_corridor_gain`, eq 25). Any other
  law's N depends only on (law parameters, geometry, f, n, W): it is found
  once per distinct combination by the report's own scalar route
  (`fields.make_law`; `force_law.wall_gain` for a monotone law, the nearest
  of `wall_equilibria` otherwise, `corridor_gain` for a corridor) and
  broadcast. NV = N·V.
* **verdicts** — `vectorized.loop_verdicts` per model, asked once per distinct
  loop (τ, T, k) for the boundary, and at the point itself near it
  (`model_answers`; heading gain c = 0: every law of the package is static,
  docs/fields.md): ``<model>_stable``,
  ``<model>_verdict``, ``<model>_NV_critical``, ``<model>_margin``, the values
  `pfm-stability report` gives for the same point. Where NV is not a loop gain
  the models take, the report's documented answers are written instead, with
  a ``reason``: N < 0 unstable in every model, margin −1
  (`models.base.divergent_reason`); no equilibrium at all, or NV beyond `models.base.NV_MAX` (the report's limit too),
  no verdict (null, NaN margins) and the report's error message as reason. N = 0 (no restoring
  force) is each model's own verdict at NV = 0, its heading loop (docs/models.md "N = 0"), with
  `models.base.NEUTRAL_REASON`.
* **simulation** (``simulate: true``) — `validation.sweep.simulate_members`
  (the one implementation behind ``validate --sweep``): ``sim_sigma`` (σ,
  1/s; NaN only with a ``sim_basis`` saying why), ``sim_stable``,
  ``sim_verdict``, ``sim_basis``, ``sim_method``, ``sim_collided``,
  ``sim_reason``.

`evaluate_chunk` returns plain numpy arrays in column order (`ChunkColumns`);
`table.to_arrow` turns them into a pyarrow table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..laws.force_law import Equilibrium, corridor_gain, power_law_corridor_gain, power_law_wall_gain, wall_equilibria, wall_gain
from ..models.verdicts import DIVERGENT_REASON, NEUTRAL_REASON, NV_MAX, beyond_reason, judge_arrays
from ..parameters import RADIANS_PER_DEGREE, Controller, Robot
from .points import chunk_points
from .spec import LAW_SWEPT, SweepSpec

__all__ = ["SIM_COLUMNS", "ChunkColumns", "distinct_rows", "evaluate_chunk", "loop_groups", "model_answers", "model_columns"]

SIM_COLUMNS = ("sim_sigma", "sim_stable", "sim_verdict", "sim_basis", "sim_method", "sim_collided", "sim_reason")
"""Simulation columns (``simulate: true``), in order."""

SIM_OFFSET = {"analytic": 1e-4, "grid": 0.01}
"""Start offset from the equilibrium line, m: small enough to stay linear, large enough for the grid's cells."""


def model_columns(model: str) -> tuple:
    """``<model>_stable``, ``<model>_verdict``, ``<model>_NV_critical``, ``<model>_margin``.

    Parameters
    ----------
    model : str
        A model name.
    """
    return tuple(f"{model}_{suffix}" for suffix in ("stable", "verdict", "NV_critical", "margin"))


@dataclass(frozen=True)
class ChunkColumns:
    """The columns of one chunk, in output order.

    Attributes
    ----------
    names : tuple of str
    arrays : tuple of ndarray
        float64, bool, int64 or object (str or None) arrays of one length.
    """

    names: tuple
    arrays: tuple

    @property
    def rows(self) -> int:
        """Number of points (rows) in the chunk."""
        return len(self.arrays[0]) if self.arrays else 0


def _inputs(spec: SweepSpec, values: dict, size: int) -> dict:
    """Every input column as a full array (fixed values broadcast)."""
    out = {}
    for name in spec.input_columns:
        if name in values:
            out[name] = np.asarray(values[name], dtype=float)
        else:
            out[name] = np.full(size, float(spec.fixed_value(name)))
    return out


@lru_cache(maxsize=4096)
def _law_gain(law: str, parameters: tuple, geometry: str, value: float, f: float, n: float, W: float) -> tuple:
    """(N in 1/m, reason) of a law at one geometry, by the report's scalar route; reason for no answer."""
    from ..laws.fields import make_law

    robot = Robot(V=1.0, tau=0.0, k=1.0, W=W)
    controller = Controller(f=f, n=n, T=0.0)
    try:
        force = make_law(law, robot, controller, **dict(parameters))
        if geometry == "corridor":
            return corridor_gain(force, value), None
        alpha = value * RADIANS_PER_DEGREE
        if force.monotone:
            return Equilibrium(*wall_gain(force, alpha)).N, None
        equilibria = wall_equilibria(force, alpha) or (Equilibrium(*wall_gain(force, alpha)),)
        return equilibria[0].N, None
    except ValueError as exc:
        return math.nan, str(exc)


def environment_gain(spec: SweepSpec, inputs: dict) -> tuple[np.ndarray, np.ndarray]:
    """(N in 1/m, reason or None per point) for every point of a chunk."""
    geometry = inputs["alpha" if spec.geometry == "wall" else "L"]
    size = geometry.size
    reasons = np.full(size, None, dtype=object)
    if spec.law == "power":
        with np.errstate(all="ignore"):
            if spec.geometry == "wall":
                N = power_law_wall_gain(inputs["f"], inputs["n"], inputs["W"], geometry * RADIANS_PER_DEGREE)
            else:
                N = power_law_corridor_gain(inputs["f"], inputs["n"], inputs["W"], geometry)
        return np.asarray(N, dtype=float), reasons
    swept = [name for name in LAW_SWEPT if name in inputs]
    keys = np.column_stack([geometry, inputs["f"], inputs["n"], inputs["W"]] + [inputs[name] for name in swept])
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    N_unique = np.empty(len(unique))
    reason_unique = np.full(len(unique), None, dtype=object)
    for j, row in enumerate(unique):
        parameters = dict(spec.law_parameters)
        for name, v in zip(swept, row[4:]):
            parameters[name] = int(v) if name == "window_cells" else float(v)
        N_unique[j], reason_unique[j] = _law_gain(spec.law, tuple(sorted(parameters.items())), spec.geometry, *map(float, row[:4]))
    inverse = np.asarray(inverse).ravel()
    return N_unique[inverse], reason_unique[inverse]


SHORTCUT_BAND = 1e-6
"""Points within this relative distance of NV* (in NV) are always decided by `loop_verdicts` at their own NV."""


def distinct_rows(*columns) -> tuple[np.ndarray, np.ndarray]:
    """(index of one row per distinct combination, each row's combination number) of equal-length float columns (`numpy.lexsort`)."""
    order = np.lexsort(columns[::-1])
    changed = np.zeros(order.size, dtype=bool)
    changed[:1] = True
    for c in columns:
        sorted_c = c[order]
        changed[1:] |= sorted_c[1:] != sorted_c[:-1]
    group = np.cumsum(changed) - 1
    inverse = np.empty(order.size, dtype=np.int64)
    inverse[order] = group
    return order[changed], inverse


def loop_groups(tau, T, k):
    """`distinct_rows(tau, T, k)`, or None where grouping the points by loop would save nothing.

    None when more than half the points have a loop of their own — seen first
    on each column alone (one sort each: a column with more than n/2 distinct
    values makes as many distinct loops), which spares random samples of τ, T
    or k the sort of all three columns together.

    Parameters
    ----------
    tau, T, k : ndarray
        τ (s), T (s) and k (1/s) per point.
    """
    n = len(tau)
    for column in (T, tau, k):
        ordered = np.sort(column)
        if 2 * (1 + np.count_nonzero(ordered[1:] != ordered[:-1])) > n:
            return None
    groups = distinct_rows(tau, T, k)
    return None if 2 * len(groups[0]) > n else groups


_GROUP = object()
"""`model_answers`' default: group the points itself (`loop_groups`)."""


def model_answers(model: str, tau, T, k, NV, *, groups=_GROUP, **options) -> tuple:
    """(stable, verdict, NV*, margin) arrays of one model: `vectorized.loop_verdicts`, once per distinct loop.

    A model's boundary depends on the loop (τ, T, k) and not on NV
    (docs/models.md), and a sweep usually has few distinct loops (a grid in V
    and T has one per T). So `loop_verdicts` is asked once per distinct loop
    for NV* and whether the stable set is the usual (0, NV*); there a point is
    stable iff NV < NV*, labelled by the one verdict rule (`models.verdicts.judge_arrays`). Points
    within `SHORTCUT_BAND` of NV*, points with NV = 0 (the heading loop decides:
    docs/models.md, "N = 0") and every point of a loop with another stable
    set are decided by `loop_verdicts` at their own NV. With more than half as
    many distinct loops as points, every point goes to `loop_verdicts` directly.
    `groups` is `loop_groups(tau, T, k)` when the caller has it already.

    Parameters
    ----------
    model : str
        One of `parameters.MODEL_NAMES`.
    tau, T, k, NV : ndarray
        τ (s), T (s), k (1/s) and NV (1/s) per point.
    groups : tuple or None, optional
        `loop_groups(tau, T, k)` if the caller has it (None: no grouping); computed when not given.
    **options
        ``hold``, ``compute_delay``, ``pade_order`` (`vectorized.loop_verdicts`).
    """
    from ..vectorized import loop_verdicts

    groups = loop_groups(tau, T, k) if groups is _GROUP else groups
    if groups is None:
        v = loop_verdicts(model, tau, T, k, NV, **options)
        return np.array(v.stable, dtype=bool), np.array(v.verdict, dtype=object), np.array(v.NV_critical, dtype=float), np.array(v.margin, dtype=float)
    first, inverse = groups
    per_loop = loop_verdicts(model, tau[first], T[first], k[first], 1.0, **options)
    critical = np.asarray(per_loop.NV_critical, dtype=float)[inverse]
    regular = np.asarray(per_loop.regular, dtype=bool)[inverse]
    with np.errstate(divide="ignore", invalid="ignore"):
        edge = (critical > 0) & np.isfinite(critical)
        near = ~regular | (NV == 0) | (edge & (np.abs(NV / np.where(edge, critical, 1.0) - 1.0) <= SHORTCUT_BAND))
    stable = (NV > 0) & (NV < critical)  # inside the stable set (0, NV*) of a regular loop; N < 0 diverges
    verdict, margin = judge_arrays(NV, critical, stable)
    verdict = verdict.astype(object)
    index = np.flatnonzero(near)
    if index.size:
        v = loop_verdicts(model, tau[index], T[index], k[index], NV[index], **options)
        stable[index], verdict[index], critical[index], margin[index] = v.stable, v.verdict, v.NV_critical, v.margin
    return stable, verdict, critical, margin


def _verdict_columns(spec: SweepSpec, inputs: dict, NV: np.ndarray, reasons: np.ndarray) -> tuple[list, list, np.ndarray]:
    """Every model's four columns; the report's answers where NV is not a gain the models take."""
    from ..vectorized import resolved_lag_and_delay

    tau, T = resolved_lag_and_delay(inputs["tau"], inputs["T"], inputs["k"])  # as the models take them, before grouping
    negative = NV < 0
    zero = NV == 0
    beyond = ~np.isfinite(NV) | (np.abs(NV) > NV_MAX)
    reasons = reasons.copy()
    given = ~np.equal(reasons, None)  # elementwise: the points whose N already has a reason (no equilibrium)
    reasons[negative & ~given] = DIVERGENT_REASON
    reasons[zero & ~given] = NEUTRAL_REASON  # the verdict is each model's own at NV = 0: its heading loop's
    undefined = beyond | given & ~negative & ~zero
    for i in np.flatnonzero(beyond & ~given):
        reasons[i] = beyond_reason(float(NV[i]))
    safe = np.where(beyond, 1.0, NV)  # NV* does not depend on NV; the answer there is overwritten
    names, arrays = [], []
    groups = loop_groups(tau, T, inputs["k"])
    for model in spec.models:
        stable, verdict, critical, margin = model_answers(
            model, tau, T, inputs["k"], safe, groups=groups, hold=spec.controller.hold,
            compute_delay=spec.controller.compute_delay, pade_order=spec.pade_order, plant_gain=spec.robot.plant_gain,
            dead_time=spec.robot.dead_time, actuator_lag=spec.robot.actuator_lag, slip_lag=spec.robot.slip_lag)
        stable[undefined], verdict[undefined], margin[undefined] = False, None, math.nan
        names += list(model_columns(model))
        arrays += [stable, verdict, critical, margin]
    return names, arrays, reasons


def _simulation_columns(spec: SweepSpec, inputs: dict) -> list:
    """The simulator's σ and verdict for every point (`validation.sweep.simulate_members`)."""
    from ..laws.fields import make_law
    from ..models import Loop
    from ..validation.sweep import simulate_members, simulation_duration

    c = spec.controller
    size = inputs["V"].size
    duration = np.empty(size)
    for i in range(size):
        loop = Loop(float(inputs["tau"][i]), float(inputs["T"][i]), float(inputs["k"][i]))
        duration[i] = simulation_duration(loop, c.hold, c.compute_delay, spec.env)
    members = {name: inputs[name] for name in ("V", "tau", "k", "W", "f", "n", "T")}
    members["duration"] = duration
    if spec.geometry == "wall":
        members["alpha"] = inputs["alpha"] * RADIANS_PER_DEGREE
    else:
        members["L"] = inputs["L"]
    swept = [name for name in LAW_SWEPT if name in inputs]
    if spec.env == "grid":
        for name in ("cell_ratio", "cell_size", "window_cells"):
            if name in inputs:
                members[name] = inputs[name].astype(int) if name == "window_cells" else inputs[name]
            elif name in spec.law_parameters:
                members[name] = spec.law_parameters[name]
    elif spec.law != "power":
        laws = np.empty(size, dtype=object)
        for i in range(size):
            parameters = {**spec.law_parameters, **{n: (int(inputs[n][i]) if n == "window_cells" else float(inputs[n][i])) for n in swept}}
            robot = Robot(V=1.0, tau=0.0, k=1.0, W=float(inputs["W"][i]))
            controller = Controller(f=float(inputs["f"][i]), n=float(inputs["n"][i]), T=0.0)
            laws[i] = make_law(spec.law, robot, controller, **parameters)
        members["law"] = laws
    results = simulate_members(spec.geometry, env=spec.env, robot=spec.robot, controller=c, offset=SIM_OFFSET[spec.env], **members)
    sigma = np.array([math.nan if r.growth_rate is None else r.growth_rate for r in results])
    return [
        sigma,
        np.array([r.verdict == "stable" for r in results], dtype=bool),
        np.array([r.verdict for r in results], dtype=object),
        np.array([r.basis for r in results], dtype=object),
        np.array([r.method for r in results], dtype=object),
        np.array([r.collided for r in results], dtype=bool),
        np.array([r.reason for r in results], dtype=object),
    ]


def evaluate_chunk(spec: SweepSpec, start: int, stop: int, sample: dict | None = None) -> ChunkColumns:
    """Every column for points ``start`` … ``stop − 1`` of the sweep.

    Parameters
    ----------
    spec : SweepSpec
    start, stop : int
        Point indices (the ``point`` column).
    sample : dict, optional
        A sample sweep's points for this chunk (parameter → array of stop − start values,
        `points.chunk_points`); a grid computes its own from the indices.

    Returns
    -------
    ChunkColumns
    """
    if spec.sample is not None and sample is None:
        raise ValueError("a sample sweep's chunk needs its points (sample=)")
    values = chunk_points(spec, start, stop) if spec.sample is None else sample
    size = stop - start
    inputs = _inputs(spec, values, size)
    N, reasons = environment_gain(spec, inputs)
    with np.errstate(all="ignore"):
        NV = N * inputs["V"]
    names = ["point", *spec.input_columns, "N", "NV"]
    arrays = [np.arange(start, stop, dtype=np.int64), *(inputs[n] for n in spec.input_columns), N, NV]
    model_names, model_arrays, reasons = _verdict_columns(spec, inputs, NV, reasons)
    names += model_names + ["reason"]
    arrays += model_arrays + [reasons]
    if spec.simulate:
        names += list(SIM_COLUMNS)
        arrays += _simulation_columns(spec, inputs)
    return ChunkColumns(tuple(names), tuple(arrays))
