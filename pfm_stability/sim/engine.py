"""Batch engine: many robots advance together, one sampling period per step (docs/simulator.md; the `sampled` loop of docs/models.md).

Every member is a `Scenario`; members may differ in everything (robot,
controller, environment, target, T). The state of all members lives in
arrays of shape (B,), and one engine step is one sampling period of each
member (member m is at t = k·T_m after k steps).

One step, for every member still running (the `sampled` model, docs/models.md):

1. **Events** at t_k (`pfm_stability.sim.events`): collision — the first
   touch of an obstacle on the exact path from t_k−1 to t_k
   (`pfm_stability.sim.contact`), or an overlap at t_k — target reached,
   trapped. A member with an event stops.
2. **Sense** at t_k: repulsion from the active window's occupied cells
   (grid, KB eq 1–2) or the analytic walls' law; attraction (eq 3);
   δ_k = direction of R (eq 4).
3. **Compute** the held value: ``hold="command"``: u_k = sat(k·wrap(δ_k − θ_k))
   (eq 5, saturated at the steering-rate limit); ``hold="reference"``:
   δ̃_k = θ_k + wrap(δ_k − θ_k). With ``compute_delay = 1`` the value
   applied over [t_k, t_k+1) is the one computed at t_k−1 (at k = 0, the
   value computed at t_0: the robot starts as if it had been running, and
   every value "computed" before t_0 is u_0). With a dead time D the command
   reaches the motor at t_k + d·T + D = t_k + m·T + ε (`robot.delay_split`):
   a delay line of the computed values gives u_(k−m−1) for the first ε of the
   period and u_(k−m) for the rest. The speed is delayed by the compute delay
   only (the dead time is the steering motor's). A member with a yaw
   acceleration limit R passes each command through the drive's velocity
   smoother first (`robot.slew_limit`: at most R·T of change per period, from
   0 at the start), and the delay line carries its outputs: the command path
   (`robot.CommandPath`) is controller → saturation → smoother → compute delay and
   dead time → motor, one function whatever computed the command.
4. **Advance** over [t_k, t_k+1) exactly (`pfm_stability.sim.robot`):
   held command → constant-input solution of eq (6) with input g·u, in two
   intervals [t_k, t_k + ε) and [t_k + ε, t_k+1) when ε > 0, each with its
   own graded rule; held reference → servo solution of eq (7) with gain g·k
   (no dead time: `Scenario` refuses it). Saturation: a held command is
   clipped to ±ω_max before the gain, and since ω moves monotonically from
   ω_k towards g·u, |ω| <= g·ω_max stays exact. A servo whose command k(δ̃ − θ(t)) would exceed ±ω_max at the
   start, a quadrature node or the end of the period is instead advanced in
   `SUBSTEPS` equal sub-intervals, each either saturated (constant ±g·ω_max)
   or linear (servo), decided at its start — exact whenever the servo is not
   saturated, first-order in the sub-interval where it switches.
   Positions: the part linear in Δ = θ − θ_k in closed form, the residual by
   a composite Gauss–Legendre rule graded to the steering time scales
   (`pfm_stability.sim.robot`; a member's rule depends on its own (τ, k, T)
   only, so it advances the same in any batch to round-off: numpy's SIMD
   sin/cos/exp may round a member differently in arrays of other lengths, a
   few ULP per step, carried on by the loop — docs/simulator.md, "Batches").

Everything is numpy on (B,) or (B, K) arrays; the grid's window sums use
the precompiled occupied-cell lists of `pfm_stability.sim.window`.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..laws.force_law import PowerLaw
from ..parameters import TAU_RESOLUTION
from .contact import StepPath, chord_cell_gap, chord_wall_gap, first_contact, path_slack, point_cell_gap, point_wall_gap
from .environment import segment_clearance, wall_coordinates
from .events import Event
from .follow import PathFollower
from .metrics import oscillation_metrics
from .scenario import check_first_order
from .results import BatchResult, RunResult, Trajectory
from .robot import CommandPath, advance_held, advance_position, constant_input, constant_input_modes, delay_split, graded_rule, propagate, servo, servo_modes, slow_rate
from .vff import cell_repulsion, direction_of, steering_command, vff_speed, wrap_angle
from .window import compile_window_table, stack_tables

__all__ = ["run_batch", "SUBSTEPS", "RECORD_MODES"]

SUBSTEPS = 8
"""Sub-intervals per period for a saturated steering servo (``hold="reference"``)."""

RECORD_MODES = ("trajectory", "offset")


def _array(scenarios, getter, dtype=float):
    return np.array([getter(s) for s in scenarios], dtype=dtype)


class _Batch:
    """Member arrays and the compiled environments of a batch."""

    def __init__(self, scenarios):
        for s in scenarios:
            check_first_order(s.robot)
        self.scenarios = scenarios
        B = self.size = len(scenarios)
        robot = lambda name: _array(scenarios, lambda s: getattr(s.robot, name))
        ctrl = lambda name: _array(scenarios, lambda s: getattr(s.controller, name))
        self.V, self.tau, self.k, self.W = robot("V"), robot("tau"), robot("k"), robot("W")
        self.gain = robot("plant_gain")
        self.tau = np.where(self.tau * self.gain * self.k < TAU_RESOLUTION, 0.0, self.tau)  # an ideal motor, as the models take it
        self.max_rate = robot("max_steering_rate")
        self.n, self.T, self.f = ctrl("n"), ctrl("T"), ctrl("f")
        self.slew_step = robot("yaw_accel_limit") * self.T  # the velocity smoother's largest change per period, rad/s
        self.limited = np.isfinite(self.slew_step)
        self.any_limited = bool(self.limited.any())
        self.reference = _array(scenarios, lambda s: s.controller.hold == "reference", bool)
        self.delayed = _array(scenarios, lambda s: s.controller.compute_delay == 1, bool)
        self.lag, self.switch = delay_split(self.T, self.delayed.astype(np.int64), robot("dead_time"))
        self.speed_law = _array(scenarios, lambda s: s.speed_law, bool)
        self.damping = _array(scenarios, lambda s: s.damping)
        self.any_damping = bool(np.any(self.damping != 0.0))
        self.any_speed_law = bool(self.speed_law.any())
        self.steps = np.ceil(_array(scenarios, lambda s: s.duration) / self.T - 1e-9).astype(np.int64)
        self.split = self.switch > 0
        self.order = _array(scenarios, lambda s: s.loop_order(), np.int64)  # the sampled loop's state
        self.history = int(np.max(np.minimum(self.lag, self.steps))) + 2  # the delay line's length (`robot.DelayLine`)
        self.shared_lag = int(self.lag[0]) if self.lag.size and np.all(self.lag == self.lag[0]) else None
        self.any_split = bool(self.split.any())
        self.unit_gain = bool(np.all(self.gain == 1.0))
        self._compile_targets()
        self._compile_measure()
        self._compile_grids()
        self._compile_walls()
        self._compile_steering()
        self.all_command = self.command_idx.size == B
        self.uniform_n2 = bool(np.all(self.n == 2.0))

    # ----------------------------------------------------------- compilation
    def _compile_steering(self):
        """Steering coefficients and quadrature rules of the held-command and the servo members (`robot`).

        Held-command members whose command reaches the motor within a period
        (ε > 0, `robot.delay_split`) take two intervals, [0, ε) and [ε, T),
        each with its own coefficients and graded rule; the others one of length T.
        """
        slow = slow_rate(self.k, self.max_rate, self.gain)
        self.command_idx = c = np.flatnonzero(~self.reference)
        self.reference_idx = r = np.flatnonzero(self.reference)
        command_rule = lambda h, idx: constant_input(self.tau[idx], graded_rule(h, *constant_input_modes(self.tau[idx]), slow[idx]))
        self.whole_idx = np.flatnonzero(~self.split[c])  # positions within the command members
        self.split_idx = np.flatnonzero(self.split[c])
        whole, split = c[self.whole_idx], c[self.split_idx]
        self.command_coef = command_rule(self.T[whole], whole)
        self.before_coef = command_rule(self.switch[split], split)
        self.after_coef = command_rule(self.T[split] - self.switch[split], split)
        gk = self.gain[r] * self.k[r]  # the servo closes g·k(δ̃ − θ)
        modes = servo_modes(self.tau[r], gk)
        self.servo_coef = servo(self.tau[r], gk, graded_rule(self.T[r], *modes, slow[r]))
        both = tuple(np.concatenate(pair, axis=1) for pair in zip(modes, constant_input_modes(self.tau[r])))
        sub = graded_rule(self.T[r] / SUBSTEPS, *both, slow[r])  # shared: each sub-interval takes either solution
        self.servo_sub = servo(self.tau[r], gk, sub)
        self.saturated_sub = constant_input(self.tau[r], sub)

    def _compile_targets(self):
        s = self.scenarios
        self.point = _array(s, lambda m: m.target.is_point, bool)
        self.tx = _array(s, lambda m: m.target.x if m.target.is_point else 0.0)
        self.ty = _array(s, lambda m: m.target.y if m.target.is_point else 0.0)
        angle = _array(s, lambda m: 0.0 if m.target.is_point else m.target.angle)
        self.dx, self.dy = np.sin(angle), np.cos(angle)
        self.radius = _array(s, lambda m: m.target.radius)
        self.finish = _array(s, lambda m: math.inf if m.target.is_point or m.target.finish is None else m.target.finish)
        self.any_point = bool(self.point.any())
        self.follow_idx = np.flatnonzero([m.target.is_path for m in s])
        self.follower = PathFollower([s[m].target for m in self.follow_idx]) if self.follow_idx.size else None
        self.trap_time = _array(s, lambda m: m.trap_time)
        self.trap_distance = _array(s, lambda m: m.trap_distance)

    def _compile_measure(self):
        s = self.scenarios
        self.mox = _array(s, lambda m: m.measure.origin[0])
        self.moy = _array(s, lambda m: m.measure.origin[1])
        self.lat = np.array([m.measure.lateral_unit for m in s], dtype=float).reshape(-1, 2)
        self.along = np.array([m.measure.along_unit for m in s], dtype=float).reshape(-1, 2)
        self.along_from = _array(s, lambda m: m.measure.along_from)

    def _compile_grids(self):
        s = self.scenarios
        self.is_grid = _array(s, lambda m: m.env == "grid", bool)
        self.grid_idx = np.flatnonzero(self.is_grid)
        self.ratio = _array(s, lambda m: m.cell_ratio if m.env == "grid" else 0.0)
        if self.grid_idx.size == 0:
            self.table = None
            return
        keys = {}
        for i in self.grid_idx:
            keys.setdefault((id(s[i].environment), s[i].window_cells), []).append(i)
        tables, member_grid = [], np.zeros(self.size, dtype=np.int64)
        for g, (key, members) in enumerate(keys.items()):
            grid = s[members[0]].environment
            widths, steps = self.W[members], self.V[members] * self.T[members]
            tables.append(compile_window_table(grid, s[members[0]].window_cells, widths.min(), widths.max(), steps.max()))
            member_grid[members] = g
        self.table = stack_tables(tables)
        geo = [self.table.grids[g] for g in member_grid[self.grid_idx]]
        take = lambda name, dtype=float: np.array([getattr(q, name) for q in geo], dtype=dtype)
        self.g_offset, self.g_nx, self.g_ny, self.g_pad = (take(n, np.int64) for n in ("cell_offset", "nx_padded", "ny_padded", "pad"))
        self.g_xmin, self.g_ymin, self.g_c = take("x_min"), take("y_min"), take("cell_size")
        self.g_listed = take("listed_within")  # every cell within this of a robot cell's square is in its near list
        self.g_scale = self.ratio[self.grid_idx] * self.W[self.grid_idx] ** self.n[self.grid_idx]

    def _compile_walls(self):
        s = self.scenarios
        self.wall_idx = np.flatnonzero(~self.is_grid)
        if self.wall_idx.size == 0:
            return
        envs = [s[i].environment.arrays() for i in self.wall_idx]
        width = max(1, max(e["p0x"].size for e in envs))
        self.walls = {}
        for key in envs[0]:
            a = np.zeros((len(envs), width))
            for row, e in enumerate(envs):
                a[row, : e[key].size] = e[key]
            self.walls[key] = a
        valid = np.zeros((len(envs), width), dtype=bool)
        for row, e in enumerate(envs):
            valid[row, : e["p0x"].size] = True
        self.walls["valid"] = valid
        self.walls["length"] = np.where(valid, self.walls["length"], 0.0)
        self.walls["ux"] = np.where(valid, self.walls["ux"], 1.0)
        # lateral laws: None = KB's power law with the member's (f, n, W), vectorized
        laws = [s[i].law for i in self.wall_idx]
        self.law_groups = {}
        for row, law in enumerate(laws):
            if law is not None and not isinstance(law, PowerLaw):
                self.law_groups.setdefault(_law_key(law), (law, []))[1].append(row)
        custom = np.zeros(len(laws), dtype=bool)
        pf, pn, pW = self.f[self.wall_idx].copy(), self.n[self.wall_idx].copy(), self.W[self.wall_idx].copy()
        for row, law in enumerate(laws):
            if isinstance(law, PowerLaw):
                pf[row], pn[row], pW[row] = law.f, law.n, law.W
            elif law is not None:
                custom[row] = True
        self.power = (pf[:, None], pn[:, None], pW[:, None], ~custom)

    # --------------------------------------------------------------- forces
    def grid_rows(self, x, y, active):
        """Window-table row of each grid member's cell: 0 for inactive members, −1 where it is colliding."""
        gi = self.grid_idx
        i = np.floor((x[gi] - self.g_xmin) / self.g_c).astype(np.int64) + self.g_pad
        j = np.floor((y[gi] - self.g_ymin) / self.g_c).astype(np.int64) + self.g_pad
        inside = (i >= 0) & (i < self.g_nx) & (j >= 0) & (j < self.g_ny) & active[gi]
        rows = self.table.row_of_cell[np.where(inside, self.g_offset + i * self.g_ny + j, 0)]
        return np.where(inside, rows, 0)

    def sensing_rows(self, rows, running):
        """Rows for the window sums of the running members (0 for the others)."""
        rows = np.where(running[self.grid_idx], rows, 0)
        if np.any(rows < 0):  # unreachable cells imply a collision, which stopped the member
            raise RuntimeError(f"member {self.grid_idx[np.flatnonzero(rows < 0)[0]]} senses from a cell where it collides")
        return rows

    def grid_repulsion(self, x, y, rows):
        """(fx, fy)/F_ct of the grid members (KB eq 1–2)."""
        gi, t = self.grid_idx, self.table
        n = 2.0 if self.uniform_n2 else self.n[gi][:, None]
        fx, fy = cell_repulsion(x[gi][:, None], y[gi][:, None], t.wx[rows], t.wy[rows], t.wcv[rows], n)
        return self.g_scale * fx, self.g_scale * fy

    def wall_repulsion(self, x, y):
        """(fx, fy, goal)/F_ct of the analytic members.

        fx, fy: Σ law(d)·normal over the walls within their extent; goal:
        Σ law.goal_force(d), the part of the repulsion that points towards the
        target (Ge & Cui 2000's F_rep2; 0 for KB's and the grid's laws), which
        adds to the attraction's magnitude.
        """
        wi, w = self.wall_idx, self.walls
        s, d = wall_coordinates(w, x[wi][:, None], y[wi][:, None])
        acting = w["valid"] & (s >= 0) & (s <= w["length"]) & (d > 0)
        d_eval = np.where(acting, d, 1.0)
        pf, pn, pW, power_rows = self.power
        magnitude = np.zeros_like(d)
        goal = np.zeros_like(d)
        magnitude[power_rows] = (pf * (pW / d_eval) ** pn)[power_rows]
        for law, rows in self.law_groups.values():
            magnitude[rows] = law.force(d_eval[rows])
            goal[rows] = law.goal_force(d_eval[rows])
        magnitude = np.where(acting, magnitude, 0.0)
        goal = np.where(acting, goal, 0.0)
        return np.sum(magnitude * w["nx"], axis=1), np.sum(magnitude * w["ny"], axis=1), np.sum(goal, axis=1)

    def gaps(self, x, y, rows):
        """Clearance minus W/2 per member (m); +inf where no obstacle is near."""
        gap = np.full(self.size, math.inf)
        if self.grid_idx.size:
            for m in self.grid_idx[rows < 0]:  # in a cell where it cannot fit: exact clearance by brute force
                gap[m] = float(self.scenarios[m].clearance([x[m]], [y[m]])[0])
            near = rows > 0
            near[near] = self.table.near_count[rows[near]] > 0
            if np.any(near):
                g = self.grid_idx[near]
                cells = self.table.near[rows[near]]
                half = (self.g_c[near] / 2)[:, None]
                gx = np.maximum(np.abs(x[g][:, None] - self.table.ox[cells]) - half, 0.0)
                gy = np.maximum(np.abs(y[g][:, None] - self.table.oy[cells]) - half, 0.0)
                gap[g] = np.sqrt(np.min(gx * gx + gy * gy, axis=1)) - self.W[g] / 2
        if self.wall_idx.size:
            wi = self.wall_idx
            gap[wi] = segment_clearance(self.walls, x[wi][:, None], y[wi][:, None]) - self.W[wi] / 2
        return gap

    def attraction(self, x, y):
        """Unit vector towards the target (KB eq 3): a path target's carrot (`follow`)."""
        if not self.any_point:
            return self.dx, self.dy
        tx, ty = self.tx, self.ty
        if self.follower is not None:
            tx, ty = tx.copy(), ty.copy()
            tx[self.follow_idx], ty[self.follow_idx] = self.follower.carrot()
        rx, ry = tx - x, ty - y
        dist = np.hypot(rx, ry)
        safe = np.where(dist > 0, dist, 1.0)
        return np.where(self.point, rx / safe, self.dx), np.where(self.point, ry / safe, self.dy)

    def follow(self, x, y):
        """Move the path targets' progress to the robots' positions at t_k, m (`follow.PathFollower.advance`)."""
        if self.follower is not None:
            self.follower.advance(x[self.follow_idx], y[self.follow_idx])

    def target_distance(self, x, y):
        """Distance to point targets, m (0 for direction targets)."""
        if not self.any_point:
            return np.zeros(self.size)
        return np.where(self.point, np.hypot(self.tx - x, self.ty - y), 0.0)

    def progress(self, x, y, x0, y0, distance):
        """Progress towards the target, m: −distance (point), advance along the direction, or along the path."""
        out = np.where(self.point, -distance, (x - x0) * self.dx + (y - y0) * self.dy)
        if self.follower is not None:
            out[self.follow_idx] = self.follower.s
        return out


