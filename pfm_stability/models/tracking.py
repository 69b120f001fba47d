"""Target tracking with position and velocity attraction (Ge & Cui 2002 eq 33–36).

With the attractive force F = −2α_p·e − 2α_v·ė on a robot of mass m (e: the
robot's position relative to a moving target), the tracking error obeys,
with α′ = α/m (Ge & Cui 2002 eq 33–36; docs/models.md, "Robot loop families"),

    ë + 2α′_v·ė + 2α′_p·e = 0,

a damped oscillator with natural frequency ω_n = √(2α′_p) and damping ratio
ζ = α′_v/√(2α′_p). Ge & Cui choose ζ = 1 (critical damping: the fastest
approach without overshoot). `tracking_dynamics` gives ω_n, ζ and the
regime; `TrackingDynamics.error` the error e(t) in closed form (each axis of
a planar error obeys the same equation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..parameters import check_parameter

__all__ = ["CRITICAL_RTOL", "REGIMES", "TrackingDynamics", "tracking_dynamics"]

CRITICAL_RTOL = 1e-12
"""|ζ − 1| at or below this is reported as "critically damped" (ζ = 1 is the design point; round-off only)."""

REGIMES = ("undamped", "underdamped", "critically damped", "overdamped")
"""The regimes of `TrackingDynamics.regime`: ζ = 0, 0 < ζ < 1, ζ = 1, ζ > 1."""


@dataclass(frozen=True)
class TrackingDynamics:
    """The tracking error's dynamics ë + 2ζω_n·ė + ω_n²·e = 0.

    Attributes
    ----------
    damping_ratio : float
        ζ = α′_v/√(2α′_p), dimensionless.
    natural_frequency : float
        ω_n = √(2α′_p), rad/s.
    regime : str
        One of `REGIMES`.
    """

    damping_ratio: float
    natural_frequency: float
    regime: str

    def error(self, t, e0, de0) -> np.ndarray:
        """e(t) from e(0) = e0 and ė(0) = de0, in closed form.

        e(t) = e^(−ζω_n t)·[e0·C(t) + (de0 + ζω_n e0)·S(t)] with C = cos ω_d t,
        S = sin(ω_d t)/ω_d (ω_d = ω_n√(1 − ζ²)) when ζ < 1, and the hyperbolic
        forms (β = ω_n√(ζ² − 1)) when ζ > 1, written with exponentials so that
        nothing overflows and S → t as ζ → 1 without cancellation.

        Parameters
        ----------
        t : array_like
            Times, s, >= 0.
        e0, de0 : float or array_like
            Initial error (m) and its rate (m/s); arrays broadcast against `t`.

        Returns
        -------
        ndarray
            e(t), m.
        """
        t = np.asarray(t, dtype=float)
        if np.any(t < 0) or not np.all(np.isfinite(t)):
            raise ValueError("t must be finite and >= 0 s")
        zeta, wn = self.damping_ratio, self.natural_frequency
        a = zeta * wn
        b = np.asarray(de0, dtype=float) + a * np.asarray(e0, dtype=float)
        if zeta < 1.0:
            wd = wn * math.sqrt(1.0 - zeta * zeta)
            decay = np.exp(-a * t)
            return decay * (e0 * np.cos(wd * t) + b * np.sin(wd * t) / wd)
        beta = wn * math.sqrt(zeta * zeta - 1.0)
        slow, fast = np.exp((beta - a) * t), np.exp(-(beta + a) * t)
        cosh_part = 0.5 * (slow + fast)
        sinh_part = fast * np.expm1(2.0 * beta * t) / (2.0 * beta) if beta > 0 else t * np.exp(-a * t)
        return e0 * cosh_part + b * sinh_part


def tracking_dynamics(alpha_p, alpha_v, mass=1.0) -> TrackingDynamics:
    """ζ, ω_n and the regime of Ge & Cui 2002's tracking error (eq 33–36).

    Parameters
    ----------
    alpha_p : float
        Position gain α_p, N/m, > 0 (``RANGES["alpha_p"]``).
    alpha_v : float
        Velocity gain α_v, N·s/m, >= 0.
    mass : float
        Robot mass m, kg, > 0.

    Returns
    -------
    TrackingDynamics
    """
    alpha_p = check_parameter("alpha_p", alpha_p)
    alpha_v = check_parameter("alpha_v", alpha_v)
    mass = check_parameter("mass", mass)
    wn = math.sqrt(2.0 * alpha_p / mass)
    zeta = (alpha_v / mass) / wn
    if zeta == 0.0:
        regime = "undamped"
    elif abs(zeta - 1.0) <= CRITICAL_RTOL:
        regime = "critically damped"
    else:
        regime = "underdamped" if zeta < 1.0 else "overdamped"
    return TrackingDynamics(zeta, wn, regime)
