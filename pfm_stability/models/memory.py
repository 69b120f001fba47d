"""A path tracker's memory closing the sampled plant: the loop of a controller whose answer to a pose error lasts several cycles.

Nav2's MPPI answers a pose error of one cycle over the following cycles too (its warm-started control sequence and
Savitzky–Golay filter: docs/path_tracking.md, "The controller's memory"). Measured as an impulse response
(`controllers.linearize`), it closes the held command's plant of the `sampled` model (`models.sampled.command_form`)
with the past samples as states: `memory_loop_matrix`. With one cycle it is the `sampled` model's own loop.
"""

from __future__ import annotations

import numpy as np

from .family import Characteristic
from .sampled import command_form

__all__ = ["memory_loop_matrix"]


def memory_loop_matrix(loop: Characteristic, taps, V: float, compute_delay: int) -> np.ndarray:
    """Φ of the sampled plant closed by a linear controller with memory (a path tracker's impulse response).

    The plant is the held command's (`command_form`: the drive's lags, plant gain, dead time and the compute delay;
    states (z,) (ω,) θ, y = x/V, then the commands on their way), its input the motor's g·u; the command is

        u_k = −Σ_j (θ_j·θ_(k−j) + y_j·V·y_(k−j)) + Σ_j w_j·ω_(k−j)

    over the J cycles of the taps (the response j cycles after a one-cycle perturbation of the heading, the lateral
    offset and the measured yaw rate), the past samples kept as extra states. With J = 1, w = 0 it is the `sampled`
    model's Φ_cl at k = θ_0, NV = y_0·V/θ_0 (tests/test_controllers_sim.py). The loop's own k is not used.

    Parameters
    ----------
    loop : Loop
        τ, τ_a, g, D and T.
    taps : (sequence, sequence, sequence)
        (θ_j in 1/s, y_j in 1/(m·s), w_j dimensionless), j = 0 … J − 1, one length.
    V : float
        The forward speed, m/s.
    compute_delay : {0, 1}
        Samples from measurement to actuation.
    """
    theta, y, w = (tuple(float(v) for v in t) for t in taps)
    if not len(theta) == len(y) == len(w) >= 1:
        raise ValueError(f"taps must be three sequences of one length >= 1; got lengths {len(theta)}, {len(y)}, {len(w)}")
    unit = loop.replace(k=1.0, c=0.0, heading_sampled=False)
    M, feed, _, _ = command_form(unit, "command", compute_delay)
    plant = unit._state_space("command")[0].shape[0]  # the lateral offset last, the heading before it, the rate before that
    if any(v != 0.0 for v in w) and plant < 3:
        raise ValueError("a controller that reads the measured yaw rate needs a plant with a lag (tau > 0) in the memory loop")
    channels = [(plant - 2, [-v for v in theta]), (plant - 1, [-V * v for v in y])] + ([(plant - 3, list(w))] if any(w) else [])
    J, n = len(y), M.shape[0]
    size = n + len(channels) * (J - 1)
    A = np.zeros((size, size))
    A[:n, :n] = M
    c = np.zeros(size)
    for ch, (index, row) in enumerate(channels):
        c[index] += row[0]
        base = n + ch * (J - 1)
        for j in range(1, J):
            c[base + j - 1] = row[j]
            A[base + j - 1, index if j == 1 else base + j - 2] = 1.0  # the sample j periods back
    A[:n] += loop.plant_gain * np.outer(feed, c)
    return A
