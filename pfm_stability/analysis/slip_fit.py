"""The base's slide: the lag τ_s of its course behind its heading, measured from its pose (docs/diagnose.md, "The slide").

Model
-----
A base that slides sideways in a turn moves along its course χ, which follows its heading ψ through a first-order lag
(`parameters.Robot.slip_lag`): τ_s·χ̇ + χ = ψ. Its slip angle β = χ − ψ obeys τ_s·β̇ + β = −τ_s·r (r = ψ̇ the yaw rate),
so β = −τ_s·r/(τ_s·s + 1), and the lateral velocity in the base's frame is v_lat = V·sin β ≈ −V·τ_s·r (V the forward
speed). Signs are ROS's: x, y in the pose's (world, odometry) frame, the yaw ψ from +x towards +y, r counter-clockwise
positive, v_lat positive to the base's left; in a left turn (r > 0) a sliding base moves to the right of where it points.

The estimator
-------------
From the pose samples (t_i, x_i, y_i, ψ_i), ψ unwrapped, each interior sample gives the chord from sample i − 1 to
i + 1 (a central difference): the world velocity (Δx, Δy)/Δt, rotated into the base's frame by the mean ψ̄ of the
chord's two ends, gives V and v_lat; r = Δψ/Δt. On a steady arc the chord points exactly along the mean of its ends'
courses, whatever Δt (a jittered pose source), so a steady turn gives no spurious v_lat; a one-sided difference rotated
by one end's heading would be off by r·Δt/2 — 6 mrad at 0.3 rad/s and 50 Hz, more than the slide's own τ_s·r ≈ 3 mrad.
The heading's own differences are the regressor's r, not a logged yaw rate: they are the same body's motion at the same
instants (wheel odometry's yaw rate is not the body's on a base that skids; a gyro's is, but on its own clock).

Least squares then fits v_lat = τ_s·(−V·r_τ) + δ·(−V) (r_τ: r through the slide's lag, below) on the samples where
the base moves forward (V ≥ `MIN_SPEED`): δ absorbs a pose whose heading is offset from the base's direction of
travel (a motion-capture body defined a little askew); it is separable from the slide because r changes sign while V does not. Its 95 % interval is value ± 1.96·σ
from the Newey–West (Bartlett) covariance of `plant_fit.covariance`, with lags within a run of consecutive chords: a
central difference makes the noise of neighbouring chords correlated (a position's error enters the chords on both
sides of it) and the HAC estimate accounts for it, as it does for the fit's residual dynamics. With white position noise
it is conservative: the chords' errors telescope (their sum over a run is the run's end errors), which the Bartlett
weights over L lags see only in part, so the interval is several times wider than the scatter (0.1 mm of noise at
50 Hz: ±0.55 ms where the errors spread by ±0.05 ms). A localisation's noise, correlated over many samples, does not
cancel so, and there the interval is the right width.

Is the small-τ_s approximation adequate?
----------------------------------------
v_lat = −V·τ_s·r ignores the lag's own lag, 1/(τ_s·s + 1). A regression on −V·r recovers τ_s·⟨1/(1 + ω²τ_s²)⟩ (the mean
over the yaw rate's power spectrum), an underestimate by a fraction ⟨ω²τ_s²/(1 + ω²τ_s²)⟩ ≤ τ_s²·⟨ṙ²⟩/⟨r²⟩ (Parseval):
small while τ_s·ω ≪ 1 at the yaw rate's frequencies (τ_s = 10 ms and yaw-rate content up to 2 Hz: below 0.2 %), but
2.5 % (bound 3.4 %) for τ_s = 0.1 s behind a yaw rate that steps through a 0.2-s lag. So the regressor is r passed
through the lag at the estimate itself (`FIXED_POINT` passes from r: each shrinks the error by about (ωτ_s)²; exact for r linear between
the chords), which removes the bias whatever τ_s; `SlipFit.lag_bias` reports the bound, τ̂²·⟨ṙ²⟩/⟨r²⟩ measured from the
data: how much the lag's own lag mattered in this log. V·sin β ≈ V·β is off by β²/6 (10⁻⁵ at β = 10 mrad).

What the pose must be
---------------------
Wheel odometry cannot show a slide: it integrates the wheels' speeds along its own heading, assuming no slip, so its
lateral velocity is zero by construction and the fit would report τ_s ≈ 0 with a tight, meaningless interval. The pose
must come from something that sees the base move: a localisation against the map, a motion-capture system, a
simulator's ground truth. It must also be the pose of the point the controller steers (the base's origin): a point d
ahead of the rotation centre moves sideways at d·r too, which at one speed reads as τ_s − d/V.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_number
from .plant_fit import Z95, Estimate, covariance

__all__ = ["SlipFit", "fit_slip_lag", "MIN_SPEED", "MIN_TURN", "MIN_SAMPLES", "MAX_SPAN", "FIXED_POINT"]

MIN_SPEED = 0.1
"""The forward speed (m/s) above which a sample is used. Slower, the base is starting, stopping, reversing or turning in
place: its lateral motion is then the scrub of its wheels and the lever arm of the pose's point (d·r), which the lag
model does not describe, and v_lat ∝ V carries no information on τ_s while the pose's noise stays."""
MIN_TURN = 0.005
"""The least standard deviation of the yaw rate (rad/s, 0.3°/s) over the moving samples: a log that drives straight or on
one circle is refused, since the slide (∝ r) cannot be told from a heading offset of the pose (∝ V) there. Above it the
interval says how well the turns determine τ_s (robot C's ±0.1-rad/s steps turn it by 0.019 rad/s: τ_s to ±0.02 ms
from its exact pose)."""
MIN_SAMPLES = 50
"""The fewest moving samples fitted (as `identification.fit_plant` asks of the rate): fewer give no stable interval."""
FIXED_POINT = 6
"""Passes of the lag's own lag: each shrinks the error by about (ωτ_s)², so 6 are exact to rounding for τ_s·ω < 0.5."""
MAX_SPAN = 3.0
"""A chord longer than this many median chords spans a gap in the pose (dropped messages): not used."""


