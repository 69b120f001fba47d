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

**Detection merges a split jump**: the equilibrium search puts s0 on the jump (`equilibria`: located to ~10 µm),
and the average over the robot's position along t (`equilibria.lateral_force`) can put F_n(s0) part-way up it; the
jump is then split between the two quarter-cell intervals next to s0. Two consecutive restoring intervals across which
the net force changes sign are one jump: their J add.

**Its amplitude, one jump** (`relay_amplitude`): the describing function of an ideal relay of half-height |J|/2 is
4·(|J|/2)/(π·A); with the smooth restoring slope N_s = −(dF_n/ds)/F_t beside it (1/m, the loop's own gain there),
the loop 1 + (N_s + 2|J|/(π·A))·G(s) = 0 has its limit cycle where that sum equals the loop's critical gain
N* = NV*/V at its phase crossover ω*:

    N_s + 2|J|/(π·A) = N*   ⇒   A = 2|J|/(π·(N* − N_s)),   N_s < N*

(N_s >= N*: the smooth loop is unstable by itself). J and N_s are per unit forward force F_t (the robot steers to
F_n/F_t). A pull P ≠ |J|/2 towards the jump (a goal) makes the relay asymmetric, duty cycle P/|J|, and multiplies
A by sin(π·P/|J|) <= 1: the symmetric relay is the largest cycle. Checked against the sampled loop simulated with
the relay (tests/test_map_relay.py, experiments/relay_amplitude.py): the first harmonic within a few per cent (the
relay's third harmonic through the loop's low-pass, and the half-period a whole number of samples).

**Its amplitude, the window's staircase** (`window_cycle`, `profile_cycle`): a cycle of more than half a cell
crosses the neighbouring cell boundaries, where a solid rack's next columns enter the window one by one — F_n is a
staircase whose mean slope (a column's force per cell, ~2.6 1/m for CARMEL beside a rack) the window sum's smooth
gradient does not contain. The describing function of the whole profile F_n(s)/F_t(s) (sampled over ±`CYCLE_REACH_CELLS`
cells): for an amplitude A the cycle's centre B makes the mean force over the cycle zero (an equilibrium: no
net pull; on a path the robot took, B = 0 — the path is its mean position and the goal supplies the mean), and
N_1(A) = −(2/A)·⟨F(s0 + B + A·sin θ)·sin θ⟩; the cycle is the first A where N_1 falls through N*. Beside a rack
at the window's edge (tests/test_map_relay.py) this is what the VFF simulator does (0.17 m), while the one-jump
formula gives 0.06 m (0.13 m with the split jump merged).

`maps.deciding.paths` calls the point unstable ("relay") when the amplitude reaches the episodes' `AMPLITUDE_THRESHOLD`: a
smaller cycle is one the driving validation would not call an oscillation either.
"""

from __future__ import annotations

import numpy as np

from .equilibria import lateral_force

__all__ = ["CYCLE_NODES", "ON_THE_JUMP", "CYCLE_REACH_CELLS", "CYCLE_STEP_CELLS", "RELAY_RATIO", "RELAY_STEPS", "profile_cycle",
           "relay_amplitude", "window_cycle", "window_relay"]

RELAY_RATIO = 1.0
"""A restoring jump is a relay when it is larger than this many times the smooth change of F_n over one cell."""
RELAY_STEPS = 2
"""Quarter-cells checked on each side of the linearization point (half a cell each way)."""
CYCLE_REACH_CELLS = 6
"""How far (cells) on each side of the path the force profile of `window_cycle` is sampled; cycles up to half of it."""
CYCLE_STEP_CELLS = 0.0625
"""Spacing of that profile, cells (a jump is smeared over one step: O(step/A) in the describing function)."""
CYCLE_NODES = 128
"""Phases θ of the describing function's averages (midpoint rule over the period)."""


ON_THE_JUMP = 1e-3
"""|F_n| at an end of a jump's interval, as a fraction of the jump, below which the net force counts as zero there:
the equilibrium search locates s0 on a jump to its bracket (~10 µm, `equilibria.NEWTON_STEPS`), so F_n(s0) is
that bracket's share of the jump, and its sign is round-off (it flipped a tb3_sandbox sample's relay between numpy's
AVX2 and AVX-512 kernels)."""


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
        # over one quarter-cell interval, or two consecutive ones: a jump split by the averaged F_n(s0) part-way up it
        # (module docstring), whose halves need not change the sign on their own (F_n(s0) ~ 0 to round-off)
        jump = np.zeros(x.size)
        for span in (1, 2):
            for k in range(jumps.shape[1] - span + 1):
                part = jumps[:, k:k + span]
                zero = ON_THE_JUMP * np.abs(np.nan_to_num(part.sum(axis=1)))  # the equilibrium found on the jump itself
                across = (part < 0).all(axis=1) & (fn[:, k] >= -zero) & (fn[:, k + span] <= zero)
                jump = np.maximum(jump, np.where(across, -np.nan_to_num(part.sum(axis=1)), 0.0))
        relay = jump > RELAY_RATIO * smooth
    return relay, np.where(relay, jump, 0.0)


def relay_amplitude(jump, N_critical: float, N_smooth=0.0):
    """Amplitude (m) of the relay's limit cycle, 2·|jump|/(π·(N_critical − N_smooth)) (module docstring: describing
    function of one jump beside the smooth slope); inf where N_smooth >= N_critical.

    Parameters
    ----------
    jump : array_like
        The jump of F_n per unit forward force F_t (dimensionless: F_ct units over F_t/F_ct).
    N_critical : float
        The loop's critical lateral gain NV*/V, 1/m (> 0).
    N_smooth : array_like
        The smooth restoring slope beside the jump, −(dF_n/ds)/F_t, 1/m (0: none; KB's N at the point).
    """
    jump = np.abs(np.asarray(jump, dtype=float))
    room = N_critical - np.asarray(N_smooth, dtype=float)
    with np.errstate(divide="ignore"):
        return np.where(room > 0, 2.0 * jump / (np.pi * np.where(room > 0, room, 1.0)), np.inf)


def profile_cycle(offsets, force, N_critical: float, centred=False):
    """(amplitude, centre) of the limit cycle of the loop with the lateral force profile `force` (module docstring,
    "the window's staircase"): the first amplitude A at which the profile's describing function
    N_1(A) = −(2/A)·⟨F(B + A·sin θ)·sin θ⟩ falls through `N_critical` from above, the cycle's centre B making
    ⟨F(B + A·sin θ)⟩ = 0 (or B = 0 where `centred`). Amplitude 0 where N_1 never exceeds N* (no cycle), inf where
    it stays above N* up to half the profile's reach (the cycle leaves it); centre nan then. Where N_1 starts below
    N* (a smooth equilibrium beside the jump) and rises above it, the cycle is the stable one past that rise; the
    rise is an unstable cycle a disturbance must exceed (at a relay point, of the order of the distance to the jump).

    Parameters
    ----------
    offsets : ndarray, shape (n,)
        Lateral offsets of the profile from the path, m, equally spaced, increasing, about 0.
    force : ndarray, shape (m, n)
        The heading reference the robot steers to, F_n/F_t, at those offsets, per path (restoring: decreasing).
    N_critical : float
        The loop's critical lateral gain NV*/V, 1/m (> 0).
    centred : bool or ndarray of bool, shape (m,)
        The cycle is centred on the path (a path the robot took: its goal supplies the mean force), not on the
        position where the mean force vanishes (an equilibrium).
    """
    offsets = np.asarray(offsets, dtype=float)
    force = np.atleast_2d(np.asarray(force, dtype=float))
    m = force.shape[0]
    h = float(offsets[1] - offsets[0])
    half = int(min(-offsets[0], offsets[-1]) / 2 / h + 1e-9)
    amplitudes = np.arange(1, half + 1) * h
    centres = np.arange(-half, half + 1) * h
    mean_w, sine_w = _cycle_weights(offsets, amplitudes, centres)
    mean = (force @ mean_w).reshape(m, amplitudes.size, centres.size)  # ⟨F(u + A sin θ)⟩
    first = (force @ sine_w).reshape(m, amplitudes.size, centres.size)  # ⟨F(u + A sin θ)·sin θ⟩
    # the centre: the root of the decreasing mean force nearest the path (linear between the centres' grid)
    with np.errstate(invalid="ignore", divide="ignore"):
        down = (mean[..., :-1] >= 0) & (mean[..., 1:] < 0)
        frac = np.where(down, mean[..., :-1] / (mean[..., :-1] - mean[..., 1:]), np.nan)
        roots = centres[:-1] + h * frac
        pick = np.argmin(np.where(down, np.abs(roots), np.inf), axis=2)
        index = np.take_along_axis(np.where(down, np.arange(centres.size - 1), -1), pick[..., None], axis=2)[..., 0]
        fraction = np.take_along_axis(frac, pick[..., None], axis=2)[..., 0]
        centred = np.broadcast_to(np.asarray(centred, dtype=bool), (m,))[:, None]
        index = np.where(centred, half, index)
        fraction = np.where(centred, 0.0, fraction)
        ok = index >= 0
        j = np.clip(index, 0, centres.size - 2)
        at = lambda a: (np.take_along_axis(a, j[..., None], axis=2)[..., 0] * (1 - fraction)  # noqa: E731
                        + np.take_along_axis(a, j[..., None] + 1, axis=2)[..., 0] * fraction)
        N1 = np.where(ok, -2.0 / amplitudes * at(first), np.nan)
        centre = np.where(ok, centres[j] + h * fraction, np.nan)
        above = N1 > N_critical
    amplitude, where = np.full(m, np.inf), np.full(m, np.nan)
    for r in range(m):
        falls = np.flatnonzero(above[r, :-1] & (N1[r, 1:] <= N_critical))
        if not above[r].any():
            amplitude[r] = 0.0
        elif falls.size:
            k = falls[0]
            a, b = N1[r, k] - N_critical, N1[r, k + 1] - N_critical
            amplitude[r] = amplitudes[k] + h * a / (a - b)
            where[r] = centre[r, k] + (centre[r, k + 1] - centre[r, k]) * a / (a - b)
    return amplitude, where


def _cycle_weights(offsets, amplitudes, centres):
    """Weights (n, K·U) of the profile's points in ⟨F(u + A sin θ)⟩ and ⟨F(u + A sin θ)·sin θ⟩ (`CYCLE_NODES` phases,
    F linear between the points) for every amplitude A (K) and centre u (U)."""
    theta = (np.arange(CYCLE_NODES) + 0.5) * 2 * np.pi / CYCLE_NODES
    sine = np.sin(theta)
    h, n = float(offsets[1] - offsets[0]), offsets.size
    u = centres[None, :, None] + amplitudes[:, None, None] * sine[None, None, :]  # (K, U, Θ)
    f = np.clip((u - offsets[0]) / h, 0.0, n - 1.000001)
    k = np.floor(f).astype(int)
    w = f - k
    column = np.broadcast_to(np.arange(amplitudes.size * centres.size).reshape(amplitudes.size, centres.size, 1), u.shape)
    out = []
    for factor in (np.ones_like(sine), sine):
        weights = np.zeros((n, amplitudes.size * centres.size))
        scale = np.broadcast_to(factor / CYCLE_NODES, u.shape)
        np.add.at(weights, (k.ravel(), column.ravel()), ((1 - w) * scale).ravel())
        np.add.at(weights, (k.ravel() + 1, column.ravel()), (w * scale).ravel())
        out.append(weights)
    return out


def window_cycle(grid, law, x, y, tx, ty, s0, N_critical: float, reference=None):
    """Amplitude (m) of the limit cycle about the points p + s0·nrm from the describing function of the window's whole
    force profile (`profile_cycle`: the relay's jump and the staircase of the next cells' columns beside it), in the
    worse travel direction (the robot steers to F_n/(1 ± F_r·t)).

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
        Lateral offsets of the paths along nrm = (−ty, tx), m.
    N_critical : float
        The loop's critical lateral gain NV*/V, 1/m (> 0).
    reference : ndarray of bool, optional
        A path the robot took (`window_relay`): the cycle is centred on it.
    """
    x, y, tx, ty, s0 = (np.asarray(v, dtype=float) for v in (x, y, tx, ty, s0))
    if x.size == 0:
        return np.zeros(0)
    cells = int(round(CYCLE_REACH_CELLS / CYCLE_STEP_CELLS))
    offsets = np.arange(-cells, cells + 1) * CYCLE_STEP_CELLS * grid.cell_size
    n = offsets.size
    rep = lambda v: np.repeat(v, n)  # noqa: E731
    fn, ft = lateral_force(grid, law, rep(x), rep(y), rep(tx), rep(ty), (s0[:, None] + offsets[None, :]).ravel())
    fn, ft = fn.reshape(-1, n), ft.reshape(-1, n)
    centred = np.zeros(x.size, dtype=bool) if reference is None else np.asarray(reference, dtype=bool)
    out = np.zeros(x.size)
    for sign in (1.0, -1.0):  # forward along t, and back (F_n and s change sign together: the same profile)
        with np.errstate(divide="ignore", invalid="ignore"):
            heading = np.where(1 + sign * ft > 0, fn / (1 + sign * ft), np.nan)
        ok = np.isfinite(heading).all(axis=1)
        if ok.any():
            amplitude, _ = profile_cycle(offsets, heading[ok], N_critical, centred[ok])
            out[ok] = np.maximum(out[ok], amplitude)
    return out
