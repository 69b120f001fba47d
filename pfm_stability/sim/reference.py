"""A plain per-robot Python loop of the same model: the benchmark baseline and an independent check.

`simulate_reference` runs one `Scenario` step by step with Python floats and
the `math` module: the active window is cut out of the histogram grid and its
occupied cells are summed in a Python loop (KB eq 1–2), the analytic walls
likewise; the steering solutions (KB eq 6–7) are the same closed forms as in
`pfm_stability.sim.robot`, written out per robot. Positions take the same
route (∫Δ dt exact, the residuals sin Δ − Δ and cos Δ − 1 by quadrature on
the rule of `robot.graded_rule`, the one piece shared), written out as sums
of the residuals; for the servo ∫Δ dt comes from Van Loan's block exponential
expm([[A, I], [0, 0]]h) = [[exp(Ah), ∫₀ʰ exp(At) dt], [0, I]] (scipy), not
from the engine's closed form. It shares no stepping code with the batch
engine, so the tests compare the two trajectories (`tests/test_sim_engine.py`,
`tests/test_sim_accuracy.py`), and `benchmarks/bench_simulator.py` times both.

The plant gain g and dead time D (docs/simulator.md, "Plant gain and dead
time") take the route of the model, not of the engine's arrays: a list of the
values computed so far, the motor's input g·u_(k−m−1) for the first ε of a
period and g·u_(k−m) after (m and ε: `robot.delay_split`, the one rule), each
piece its own `_Steering` interval; the servo closes g·k(δ̃ − θ). A yaw
acceleration limit R passes each held command through the velocity smoother
written out with Python floats (v = v + min(max(u − v, −R·T), R·T), from 0)
before the list.

Collisions between samples take their own route too: a period that starts
within its length V·T of an obstacle (the only ones the disc can touch) is
walked at `PATH_SAMPLES` instants, each position computed afresh from the
period's start (a new `_Steering` of that length), and the first instant that
overlaps is narrowed by `solve.bisect_root` on the clearance (the engine:
chords and a batched bisection, `pfm_stability.sim.contact`).
"""

from __future__ import annotations

import math

import numpy as np

from ..laws.force_law import PowerLaw
from ..parameters import TAU_RESOLUTION
from ..numerics.solve import bisect_root
from .engine import SUBSTEPS
from .events import Event
from .grid import HistogramGrid
from .results import Trajectory
from .robot import constant_input_modes, delay_split, graded_rule, servo_modes, slow_rate
from .scenario import Scenario, check_first_order

__all__ = ["simulate_reference", "PATH_SAMPLES"]

PATH_SAMPLES = 32
"""Instants at which a period that may touch an obstacle is walked (its end included)."""


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _constant_input(tau, t):
    """(a, decay) of θ = θ₀ + aω₀ + (t − a)u, ω = decay·ω₀ + (1 − decay)u."""
    if tau > 0:
        return -tau * math.expm1(-t / tau), math.exp(-t / tau)
    return 0.0, 0.0


def _servo_matrix(tau, k, t):
    """exp(A t) for (e, ω), A = [[0, 1], [−k/τ, −1/τ]] (τ = 0: e decays as e^(−kt))."""
    if tau > 0:
        from scipy.linalg import expm

        E = expm(np.array([[0.0, 1.0], [-k / tau, -1.0 / tau]]) * t)
        return tuple(float(v) for v in E.ravel())
    d = math.exp(-k * t)
    return (d, 0.0, -k * d, 0.0)


def _servo_integral(tau, k, h):
    """(∫P, ∫Q) over [0, h], the first row of ∫₀ʰ exp(At) dt (Van Loan's block exponential; τ = 0: ∫e^(−kt))."""
    if tau > 0:
        from scipy.linalg import expm

        M = np.zeros((4, 4))
        M[:2, :2] = [[0.0, 1.0], [-k / tau, -1.0 / tau]]
        M[:2, 2:] = np.eye(2)
        F = expm(M * h)
        return float(F[0, 2]), float(F[0, 3])
    return -math.expm1(-k * h) / k, 0.0


