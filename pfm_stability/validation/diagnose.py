"""Why a robot oscillates, from its own log: the oscillation measured on each stretch set against every model's (docs/diagnose.md).

`diagnose` takes a log read with the command, the odometry (its yaw rate and pose) and the scans reduced by
`analysis.stretches.wall_lines`, and the robot and controller (k, W, f, n from the user; τ and T from the user
or identified from the same log, `complete_from_log`). On every stretch along a wall or through a corridor
(`analysis.stretches.find_stretches`) it

1. **measures** the lateral oscillation on the binned lateral offset: σ (1/s) and the amplitude (the limit cycle's,
   else the largest half peak-to-peak swing, m) with the project's one estimator (`sim.metrics.oscillation_metrics`),
   and ω (rad/s) with its 95 % interval from the zero crossings of the part of the stretch that oscillates, the start
   transient dropped (`analysis.frequency.crossing_frequency`; a stretch of too few periods says so);
2. **predicts** it with every loop model, at the loop gain NV of the corridor of the measured half-width L
   (`laws.force_law.corridor_gain`) or of the wall whose equilibrium is the measured d0 (α and N from the law's
   balance at d0, `laws.force_law.wall_gain_at_distance`), V the robot's measured speed there: each model's
   verdict, margin and V* (the one verdict rule, `models.verdicts.judge`) and its dominant root σ + jω; for the
   stretch that answers for the whole log also T*, k* and the remedies (`report.stability.build_report`, whose
   verdicts these are);
3. **compares**: a model *matches* when its verdict is the measured one (the sign of σ; a stretch without an
   oscillation that settles is stable) and its root is within `MATCH` of the measured σ + jω (relative
   distance in the complex plane); the best match is the nearest. The remedies are the report's for that
   model (else the ``sampled`` model's).

A stretch that cannot be judged says why (`StretchDiagnosis.reason`): shorter than `MIN_DURATION`, odometry
missing for longer than `MAX_GAP`, a corridor not wider than the robot, a wall where the law never balances
the pull, a robot too slow, or an offset that neither oscillates measurably nor settles. The whole log's
answer is that of its worst judged stretch (the largest measured σ; a stretch without σ ranks below any σ).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..analysis.frequency import FrequencyEstimate, crossing_frequency
from ..analysis.identification import ridge_point
from ..analysis.stretches import MIN_DURATION, MIN_SPEED, LateralOffset, Stretch, find_stretches, lateral_offset
from ..io.logs import LogData, PoseSeries
from ..io.serialize import json_number
from ..laws.force_law import ForceLaw, corridor_gain, law_in_force, wall_gain_at_distance
from ..models import Loop, models_for
from ..models.verdicts import judge
from ..parameters import MODEL_NAMES, RANGES, Controller, Robot, to_degrees
from ..report.stability import build_report
from ..sim.metrics import HYSTERESIS, OscillationMetrics, oscillation_metrics, turning_points

__all__ = ["Measured", "Predicted", "StretchDiagnosis", "Diagnosis", "diagnose", "complete_from_log", "missing_parameters",
           "Limiter",
           "needs_identification", "USER_PARAMETERS", "LOG_PARAMETERS", "MATCH", "MAX_GAP", "MIN_AMPLITUDE", "VERDICTS", "REACHED"]

USER_PARAMETERS = ("k", "W", "f", "n")
"""What no log shows: the steering gain, the robot's width and KB's law (f, n): the user's (``--config`` or options)."""
LOG_PARAMETERS = ("tau", "T", "dead_time", "plant_gain", "actuator_lag", "yaw_accel_limit", "slip_lag")
"""What the log shows (`analysis.identification`): the steering lag, the controller's period, the plant's dead time and
gain, its second lag and the slew limit on its command (when the data support them), and its base's slide from the
odometry's pose (when its interval excludes 0), unless the user gives them. The log is identified when τ or T is
missing (`needs_identification`); D, g, τ_a, the limit and the slide alone keep their defaults (0 s, 1, 0 s, none,
0 s) rather than ask a log without commands for them."""
MATCH = 0.15
"""A model matches when its root is within this relative distance of the measured σ + jω (and its verdict agrees)."""
MIN_AMPLITUDE = 0.005
"""Swings of the lateral offset smaller than this (m) are not an oscillation: wheel odometry and walls fitted to a
scan's ranges do not resolve them (a settled robot's offset wanders by about a millimetre)."""
MAX_GAP = 1.0
"""A stretch whose odometry misses more than this (s) at once is not judged (interpolating over it would invent a swing)."""
VERDICTS = ("oscillating", "stable", "nothing to diagnose")
"""The whole log's answer."""
REACHED = 0.9
"""The commands reached the slew limit A on a stretch when their |du/dt| (95th percentile) is at least this fraction of A:
a discrete smoother's staircase shows slopes of about A while it ramps, and a command changing at 90 % of A is ramped
every few ticks."""