def _law_key(law):
    """Equal laws (frozen dataclasses) share one evaluation; others are grouped by identity."""
    try:
        hash(law)
        return law
    except TypeError:
        return id(law)


class _Recorder:
    """Per-sample storage: lateral offset along the measure axis, optionally the full state."""

    def __init__(self, batch: _Batch, trajectory: bool):
        shape = (batch.size, int(batch.steps.max()) + 1)
        self.batch = batch
        self.offset = np.zeros(shape)
        self.along = np.zeros(shape)
        self.full = trajectory
        if trajectory:
            self.x, self.y, self.theta = np.zeros(shape), np.zeros(shape), np.zeros(shape)

    def record(self, k, x, y, theta):
        b = self.batch
        rx, ry = x - b.mox, y - b.moy
        self.offset[:, k] = rx * b.lat[:, 0] + ry * b.lat[:, 1]
        self.along[:, k] = rx * b.along[:, 0] + ry * b.along[:, 1]
        if self.full:
            self.x[:, k], self.y[:, k], self.theta[:, k] = x, y, theta


def _start_state(scenarios):
    x, y, theta = (np.array([getattr(s.start, a) for s in scenarios], dtype=float) for a in ("x", "y", "theta"))
    for i, s in enumerate(scenarios):
        if s.start_jitter > 0:
            shift = np.random.default_rng(s.seed).normal(0.0, s.start_jitter)
            x[i] += shift * math.cos(theta[i])
            y[i] -= shift * math.sin(theta[i])
    return x, y, theta


