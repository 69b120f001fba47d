"""A Nav2 controller tracking a straight path, decided by every loop model: verdicts and critical values.

The controller's law linearised about the path (`analysis.path_laws`: ω = −k_θ·e_θ − k_y·e_y at speed V) is KB's
steering loop `models.Loop` with k = k_θ, NV = k_y·V/k_θ and the heading sampled by the controller
(``heading_sampled=True``: every Nav2 controller computes ω from the pose, so the continuous-time models delay the
heading term by T + D as the rest), on the robot's plant g·e^(−sD)/((τs + 1)(τ_a·s + 1)); the ``sampled`` model holds
the command with the controller's compute delay. Every model decides that one loop, by the one verdict rule
(`models.verdicts.judge`), and gives (docs/path_tracking.md):

* **ρ*** (closed-form laws): with k = b·ρ and NV = a·ρ (ρ = V/L) the loop is one curve in ρ, and ρ* is the first
  ρ at which it loses stability (`ratio_critical`, by `numerics.solve.first_crossing` of the growth rate; time
  scaling makes every probe the loop at ρ_top with its lags and delays scaled by ρ/ρ_top, so a model's growth
  rates come in batches). ``exact_delay`` measures D − D*(ρ) instead, its exact dead-time margin.
* **V*** (the fastest stable cruising speed, the regulated speed, k and NV moving with it), **L*** (the shortest
  stable lookahead) and **lookahead_time*** (velocity-scaled RPP): where ρ reaches ρ* (ρ is monotone in each,
  `numerics.solve.bisect_root`); for measured gains (MPPI, DWB) V* = NV*/N with the gains held.
* **D*** and **T***: the model's `critical_dead_time` and `critical_delay` at the operating point.
* the **margin**: ρ*/ρ − 1 for the closed-form laws (how much V/L may grow), NV*/NV − 1 for measured gains, and
  the margin over the gains' uncertainty (±2 standard errors).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..io.serialize import json_number
from ..models import Loop, judge
from ..models.family import root_json
from ..numerics.solve import bisect_root, first_crossing
from ..parameters import RANGES
from .path_laws import Graceful, MeasuredGains, PurePursuit, TrackingPoint

__all__ = ["PathVerdict", "PathTracking", "LawVerdict", "law_verdict", "check_tracking_point", "ModelDelay", "analyze_path_tracking", "tracking_loop", "ratio_critical", "pure_delay_ratio", "GAIN_SPREAD",
           "RATIO_RTOL", "RATIO_POINTS_PER_DECADE"]

GAIN_SPREAD = 2.0
"""Standard errors either side of measured gains at which the verdict is checked too (about 95 % per gain)."""

RATIO_RTOL = 1e-6
"""Relative width to which ρ* is bisected (reports show 4 digits; V*, L* inherit it)."""

RATIO_POINTS_PER_DECADE = 8
"""Grid density of the search for ρ* (`numerics.solve.first_crossing`; its local maxima are refined, so a short
excursion above 0 between grid points is still found)."""

SERIAL_RTOL = 3e-2
"""Where a search whose probes cost one at a time (`exact_delay`'s dead-time margins, `pade`'s polynomials, `sampled`
with a dead time: `_serial`) leaves `numerics.solve.first_crossing` (one round of its batched bisection from a grid
cell) for `numerics.solve.bisect_root` (one probe a halving): the same bracket, about half the probes."""

_RATIO_DECADES = 3.0
"""The search for ρ* spans this many decades below the loop's slowest scale and above its fastest (`_ratio_bracket`)."""

PERIODS_IN_FLIGHT = 64
"""The `sampled` model's search for T* with a dead time D starts at T = D/64 (below it more than 64 commands are on
their way and each probe's eigenvalues cost the cube of that; the loop there is its T → 0 limit, checked stable,
to within a 64th of the dead time: `_delay_margins`)."""


