"""Least-squares fits of the steering plant to a log's samples, their covariance, and which plant the data support
(docs/diagnose.md, "The fit", "Which plant").

The candidates (`PLANT_MODELS`), each g·[plant](u)(t − D) + b with the command u held between its stamps:

| model | plant | parameters |
| --- | --- | --- |
| ``first_order`` | 1/(τs + 1) | g, τ, D, b |
| ``two_lags`` | 1/((τs + 1)(τ_a·s + 1)), τ_a < τ | g, τ, τ_a, D, b |
| ``slew_limited`` | 1/(τs + 1) behind a slew limit A on u | g, τ, D, A, b |
| ``two_lags_slew_limited`` | both | g, τ, τ_a, D, A, b |

(`analysis.plant_response` computes each response exactly.) The first order's Jacobian is analytic; the others' are
forward differences of the exact response (τ_a and A enter through ρ = τ_a/τ in (0, `RATIO_HIGH`] and ln A, which keep
the partial fractions away from τ_a = τ and A positive; their intervals are mapped back by the delta method).

**Which plant.** Every candidate is fitted to the same samples (a contiguous stretch of at most `SELECT_SAMPLES`) and
scored by Schwarz's Bayesian information criterion BIC = n·ln(SSR/n) + p·ln n (and Akaike's AIC = n·ln(SSR/n) + 2p,
reported); the smallest BIC is the model the data support. The residuals' whiteness of each is Ljung and Box's
Q = n(n + 2)·Σ_(k ≤ h) ρ_k²/(n − k) over h = `LJUNG_BOX_LAGS` lags, with its χ²_h p-value: a small p says the model
leaves structure the noise does not explain.

**Intervals.** 95 % intervals are value ± 1.96·σ from the covariance H⁻¹·S·H⁻¹, H = JᵀJ, with the Newey–West estimate
S = Σ_l w_l·Σ_t (J_t r_t)(J_(t−l) r_(t−l))ᵀ (Bartlett weights, lags within one window only); L is the larger of Newey
and West's 4·(n/100)^(2/9) and three times the lag at which the residuals' autocorrelation falls below 0.1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..io.serialize import json_number
from .plant_response import lag_at, lag_response, lag_states, plant_response, slew_limited, smoothed

__all__ = ["Estimate", "Samples", "CandidateFit", "PlantParameters", "PLANT_MODELS", "MODEL_PARAMETERS", "DEAD_TIME_BOUNDS", "TAU_BOUNDS",
           "RATIO_HIGH", "SLEW_BOUNDS", "SMOOTHING_FREQUENCY", "PHASES", "SELECT_SAMPLES", "LJUNG_BOX_LAGS", "Z95", "grid_start", "fit_first_order",
           "fit_model", "residuals", "jacobian", "covariance", "autocorrelation", "ljung_box", "candidates"]

DEAD_TIME_BOUNDS = (-0.1, 1.0)
"""The dead time D searched (s); a negative D means the rate's stamps lead the command's (clocks differ)."""
TAU_BOUNDS = (0.005, 5.0)
"""The lag τ searched (s)."""
RATIO_HIGH = 0.9
"""The second lag is at most this fraction of the first (τ_a ≤ 0.9·τ): the partial fractions (τx_τ − τ_a·x_(τ_a))/(τ − τ_a)
lose digits as τ_a → τ; two equal lags are fitted as τ_a = 0.9·τ."""
RATIO_LOW = 1e-3
"""The smallest τ_a/τ searched (a second lag of 0.1 % of the first is none)."""
SLEW_BOUNDS = (0.05, 1000.0)
"""The slew limit A searched (rad/s²): from a drive that takes 20 s to reach 1 rad/s to one that no command reaches."""
SMOOTHING_FREQUENCY = 20.0
"""The slew limit's timer (Hz): Nav2's velocity smoother's default ``smoothing_frequency``; 0 fits a continuous ramp."""
PHASES = 10
"""The smoother's timer phase φ is searched on this many points of [0, 1/f) (a phase moves which command each tick
reads: no derivative; 5 ms apart at 20 Hz, below the odometry's period)."""
SELECT_SAMPLES = 8_000
"""The candidates are compared on a contiguous stretch of at most this many samples (the same for all; speed)."""
LJUNG_BOX_LAGS = 20
"""Lags h of the Ljung–Box statistic (0.4 s of 50-Hz odometry: a lag's or a smoother's memory)."""
Z95 = 1.959963984540054
TR_SOLVER = "lsmr"