def _advance_commands(b, theta, omega, earlier, later, V, x, y):
    """The held-command members over one period: motor input g·u, the split members in two intervals (ε, T − ε).

    `earlier` and `later` are the commands the motor sees before and after the switch (rad/s, per command member).
    """
    w, s = b.whole_idx, b.split_idx
    if s.size == 0 and b.unit_gain:  # KB's motor: the command itself (no product, as before g and D)
        return advance_held(b.command_coef, theta, omega, later, V, x, y)
    g = b.gain[b.command_idx]
    if s.size == 0:
        return advance_held(b.command_coef, theta, omega, g * later, V, x, y)
    x_new, y_new, th_new, om_new = x.copy(), y.copy(), theta.copy(), omega.copy()
    if w.size:
        x_new[w], y_new[w], th_new[w], om_new[w] = advance_held(b.command_coef, theta[w], omega[w], g[w] * later[w], V[w], x[w], y[w])
    xs, ys, ts, os_ = advance_held(b.before_coef, theta[s], omega[s], g[s] * earlier[s], V[s], x[s], y[s])
    x_new[s], y_new[s], th_new[s], om_new[s] = advance_held(b.after_coef, ts, os_, g[s] * later[s], V[s], xs, ys)
    return x_new, y_new, th_new, om_new