@dataclass(frozen=True)
class ModelDelay:
    """MPPI's model delay recommended from the robot's delays (docs/path_tracking.md, "MPPI's model delay").

    Attributes
    ----------
    latency : float
        D + d·T: the time from the pose a command is computed from to the motor's first response, s.
    model_dt : float
        MPPI's rollout step, s.
    steps : int
        ⌊latency/model_dt + 0.5⌋: the shift MPPI's motion model applies (``motion_models.hpp``, ``offsetSteps``).
    recommended : float
        steps·model_dt, s: the value to set ``model_delay_wz`` (and ``model_delay_vx`` for the same drive) to.
    current : float
        The file's (or Nav2's default) ``model_delay_wz``, s.
    """

    latency: float
    model_dt: float
    steps: int
    recommended: float
    current: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (s)."""
        return dict(self.__dict__)


@dataclass(frozen=True)
class PathVerdict:
    """One model's answer for the path-tracking loop.

    Attributes
    ----------
    model : str
        `parameters.MODEL_NAMES`.
    verdict : str
        "stable", "unstable" or "undecided" (`models.verdicts.judge`).
    margin : float
        ρ*/ρ − 1 (closed-form laws) or NV*/NV − 1 (measured gains): > 0 stable.
    NV, NV_critical : float
        The loop's NV and the model's NV* with k held, 1/s.
    omega_critical : float or None
        rad/s at NV*.
    ratio_critical : float or None
        ρ* = (V/L)*, 1/s (None for measured gains).
    V_critical : float
        V*, m/s: every slower cruising speed is stable (``inf``: up to 100 m/s; 0: none).
    lookahead_critical : float or None
        L*, m: every longer lookahead is stable at this speed (``inf``: none is; 0: every one; None: no lookahead).
    lookahead_time_critical : float or None
        lookahead_time*, s (velocity-scaled RPP; None otherwise).
    dead_time_critical : float or None
        D*, s (None: the model has none, `sampled` with a held reference).
    T_critical : float
        T*, s.
    rightmost_root : complex or None
        σ + jω at the operating point.
    margin_range : tuple or None
        (lowest, highest) margin over the measured gains' ±`GAIN_SPREAD` standard errors (None: exact gains).
    verdict_range : str or None
        The verdict over that range: "stable" or "unstable" when all agree, else "undecided".
    reason : str or None
        Why the verdict is what it is beyond the model's answer.
    """

    model: str
    verdict: str
    margin: float
    NV: float
    NV_critical: float
    omega_critical: float | None
    ratio_critical: float | None
    V_critical: float
    lookahead_critical: float | None
    lookahead_time_critical: float | None
    dead_time_critical: float | None
    T_critical: float
    rightmost_root: complex | None = None
    margin_range: tuple | None = None
    verdict_range: str | None = None
    reason: str | None = None

    @property
    def stable(self) -> bool:
        """True only when the verdict is "stable"."""
        return self.verdict == "stable"

    def stable_side(self) -> dict:
        """Each critical value's side on which the loop is stable ("below", "above"; None for an undefined one)."""
        sides = {"V_critical": "below", "lookahead_critical": "above", "lookahead_time_critical": "above", "dead_time_critical": "below",
                 "T_critical": "below", "NV_critical": "below", "ratio_critical": "below"}
        return {key: (side if getattr(self, key) is not None and not _nan(getattr(self, key)) else None) for key, side in sides.items()}

    def to_dict(self) -> dict:
        """JSON-ready (SI units; infinities as "inf")."""
        out = {"stable": self.stable, "verdict": self.verdict, "margin": json_number(self.margin), "NV": self.NV,
               "NV_critical": json_number(self.NV_critical), "omega_critical": json_number(self.omega_critical)}
        for key in ("ratio_critical", "V_critical", "lookahead_critical", "lookahead_time_critical", "dead_time_critical", "T_critical"):
            value = getattr(self, key)
            out[key] = None if value is None else json_number(value)
        out["rightmost_root"] = root_json(self.rightmost_root)
        out["stable_side"] = self.stable_side()
        if self.margin_range is not None:
            out["margin_range"] = [json_number(m) for m in self.margin_range]
            out["verdict_range"] = self.verdict_range
        if self.reason is not None:
            out["reason"] = self.reason
        return out


@dataclass(frozen=True)
class MemoryVerdict:
    """The `sampled` loop closed by a measured controller's memory, its impulse response over several cycles
    (`models.memory.memory_loop_matrix`; MPPI's warm-started sequence: docs/path_tracking.md).

    Attributes
    ----------
    cycles : int
        Cycles of the response carried.
    stable : bool
        Every pole inside the unit circle.
    spectral_radius : float
        The largest pole modulus.
    growth_rate : float
        ln(spectral_radius)/T, 1/s.
    dead_time_critical : float
        D*, s: the largest dead time the loop with memory tolerates (0: unstable without one; ``inf``: stable up to the
        longest searched, `MEMORY_DEAD_TIME_PERIODS` periods or 10 s).
    """

    cycles: int
    stable: bool
    spectral_radius: float
    growth_rate: float
    dead_time_critical: float

    def to_dict(self) -> dict:
        """The fields, JSON-ready."""
        return {"cycles": self.cycles, "stable": self.stable, "spectral_radius": self.spectral_radius,
                "growth_rate": self.growth_rate, "dead_time_critical": json_number(self.dead_time_critical)}


