"""Oscillation metrics of a simulated run (docs/simulator.md, measuring oscillation).

The input is the lateral offset x_k of the robot at the sample instants
t_k = kT inside the measurement window. Two estimators:

**Peaks** (robust; used for every run). Turning points of x_k are
found with a hysteresis of 1 % of the window's range (so cell-quantization
ripple does not count as an oscillation); each swing between consecutive
turning points gives a half peak-to-peak amplitude a_i at the swing's mid
time. Half peak-to-peak amplitudes are the local maxima of |x − x_eq| when
the equilibrium x_eq is known, and stay right when it is not (a grid
corridor's centre, a wall's d0 after a disturbance). σ is the slope of
ln a_i against time (least squares; the first swing, which carries the
transient from the start or the disturbance, is left out when three or more
remain), ω = π / (mean time between turning points). Both carry the
quantization of turning points to the sample grid (|error| ≲ ωT/2 in phase),
and σ is biased when the oscillation dies out within a few swings (the
faster modes are still present: −0.68 for a true −0.77 1/s).

**Linear prediction** (exact for a linear sampled loop). A linear
time-invariant sampled loop of order p makes x_k obey
x_k = a_1 x_(k−1) + … + a_p x_(k−p) + b exactly (b: the equilibrium offset),
and the roots of z^p − a_1 z^(p−1) − … − a_p are the loop's poles z. The
coefficients are fitted by least squares on the whole window; if the fit
leaves a relative residual below `LINEAR_RESIDUAL` (the run stayed linear),
agrees with the peaks' σ and ω where those exist (`PEAKS_AGREEMENT`: a run
that grew out of the linear regime can leave a small residual and a wrong
root — a wall run at α = 30° grown to 1e-3 m fitted σ = 0.61 against the true
0.37 at a residual of 5e-7), and describes either a decay or
an oscillation seen in the data (>= 2 turning points: a smooth monotone drift
is fitted well by a root near z = 1 and says nothing), the dominant root gives
σ = ln|z|/T and ω = arg z / T — equal to the `sampled` model's dominant pole
to round-off, which is what the validation tests compare. Otherwise (grid
quantization, large amplitudes, saturation) the peaks estimate is reported.

Classification: a **limit cycle** is ≥ 4 swings in the second half of the
window whose amplitudes differ by less than 30 % and whose fitted trend
changes the amplitude by less than 10 % across that half (in a run that did
not stay linear; a slow decay, σ = −0.02 1/s over 15 s, is not one); **oscillating** = a limit cycle, or σ > 0 with ω > 0 (a growing
oscillation); **stable** (the run *settled*) = no collision, not oscillating,
and σ < 0 when σ is defined — not the linear-stability verdict (the sign of σ)
that is compared with the models (`pfm_stability.sim.verdict`). When too few turning points exist and the fit is rejected, σ and ω
are ``None`` with a `reason`, never NaN.

The answer is explicit where nothing was measured:

* a **collision** (on the path between samples too, `pfm_stability.sim.contact`)
  — not stable, whatever the offset did before;
* fewer than 8 samples in the measurement window (a run that ended, or left
  the window, almost at once: e.g. T = 100 s) — not stable: nothing shows that
  it settled (σ None, `reason` says why);
* σ undefined otherwise (no oscillation and a rejected fit: a constant
  offset, a monotone decay the grid's ripple keeps from fitting, or a drift)
  — stable only when the offset is settling: its range over the second half
  of the window at most `SETTLING` times its range over the first half (a
  constant offset: 0 against 0; a decay e^(σt): e^(σD/2)); a robot drifting
  away at a steady or growing rate is not stable.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

__all__ = [
    "OscillationMetrics", "oscillation_metrics", "linear_prediction", "turning_points", "LINEAR_RESIDUAL", "PEAKS_AGREEMENT",
    "HYSTERESIS", "SETTLING",
]

LINEAR_RESIDUAL = 1e-6
"""Largest relative residual of the linear-prediction fit for the run to count as linear."""

PEAKS_AGREEMENT = (0.25, 0.02)
"""The fit's σ must lie within 25 % + 0.02 1/s of the peaks' σ (when defined) to be used.

Wide enough for the peaks' own bias on oscillations that die out within a
few swings (−0.68 against the true −0.77 1/s for a CARMEL corridor at
L = 1.2 m), narrow enough to reject a fit that left the linear regime."""

HYSTERESIS = 0.01
"""Turning-point hysteresis as a fraction of the window's range of x."""

SETTLING = 0.9
"""A run without a measurable σ is settling when its offset moves over the second half of the window at most this
fraction of what it moved over the first half (module docstring): a decay qualifies (measured 0.0002–0.27 for slow
grid corridors, V = 0.1–0.3 m/s over 20 s), a steady drift (1) or a growing one (> 1) does not."""