# ------------------------------------------------------------------------------------------ results
@dataclass(frozen=True)
class Measured:
    """The oscillation measured on one stretch (`sim.metrics.oscillation_metrics` of its lateral offset).

    Attributes
    ----------
    omega : float or None
        ω, rad/s: from the zero crossings of the established oscillation (`frequency`), else the estimator's.
    sigma : float or None
        σ, 1/s (> 0 growing); None when no oscillation was measured.
    amplitude : float or None
        m: the limit cycle's half peak-to-peak amplitude, else the largest half peak-to-peak swing.
    stable : bool
        σ < 0, or no oscillation and a settling offset.
    method : str
        The estimator's method (``peaks``, ``linear_prediction``, ``none``).
    turning_points : int
        Turning points of the offset.
    reason : str or None
        Why σ is undefined.
    frequency : FrequencyEstimate or None
        ω from the zero crossings: its 95 % interval, the crossings used and dropped (the start transient), the
        established periods and whether they are too few for an interval (`analysis.frequency`); None without a
        measured oscillation.
    """

    omega: float | None
    sigma: float | None
    amplitude: float | None
    stable: bool
    method: str
    turning_points: int
    reason: str | None = None
    frequency: FrequencyEstimate | None = None

    @property
    def few_periods(self) -> bool:
        """Whether ω rests on too few established periods for an interval (`analysis.frequency.MIN_CROSSINGS`)."""
        return self.frequency is not None and self.frequency.few_periods

    def to_dict(self) -> dict:
        """``{omega, omega_interval, frequency, sigma, amplitude, stable, method, turning_points, reason}`` (SI units)."""
        f = self.frequency
        return {"omega": json_number(self.omega),
                "omega_interval": None if f is None or f.low is None else [json_number(f.low), json_number(f.high)],
                "frequency": None if f is None else f.to_dict(),
                "sigma": json_number(self.sigma), "amplitude": json_number(self.amplitude),
                "stable": self.stable, "method": self.method, "turning_points": self.turning_points, "reason": self.reason}


@dataclass(frozen=True)
class Predicted:
    """One model's prediction for one stretch.

    Attributes
    ----------
    model : str
    stable : bool
    verdict : str
        ``stable``, ``unstable`` or ``undecided``.
    margin : float
        NV*/NV − 1.
    V_critical : float
        The critical speed V* = NV*/N (m/s), the others fixed (``inf``: none).
    T_critical, k_critical : float or None
        The critical period (s) and steering gain (1/s), the others fixed (``inf``: none); computed for the whole log's
        stretch only (None elsewhere: their searches cost 0.1 s a stretch).
    omega, sigma : float or None
        The dominant root's imaginary (rad/s) and real part (1/s); None where the model has none.
    root_error : float or None
        |predicted − measured root| / |measured root| (None without both roots).
    matches : bool
        The verdict agrees with the measured one and `root_error` ≤ `MATCH` (without a measured root: the verdict alone).
    """

    model: str
    stable: bool
    verdict: str
    margin: float
    V_critical: float
    T_critical: float | None
    k_critical: float | None
    omega: float | None
    sigma: float | None
    root_error: float | None
    matches: bool

    def to_dict(self) -> dict:
        """``{stable, verdict, V_critical, T_critical, k_critical, margin, omega, sigma, root_error, matches}``."""
        return {"stable": self.stable, "verdict": self.verdict, "V_critical": json_number(self.V_critical),
                "T_critical": json_number(self.T_critical), "k_critical": json_number(self.k_critical),
                "margin": json_number(self.margin), "omega": json_number(self.omega), "sigma": json_number(self.sigma),
                "root_error": json_number(self.root_error), "matches": self.matches}