MEMORY_DEAD_TIME_PERIODS = 399
"""The longest dead time `memory_verdict` searches, in controller periods: the closed-loop matrix carries the commands
on their way as states, as many as the eigenvalues resolve (`models.sampled.MAX_EIGEN_STATES`, less one)."""


def memory_verdict(loop: Loop, law: MeasuredGains, compute_delay: int) -> MemoryVerdict:
    """The loop with the measured controller's memory: its verdict and D* (`MemoryVerdict`).

    Parameters
    ----------
    loop : models.Loop
        The plant (τ, τ_a, g, D) and the period T.
    law : MeasuredGains
        With ``memory``.
    compute_delay : {0, 1}
        Samples from measurement to actuation.
    """
    from ..models.memory import memory_loop_matrix

    def rate(D: float) -> float:
        A = memory_loop_matrix(loop.replace(dead_time=float(D)), law.memory, law.V, compute_delay)
        return float(np.log(np.max(np.abs(np.linalg.eigvals(A))))) / loop.T

    sigma = rate(loop.dead_time)
    if rate(0.0) >= 0:
        D_star = 0.0
    else:
        high = min(MEMORY_DEAD_TIME_PERIODS * loop.T, RANGES["dead_time"].high)
        D_star = first_crossing(lambda Ds: np.array([rate(D) for D in Ds]), 1e-2 * loop.T, high, rtol=1e-6)
    return MemoryVerdict(len(law.memory[0]), sigma < 0, float(math.exp(sigma * loop.T)), sigma, D_star)


def _nan(x) -> bool:
    return isinstance(x, float) and math.isnan(x)


@dataclass(frozen=True)
class PathTracking:
    """A controller on a straight path (or a corridor's centre line), decided by every model.

    Attributes
    ----------
    controller : str
        ``rpp``, ``graceful``, ``mppi``, ``dwb``.
    law : PurePursuit, Graceful or MeasuredGains
        The linearised law (`analysis.path_laws`).
    point : TrackingPoint
        The law at the robot's cruising speed.
    loop : models.Loop
        The loop every model decides.
    half_width : float or None
        The corridor's half-width L_c, m (None: free space).
    models : dict
        Model name → `PathVerdict`.
    notes : tuple of str
        What the linearisation assumed or found inactive (the curvature heuristic on a straight path …).
    model_delay : ModelDelay or None
        MPPI's model delay recommended from D and T.
    pose_cost : int or None
        RPP: the costmap's cost at the robot (None for the other laws).
    memory : MemoryVerdict or None
        A measured controller's loop with its memory (MPPI, DWB measured over several cycles; None otherwise).
    """

    controller: str
    law: object
    point: TrackingPoint
    loop: Loop
    half_width: float | None
    models: dict
    notes: tuple = ()
    model_delay: ModelDelay | None = None
    pose_cost: int | None = field(default=None)
    memory: MemoryVerdict | None = None

    def to_dict(self) -> dict:
        """The geometry, the linearised law and every model's verdict, JSON-ready (SI units)."""
        p = self.point
        law = {"V_set": p.V_set, "V": p.V, "L": p.L, "k_theta": p.k_theta, "k_y": p.k_y, "N": p.N, "NV": p.NV, "ratio": p.ratio,
               "steering_lookahead": getattr(self.law, "steering", None)}
        if isinstance(self.law, MeasuredGains):
            law.update(k_theta_se=self.law.k_theta_se, k_y_se=self.law.k_y_se)
        out = {"controller": self.controller, "geometry": "corridor" if self.half_width is not None else "straight path",
               "L_corridor": self.half_width, "pose_cost": self.pose_cost, "law": law, "notes": list(self.notes),
               "models": {name: v.to_dict() for name, v in self.models.items()}}
        if self.memory is not None:
            out["memory"] = self.memory.to_dict()
        if self.model_delay is not None:
            out["model_delay"] = self.model_delay.to_dict()
        return out