def _steering_rule(tau, k, h, max_rate, solutions, gain=1.0):
    """(node times, weights) of `robot.graded_rule` for one robot, resolving the modes of `solutions` (the servo's with g·k)."""
    one = lambda v: np.array([float(v)])
    found = {"constant": constant_input_modes(one(tau)), "servo": servo_modes(one(tau), one(gain * k))}
    modes = tuple(np.concatenate(part, axis=1) for part in zip(*(found[name] for name in solutions)))
    slow = slow_rate(one(k), one(max_rate), gain)
    rule = graded_rule(one(h), *modes, slow)
    return rule.t[0].tolist(), rule.w[0].tolist()


class _Steering:
    """Per-robot closed-form steering over one hold interval.

    `solutions` names the solutions used over the interval, "constant"
    (held command) and/or "servo" (held reference); the quadrature rule
    resolves all of them. The servo closes g·k(δ̃ − θ) (`gain` g); `constant`
    takes the motor's input (g·u).
    """

    def __init__(self, tau, k, h, max_rate, solutions, gain=1.0):
        self.tau, self.k, self.h = tau, gain * k, h
        self.gain, self.command_gain = gain, k  # the servo command k(ref − θ) is clipped before the plant gain
        self.times, self.weights = _steering_rule(tau, k, h, max_rate, solutions, gain)
        self.const = [_constant_input(tau, t) for t in self.times + [h]]
        lagged = tau * (h - self.const[-1][0])
        self.const_integral = (lagged, h * h / 2 - lagged)
        if "servo" in solutions:
            self.servo = [_servo_matrix(tau, gain * k, t) for t in self.times + [h]]
            self.servo_integral = _servo_integral(tau, gain * k, h)

    def constant(self, theta, omega, u):
        """(Δ at the nodes, ∫Δ dt, θ at the end, ω at the end) for a held command u."""
        delta = [a * omega + (t - a) * u for (a, _), t in zip(self.const, self.times)]
        a, decay = self.const[-1]
        iw, iu = self.const_integral
        return delta, iw * omega + iu * u, theta + a * omega + (self.h - a) * u, decay * omega + (1 - decay) * u

    def reference(self, theta, omega, ref):
        """(Δ at the nodes, ∫Δ dt, θ at the end, ω at the end) for a held reference, the servo closed."""
        e = theta - ref
        delta = [(P - 1) * e + Q * omega for P, Q, _, _ in self.servo[:-1]]
        P, Q, R, S = self.servo[-1]
        iP, iQ = self.servo_integral
        return delta, (iP - self.h) * e + iQ * omega, ref + P * e + Q * omega, R * e + S * omega

    def servo_step(self, x, y, V, theta, omega, ref, max_rate):
        """(x, y, θ, ω) at the end of the interval for a held reference whose servo command k(ref − θ) is taken at
        its start and saturated at ±`max_rate` (the constant command then) — one substep of a saturating servo."""
        u = self.command_gain * (ref - theta)
        if abs(u) > max_rate:  # the motor turns at g times the clipped command
            nodes, integral, theta_end, omega_end = self.constant(theta, omega, self.gain * min(max(u, -max_rate), max_rate))
        else:
            nodes, integral, theta_end, omega_end = self.reference(theta, omega, ref)
        x, y = self.move(x, y, V, theta, nodes, integral)
        return x, y, theta_end, omega_end

    def move(self, x, y, V, theta, delta, integral):
        """x + V∫sin θ, y + V∫cos θ: ∫Δ exact, the residuals sin Δ − Δ and cos Δ − 1 by quadrature."""
        across, along = integral, self.h
        for w, d in zip(self.weights, delta):
            across += w * (math.sin(d) - d)
            along += w * (math.cos(d) - 1.0)
        s0, c0 = math.sin(theta), math.cos(theta)
        return x + V * (s0 * along + c0 * across), y + V * (c0 * along - s0 * across)


