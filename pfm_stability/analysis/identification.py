"""The controller's period and the yaw-rate plant, identified from a robot's log (docs/diagnose.md).

Controller period
-----------------
From the command's stamps (`controller_timing`): T is the median interval, the jitter its 5th and 95th
percentiles, a missed cycle an interval longer than 1.5·T (counted), and the achieved rate (messages per
second over the log) is set against the nominal 1/T.

The plant
---------
The commanded yaw rate u is held between its stamps (zero-order hold), delayed by D (any value, not a
whole number of periods) and passed through the plant of gain g; a constant offset b absorbs a gyro's bias
(docs/diagnose.md, "Model"). The plant is the one the data support (`analysis.plant_fit`, "Which plant"): the
first-order lag 1/(τs + 1), two lags 1/((τs + 1)(τ_a·s + 1)), either behind a slew limit A on u (a velocity
smoother's angular acceleration limit). Every response is exact between the commands (`analysis.plant_response`).

The fit uses the samples where the command excites the plant (`excitation_windows`: from 0.5 s before
each change of the command to `SETTLE` s after it; long constant stretches and a robot told to stand
still are left out, and so is a sample whose newest command is older than `STALE` periods, when a base
may have stopped on its command timeout). The first order comes first: a coarse grid over (τ, D), with g and b
solved linearly at each point, starts `scipy.optimize.least_squares` (D's residual has a local minimum per period
of the command's oscillation; the grid finds the right one). Every candidate is then fitted from it on the same
stretch of at most `plant_fit.SELECT_SAMPLES` samples and scored by BIC; the selected one is polished on every
sample.

Intervals
---------
95 % intervals are value ± 1.96·σ from the covariance H⁻¹·S·H⁻¹, H = JᵀJ, with the Newey–West estimate
S = Σ_l w_l·Σ_t (J_t r_t)(J_(t−l) r_(t−l))ᵀ (Bartlett weights, lags within one window only; `plant_fit.covariance`).
With white residuals this is s²·(JᵀJ)⁻¹; with residuals correlated over L samples (unmodelled dynamics, a smoothed
odometry) it widens by the right amount for each parameter, where an effective sample count would
widen every parameter alike. L is the larger of Newey and West's 4·(n/100)^(2/9) and three times the
lag at which the residuals' autocorrelation falls below 0.1. τ_a = ρ·τ and A = e^(ln A) (the fit's coordinates)
get theirs by the delta method and as exp of ln A's interval (positive).

Can the log separate g, τ and D?
--------------------------------
A robot oscillating in a corridor commands essentially one frequency ω. The log then fixes the plant's gain
|G(jω)| = g/√(1 + ω²τ²) and phase −ωD − atan(ωτ) at ω — two numbers for three unknowns: every (g, τ, D) on that
ridge explains the log as well, up to harmonics and the held commands' staircase, whose small ripple (one local
minimum of the residual per controller period along D) picks a point on the ridge by luck, and the covariance of
that point is then small and wrong. `command_spectrum` measures the excitation before any fit: the held command on
a grid of T, its mean removed, its periodogram (Hann window); ω the peak (DC excluded) and `outside` the fraction
of the power outside [ω/`BAND`, `BAND`·ω]. Below `NARROWBAND` the fit is kept (it explains the log, and its
gain and phase at ω are what the log determines) but its intervals are null and the `narrowband` warning says why
(docs/diagnose.md, "Identifiability"). The criterion reads the commands only, not the noise or the fit, so it does
not depend on where the optimizer stopped on the ridge.

Does the model explain the data?
--------------------------------
`FitQuality` gives the normalized error (NRMSE = rms(r)/std(y)), R² and the residuals' whiteness of the selected
plant, and `FitWarning` names what it does not explain: a rate limit the selected plant has not taken up (the
measured |dω/dt| saturates where the model asks for more) and a deadband or backlash (a first-order plant whose
small commands deliver nothing fits better by at least `BETTER` of the residual sum of squares on the same samples).
A narrowband log is fitted with the first order alone: it cannot tell the candidates apart.

The slide
---------
With a pose (``log.pose``: a localisation's, a motion-capture system's, a simulator's ground truth — not wheel
odometry's, which cannot show it), `analysis.slip_fit.fit_slip_lag` measures the lag τ_s of the base's course behind
its heading from the lateral velocity in the base's frame (docs/diagnose.md, "The slide"); it needs no command and is
reported whether or not the plant is identified (`Identification.slip`, or `slip_reason` why not).

Nothing identified
------------------
A log whose command never changes, a robot that does not follow its commands (g's interval holds 0 or
|g| < 0.05) and excitation too small for the noise (g's interval wider than ±50 %) give an
`Identification` with ``identified`` false and the reason; the controller's period is still measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.logs import LogData, TimeSeries
from ..io.serialize import json_number
from .excitation import BAND, NARROWBAND, Excitation, command_spectrum, excitation_of, ridge_point
from .plant_fit import (DEAD_TIME_BOUNDS, PLANT_MODELS, SELECT_SAMPLES, SMOOTHING_FREQUENCY, TAU_BOUNDS, Z95, CandidateFit, Estimate,
                        PlantParameters, Samples, autocorrelation, candidates, covariance, fit_first_order, fit_model, grid_start,
                        jacobian, residuals)
from .plant_response import lag_response, mean_wait
from .slip_fit import SlipFit, fit_slip_lag

__all__ = ["Estimate", "ControllerTiming", "FitWarning", "FitQuality", "Excitation", "PlantFit", "LogSummary",
           "Identification", "SlipFit", "CandidateFit", "SmootherFit", "SMOOTHING_FREQUENCY", "controller_timing", "excitation_windows", "command_spectrum", "lag_response",
           "fit_plant", "identify", "ridge_point", "NARROWBAND", "BAND", "PLANT_MODELS",
           "MISSED_FACTOR", "SETTLE", "LEAD", "STALE", "DEAD_TIME_BOUNDS", "TAU_BOUNDS", "BETTER", "RATE_SOURCES"]

MISSED_FACTOR = 1.5
"""An interval between commands longer than this many median periods is a missed cycle."""
LEAD, SETTLE = 0.5, 4.0
"""A window of excitation runs from LEAD s before a change of the command to SETTLE s after it."""
STALE = 5.0
"""A sample whose newest command is older than max(0.5 s, STALE·T) is not used (the base may have stopped)."""
BETTER = 0.1
"""A deadband is named when it lowers the residual sum of squares by this fraction."""
RATE_SOURCES = ("odometry", "imu")
"""Where the achieved yaw rate comes from: the odometry's twist, or the IMU's angular velocity."""
GRID_SAMPLES, CHECK_SAMPLES, FIRST_SAMPLES = 5_000, 8_000, 20_000
"""The grid search, the deadband's check and a long log's first fit use a contiguous stretch of at most this many
samples (speed: the final fit uses every sample; the candidates are compared on `plant_fit.SELECT_SAMPLES`)."""


# ------------------------------------------------------------------------------------------ results
@dataclass(frozen=True)
class ControllerTiming:
    """The controller's real period from its command stamps.

    Attributes
    ----------
    T : float
        Median interval between commands, s.
    p5, p95 : float
        5th and 95th percentiles of the intervals (the jitter), s.
    missed : int
        Intervals longer than `MISSED_FACTOR`·T.
    messages : int
        Number of commands.
    rate : float
        Achieved rate, Hz: messages − 1 over their span.
    nominal : float
        1/T, Hz.
    """

    T: float
    p5: float
    p95: float
    missed: int
    messages: int
    rate: float
    nominal: float

    def to_dict(self) -> dict:
        """The ``controller`` of the JSON output."""
        return {"T": json_number(self.T), "jitter": {"p5": json_number(self.p5), "p95": json_number(self.p95)},
                "missed": self.missed, "messages": self.messages,
                "rate": {"achieved": json_number(self.rate), "nominal": json_number(self.nominal)}}


@dataclass(frozen=True)
class FitWarning:
    """Something the model does not explain, or a log that cannot determine it.

    Attributes
    ----------
    kind : str
        ``rate_limit``, ``deadband``, ``second_order``, ``poor_fit``, ``dead_time_at_bound``, ``negative_dead_time``
        or ``narrowband``.
    message : str
        One line for the user.
    """

    kind: str
    message: str

    def to_dict(self) -> dict:
        """``{kind, message}``."""
        return {"kind": self.kind, "message": self.message}


@dataclass(frozen=True)
class FitQuality:
    """How well the model explains the samples it was fitted to.

    Attributes
    ----------
    nrmse : float
        Rms residual over the samples' standard deviation, dimensionless.
    r2 : float
        1 − SSR/SST, dimensionless.
    lag1 : float
        The residuals' autocorrelation at one sample, dimensionless.
    outside : float
        Fraction of lags 1–20 whose autocorrelation is outside ±1.96/√n.
    white : bool
        outside <= 0.2.
    samples : int
        Samples fitted.
    effective_samples : float
        Samples over the residuals' integrated autocorrelation.
    windows : int
        Excited windows fitted.
    excited : float
        Their total length, s.
    bias : float
        The fitted offset b, rad/s.
    hac_lags : int
        L of the interval's covariance (HAC lags).
    """

    nrmse: float
    r2: float
    lag1: float
    outside: float
    white: bool
    samples: int
    effective_samples: float
    windows: int
    excited: float
    bias: float
    hac_lags: int

    def to_dict(self) -> dict:
        """The ``fit.quality`` of the JSON output."""
        return {"nrmse": json_number(self.nrmse), "r2": json_number(self.r2),
                "whiteness": {"lag1": json_number(self.lag1), "outside": json_number(self.outside), "white": self.white},
                "samples": self.samples, "effective_samples": json_number(self.effective_samples), "windows": self.windows,
                "excited_seconds": json_number(self.excited), "bias": json_number(self.bias), "hac_lags": self.hac_lags}


@dataclass(frozen=True)
class SmootherFit:
    """The slew limit as a smoother on its own timer (`plant_response.smoothed`): its rate, the timer's phase found, and
    the mean wait of the log's commands for its next tick.

    Attributes
    ----------
    frequency : float
        f, Hz (`plant_fit.SMOOTHING_FREQUENCY` unless told).
    phase : float
        φ, s, in [0, 1/f): the ticks are at φ + i/f on the log's clock.
    mean_wait : float
        s: how long the log's commands waited for a tick on average (h/2 for commands on a clock of their own). A small
        command's response is delayed by it beyond D: the loop's dead time is D + mean_wait (`PlantFit.loop_dead_time`).
    """

    frequency: float
    phase: float
    mean_wait: float

    def to_dict(self) -> dict:
        """``{frequency, phase, mean_wait}`` (Hz, s, s)."""
        return {"frequency": json_number(self.frequency), "phase": json_number(self.phase), "mean_wait": json_number(self.mean_wait)}


@dataclass(frozen=True)
class PlantFit:
    """The fitted plant g·e^(−sD)/((τs + 1)(τ_a·s + 1)) behind an optional slew limit A on the commanded yaw rate: the
    model the data support (`analysis.plant_fit`, "Which plant").

    Parameters
    ----------
    g : Estimate
        The plant gain (−) and its 95 % interval.
    tau : Estimate
        The lag (s) and its 95 % interval (the slower lag of two).
    dead_time : Estimate
        The dead time D (s) from the command's publication (docs/diagnose.md, "Time") and its 95 % interval.
    quality : FitQuality
        How well the selected model explains the samples.
    warnings : tuple of FitWarning
        What the model does not explain, and ``narrowband``.
    excitation : Excitation or None
        How the commands excite the plant; when narrowband the values are one point of the ridge the log cannot
        resolve and the intervals are NaN.
    actuator_lag : Estimate or None
        The second lag τ_a (s) and its interval when the selected model has one, else None (none: 0).
    yaw_accel_limit : Estimate or None
        The slew limit A on the commanded yaw rate (rad/s²) and its interval when the selected model has one, else None
        (none: inf).
    model : str
        The selected model (`plant_fit.PLANT_MODELS`).
    models : tuple of CandidateFit
        Every candidate compared (empty on a narrowband log: first order only, the log cannot tell them apart).
    smoother : SmootherFit or None
        The slew limit's timer when the selected model has a slew limit fitted as a smoother on its own timer.
    """

    g: Estimate
    tau: Estimate
    dead_time: Estimate
    quality: FitQuality
    warnings: tuple[FitWarning, ...]
    excitation: Excitation | None = None
    actuator_lag: Estimate | None = None
    yaw_accel_limit: Estimate | None = None
    model: str = "first_order"
    models: tuple = ()
    smoother: SmootherFit | None = None

    @property
    def loop_dead_time(self) -> float:
        """The dead time a small command sees (s): D, plus the smoother's mean wait for its next tick."""
        return self.dead_time.value + (self.smoother.mean_wait if self.smoother is not None else 0.0)

    @property
    def identifiable(self) -> bool:
        """Whether g, τ and D are separately determined by the log (not `Excitation.narrowband`)."""
        return self.excitation is None or not self.excitation.narrowband

    def to_dict(self) -> dict:
        """The ``plant`` of the JSON output."""
        none = lambda e: None if e is None else e.to_dict()  # noqa: E731
        return {"model": self.model, "g": self.g.to_dict(), "tau": self.tau.to_dict(), "dead_time": self.dead_time.to_dict(),
                "actuator_lag": none(self.actuator_lag), "yaw_accel_limit": none(self.yaw_accel_limit),
                "smoother": none(self.smoother), "loop_dead_time": json_number(self.loop_dead_time),
                "identifiable": self.identifiable}