# ------------------------------------------------------------------ the loop
def tracking_loop(robot, controller, point: TrackingPoint) -> Loop:
    """The steering loop of a linearised law: k = k_θ, the robot's plant, the controller's period, heading sampled.

    Parameters
    ----------
    robot : parameters.Robot
        τ, g, D, τ_a, τ_s (its k is not used: the controller's gains replace it).
    controller : parameters.Controller
        T.
    point : TrackingPoint
        The law's gains.
    """
    return Loop(robot.tau, controller.T, point.k_theta, plant_gain=robot.plant_gain, dead_time=robot.dead_time,
                actuator_lag=robot.actuator_lag, heading_sampled=True, slip_lag=robot.slip_lag)


def _ratio_bracket(loop: Loop, shape: tuple) -> tuple | None:
    """(ρ_lo, ρ_hi), 1/s, for the search of ρ*; None when the loop has neither a delay nor a lag (stable at every ρ).

    The loop's scales are 1/(g·(T + D)) (delays: a gain g·k against them) and 1/(τ + τ_a) (lags); the bracket runs
    `_RATIO_DECADES` decades below the smaller and above the larger, and stops where k = b·ρ leaves k's range.
    """
    g, delay, lags = loop.plant_gain, loop.T + loop.dead_time, loop.tau + loop.actuator_lag
    scales = ([1.0 / (g * delay)] if delay > 0 else []) + ([1.0 / lags] if lags > 0 else [])
    if not scales:
        return None
    factor = 10.0 ** _RATIO_DECADES
    top = min(max(scales) * factor, RANGES["k"].high / shape[1])
    return min(min(scales) / factor, 0.5 * top), top


def pure_delay_ratio(shape: tuple, plant_gain: float = 1.0) -> float:
    """c = ρ*·h of the loop without lags whose whole command is delayed by h: s² + g·b·ρ·(s + a·ρ)·e^(−sh) = 0.

    At a crossing s = jω, ν = ω/ρ solves ν⁴ = g²b²(a² + ν²), so ν² = (g²b² + √(g⁴b⁴ + 4g²b²a²))/2, and the phase
    gives ωh = atan(ν/a): stable iff ρ·h < atan(ν/a)/ν (RPP, a = 1, b = 2, g = 1: ν = 2.1973, c = 0.52049; the
    derivation is re-done with sympy in tests/test_path_tracking.py).

    Parameters
    ----------
    shape : (float, float)
        (a, b) of the law: NV = a·ρ, k = b·ρ.
    plant_gain : float
        g.
    """
    a, b = shape
    gb = plant_gain * b
    nu = math.sqrt(0.5 * (gb * gb + math.sqrt(gb ** 4 + 4.0 * gb * gb * a * a)))
    return math.atan(nu / a) / nu


def ratio_critical(model, loop: Loop, shape: tuple) -> float:
    """ρ*, 1/s: the first ρ > 0 at which the loop with k = b·ρ, NV = a·ρ (the rest of `loop`) loses stability.

    ``inf`` when it is stable up to the top of the search (`_ratio_bracket`) or at every ρ (no delay, no lag:
    s²(…) + g·b·ρ·(s + a·ρ) has positive coefficients). By `numerics.solve.first_crossing` of the growth rate σ(ρ),
    each probe the loop at ρ_top with its times scaled by λ = ρ/ρ_top (σ(ρ) = λ·σ_top(λ): the characteristic
    equation in s/λ), so the model's growth rates come for a batch at one gain, a decade at a time from a tenth of
    the pure-delay estimate (`pure_delay_ratio` with the lags counted as delays) up. ``exact_delay`` without lags is
    `pure_delay_ratio` itself (exact: its loop has the one delay T + D); with lags it measures D − D*(ρ), its exact
    dead-time margin (its growth rate is a pseudospectral eigenproblem).

    Parameters
    ----------
    model : LoopModel
        One of the five models.
    loop : Loop
        τ, T, g, D, τ_a (its k is replaced).
    shape : (float, float)
        (a, b) of the law (`PurePursuit.shape`, `Graceful.shape`).
    """
    a, b = shape
    bracket = _ratio_bracket(loop, shape)
    if bracket is None:
        return math.inf
    lo, top = bracket
    lags = loop.tau + loop.actuator_lag
    estimate = pure_delay_ratio(shape, loop.plant_gain) / (loop.T + loop.dead_time + lags)
    if model.name == "exact_delay":
        if lags == 0:
            return estimate if estimate <= top else math.inf
        D = loop.dead_time

        def measure(rhos):
            return np.array([D - model.critical_dead_time(a * r, loop.replace(k=b * r)) for r in np.atleast_1d(rhos)])
    else:
        top_loop, NV_top = loop.replace(k=b * top), a * top

        def measure(rhos):
            lam = np.atleast_1d(np.asarray(rhos, dtype=float)) / top
            scaled = [top_loop.replace(tau=top_loop.tau * x, actuator_lag=top_loop.actuator_lag * x, T=top_loop.T * x,
                                       dead_time=top_loop.dead_time * x) for x in lam]
            return lam * np.asarray(model.searched_growth_rates(NV_top, scaled), dtype=float)
    edges = [min(max(lo, 0.1 * estimate), 0.5 * top)]
    while edges[-1] < top:
        edges.append(min(10.0 * edges[-1], top))
    serial = _serial(model, loop)
    start = 0.0
    for low, high in zip(edges[:-1], edges[1:]):
        found = first_crossing(measure, low, high, start=start, points_per_decade=RATIO_POINTS_PER_DECADE,
                               rtol=SERIAL_RTOL if serial else RATIO_RTOL)
        if found < math.inf:
            return _refined(lambda r: float(measure(r)[0]), found, RATIO_RTOL) if serial else found
        start = high
    return math.inf


