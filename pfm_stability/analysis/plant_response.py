"""The exact response of the steering plant to a log's commands: one lag, two lags, a slew limit (docs/diagnose.md, "Model").

The plant is g·e^(−sD)/((τs + 1)(τ_a·s + 1)) behind an optional slew limit A on the commanded yaw rate (a velocity
smoother's angular acceleration limit): the command u is held between its stamps (zero-order hold), its slew-limited
version r follows it at |dr/dt| ≤ A, and r, delayed by D, passes the lags. Every response here is exact between the
commands; none integrates numerically.

**One lag, held commands.** Between two held commands the lag's response is exact: with the state X_j when command j
takes effect (at its stamp c_j + D),

    X_(j+1) = u_j + (X_j − u_j)·exp(−(c_(j+1) − c_j)/τ),       x(t) = u_j + (X_j − u_j)·exp(−(t − c_j − D)/τ)

— an affine recursion in j, computed for every command at once by a doubling scan (`affine_scan`, log₂ m passes
over the arrays), and independent of D: D only moves where each sample falls. Its sensitivities to τ (a second
scan) and to D (−dx/dt) are exact too (`lag_response`).

**The slew limit.** r starts at u_0 and, over each command's interval, ramps towards u_j at ±A until it reaches it
(`slew_limited`: r_(j+1) = r_j + clip(u_j − r_j, ±A·(c_(j+1) − c_j)), a recursion a clip makes sequential; one pass
over the commands). r is continuous and piecewise linear, with a knot at each command and where each ramp ends.

**A smoother on its own timer.** Nav2's velocity smoother does not ramp continuously: a timer every 1/f reads the newest
command and moves its held output towards it by at most A/f (`smoothed`). Its output is a sequence of held commands
at its ticks φ + i/f, and the lags' response to it is the held commands' (above). A small command then waits for the
next tick (`mean_wait`: h/2 on average when the commands' clock is independent of the smoother's).

**One lag, piecewise-linear input.** Over a segment of slope m from knot (s_k, v_k) the lag follows
x(s_k + θ) = v_k + m(θ − τ) + (x_k − v_k + mτ)·e^(−θ/τ): again an affine recursion over the knots (`ramp_lag`).

**Two lags** by partial fractions: 1/((τs + 1)(τ_a·s + 1)) = (τ/(τs + 1) − τ_a/(τ_a·s + 1))/(τ − τ_a), so
x₂ = (τ·x_τ − τ_a·x_(τ_a))/(τ − τ_a) from two one-lag responses to the same input, both starting at rest
(`plant_response`; τ_a < τ, the faster lag the actuator's).
"""

from __future__ import annotations

import math

import numpy as np

_TINY = 1e-200
"""Magnitudes below this are 0 in `affine_scan` (a state decaying over many commands of a short lag would become
subnormal)."""
_FLOOR = -60.0
"""Decay exponents −θ/τ below this are clamped (e^(−60) ≈ 1e-26: nothing at double precision; subnormal numbers
from e^(−θ/τ) of a short lag make the arithmetic a hundred times slower)."""


def _decay(x) -> np.ndarray:
    """e^(x) for x ≤ 0, with x clamped at `_FLOOR`."""
    return np.exp(np.maximum(x, _FLOOR))


__all__ = ["affine_scan", "lag_response", "lag_states", "lag_at", "slew_limited", "smoothed", "mean_wait", "ramp_lag",
           "plant_response"]


def affine_scan(a: np.ndarray, b: np.ndarray, x0: float) -> np.ndarray:
    """X with X_0 = x0 and X_(k+1) = a_k·X_k + b_k (length len(a) + 1), by doubling: log₂ n vector passes.

    Parameters
    ----------
    a, b : numpy.ndarray
        The recursion's coefficients, one per step.
    x0 : float
        The first value.
    """
    A, B = a.astype(float).copy(), b.astype(float).copy()
    shift = 1
    while shift < A.size:
        B[shift:] = A[shift:] * B[:-shift] + B[shift:]
        A[shift:] = A[shift:] * A[:-shift]
        A[A < _TINY] = 0.0  # no subnormal numbers (a hundred times slower arithmetic; they are 0 to double precision)
        B[np.abs(B) < _TINY] = 0.0
        shift *= 2
    out = np.concatenate([[x0], A * x0 + B])
    out[np.abs(out) < _TINY] = 0.0
    return out


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
    a, X = lag_states(dt, u, tau)
    x, j, before, elapsed, e = lag_at(cmd_t, u, X, t, tau, dead_time)
    if not derivatives:
        return x
    gap = X[j] - u[j]
    dX = affine_scan(a, (X[:-1] - u[:-1]) * a * dt / tau**2, 0.0)
    dx_dtau = np.where(before, 0.0, dX[j] * e + gap * e * elapsed / tau**2)
    dx_dD = np.where(before, 0.0, (x - u[j]) / tau)
    return x, dx_dtau, dx_dD