@dataclass(frozen=True)
class LogSummary:
    """What was read: the log, the topics used and where the rate and the command's times come from.

    Attributes
    ----------
    path : str
        The log as given.
    format : str
        Its format (`io.logs.log_format`).
    duration : float
        Length of the log, s.
    command_topic, rate_topic : str
        The command's and the rate's topics.
    rate_source : str
        Where the rate comes from (`RATE_SOURCES`).
    command_stamps : str
        Where the command's times come from: ``header``, ``receive`` or ``csv``.
    pose_topic : str or None
        The pose's topic (a CSV's: ``x,y,yaw``) when the slide was measured from it, else None.
    """

    path: str
    format: str
    duration: float
    command_topic: str
    rate_topic: str
    rate_source: str
    command_stamps: str
    pose_topic: str | None = None

    def to_dict(self) -> dict:
        """The ``log`` of the JSON output (``topics.pose`` only with a pose)."""
        topics = {"command": self.command_topic, "rate": self.rate_topic}
        if self.pose_topic is not None:
            topics["pose"] = self.pose_topic
        return {"path": self.path, "format": self.format, "duration": json_number(self.duration), "topics": topics,
                "rate_source": self.rate_source, "command_stamps": self.command_stamps}


@dataclass(frozen=True)
class Identification:
    """What `identify` found: the controller's timing always; the plant when `identified`, else the `reason`.

    Attributes
    ----------
    identified : bool
        Whether the plant was identified.
    reason : str or None
        Why not, when it was not.
    controller : ControllerTiming
        The controller's timing (always).
    plant : PlantFit or None
        The fitted plant when `identified`.
    log : LogSummary
        What was read.
    slip : SlipFit or None
        The slide measured from the log's pose (`analysis.slip_fit`), when it has one and it shows the slide.
    slip_reason : str or None
        Why the slide was not measured from the log's pose; None when it was, or when the log has no pose.
    """

    identified: bool
    reason: str | None
    controller: ControllerTiming
    plant: PlantFit | None
    log: LogSummary
    slip: SlipFit | None = None
    slip_reason: str | None = None

    @property
    def has_pose(self) -> bool:
        """Whether the slide was looked for (the log has a pose): measured, or not with `slip_reason`."""
        return self.slip is not None or self.slip_reason is not None

    def slip_dict(self) -> dict | None:
        """The ``slip`` of the JSON output: null without a pose; else ``slip_lag`` (null with ``reason`` when not
        measured) and the fit's details."""
        if not self.has_pose:
            return None
        if self.slip is None:
            return {"slip_lag": None, "reason": self.slip_reason}
        return {**self.slip.to_dict(), "reason": None}

    def to_dict(self) -> dict:
        """The JSON output of ``pfm-stability identify`` without ``schema_version``, ``command`` and ``timing``."""
        plant = self.plant
        return {
            "identified": self.identified,
            "reason": self.reason,
            "plant": None if plant is None else plant.to_dict(),
            "controller": self.controller.to_dict(),
            "fit": {"quality": None if plant is None else plant.quality.to_dict(),
                    "warnings": [] if plant is None else [w.to_dict() for w in plant.warnings],
                    "excitation": None if plant is None or plant.excitation is None else plant.excitation.to_dict(),
                    "models": [] if plant is None else [m.to_dict() for m in plant.models]},
            "slip": self.slip_dict(),
            "log": self.log.to_dict(),
        }