def _serial(model, loop: Loop) -> bool:
    """Whether the model's probes of this loop cost one at a time (`SERIAL_RTOL`): `exact_delay` (its margins), `pade` (its
    polynomials are built loop by loop), `sampled` with a dead time (its eigenvalues loop by loop)."""
    return model.name in ("exact_delay", "pade") or (model.name == "sampled" and loop.dead_time > 0)


def _refined(measure, found: float, rtol: float) -> float:
    """The sign change of `measure` in [found·(1 − SERIAL_RTOL), found] (a coarse first crossing) to `rtol`, by
    `numerics.solve.bisect_root`; `found` itself when the bracket's low end is not below 0 (a crossing at its start)."""
    low = found * (1.0 - SERIAL_RTOL)
    if not measure(low) < 0:
        return found
    return bisect_root(measure, low, found, rtol=rtol)


# ------------------------------------------------------------------ where ρ reaches ρ*
def _crossing(ratio_of, rho_star: float, lo: float, hi: float, increasing: bool) -> float:
    """The x in [lo, hi] where the monotone ρ(x) = `ratio_of(x)` reaches ρ* (stable on the side where ρ < ρ*).

    Increasing ρ: the largest stable x (0 when ρ(lo) >= ρ*, ``inf`` when ρ(hi) < ρ*). Decreasing: the smallest
    (``inf`` when ρ(hi) >= ρ*, 0 when ρ(lo) < ρ*). `numerics.solve.bisect_root` on the sign of ρ(x) − ρ*.
    """
    if rho_star == math.inf:
        return math.inf if increasing else 0.0
    if rho_star <= 0:
        return 0.0 if increasing else math.inf
    f = lambda x: 1.0 if ratio_of(x) >= rho_star else -1.0  # noqa: E731
    if increasing:
        if f(lo) > 0:
            return 0.0
        if f(hi) < 0:
            return math.inf
    else:
        if f(hi) > 0:
            return math.inf
        if f(lo) < 0:
            return 0.0
    return bisect_root(f, lo, hi, rtol=1e-12)


def _speed_critical(law, rho_star: float) -> float:
    """V*: the fastest stable cruising speed (ρ non-decreasing in it), m/s."""
    r = RANGES["V"]
    return _crossing(lambda V: law.point(V).ratio, rho_star, 1e-9 * r.high, r.high, True)


def _lookahead_critical(law, point: TrackingPoint, rho_star: float) -> float:
    """L*: the shortest stable lookahead at this speed, m (RPP: V/ρ*; Graceful: its speed moves with L)."""
    if isinstance(law, PurePursuit):
        return point.V / rho_star if rho_star > 0 else math.inf
    return _crossing(lambda L: law.with_lookahead("max_lookahead", L).point(point.V_set).ratio, rho_star, 1e-6, RANGES["L"].high, False)


def _lookahead_time_critical(law, point: TrackingPoint, rho_star: float) -> float | None:
    """lookahead_time* of velocity-scaled RPP, s (None for another law)."""
    if not (isinstance(law, PurePursuit) and law.steering == "velocity-scaled"):
        return None
    return _crossing(lambda t: law.with_lookahead("lookahead_time", t).point(point.V_set).ratio, rho_star, 1e-9, 100.0, False)