@dataclass(frozen=True)
class Limiter:
    """The slew limit on the commanded yaw rate the prediction was made with, and whether the log's commands reached it.

    Attributes
    ----------
    yaw_accel_limit : float
        A, rad/s² (`Robot.yaw_accel_limit`).
    in_prediction : bool
        Whether the predicted V* accounts for it (False: the loop models are linear; their V* holds for a disturbance
        small enough that the commands never change faster than A).
    commanded_acceleration : float or None
        The 95th percentile of the commands' |du/dt| over the judged stretch, rad/s² (None: the log was read without
        its commands).
    reached : bool or None
        commanded_acceleration ≥ `REACHED`·A: the limit shaped the measured oscillation, and the linear V* may be off
        for it (None without the commands).
    note : str
        What this means for the prediction, in words.
    disturbance : float or None
        The size of the weave the judged stretch shows (its measured amplitude, m) at which the limited loop is asked.
    V_disturbance : float or None
        V*(disturbance), m/s: the fastest speed at which a start that size settles with the limit (the limiter's
        describing function on the sampled loop, `analysis.disturbance`; None where it gives none, see `note`).
    """

    yaw_accel_limit: float
    in_prediction: bool
    commanded_acceleration: float | None
    reached: bool | None
    note: str
    disturbance: float | None = None
    V_disturbance: float | None = None

    def to_dict(self) -> dict:
        """``{yaw_accel_limit, in_prediction, commanded_acceleration, reached, note, disturbance, V_disturbance}`` (SI units)."""
        return {"yaw_accel_limit": json_number(self.yaw_accel_limit), "in_prediction": self.in_prediction,
                "commanded_acceleration": json_number(self.commanded_acceleration), "reached": self.reached, "note": self.note,
                "disturbance": json_number(self.disturbance), "V_disturbance": json_number(self.V_disturbance)}


@dataclass(frozen=True)
class StretchDiagnosis:
    """One stretch: what was measured and predicted there, or why it was not judged.

    Attributes
    ----------
    stretch : Stretch
    judged : bool
    reason : str or None
        Why it was not judged (None when judged).
    V : float or None
        The robot's speed on the stretch, m/s: the odometry's forward speed (median), else its path length over time.
    geometry : float or None
        L (corridor) or d0 (wall), m: d0 is the swings' midpoint extrapolated to zero amplitude (`_equilibrium_shift`).
    alpha_deg : float or None
        The wall's α (deg) at which the law balances the pull at d0.
    offset : LateralOffset or None
        The lateral offset measured.
    measured : Measured or None
    predicted : dict
        Model name → `Predicted`.
    matching : str or None
        The best-matching model (module docstring), None if none matches.
    remedies : dict
        Parameter → {to, direction, change_percent} (`report.stability.remedies`) of the matching model, else ``sampled``'s;
        for the whole log's stretch only (empty elsewhere).
    envelope : tuple or None
        (t0 in s, a0 in m): the first swing's mid time and half amplitude, where the predicted envelope a0·e^(σ(t − t0)) starts.
    """

    stretch: Stretch
    judged: bool
    reason: str | None = None
    V: float | None = None
    geometry: float | None = None
    alpha_deg: float | None = None
    offset: LateralOffset | None = None
    measured: Measured | None = None
    predicted: dict = field(default_factory=dict)
    matching: str | None = None
    remedies: dict = field(default_factory=dict)
    envelope: tuple | None = None

    @property
    def margin(self) -> float | None:
        """The margin of the matching model, else of ``sampled`` (None without predictions)."""
        p = self.predicted.get(self.matching or "sampled")
        return None if p is None else p.margin

    def to_dict(self) -> dict:
        """The stretch, the numbers, ``measured`` and ``predicted.<model>`` (JSON-ready)."""
        out = {**self.stretch.to_dict(), "judged": self.judged, "reason": self.reason, "V": json_number(self.V)}
        out["L" if self.stretch.kind == "corridor" else "d0"] = json_number(self.geometry)
        if self.stretch.kind == "wall":
            out["alpha_deg"] = json_number(self.alpha_deg)
        out["measured"] = None if self.measured is None else {**self.measured.to_dict(), "stretch": self.stretch.index}
        out["predicted"] = {name: p.to_dict() for name, p in self.predicted.items()}
        out["matching_model"] = self.matching
        out["margin"] = json_number(self.margin)
        out["remedies"] = self.remedies
        return out