@dataclass(frozen=True)
class SlipFit:
    """The slide measured from a pose (module docstring).

    Attributes
    ----------
    slip_lag : Estimate
        τ_s, s, and its 95 % interval.
    misalignment : Estimate
        δ, rad: the pose's heading minus the base's direction of travel on a straight line, and its 95 % interval.
    samples : int
        Chords fitted (moving, no gap).
    speed : float
        Their median forward speed V, m/s.
    turn : float
        The standard deviation of their yaw rate r, rad/s.
    r2 : float
        The fraction of v_lat's variance the fit explains, dimensionless.
    hac_lags : int
        L of the interval's covariance.
    lag_bias : float
        τ_s²·⟨ṙ²⟩/⟨r²⟩, dimensionless: the bound on the relative underestimate a regression ignoring the lag's own lag
        would have made here (the fit corrects for it; module docstring).
    """

    slip_lag: Estimate
    misalignment: Estimate
    samples: int
    speed: float
    turn: float
    r2: float
    hac_lags: int
    lag_bias: float

    def to_dict(self) -> dict:
        """The ``slip`` of ``identify``'s JSON output, but its ``reason``."""
        return {"slip_lag": self.slip_lag.to_dict(), "misalignment": self.misalignment.to_dict(), "samples": self.samples,
                "speed": json_number(self.speed), "turn": json_number(self.turn), "r2": json_number(self.r2),
                "hac_lags": self.hac_lags, "lag_bias": json_number(self.lag_bias)}


@dataclass(frozen=True)
class _Chords:
    """Each interior sample's central difference: its time (s), V and v_lat (m/s), r (rad/s), and whether it is usable
    (its chord has a positive span of at most `MAX_SPAN` median spans)."""

    t: np.ndarray
    V: np.ndarray
    lateral: np.ndarray
    r: np.ndarray
    usable: np.ndarray


def _checked(t, x, y, yaw) -> tuple[np.ndarray, ...]:
    """The four series as 1-d float arrays of one length, all finite, t non-decreasing; else ValueError."""
    arrays = []
    for name, a in (("t", t), ("x", x), ("y", y), ("yaw", yaw)):
        a = np.asarray(a, dtype=float)
        if a.ndim != 1:
            raise ValueError(f"the pose's {name} must be one-dimensional; got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"the pose's {name} holds a value that is not a finite number (at sample "
                             f"{int(np.flatnonzero(~np.isfinite(a))[0])})")
        arrays.append(a)
    if len({a.size for a in arrays}) != 1:
        raise ValueError(f"the pose's t, x, y and yaw must have one length; got {', '.join(str(a.size) for a in arrays)}")
    if np.any(np.diff(arrays[0]) < 0):
        raise ValueError("the pose's times go backwards")
    return tuple(arrays)


def _chords(t: np.ndarray, x: np.ndarray, y: np.ndarray, yaw: np.ndarray) -> _Chords:
    """The central differences of the pose, rotated into the base's frame by the mean heading of each chord's ends."""
    psi = np.unwrap(yaw)
    span = t[2:] - t[:-2]
    typical = float(np.median(span[span > 0])) if np.any(span > 0) else 0.0
    usable = (span > 0) & (span <= MAX_SPAN * typical)
    safe = np.where(usable, span, 1.0)
    vx, vy = (x[2:] - x[:-2]) / safe, (y[2:] - y[:-2]) / safe
    mean = 0.5 * (psi[2:] + psi[:-2])
    c, s = np.cos(mean), np.sin(mean)
    return _Chords(0.5 * (t[2:] + t[:-2]), vx * c + vy * s, -vx * s + vy * c, (psi[2:] - psi[:-2]) / safe, usable)