# ------------------------------------------------------------------ every model
@dataclass(frozen=True)
class LawVerdict:
    """One model's verdict and ρ-critical values of a closed-form law (RPP, Graceful) at one operating point: the part of
    `PathVerdict` that does not need the delay searches (D*, T*), so that many operating points of one loop (the
    stretches of a map, `maps.deciding.tracking`) share one ρ* search.

    Attributes
    ----------
    verdict : str
        "stable", "unstable" or "undecided" (`models.verdicts.judge`).
    margin : float
        ρ*/ρ − 1.
    NV, NV_critical : float
        The loop's NV and the model's NV* with k held, 1/s.
    omega_critical : float or None
        rad/s at NV*.
    ratio_critical : float
        ρ* = (V/L)*, 1/s.
    V_critical : float
        V*, m/s (`_speed_critical`).
    lookahead_critical : float
        L*, m (`_lookahead_critical`).
    lookahead_time_critical : float or None
        lookahead_time*, s (velocity-scaled RPP; None otherwise).
    reason : str or None
        Why the verdict is what it is beyond the model's answer.
    """

    verdict: str
    margin: float
    NV: float
    NV_critical: float
    omega_critical: float | None
    ratio_critical: float
    V_critical: float
    lookahead_critical: float
    lookahead_time_critical: float | None
    reason: str | None = None


def law_verdict(model, law, point: TrackingPoint, loop: Loop, rho_star: float | None = None) -> LawVerdict:
    """One model's `LawVerdict` for a closed-form law at `point` (module docstring): the verdict by the one rule
    (`models.verdicts.judge`), ρ* (`ratio_critical`), the margin ρ*/ρ − 1, V*, L* and lookahead_time*.

    Parameters
    ----------
    model : LoopModel
        One of the five models.
    law : PurePursuit or Graceful
        The linearised law.
    point : TrackingPoint
        The law at the cruising speed.
    loop : Loop
        The loop of `point` (`tracking_loop`).
    rho_star : float, optional
        ρ* of this model and loop, 1/s, when already known (it does not depend on k, so every operating point of one
        plant and period shares it); default: searched (`ratio_critical`).
    """
    boundary = model.boundary(loop)
    judgement = judge(point.NV, point.N, boundary, lambda nv: model.is_stable(nv, loop))
    rho_star = ratio_critical(model, loop, law.shape) if rho_star is None else rho_star
    margin = rho_star / point.ratio - 1.0
    reason = judgement.reason
    if judgement.verdict == "stable" and margin < 0:  # stable beyond the first loss along the ray: a later band of ρ
        reason = "stable in a band of V/L beyond the first loss of stability (V*, L* bound the first band)"
    return LawVerdict(judgement.verdict, margin, point.NV, boundary.NV_critical, boundary.omega_critical, rho_star,
                      _speed_critical(law, rho_star), _lookahead_critical(law, point, rho_star),
                      _lookahead_time_critical(law, point, rho_star), reason)


def _verdict(model, law, point: TrackingPoint, loop: Loop) -> PathVerdict:
    """One model's `PathVerdict` (module docstring)."""
    NV, N = point.NV, point.N
    unstable_at_once = N < 0
    if isinstance(law, MeasuredGains):
        boundary = model.boundary(loop)
        judgement = judge(NV, N, boundary, lambda nv: model.is_stable(nv, loop))
        stable = judgement.stable
    else:
        own = law_verdict(model, law, point, loop)
        stable = own.verdict == "stable"
    T_star, D_star = (0.0, 0.0) if unstable_at_once else _delay_margins(model, NV, loop, stable)
    root = None if unstable_at_once else model.rightmost_root(NV, loop)
    if isinstance(law, MeasuredGains):
        low, high, verdicts = _gain_range(model, law, loop)
        return PathVerdict(model=model.name, verdict=judgement.verdict, NV=NV, NV_critical=boundary.NV_critical,
                           omega_critical=boundary.omega_critical, dead_time_critical=D_star, T_critical=T_star, rightmost_root=root,
                           reason=judgement.reason, margin=judgement.margin, ratio_critical=None, V_critical=judgement.V_critical,
                           lookahead_critical=None, lookahead_time_critical=None, margin_range=None if low is None else (low, high),
                           verdict_range=verdicts)
    return PathVerdict(model=model.name, verdict=own.verdict, margin=own.margin, NV=NV, NV_critical=own.NV_critical,
                       omega_critical=own.omega_critical, ratio_critical=own.ratio_critical, V_critical=own.V_critical,
                       lookahead_critical=own.lookahead_critical, lookahead_time_critical=own.lookahead_time_critical,
                       dead_time_critical=D_star, T_critical=T_star, rightmost_root=root, reason=own.reason)