# ------------------------------------------------------------------------------------------ timing
def controller_timing(t: np.ndarray) -> ControllerTiming:
    """The controller's period, jitter, missed cycles and rate from its command times.

    Parameters
    ----------
    t : numpy.ndarray
        The commands' times (s), non-decreasing; at least 3.

    Returns
    -------
    ControllerTiming

    Raises
    ------
    ValueError
        Fewer than 3 commands, or all at one instant.
    """
    t = np.asarray(t, dtype=float)
    if t.size < 3:
        raise ValueError(f"the command has {t.size} message(s): at least 3 are needed to measure the controller's period")
    intervals = np.diff(t)
    T = float(np.median(intervals))
    if not T > 0:
        raise ValueError("the command's stamps do not advance: half or more of its intervals are 0 s")
    p5, p95 = (float(v) for v in np.percentile(intervals, [5, 95]))
    span = float(t[-1] - t[0])
    return ControllerTiming(T, p5, p95, int(np.count_nonzero(intervals > MISSED_FACTOR * T)), int(t.size),
                            (t.size - 1) / span, 1.0 / T)


# ------------------------------------------------------------------------------------------ the command's deadband
def _deadband(u: np.ndarray, width: float) -> np.ndarray:
    return np.sign(u) * np.maximum(np.abs(u) - width, 0.0)


