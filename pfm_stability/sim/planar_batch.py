"""The batched planar stepper: many Ge & Cui robots advance together, one sampling period per step (docs/simulator.md).

Every member (`PlanarMember`) has its own robot (`PointMass`, `Steering`, `DiffDrive`;
`sim.planar_robots`), field and world (`sim.planar_field`), start, period T, compute delay,
duration and collision policy. Their states are arrays of shape (B,); one step is one
sampling period of each member (member m is at t = k·T_m after k steps). One step, for
every member still running:

1. **Sense** at t_k (`FieldArrays.sense`): attraction, repulsion of each obstacle, and per
   obstacle the clearance ρ_s, v_RO and D = ρ_s − v_RO²/(2a_max).
2. **Events** between t_k−1 and t_k, per member and obstacle (masks over (B, O)):
   ``gate_open`` / ``gate_close`` (v_RO crosses 0), ``influence_enter`` / ``influence_exit``
   (D crosses ρ0), ``contact`` (ρ_s ≤ 0) or else ``collision_unavoidable`` (the gated
   repulsion undefined: D ≤ 0 while approaching); crossing times interpolated linearly.
   A contact stops the member, and so does an unavoidable collision under
   ``on_collision="stop"`` (under ``"continue"`` that repulsion counts as 0). A stopped
   member's last sample is t_k.
3. **Record** t_k, p, v, θ and the force.
4. **Command** from the force (each robot group) and apply it at once or one period later
   (``compute_delay``; at k = 0 the command of t_0, as if the robot had been running).
5. **Advance** the running members over [t_k, t_k+1) exactly under the held command.

Every formula is element-wise in the member (its obstacles padded to the batch's largest
count; forces added one obstacle after the other), so a member advances alike alone or in
any batch, to round-off (numpy's SIMD transcendental functions may round a member of an
array of another length differently: docs/simulator.md, "Batches"). The single-robot
`sim.planar.simulate_planar` is a batch of one. A member's state that stops being finite
raises `FloatingPointError` naming it: a run never returns NaN.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_integer, check_number, check_type
from ..laws.velocity_laws import VelocityAttraction
from .planar_field import Field, FieldArrays, Start, World
from .planar_robots import ROBOTS, DiffDrive, DiffDriveGroup, PlanarState, PointMass, positive, robot_groups

__all__ = [
    "COLLISION_POLICIES",
    "EVENT_KINDS",
    "STOP_REASONS",
    "PlanarBatch",
    "PlanarEvent",
    "PlanarMember",
    "PlanarRun",
    "simulate_planar_batch",
]

STOP_REASONS = ("duration", "contact", "collision_unavoidable")
"""Why a run ended: its duration elapsed, the robot touched an obstacle, or GC2002 eq 12 became undefined."""

COLLISION_POLICIES = ("stop", "continue")
"""On D ≤ 0 while approaching: stop the run, or continue with that obstacle's repulsion taken as 0."""

EVENT_KINDS = ("gate_open", "gate_close", "influence_enter", "influence_exit", "contact", "collision_unavoidable")
"""The kinds of `PlanarEvent`."""

MAX_SAMPLES = 10_000_000
"""Most samples (duration/T) of one member."""

FINITE_CHECK = 64
"""Steps between two checks that every running member's state is finite."""


@dataclass(frozen=True)
class PlanarEvent:
    """Something that happened during a run.

    Attributes
    ----------
    kind : str
        ``gate_open`` / ``gate_close`` (v_RO crosses 0 upwards / downwards), ``influence_enter`` /
        ``influence_exit`` (D = ρ_s − v_RO²/(2a_max) crosses ρ0 downwards / upwards),
        ``collision_unavoidable`` (D ≤ 0 while approaching, GC2002 eq 12), ``contact`` (clearance ≤ 0).
    time : float
        s; crossings are interpolated linearly between the two samples that bracket them.
    obstacle : int
        Index into `World.obstacles`.
    """

    kind: str
    time: float
    obstacle: int

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {"kind": self.kind, "time": self.time, "obstacle": self.obstacle}


