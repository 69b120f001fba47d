"""Can a log separate the plant's g, τ and D? The commands' spectrum, and the plants a narrowband log cannot tell
apart (docs/diagnose.md, "Identifiability").

A robot oscillating in a corridor commands essentially one frequency ω: a first-order-plus-dead-time plant's gain g, lag τ
and dead time D are then not separately identifiable — the log determines only the plant's gain and phase at ω, two numbers
for three unknowns (the τ–D ridge). `command_spectrum` measures how much of the commands' power lies away from their
dominant frequency before any fit; `ridge_point` gives the plant of the ridge that has one value the user knows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_number

__all__ = ["NARROWBAND", "BAND", "Excitation", "command_spectrum", "excitation_of", "ridge_point"]

NARROWBAND = 0.05
"""The commands are narrowband (g, τ and D not separately identifiable) when less than this fraction of their power
lies outside [ω/`BAND`, `BAND`·ω] around their dominant angular frequency ω. Measured: the VFF simulator's corridors
and walls 0.0002–0.019 (20 seeds), step turns and chirps 0.14–0.93 (docs/diagnose.md, "Identifiability")."""
BAND = 1.5
"""The band around the dominant frequency that `NARROWBAND` counts as one frequency (a factor each way)."""


@dataclass(frozen=True)
class Excitation:
    """How the commands excite the plant (`analysis.identification`'s module docstring, "Can the log separate g, τ and D?").

    Parameters
    ----------
    omega : float
        The commands' dominant angular frequency (rad/s); NaN for a constant command.
    outside : float
        The fraction (−, 0–1) of their power outside [ω/`BAND`, `BAND`·ω].
    narrowband : bool
        outside < `NARROWBAND`: g, τ and D are not separately identifiable.
    gain : float
        The fitted plant's gain |g·e^(−jωD)/(jωτ + 1)| at omega (−), which a narrowband log does determine.
    phase : float
        Its phase −ωD − atan(ωτ) at omega (rad), which a narrowband log does determine.
    """

    omega: float
    outside: float
    narrowband: bool
    gain: float
    phase: float

    def to_dict(self) -> dict:
        """The ``fit.excitation`` of the JSON output."""
        return {"omega": json_number(self.omega), "outside": json_number(self.outside), "narrowband": self.narrowband,
                "gain": json_number(self.gain), "phase": json_number(self.phase)}


def command_spectrum(cmd_t: np.ndarray, u: np.ndarray, T: float) -> tuple[float, float]:
    """The commands' dominant angular frequency and the fraction of their power outside [ω/`BAND`, `BAND`·ω].

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commanded yaw rates (rad/s), each held until the next.
    T : float
        The controller's period (s), > 0: the held command is sampled every T.

    Returns
    -------
    tuple of float
        (ω in rad/s, the fraction outside in 0–1); (NaN, 1.0) when the command is constant.
    """
    cmd_t, u = np.asarray(cmd_t, dtype=float), np.asarray(u, dtype=float)
    grid = np.arange(cmd_t[0], cmd_t[-1], T)
    x = u[np.clip(np.searchsorted(cmd_t, grid, side="right") - 1, 0, u.size - 1)]
    x = x - x.mean()
    power = np.abs(np.fft.rfft(x * np.hanning(x.size))) ** 2 if x.size >= 4 else np.zeros(1)
    omega = 2.0 * math.pi * np.fft.rfftfreq(x.size, T) if x.size >= 4 else np.zeros(1)
    total = float(power[1:].sum())
    if power.size < 3 or not total > 0 or not np.ptp(x) > 1e-12 * max(1.0, float(np.max(np.abs(u)))):
        return math.nan, 1.0
    peak = int(np.argmax(power[1:])) + 1
    band = (omega >= omega[peak] / BAND) & (omega <= omega[peak] * BAND)
    centre = float(np.sum(omega[band] * power[band]) / np.sum(power[band]))  # the peak refined: the band's centroid
    return centre, float(max(0.0, 1.0 - power[band].sum() / total))


def ridge_point(excitation: Excitation, *, tau: float | None = None, dead_time: float | None = None,
                plant_gain: float | None = None) -> tuple[float, float, float] | None:
    """The plant (g, τ, D) of a narrowband log's ridge — its gain and phase at ω — that has the one value given.

    Parameters
    ----------
    excitation : Excitation
        What the log determines: ω (rad/s), and the gain (−) and phase (rad) there.
    tau : float, optional
        The lag (s), > 0: g = gain·√(1 + ω²τ²), D = (−phase − atan(ωτ))/ω.
    dead_time : float, optional
        The dead time (s): atan(ωτ) = −phase − ωD, which must lie in [0, π/2).
    plant_gain : float, optional
        The plant gain (−), at least the gain at ω: ωτ = √((g/gain)² − 1).

    Returns
    -------
    tuple of float or None
        (g, τ, D) with the same gain and phase at ω; None when no plant of the ridge has the value given (or ω is
        undefined).

    Raises
    ------
    ValueError
        Not exactly one of tau, dead_time, plant_gain given.
    """
    given = [name for name, v in (("tau", tau), ("dead_time", dead_time), ("plant_gain", plant_gain)) if v is not None]
    if len(given) != 1:
        raise ValueError(f"give exactly one of tau, dead_time, plant_gain; got {', '.join(given) or 'none'}")
    w, gain, phase = excitation.omega, excitation.gain, excitation.phase
    if not (math.isfinite(w) and w > 0 and gain > 0):
        return None
    if tau is None and dead_time is not None:
        lag = -phase - w * dead_time
        if not 0.0 <= lag < math.pi / 2:
            return None
        tau = math.tan(lag) / w
    elif tau is None:
        if not abs(plant_gain) >= gain:
            return None
        tau = math.sqrt((plant_gain / gain) ** 2 - 1.0) / w
    if not tau >= 0:
        return None
    g = math.copysign(gain * math.sqrt(1.0 + (w * tau) ** 2), plant_gain if plant_gain is not None else 1.0)
    return g, tau, (-phase - math.atan(w * tau)) / w


def excitation_of(cmd_t, u, T: float, g: float, tau: float, delay: float) -> Excitation:
    """The `Excitation` of a log's commands and of the plant fitted to it.

    Parameters
    ----------
    cmd_t : numpy.ndarray
        The commands' times (s), non-decreasing.
    u : numpy.ndarray
        The commanded yaw rates (rad/s).
    T : float
        The controller's period (s), > 0.
    g : float
        The fitted plant gain (−).
    tau : float
        The fitted lag (s).
    delay : float
        The fitted dead time (s).
    """
    omega, outside = command_spectrum(cmd_t, u, T)
    w = omega if math.isfinite(omega) else 0.0
    return Excitation(omega, outside, bool(outside < NARROWBAND), abs(g) / math.sqrt(1.0 + (w * tau) ** 2),
                      -w * delay - math.atan(w * tau))
