"""`loop_verdicts`: every loop model's verdict, NV* and margin for arrays of points.

A point is (τ, T, k, NV[, c]); a model (`parameters.MODEL_NAMES`) decides it
exactly as the scalar route of `pfm_stability.models` does,

    loop = Loop(τ, T, k, c=c); boundary = model.boundary(loop)
    stable = model.is_stable(NV, loop)
    verdict = verdict_label(NV, boundary, stable); margin = gain_margin(NV, boundary, stable)

but in arrays (docs/models.md, "Verdicts and margins"):

* ``continuous``, ``kb_first_order``: Routh's closed forms;
* ``exact_delay``: the crossing count and KB's three-level K* of
  `pfm_stability.numerics.delay` (c = 0); with a heading gain the stable set in K may
  be several intervals, and NV* comes from the scalar model, once per
  distinct loop;
* ``pade``, ``sampled``: the characteristic polynomial D + K·E (K = kNV) in
  arrays, decided by Liénard–Chipart (`vectorized.polynomial`); ``sampled``
  in the bilinear w-plane of its δ form (`vectorized.sampled`, closed-form
  zero-order hold).

Where the stable set in NV is not (0, NV*) (a sampled loop stable again
above NV*, or only above some NV > 0) the boundary and the verdict of those
few loops come from the scalar model, so `margin` and `verdict` always equal
the scalar route's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..models import Loop, make_model
from ..models.base import _check_NV
from ..models.verdicts import NV_MAX, gain_margin, judge_arrays, verdict_label
from ..parameters import HOLDS, KB_PLANT, MODEL_NAMES, check_parameter
from . import routes
from .exact_delay import _check, heading_gain_array, resolved_lag_and_delay
from .routes import Answers as _Answers

__all__ = ["COLUMNS", "LoopVerdicts", "loop_verdicts"]


@dataclass(frozen=True)
class LoopVerdicts:
    """Per-point answers of one loop model (arrays shaped like the broadcast inputs).

    Attributes
    ----------
    model : str
        The model's name (`parameters.MODEL_NAMES`).
    stable : ndarray of bool
        The scalar ``model.is_stable(NV, loop)``.
    verdict : ndarray of str
        ``"stable"``, ``"unstable"`` or ``"undecided"`` (within
        `models.base.UNDECIDED_RTOL` of an edge of the stable set):
        `models.verdict_label`.
    NV_critical : ndarray of float
        NV*, 1/s: stable for 0 < NV < NV* (``inf``: for every NV; 0: for no
        small NV) — `models.Boundary.NV_critical`.
    margin : ndarray of float
        `models.gain_margin`: NV_edge/NV − 1 (``inf`` when nothing bounds a
        stable point, −1 when no smaller NV is stable).
    omega_critical : ndarray of float
        Frequency of the oscillation that starts at NV*, rad/s; NaN where the
        scalar boundary has None (NV* 0 or infinite: no oscillation starts).
    K_critical : ndarray of float
        K* = k·NV*, 1/s².
    regular : ndarray of bool
        The loop's stable set in NV is (0, NV*) (or empty); False where it
        has other intervals (then verdict and margin follow the whole set).
    """

    model: str
    stable: np.ndarray
    verdict: np.ndarray
    NV_critical: np.ndarray
    margin: np.ndarray
    omega_critical: np.ndarray
    K_critical: np.ndarray
    regular: np.ndarray


def _NV_array(NV) -> np.ndarray:
    """NV as a float array: finite, |NV| <= `NV_MAX` (the scalar models' check, with the point index); −0.0 becomes 0.0."""
    try:
        NV = np.asarray(NV, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"NV must be a real number or an array of real numbers; got {NV!r}") from None
    bad = ~np.isfinite(NV) | (np.abs(NV) > NV_MAX)
    if bad.any():
        index = int(np.flatnonzero(bad.ravel())[0])
        value = float(NV.ravel()[index])
        try:
            _check_NV(check_number("NV", value, -NV_MAX, NV_MAX, low_open=False, high_open=False, unit="1/s"))
        except ValueError as exc:
            raise ValueError(f"{exc} (point {index})") from None
    return NV + 0.0


def _options(model, hold, compute_delay, pade_order, plant: dict):
    """The checked model name and its options (the scalar models' messages); `plant` holds each of
    `parameters.KB_PLANT`'s fields."""
    check_choice("model", model, MODEL_NAMES)
    hold = check_choice("hold", hold, HOLDS)
    compute_delay = check_integer("compute_delay", compute_delay, 0, 1)
    pade_order = check_integer("pade_order", pade_order, 1, 12)
    plant = {name: check_parameter(name, plant[name]) for name in KB_PLANT}
    return model, {"hold": hold, "compute_delay": compute_delay, "pade_order": pade_order, "plant": plant}


def _kb_plant(options) -> bool:
    """KB's plant 1/(τs + 1) (plant gain 1, no dead time, no second lag, no slip): the loops the array routes solve."""
    return options["plant"] == KB_PLANT


def loop_arrays(tau, T, k, NV, c=None):
    """Checked, broadcast, flattened (τ, T, k, c, NV) and their common shape.

    τ and T below their resolutions become 0, as `models.Loop` stores them
    (`resolved_lag_and_delay`); c defaults to 0.

    Raises
    ------
    ValueError
        Naming the first offending parameter, its range and the point index.
    """
    tau, T, k = (_check(name, x) for name, x in zip(("tau", "T", "k"), (tau, T, k)))
    NV = _NV_array(NV)
    c = np.zeros(()) if c is None else heading_gain_array(c)
    tau, T, k, c, NV = np.broadcast_arrays(tau, T, k, c, NV)
    shape = NV.shape
    tau, T, k, c, NV = (np.array(x, dtype=float).ravel() for x in (tau, T, k, c, NV))
    tau, T = resolved_lag_and_delay(tau, T, k)
    return (tau, T, k, c, NV), shape


def _scalar_route(model, points, index, answers: _Answers, verdicts: bool, plant: dict) -> list:
    """The scalar model's boundary at the points `index` (and its `is_stable` if `verdicts`), for the steering plant
    `plant` (``plant_gain``, ``dead_time``, ``actuator_lag``, ``slip_lag``): fills `answers` there and returns the (point, Boundary) pairs."""
    tau, T, k, c, NV = points
    out = []
    for i in index:
        loop = Loop(float(tau[i]), float(T[i]), float(k[i]), c=float(c[i]), **plant)
        boundary = model.boundary(loop)
        if verdicts:
            answers.stable[i] = model.is_stable(float(NV[i]), loop)
        answers.NV_critical[i] = boundary.NV_critical
        answers.omega_critical[i] = math.nan if boundary.omega_critical is None else boundary.omega_critical
        answers.regular[i] = _regular_set(boundary)
        out.append((i, boundary))
    return out


def _regular_set(boundary) -> bool:
    """The stable set is (0, NV*) — or empty when NV* = 0 — as `gain_margin` reads it without the set."""
    expected = ((0.0, boundary.NV_critical),) if boundary.NV_critical > 0 else ()
    return not boundary.stable_set or tuple(boundary.stable_set) == expected


def _fallback(points, options):
    """The scalar model at every point (a route for a model without an array route)."""
    n = points[0].size
    return _Answers(np.zeros(n, bool), np.zeros(n), np.zeros(n), np.ones(n, bool)), np.arange(n), True


def loop_verdicts(model, tau, T, k, NV, *, c=None, hold="command", compute_delay=0, pade_order=3, plant_gain=1.0, dead_time=0.0,
                  actuator_lag=0.0, slip_lag=0.0, columns="all") -> LoopVerdicts:
    """One loop model's verdicts, NV* and margins for arrays of points.

    All arrays broadcast together (scalars allowed).

    Parameters
    ----------
    model : str
        One of `parameters.MODEL_NAMES`.
    tau, T, k : array_like
        Steering time constant τ (s, [0, 100]), sampling period / delay T
        (s, [0, 100]), steering gain k (1/s, [10⁻⁶, 10⁴]).
    NV : array_like
        Loop gain NV, 1/s: finite, |NV| <= 10¹² (NV < 0 is unstable in
        every model: `models.divergent_reason`; NV = 0 is each model's
        heading loop, the neutral lateral root left out: `models.neutral_reason`,
        margin ``inf`` or −1).
    c : array_like, optional
        Heading gain (dimensionless, [−0.99, 100]; default 0, KB's loop).
    hold : {"command", "reference"}
        ``sampled`` only: what the computer holds (`parameters.HOLDS`).
    compute_delay : {0, 1}
        ``sampled`` only: samples from measurement to actuation.
    pade_order : int
        ``pade`` only: Padé order m, 1 … 12.
    plant_gain, dead_time, actuator_lag, slip_lag : float
        The steering plant's gain g ([0.001, 100]), dead time D (s, [0, 10]), second lag τ_a (s, [0, 10]) and the
        course's lag τ_s (s, [0, 10]), the same at every point (`models.Loop`; default 1, 0, 0 and 0, KB's plant). Another plant than KB's has no array route: every point is
        the scalar model's (`models.make_model`), some thirty times slower (6.5 against 0.25 ms a point for the five
        models, 200 random loops).
    columns : {"all", "verdict"}
        ``"all"`` (default): every field. ``"verdict"``: only `stable` and
        `verdict` (the same values as with ``"all"``), several times faster
        for ``sampled``, ``pade`` and ``exact_delay`` (no boundary search
        except at the few points near an edge, `_verdicts_only`); the other
        fields are then NaN (`regular`: False), not computed.

    Returns
    -------
    LoopVerdicts
        Arrays shaped like the broadcast inputs.

    Raises
    ------
    ValueError
        An unknown model or option, or the first out-of-range value
        (parameter, range, point index) — the scalar models' messages.
    """
    name, options = _options(model, hold, compute_delay, pade_order,
                             {"plant_gain": plant_gain, "dead_time": dead_time, "actuator_lag": actuator_lag, "slip_lag": slip_lag})
    check_choice("columns", columns, COLUMNS)
    points, shape = loop_arrays(tau, T, k, NV, c)
    if columns == "verdict" and name in _STABILITY and _kb_plant(options):
        return _verdicts_only(name, points, shape, options)
    return _all_columns(name, points, shape, options)


def _all_columns(name, points, shape, options) -> LoopVerdicts:
    """Every field of `LoopVerdicts` for flat checked points."""
    route = _ROUTES.get(name, _fallback) if _kb_plant(options) else _fallback  # another plant: the scalar model
    answers, scalar, verdicts = route(points, options)
    irregular = []
    if len(scalar):
        scalar_model = make_model(name, pade_order=options["pade_order"], hold=options["hold"], compute_delay=options["compute_delay"])
        irregular = _scalar_route(scalar_model, points, scalar, answers, verdicts, options["plant"])
    NV = points[4]
    verdict, margin = judge_arrays(NV, answers.NV_critical, answers.stable)
    if irregular:
        verdict = verdict.astype("<U9")
        for i, boundary in irregular:
            if not answers.regular[i]:
                verdict[i] = verdict_label(float(NV[i]), boundary, bool(answers.stable[i]))
                margin[i] = gain_margin(float(NV[i]), boundary, bool(answers.stable[i]))
    K_critical = points[2] * answers.NV_critical
    fields = (answers.stable, verdict, answers.NV_critical, margin, answers.omega_critical, K_critical, answers.regular)
    return LoopVerdicts(name, *(np.asarray(x).reshape(shape) for x in fields))


VERDICT_STEP = 1e-6
"""Relative step in NV of the verdict-only path's two extra tests (`_verdicts_only`)."""

_CHUNK = 1 << 16
"""Points per chunk of the verdict-only path (temporaries stay in the cache)."""


def _verdicts_only(name, points, shape, options) -> LoopVerdicts:
    """`stable` and `verdict` without the boundary: the same values as `_all_columns` gives.

    ``verdict`` is "undecided" when NV is within `UNDECIDED_RTOL` of an edge
    of the stable set, which needs that edge. But a point whose stability
    test gives one answer at NV(1 − ε), NV and NV(1 + ε) (ε = `VERDICT_STEP`
    = 10⁻⁶, a thousand times `UNDECIDED_RTOL`) has no edge within ε·NV: an
    edge there would flip the test between two of the three gains. Its label
    is then "stable" or "unstable" by the test at NV — exactly what
    `verdict_label` returns, since no |NV/edge − 1| <= 10⁻⁹ exists. Only the
    points where the three tests differ (about 2ε of random points), and
    those a model's test leaves open (`exact_delay`: three crossing
    frequencies, about 0.6 % of random points), go through `_all_columns`,
    in one call. Two assumptions, both stated: the array test
    and the array boundary agree to better than ε − 10⁻⁹ in NV (they come
    from the same polynomials: 10⁻¹² for closed forms, ~10⁻⁸ for the
    stiffest sampled loops), and no two edges of a stable set lie within
    ε·NV of each other around NV (two sign flips would cancel; the
    irregular sets of `sampled` have edges tens of percent apart).
    """
    test = _STABILITY[name]
    n = points[0].size
    stable = np.empty(n, dtype=bool)
    near = np.empty(n, dtype=bool)
    for lo in range(0, n, _CHUNK):
        part = tuple(x[lo:lo + _CHUNK] for x in points)
        stable[lo:lo + _CHUNK], near[lo:lo + _CHUNK] = test(part, options, part[2] * part[4], VERDICT_STEP)
    verdict = _LABELS.take(stable.view(np.uint8))
    index = np.flatnonzero(near)
    if index.size:
        edge = _all_columns(name, tuple(x[index] for x in points), (index.size,), options)
        stable[index] = edge.stable
        verdict[index] = edge.verdict
    nan = np.full(n, math.nan)
    fields = (stable, verdict, nan, nan, nan, nan, np.zeros(n, dtype=bool))
    return LoopVerdicts(name, *(np.asarray(x).reshape(shape) for x in fields))


_LABELS = np.array(["unstable", "stable"], dtype="<U9")

COLUMNS = ("all", "verdict")
"""What `loop_verdicts` computes: every field, or `stable` and `verdict` only."""

_STABILITY = {
    "exact_delay": routes.exact_delay_stable,
    "pade": routes.pade_stable,
    "sampled": routes.sampled_stable,
}
"""Model name → ``test(points, options, K, ε) -> (stable, near)`` (verdict-only path): `stable` at
the gains K, and `near` where an edge of the stable set may lie within a relative step ε of K (or where
the test does not decide: those points are decided with the boundary too)."""

_ROUTES = {
    "continuous": routes.continuous,
    "kb_first_order": routes.kb_first_order,
    "exact_delay": routes.exact_delay,
    "pade": routes.pade,
    "sampled": routes.sampled,
}
"""Model name → ``route(points, options) -> (_Answers, indices for the scalar boundary, scalar verdicts too)``."""