PLANT_MODELS = ("first_order", "two_lags", "slew_limited", "two_lags_slew_limited")
"""The candidate plants (module docstring), simplest first."""
MODEL_PARAMETERS = {"first_order": ("g", "tau", "D", "b"), "two_lags": ("g", "tau", "rho", "D", "b"),
                    "slew_limited": ("g", "tau", "D", "log_slew", "b"),
                    "two_lags_slew_limited": ("g", "tau", "rho", "D", "log_slew", "b")}
"""Each candidate's free parameters (ρ = τ_a/τ, ln A)."""
_ORDER = ("g", "tau", "rho", "D", "log_slew", "b")
_STEP = {"tau": 1e-6, "rho": 1e-6, "D": 1e-7, "log_slew": 1e-6}
"""Forward-difference steps (s, −, s, −): the responses are smooth in each at this scale, and ε/h ~ 1e-10."""


@dataclass(frozen=True)
class Estimate:
    """A parameter and its 95 % interval [low, high] (the parameter's unit); low and high are NaN (null in JSON) when
    the log cannot determine the parameter (`analysis.excitation.Excitation.narrowband`).

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
class Samples:
    """The problem: the commands and the rate samples fitted.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commanded yaw rates (rad/s).
    t : numpy.ndarray
        The samples' times (s).
    y : numpy.ndarray
        The measured yaw rate there (rad/s).
    segment : numpy.ndarray
        The excitation window each sample belongs to (lags are taken within one).
    """

    cmd_t: np.ndarray
    u: np.ndarray
    t: np.ndarray
    y: np.ndarray
    segment: np.ndarray

    def chunk(self, size: int) -> "Samples":
        """A contiguous stretch around the middle with at most `size` samples, and the commands it needs.

        Parameters
        ----------
        size : int
            The largest number of samples.
        """
        if self.t.size <= size:
            return self
        first = (self.t.size - size) // 2
        t0, t1 = self.t[first], self.t[first + size - 1]
        c0 = max(int(np.searchsorted(self.cmd_t, t0 - 30.0)) - 1, 0)
        c1 = int(np.searchsorted(self.cmd_t, t1, side="right"))
        keep = slice(first, first + size)
        return Samples(self.cmd_t[c0:c1], self.u[c0:c1], self.t[keep], self.y[keep], self.segment[keep])


@dataclass(frozen=True)
class PlantParameters:
    """One plant's parameters (the candidates' common vector).

    Attributes
    ----------
    g : float
        Plant gain (−).
    tau : float
        The (slower) lag τ, s.
    actuator_lag : float
        The second lag τ_a, s (0: none).
    dead_time : float
        D, s.
    slew : float
        The slew limit A, rad/s² (inf: none).
    bias : float
        The offset b, rad/s.
    phase : float
        The smoother's timer phase φ, s (`plant_response.smoothed`; with a slew limit and a smoothing frequency only).
    """

    g: float
    tau: float
    actuator_lag: float
    dead_time: float
    slew: float
    bias: float
    phase: float = 0.0

    def vector(self) -> dict:
        """The fit's internal coordinates (g, τ, ρ = τ_a/τ, D, ln A, b)."""
        return {"g": self.g, "tau": self.tau, "rho": self.actuator_lag / self.tau, "D": self.dead_time,
                "log_slew": math.log(self.slew) if math.isfinite(self.slew) else math.inf, "b": self.bias}

    @classmethod
    def of(cls, q: dict, phase: float = 0.0) -> "PlantParameters":
        """From the internal coordinates (absent ones: no second lag, no slew limit).

        Parameters
        ----------
        q : dict
            Some of g, tau, rho, D, log_slew, b.
        phase : float
            The smoother's timer phase, s.
        """
        rho, log_slew = q.get("rho", 0.0), q.get("log_slew", math.inf)
        return cls(float(q["g"]), float(q["tau"]), float(rho * q["tau"]), float(q["D"]),
                   math.exp(log_slew) if math.isfinite(log_slew) else math.inf, float(q["b"]), float(phase))


