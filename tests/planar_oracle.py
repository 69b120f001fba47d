"""The planar simulator's former scalar stepper, kept as the oracle of the batched one (docs/simulator.md, "Planar robots").

A plain per-robot loop in Python floats, exactly as `sim.planar` stepped one robot before
the batched stepper (`sim.planar_batch`) replaced it: the field and events of one sample
(`sense`, `events`), the three robots' exact motion over a period (`_MassDynamics`,
`_SteeringDynamics`, `_DiffDriveDynamics`) and the loop (`simulate_scalar`). It shares
with the batch only the scene's data classes and the steering robot's closed-form
coefficients of `sim.robot` (KB eq 6–7); everything the batch vectorizes — forces,
gates, events, command, compute delay, masking — is written out here once more.
"""

from __future__ import annotations

import math
import numpy as np

from pfm_stability.laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion
from pfm_stability.parameters import TAU_RESOLUTION
from pfm_stability.sim.movers import Pull
from pfm_stability.sim.planar import DiffDrive, PlanarEvent, PlanarRun, PointMass, Steering
from pfm_stability.sim.robot import advance_position, constant_input, constant_input_modes, graded_rule, propagate, servo, servo_modes, slow_rate

__all__ = ["simulate_scalar"]

_BIG = 1e6


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class _MassDynamics:
    def __init__(self, robot, T, start):
        self.r, self.T = robot, T
        self.p, self.v = np.array(start.position), np.array(start.velocity)
        self.theta = None

    def velocity(self):
        return self.v

    def command(self, force, clearance):
        a = force / self.r.mass
        norm = math.hypot(*a)
        if norm > self.r.a_max:
            a = a * (self.r.a_max / norm)
        return a

    def advance(self, a):
        T = self.T
        self.p = self.p + self.v * T + 0.5 * a * T * T
        self.v = self.v + a * T


class _SteeringDynamics:
    def __init__(self, robot, T, start):
        self.r, self.T = robot, T
        one = lambda value: np.array([float(value)])  # noqa: E731
        tau = robot.tau if robot.tau * robot.k >= TAU_RESOLUTION else 0.0
        slow = slow_rate(one(robot.k), one(robot.max_rate if robot.max_rate < math.inf else _BIG))
        if robot.hold == "command":
            self.rule = graded_rule(one(T), *constant_input_modes(one(tau)), slow)
            self.coef = constant_input(one(tau), self.rule)
        else:
            self.rule = graded_rule(one(T), *servo_modes(one(tau), one(robot.k)), slow)
            self.coef = servo(one(tau), one(robot.k), self.rule)
        self.p = np.array(start.position)
        self.theta, self.omega = float(start.heading), 0.0

    def velocity(self):
        return self.r.V * np.array([math.cos(self.theta), math.sin(self.theta)])

    def command(self, force, clearance):
        fx, fy = force
        delta = math.atan2(fy, fx) if (fx or fy) else self.theta
        error = _wrap(delta - self.theta)
        if self.r.hold == "command":
            return min(max(self.r.k * error, -self.r.max_rate), self.r.max_rate)
        return self.theta + error

    def advance(self, value):
        arr = lambda x: np.array([float(x)])  # noqa: E731
        delta, correction, theta, omega = propagate(self.coef, arr(self.theta), arr(self.omega), arr(value))
        y, x = advance_position(arr(self.p[1]), arr(self.p[0]), arr(self.r.V), self.rule, arr(self.theta), delta, correction)
        self.p = np.array([float(x[0]), float(y[0])])
        self.theta, self.omega = float(theta[0]), float(omega[0])


class _DiffDriveDynamics:
    def __init__(self, robot, T, start):
        self.r, self.T = robot, T
        self.p = np.array(start.position)
        self.theta = float(start.heading)
        self.speed = math.hypot(*start.velocity)

    def velocity(self):
        return self.speed * np.array([math.cos(self.theta), math.sin(self.theta)])

    def command(self, force, clearance):
        fx, fy = force
        heading = math.atan2(fy, fx) if (fx or fy) else self.theta
        omega = self.r.K_s * _wrap(heading - self.theta)
        speed = self.r.v_opt * min(1.0, clearance / self.r.rho0_speed)
        return max(speed, 0.0), omega

    def advance(self, command):
        speed, omega = command
        turn = omega * self.T
        chord = speed * self.T * float(np.sinc(turn / (2.0 * math.pi)))
        mid = self.theta + 0.5 * turn
        self.p = self.p + chord * np.array([math.cos(mid), math.sin(mid)])
        self.theta += turn
        self.speed = speed


_DYNAMICS = {PointMass: _MassDynamics, Steering: _SteeringDynamics, DiffDrive: _DiffDriveDynamics}