_MIN_SAMPLES = 8


@dataclass(frozen=True)
class OscillationMetrics:
    """Oscillation metrics of one run (docs/simulator.md, measuring oscillation).

    Attributes
    ----------
    growth_rate : float or None
        σ, 1/s (> 0: growing).
    angular_frequency : float or None
        ω, rad/s.
    amplitude : float or None
        Half peak-to-peak amplitude of the limit cycle, m (None: no limit cycle).
    limit_cycle : bool
    oscillating : bool
        A growing oscillation or a limit cycle.
    stable : bool
        The run settled: no collision, not oscillating, σ < 0 when defined,
        settling when not; False when the window holds too few samples to say
        (module docstring). (The linear-stability verdict the loop models
        predict is the sign of σ alone: `pfm_stability.sim.verdict.simulated_verdict`.)
    method : {"linear_prediction", "peaks", "none"}
        Estimator that produced σ and ω.
    turning_points : int
        Turning points found in the window.
    peaks_growth_rate, peaks_angular_frequency : float or None
        The peaks estimate (reported even when linear prediction is used).
    fit_residual : float or None
        Relative residual of the linear-prediction fit.
    time_to_collision : float or None
        Time of the collision, s from the start of the run.
    window : (float, float) or None
        First and last sample time used, s.
    reason : str or None
        Why σ or ω is undefined.
    """

    growth_rate: float | None
    angular_frequency: float | None
    amplitude: float | None
    limit_cycle: bool
    oscillating: bool
    stable: bool
    method: str
    turning_points: int
    peaks_growth_rate: float | None = None
    peaks_angular_frequency: float | None = None
    fit_residual: float | None = None
    time_to_collision: float | None = None
    window: tuple | None = None
    reason: str | None = None

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        out = asdict(self)
        out["window"] = list(self.window) if self.window is not None else None
        return out


def turning_points(x, hysteresis: float) -> np.ndarray:
    """Indices of alternating maxima and minima of x, each swing exceeding `hysteresis`.

    A zigzag filter: a maximum is confirmed once x has fallen `hysteresis`
    below it, a minimum once x has risen that much above it. The first sample
    is never a turning point.

    Parameters
    ----------
    x : ndarray
        The signal (e.g. the lateral offset, m).
    hysteresis : float
        Smallest swing that counts, in x's units.
    """
    x = np.asarray(x, dtype=float)
    points = []
    direction = 0  # 0: undecided, +1: rising (next point a maximum), −1: falling
    i_max = i_min = 0
    for i in range(1, x.size):
        xi = x[i]
        if xi > x[i_max]:
            i_max = i
        if xi < x[i_min]:
            i_min = i
        if direction >= 0 and x[i_max] - xi > hysteresis:
            if i_max > 0:
                points.append(i_max)
            direction, i_min = -1, i
        elif direction <= 0 and xi - x[i_min] > hysteresis:
            if i_min > 0:
                points.append(i_min)
            direction, i_max = 1, i
    return np.array(points, dtype=int)


def _peaks(t, x, extrema):
    """(σ, ω, swing amplitudes, swing times) from turning points; σ/ω None when too few."""
    tx, xx = t[extrema], x[extrema]
    amplitudes = np.abs(np.diff(xx)) / 2
    mid = (tx[1:] + tx[:-1]) / 2
    omega = math.pi / float(np.mean(np.diff(tx))) if extrema.size >= 2 else None
    sigma = None
    use = slice(1, None) if amplitudes.size >= 3 else slice(None)
    if amplitudes[use].size >= 2:
        sigma = float(np.polyfit(mid[use], np.log(amplitudes[use]), 1)[0])
    return sigma, omega, amplitudes, mid


def linear_prediction(x, order: int, T: float):
    """Dominant root of a linear-prediction (Prony-type) fit to a sampled record.

    Fits x_k = Σ a_i x_(k−i) + b (least squares, `order` lags plus an offset)
    and takes the recurrence's root of largest modulus z (the one with
    positive imaginary part of a pair).

    Parameters
    ----------
    x : ndarray
        Samples taken every `T` seconds; at least 4·(order + 1) of them.
    order : int
        Number of lags (4: an oscillating pair, one real mode, margin).
    T : float
        Sampling period, s.

    Returns
    -------
    tuple of (float, float, float) or None
        (σ = ln|z|/T in 1/s, ω = |arg z|/T in rad/s, the fit's relative
        residual), or None when the record is too short, constant or its
        dominant root is 0.
    """
    n = x.size
    if n < 4 * (order + 1):
        return None
    scale = np.std(x)
    if not scale > 0:
        return None
    y = (x - np.mean(x)) / scale
    A = np.column_stack([y[order - 1 - i : n - 1 - i] for i in range(order)] + [np.ones(n - order)])
    b = y[order:]
    coef = np.linalg.lstsq(A, b, rcond=None)[0]
    residual = float(np.linalg.norm(b - A @ coef) / max(np.linalg.norm(b), np.finfo(float).tiny))
    roots = np.roots(np.concatenate([[1.0], -coef[:order]]))
    radius = np.abs(roots)
    top = roots[radius >= radius.max() * (1 - 1e-9)]
    z = top[np.argmax(top.imag)]
    if z == 0:
        return None
    return math.log(abs(z)) / T, abs(math.atan2(z.imag, z.real)) / T, residual