def lag_states(dt: np.ndarray, u: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """(exp(−Δc_j/τ), X_j): the lag's state when each held command takes effect (module docstring), unit gain.

    Parameters
    ----------
    dt : numpy.ndarray
        The intervals between the commands (s).
    u : numpy.ndarray
        The commands.
    tau : float
        The lag (s), > 0.
    """
    a = _decay(-dt / tau)
    return a, affine_scan(a, (1.0 - a) * u[:-1], u[0])


def lag_at(cmd_t, u, X, t, tau: float, dead_time: float):
    """(x, j, before, elapsed, e) at `t`: the response, the command in effect, t before the first, time since it, e^(−elapsed/τ).

    Parameters
    ----------
    cmd_t, u : numpy.ndarray
        The commands' times (s) and values.
    X : numpy.ndarray
        The lag's states when each takes effect (`lag_states`).
    t : numpy.ndarray
        Where the response is wanted (s).
    tau, dead_time : float
        The lag and the delay (s).
    """
    j = np.searchsorted(cmd_t + dead_time, t, side="right") - 1
    before = j < 0
    j = np.maximum(j, 0)
    elapsed = np.where(before, 0.0, t - (cmd_t[j] + dead_time))
    e = _decay(-elapsed / tau)
    return u[j] + (X[j] - u[j]) * e, j, before, elapsed, e


def slew_limited(cmd_t: np.ndarray, u: np.ndarray, limit: float) -> tuple[np.ndarray, np.ndarray]:
    """The knots (times s, values) of the held command slew-limited to ±`limit` (module docstring): r starts at u[0].

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commands (rad/s).
    limit : float
        A, the largest |dr/dt| (rad/s²), > 0.

    Returns
    -------
    tuple of numpy.ndarray
        Knot times (non-decreasing; at each command, and where a ramp reaches its command) and r there; r is linear
        between knots and constant after the last.
    """
    c, v = cmd_t.tolist(), u.tolist()
    times, values = [c[0]], [v[0]]
    r = v[0]
    for j in range(len(c) - 1):
        gap = v[j] - r
        reach = abs(gap) * (1.0 / limit)
        span = c[j + 1] - c[j]
        if reach <= span:
            if reach > 0.0:
                times.append(c[j] + reach)
                values.append(v[j])
            r = v[j]
        else:
            r += limit * span if gap > 0 else -limit * span
        times.append(c[j + 1])
        values.append(r)
    gap = v[-1] - r
    if gap != 0.0:  # the last command's ramp
        times.append(c[-1] + abs(gap) / limit)
        values.append(v[-1])
    return np.asarray(times), np.asarray(values)


def smoothed(cmd_t: np.ndarray, u: np.ndarray, limit: float, frequency: float, phase: float) -> tuple[np.ndarray, np.ndarray]:
    """The held output (tick times s, values) of a velocity smoother on its own timer, as Nav2's computes it (module
    docstring): at each tick φ + i/f it moves its last output towards the newest command by at most A/f.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commands (rad/s); the output starts at u[0].
    limit : float
        A, rad/s², > 0.
    frequency : float
        f, Hz, > 0.
    phase : float
        φ, s: the first tick at or after cmd_t[0] is cmd_t[0] + (φ − cmd_t[0]) mod (1/f).

    Returns
    -------
    tuple of numpy.ndarray
        The ticks (s) and the output held from each (rad/s): a sequence of held commands.
    """
    h = 1.0 / frequency
    first = cmd_t[0] + (phase - cmd_t[0]) % h
    ticks = np.arange(first, cmd_t[-1] + 4 * h, h)
    newest = (np.searchsorted(cmd_t, ticks, side="right") - 1).tolist()
    v, step = u.tolist(), limit * h
    out = np.empty(ticks.size)
    last = v[0]
    for i, j in enumerate(newest):
        gap = v[j] - last
        last += step if gap > step else -step if gap < -step else gap
        out[i] = last
    return np.concatenate([[cmd_t[0]], ticks]), np.concatenate([[v[0]], out])


def mean_wait(cmd_t: np.ndarray, frequency: float, phase: float) -> float:
    """The mean time (s) a command waits for the smoother's next tick φ + i/f: what a small command's response is delayed
    by beyond the dead time (h/2 when the commands' times are independent of the smoother's clock).

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s).
    frequency : float
        f, Hz.
    phase : float
        φ, s.
    """
    h = 1.0 / frequency
    return float(np.mean((phase - cmd_t) % h))


def ramp_lag(knot_t: np.ndarray, knot_v: np.ndarray, t: np.ndarray, tau: float, dead_time: float) -> np.ndarray:
    """The unit-gain lag's response at `t` to the piecewise-linear input through (`knot_t`, `knot_v`), delayed by `dead_time`.

    Parameters
    ----------
    knot_t, knot_v : numpy.ndarray
        The input's knots (s, rad/s): linear between them, knot_v[0] before the first and knot_v[-1] after the last.
    t : numpy.ndarray
        Where the response is wanted (s).
    tau : float
        The lag (s), > 0.
    dead_time : float
        The delay D (s).

    Returns
    -------
    numpy.ndarray
        x(t) (rad/s), exact (module docstring).
    """
    span = np.diff(knot_t)
    slope = np.divide(np.diff(knot_v), span, out=np.zeros(span.size), where=span > 0)
    a = _decay(-span / tau)
    v = knot_v[:-1]
    X = affine_scan(a, v + slope * (span - tau) - (v - slope * tau) * a, knot_v[0])
    k = np.searchsorted(knot_t + dead_time, t, side="right") - 1
    before = k < 0
    k = np.clip(k, 0, knot_t.size - 1)
    theta = np.where(before, 0.0, t - dead_time - knot_t[k])
    m = np.concatenate([slope, [0.0]])[k]
    vk = knot_v[k]
    return np.where(before, knot_v[0], vk + m * (theta - tau) + (X[k] - vk + m * tau) * _decay(-theta / tau))


def plant_response(cmd_t: np.ndarray, u: np.ndarray, t: np.ndarray, tau: float, dead_time: float, actuator_lag: float = 0.0,
                   slew: float = math.inf, knots: tuple | None = None, smoother: tuple | None = None) -> np.ndarray:
    """The unit-gain response at `t` of e^(−sD)/((τs + 1)(τ_a·s + 1)) behind a slew limit to the held commands, exactly.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commands (rad/s); before the first the plant rests at u[0].
    t : numpy.ndarray
        Where the response is wanted (s).
    tau : float
        The lag τ (s), > 0.
    dead_time : float
        The delay D (s).
    actuator_lag : float
        The second lag τ_a (s), in [0, τ) (0: none).
    slew : float
        The slew limit A (rad/s²), > 0 (inf: none).
    knots : tuple of numpy.ndarray, optional
        `slew_limited(cmd_t, u, slew)` when already computed (a fit varies τ, τ_a and D at one A); with `smoother`, the
        `smoothed` ticks and outputs.
    smoother : tuple of float, optional
        (f Hz, φ s): the slew limit is a smoother on its own timer (`smoothed`), not a continuous ramp.

    Returns
    -------
    numpy.ndarray
        The response (rad/s), before the gain g.
    """
    if math.isfinite(slew) and smoother is not None:
        held = knots if knots is not None else smoothed(cmd_t, u, slew, *smoother)
        one = lambda lag: lag_response(held[0], held[1], t, lag, dead_time)  # noqa: E731
    elif math.isinf(slew):
        one = lambda lag: lag_response(cmd_t, u, t, lag, dead_time)  # noqa: E731
    else:
        kt, kv = knots if knots is not None else slew_limited(cmd_t, u, slew)
        one = lambda lag: ramp_lag(kt, kv, t, lag, dead_time)  # noqa: E731
    if not actuator_lag > 0:
        return one(tau)
    return (tau * one(tau) - actuator_lag * one(actuator_lag)) / (tau - actuator_lag)