def _advance_reference(b, theta, omega, ref, V, x, y):
    """Servo members over one period; saturated ones in SUBSTEPS sub-intervals (returned: which, bool per member).

    The servo closes g·k(δ̃ − θ); a saturated sub-interval holds g·clip(k(δ̃ − θ), ±ω_max).
    """
    r = b.reference_idx
    k, wmax, g = b.k[r], b.max_rate[r], b.gain[r]
    delta, correction, theta_end, omega_end = propagate(b.servo_coef, theta, omega, ref)
    x_new, y_new = advance_position(x, y, V, b.servo_coef.rule, theta, delta, correction)
    heading = np.concatenate([theta[:, None], theta[:, None] + delta, theta_end[:, None]], axis=1)
    sat = np.any(np.abs(k[:, None] * (ref[:, None] - heading)) > wmax[:, None], axis=1)
    if np.any(sat):
        s = np.flatnonzero(sat)
        th, om, xs, ys = theta[s], omega[s], x[s], y[s]
        lin, cst = b.servo_sub.take(s), b.saturated_sub.take(s)
        for _ in range(SUBSTEPS):
            u = k[s] * (ref[s] - th)
            clipped = np.abs(u) > wmax[s]
            d1, c1, e1, o1 = propagate(lin, th, om, ref[s])
            d2, c2, e2, o2 = propagate(cst, th, om, g[s] * np.clip(u, -wmax[s], wmax[s]))
            d, c = np.where(clipped[:, None], d2, d1), np.where(clipped, c2, c1)
            xs, ys = advance_position(xs, ys, V[s], lin.rule, th, d, c)
            th, om = np.where(clipped, e2, e1), np.where(clipped, o2, o1)
        x_new[s], y_new[s], theta_end[s], omega_end[s] = xs, ys, th, om
    return x_new, y_new, theta_end, omega_end, sat