@dataclass(frozen=True)
class Diagnosis:
    """The whole log's diagnosis.

    Attributes
    ----------
    verdict : str
        One of `VERDICTS`.
    reason : str
        The answer in words (why nothing was diagnosed, or what oscillates).
    stretches : tuple of StretchDiagnosis
        Every stretch found, judged or not.
    worst : int or None
        The index of the stretch that answers for the whole log (module docstring).
    robot, controller : Robot, Controller
        The parameters predicted with (V: the worst stretch's, else the robot's).
    pose : PoseSeries
        The odometry's pose (for the picture).
    law : ForceLaw
        The lateral law predicted with.
    limiter : Limiter or None
        The slew limit on the commanded yaw rate and what it means for the prediction (None: the robot has none).
    """

    verdict: str
    reason: str
    stretches: tuple
    worst: int | None
    robot: Robot
    controller: Controller
    pose: PoseSeries
    law: ForceLaw
    limiter: Limiter | None = None

    @property
    def judged(self) -> StretchDiagnosis | None:
        """The stretch that answers for the whole log, or None."""
        return None if self.worst is None else self.stretches[self.worst]

    def plot(self, path=None, **kwargs):
        """Draw the lateral offsets with the predicted envelopes, the walls seen and the stretches judged (`plots.diagnose`).

        Parameters
        ----------
        path : str, optional
            Save the figure there (`io.files.save_figure`).
        **kwargs
            Passed to `plots.diagnose.plot_diagnosis`.
        """
        from ..plots.diagnose import plot_diagnosis

        return plot_diagnosis(self, path, **kwargs)

    def to_dict(self) -> dict:
        """``verdict``, ``reason``, ``measured`` and ``predicted`` (the worst stretch's), the rest of it, and ``stretches``."""
        worst = self.judged
        out = {"verdict": self.verdict, "reason": self.reason}
        if worst is None:
            out.update({"measured": None, "predicted": {}, "matching_model": None, "margin": None, "critical": None, "remedies": {}})
        else:
            d = worst.to_dict()
            best = worst.predicted.get(worst.matching or "sampled")
            out.update({"measured": d["measured"], "predicted": d["predicted"], "matching_model": worst.matching,
                        "margin": d["margin"],
                        "critical": None if best is None else {"model": best.model, "V": json_number(best.V_critical),
                                                               "T": json_number(best.T_critical), "k": json_number(best.k_critical)},
                        "remedies": worst.remedies})
        out["limiter"] = None if self.limiter is None else self.limiter.to_dict()
        out["stretches"] = [s.to_dict() for s in self.stretches]
        return out


# ------------------------------------------------------------------------------------------ parameters
def missing_parameters(sources: dict) -> tuple[str, ...]:
    """The `USER_PARAMETERS` that nobody gave: their source is a preset the user did not choose (``preset …``, ``ASSUMED (preset …``).

    Parameters
    ----------
    sources : dict
        Parameter → provenance (``user``, ``config FILE``, ``preset carmel`` …; `cli.options.resolve_parameters`).
    """
    return tuple(name for name in USER_PARAMETERS if _from_preset(sources, name))


def _from_preset(sources: dict, name: str) -> bool:
    return str(sources.get(name, "")).startswith(("preset ", "ASSUMED (preset "))


def needs_identification(sources: dict) -> bool:
    """Whether τ or T must come from the log: the user gave it nowhere (its source is a preset).

    Parameters
    ----------
    sources : dict
        Parameter → provenance (`cli.options.resolve_parameters`).
    """
    return _from_preset(sources, "tau") or _from_preset(sources, "T")


def _linear_plant(fit) -> dict:
    """τ, D and g of the selected plant as `Estimate` by name, D the loop's: a smoother's mean wait for its tick added
    (`analysis.identification.PlantFit.loop_dead_time`)."""
    from ..analysis.identification import Estimate

    wait = fit.smoother.mean_wait if fit.smoother is not None else 0.0
    D = fit.dead_time
    return {"tau": fit.tau, "dead_time": Estimate(D.value + wait, D.low + wait, D.high + wait), "plant_gain": fit.g}


def _drive_limits(robot: Robot, sources: dict, from_preset: set, identification) -> tuple[Robot, dict]:
    """τ_a and the slew limit from the identification where the user gave neither (docs/diagnose.md, "What it needs")."""
    fit, where = identification.plant, identification.log.path
    for name, estimate, unit in (("actuator_lag", fit.actuator_lag, "s"), ("yaw_accel_limit", fit.yaw_accel_limit, "rad/s²")):
        if name not in from_preset or not fit.identifiable:
            continue
        if estimate is None:
            sources[name] = f"identified from {where}: none (the plant the data support, {fit.model}, has none)"
        else:
            robot = robot.replace(**{name: estimate.value})
            sources[name] = f"identified from {where} ({estimate.low:.4g} to {estimate.high:.4g} {unit})"
    return robot, sources