@dataclass(frozen=True)
class CandidateFit:
    """One candidate plant fitted to the selection's samples (module docstring, "Which plant").

    Attributes
    ----------
    model : str
        One of `PLANT_MODELS`.
    parameters : PlantParameters
        Its fitted parameters.
    samples : int
        n, the samples fitted (the same for every candidate).
    count : int
        p, its free parameters.
    ssr : float
        Residual sum of squares, (rad/s)².
    aic, bic : float
        Akaike's and Schwarz's criteria (dimensionless; differences matter).
    ljung_box : float
        Q over `LJUNG_BOX_LAGS` lags.
    ljung_box_p : float
        Its χ² p-value (small: structure left in the residuals).
    selected : bool
        The smallest BIC.
    """

    model: str
    parameters: PlantParameters
    samples: int
    count: int
    ssr: float
    aic: float
    bic: float
    ljung_box: float
    ljung_box_p: float
    selected: bool

    def to_dict(self) -> dict:
        """The ``fit.models[]`` of the JSON output."""
        p = self.parameters
        return {"model": self.model, "selected": self.selected, "g": json_number(p.g), "tau": json_number(p.tau),
                "actuator_lag": json_number(p.actuator_lag), "dead_time": json_number(p.dead_time),
                "yaw_accel_limit": json_number(p.slew), "parameters": self.count, "samples": self.samples,
                "ssr": json_number(self.ssr), "aic": json_number(self.aic), "bic": json_number(self.bic),
                "ljung_box": {"q": json_number(self.ljung_box), "p": json_number(self.ljung_box_p), "lags": LJUNG_BOX_LAGS}}


# ------------------------------------------------------------------------------------------ the first order
def grid_start(s: Samples) -> tuple[float, float, float, float]:
    """(g, τ, D, b) of the best point of a (τ, D) grid, g and b solved by linear least squares at each.

    Parameters
    ----------
    s : Samples
        The problem.
    """
    taus = np.geomspace(0.01, 3.0, 18)
    delays = np.arange(DEAD_TIME_BOUNDS[0], DEAD_TIME_BOUNDS[1] + 1e-9, 0.02)
    y = s.y - s.y.mean()
    sst = float(y @ y)
    best = (math.inf, 1.0, 0.1, 0.0)
    dt = np.diff(s.cmd_t)
    for tau in taus:
        _, X = lag_states(dt, s.u, tau)
        x = np.stack([lag_at(s.cmd_t, s.u, X, s.t, tau, d)[0] for d in delays])
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


def _first_order_jacobian(p, s: Samples):
    g, tau, delay, b = p
    x, dtau, dD = lag_response(s.cmd_t, s.u, s.t, tau, delay, derivatives=True)
    r = g * x + b - s.y
    return r, np.column_stack([x, g * dtau, g * dD, np.ones_like(x)])


def _solve(fun, jac, p0, lower, upper, max_nfev: int):
    from scipy.optimize import least_squares

    p0 = np.clip(np.asarray(p0, dtype=float), np.add(lower, 1e-9), np.subtract(upper, 1e-9))
    return least_squares(fun, p0, jac=jac, bounds=(lower, upper), x_scale="jac", method="trf", tr_solver=TR_SOLVER, xtol=1e-10, ftol=1e-10,
                         gtol=1e-10, max_nfev=max_nfev)