def run_batch(scenarios, *, record: str = "trajectory", metrics: bool = True, progress=None) -> BatchResult:
    """Simulate every scenario of `scenarios` together.

    Parameters
    ----------
    scenarios : sequence of Scenario
    record : {"trajectory", "offset"}
        Keep every sample's (x, y, θ), or only the lateral offset needed by
        the metrics (less memory for large batches).
    metrics : bool
        Compute the oscillation metrics of each member (docs/simulator.md, measuring oscillation); if
        False, each run's ``metrics`` is None (for timing and sweeps of events).
    progress : callable, optional
        ``progress(step, total)`` is called every 1024 engine steps and once at
        the end (step = samples done by the longest member, total = its
        samples); for progress bars.

    Returns
    -------
    BatchResult
    """
    from ..checks import check_choice

    check_choice("record", record, RECORD_MODES)
    scenarios = list(scenarios)
    if not scenarios:
        raise ValueError("scenarios must hold at least one Scenario")
    b = _Batch(scenarios)
    B = b.size
    x, y, theta = _start_state(scenarios)
    x0, y0 = x.copy(), y.copy()
    omega = np.zeros(B)
    alive = np.ones(B, dtype=bool)
    line = CommandPath(B, b.history, b.slew_step if b.any_limited else None)
    pending_V = b.V.copy()
    best = b.progress(x, y, x0, y0, b.target_distance(x, y))
    best_t = np.zeros(B)
    last_gap = np.full(B, math.inf)
    min_gap = np.full(B, math.inf)
    done_steps = np.zeros(B, dtype=np.int64)
    events = [None] * B
    rec = _Recorder(b, record == "trajectory")
    rec.record(0, x, y, theta)
    started = time.perf_counter()
    k = 0
    max_steps = int(b.steps.max())
    step = None  # the last period's start, for the collision check along the path
    while True:
        due = alive & (k <= b.steps)
        done_steps[due] = k
        rows = b.grid_rows(x, y, due) if b.grid_idx.size else None
        gap = b.gaps(x, y, rows) if rows is not None or b.wall_idx.size else np.full(B, math.inf)
        if step is not None:
            for m, contact in _swept_contacts(b, step, x, y, gap).items():
                events[m] = Event("collision", float((k - 1) * b.T[m] + contact.t), contact.x, contact.y)
                alive[m] = False
                min_gap[m] = min(min_gap[m], contact.gap)
            due &= alive
        b.follow(x, y)
        _check_events(b, k, x, y, x0, y0, gap, due, alive, events, best, best_t, last_gap)
        np.minimum(min_gap, last_gap, out=min_gap)
        running = due & alive & (k < b.steps)
        if k == max_steps or not running.any():
            break
        if rows is not None:
            rows = b.sensing_rows(rows, running)
        # sense (KB eq 1–4)
        fx, fy, pull = np.zeros(B), np.zeros(B), np.ones(B)
        if rows is not None:
            fx[b.grid_idx], fy[b.grid_idx] = b.grid_repulsion(x, y, rows)
        if b.wall_idx.size:
            fx[b.wall_idx], fy[b.wall_idx], goal = b.wall_repulsion(x, y)
            pull[b.wall_idx] += goal
        ax, ay = b.attraction(x, y)
        if b.any_damping:  # a velocity-dependent field: −β·v, v = V(sin θ, cos θ)
            fx, fy = fx - b.damping * b.V * np.sin(theta), fy - b.damping * b.V * np.cos(theta)
        delta = direction_of(fx + pull * ax, fy + pull * ay)
        # compute the held value (eq 5) and the speed
        value = np.where(b.reference, theta + wrap_angle(delta - theta), steering_command(delta, theta, b.k, b.max_rate))
        speed = np.where(b.speed_law, vff_speed(b.V, fx, fy, theta), b.V) if b.any_speed_law else b.V
        if k == 0:
            pending_V = speed
        line.push(k, value)
        applied = line.back(k, b.shared_lag if b.shared_lag is not None else b.lag)  # the motor's input after the switch
        earlier = line.back(k, b.lag + 1) if b.any_split else applied  # and before it (only split members read it)
        applied_V = np.where(b.delayed, pending_V, speed)
        pending_V = speed
        # advance over [t_k, t_k+1)
        substepped = np.zeros(B, dtype=bool)
        if b.all_command:
            x_new, y_new, th_new, om_new = _advance_commands(b, theta, omega, earlier, applied, applied_V, x, y)
        else:
            x_new, y_new, th_new, om_new = x.copy(), y.copy(), theta.copy(), omega.copy()
            c, r = b.command_idx, b.reference_idx
            if c.size:
                x_new[c], y_new[c], th_new[c], om_new[c] = _advance_commands(b, theta[c], omega[c], earlier[c], applied[c], applied_V[c], x[c], y[c])
            if r.size:
                x_new[r], y_new[r], th_new[r], om_new[r], substepped[r] = _advance_reference(b, theta[r], omega[r], applied[r], applied_V[r], x[r], y[r])
        step = dict(running=running, x=x, y=y, theta=theta, omega=omega, value=applied, earlier=earlier, V=applied_V, gap=gap, rows=rows,
                    substepped=substepped)
        x, y = np.where(running, x_new, x), np.where(running, y_new, y)
        theta, omega = np.where(running, th_new, theta), np.where(running, om_new, omega)
        k += 1
        rec.record(k, x, y, theta)
        if k % 64 == 0:
            _check_finite(x, y, theta, omega, k, b)
        if progress is not None and k % 1024 == 0:
            progress(k, max_steps)
    seconds = time.perf_counter() - started
    _check_finite(x, y, theta, omega, k, b)
    if progress is not None:
        progress(max_steps, max_steps)
    runs = tuple(_member_result(b, rec, m, int(done_steps[m]), events[m], metrics, float(min_gap[m])) for m in range(B))
    return BatchResult(runs, int(done_steps.sum()), seconds)