def complete_from_log(robot: Robot, controller: Controller, sources: dict, identification) -> tuple[Robot, Controller, dict]:
    """τ, T, D, g, τ_a, the slew limit and the slide from the identification where the user did not give them (their source is
    preset); the new sources.

    Parameters
    ----------
    robot, controller : Robot, Controller
        The user's parameters.
    sources : dict
        Their provenance.
    identification : analysis.identification.Identification or None
        What `identify` found in the same log.

    Raises
    ------
    ValueError
        τ, D or g is needed and the plant was not identified (the line says why and which keys to give).
    """
    sources = dict(sources)
    from_preset = {name for name in LOG_PARAMETERS if _from_preset(sources, name)}
    if not from_preset or identification is None:
        return robot, controller, sources
    robot, sources = _slide(robot, sources, from_preset, identification)  # from the pose: whatever the plant's fit
    if "T" in from_preset:
        controller = controller.replace(T=identification.controller.T)
        sources["T"] = f"identified from {identification.log.path} (median period of {identification.log.command_topic})"
    plant = [name for name in ("tau", "dead_time", "plant_gain") if name in from_preset]
    if plant and not identification.identified:
        raise ValueError(f"the steering plant could not be identified from {identification.log.path}: {identification.reason}; "
                         f"give {', '.join('robot.' + name for name in plant)} in --config "
                         f"(or {' '.join('--' + name.replace('_', '-') for name in plant)})")
    if not identification.identified:
        return robot, controller, sources
    fit = identification.plant
    linear = _linear_plant(fit)
    values = {name: linear[name].value for name in plant}
    if plant and not fit.identifiable:  # stay on the ridge the log determines (docs/diagnose.md, "Identifiability")
        given = [name for name in ("tau", "dead_time", "plant_gain") if name not in plant]
        anchor = {given[0]: getattr(robot, given[0])} if len(given) == 1 else \
            {"dead_time": 0.0} if not given and fit.dead_time.value < 0 else {}
        point = ridge_point(fit.excitation, **anchor) if anchor else None
        if point is not None:
            values.update((name, v) for name, v in zip(("plant_gain", "tau", "dead_time"), point) if name in plant)
    for name in plant:
        estimate, unit = linear[name], ("" if name == "plant_gain" else "s")
        value = max(values[name], 0.0) if name == "dead_time" else values[name]  # a negative D: clocks differ (identify warns)
        robot = robot.replace(**{name: value})
        if fit.identifiable:
            sources[name] = f"identified from {identification.log.path} ({estimate.low:.4g} to {estimate.high:.4g}{' ' + unit if unit else ''})"
        else:  # a narrowband log: any plant of the ridge predicts the same loop near ω (docs/diagnose.md, "Identifiability")
            x = fit.excitation
            sources[name] = (f"identified from {identification.log.path}, not separately identifiable (narrowband at "
                             f"ω ≈ {x.omega:.3g} rad/s): the prediction uses the plant's gain {x.gain:.3g} and phase "
                             f"{math.degrees(x.phase):.0f}° there, which the log determines")
    robot, sources = _drive_limits(robot, sources, from_preset, identification)
    return robot, controller, sources


def _slide(robot: Robot, sources: dict, from_preset: set, identification) -> tuple[Robot, dict]:
    """τ_s from the log's pose where the user gave none (docs/diagnose.md, "The slide"): taken when its 95 % interval
    excludes 0 (a slide the pose shows); else none. A wheel odometry's pose shows none — or half its period, if it
    integrates its heading by Euler's rule — which robot.slip_lag in --config overrides."""
    if "slip_lag" not in from_preset or not identification.has_pose:
        return robot, sources
    where, fit = identification.log.path, identification.slip
    if fit is None:
        sources["slip_lag"] = f"none: not measured from the pose of {where} ({identification.slip_reason})"
    elif fit.slip_lag.low <= 0.0:
        sources["slip_lag"] = (f"none: the pose of {where} shows no slide ({fit.slip_lag.low:.3g} to {fit.slip_lag.high:.3g} s "
                               "holds 0)")
    else:
        robot = robot.replace(slip_lag=fit.slip_lag.value)
        sources["slip_lag"] = (f"identified from the pose of {where} ({fit.slip_lag.low:.4g} to {fit.slip_lag.high:.4g} s; "
                               "a wheel odometry integrated by Euler's rule shows half its period: give robot.slip_lag if so)")
    return robot, sources


# ------------------------------------------------------------------------------------------ judging
def _measure(offset: LateralOffset) -> tuple[OscillationMetrics, Measured, tuple | None]:
    metrics = oscillation_metrics(offset.t, offset.offset, offset.step)
    x = offset.offset
    span = float(np.ptp(x))
    points = turning_points(x, HYSTERESIS * span) if span > 0 else np.array([], dtype=int)
    swings = np.abs(np.diff(x[points])) / 2 if points.size >= 2 else np.array([])
    amplitude = metrics.amplitude if metrics.amplitude is not None else (float(swings.max()) if swings.size else None)
    envelope = (float((offset.t[points[0]] + offset.t[points[1]]) / 2), float(swings[0])) if swings.size else None
    stable = metrics.growth_rate < 0 if metrics.growth_rate is not None else metrics.stable
    omega, frequency = None, None
    if metrics.growth_rate is not None:
        frequency = crossing_frequency(offset.t, x)
        omega = frequency.omega if frequency.omega is not None else metrics.angular_frequency
    measured = Measured(omega, metrics.growth_rate, amplitude, bool(stable), metrics.method, metrics.turning_points,
                        metrics.reason, frequency)
    return metrics, measured, envelope