def _delay_margins(model, NV: float, loop: Loop, stable: bool) -> tuple:
    """(T*, D*), s, of the operating point (`stable`: the model's verdict there).

    The model's own where they are exact or closed (`kb_first_order`, `exact_delay`; `continuous` has no delay: ``inf``
    or 0 for both). Searched otherwise (`LoopModel.first_loss`, a decade at a time from the bottom:
    `_searched_margin`). The continuous-time models see T and D only as the loop's one delay h = T + D (the heading is
    sampled), so `pade` searches h from 0 once: stable for every h < h*, so T* = h* − D and D* = h* − T when the
    operating point lies below h* (else each is searched). `sampled` searches T from D/`PERIODS_IN_FLIGHT` and has no
    D* with a held reference (None)."""
    from ..models.base import LoopModel

    if model.name == "continuous":  # no delay in the model: stable at every T and D, or at none (its own T*)
        T_star = model.critical_delay(NV, loop)
        return T_star, T_star
    if type(model).critical_delay is not LoopModel.critical_delay:  # exact or closed: kb_first_order, exact_delay
        return model.critical_delay(NV, loop), model.critical_dead_time(NV, loop)
    tolerances = loop.delay_search(NV)
    start = tolerances[0]
    dead_time = lambda D, base=loop: base.replace(dead_time=float(D))  # noqa: E731
    if model.name != "sampled":  # pade: the whole delay h = T + D
        h_star = _searched_margin(model, NV, lambda h: dead_time(h, loop.replace(T=0.0)), start, RANGES["dead_time"].high, tolerances)
        if stable and h_star > loop.T + loop.dead_time:
            return h_star - loop.dead_time, h_star - loop.T
    if model.name == "sampled" and loop.dead_time > 0:
        start = max(start, loop.dead_time / PERIODS_IN_FLIGHT)
    T_star = _searched_margin(model, NV, loop._with_delay, start, RANGES["T"].high, tolerances)
    if model.name == "sampled" and model.hold == "reference":
        return T_star, None
    return T_star, _searched_margin(model, NV, dead_time, tolerances[0], RANGES["dead_time"].high, tolerances)


def _searched_margin(model, NV: float, probe, low: float, high: float, tolerances) -> float:
    """The first x in (0, high] at which the loop `probe(x)` loses stability (0: already at x = 0; ``inf``: not up to
    `high`), by the model's search over [low, high] a decade at a time from the bottom, stopping at the first crossing."""
    _, rtol, atol = tolerances
    serial = _serial(model, probe(low))
    options = {"rtol": SERIAL_RTOL if serial else rtol, "atol": atol, "points_per_decade": RATIO_POINTS_PER_DECADE}
    edges = [low]
    while edges[-1] < high:
        edges.append(min(10.0 * edges[-1], high))
    origin = 0.0
    for lo, hi in zip(edges[:-1], edges[1:]):
        found = model.first_loss(NV, probe, origin, lambda lo=lo, hi=hi: (lo, hi, options))
        if found < math.inf:
            if serial and found > 0:
                return _refined(lambda x: float(model.searched_growth_rates(NV, [probe(x)])[0]), found, rtol)
            return found
        origin = hi
    return math.inf


def _gain_range(model, law: MeasuredGains, loop: Loop) -> tuple:
    """(lowest margin, highest margin, verdict) over the measured gains' corners at ±`GAIN_SPREAD` standard errors;
    (None, None, None) for exact gains."""
    if law.k_theta_se == 0 and law.k_y_se == 0:
        return None, None, None
    margins, verdicts = [], set()
    for k_theta, k_y in law.corners(GAIN_SPREAD):
        corner = loop.replace(k=k_theta)
        NV = k_y * law.V / k_theta
        j = judge(NV, k_y / k_theta, model.boundary(corner), lambda nv: model.is_stable(nv, corner))
        margins.append(j.margin)
        verdicts.add(j.verdict)
    return min(margins), max(margins), verdicts.pop() if len(verdicts) == 1 else "undecided"


