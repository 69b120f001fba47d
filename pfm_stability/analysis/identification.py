"""The controller's period and the yaw-rate plant g·e^(−sD)/(τs + 1), identified from a robot's log (docs/diagnose.md).

Controller period
-----------------
From the command's stamps (`controller_timing`): T is the median interval, the jitter its 5th and 95th
percentiles, a missed cycle an interval longer than 1.5·T (counted), and the achieved rate (messages per
second over the log) is set against the nominal 1/T.

The plant
---------
The commanded yaw rate u is held between its stamps (zero-order hold), delayed by D (any value, not a
whole number of periods) and passed through the first-order lag of gain g and time constant τ; a constant
offset b absorbs a gyro's bias (docs/diagnose.md, "Model"). Between two held commands the lag's response
is exact: with the state X_j when command j takes effect (at its stamp c_j + D),

    X_(j+1) = u_j + (X_j − u_j)·exp(−(c_(j+1) − c_j)/τ),       y(t) = g·(u_j + (X_j − u_j)·exp(−(t − c_j − D)/τ)) + b

— an affine recursion in j, computed for every command at once by a doubling scan (`_affine_scan`,
log₂ m passes over the arrays), and independent of D: D only moves where each sample falls. Its
sensitivities to τ (a second scan) and to D (−dy/dt) are exact too, so the Jacobian is analytic.

The fit uses the samples where the command excites the plant (`excitation_windows`: from 0.5 s before
each change of the command to `SETTLE` s after it; long constant stretches and a robot told to stand
still are left out, and so is a sample whose newest command is older than `STALE` periods, when a base
may have stopped on its command timeout). A coarse grid over (τ, D), with g and b solved linearly at each
point, starts `scipy.optimize.least_squares` (D's residual has a local minimum per period of the
command's oscillation; the grid finds the right one).

Intervals
---------
95 % intervals are value ± 1.96·σ from the covariance H⁻¹·S·H⁻¹, H = JᵀJ, with the Newey–West estimate
S = Σ_l w_l·Σ_t (J_t r_t)(J_(t−l) r_(t−l))ᵀ (Bartlett weights, lags within one window only). With white
residuals this is s²·(JᵀJ)⁻¹; with residuals correlated over L samples (unmodelled dynamics, a smoothed
odometry) it widens by the right amount for each parameter, where an effective sample count would
widen every parameter alike. L is the larger of Newey and West's 4·(n/100)^(2/9) and three times the
lag at which the residuals' autocorrelation falls below 0.1.

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
`FitQuality` gives the normalized error (NRMSE = rms(r)/std(y)), R² and the residuals' whiteness, and
`FitWarning` names what the model does not explain: a rate limit (the measured |dω/dt| saturates where
the model asks for more), a deadband or backlash (a model whose small commands deliver nothing fits
significantly better) and second-order behaviour (a second lag fits significantly better). "Significantly"
is at least `BETTER` of the residual sum of squares on the same samples.

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

__all__ = ["Estimate", "ControllerTiming", "FitWarning", "FitQuality", "Excitation", "PlantFit", "LogSummary",
           "Identification", "controller_timing", "excitation_windows", "command_spectrum", "lag_response", "fit_plant",
           "identify", "ridge_point", "NARROWBAND", "BAND",
           "MISSED_FACTOR", "SETTLE", "LEAD", "STALE", "DEAD_TIME_BOUNDS", "TAU_BOUNDS", "BETTER", "RATE_SOURCES"]

MISSED_FACTOR = 1.5
"""An interval between commands longer than this many median periods is a missed cycle."""
LEAD, SETTLE = 0.5, 4.0
"""A window of excitation runs from LEAD s before a change of the command to SETTLE s after it."""
STALE = 5.0
"""A sample whose newest command is older than max(0.5 s, STALE·T) is not used (the base may have stopped)."""
DEAD_TIME_BOUNDS = (-0.1, 1.0)
"""The dead time D searched (s); a negative D means the rate's stamps lead the command's (clocks differ)."""
TAU_BOUNDS = (0.005, 5.0)
"""The lag τ searched (s)."""
BETTER = 0.1
"""A richer model (second lag, deadband) is named when it lowers the residual sum of squares by this fraction."""
RATE_SOURCES = ("odometry", "imu")
"""Where the achieved yaw rate comes from: the odometry's twist, or the IMU's angular velocity."""
Z95 = 1.959963984540054
GRID_SAMPLES, CHECK_SAMPLES, FIRST_SAMPLES = 5_000, 8_000, 20_000
"""The grid search, the checks of richer models and a long log's first fit use a contiguous stretch of at most this
many samples (speed: the final fit uses every sample)."""


# ------------------------------------------------------------------------------------------ results
@dataclass(frozen=True)
class Estimate:
    """A parameter and its 95 % interval [low, high] (the parameter's unit); low and high are NaN (null in JSON) when
    the log cannot determine the parameter (`Excitation.narrowband`).

    Attributes
    ----------
    value : float
        The estimate, in the parameter's unit.
    low, high : float
        The 95 % interval's ends, same unit; NaN when not identifiable.
    """

    value: float
    low: float
    high: float

    def to_dict(self) -> dict:
        """``{value, low, high}``."""
        return {"value": json_number(self.value), "low": json_number(self.low), "high": json_number(self.high)}


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
class PlantFit:
    """The fitted plant g·e^(−sD)/(τs + 1).

    Parameters
    ----------
    g : Estimate
        The plant gain (−) and its 95 % interval.
    tau : Estimate
        The lag (s) and its 95 % interval.
    dead_time : Estimate
        The dead time D (s) from the command's publication (docs/diagnose.md, "Time") and its 95 % interval.
    quality : FitQuality
        How well the model explains the samples.
    warnings : tuple of FitWarning
        What the model does not explain, and ``narrowband``.
    excitation : Excitation or None
        How the commands excite the plant; when narrowband the values are one point of the ridge the log cannot
        resolve and the intervals are NaN.
    """

    g: Estimate
    tau: Estimate
    dead_time: Estimate
    quality: FitQuality
    warnings: tuple[FitWarning, ...]
    excitation: Excitation | None = None

    @property
    def identifiable(self) -> bool:
        """Whether g, τ and D are separately determined by the log (not `Excitation.narrowband`)."""
        return self.excitation is None or not self.excitation.narrowband


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
    """

    path: str
    format: str
    duration: float
    command_topic: str
    rate_topic: str
    rate_source: str
    command_stamps: str

    def to_dict(self) -> dict:
        """The ``log`` of the JSON output."""
        return {"path": self.path, "format": self.format, "duration": json_number(self.duration),
                "topics": {"command": self.command_topic, "rate": self.rate_topic},
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
    """

    identified: bool
    reason: str | None
    controller: ControllerTiming
    plant: PlantFit | None
    log: LogSummary

    def to_dict(self) -> dict:
        """The JSON output of ``pfm-stability identify`` without ``schema_version``, ``command`` and ``timing``."""
        plant = self.plant
        return {
            "identified": self.identified,
            "reason": self.reason,
            "plant": None if plant is None else {"g": plant.g.to_dict(), "tau": plant.tau.to_dict(),
                                                 "dead_time": plant.dead_time.to_dict(),
                                                 "identifiable": plant.identifiable},
            "controller": self.controller.to_dict(),
            "fit": {"quality": None if plant is None else plant.quality.to_dict(),
                    "warnings": [] if plant is None else [w.to_dict() for w in plant.warnings],
                    "excitation": None if plant is None or plant.excitation is None else plant.excitation.to_dict()},
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


# ------------------------------------------------------------------------------------------ the excitation
# ------------------------------------------------------------------------------------------ the exact response
def _affine_scan(a: np.ndarray, b: np.ndarray, x0: float) -> np.ndarray:
    """X with X_0 = x0 and X_(k+1) = a_k·X_k + b_k (length len(a) + 1), by doubling: log₂ n vector passes."""
    A, B = a.astype(float).copy(), b.astype(float).copy()
    shift = 1
    while shift < A.size:
        B[shift:] = A[shift:] * B[:-shift] + B[shift:]
        A[shift:] = A[shift:] * A[:-shift]
        shift *= 2
    return np.concatenate([[x0], A * x0 + B])


def lag_response(cmd_t: np.ndarray, u: np.ndarray, t: np.ndarray, tau: float, dead_time: float,
                 derivatives: bool = False):
    """The unit-gain lag's response at `t` to `u` held from each `cmd_t` on and delayed by `dead_time`, exactly.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commands (rad/s); before the first the plant rests at u[0].
    t : numpy.ndarray
        Where the response is wanted (s).
    tau : float
        The lag's time constant (s), > 0.
    dead_time : float
        The delay D (s).
    derivatives : bool
        Also return the derivatives with respect to τ and D.

    Returns
    -------
    numpy.ndarray or tuple of numpy.ndarray
        x(t) (rad/s); with `derivatives`, (x, ∂x/∂τ, ∂x/∂D).
    """
    u = np.asarray(u, dtype=float)
    dt = np.diff(cmd_t)
    a, X = _lag_states(dt, u, tau)
    x, j, before, elapsed, e = _lag_at(cmd_t, u, X, t, tau, dead_time)
    if not derivatives:
        return x
    gap = X[j] - u[j]
    dX = _affine_scan(a, (X[:-1] - u[:-1]) * a * dt / tau**2, 0.0)
    dx_dtau = np.where(before, 0.0, dX[j] * e + gap * e * elapsed / tau**2)
    dx_dD = np.where(before, 0.0, (x - u[j]) / tau)
    return x, dx_dtau, dx_dD


def _lag_states(dt: np.ndarray, u: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """(exp(−Δc_j/τ), X_j): the lag's state when each command takes effect (module docstring), unit gain."""
    a = np.exp(-dt / tau)
    return a, _affine_scan(a, (1.0 - a) * u[:-1], u[0])


def _lag_at(cmd_t, u, X, t, tau: float, dead_time: float):
    """(x, j, before, elapsed, e) at `t`: the response, the command in effect, t before the first, time since it, e^(−elapsed/τ)."""
    j = np.searchsorted(cmd_t + dead_time, t, side="right") - 1
    before = j < 0
    j = np.maximum(j, 0)
    elapsed = np.where(before, 0.0, t - (cmd_t[j] + dead_time))
    e = np.exp(-elapsed / tau)
    return u[j] + (X[j] - u[j]) * e, j, before, elapsed, e


def _second_order(cmd_t, u, t, tau1: float, ratio: float, dead_time: float) -> np.ndarray:
    """Unit-gain response of 1/((τ1·s + 1)(τ2·s + 1)), τ2 = ratio·τ1 < τ1, by partial fractions of two lags."""
    tau2 = ratio * tau1
    return (tau1 * lag_response(cmd_t, u, t, tau1, dead_time) - tau2 * lag_response(cmd_t, u, t, tau2, dead_time)) / (tau1 - tau2)


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


@dataclass(frozen=True)
class _Samples:
    """The problem: commands (cmd_t, u) and the samples (t, y) used, with the segment each belongs to."""

    cmd_t: np.ndarray
    u: np.ndarray
    t: np.ndarray
    y: np.ndarray
    segment: np.ndarray

    def chunk(self, size: int) -> "_Samples":
        """A contiguous stretch around the middle with at most `size` samples, and the commands it needs."""
        if self.t.size <= size:
            return self
        first = (self.t.size - size) // 2
        t0, t1 = self.t[first], self.t[first + size - 1]
        c0 = max(int(np.searchsorted(self.cmd_t, t0 - 30.0)) - 1, 0)
        c1 = int(np.searchsorted(self.cmd_t, t1, side="right"))
        keep = slice(first, first + size)
        return _Samples(self.cmd_t[c0:c1], self.u[c0:c1], self.t[keep], self.y[keep], self.segment[keep])


def _select(cmd_t, u, rate: TimeSeries, T: float) -> tuple[_Samples, np.ndarray]:
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
    return _Samples(cmd_t, u, ts, y[keep], segment), windows


# ------------------------------------------------------------------------------------------ the fit
def _grid_start(s: _Samples) -> tuple[float, float, float, float]:
    """(g, τ, D, b) of the best point of a (τ, D) grid, g and b solved by linear least squares at each."""
    taus = np.geomspace(0.01, 3.0, 18)
    delays = np.arange(DEAD_TIME_BOUNDS[0], DEAD_TIME_BOUNDS[1] + 1e-9, 0.02)
    y = s.y - s.y.mean()
    sst = float(y @ y)
    best = (math.inf, 1.0, 0.1, 0.0)
    dt = np.diff(s.cmd_t)
    for tau in taus:
        _, X = _lag_states(dt, s.u, tau)
        x = np.stack([_lag_at(s.cmd_t, s.u, X, s.t, tau, d)[0] for d in delays])
        xc = x - x.mean(axis=1, keepdims=True)
        var = np.einsum("ij,ij->i", xc, xc)
        cov = xc @ y
        ssr = sst - np.where(var > 0, cov**2 / np.where(var > 0, var, 1.0), 0.0)
        k = int(np.argmin(ssr))
        if ssr[k] < best[0]:
            best = (float(ssr[k]), float(tau), float(delays[k]), float(cov[k] / var[k]) if var[k] > 0 else 0.0)
    _, tau, delay, g = best
    b = float(s.y.mean() - g * lag_response(s.cmd_t, s.u, s.t, tau, delay).mean())
    return g, tau, delay, b


def _residuals_and_jacobian(p, s: _Samples):
    g, tau, delay, b = p
    x, dtau, dD = lag_response(s.cmd_t, s.u, s.t, tau, delay, derivatives=True)
    r = g * x + b - s.y
    return r, np.column_stack([x, g * dtau, g * dD, np.ones_like(x)])


def _least_squares(p0, s: _Samples):
    from scipy.optimize import least_squares

    lower = [-np.inf, TAU_BOUNDS[0], DEAD_TIME_BOUNDS[0], -np.inf]
    upper = [np.inf, TAU_BOUNDS[1], DEAD_TIME_BOUNDS[1], np.inf]
    p0 = np.clip(np.asarray(p0, dtype=float), np.add(lower, 1e-9), np.subtract(upper, 1e-9))
    cache = {}

    def both(p):
        key = p.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = _residuals_and_jacobian(p, s)
        return cache[key]

    result = least_squares(lambda p: both(p)[0], p0, jac=lambda p: both(p)[1], bounds=(lower, upper), x_scale="jac",
                           method="trf", xtol=1e-10, ftol=1e-10, gtol=1e-10, max_nfev=200)
    return result.x


def _autocorrelation(r: np.ndarray, segment: np.ndarray, lags: int) -> np.ndarray:
    """ρ_1..ρ_lags of `r` counting only pairs within one segment."""
    r = r - r.mean()
    var = float(r @ r)
    out = np.zeros(lags)
    if var <= 0:
        return out
    for k in range(1, min(lags, r.size - 1) + 1):
        same = segment[k:] == segment[:-k]
        out[k - 1] = float(np.sum((r[k:] * r[:-k])[same])) / var
    return out


def _covariance(J: np.ndarray, r: np.ndarray, segment: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """Newey–West covariance of the parameters (module docstring, "Intervals"), its lag L and ρ_1..ρ_L of r."""
    n = r.size
    rule = int(math.floor(4.0 * (n / 100.0) ** (2.0 / 9.0)))
    rho = _autocorrelation(r, segment, 400)
    below = np.flatnonzero(rho < 0.1)
    crossing = int(below[0]) + 1 if below.size else rho.size
    L = int(min(max(rule, 3 * crossing), 400, max(n // 10, 1)))
    scores = J * r[:, None]
    S = scores.T @ scores
    for lag in range(1, L + 1):
        same = (segment[lag:] == segment[:-lag])[:, None]
        G = (scores[lag:] * same).T @ scores[:-lag]
        S += (1.0 - lag / (L + 1.0)) * (G + G.T)
    H_inv = np.linalg.pinv(J.T @ J)
    return H_inv @ S @ H_inv, L, rho[:L]


def _interval(value: float, variance: float) -> Estimate:
    half = Z95 * math.sqrt(max(variance, 0.0))
    return Estimate(float(value), float(value - half), float(value + half))


def fit_plant(cmd_t: np.ndarray, u: np.ndarray, rate: TimeSeries, T: float) -> tuple[PlantFit | None, str | None]:
    """Fit g·e^(−sD)/(τs + 1) (and an offset) to the rate samples where the command excites the plant.

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

    Returns
    -------
    tuple
        (the fit, None), or (None, why nothing was identified).
    """
    cmd_t, u = np.asarray(cmd_t, dtype=float), np.asarray(u, dtype=float)
    if np.ptp(u) <= 1e-3:
        what = "stand still" if np.all(np.abs(u) <= 1e-3) else f"turn at a constant {float(np.median(u)):.3g} rad/s"
        return None, f"the command never changes (the robot was told to {what}): nothing excites the plant"
    s, windows = _select(cmd_t, u, rate, T)
    if s.t.size < 50:
        return None, (f"only {s.t.size} samples of the rate while the command changes (at least 50 are needed): "
                      "the log is too short or the rate topic is too sparse")
    start, chunk = _grid_start(s.chunk(GRID_SAMPLES)), s.chunk(FIRST_SAMPLES)
    if chunk is not s:  # a long log: fit a stretch first, then polish on every sample from there
        start = _least_squares(start, chunk)
    g, tau, delay, b = _least_squares(start, s)
    r, J = _residuals_and_jacobian((g, tau, delay, b), s)
    cov, L, rho = _covariance(J, r, s.segment)
    estimates = [_interval(v, cov[i, i]) for i, v in enumerate((g, tau, delay))]
    g_est = estimates[0]
    if abs(g) < 0.05 or g_est.low <= 0.0 <= g_est.high:
        return None, (f"the robot did not follow the commands (g = {g:.3g}, 95 % interval {g_est.low:.3g} to {g_est.high:.3g}): "
                      "it stood still (stopped, emergency stop) or the rate topic is not this robot's")
    if g_est.high - g_est.low > abs(g):
        return None, (f"the commands excite the plant too little for the noise (g = {g:.3g} ± {(g_est.high - g_est.low) / 2:.2g}): "
                      "record steps or turns of the yaw rate (docs/diagnose.md)")
    y = s.y
    sst = float(np.sum((y - y.mean()) ** 2))
    ssr = float(r @ r)
    rho20 = _autocorrelation(r, s.segment, 20)
    outside = float(np.mean(np.abs(rho20) > 1.96 / math.sqrt(r.size)))
    bartlett = 1.0 + 2.0 * float(np.sum((1.0 - np.arange(1, L + 1) / (L + 1.0)) * rho)) if L else 1.0
    quality = FitQuality(
        nrmse=math.sqrt(ssr / r.size) / max(float(np.std(y)), 1e-300), r2=1.0 - ssr / sst if sst > 0 else math.nan,
        lag1=float(rho20[0]), outside=outside, white=outside <= 0.2, samples=int(r.size),
        effective_samples=float(r.size / max(bartlett, 1.0)), windows=int(len(windows)),
        excited=float(np.sum(windows[:, 1] - windows[:, 0])), bias=float(b), hac_lags=L)
    excitation = excitation_of(cmd_t, u, T, g, tau, delay)
    warnings = _checks(s, (g, tau, delay, b), estimates, quality, excitation.narrowband)
    if excitation.narrowband:  # one frequency: the fit is one point of a ridge, its intervals mean nothing
        warnings.insert(0, FitWarning("narrowband", (
            f"the commands excite one frequency (ω ≈ {excitation.omega:.3g} rad/s; {100 * (1 - excitation.outside):.1f} % "
            f"of their power within a factor {BAND:g} of it): g, τ and D are not separately identifiable, only the plant's "
            f"gain {excitation.gain:.3g} and phase {math.degrees(excitation.phase):.0f}° there; record step turns "
            "(docs/diagnose.md)")))
        estimates = [Estimate(e.value, math.nan, math.nan) for e in estimates]
    return PlantFit(estimates[0], estimates[1], estimates[2], quality, tuple(warnings), excitation), None


# ------------------------------------------------------------------------------------------ what the model misses
def _checks(s: _Samples, p, estimates, quality: FitQuality, narrowband: bool = False) -> list[FitWarning]:
    g, tau, delay, b = p
    warnings = []
    if quality.r2 < 0.8:
        warnings.append(FitWarning("poor_fit", f"the model explains only {100 * quality.r2:.0f} % of the rate's variance "
                                               f"(NRMSE {quality.nrmse:.2f}): its numbers are rough"))
    if delay >= DEAD_TIME_BOUNDS[1] - 1e-3:
        warnings.append(FitWarning("dead_time_at_bound", f"the dead time reached the largest searched, {DEAD_TIME_BOUNDS[1]:g} s: "
                                                         "the command and rate topics may not belong together"))
    if estimates[2].high < 0 and not narrowband:  # on a ridge a negative D is where the fit stopped, not the clocks
        warnings.append(FitWarning("negative_dead_time", f"the rate leads the command by {-1000 * delay:.0f} ms: "
                                                         "their stamps come from different clocks"))
    limit = _rate_limit(s, p)
    if limit is not None:
        warnings.append(FitWarning("rate_limit", f"the yaw acceleration saturates near {limit:.2g} rad/s² where the model "
                                                 f"asks for more: a rate limit the lag does not explain"))
    c = s.chunk(CHECK_SAMPLES)
    base = g * lag_response(c.cmd_t, c.u, c.t, tau, delay) + b - c.y
    ssr = float(base @ base)
    second = None if limit is not None else _better_second_order(c, p, ssr)  # a rate limit also makes a second lag fit better
    if second is not None:
        ratio, gain = second
        warnings.append(FitWarning("second_order", f"a second lag of {ratio * tau:.2g} s (with the first {tau:.2g} s) "
                                                   f"lowers the residual by {100 * gain:.0f} %: the plant is not first order"))
    band = _better_deadband(c, p, ssr)
    if band is not None:
        width, gain = band
        warnings.append(FitWarning("deadband", f"small commands are under-delivered: a deadband (or backlash) of {width:.2g} rad/s "
                                               f"lowers the residual by {100 * gain:.0f} %"))
    return warnings


def _refit(model, starts, lower, upper, c: _Samples) -> tuple[float, np.ndarray]:
    """(residual sum of squares, parameters) of the best fit of `model(p)` to c.y from each of `starts` (bounded)."""
    from scipy.optimize import least_squares

    best = (math.inf, np.asarray(starts[0], dtype=float))
    for start in starts:
        start = np.clip(np.asarray(start, dtype=float), np.add(lower, 1e-9), np.subtract(upper, 1e-9))
        result = least_squares(lambda q: model(q) - c.y, start, bounds=(lower, upper), x_scale="jac", max_nfev=40)
        if 2.0 * result.cost < best[0]:
            best = (2.0 * float(result.cost), result.x)
    return best


def _better_second_order(c: _Samples, p, ssr: float):
    """(τ2/τ1, relative improvement) when a second lag lowers the residual by `BETTER` or more, else None."""
    g, tau, delay, b = p
    model = lambda q: q[0] * _second_order(c.cmd_t, c.u, c.t, q[1], q[2], q[3]) + q[4]
    lower = [-np.inf, TAU_BOUNDS[0], 0.02, DEAD_TIME_BOUNDS[0], -np.inf]
    upper = [np.inf, TAU_BOUNDS[1], 0.9, DEAD_TIME_BOUNDS[1], np.inf]
    starts = [[g, tau / (1.0 + ratio), ratio, max(delay - 0.5 * ratio * tau, DEAD_TIME_BOUNDS[0]), b] for ratio in (0.3,)]
    fitted, q = _refit(model, starts, lower, upper, c)
    gain = 1.0 - fitted / ssr if ssr > 0 else 0.0
    return (float(q[2]), gain) if gain >= BETTER else None


def _better_deadband(c: _Samples, p, ssr: float):
    """(deadband rad/s, relative improvement) when a deadband on the command lowers the residual by `BETTER`, else None."""
    g, tau, delay, b = p
    top = float(np.max(np.abs(c.u)))
    if top <= 0:
        return None
    model = lambda q: q[0] * lag_response(c.cmd_t, _deadband(c.u, q[4]), c.t, q[1], q[2]) + q[3]
    lower = [-np.inf, TAU_BOUNDS[0], DEAD_TIME_BOUNDS[0], -np.inf, 0.0]
    upper = [np.inf, TAU_BOUNDS[1], DEAD_TIME_BOUNDS[1], np.inf, 0.5 * top]
    starts = [[g / (1.0 - width), tau, delay, b, width * top] for width in (0.1,)]
    fitted, q = _refit(model, starts, lower, upper, c)
    gain = 1.0 - fitted / ssr if ssr > 0 else 0.0
    return (float(q[4]), gain) if gain >= BETTER else None


def _rate_limit(s: _Samples, p) -> float | None:
    """The measured |dω/dt| where it saturates, or None.

    The same central difference over ±h samples (h·dt ≈ 40 ms) is applied to the measured rate and to the model's;
    among the samples where the model's slope is in its top 2 %, a rate limit shows as measured slopes well below the
    model's (median ratio < 0.8) that do not grow with the model's: the log-log slope of the measured against the
    model's, over the upper half of the samples steeper than a quarter of the model's 99th percentile, is below 0.25
    (1 for a linear plant; a second lag gives 0.4–0.8). A log with one step size cannot show it.
    """
    g, tau, delay, b = p
    if s.t.size < 200:
        return None
    dt = float(np.median(np.diff(s.t)))
    h = max(1, int(round(0.04 / dt)))
    model = g * lag_response(s.cmd_t, s.u, s.t, tau, delay) + b
    span = s.t[2 * h:] - s.t[:-2 * h]
    ok = (s.segment[2 * h:] == s.segment[:-2 * h]) & (span <= 2 * h * dt * 1.5) & (span > 0)
    measured = np.abs((s.y[2 * h:] - s.y[:-2 * h]) / np.where(ok, span, 1.0))[ok]
    predicted = np.abs((model[2 * h:] - model[:-2 * h]) / np.where(ok, span, 1.0))[ok]
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
def identify(log: LogData, rate_source: str = "odometry") -> Identification:
    """The controller's timing and the yaw-rate plant identified from `log`.

    Parameters
    ----------
    log : LogData
        A log read with the command and the rate source (`pfm_stability.io.logs.read_log`).
    rate_source : str
        ``"odometry"`` or ``"imu"`` (`RATE_SOURCES`): where the achieved yaw rate comes from.

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
    summary = LogSummary(log.path, log.format, float(log.duration), command.topic, rate.topic, rate_source, command.stamps)
    plant, reason = fit_plant(command.t, command.value, rate, timing.T)
    return Identification(plant is not None, reason, timing, plant, summary)