def _grid_sense(s: Scenario, x, y):
    """(fx, fy, clearance − W/2) from the occupied cells of the window around (x, y)."""
    g: HistogramGrid = s.environment
    c, h = g.cell_size, s.window_cells // 2
    i, j = (int(v) for v in g.cell_index(x, y))
    nx, ny = g.shape
    i0, i1, j0, j1 = max(i - h, 0), min(i + h + 1, nx), max(j - h, 0), min(j + h + 1, ny)
    fx = fy = 0.0
    gap = math.inf
    if i0 < i1 and j0 < j1:
        ii, jj = np.nonzero(g.cv[i0:i1, j0:j1])
        n, W = s.controller.n, s.robot.W
        for a, b in zip(ii.tolist(), jj.tolist()):
            cx, cy = g.x_min + (i0 + a + 0.5) * c, g.y_min + (j0 + b + 0.5) * c
            dx, dy = x - cx, y - cy
            d = math.hypot(dx, dy)
            weight = s.cell_ratio * float(g.cv[i0 + a, j0 + b]) * W**n / d ** (n + 1)
            fx += weight * dx
            fy += weight * dy
            gx, gy = max(abs(dx) - c / 2, 0.0), max(abs(dy) - c / 2, 0.0)
            gap = min(gap, math.hypot(gx, gy))
    return fx, fy, gap - s.robot.W / 2, 0.0


def _wall_sense(s: Scenario, x, y):
    law = s.effective_law()
    fx = fy = goal = 0.0
    gap = math.inf
    for w in s.environment.walls:
        (ux, uy), (nx, ny) = w.unit, w.normal
        sx, sy = x - w.p0[0], y - w.p0[1]
        along, d = sx * ux + sy * uy, sx * nx + sy * ny
        if 0 <= along <= w.length and d > 0:
            if isinstance(law, PowerLaw):
                F = law.f * (law.W / d) ** law.n
            else:
                F = float(law.force(d))
            fx += F * nx
            fy += F * ny
            goal += float(law.goal_force(d))  # towards the target (Ge & Cui's F_rep2; 0 for KB's laws)
        outside = max(-along, along - w.length, 0.0)
        gap = min(gap, math.hypot(outside, d))
    return fx, fy, gap - s.robot.W / 2, goal