@dataclass(frozen=True)
class PlanarRun:
    """One planar run, sampled at t_k = kT.

    Attributes
    ----------
    t : ndarray, shape (K,)
        s.
    p, v : ndarray, shape (K, 2)
        Position (m) and velocity (m/s).
    theta : ndarray, shape (K,), or None
        Heading, rad (unwrapped); None for a point mass.
    force : ndarray, shape (K, 2)
        The field's force computed at each sample, N (an undefined repulsion counted as 0).
    wheel_speeds : ndarray, shape (K, 2), or None
        (v_l, v_r) applied from each sample on, m/s (differential drive only).
    events : tuple of PlanarEvent
    collision : bool
        A contact or an unavoidable collision happened.
    stop_reason : str
        One of `STOP_REASONS`.
    T : float
        Sampling period, s.
    compute_delay : int
    """

    t: np.ndarray
    p: np.ndarray
    v: np.ndarray
    theta: np.ndarray | None
    force: np.ndarray
    wheel_speeds: np.ndarray | None
    events: tuple
    collision: bool
    stop_reason: str
    T: float
    compute_delay: int

    def first_event(self, kind: str) -> PlanarEvent | None:
        """The first event of a kind, or None.

        Parameters
        ----------
        kind : str
            The event's kind (`PlanarEvent.kind`).
        """
        return next((e for e in self.events if e.kind == kind), None)

    def to_dict(self) -> dict:
        """Summary (no arrays): duration, final state, events, collision, stop reason."""
        return {
            "duration": float(self.t[-1]),
            "final_position": [float(c) for c in self.p[-1]],
            "final_velocity": [float(c) for c in self.v[-1]],
            "events": [e.to_dict() for e in self.events],
            "collision": self.collision,
            "stop_reason": self.stop_reason,
            "T": self.T,
            "compute_delay": self.compute_delay,
        }


@dataclass(frozen=True)
class PlanarMember:
    """One member of a planar batch: a robot in a field and world, sampled with period T.

    Parameters
    ----------
    robot : PointMass, Steering or DiffDrive
        The robot (`sim.planar_robots`).
    field : Field
        Attraction and repulsion.
    world : World
        Target and obstacles.
    start : Start
        Initial state.
    T : float
        Sampling period, s, in (0, 1e4].
    duration : float
        s, in (0, 1e7]; the run has ⌈duration/T⌉ + 1 samples (at most 1e7) unless it stops earlier.
    compute_delay : {0, 1}
        Periods between a sample and the application of the command computed from it.
    on_collision : {"stop", "continue"}
        At D ≤ 0 while approaching (the repulsion undefined): stop, or continue with
        that repulsion taken as 0. A contact (clearance ≤ 0) always stops the run.
    """

    robot: object
    field: Field
    world: World
    start: Start
    T: float
    duration: float
    compute_delay: int = 0
    on_collision: str = "stop"

    def __post_init__(self):
        check_type("robot", self.robot, ROBOTS, "a PointMass, Steering or DiffDrive")
        check_type("field", self.field, Field, "a Field")
        check_type("world", self.world, World, "a World")
        check_type("start", self.start, Start, "a Start")
        T = positive("T", self.T, "s", 1e4)
        object.__setattr__(self, "T", T)
        object.__setattr__(self, "compute_delay", check_integer("compute_delay", self.compute_delay, 0, 1))
        duration = check_number("duration", self.duration, 0.0, 1e7, high_open=False, unit="s")
        object.__setattr__(self, "duration", duration)
        check_choice("on_collision", self.on_collision, COLLISION_POLICIES)
        if isinstance(self.field.attraction, VelocityAttraction) and self.world.target is None:
            raise ValueError("world.target must be a Target when the attraction is a VelocityAttraction")
        if math.ceil(duration / T - 1e-9) > MAX_SAMPLES:
            raise ValueError(f"duration/T must be at most 1e7 samples; got {duration / T:.3g}")

    @property
    def steps(self) -> int:
        """Sampling periods of the full run: ⌈duration/T⌉."""
        return math.ceil(self.duration / self.T - 1e-9)


@dataclass(frozen=True)
class PlanarBatch:
    """The runs of a batch and what stepping them cost.

    Attributes
    ----------
    runs : tuple of PlanarRun
        One per member, in the members' order.
    robot_steps : int
        Sampling periods advanced, summed over the members.
    seconds : float
        Wall time of the stepping loop, s.
    """

    runs: tuple
    robot_steps: int
    seconds: float


def _crossing(t0, t1, a0, a1, level):
    """Times a sampled quantity crossed `level` between (t0, a0) and (t1, a1), interpolated linearly (t1 where a1 = a0)."""
    same = a1 == a0
    fraction = np.minimum(np.maximum((level - a0) / np.where(same, 1.0, a1 - a0), 0.0), 1.0)
    return np.where(same, t1, t0 + (t1 - t0) * fraction)