def _swept_contacts(b, step, x, y, gap) -> dict:
    """Members whose disc touched an obstacle on their exact path over the last period: {member: Contact}.

    `step` holds the period's start (positions, heading, rate, held values
    before and after the dead time's switch, speed, gaps, grid rows, sub-stepped servos). A member is cleared by the
    Lipschitz bound on its gaps at both ends, then by its chord
    (`pfm_stability.sim.contact`); the rest are searched along the path with
    `first_contact`. Gaps are lower bounds: a grid member's near list holds
    every cell within `g_listed` of its cell's square, so farther cells are
    at least that far.
    """
    stepped = step["running"]
    length = step["V"] * b.T
    low_start, low_end = step["gap"].copy(), gap.copy()
    if b.grid_idx.size:
        gi = b.grid_idx
        unlisted = b.g_listed - b.W[gi] / 2
        low_start[gi], low_end[gi] = np.minimum(low_start[gi], unlisted), np.minimum(low_end[gi], unlisted)
    suspect = stepped & ~(low_start + low_end > length)
    if not suspect.any():
        return {}
    ax, ay = step["x"], step["y"]
    chord = np.full(b.size, -math.inf)  # the chords' clearance where known (−inf: search the path)
    if b.wall_idx.size:
        pick = suspect[b.wall_idx]
        w = b.wall_idx[pick]
        walls = {key: value[pick] for key, value in b.walls.items()}
        chord[w] = chord_wall_gap(walls, *(v[w][:, None] for v in (ax, ay, x, y)))
    if b.grid_idx.size:
        listed = b.W[b.grid_idx] / 2 + length[b.grid_idx] < b.g_listed  # the near list holds every reachable cell
        pick = suspect[b.grid_idx] & listed
        g = b.grid_idx[pick]
        cells = b.table.near[step["rows"][pick]]
        near = chord_cell_gap(b.table.ox[cells], b.table.oy[cells], b.g_c[pick][:, None] / 2, *(v[g][:, None] for v in (ax, ay, x, y)))
        chord[g] = np.minimum(near, b.g_listed[pick] - length[g])
    slack = path_slack(length, np.hypot(x - ax, y - ay))
    contacts = {}
    for m in np.flatnonzero(suspect & ~(chord - b.W / 2 > slack)):
        path = StepPath(
            float(b.tau[m]), float(b.k[m]), float(b.max_rate[m]), float(b.T[m]), bool(b.reference[m]), bool(step["substepped"][m]),
            SUBSTEPS, float(step["theta"][m]), float(step["omega"][m]), float(step["value"][m]), float(step["V"][m]),
            float(ax[m]), float(ay[m]), gain=float(b.gain[m]), switch=float(b.switch[m]), earlier=float(step["earlier"][m]),
        )
        contact = first_contact(path, (float(x[m]), float(y[m])), *_obstacles(b, step, m, float(length[m])), float(b.W[m]) / 2)
        if contact is not None:
            contacts[int(m)] = contact
    return contacts


