"""The window-edge relay: where VFF's lateral force jumps within the robot's lateral excursion (docs/maps.md,
"Verdicts along every route").

The robot's active window is the w × w block of cells centred on the cell it stands in. When it moves one cell
sideways the window gains a column on one side and loses one on the other: F_n(s) (the lateral force at lateral
offset s from the path) is smooth inside a cell and jumps at the cell boundaries by the force of the column gained
or lost. Near walls the smooth slope dominates and the jumps are ripple; but a robot riding 1.65 m (h·c) from a
rack, pulled there by its goal, has almost no slope and the rack's whole column at its window's edge: F_n drops by
the column's force when the robot moves a cell towards the rack and comes back when it moves away. That is a relay
— a discontinuous restoring force behind the loop's delay — and it holds the robot in a sustained oscillation
about the boundary of about a cell's amplitude, which the linearization (the smooth gradient) cannot see: the
non-smooth analogue of the velocity-gated laws' relay verdict (docs/velocity_and_fuzzy.md).

**Detection** (`window_relay`). F_n and its smooth derivative g = dF_n/ds (`equilibria.lateral_force`, the window
sum's own Jacobian, which has no jump) are evaluated at s0 + k·c/4, k = −2 … 2, about the linearization point s0
(half a cell each way: where the robot's path lies). Over each quarter-cell interval the jump is what the smooth
slope does not explain, J = ΔF_n − ½(g_a + g_b)·Δs (exact for a quadratic F_n; the curvature's error is O(c³)). The
point is a relay when the net lateral force changes sign across a jump — F_n itself about an equilibrium (the
equilibrium search converges onto a jump that changes F_n's sign), F_n − F_n(s0) on a path the robot took towards
its goal (the goal's pull balances F_n there) — that **restores** (J < 0: the net force falls from >= 0 to <= 0
as the robot moves along +n, so either side pushes it back across) and is larger than the smooth change over one
cell, |J| > `RELAY_RATIO`·max|g|·c. A jump that pushes the robot away (J > 0) only moves it off the boundary.

**Its amplitude** (`relay_amplitude`, the describing function of an ideal relay of half-height |J|/2,
4·(|J|/2)/(π·A), in the loop 1 + N·G(s) = 0): the limit cycle sits where that gain equals the loop's critical
gain N* = NV*/V at the loop's phase crossover ω*, A = 2|J|/(π·N*). `maps.paths` calls the point unstable ("relay")
when A reaches the episodes' `AMPLITUDE_THRESHOLD`: a smaller cycle is one the driving validation would not call an
oscillation either.
"""

from __future__ import annotations

import numpy as np

from .equilibria import lateral_force

__all__ = ["RELAY_RATIO", "RELAY_STEPS", "relay_amplitude", "window_relay"]

RELAY_RATIO = 1.0
"""A restoring jump is a relay when it is larger than this many times the smooth change of F_n over one cell."""
RELAY_STEPS = 2
"""Quarter-cells checked on each side of the linearization point (half a cell each way)."""


def window_relay(grid, law, x, y, tx, ty, s0, reference=None):
    """(relay, jump): whether the lateral force's zero at the points p + s0·nrm is a restoring jump larger than the
    smooth change over a cell (module docstring), and the jump (F_ct units; 0 where no relay).

    Parameters
    ----------
    grid : HistogramMap
        The map's histogram grid.
    law : GridWallLaw
        KB's grid law.
    x, y : ndarray
        Points on the routes, m.
    tx, ty : ndarray
        Unit travel directions at them.
    s0 : ndarray
        Lateral offsets of the linearization points along nrm = (−ty, tx), m.
    reference : ndarray of bool, optional
        Where the force that holds the robot on its path is not F_n alone (a path the robot took towards its goal):
        there the net force is F_n − F_n(s0), zero at the path; elsewhere F_n itself (s0 an equilibrium).
    """
    x, y, tx, ty, s0 = (np.asarray(v, dtype=float) for v in (x, y, tx, ty, s0))
    if x.size == 0:
        return np.zeros(0, dtype=bool), np.zeros(0)
    step = grid.cell_size / 4
    steps = np.arange(-RELAY_STEPS, RELAY_STEPS + 1) * step
    n = steps.size
    s = (s0[:, None] + steps[None, :]).ravel()
    rep = lambda v: np.repeat(v, n)  # noqa: E731
    fn, _, dfn = lateral_force(grid, law, rep(x), rep(y), rep(tx), rep(ty), s, jacobian=True)
    fn, dfn = fn.reshape(-1, n), dfn.reshape(-1, n)
    if reference is not None:
        fn = fn - np.where(np.asarray(reference, dtype=bool), fn[:, RELAY_STEPS], 0.0)[:, None]
    with np.errstate(invalid="ignore"):
        jumps = np.diff(fn, axis=1) - 0.5 * (dfn[:, 1:] + dfn[:, :-1]) * step
        smooth = np.nanmax(np.abs(dfn), axis=1) * grid.cell_size
        # a restoring jump across which the net force changes sign: the robot is pushed back across it from both sides
        across = (jumps < 0) & (fn[:, :-1] >= 0) & (fn[:, 1:] <= 0) & (-jumps > RELAY_RATIO * smooth[:, None])
        relay = across.any(axis=1)
        jump = np.where(across, -jumps, 0.0).max(axis=1)
    return relay, np.where(relay, jump, 0.0)


def relay_amplitude(jump, N_critical: float):
    """Amplitude (m) of the relay's limit cycle, 2·|jump|/(π·N_critical) (module docstring: describing function).

    Parameters
    ----------
    jump : array_like
        The jump of F_n, F_ct units.
    N_critical : float
        The loop's critical lateral gain NV*/V, 1/m (> 0).
    """
    return 2.0 * np.abs(np.asarray(jump, dtype=float)) / (np.pi * N_critical)