def _predicted(name: str, verdict: str, margin: float, V_critical: float, root, measured: Measured, T_critical=None,
               k_critical=None) -> Predicted:
    """One model's `Predicted` from its verdict, margin, V* and dominant root, against the measurement."""
    stable = verdict == "stable"
    sigma = omega = error = None
    if root is not None and np.isfinite(root):
        sigma, omega = float(root.real), abs(float(root.imag))
        if measured.sigma is not None and measured.omega is not None:
            truth = complex(measured.sigma, measured.omega)
            error = abs(complex(sigma, omega) - truth) / abs(truth)
    agrees = stable == measured.stable
    matches = agrees and (error is None and measured.sigma is None or error is not None and error <= MATCH)
    return Predicted(name, stable, verdict, float(margin), float(V_critical),
                     None if T_critical is None else float(T_critical), None if k_critical is None else float(k_critical),
                     omega, sigma, error, bool(matches))


@dataclass(frozen=True)
class _Models:
    """The models built once for the log's loop, with their boundaries: the loop (τ, T, k, D, g) is the same on every
    stretch; only NV = N·V changes."""

    loop: Loop
    pairs: tuple

    @classmethod
    def of(cls, robot: Robot, controller: Controller, names) -> "_Models":
        loop = Loop.of(robot, controller)
        return cls(loop, tuple((model, model.boundary(loop)) for model in models_for(controller, names)))

    def predict(self, N: float, V: float, measured: Measured) -> dict:
        """Model name → `Predicted` without T* and k* (their searches cost 0.1 s a stretch): the verdict rule
        (`models.verdicts.judge`) on each model's boundary and its dominant root at NV = N·V, as the report's criteria."""
        NV, loop = N * V, self.loop
        out = {}
        for model, boundary in self.pairs:
            judgement = judge(NV, N, boundary, model.is_stable(NV, loop))
            out[model.name] = _predicted(model.name, judgement.verdict, judgement.margin, judgement.V_critical,
                                         model.rightmost_root(NV, loop), measured)
        return out


def _full(d: StretchDiagnosis, robot: Robot, controller: Controller, law: ForceLaw, models) -> StretchDiagnosis:
    """`d` with every model's T* and k* and the remedies: the stability report (`report.stability.build_report`)."""
    geometry = {"L": d.geometry} if d.stretch.kind == "corridor" else {"alpha_deg": d.alpha_deg}
    report = build_report(robot.replace(V=d.V), controller, law=law, models=models, **geometry)
    scene = report.corridor if d.stretch.kind == "corridor" else report.wall
    predicted = {name: _predicted(name, v.verdict, v.margin, v.critical["V_critical"], v.rightmost_root, d.measured,
                                  v.critical["T_critical"], v.critical["k_critical"])
                 for name, v in scene.models.items()}
    name = d.matching or "sampled"
    return replace(d, predicted=predicted, remedies=report.remedies.get((d.stretch.kind, name), {}) if name in predicted else {})


def _equilibrium_shift(offset: LateralOffset) -> float:
    """Where the wall's equilibrium d0 lies from the offset's zero (m): the swings' midpoints extrapolated to zero amplitude.

    A repulsion that grows faster than linearly as the robot nears the wall (f(W/d)^n) shifts the middle of a swing away
    from the wall by about c·a² (a weakly nonlinear oscillator's mean moves with the square of its amplitude), so the
    median distance of a growing oscillation overstates d0 (and α, and the margin): the midpoints m_i of the swings
    against their squared half amplitudes a_i² are fitted with a line, whose intercept is d0's offset. With fewer than
    three swings or amplitudes too alike to extrapolate, the midpoints' mean; without swings, 0.
    """
    x = offset.offset
    span = float(np.ptp(x))
    points = turning_points(x, HYSTERESIS * span) if span > 0 else np.array([], dtype=int)
    if points.size < 2:
        return 0.0
    extremes = x[points]
    middle = (extremes[1:] + extremes[:-1]) / 2
    squared = ((extremes[1:] - extremes[:-1]) / 2) ** 2
    if middle.size < 3 or np.ptp(squared) < 0.3 * squared.max():
        return float(np.mean(middle))
    return float(np.polyfit(squared, middle, 1)[1])


def _speed(stretch: Stretch, pose: PoseSeries) -> float:
    """The robot's speed over the stretch, m/s: the odometry's forward speed (median), else its path length over time."""
    inside = (pose.t >= stretch.start) & (pose.t <= stretch.end)
    vx = np.abs(pose.vx[inside])
    if np.median(vx) > 0:
        return float(np.median(vx))
    xs, ys, ts = pose.x[inside], pose.y[inside], pose.t[inside]
    return float(np.sum(np.hypot(np.diff(xs), np.diff(ys))) / (ts[-1] - ts[0]))