def _position_after(s, tau, t, theta, omega, applied, V, x, y, substepped, switch=0.0, earlier=0.0):
    """(x, y) t seconds into a period that starts at (x, y, θ, ω) with `applied` held (`simulate_reference`'s motion).

    A held command whose dead time ends at `switch` (ε > 0) holds `earlier` before it; commands are before the plant gain.
    """
    k, wmax, T, g = s.robot.k, s.robot.max_steering_rate, s.controller.T, s.robot.plant_gain
    if s.controller.hold == "command":
        if 0 < switch < t:
            first = _Steering(tau, k, switch, wmax, ("constant",), g)
            nodes, integral, theta2, omega2 = first.constant(theta, omega, g * earlier)
            x, y = first.move(x, y, V, theta, nodes, integral)
            t, theta, omega = t - switch, theta2, omega2
        else:
            applied = earlier if switch > 0 else applied
        one = _Steering(tau, k, t, wmax, ("constant",), g)
        nodes, integral, _, _ = one.constant(theta, omega, g * applied)
        return one.move(x, y, V, theta, nodes, integral)
    if not substepped:
        one = _Steering(tau, k, t, wmax, ("servo",), g)
        nodes, integral, _, _ = one.reference(theta, omega, applied)
        return one.move(x, y, V, theta, nodes, integral)
    part = T / SUBSTEPS
    whole = min(int(t // part), SUBSTEPS - 1)
    for length in [part] * whole + [t - whole * part]:
        if length <= 0:
            break
        x, y, theta, omega = _Steering(tau, k, length, wmax, ("servo", "constant"), g).servo_step(x, y, V, theta, omega, applied, wmax)
    return x, y


def _path_contact(s, sense, tau, start, applied, V, substepped, gap_start, switch=0.0, earlier=0.0):
    """The first instant (s into the period) and place where the disc touches an obstacle, or None."""
    x, y, theta, omega = start
    T = s.controller.T
    if s.env == "grid":  # the window's cells only: those beyond it are at least h·c away
        gap_start = min(gap_start, (s.window_cells // 2) * s.environment.cell_size - s.robot.W / 2)
    if gap_start > V * T:  # the clearance is 1-Lipschitz: no point of a path of length V·T gets closer
        return None
    gap_at = lambda t: sense(s, *_position_after(s, tau, t, theta, omega, applied, V, x, y, substepped, switch, earlier))[2]
    before = 0.0
    for i in range(1, PATH_SAMPLES + 1):
        t = T * i / PATH_SAMPLES
        if gap_at(t) <= 0:
            hit = bisect_root(gap_at, before, t, rtol=1e-14)
            return (hit, *_position_after(s, tau, hit, theta, omega, applied, V, x, y, substepped, switch, earlier))
        before = t
    return None


def _path_progress(path, lookahead, along, x, y):
    """A path target's progress (m): the arc of the nearest point of the path within arc [along, along + lookahead]
    from (x, y), m, never less than `along` (the rule of `sim.follow`, walked segment by segment)."""
    best, best_arc, start = math.inf, along, 0.0
    for (ax, ay), (bx, by) in zip(path[:-1], path[1:]):
        length = math.hypot(bx - ax, by - ay)
        if length > 0 and start + length >= along and start <= along + lookahead:
            u = ((x - ax) * (bx - ax) + (y - ay) * (by - ay)) / (length * length)
            u = min(max(u, (along - start) / length, 0.0), (along + lookahead - start) / length, 1.0)
            d = math.hypot(ax + u * (bx - ax) - x, ay + u * (by - ay) - y)
            if d < best:
                best, best_arc = d, start + u * length
        start += length
    return max(along, best_arc)


def _path_point(path, arc):
    """The point of the polyline `path` at `arc` m from its start (its end beyond)."""
    for (ax, ay), (bx, by) in zip(path[:-1], path[1:]):
        length = math.hypot(bx - ax, by - ay)
        if arc <= length:
            return ax + arc / length * (bx - ax), ay + arc / length * (by - ay)
        arc -= length
    return path[-1]


def simulate_reference(s: Scenario):
    """Run one scenario in a per-robot Python loop.

    Parameters
    ----------
    s : Scenario
        The scenario to run.

    Returns
    -------
    (Trajectory, Event or None)
    """
    check_first_order(s.robot)
    r, c = s.robot, s.controller
    T, k, wmax, g = c.T, r.k, r.max_steering_rate, r.plant_gain
    sense = _grid_sense if s.env == "grid" else _wall_sense
    servo = c.hold == "reference"
    tau = r.tau if r.tau * g * k >= TAU_RESOLUTION else 0.0  # an ideal motor, as the engine and the models take it
    lag, switch = (float(v[0]) for v in delay_split(np.array([T]), np.array([c.compute_delay]), np.array([r.dead_time])))
    lag = int(lag)
    full = _Steering(tau, k, T, wmax, ("servo",) if servo else ("constant",), g)
    sub = _Steering(tau, k, T / SUBSTEPS, wmax, ("servo", "constant"), g) if servo else None
    if switch > 0:  # the dead time ends within the period: two intervals of the held command
        before, after = _Steering(tau, k, switch, wmax, ("constant",), g), _Steering(tau, k, T - switch, wmax, ("constant",), g)
    computed = []  # every value computed so far (with a yaw acceleration limit, the smoother's outputs); before t_0, u_0
    smoothed = 0.0
    x, y, theta = s.start.x, s.start.y, s.start.theta
    if s.start_jitter > 0:
        shift = float(np.random.default_rng(s.seed).normal(0.0, s.start_jitter))
        x, y = x + shift * math.cos(theta), y - shift * math.sin(theta)
    x0, y0 = x, y
    omega = 0.0
    tgt = s.target
    steps = math.ceil(s.duration / T - 1e-9)
    xs, ys, ths = [x], [y], [theta]
    pending_V = None
    best, best_t, last_gap = None, 0.0, math.inf
    event = None
    along = 0.0  # a path target's progress, m
    for step in range(steps + 1):
        t = step * T
        fx, fy, gap, goal = sense(s, x, y)
        distance = math.hypot(tgt.x - x, tgt.y - y) if tgt.is_point else 0.0
        if tgt.is_path:
            along = _path_progress(tgt.path, tgt.lookahead, along, x, y)
            progress = along
        else:
            progress = -distance if tgt.is_point else (x - x0) * math.sin(tgt.angle) + (y - y0) * math.cos(tgt.angle)
        if best is None:
            best = progress
        if progress >= best + s.trap_distance:
            best, best_t = progress, t
        if gap <= 0:
            frac = last_gap / (last_gap - gap) if math.isfinite(last_gap) and last_gap > 0 and step > 0 else 1.0
            event = Event("collision", (step - 1 + frac) * T if step > 0 else 0.0, x, y)
        elif (distance <= tgt.radius) if tgt.is_point else (tgt.finish is not None and progress >= tgt.finish):
            event = Event("target_reached", t, x, y)
        elif t - best_t > s.trap_time:
            event = Event("trapped", t, x, y)
        last_gap = gap
        if event is not None or step == steps:
            break
        if tgt.is_path:
            cx, cy = _path_point(tgt.path, along + tgt.lookahead)
            reach = math.hypot(cx - x, cy - y)
            ax, ay = ((cx - x) / reach, (cy - y) / reach) if reach > 0 else (0.0, 0.0)
        elif tgt.is_point:
            ax, ay = (tgt.x - x) / distance, (tgt.y - y) / distance
        else:
            ax, ay = math.sin(tgt.angle), math.cos(tgt.angle)
        if s.damping:  # a velocity-dependent field: −β·v
            fx, fy = fx - s.damping * r.V * math.sin(theta), fy - s.damping * r.V * math.cos(theta)
        delta = math.atan2(fx + (1.0 + goal) * ax, fy + (1.0 + goal) * ay)
        if c.hold == "command":
            value = min(max(k * _wrap(delta - theta), -wmax), wmax)
        else:
            value = theta + _wrap(delta - theta)
        if s.speed_law:
            norm = math.hypot(fx, fy)
            cos_phi = (fx * math.sin(theta) + fy * math.cos(theta)) / norm if norm > 0 else 0.0
            speed = r.V * (1 - abs(cos_phi))
        else:
            speed = r.V
        if pending_V is None:
            pending_V = speed
        V = pending_V if c.compute_delay == 1 else speed  # the speed: the compute delay only
        pending_V = speed
        if c.hold == "command" and math.isfinite(r.yaw_accel_limit):  # the velocity smoother, from a zero command
            smoothed = smoothed + min(max(value - smoothed, -r.yaw_accel_limit * T), r.yaw_accel_limit * T)
            value = smoothed
        computed.append(value)
        applied = computed[max(step - lag, 0)]
        earlier = computed[max(step - lag - 1, 0)]
        start, substepped = (x, y, theta, omega), False
        if c.hold == "command" and switch > 0:
            nodes, integral, theta_mid, omega_mid = before.constant(theta, omega, g * earlier)
            x, y = before.move(x, y, V, theta, nodes, integral)
            nodes, integral, theta_end, omega_end = after.constant(theta_mid, omega_mid, g * applied)
            x, y = after.move(x, y, V, theta_mid, nodes, integral)
        elif c.hold == "command":
            nodes, integral, theta_end, omega_end = full.constant(theta, omega, g * applied)
            x, y = full.move(x, y, V, theta, nodes, integral)
        else:
            nodes, integral, theta_end, omega_end = full.reference(theta, omega, applied)
            checks = [theta] + [theta + d for d in nodes] + [theta_end]
            if all(abs(k * (applied - th)) <= wmax for th in checks):
                x, y = full.move(x, y, V, theta, nodes, integral)
            else:
                substepped = True
                theta_end, omega_end = theta, omega
                for _ in range(SUBSTEPS):
                    x, y, theta_end, omega_end = sub.servo_step(x, y, V, theta_end, omega_end, applied, wmax)
        theta, omega = theta_end, omega_end
        xs.append(x), ys.append(y), ths.append(theta)
        contact = _path_contact(s, sense, tau, start, applied, V, substepped, gap, switch, earlier)
        if contact is not None:  # the run ends at the sample after the touch, as the engine's does
            hit, cx, cy = contact
            event = Event("collision", step * T + hit, cx, cy)
            break
    n = len(xs)
    return Trajectory(np.arange(n) * T, np.array(xs), np.array(ys), np.array(ths)), event