def fit_first_order(p0, s: Samples) -> tuple[float, float, float, float]:
    """(g, τ, D, b) of the first-order plant fitted from `p0`, with its analytic Jacobian.

    Parameters
    ----------
    p0 : sequence of float
        The start (g, τ, D, b).
    s : Samples
        The problem.
    """
    lower = [-np.inf, TAU_BOUNDS[0], DEAD_TIME_BOUNDS[0], -np.inf]
    upper = [np.inf, TAU_BOUNDS[1], DEAD_TIME_BOUNDS[1], np.inf]
    cache = {}

    def both(p):
        key = p.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = _first_order_jacobian(p, s)
        return cache[key]

    result = _solve(lambda p: both(p)[0], lambda p: both(p)[1], p0, lower, upper, 200)
    return tuple(float(v) for v in result.x)


# ------------------------------------------------------------------------------------------ every candidate
_LOWER = {"g": -np.inf, "tau": TAU_BOUNDS[0], "rho": RATIO_LOW, "D": DEAD_TIME_BOUNDS[0], "log_slew": math.log(SLEW_BOUNDS[0]),
          "b": -np.inf}
_UPPER = {"g": np.inf, "tau": TAU_BOUNDS[1], "rho": RATIO_HIGH, "D": DEAD_TIME_BOUNDS[1], "log_slew": math.log(SLEW_BOUNDS[1]),
          "b": np.inf}


class _Model:
    """The response of one candidate on `s` as a function of its free parameters, the slew limit's input (a continuous
    ramp's knots, or a smoother's held ticks at `frequency` Hz and `phase` s) cached per A."""

    def __init__(self, model: str, s: Samples, frequency: float = SMOOTHING_FREQUENCY, phase: float = 0.0):
        self.names, self.s, self._knots = MODEL_PARAMETERS[model], s, {}
        self.smoother = (frequency, phase) if frequency > 0 else None

    def unit(self, q: dict) -> np.ndarray:
        """The unit-gain response at the samples."""
        log_slew = q.get("log_slew", math.inf)
        knots = None
        if math.isfinite(log_slew):
            if log_slew not in self._knots:
                if len(self._knots) > 4:
                    self._knots.clear()
                A = math.exp(log_slew)
                self._knots[log_slew] = smoothed(self.s.cmd_t, self.s.u, A, *self.smoother) if self.smoother else \
                    slew_limited(self.s.cmd_t, self.s.u, A)
            knots = self._knots[log_slew]
        rho = q.get("rho", 0.0)
        return plant_response(self.s.cmd_t, self.s.u, self.s.t, q["tau"], q["D"], rho * q["tau"],
                              math.exp(log_slew) if knots is not None else math.inf, knots, self.smoother)

    def q(self, p) -> dict:
        return dict(zip(self.names, (float(v) for v in p)))

    def residuals(self, p) -> np.ndarray:
        q = self.q(p)
        return q["g"] * self.unit(q) + q["b"] - self.s.y

    def jacobian(self, p) -> np.ndarray:
        q = self.q(p)
        x = self.unit(q)
        columns = []
        for name in self.names:
            if name == "g":
                columns.append(x)
            elif name == "b":
                columns.append(np.ones_like(x))
            else:
                h = _STEP[name] * max(1.0, abs(q[name]))
                columns.append(q["g"] * (self.unit({**q, name: q[name] + h}) - x) / h)
        return np.column_stack(columns)