class _Events:
    """Per-step event detection over (B, O) masks, kept as arrays until the runs are built."""

    def __init__(self, field: FieldArrays):
        self.valid = field.valid
        self.rho0 = field.rho0
        self.gated = field.any_gated
        self.previous = None
        self.found = []  # (member, obstacle, kind code, time) arrays per step with events

    def step(self, t, T, sensed, due):
        """Events of the due members at one sample (times t); returns (contact, collision) per member (bool arrays),
        or None when no member touched an obstacle or met an unavoidable collision."""
        c, v, D = sensed.clearance, sensed.closing_speed, sensed.braked
        touch = (c <= 0) | sensed.collision  # a contact, else an unavoidable collision
        signs = (v > 0, D < self.rho0) if self.gated else None  # gate open, inside the influence
        previous, self.previous = self.previous, (c, v, D, signs)
        changed = touch
        if previous is not None and self.gated:
            changed = touch | (previous[3][0] != signs[0]) | (previous[3][1] != signs[1])
        live = self.valid & due[:, None]
        if not (changed & live).any():
            return None
        contact = live & (c <= 0)
        collision = live & ~contact & sensed.collision
        touch = contact | collision
        gate = influence = np.zeros_like(live)
        if previous is not None:
            c0, v0, D0, _ = previous
            if self.gated:
                gate = live & (previous[3][0] != signs[0])
                influence = live & (previous[3][1] != signs[1])
        mask = np.stack([gate, influence, touch], axis=-1)
        m, j, slot = np.nonzero(mask)
        t1 = t[m]
        t0 = t1 - T[m]
        kind = np.empty(m.size, dtype=np.int64)
        when = np.empty(m.size)
        gate, influence, touch = slot == 0, slot == 1, slot == 2
        if gate.any():
            v1 = v[m[gate], j[gate]]
            kind[gate] = np.where(v1 > 0, 0, 1)
            when[gate] = _crossing(t0[gate], t1[gate], v0[m[gate], j[gate]], v1, 0.0)
        if influence.any():
            D1, rho0 = D[m[influence], j[influence]], self.rho0[m[influence], 0]
            kind[influence] = np.where(D1 < rho0, 2, 3)
            when[influence] = _crossing(t0[influence], t1[influence], D0[m[influence], j[influence]], D1, rho0)
        if touch.any():
            mt, jt = m[touch], j[touch]
            hit = contact[mt, jt]
            kind[touch] = np.where(hit, 4, 5)
            c1 = c[mt, jt]
            start = c0[mt, jt] if previous is not None else c1
            when[touch] = np.where(hit, _crossing(t0[touch], t1[touch], start, c1, 0.0), t1[touch])
        self.found.append((m, j, kind, when))
        return contact.any(axis=1), collision.any(axis=1)

    def per_member(self, B):
        """(events, collided): each member's events as a tuple, in the order they were found (by step, then obstacle,
        then gate, influence, contact), and whether it had a contact or an unavoidable collision (bool array)."""
        collided = np.zeros(B, dtype=bool)
        if not self.found:
            return [()] * B, collided
        m, j, kind, when = (np.concatenate(parts) for parts in zip(*self.found))
        collided[m[kind >= 4]] = True
        order = np.argsort(m, kind="stable")
        made = [PlanarEvent(EVENT_KINDS[k], t, o) for k, t, o in zip(kind[order].tolist(), when[order].tolist(), j[order].tolist())]
        ends = np.searchsorted(m[order], np.arange(B + 1))
        return [tuple(made[ends[i]:ends[i + 1]]) for i in range(B)], collided


class _Recorder:
    """Samples by row (step k) and member column."""

    def __init__(self, samples: int, B: int, headings: bool, wheels: bool):
        shape = (samples, B)
        self.px, self.py, self.vx, self.vy, self.fx, self.fy = (np.empty(shape) for _ in range(6))
        self.theta = np.empty(shape) if headings else None
        self.wheels = (np.empty(shape), np.empty(shape)) if wheels else None

    def record(self, k, state: PlanarState, sensed):
        self.px[k], self.py[k], self.vx[k], self.vy[k] = state.px, state.py, state.vx, state.vy
        self.fx[k], self.fy[k] = sensed.fx, sensed.fy
        if self.theta is not None:
            self.theta[k] = state.theta

    def by_member(self, n: int) -> dict:
        """The first n samples member-major (one transposed copy each; a run's arrays are views of them):
        p, v, force, wheels of shape (B, n, 2), theta (B, n)."""
        def pair(a, b):
            out = np.empty((a.shape[1], n, 2))
            out[:, :, 0], out[:, :, 1] = a[:n].T, b[:n].T
            return out

        return {"p": pair(self.px, self.py), "v": pair(self.vx, self.vy), "force": pair(self.fx, self.fy),
                "theta": None if self.theta is None else np.ascontiguousarray(self.theta[:n].T),
                "wheels": None if self.wheels is None else pair(*self.wheels)}