def _obstacles(b, step, m, length):
    """(clearance of points, clearance of chords) of member m's obstacles near its last period, as functions of arrays (m).

    Analytic walls: all of them, exactly. Grid: the near list of the cell the
    period started in when it holds every cell the disc can reach
    (W/2 + ℓ < `g_listed`; farther cells are then at least g_listed − ℓ
    away from any point of the path), else every occupied cell of the grid.
    """
    if not b.is_grid[m]:
        row = int(np.searchsorted(b.wall_idx, m))
        walls = {key: value[row] for key, value in b.walls.items()}
        return (lambda px, py: point_wall_gap(walls, px[:, None], py[:, None]),
                lambda ax, ay, bx, by: chord_wall_gap(walls, ax[:, None], ay[:, None], bx[:, None], by[:, None]))
    g = int(np.searchsorted(b.grid_idx, m))
    half = float(b.g_c[g]) / 2
    if b.W[m] / 2 + length < b.g_listed[g]:
        row = int(step["rows"][g])
        cells = b.table.near[row][: b.table.near_count[row]]
        cx, cy, floor = b.table.ox[cells], b.table.oy[cells], float(b.g_listed[g]) - length
    else:
        cx, cy, _ = b.scenarios[m].environment.occupied()
        floor = math.inf
    return (lambda px, py: np.minimum(point_cell_gap(cx, cy, half, px[:, None], py[:, None]), floor),
            lambda ax, ay, bx, by: np.minimum(chord_cell_gap(cx, cy, half, ax[:, None], ay[:, None], bx[:, None], by[:, None]), floor))