def sense(field, world, p, v, t, gated):
    """(force, per-obstacle [clearance, v_RO, D, status, away, where], nearest clearance) at one sample."""
    target = world.target
    if isinstance(field.attraction, Pull):
        force = field.attraction.magnitude * field.attraction.unit
        goal_dir = field.attraction.unit
    else:
        p_tar, v_tar = target.at(t)
        force = field.attraction.force(p, v, p_tar, v_tar)
        e = p_tar - p
        r = math.hypot(*e)
        goal_dir = e / r if r > 0 else np.zeros(2)
    info = []
    for o in world.obstacles:
        clearance, away, where = o.geometry(p, t)
        if gated is not None:
            rel = v - np.array(o.velocity)
            v_ro = float(-(rel @ away))
            D = gated.braked_clearance(clearance, v_ro)
        else:
            v_ro = D = math.nan
        info.append([clearance, v_ro, D, "inactive", away, where])
    rep = field.repulsion
    if rep is None or not info:
        return force, info, min((i[0] for i in info), default=math.inf)
    nearest = min(range(len(info)), key=lambda i: info[i][0])
    for i, (o, row) in enumerate(zip(world.obstacles, info)):
        if field.nearest_only and i != nearest:
            continue
        clearance, _, _, _, away, where = row
        if clearance <= 0:
            continue
        if gated is not None:
            r = gated.evaluate(p, v, o.kind, where, getattr(o, "radius", 0.0), o.velocity)
            row[3] = r.status
            if r.status == "active":
                force = force + r.force
        else:
            P = float(rep.force(clearance))
            Q = float(rep.goal_force(clearance))
            if P or Q:
                row[3] = "active"
                force = force + field.repulsion_scale * (P * away + Q * goal_dir)
    return force, info, info[nearest][0]


def _crossing_time(t0, t1, a0, a1, level):
    if a1 == a0:
        return t1
    return t0 + (t1 - t0) * min(max((level - a0) / (a1 - a0), 0.0), 1.0)


def events(previous, info, t0, t1, gated):
    """(kind, time, obstacle) between two samples."""
    out = []
    for i, row in enumerate(info):
        clearance, v_ro, D, status = row[:4]
        if previous is not None and gated is not None:
            _, v0, D0 = previous[i][:3]
            if (v0 > 0) != (v_ro > 0):
                out.append(("gate_open" if v_ro > 0 else "gate_close", _crossing_time(t0, t1, v0, v_ro, 0.0), i))
            if (D0 < gated.rho0) != (D < gated.rho0):
                out.append(("influence_enter" if D < gated.rho0 else "influence_exit", _crossing_time(t0, t1, D0, D, gated.rho0), i))
        if clearance <= 0:
            c0 = previous[i][0] if previous is not None else clearance
            out.append(("contact", _crossing_time(t0, t1, c0, clearance, 0.0), i))
        elif status == "collision":
            out.append(("collision_unavoidable", t1, i))
    return out


def simulate_scalar(robot, field, world, *, T, compute_delay=0, duration, start, on_collision="stop") -> PlanarRun:
    """The former `simulate_planar`, one robot in Python floats (inputs assumed valid)."""
    gated = field.repulsion if isinstance(field.repulsion, VelocityGatedRepulsion) else None
    assert not isinstance(field.attraction, VelocityAttraction) or world.target is not None
    state = _DYNAMICS[type(robot)](robot, T, start)
    steps = math.ceil(duration / T - 1e-9)
    ts, ps, vs, ths, fs, wheels, evs = [], [], [], [], [], [], []
    previous, pending, reason = None, None, "duration"
    for step in range(steps + 1):
        t = step * T
        v = state.velocity()
        force, info, nearest = sense(field, world, state.p, v, t, gated)
        new = events(previous, info, t - T, t, gated)
        evs.extend(new)
        ts.append(t), ps.append(state.p.copy()), vs.append(np.array(v)), ths.append(state.theta), fs.append(force)
        kinds = {e[0] for e in new}
        if "contact" in kinds:
            reason = "contact"
        elif "collision_unavoidable" in kinds and on_collision == "stop":
            reason = "collision_unavoidable"
        value = state.command(force, nearest)
        if pending is None:
            pending = [value] * compute_delay
        pending.append(value)
        applied = pending.pop(0)
        if isinstance(robot, DiffDrive):
            speed, omega = applied
            wheels.append((speed - robot.axle * omega / 2.0, speed + robot.axle * omega / 2.0))
        if reason != "duration" or step == steps:
            break
        previous = info
        state.advance(applied)
    return PlanarRun(np.array(ts), np.array(ps), np.array(vs), None if isinstance(robot, PointMass) else np.array(ths, dtype=float),
                     np.array(fs), np.array(wheels) if wheels else None, tuple(PlanarEvent(*e) for e in evs),
                     any(e[0] in ("contact", "collision_unavoidable") for e in evs), reason, T, compute_delay)
