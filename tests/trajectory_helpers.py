"""Helper shared by the simulator tests: two runs of one member agree to round-off (docs/simulator.md, "Batches").

A member advances the same alone or in any batch up to round-off, not bit for
bit: numpy's SIMD kernels of sin, cos, exp, expm1 (AVX-512 and others) round
the elements of an array's vector body and of its scalar tail differently, so
the same member at another index or in an array of another length can differ
by a few units in the last place (ULP) in a step. Such a difference enters the
closed loop and is carried on: after k steps it is at most about k times the
per-step round-off of the state's scale, times the growth e^(σt) of a run that
grows (a perturbation made at t_j is amplified by e^(σ(t_k − t_j)) <= e^(σt_k)).
`assert_same_to_roundoff` checks exactly that bound.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EPS", "ROUNDOFF_PER_STEP", "roundoff_bound", "assert_same_to_roundoff"]

EPS = float(np.finfo(float).eps)

ROUNDOFF_PER_STEP = 64
"""Allowed round-off per step, in units of ε times the state's scale.

Measured (AVX-512 machine, numpy dispatching X86_V4/AVX512_ICL kernels; the
members of `tests/test_sim_accuracy.py` and `tests/test_sim_engine.py`): at
most 1.6 ε·(k + 1)·scale (the heading of a T/τ = 30 member, two steps in), and
0 with numpy capped at AVX2 or at its baseline. 64 is 40× the measured worst;
over the 140 steps of those runs it allows 2e-12 of the scale (2 pm on a
metre), far below anything the metrics or the verdicts resolve."""


def roundoff_bound(trajectory, growth_rate: float, per_step: float = ROUNDOFF_PER_STEP):
    """Largest round-off difference allowed at each sample: (position in m, heading in rad), arrays.

    Position: per_step·ε·(k + 1)·P·e^(max(σ, 0)·t_k) with P the largest distance
    of the robot from the origin over the run (m; the scale of the coordinates'
    rounding); heading likewise with the largest |θ| over the run (rad).

    Parameters
    ----------
    trajectory : Trajectory
        The reference run (t in s, x and y in m, θ in rad).
    growth_rate : float
        σ of the run, 1/s (only its positive part counts: the growth of an
        unstable run amplifies earlier round-off).
    per_step : float
        Round-off allowed per step, in ε times the scale.
    """
    k = np.arange(trajectory.t.size) + 1.0
    growth = np.exp(max(float(growth_rate), 0.0) * trajectory.t)
    position_scale = float(np.max(np.hypot(trajectory.x, trajectory.y)))
    heading_scale = float(np.max(np.abs(trajectory.theta)))
    allowed = per_step * EPS * k * growth
    return allowed * position_scale, allowed * heading_scale


def assert_same_to_roundoff(got, want, growth_rate: float, label: str = "") -> None:
    """`got` and `want` (Trajectory) have the same samples and agree within `roundoff_bound(want, σ)` at each one."""
    assert got.t.size == want.t.size, f"{label}: {got.t.size} samples against {want.t.size}"
    position, heading = roundoff_bound(want, growth_rate)
    dp = np.hypot(got.x - want.x, got.y - want.y)
    dtheta = np.abs(got.theta - want.theta)
    assert np.all(dp <= position), f"{label}: position differs by {dp.max():.3g} m (allowed {position[np.argmax(dp - position)]:.3g} m)"
    assert np.all(dtheta <= heading), f"{label}: heading differs by {dtheta.max():.3g} rad (allowed {heading[np.argmax(dtheta - heading)]:.3g} rad)"