def simulate_planar_batch(members) -> PlanarBatch:
    """Simulate every member of `members` together (module docstring).

    Parameters
    ----------
    members : sequence of PlanarMember
        At least one.

    Returns
    -------
    PlanarBatch
        The runs, in the members' order, and the stepping cost.
    """
    members = list(members)
    if not members:
        raise ValueError("members must hold at least one PlanarMember")
    for m in members:
        check_type("members", m, PlanarMember, "a sequence of PlanarMember")
    B = len(members)
    robots = [m.robot for m in members]
    T = np.array([m.T for m in members])
    steps = np.array([m.steps for m in members], dtype=np.int64)
    delayed = np.array([m.compute_delay == 1 for m in members], dtype=bool)
    any_delay, all_delay = bool(delayed.any()), bool(delayed.all())
    stop_on_collision = np.array([m.on_collision == "stop" for m in members], dtype=bool)
    groups = robot_groups(robots, T)
    mover_groups = [g for g in groups if g.heading]
    diff = [g for g in groups if isinstance(g, DiffDriveGroup)]
    field = FieldArrays([m.field for m in members], [m.world for m in members])
    state = PlanarState([m.start.position for m in members], [m.start.velocity for m in members], [m.start.heading for m in members])
    K = int(steps.max())
    rec = _Recorder(K + 1, B, any(g.heading for g in groups), bool(diff))
    events = _Events(field)
    alive = np.ones(B, dtype=bool)
    reason = np.zeros(B, dtype=np.int64)
    done = steps.copy()  # the last sample of each member: its duration's, or the one of the event that stopped it
    pending = None
    single = groups[0] if len(groups) == 1 else None
    started = time.perf_counter()
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for k in range(K + 1):
            t = k * T
            due = alive & (k <= steps)
            for g in mover_groups:
                g.velocity(state)
            sensed = field.sense(t, state.px, state.py, state.vx, state.vy)
            touched = events.step(t, T, sensed, due)
            rec.record(k, state, sensed)
            if touched is not None:
                contact, collision = touched
                stopped = contact | (collision & stop_on_collision)
                done[stopped] = k
                reason[contact] = 1
                reason[~contact & collision & stop_on_collision] = 2
                alive &= ~stopped
            if single is not None:
                first, second = single.command(state, sensed.fx, sensed.fy, sensed.nearest)
            else:
                first, second = np.zeros(B), np.zeros(B)
                for g in groups:
                    first[g.index], second[g.index] = g.command(state, sensed.fx, sensed.fy, sensed.nearest)
            if any_delay:
                if pending is None:
                    pending = (first, second)
                applied = pending if all_delay else (np.where(delayed, pending[0], first), np.where(delayed, pending[1], second))
                pending = (first, second)
            else:
                applied = (first, second)
            for g in diff:
                rec.wheels[0][k, g.index], rec.wheels[1][k, g.index] = g.wheels(*applied)
            running = due & alive & (k < steps)
            if not running.any():
                break
            mask = None if running.all() else running
            for g in groups:
                g.advance(state, applied[0], applied[1], mask)
            if k % FINITE_CHECK == FINITE_CHECK - 1:
                _check_finite(state, running, k + 1, T)
    seconds = time.perf_counter() - started
    _check_finite(state, due, int(done.max()), T)
    found, collided = events.per_member(B)
    arrays = rec.by_member(int(done.max()) + 1)
    runs = tuple(_run(members[m], arrays, m, int(done[m]), found[m], bool(collided[m]), STOP_REASONS[reason[m]]) for m in range(B))
    return PlanarBatch(runs, int(done.sum()), seconds)


def _check_finite(state: PlanarState, which, k, T):
    bad = which & ~state.finite()
    if np.any(bad):
        m = int(np.flatnonzero(bad)[0])
        raise FloatingPointError(f"member {m} reached a non-finite state at t = {k * T[m]:g} s")


def _run(member: PlanarMember, arrays: dict, m: int, steps: int, events: tuple, collided: bool, reason: str) -> PlanarRun:
    n = steps + 1
    return PlanarRun(
        t=np.arange(n) * member.T,
        p=arrays["p"][m, :n],
        v=arrays["v"][m, :n],
        theta=None if isinstance(member.robot, PointMass) else arrays["theta"][m, :n],
        force=arrays["force"][m, :n],
        wheel_speeds=arrays["wheels"][m, :n] if isinstance(member.robot, DiffDrive) else None,
        events=events,
        collision=collided,
        stop_reason=reason,
        T=member.T,
        compute_delay=member.compute_delay,
    )