def _judge(stretch: Stretch, pose: PoseSeries, robot: Robot, law: ForceLaw, models: _Models) -> StretchDiagnosis:
    if stretch.duration < MIN_DURATION:
        return StretchDiagnosis(stretch, False, f"shorter than {MIN_DURATION:g} s ({stretch.duration:.1f} s)")
    offset = lateral_offset(stretch, pose)
    if offset is None or offset.samples < 8:
        return StretchDiagnosis(stretch, False, "too few odometry samples inside it")
    if offset.longest_gap > MAX_GAP:
        return StretchDiagnosis(stretch, False, f"the odometry misses {offset.longest_gap:.1f} s at once (more than {MAX_GAP:g} s)",
                                offset=offset)
    V = _speed(stretch, pose)
    base = dict(V=V, geometry=offset.geometry, offset=offset)
    if V < MIN_SPEED:
        return StretchDiagnosis(stretch, False, f"the robot moved at {V:.3g} m/s only", **base)
    if V > RANGES["V"].high:
        return StretchDiagnosis(stretch, False, f"a speed of {V:.3g} m/s is out of range {RANGES['V'].describe()}", **base)
    metrics, measured, envelope = _measure(offset)
    if measured.amplitude is None or measured.amplitude < MIN_AMPLITUDE:  # the robot holds its line: noise, not a swing
        measured = Measured(None, None, measured.amplitude, True, measured.method, measured.turning_points,
                            f"no swing larger than {1000 * MIN_AMPLITUDE:g} mm (the offset holds its line)", None)
        envelope = None
    if measured.sigma is None and not measured.stable:
        return StretchDiagnosis(stretch, False, f"no oscillation measured and the offset does not settle ({metrics.reason})",
                                measured=measured, **base)
    geometry = {}
    if stretch.kind == "corridor":
        if offset.geometry <= robot.W / 2:
            return StretchDiagnosis(stretch, False, f"the corridor's half-width L = {offset.geometry:.3g} m is not wider than "
                                    f"the robot's half-width W/2 = {robot.W / 2:.3g} m", measured=measured, **base)
        if offset.geometry > RANGES["L"].high:
            return StretchDiagnosis(stretch, False, f"L = {offset.geometry:.3g} m is out of range {RANGES['L'].describe()}",
                                    measured=measured, **base)
        geometry["L"] = offset.geometry
    else:
        offset = replace(offset, geometry=offset.geometry + _equilibrium_shift(offset))
        base["geometry"] = offset.geometry
        with np.errstate(divide="ignore", invalid="ignore"):  # d0 where the law balances no pull: α undefined, said below
            alpha, N_wall = wall_gain_at_distance(law, offset.geometry)
        alpha = float(alpha)
        low, high = RANGES["alpha_deg"].low, RANGES["alpha_deg"].high
        if not np.isfinite(alpha) or not low < to_degrees(alpha) < high:
            return StretchDiagnosis(stretch, False, f"at d0 = {offset.geometry:.3g} m the law does not balance a target's pull "
                                    f"at any angle α in {RANGES['alpha_deg'].describe()}", measured=measured, **base)
        geometry["alpha"] = alpha
    N = corridor_gain(law, offset.geometry) if stretch.kind == "corridor" else float(N_wall)
    predicted = models.predict(N, V, measured)
    matching = [p for p in predicted.values() if p.matches]
    best = min(matching, key=lambda p: (p.root_error if p.root_error is not None else 0.0, -MODEL_NAMES.index(p.model))) \
        if matching else None
    return StretchDiagnosis(stretch, True, None, V, offset.geometry,
                            to_degrees(geometry["alpha"]) if "alpha" in geometry else None, offset, measured, predicted,
                            best.model if best else None, {}, envelope)