# ------------------------------------------------------------------------------------------ the samples
def excitation_windows(cmd_t: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The windows where the command excites the plant: [change − `LEAD`, change + `SETTLE`] merged, as (k, 2) seconds.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s).
    u : numpy.ndarray
        The commands (rad/s). A change is a step larger than max(1e-3 rad/s, 1 % of the command's range).

    Returns
    -------
    numpy.ndarray
        (start, end) of each window, sorted and disjoint; empty (0, 2) when the command never changes.
    """
    u = np.asarray(u, dtype=float)
    span = float(np.percentile(u, 99) - np.percentile(u, 1)) if u.size else 0.0
    step = np.abs(np.diff(u))
    changes = cmd_t[1:][step > max(1e-3, 0.01 * span)]
    if changes.size == 0:
        return np.zeros((0, 2))
    starts, ends = changes - LEAD, changes + SETTLE
    new = np.concatenate([[True], starts[1:] > np.maximum.accumulate(ends)[:-1]])
    group = np.cumsum(new) - 1
    out = np.empty((int(group[-1]) + 1, 2))
    out[:, 0] = starts[new]
    out[:, 1] = np.maximum.reduceat(ends, np.flatnonzero(new))
    return out


def _select(cmd_t, u, rate: TimeSeries, T: float) -> tuple[Samples, np.ndarray]:
    """The rate samples inside the excitation windows where the command is held and fresh; and the windows."""
    windows = excitation_windows(cmd_t, u)
    t, y = rate.t, rate.value
    w = np.searchsorted(windows[:, 0], t, side="right") - 1
    inside = (w >= 0) & (t <= windows[np.maximum(w, 0), 1]) if windows.size else np.zeros(t.size, bool)
    newest = np.searchsorted(cmd_t, t, side="right") - 1
    fresh = (newest >= 0) & (t - cmd_t[np.maximum(newest, 0)] <= max(0.5, STALE * T))
    keep = inside & fresh & (t >= cmd_t[0] + DEAD_TIME_BOUNDS[1]) & np.isfinite(y)
    ts = t[keep]
    dt = np.diff(ts)
    typical = float(np.median(dt)) if dt.size else 0.0
    segment = np.concatenate([[0], np.cumsum(dt > 5.0 * typical)]) if ts.size else np.zeros(0, int)
    return Samples(cmd_t, u, ts, y[keep], segment), windows


# ------------------------------------------------------------------------------------------ the fit
def _interval(value: float, variance: float) -> Estimate:
    half = Z95 * math.sqrt(max(variance, 0.0))
    return Estimate(float(value), float(value - half), float(value + half))


def _estimates(names: tuple, p: PlantParameters, cov: np.ndarray) -> dict:
    """Name → `Estimate` of g, tau, dead_time and, in the model, actuator_lag (τ_a = ρτ, the delta method) and
    yaw_accel_limit (A = e^(ln A): exp of ln A's interval, positive)."""
    at = {name: i for i, name in enumerate(names)}
    out = {"g": _interval(p.g, cov[at["g"], at["g"]]), "tau": _interval(p.tau, cov[at["tau"], at["tau"]]),
           "dead_time": _interval(p.dead_time, cov[at["D"], at["D"]])}
    if "rho" in at:
        grad = np.zeros(len(names))
        grad[at["rho"]], grad[at["tau"]] = p.tau, p.actuator_lag / p.tau
        out["actuator_lag"] = _interval(p.actuator_lag, float(grad @ cov @ grad))
    if "log_slew" in at:
        half = Z95 * math.sqrt(max(cov[at["log_slew"], at["log_slew"]], 0.0))
        out["yaw_accel_limit"] = Estimate(p.slew, p.slew * math.exp(-half), p.slew * math.exp(half))
    return out


def _quality(s: Samples, r: np.ndarray, L: int, rho: np.ndarray, windows: np.ndarray, bias: float) -> FitQuality:
    y = s.y
    sst = float(np.sum((y - y.mean()) ** 2))
    ssr = float(r @ r)
    rho20 = autocorrelation(r, s.segment, 20)
    outside = float(np.mean(np.abs(rho20) > 1.96 / math.sqrt(r.size)))
    bartlett = 1.0 + 2.0 * float(np.sum((1.0 - np.arange(1, L + 1) / (L + 1.0)) * rho)) if L else 1.0
    return FitQuality(
        nrmse=math.sqrt(ssr / r.size) / max(float(np.std(y)), 1e-300), r2=1.0 - ssr / sst if sst > 0 else math.nan,
        lag1=float(rho20[0]), outside=outside, white=outside <= 0.2, samples=int(r.size),
        effective_samples=float(r.size / max(bartlett, 1.0)), windows=int(len(windows)),
        excited=float(np.sum(windows[:, 1] - windows[:, 0])), bias=float(bias), hac_lags=L)


def _first_order(s: Samples) -> PlantParameters:
    """The first-order plant: a (τ, D) grid on a stretch, least squares there and then on every sample."""
    start, chunk = grid_start(s.chunk(GRID_SAMPLES)), s.chunk(FIRST_SAMPLES)
    if chunk is not s:  # a long log: fit a stretch first, then polish on every sample from there
        start = fit_first_order(start, chunk)
    g, tau, delay, b = fit_first_order(start, s)
    return PlantParameters(g, tau, 0.0, delay, math.inf, b)


def _which_plant(s: Samples, first: PlantParameters, frequency: float) -> tuple[str, PlantParameters, tuple]:
    """(the selected model, its plant fitted to every sample, every candidate) (`analysis.plant_fit.candidates`)."""
    chunk = s.chunk(SELECT_SAMPLES)
    fits = candidates(chunk, first, _measured_acceleration(s), frequency)
    chosen = next(c for c in fits if c.selected)
    if chosen.model == "first_order":
        return chosen.model, first, fits
    p = chosen.parameters if chunk is s else fit_model(chosen.model, chosen.parameters, s, max_nfev=20, frequency=frequency)
    return chosen.model, p, fits


def fit_plant(cmd_t: np.ndarray, u: np.ndarray, rate: TimeSeries, T: float,
              smoothing_frequency: float = SMOOTHING_FREQUENCY) -> tuple[PlantFit | None, str | None]:
    """Fit the plant the data support (first order, a second lag, a slew limit; `analysis.plant_fit`) to the rate samples
    where the command excites the plant.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s).
    u : numpy.ndarray
        The commanded yaw rates (rad/s).
    rate : TimeSeries
        The achieved yaw rate (rad/s) and its times (s).
    T : float
        The controller's period (s): a sample whose newest command is older than max(0.5 s, `STALE`·T) is left out.
    smoothing_frequency : float
        The rate (Hz) of the smoother a slew limit is fitted as (Nav2's default 20); 0: a continuous ramp.

    Returns
    -------
    tuple
        (the fit, None), or (None, why nothing was identified).
    """
    cmd_t, u = np.asarray(cmd_t, dtype=float), np.asarray(u, dtype=float)
    f = float(smoothing_frequency)
    if np.ptp(u) <= 1e-3:
        what = "stand still" if np.all(np.abs(u) <= 1e-3) else f"turn at a constant {float(np.median(u)):.3g} rad/s"
        return None, f"the command never changes (the robot was told to {what}): nothing excites the plant"
    s, windows = _select(cmd_t, u, rate, T)
    if s.t.size < 50:
        return None, (f"only {s.t.size} samples of the rate while the command changes (at least 50 are needed): "
                      "the log is too short or the rate topic is too sparse")
    first = _first_order(s)
    excitation = excitation_of(cmd_t, u, T, first.g, first.tau, first.dead_time)
    model, p, fits = ("first_order", first, ()) if excitation.narrowband else _which_plant(s, first, f)
    r = residuals(model, p, s, f)
    J, names = jacobian(model, p, s, f)
    cov, L, rho = covariance(J, r, s.segment)
    estimates = _estimates(names, p, cov)
    g, g_est = p.g, estimates["g"]
    if abs(g) < 0.05 or g_est.low <= 0.0 <= g_est.high:
        return None, (f"the robot did not follow the commands (g = {g:.3g}, 95 % interval {g_est.low:.3g} to {g_est.high:.3g}): "
                      "it stood still (stopped, emergency stop) or the rate topic is not this robot's")
    if g_est.high - g_est.low > abs(g):
        return None, (f"the commands excite the plant too little for the noise (g = {g:.3g} ± {(g_est.high - g_est.low) / 2:.2g}): "
                      "record steps or turns of the yaw rate (docs/diagnose.md)")
    quality = _quality(s, r, L, rho, windows, p.bias)
    warnings = _checks(s, model, p, first, estimates, quality, excitation.narrowband)
    if excitation.narrowband:  # one frequency: the fit is one point of a ridge, its intervals mean nothing
        warnings.insert(0, FitWarning("narrowband", (
            f"the commands excite one frequency (ω ≈ {excitation.omega:.3g} rad/s; {100 * (1 - excitation.outside):.1f} % "
            f"of their power within a factor {BAND:g} of it): g, τ and D are not separately identifiable, only the plant's "
            f"gain {excitation.gain:.3g} and phase {math.degrees(excitation.phase):.0f}° there; record step turns "
            "(docs/diagnose.md)")))
        estimates = {name: Estimate(e.value, math.nan, math.nan) for name, e in estimates.items()}
    smoother = SmootherFit(f, p.phase, mean_wait(cmd_t, f, p.phase)) if math.isfinite(p.slew) and f > 0 else None
    return PlantFit(estimates["g"], estimates["tau"], estimates["dead_time"], quality, tuple(warnings), excitation,
                    estimates.get("actuator_lag"), estimates.get("yaw_accel_limit"), model, fits, smoother), None


# ------------------------------------------------------------------------------------------ what the model misses
def _checks(s: Samples, model: str, p: PlantParameters, first: PlantParameters, estimates: dict, quality: FitQuality,
            narrowband: bool = False) -> list[FitWarning]:
    warnings = []
    if quality.r2 < 0.8:
        warnings.append(FitWarning("poor_fit", f"the model explains only {100 * quality.r2:.0f} % of the rate's variance "
                                               f"(NRMSE {quality.nrmse:.2f}): its numbers are rough"))
    if p.dead_time >= DEAD_TIME_BOUNDS[1] - 1e-3:
        warnings.append(FitWarning("dead_time_at_bound", f"the dead time reached the largest searched, {DEAD_TIME_BOUNDS[1]:g} s: "
                                                         "the command and rate topics may not belong together"))
    if estimates["dead_time"].high < 0 and not narrowband:  # on a ridge a negative D is where the fit stopped, not the clocks
        warnings.append(FitWarning("negative_dead_time", f"the rate leads the command by {-1000 * p.dead_time:.0f} ms: "
                                                         "their stamps come from different clocks"))
    limit = None if math.isfinite(p.slew) or narrowband else _rate_limit(s, first)
    if limit is not None:  # the data saturate where the selected plant does not
        warnings.append(FitWarning("rate_limit", f"the yaw acceleration saturates near {limit:.2g} rad/s² where the model "
                                                 f"asks for more: a rate limit the selected plant does not explain"))
    band = _better_deadband(s.chunk(CHECK_SAMPLES), first)
    if band is not None:
        width, gain = band
        warnings.append(FitWarning("deadband", f"small commands are under-delivered: a deadband (or backlash) of {width:.2g} rad/s "
                                               f"lowers the residual by {100 * gain:.0f} %"))
    return warnings


def _better_deadband(c: Samples, p: PlantParameters):
    """(deadband rad/s, relative improvement) when a deadband on the first-order plant's command lowers the residual sum
    of squares by `BETTER`, else None (refitted on a stretch)."""
    from scipy.optimize import least_squares

    top = float(np.max(np.abs(c.u)))
    if top <= 0:
        return None
    base = p.g * lag_response(c.cmd_t, c.u, c.t, p.tau, p.dead_time) + p.bias - c.y
    ssr = float(base @ base)
    model = lambda q: q[0] * lag_response(c.cmd_t, _deadband(c.u, q[4]), c.t, q[1], q[2]) + q[3]  # noqa: E731
    lower = [-np.inf, TAU_BOUNDS[0], DEAD_TIME_BOUNDS[0], -np.inf, 0.0]
    upper = [np.inf, TAU_BOUNDS[1], DEAD_TIME_BOUNDS[1], np.inf, 0.5 * top]
    start = np.clip([p.g / 0.9, p.tau, p.dead_time, p.bias, 0.1 * top], np.add(lower, 1e-9), np.subtract(upper, 1e-9))
    result = least_squares(lambda q: model(q) - c.y, start, bounds=(lower, upper), x_scale="jac", max_nfev=40)
    gain = 1.0 - 2.0 * result.cost / ssr if ssr > 0 else 0.0
    return (float(result.x[4]), gain) if gain >= BETTER else None


def _slopes(s: Samples, y: np.ndarray) -> np.ndarray:
    """|dy/dt| by the central difference over ±h samples (h·dt ≈ 40 ms) within one window, rad/s²."""
    dt = float(np.median(np.diff(s.t)))
    h = max(1, int(round(0.04 / dt)))
    if s.t.size <= 2 * h:
        return np.zeros(0)
    span = s.t[2 * h:] - s.t[:-2 * h]
    ok = (s.segment[2 * h:] == s.segment[:-2 * h]) & (span <= 2 * h * dt * 1.5) & (span > 0)
    return np.abs((y[2 * h:] - y[:-2 * h]) / np.where(ok, span, 1.0))[ok]


def _measured_acceleration(s: Samples) -> float:
    """The measured yaw acceleration's 99th percentile (rad/s²): where a slew limit's fit starts."""
    slopes = _slopes(s, s.y)
    return float(np.percentile(slopes, 99)) if slopes.size else 1.0


def _rate_limit(s: Samples, p: PlantParameters) -> float | None:
    """The measured |dω/dt| where it saturates, or None.

    The same central difference over ±h samples (h·dt ≈ 40 ms) is applied to the measured rate and to the model's;
    among the samples where the model's slope is in its top 2 %, a rate limit shows as measured slopes well below the
    model's (median ratio < 0.8) that do not grow with the model's: the log-log slope of the measured against the
    model's, over the upper half of the samples steeper than a quarter of the model's 99th percentile, is below 0.25
    (1 for a linear plant; a second lag gives 0.4–0.8). A log with one step size cannot show it.
    """
    if s.t.size < 200:
        return None
    measured = _slopes(s, s.y)
    predicted = _slopes(s, p.g * lag_response(s.cmd_t, s.u, s.t, p.tau, p.dead_time) + p.bias)
    if predicted.size < 200:
        return None
    top = predicted >= np.percentile(predicted, 98)
    ratio = float(np.median(measured[top]) / max(np.median(predicted[top]), 1e-300))
    steep = predicted >= 0.25 * np.percentile(predicted, 99)
    edges = np.percentile(predicted[steep], np.linspace(0, 100, 7))
    which = np.clip(np.searchsorted(edges, predicted[steep], side="right") - 1, 0, 5)
    xs, ys = [], []
    for k in range(3, 6):  # the upper half of the steep samples, in three bins of the model's slope
        inside = which == k
        if np.count_nonzero(inside) >= 5:
            xs.append(math.log(max(float(np.median(predicted[steep][inside])), 1e-300)))
            ys.append(math.log(max(float(np.median(measured[steep][inside])), 1e-300)))
    elasticity = float(np.polyfit(xs, ys, 1)[0]) if len(xs) == 3 and np.ptp(xs) > 0.2 else 1.0
    if ratio < 0.8 and elasticity < 0.25:
        return float(np.percentile(measured, 99))
    return None


# ------------------------------------------------------------------------------------------ the whole
def _slide(pose) -> tuple[SlipFit | None, str | None]:
    """`fit_slip_lag` of the pose; a pose that is no numbers (a localisation that lost itself) is a reason, not an error:
    the plant does not need it."""
    try:
        return fit_slip_lag(pose.t, pose.x, pose.y, pose.yaw)
    except ValueError as exc:
        return None, f"{exc} ({pose.topic})"


def identify(log: LogData, rate_source: str = "odometry", smoothing_frequency: float = SMOOTHING_FREQUENCY, *,
             slip: bool = True) -> Identification:
    """The controller's timing and the yaw-rate plant identified from `log`, and the base's slide from its pose.

    Parameters
    ----------
    log : LogData
        A log read with the command and the rate source (`pfm_stability.io.logs.read_log`).
    rate_source : str
        ``"odometry"`` or ``"imu"`` (`RATE_SOURCES`): where the achieved yaw rate comes from.
    smoothing_frequency : float
        The rate (Hz) of the velocity smoother a slew limit is fitted as (Nav2's default 20); 0: a continuous ramp.
    slip : bool
        Measure the slide's lag τ_s from ``log.pose`` when there is one (`analysis.slip_fit.fit_slip_lag`; the pose must
        see the base move: not wheel odometry's). False: not looked for, as without a pose.

    Returns
    -------
    Identification

    Raises
    ------
    ValueError
        An unknown rate source, a series missing from `log`, or fewer than 3 commands.
    """
    if rate_source not in RATE_SOURCES:
        raise ValueError(f"rate source must be one of {', '.join(RATE_SOURCES)}; got {rate_source!r}")
    rate = getattr(log, rate_source)
    if log.command is None or rate is None:
        raise ValueError(f"the log was read without its {'command' if log.command is None else rate_source}")
    command = log.command
    timing = controller_timing(command.t)
    pose = log.pose if slip else None
    summary = LogSummary(log.path, log.format, float(log.duration), command.topic, rate.topic, rate_source, command.stamps,
                         None if pose is None else pose.topic)
    if not (math.isfinite(smoothing_frequency) and 0.0 <= smoothing_frequency <= 1000.0):
        raise ValueError(f"smoothing frequency must be in [0, 1000] Hz (0: a continuous ramp); got {smoothing_frequency!r}")
    plant, reason = fit_plant(command.t, command.value, rate, timing.T, smoothing_frequency)
    slide, slip_reason = (None, None) if pose is None else _slide(pose)
    return Identification(plant is not None, reason, timing, plant, summary, slide, slip_reason)