def _check_events(b, k, x, y, x0, y0, gap, due, alive, events, best, best_t, last_gap):
    """Collision (an overlap at t_k: at the start, or one the path check missed), target reached, trapped at t_k
    for the members due a check (in that priority)."""
    t = k * b.T
    hit = due & (gap <= 0)
    distance = b.target_distance(x, y)
    prog = b.progress(x, y, x0, y0, distance)
    reached = due & ~hit & np.where(b.point, distance <= b.radius, prog >= b.finish)
    improved = prog >= best + b.trap_distance
    best[improved] = prog[improved]
    best_t[improved] = t[improved]
    trapped = due & ~hit & ~reached & (t - best_t > b.trap_time)
    for m in np.flatnonzero(hit | reached | trapped):
        if hit[m]:
            g0 = last_gap[m]
            frac = g0 / (g0 - gap[m]) if math.isfinite(g0) and g0 > 0 and k > 0 else 1.0
            events[m] = Event("collision", float((k - 1 + frac) * b.T[m]) if k > 0 else 0.0, float(x[m]), float(y[m]))
        else:
            events[m] = Event("target_reached" if reached[m] else "trapped", float(t[m]), float(x[m]), float(y[m]))
        alive[m] = False
    last_gap[:] = np.where(due, gap, last_gap)


def _check_finite(x, y, theta, omega, k, b):
    bad = ~(np.isfinite(x) & np.isfinite(y) & np.isfinite(theta) & np.isfinite(omega))
    if np.any(bad):
        m = int(np.flatnonzero(bad)[0])
        raise FloatingPointError(f"member {m} ({b.scenarios[m].name}) reached a non-finite state at step {k}")


def _member_result(b, rec, m, steps, event, want_metrics, min_gap) -> RunResult:
    n = steps + 1
    T = float(b.T[m])
    t = np.arange(n) * T
    window = rec.along[m, :n] >= b.along_from[m]
    if np.any(window):
        window[np.argmax(window):] = True  # from the first sample past the start of the window
    offset_t, offset = t[window], rec.offset[m, :n][window]
    collision = event.t if event is not None and event.type == "collision" else None
    if want_metrics:
        metrics = oscillation_metrics(offset_t, offset, T, order=int(b.order[m]), collision_time=collision)
    else:
        metrics = None
    trajectory = None
    if rec.full:
        trajectory = Trajectory(t, rec.x[m, :n].copy(), rec.y[m, :n].copy(), rec.theta[m, :n].copy())
    events = (event,) if event is not None else ()
    clearance = min_gap if math.isfinite(min_gap) else None
    return RunResult(b.scenarios[m], events, metrics, steps * T, steps, offset_t, offset.copy(), clearance, trajectory)