def _notes(law, point: TrackingPoint, half_width) -> tuple:
    """What the linearisation found inactive or assumed (docs/path_tracking.md)."""
    notes = []
    if isinstance(law, PurePursuit):
        v = law.values
        if v["use_regulated_linear_velocity_scaling"] and law.curvature == 0:
            notes.append("curvature heuristic inactive on a straight path (kappa = 0: radius beyond regulated_linear_scaling_min_radius)")
        elif v["use_regulated_linear_velocity_scaling"]:
            notes.append(f"curvature heuristic at the path's curvature {law.curvature:.4g} 1/m (radius {1 / abs(law.curvature):.4g} m; "
                         "the gains are the straight path's)")
        scale = law.cost_scale()
        if v["use_cost_regulated_linear_velocity_scaling"]:
            if scale is None:
                notes.append(f"cost heuristic inactive (cost {law.pose_cost} at the robot"
                             + (": free space)" if half_width is None else f" in the corridor L = {half_width:g} m)"))
            else:
                notes.append(f"cost heuristic: V = max_linear_vel x {scale:.4g} (cost {law.pose_cost} at the robot in the corridor "
                             f"L = {half_width:g} m), at least regulated_linear_scaling_min_speed")
        if law.steering == "curvature":
            notes.append("use_fixed_curvature_lookahead: the carrot at curvature_lookahead_dist steers (L is that distance)")
        if v["use_dynamic_window"]:
            notes.append("use_dynamic_window: the window's acceleration limits do not bind for the small deviations of the linear loop")
        notes.append("the carrot is interpolated along the plan (Nav2 always does): L is the lookahead itself")
    if isinstance(law, Graceful):
        notes.append("motion target at max_lookahead (the farthest valid target: in a free corridor the first); min_lookahead is "
                     "not read by the control law")
    if isinstance(law, MeasuredGains):
        notes.append(f"numeric gains measured at V = {point.V:g} m/s (V* holds them: a controller whose gains move with V needs "
                     "them measured there)")
    return tuple(notes)


def _model_delay(law, values: dict, robot, controller) -> ModelDelay | None:
    """MPPI's ``model_delay_wz`` recommended from the robot's dead time and the controller's compute delay."""
    if getattr(law, "name", None) != "mppi" or values is None:
        return None
    dt = values["model_dt"]
    latency = robot.dead_time + controller.compute_delay * controller.T
    steps = int(math.floor(latency / dt + 0.5))
    return ModelDelay(latency, dt, steps, steps * dt, values["model_delay_wz"])


def check_tracking_point(point: TrackingPoint) -> None:
    """ValueError unless the law at `point` drives forward (V > 0) with a steering gain k_θ in the loop's range.

    Parameters
    ----------
    point : TrackingPoint
        The law at the cruising speed.
    """
    if point.V <= 0:
        raise ValueError(f"the controller drives at V = {point.V:g} m/s on the path: the lateral loop needs V > 0")
    k = RANGES["k"]
    if not k.low <= point.k_theta <= k.high:
        what = f"V = {point.V:g} m/s over the lookahead L = {point.L:g} m" if point.L is not None else f"k_theta = {point.k_theta:g} 1/s"
        raise ValueError(f"the controller's steering gain k_theta = {point.k_theta:g} 1/s ({what}) is outside the loop's "
                         f"steering gains {k.describe()}")


def analyze_path_tracking(robot, controller, law, models, *, V_set: float | None = None, half_width: float | None = None,
                          values: dict | None = None) -> PathTracking:
    """Every model's verdict and critical values for a controller's law about a straight path (module docstring).

    Parameters
    ----------
    robot : parameters.Robot
        The plant: τ, g, D, τ_a (its V is the cruising speed unless `V_set` is given).
    controller : parameters.Controller
        T, hold and compute delay (the `sampled` model's).
    law : PurePursuit, Graceful or MeasuredGains
        The linearised law (`analysis.path_laws.path_law`).
    models : sequence of LoopModel
        The models (`models.models_for(controller, …)`).
    V_set : float, optional
        The cruising speed parameter, m/s (default robot.V).
    half_width : float, optional
        The corridor's half-width L_c, m (default the law's: `PurePursuit.half_width`; None: free space).
    values : dict, optional
        The controller's Nav2 parameters (MPPI's ``model_dt`` and ``model_delay_wz`` for `ModelDelay`).

    Returns
    -------
    PathTracking
    """
    half_width = getattr(law, "half_width", None) if half_width is None else half_width
    point = law.point(robot.V if V_set is None else V_set)
    check_tracking_point(point)
    loop = tracking_loop(robot, controller, point)
    verdicts = {m.name: _verdict(m, law, point, loop) for m in models}
    memory = None
    if isinstance(law, MeasuredGains) and law.memory is not None and len(law.memory[0]) > 1 and loop.T > 0:
        memory = memory_verdict(loop, law, controller.compute_delay)
    return PathTracking(law.name, law, point, loop, half_width, verdicts, _notes(law, point, half_width),
                        _model_delay(law, values, robot, controller), getattr(law, "pose_cost", None), memory)