def _lag_bias(tau: float, t: np.ndarray, r: np.ndarray, segment: np.ndarray) -> float:
    """τ²·⟨ṙ²⟩/⟨r²⟩ with ṙ from consecutive chords of one run (module docstring)."""
    same = segment[1:] == segment[:-1]
    dt = np.diff(t)
    ok = same & (dt > 0)
    if not np.any(ok) or not np.any(r):
        return 0.0
    rdot = np.diff(r)[ok] / dt[ok]
    return float(tau * tau * np.mean(rdot**2) / np.mean(r**2))


def _lagged(t: np.ndarray, r: np.ndarray, segment: np.ndarray, tau: float) -> np.ndarray:
    """r through the lag 1/(τs + 1), exact for r linear between the chords' times; each run starts in steady state."""
    if tau <= 0:
        return r
    out = np.empty_like(r)
    t_, r_, seg = t.tolist(), r.tolist(), segment.tolist()
    z = r_[0]
    for i, value in enumerate(r_):
        if i and seg[i] == seg[i - 1]:
            h = t_[i] - t_[i - 1]
            slope = (value - r_[i - 1]) / h if h > 0 else 0.0
            z = value - tau * slope + (z - r_[i - 1] + tau * slope) * math.exp(-h / tau)
        else:
            z = value
        out[i] = z
    return out


def _regression(V, lateral, r, t, segment) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(τ_s, δ, the regressors, the residuals) of v_lat = τ_s·(−V·r_τ) + δ·(−V), r_τ the yaw rate through the lag at
    the estimate itself: `FIXED_POINT` passes from r_0 = r (module docstring, "Is the small-τ_s approximation adequate?")."""
    tau = 0.0
    for _ in range(FIXED_POINT):
        X = np.column_stack([-V * _lagged(t, r, segment, tau), -V])
        coef, *_ = np.linalg.lstsq(X, lateral, rcond=None)
        done = abs(float(coef[0]) - tau) <= 1e-7
        tau = float(coef[0])
        if done:
            break
    return tau, float(coef[1]), X, X @ coef - lateral


def fit_slip_lag(t, x, y, yaw) -> tuple[SlipFit | None, str | None]:
    """Measure the slide's lag τ_s from the base's pose (module docstring).

    Parameters
    ----------
    t : array_like
        The pose's times, s, non-decreasing.
    x, y : array_like
        The base's position, m, in a frame that sees it move (not wheel odometry's: module docstring).
    yaw : array_like
        Its heading, rad from +x towards +y (ROS), wrapped or not.

    Returns
    -------
    tuple
        (the fit, None), or (None, a one-line reason: too few samples, the base not moving, too little turning).

    Raises
    ------
    ValueError
        Arrays of different lengths or not one-dimensional, a value that is not a finite number, times that go backwards.
    """
    t, x, y, yaw = _checked(t, x, y, yaw)
    if t.size < MIN_SAMPLES + 2:
        return None, (f"the pose has only {t.size} samples (at least {MIN_SAMPLES + 2} are needed): the log is too short "
                      "or the pose too sparse")
    ch = _chords(t, x, y, yaw)
    moving = ch.usable & (ch.V >= MIN_SPEED)
    count = int(np.count_nonzero(moving))
    if count == 0:
        fastest = float(np.max(np.abs(ch.V[ch.usable]))) if np.any(ch.usable) else 0.0
        return None, (f"the robot did not move: its speed from the pose never reaches {MIN_SPEED:g} m/s (at most "
                      f"{fastest:.3g} m/s); a slide shows only while the base drives")
    if count < MIN_SAMPLES:
        return None, (f"only {count} pose samples while the robot moves faster than {MIN_SPEED:g} m/s (at least "
                      f"{MIN_SAMPLES} are needed): the log is too short")
    V, lateral, r, tc = ch.V[moving], ch.lateral[moving], ch.r[moving], ch.t[moving]
    turn = float(np.std(r))
    if turn < MIN_TURN:
        return None, (f"too little turning: the yaw rate varies by {turn:.3g} rad/s (standard deviation; at least "
                      f"{MIN_TURN:g} needed): a slide, sideways in proportion to the yaw rate, cannot be told from a "
                      "heading offset of the pose; record turns both ways")
    index = np.flatnonzero(moving)
    segment = np.concatenate([[0], np.cumsum(np.diff(index) != 1)])
    tau, delta, X, residual = _regression(V, lateral, r, tc, segment)
    cov, L, _ = covariance(X, residual, segment)
    half = Z95 * np.sqrt(np.maximum(np.diag(cov), 0.0))
    sst = float(np.sum((lateral - lateral.mean()) ** 2))
    return SlipFit(
        slip_lag=Estimate(tau, tau - float(half[0]), tau + float(half[0])),
        misalignment=Estimate(delta, delta - float(half[1]), delta + float(half[1])),
        samples=count, speed=float(np.median(V)), turn=turn,
        r2=1.0 - float(residual @ residual) / sst if sst > 0 else math.nan, hac_lags=int(L),
        lag_bias=_lag_bias(tau, tc, r, segment)), None