def fit_model(model: str, start: PlantParameters, s: Samples, max_nfev: int = 60,
              frequency: float = SMOOTHING_FREQUENCY) -> PlantParameters:
    """The candidate `model` fitted to `s` from `start` (its absent parameters ignored; a smoother's phase kept).

    Parameters
    ----------
    model : str
        One of `PLANT_MODELS`.
    start : PlantParameters
        Where the fit starts.
    s : Samples
        The problem.
    max_nfev : int
        The largest number of residual evaluations.
    frequency : float
        The slew limit's smoother's rate, Hz (0: a continuous ramp).
    """
    if model == "first_order":
        g, tau, D, b = fit_first_order((start.g, start.tau, start.dead_time, start.bias), s)
        return PlantParameters(g, tau, 0.0, D, math.inf, b)
    m = _Model(model, s, frequency, start.phase)
    v = start.vector()
    p0 = [min(max(v[n], _LOWER[n]), _UPPER[n]) for n in m.names]
    result = _solve(m.residuals, m.jacobian, p0, [_LOWER[n] for n in m.names], [_UPPER[n] for n in m.names], max_nfev)
    return PlantParameters.of(m.q(result.x), start.phase)


def residuals(model: str, p: PlantParameters, s: Samples, frequency: float = SMOOTHING_FREQUENCY) -> np.ndarray:
    """Fitted minus measured at the samples, rad/s.

    Parameters
    ----------
    model : str
        One of `PLANT_MODELS`.
    p : PlantParameters
        The plant.
    s : Samples
        The problem.
    frequency : float
        The slew limit's smoother's rate, Hz (0: a continuous ramp).
    """
    m = _Model(model, s, frequency, p.phase)
    v = p.vector()
    return m.residuals([v[n] for n in m.names])


def jacobian(model: str, p: PlantParameters, s: Samples, frequency: float = SMOOTHING_FREQUENCY) -> tuple[np.ndarray, tuple]:
    """(J, the parameters' names) of the residuals at `p` (analytic for the first order, else forward differences).

    Parameters
    ----------
    model : str
        One of `PLANT_MODELS`.
    p : PlantParameters
        The plant.
    s : Samples
        The problem.
    frequency : float
        The slew limit's smoother's rate, Hz (0: a continuous ramp).
    """
    if model == "first_order":
        return _first_order_jacobian((p.g, p.tau, p.dead_time, p.bias), s)[1], MODEL_PARAMETERS[model]
    m = _Model(model, s, frequency, p.phase)
    v = p.vector()
    return m.jacobian([v[n] for n in m.names]), m.names


def _best_phase(model: str, p: PlantParameters, s: Samples, frequency: float) -> PlantParameters:
    """`p` with the smoother's phase of least residual on `PHASES` points of [0, 1/f), the other parameters kept."""
    if frequency <= 0 or not math.isfinite(p.slew):
        return p
    trials = [replace(p, phase=k / (PHASES * frequency)) for k in range(PHASES)]
    costs = [float(np.sum(residuals(model, q, s, frequency) ** 2)) for q in trials]
    return trials[int(np.argmin(costs))]


# ------------------------------------------------------------------------------------------ statistics
def autocorrelation(r: np.ndarray, segment: np.ndarray, lags: int) -> np.ndarray:
    """ρ_1..ρ_lags of `r` counting only pairs within one segment.

    Parameters
    ----------
    r : numpy.ndarray
        The residuals.
    segment : numpy.ndarray
        The window each belongs to.
    lags : int
        How many lags.
    """
    r = r - r.mean()
    var = float(r @ r)
    out = np.zeros(lags)
    if var <= 0:
        return out
    for k in range(1, min(lags, r.size - 1) + 1):
        same = segment[k:] == segment[:-k]
        out[k - 1] = float(np.sum((r[k:] * r[:-k])[same])) / var
    return out


