"""The drive's yaw acceleration limit in the harmonic balance: the loop seen from its command (docs/wobble.md).

A velocity smoother limits the rate of change of the commanded yaw rate; its describing function
(`describing.rate_limit_df`) is complex — amplitude- and frequency-dependent with a phase lag — so the cycle of an
amplitude A is no longer the loop model's own boundary at a reduced gain (`wobble`'s route without it): the balance
is solved on the loop's transfer seen from the command. `command_responses` gives it (the `sampled` loop's own
matrices, `models.sampled.command_form`, or the continuous loop with the whole command delayed), `limited_balance`
solves it amplitude by amplitude, and `wobble.limited_branch` makes the branch of it. `loop_filtering` and
`limiter_harmonic` are the trust measures' pieces both routes share; `motor_loop`, `drive_lags` and `lag_gain` the
robot's loop as both routes close it, with both of the drive's lags (τ and a second lag τ_a).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from ..models import make_model
from ..models.loop import Loop
from .describing import J1_PEAK, harmonic_content, rate_limit_df, rate_limit_waveform, saturation_df_for_output

__all__ = ["LimitedBalance", "command_responses", "drive_lags", "lag_gain", "limited_balance", "limiter_harmonic", "loop_filtering",
           "motor_loop"]


@dataclass(frozen=True)
class LimitedBalance:
    """The harmonic balance with the drive's limiter at each amplitude of a branch (`limited_balance`): the arrays of
    `wobble.WobbleBranch` (nan where no cycle of that amplitude exists), and the loop's linear boundary.

    Attributes
    ----------
    speeds, omegas, headings, rate_gains, third_harmonics, rate_harmonics : ndarray
        V (m/s), ω (rad/s), Θ (rad: the course's amplitude, the heading's without a slide, `Robot.slip_lag`), the
        saturation's (or the heading's rate limit's) gain, the trust measures.
    limiter_gains, limiter_lags : ndarray or None
        |N_r| and its lag (rad); None without a yaw acceleration limit.
    cascades : ndarray of bool or None
        Where the saturation clips the smoother's input (`wobble.WobbleCycle.cascade`); None without a limit or with
        ``heading_limit``.
    NV_critical : float
        NV*, 1/s, of the loop model (the limiter is linear there).
    omega_critical : float
        ω*, rad/s.
    """

    speeds: np.ndarray
    omegas: np.ndarray
    headings: np.ndarray
    rate_gains: np.ndarray
    third_harmonics: np.ndarray
    rate_harmonics: np.ndarray
    limiter_gains: np.ndarray | None
    limiter_lags: np.ndarray | None
    cascades: np.ndarray | None
    NV_critical: float
    omega_critical: float


def command_responses(robot, controller, model: str):
    """ω ↦ (H₀, H₁): the loop seen from its command, in the motor's units, for the harmonic balance with the drive's limiter.

    The applied command w (motor units, g·u after the limiter) drives the plant, the controller computes
    v = −(H₀ + K·H₁)·w with K = g·k·NV, so a describing function N_c on the command closes the loop where
    1 + N_c·(H₀ + K·H₁) = 0. `sampled` (T > 0): the sampled loop's own matrices (`models.sampled.command_form`,
    x_(k+1) = M·x_k + n·w_k, v_k = −(F0 + K·F1)·x_k), H_i = F_i·(zI − M)⁻¹·n at z = e^(jωT); otherwise the
    continuous loop with the whole command delayed by D and the field's term by T more,
    H₀ = g·k·e^(−jωD)/(jω·P(jω)), H₁ = e^(−jω(T + D))/((jω)²·P(jω)) with the drive's lags P(s) = (τs + 1)(τ_a·s + 1):
    s²·P(s) + gk(s + NV·e^(−sT))·e^(−sD) = 0 with N_c = 1.

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, g, D, τ_a.
    controller : parameters.Controller
        T, compute delay (``hold="command"``).
    model : {"exact_delay", "sampled"}

    Returns
    -------
    callable
        ω (array, rad/s) ↦ (H₀, H₁) (complex arrays).
    """
    from ..models.sampled import command_form

    D, T = robot.dead_time, controller.T
    loop = motor_loop(robot, controller)
    gk, lags = loop.k, drive_lags(loop)
    if model == "sampled" and T > 0:
        M, n, F0, F1 = command_form(loop, "command", controller.compute_delay)
        eye = np.eye(M.shape[0])

        def sampled(w):
            z = np.exp(1j * np.asarray(w, dtype=float) * T)
            X = np.linalg.solve(z[..., None, None] * eye - M, np.broadcast_to(n, z.shape + n.shape)[..., None])[..., 0]
            return X @ F0, X @ F1

        return sampled

    def continuous(w):
        s = 1j * np.asarray(w, dtype=float)
        plant = np.exp(-s * D) / (s * (lags[0] * s + 1.0) * (lags[1] * s + 1.0))
        return gk * plant, np.exp(-s * T) * plant / (s * (lags[2] * s + 1.0))  # y follows the course: τ_s

    return continuous


def limiter_harmonic(rho: float) -> float:
    """|3rd harmonic|/|fundamental| of the continuous rate limiter's output at ρ (1/9 for the triangle, 0 for ρ <= 1).

    Parameters
    ----------
    rho : float
        Aω/R.
    """
    if rho <= 1.0:
        return 0.0
    theta = _circle_nodes()
    spectrum = np.abs(np.fft.rfft(rate_limit_waveform(rho, theta)))
    return float(spectrum[3] / spectrum[1])


@functools.lru_cache(maxsize=1)
def _circle_nodes():
    return 2.0 * math.pi * np.arange(256) / 256


def limited_balance(robot, controller, delta, A, Nf, model: str, *, heading_limit: bool = False) -> LimitedBalance:
    """Solve the harmonic balance with the drive's limiter at each amplitude A (`wobble.limited_branch` says what it is).

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, g, D, τ_a, `max_steering_rate`, `yaw_accel_limit` (finite unless ``heading_limit``).
    controller : parameters.Controller
        T, compute delay; ``hold="command"``.
    delta : callable
        δ(y), the field's steering (for its third harmonic).
    A, Nf : ndarray
        Amplitudes (m, increasing) and the field's describing function there (1/m).
    model : {"exact_delay", "sampled"}
    heading_limit : bool
        The steering-rate limit as the heading's rate limit (`wobble.limited_branch`).

    Returns
    -------
    LimitedBalance
    """
    if controller.hold != "command":
        raise ValueError(f"yaw_accel_limit needs hold=command (a servo closing k(δ − θ) continuously has no command sequence to "
                         f"limit; docs/wobble.md); got hold={controller.hold}")
    loop_model = make_model(model, hold=controller.hold, compute_delay=controller.compute_delay)
    g, D = robot.plant_gain, robot.dead_time
    gk, M, R = g * robot.k, g * robot.max_steering_rate, g * robot.yaw_accel_limit
    T = controller.T
    loop = motor_loop(robot, controller)
    lags = drive_lags(loop)
    limiter_T = T if model == "sampled" else 0.0
    b = loop_model.boundary(loop)
    NV0, w0 = b.NV_critical, b.omega_critical
    if not (math.isfinite(NV0) and NV0 > 0 and w0):
        raise ValueError(f"the {model} loop has no oscillatory stability boundary here (NV* = {NV0:g} 1/s): no wobble to predict")
    responses = command_responses(robot, controller, model)
    h3_field = harmonic_content(delta, A)

    def state(x, a, nf):
        w, U = math.exp(x[0]), math.exp(x[1])
        n_s = 1.0 if U <= M or heading_limit else float(saturation_df_for_output(U, M))
        step = 2.0 * U * math.sin(0.5 * w * limiter_T) / (R * limiter_T) if limiter_T > 0 else U * w / R  # <= 1: not limiting
        N_r = complex(rate_limit_df(U, w, R, limiter_T)) if step > 1.0 else 1.0 + 0j
        theta = abs(N_r) * U / (w * lag_gain(w, lags))  # the course's amplitude (the heading's without a slide)
        heading = theta * math.hypot(1.0, w * lags[2])
        N_h = complex(rate_limit_df(heading, w, M)) if heading_limit and heading * w > M else 1.0 + 0j
        theta *= abs(N_h)
        return w, U, n_s, N_r, N_h, theta, gk * nf * a * w / theta

    def residual(x, a, nf):
        w, U, n_s, N_r, N_h, theta, K = state(x, a, nf)
        if not n_s > 0:
            return [1e6, 1e6]
        H0, H1 = responses(np.array([w]))
        r = 1.0 + n_s * N_r * (complex(H0[0]) + N_h * K * complex(H1[0]))
        return [r.real, r.imag]

    speeds, omegas, headings, gains, thirds, rates, lim_gains, lim_lags = (np.full(A.size, np.nan) for _ in range(8))
    cascades = np.zeros(A.size, dtype=bool)
    theta0 = A[0] * w0 * Nf[0] / NV0
    linear = np.array([math.log(w0), math.log(theta0 * w0 * lag_gain(w0, lags))])  # U ∝ A on the linear part
    guess = linear
    for i, (a, nf) in enumerate(zip(A, Nf)):
        if not math.isfinite(nf):
            continue
        solved = None
        attempts = ((guess, "hybr"), (guess, "lm"), (linear + np.array([0.0, math.log(a / A[0])]), "hybr"))
        for start, method in attempts:  # Powell's hybrid, then Levenberg–Marquardt where the limiter's onset kinks N_r
            sol = optimize.root(residual, start, args=(a, nf), method=method, options={"xtol": 1e-13})
            if math.hypot(*residual(sol.x, a, nf)) <= 1e-9:
                solved = sol.x
                break
        if solved is None:
            continue
        guess = solved
        w, U, n_s, N_r, N_h, theta, _ = state(solved, a, nf)
        if not theta < J1_PEAK:
            continue
        speeds[i] = a * w / (2.0 * special.j1(theta))
        omegas[i], headings[i], gains[i] = w, theta, n_s * abs(N_h)
        lim_gains[i], lim_lags[i] = abs(N_r), -math.atan2(N_r.imag, N_r.real)
        E = U / n_s  # the saturation's input: its clipped flank still rises at E·ω, which the smoother may not follow
        flank = 2.0 * E * math.sin(0.5 * w * limiter_T) / (R * limiter_T) if limiter_T > 0 else E * w / R
        cascades[i] = n_s < 1.0 and flank > 1.0
        h3_sat = harmonic_content(lambda x: np.clip(x, -M, M), U / n_s) if n_s < 1.0 else 0.0
        h3_lim = limiter_harmonic(U * w / R) if math.isfinite(R) else 0.0
        to_heading = lag_gain(w, lags) / (3.0 * lag_gain(3.0 * w, lags))
        h3_head = limiter_harmonic(theta / abs(N_h) * math.hypot(1.0, w * lags[2]) * w / M) if heading_limit else 0.0  # the heading's own triangle
        rates[i] = h3_sat * to_heading + h3_head
        thirds[i] = (h3_field[i] + h3_sat + h3_lim) * loop_filtering(w, lags, gk * n_s * abs(N_r)) + h3_head / 3.0 \
            + special.jv(3, theta) / (3.0 * special.j1(theta))
    limited = math.isfinite(R)
    return LimitedBalance(speeds, omegas, headings, gains, thirds, rates, lim_gains if limited else None, lim_lags if limited else None,
                          cascades if limited and not heading_limit else None, NV0, w0)


def loop_filtering(omega: float, lags: tuple, k: float) -> float:
    """|L(3jω)|/|L(jω)| with L(s) = 1/(s(s·P(s) + k)(τ_s·s + 1)), P(s) = (τs + 1)(τ_a·s + 1) the drive's lags and τ_s the
    course's: how the steering loop filters a third harmonic on its way to y (τ_a = τ_s = 0: 1/(s(τs² + s + k))).

    Parameters
    ----------
    omega : float
        rad/s.
    lags : tuple of float
        (τ, τ_a, τ_s), s (`drive_lags`).
    k : float
        The loop's (equivalent) steering gain, 1/s.
    """
    tau, second, slip = lags
    L = lambda s: 1.0 / (s * (s * (tau * s + 1.0) * (second * s + 1.0) + k) * (slip * s + 1.0))
    return abs(L(3j * omega)) / abs(L(1j * omega))


def motor_loop(robot, controller, gain_factor: float = 1.0) -> Loop:
    """The robot's loop in the motor's units, the one the harmonic balance closes: steering gain g·k·`gain_factor`, plant
    gain 1, the robot's dead time D, both of its lags τ, τ_a and its course's τ_s (`Loop.of` with g folded into k: the
    saturation and the limiter act on g·u, docs/simulator.md).

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, g, D, τ_a.
    controller : parameters.Controller
        T.
    gain_factor : float
        The saturation's describing function on the steering gain (1: not saturating).
    """
    return Loop(robot.tau, controller.T, robot.plant_gain * robot.k * gain_factor, dead_time=robot.dead_time,
                actuator_lag=robot.actuator_lag, slip_lag=robot.slip_lag)


def drive_lags(loop: Loop) -> tuple:
    """(τ, τ_a, τ_s), s: the drive's lags and the course's as a `Loop` stores them (0 where there is none).

    Parameters
    ----------
    loop : Loop
    """
    return float(loop.tau), float(loop.actuator_lag), float(loop.slip_lag)


def lag_gain(omega, lags: tuple):
    """|P(jω)|·|1 + jωτ_s| = √(1 + ω²τ²)·√(1 + ω²τ_a²)·√(1 + ω²τ_s²): the applied command's amplitude over the course's
    rate at ω (the turning rate's without a slide: the harmonic balance's Θ is the course's amplitude, which the lateral
    motion ẋ = V·sin χ sees; docs/wobble.md).

    Parameters
    ----------
    omega : float or ndarray
        rad/s.
    lags : tuple of float
        (τ, τ_a, τ_s), s (`drive_lags`).
    """
    return np.hypot(1.0, omega * lags[0]) * np.hypot(1.0, omega * lags[1]) * np.hypot(1.0, omega * lags[2])