def diagnose(log: LogData, robot: Robot, controller: Controller, *, law: ForceLaw | None = None,
             models=MODEL_NAMES) -> Diagnosis:
    """Measure and predict the oscillation on every stretch of `log` (module docstring).

    Parameters
    ----------
    log : LogData
        Read with ``pose`` and ``scan`` (reduced by `analysis.stretches.wall_lines`).
    robot, controller : Robot, Controller
        τ, k, W (V is measured on each stretch) and T, f, n, the hold and the compute delay.
    law : ForceLaw, optional
        The lateral law (KB's power law f(W/d)^n by default).
    models : sequence of str
        The models to predict with (`parameters.MODEL_NAMES`).

    Returns
    -------
    Diagnosis

    Raises
    ------
    ValueError
        A log read without its pose or scans.
    """
    if log.pose is None or log.scan is None:
        raise ValueError("diagnose needs the log read with its pose and scans (read_log(..., need=('pose', 'scan'), "
                         "scan_reducer=wall_lines))")
    law = law_in_force(robot, controller, law)
    stretches = find_stretches(log.scan.t, log.scan.values, log.pose)
    built = _Models.of(robot, controller, tuple(models))
    judged = tuple(_judge(s, log.pose, robot, law, built) for s in stretches)
    rated = [d for d in judged if d.judged]
    if not stretches:
        verdict, reason, worst = "nothing to diagnose", "no wall in view while the robot moved (no stretch along a wall or through a corridor)", None
    elif not rated:
        verdict, worst = "nothing to diagnose", None
        reason = "no stretch could be judged: " + "; ".join(f"stretch {d.stretch.index}: {d.reason}" for d in judged)
    else:
        top = max(rated, key=lambda d: (d.measured.sigma if d.measured.sigma is not None else -math.inf, d.stretch.duration))
        worst = top.stretch.index
        m = top.measured
        where = f"stretch {worst} ({top.stretch.kind}, {top.stretch.start:.1f}–{top.stretch.end:.1f} s)"
        if m.stable:
            verdict = "stable"
            reason = (f"every judged stretch is stable; the least damped is {where}: σ = {m.sigma:.3g} 1/s" if m.sigma is not None
                      else f"no oscillation on any judged stretch; {where} settles")
        else:
            verdict = "oscillating"
            reason = f"{where} oscillates: σ = {m.sigma:+.3g} 1/s at ω = {m.omega:.3g} rad/s"
    if worst is not None:  # the whole log's stretch: every critical value and the remedies
        judged = tuple(_full(d, robot, controller, law, tuple(models)) if d.stretch.index == worst else d for d in judged)
    V = judged[worst].V if worst is not None else robot.V
    limiter = _limiter(robot, controller, law, log, judged[worst] if worst is not None else None)
    return Diagnosis(verdict, reason, judged, worst, robot.replace(V=V), controller, log.pose, law, limiter)


def _limiter(robot: Robot, controller: Controller, law: ForceLaw, log: LogData, judged: StretchDiagnosis | None) -> Limiter | None:
    """The robot's slew limit set against the commands of the judged stretch, and the limited loop's V* for a disturbance
    the size of the weave it shows (`Limiter`)."""
    A = robot.yaw_accel_limit
    if not math.isfinite(A):
        return None
    stretch = judged.stretch if judged is not None else None
    acceleration = None
    if log.command is not None and stretch is not None:
        t, u = log.command.t, log.command.value
        inside = (t >= stretch.start) & (t <= stretch.end)
        if np.count_nonzero(inside) >= 3:
            dt = np.diff(t[inside])
            ok = dt > 0
            acceleration = float(np.percentile(np.abs(np.diff(u[inside])[ok] / dt[ok]), 95)) if np.any(ok) else None
    reached = None if acceleration is None else bool(acceleration >= REACHED * A)
    size, V_size, why = _limited_boundary(robot, controller, law, judged)
    note = (f"the predictions' table is the linear loop's, which a slew limit of {A:.3g} rad/s² does not change: it holds for a "
            "disturbance small enough that the commands never change faster than the limit")
    note += (f"; with the limit, a weave of {size:.3g} m (the judged stretch's) settles at or below V* = {V_size:.4g} m/s "
             "(the limiter's describing function on the sampled loop, docs/wobble.md)") if V_size is not None else f"; {why}"
    if reached is not None:
        note += (f"; on the judged stretch the commands changed at up to {acceleration:.3g} rad/s² (95th percentile): the limit "
                 + ("was reached, so the measured oscillation is the limited loop's" if reached else "was not reached"))
    return Limiter(A, V_size is not None, acceleration, reached, note, size, V_size)


def _limited_boundary(robot: Robot, controller: Controller, law: ForceLaw, judged: StretchDiagnosis | None) -> tuple:
    """(size m, V*(size) m/s, why none): the limited corridor loop asked at the judged stretch's measured amplitude
    (`analysis.disturbance.corridor_disturbance`); a wall's stretch, or no amplitude, gives no V*(size) and says why."""
    if judged is None or judged.measured is None or not judged.measured.amplitude:
        return None, None, "the judged stretch has no measured amplitude to ask the limited loop at"
    if judged.stretch.kind != "corridor":
        return judged.measured.amplitude, None, "V*(size) is computed for a corridor's stretch (a wall's biased cycle is not)"
    from ..analysis.disturbance import corridor_disturbance

    clearance = judged.geometry - robot.W / 2
    size = min(judged.measured.amplitude, 0.95 * clearance)
    try:
        d = corridor_disturbance(robot.replace(V=judged.V), controller, law, judged.geometry, size)
    except ValueError as exc:
        return size, None, f"the limited loop gives no V*(size): {exc}"
    V = d.V_disturbance
    return size, (V if V is not None and math.isfinite(V) else None), (d.reason or "the describing function gives no V*(size)")