def covariance(J: np.ndarray, r: np.ndarray, segment: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """Newey–West covariance of the parameters (module docstring, "Intervals"), its lag L and ρ_1..ρ_L of r.

    Parameters
    ----------
    J : numpy.ndarray
        The residuals' Jacobian (samples × parameters).
    r : numpy.ndarray
        The residuals.
    segment : numpy.ndarray
        The window of each sample (lags are taken within one).
    """
    n = r.size
    rule = int(math.floor(4.0 * (n / 100.0) ** (2.0 / 9.0)))
    rho = autocorrelation(r, segment, 400)
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


def ljung_box(r: np.ndarray, segment: np.ndarray, lags: int = LJUNG_BOX_LAGS) -> tuple[float, float]:
    """(Q, p-value) of Ljung and Box's statistic of `r` over `lags` lags (pairs within one segment).

    Parameters
    ----------
    r : numpy.ndarray
        The residuals.
    segment : numpy.ndarray
        The window each belongs to.
    lags : int
        h.
    """
    from scipy.special import chdtrc

    n = r.size
    rho = autocorrelation(r, segment, lags)
    k = np.arange(1, lags + 1)
    q = float(n * (n + 2) * np.sum(rho**2 / np.maximum(n - k, 1)))
    return q, float(chdtrc(lags, q))


# ------------------------------------------------------------------------------------------ which plant
def _start(model: str, fitted: dict, first: PlantParameters, slope: float) -> PlantParameters:
    """Where a richer candidate's fit starts: a second lag splits the first order's τ (τ_a = 0.3·τ/1.3, D shortened by half
    of it); a slew limit starts where the measured yaw acceleration saturates (`slope`/g); both from the two fits of one."""
    if model == "two_lags":
        return PlantParameters(first.g, first.tau / 1.3, 0.3 * first.tau / 1.3,
                               max(first.dead_time - 0.15 * first.tau, DEAD_TIME_BOUNDS[0]), math.inf, first.bias)
    if model == "slew_limited":
        A = min(max(slope / max(abs(first.g), 1e-3), 2 * SLEW_BOUNDS[0]), SLEW_BOUNDS[1] / 4)
        return PlantParameters(first.g, first.tau, 0.0, first.dead_time, A, first.bias)
    lags, slew = fitted["two_lags"], fitted["slew_limited"]
    return PlantParameters(lags.g, lags.tau, lags.actuator_lag, lags.dead_time, slew.slew, 0.5 * (lags.bias + slew.bias), slew.phase)


def candidates(s: Samples, first: PlantParameters, slope: float, frequency: float = SMOOTHING_FREQUENCY) -> tuple[CandidateFit, ...]:
    """Every candidate (`PLANT_MODELS`) fitted to the same samples `s` and scored; the smallest BIC selected.

    Parameters
    ----------
    s : Samples
        The samples every candidate is fitted to (a stretch of at most `SELECT_SAMPLES`).
    first : PlantParameters
        The first-order plant fitted to the whole log (the start of every fit).
    slope : float
        The largest measured yaw acceleration (rad/s², its 99th percentile): where the slew limit's fit starts.
    frequency : float
        The slew limit's smoother's rate, Hz (`SMOOTHING_FREQUENCY`; 0: a continuous ramp).
    """
    n = int(s.t.size)
    fits, fitted = [], {}
    for model in PLANT_MODELS:
        p = fit_model(model, first if model == "first_order" else _start(model, fitted, first, slope), s, frequency=frequency)
        if "log_slew" in MODEL_PARAMETERS[model] and frequency > 0:  # the smoother's phase, then the fit again there
            p = fit_model(model, _best_phase(model, p, s, frequency), s, frequency=frequency)
        fitted[model] = p
        r = residuals(model, p, s, frequency)
        ssr = float(r @ r)
        count = len(MODEL_PARAMETERS[model])
        log_l = n * math.log(max(ssr, 1e-300) / n)
        q, pq = ljung_box(r, s.segment)
        fits.append((model, p, count, ssr, log_l + 2 * count, log_l + count * math.log(n), q, pq))
    chosen = min(range(len(fits)), key=lambda i: fits[i][5])
    return tuple(CandidateFit(m, p, n, c, ssr, aic, bic, q, pq, i == chosen)
                 for i, (m, p, c, ssr, aic, bic, q, pq) in enumerate(fits))