def _limit_cycle(t, amplitudes, mid):
    """(True, mean amplitude) if the swings of the window's second half neither grow nor decay."""
    late = mid >= (t[0] + t[-1]) / 2
    a, m = amplitudes[late], mid[late]
    if a.size < 4 or a.max() >= 1.3 * a.min():
        return False, None
    trend = np.polyfit(m, np.log(a), 1)[0] * (m[-1] - m[0])
    if abs(trend) >= math.log(1.1):
        return False, None
    return True, float(np.mean(a))


def oscillation_metrics(t, x, T: float, *, order: int = 4, collision_time: float | None = None) -> OscillationMetrics:
    """Growth rate, frequency, limit cycle and verdict of a sampled lateral offset (docs/simulator.md).

    Parameters
    ----------
    t : array_like
        Sample times, s (uniform step T).
    x : array_like
        Lateral offset at those times, m.
    T : float
        Sampling period, s.
    order : int
        Order p of the loop (the `sampled` model's state dimension:
        (τ > 0) + 2 + compute_delay) for the linear-prediction fit.
    collision_time : float, optional
        Time of a collision, s (makes the run unstable).

    Returns
    -------
    OscillationMetrics
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    collided = collision_time is not None
    if not np.all(np.isfinite(x)):
        raise FloatingPointError("lateral offset has non-finite samples")
    base = dict(time_to_collision=collision_time, window=(float(t[0]), float(t[-1])) if t.size else None)
    if t.size < _MIN_SAMPLES:  # nothing measured: not "stable" (module docstring)
        return OscillationMetrics(
            None, None, None, False, False, False, "none", 0,
            reason=f"fewer than {_MIN_SAMPLES} samples in the measurement window ({t.size}): not measurable", **base,
        )
    span = float(np.max(x) - np.min(x))
    extrema = turning_points(x, HYSTERESIS * span) if span > 0 else np.array([], dtype=int)
    sigma_p = omega_p = None
    amplitudes = mid = np.array([])
    if extrema.size >= 1:
        sigma_p, omega_p, amplitudes, mid = _peaks(t, x, extrema)
    fit = linear_prediction(x, order, T)
    residual = fit[2] if fit is not None else None
    rel, floor = PEAKS_AGREEMENT
    linear = (
        fit is not None
        and fit[2] < LINEAR_RESIDUAL
        and (extrema.size >= 2 or fit[0] < 0)
        and (omega_p is None or abs(fit[1] - omega_p) <= 0.25 * omega_p)
        and (sigma_p is None or abs(fit[0] - sigma_p) <= rel * abs(sigma_p) + floor)
    )
    limit_cycle, amplitude = (False, None) if linear or amplitudes.size == 0 else _limit_cycle(t, amplitudes, mid)
    if linear:
        sigma, omega, method, reason = fit[0], fit[1], "linear_prediction", None
    elif sigma_p is not None:
        sigma, omega, method, reason = sigma_p, omega_p, "peaks", None
    else:
        sigma, omega, method = None, omega_p, "none"
        reason = f"{extrema.size} turning point(s) in the window and the run is not linear (fit residual {residual})"
    oscillating = limit_cycle or (sigma is not None and sigma > 0 and omega is not None and omega > 0)
    if sigma is None:  # stable only when settling: the second half of the window moves less than the first
        late = t >= (t[0] + t[-1]) / 2
        moved = [float(np.ptp(x[~late])) if np.any(~late) else 0.0, float(np.ptp(x[late]))]
        settling = moved[1] <= SETTLING * moved[0]
        reason += f"; the offset {'is settling' if settling else 'is not settling'} (it moved {moved[0]:.3g} m, then {moved[1]:.3g} m)"
    stable = not collided and not oscillating and (sigma < 0 if sigma is not None else settling)
    return OscillationMetrics(
        growth_rate=sigma,
        angular_frequency=omega,
        amplitude=amplitude,
        limit_cycle=limit_cycle,
        oscillating=oscillating,
        stable=stable,
        method=method,
        turning_points=int(extrema.size),
        peaks_growth_rate=sigma_p,
        peaks_angular_frequency=omega_p,
        fit_residual=residual,
        reason=reason,
        **base,
    )
