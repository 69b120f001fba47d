"""A sampled-data planar simulator for Ge & Cui 2002's robots and fields (docs/simulator.md, "Planar robots").

One engine drives three robots in the plane (x, y; headings counter-clockwise
from +x) through fields of Ge & Cui, "Dynamic motion planning for mobile robots
using potential field method", Autonomous Robots 13, 2002 (GC2002), and its
conference form (2000):

* `PointMass(mass, a_max)` — holonomic, force = acceleration (GC2002 eq 24, 29),
  a = F/m saturated at a_max (the conference paper's eq 22), held over the period;
  p and v are integrated exactly under the constant acceleration.
* `Steering(V, tau, k)` — Koren & Borenstein's (KB) robot at constant speed V:
  τω̇ + ω = u, θ̇ = ω; ``hold="reference"`` holds δ (the force's direction) and
  closes u = k(δ − θ) continuously, ``hold="command"`` holds u = k·wrap(δ − θ)
  (optionally clipped to ±max_rate); the exact solutions of `sim.robot`.
* `DiffDrive(K_s, v_opt, rho0_speed, axle)` — GC2002 §7 (eq 37–43): ω = K_s·wrap(θ_f − θ),
  speed v = v_opt·min(1, ρ/ρ0) (eq 41, ρ the nearest clearance), both held; the
  unicycle's arc is integrated exactly; wheel speeds v_l = v − Lω/2, v_r = v + Lω/2.

The field (`Field`) is an attraction — `VelocityAttraction` towards the `Target`
(fixed or moving at constant velocity, GC2002 eq 1, 7–9) or a constant `Pull`
towards a target at infinity (KB's wall runs) — plus a repulsion from every
obstacle (`Wall`, `PointObstacle`, `Ball` of `sim.movers`, each fixed or moving):
`VelocityGatedRepulsion` (eq 10–12, 19–20, corrected gradients) or any static
`ForceLaw` of the clearance (e.g. `fields.KhatibLaw`, in units of
`Field.repulsion_scale` newtons), summed over the obstacles or, with
``nearest_only``, from the nearest one (the conference paper's Assumption 4).
The force is computed at the sampling instants t_k = kT from the state there
and applied at once (``compute_delay=0``) or one period later (1), held (ZOH).

Usage
-----
>>> from pfm_stability.laws.velocity_laws import VelocityAttraction
>>> from pfm_stability.sim.planar import PointMass, Field, World, Start, simulate_planar
>>> from pfm_stability.sim.movers import Target, Ball
>>> run = simulate_planar(PointMass(mass=1.0), Field(VelocityAttraction(0.005, 0.1)),
...                       World(Target((10.0, 10.0), (0.1, -0.05))), T=0.1, duration=60.0,
...                       start=Start((1.0, 1.0)))
>>> run.p.shape[1], run.stop_reason
(2, 'duration')

``run.t, run.p, run.v, run.theta, run.force`` are arrays at the samples,
``run.events`` the `PlanarEvent` records (gate open/close at v_RO = 0, influence
enter/exit at D = ρ0, ``collision_unavoidable`` at D ≤ 0 while approaching — GC2002
eq 12 leaves the force undefined there — and ``contact`` at clearance ≤ 0).
`wall_cycle` runs the non-smooth wall of the velocity-gated repulsion and measures its
cycle (`WallCycle`); growth rates and frequencies of a run: `sim.cycles.lateral_metrics`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..checks import check_choice, check_integer, check_number, check_type
from ..laws.force_law import ForceLaw
from ..laws.velocity_laws import VelocityAttraction, VelocityGatedRepulsion
from .metrics import HYSTERESIS, turning_points
from .movers import Obstacle, Pull, Target, Wall, vector
from .planar_robots import _DYNAMICS, ROBOTS, DiffDrive, PointMass, Steering, positive

__all__ = [
    "COLLISION_POLICIES",
    "REST_TOLERANCE",
    "STOP_REASONS",
    "DiffDrive",
    "Field",
    "PlanarEvent",
    "PlanarRun",
    "PointMass",
    "Pull",
    "Start",
    "Steering",
    "WallCycle",
    "World",
    "measure_wall_cycle",
    "simulate_planar",
    "wall_cycle",
]

STOP_REASONS = ("duration", "contact", "collision_unavoidable")
"""Why a run ended: its duration elapsed, the robot touched an obstacle, or GC2002 eq 12 became undefined."""

COLLISION_POLICIES = ("stop", "continue")
"""On D ≤ 0 while approaching: stop the run, or continue with that obstacle's repulsion taken as 0."""

REST_TOLERANCE = 1e-3
"""Largest lateral peak-to-peak (m) of the measured half of a wall run for a robot to count as at rest.

A point mass resting in the Filippov band chatters at the sampling rate (the sampled relay:
its lateral velocity changes sign every 2 + d samples, d the compute delay), by at most
(2 + d)²·a·T² with a = max|F_x|/m over the measured half; its tolerance is the larger of
the two (5.3 mm measured at T = 0.065 s, d = 1, against a bound of 19 mm). A steering
robot's relay cycle has no such bound (its amplitude is ∝ T, tenths of a metre at KB's T)."""

@dataclass(frozen=True)
class Field:
    """Attraction plus repulsion.

    Parameters
    ----------
    attraction : VelocityAttraction or Pull
        GC2002's attraction towards the world's target, or a constant pull.
    repulsion : VelocityGatedRepulsion, ForceLaw or None
        GC2002's velocity-gated repulsion, or a static law P(ρ) of the clearance (with its
        goal part Q(ρ) towards the target), scaled by `repulsion_scale`.
    repulsion_scale : float
        Newtons per unit of a `ForceLaw` (its "units of the attraction"), in (0, 1e12].
    nearest_only : bool
        Only the nearest obstacle repels (the conference paper's Assumption 4).
    """

    attraction: object
    repulsion: object = None
    repulsion_scale: float = 1.0
    nearest_only: bool = False

    def __post_init__(self):
        check_type("attraction", self.attraction, (VelocityAttraction, Pull), "a VelocityAttraction or a Pull")
        if self.repulsion is not None:
            check_type("repulsion", self.repulsion, (VelocityGatedRepulsion, ForceLaw), "a VelocityGatedRepulsion, a ForceLaw or None")
        object.__setattr__(self, "repulsion_scale", positive("repulsion_scale", self.repulsion_scale, "N", 1e12))
        check_type("nearest_only", self.nearest_only, bool, "True or False")


@dataclass(frozen=True)
class World:
    """A target (needed by a `VelocityAttraction`) and obstacles (`sim.movers`).

    Attributes
    ----------
    target : Target or None
        The target.
    obstacles : tuple
        `sim.movers` obstacles (`Wall`, `PointObstacle`, `Ball`).
    """

    target: Target | None = None
    obstacles: tuple = ()

    def __post_init__(self):
        if self.target is not None:
            check_type("target", self.target, Target, "a Target or None")
        obstacles = tuple(self.obstacles)
        for o in obstacles:
            check_type("obstacles", o, Obstacle, "a sequence of Wall, PointObstacle or Ball")
        object.__setattr__(self, "obstacles", obstacles)


@dataclass(frozen=True)
class Start:
    """Initial state: `position` (m), `velocity` (m/s; a steering robot's speed is always V) and `heading`.

    `heading` (rad from +x) defaults to the velocity's direction, or 0 at rest.

    Attributes
    ----------
    position : (float, float)
        m.
    velocity : (float, float)
        m/s.
    heading : float or None
        rad from +x (None: the velocity's direction).
    """

    position: tuple
    velocity: tuple = (0.0, 0.0)
    heading: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "position", vector("start position", self.position))
        object.__setattr__(self, "velocity", vector("start velocity", self.velocity))
        if self.heading is None:
            vx, vy = self.velocity
            object.__setattr__(self, "heading", math.atan2(vy, vx) if (vx or vy) else 0.0)
        else:
            object.__setattr__(self, "heading", check_number("heading", self.heading, -100.0, 100.0, unit="rad"))


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


# ---------------------------------------------------------------- the field


def _sense(field: Field, world: World, p, v, t, gated: VelocityGatedRepulsion | None):
    """(force, per-obstacle (clearance, v_RO, D, status), nearest clearance) at one sample."""
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
    """Linear interpolation of the time a sampled quantity crossed `level` between (t0, a0) and (t1, a1)."""
    if a1 == a0:
        return t1
    return t0 + (t1 - t0) * min(max((level - a0) / (a1 - a0), 0.0), 1.0)


def _events(previous, info, t0, t1, gated):
    """Events between two samples from the per-obstacle rows (clearance, v_RO, D, status)."""
    out = []
    for i, row in enumerate(info):
        clearance, v_ro, D, status = row[:4]
        if previous is not None and gated is not None:
            _, v0, D0 = previous[i][:3]
            if (v0 > 0) != (v_ro > 0):
                out.append(PlanarEvent("gate_open" if v_ro > 0 else "gate_close", _crossing_time(t0, t1, v0, v_ro, 0.0), i))
            if (D0 < gated.rho0) != (D < gated.rho0):
                kind = "influence_enter" if D < gated.rho0 else "influence_exit"
                out.append(PlanarEvent(kind, _crossing_time(t0, t1, D0, D, gated.rho0), i))
        if clearance <= 0:
            c0 = previous[i][0] if previous is not None else clearance
            out.append(PlanarEvent("contact", _crossing_time(t0, t1, c0, clearance, 0.0), i))
        elif status == "collision":
            out.append(PlanarEvent("collision_unavoidable", t1, i))
    return out


# ---------------------------------------------------------------- the engine


def _check_inputs(robot, field, world, T, compute_delay, duration, start, on_collision):
    check_type("robot", robot, ROBOTS, "a PointMass, Steering or DiffDrive")
    check_type("field", field, Field, "a Field")
    check_type("world", world, World, "a World")
    check_type("start", start, Start, "a Start")
    T = positive("T", T, "s", 1e4)
    compute_delay = check_integer("compute_delay", compute_delay, 0, 1)
    duration = check_number("duration", duration, 0.0, 1e7, high_open=False, unit="s")
    check_choice("on_collision", on_collision, COLLISION_POLICIES)
    if isinstance(field.attraction, VelocityAttraction) and world.target is None:
        raise ValueError("world.target must be a Target when the attraction is a VelocityAttraction")
    if math.ceil(duration / T - 1e-9) > 10_000_000:
        raise ValueError(f"duration/T must be at most 1e7 samples; got {duration / T:.3g}")
    return T, compute_delay, duration


def simulate_planar(robot, field: Field, world: World, *, T: float, compute_delay: int = 0, duration: float, start: Start, on_collision: str = "stop") -> PlanarRun:
    """Simulate one robot in a planar field, sampled with period T (module docstring).

    Parameters
    ----------
    robot : PointMass, Steering or DiffDrive
    field : Field
    world : World
    T : float
        Sampling period, s, in (0, 1e4].
    compute_delay : {0, 1}
        Periods between a sample and the application of the command computed from it.
    duration : float
        s, in (0, 1e7]; the run has ⌈duration/T⌉ + 1 samples unless it stops earlier.
    start : Start
    on_collision : {"stop", "continue"}
        At D ≤ 0 while approaching (the repulsion undefined): stop, or continue with
        that repulsion taken as 0. A contact (clearance ≤ 0) always stops the run.

    Returns
    -------
    PlanarRun
    """
    T, compute_delay, duration = _check_inputs(robot, field, world, T, compute_delay, duration, start, on_collision)
    gated = field.repulsion if isinstance(field.repulsion, VelocityGatedRepulsion) else None
    state = _DYNAMICS[type(robot)](robot, T, start)
    steps = math.ceil(duration / T - 1e-9)
    ts, ps, vs, ths, fs, wheels, events = [], [], [], [], [], [], []
    previous, pending, reason = None, None, "duration"
    for step in range(steps + 1):
        t = step * T
        v = state.velocity()
        force, info, nearest = _sense(field, world, state.p, v, t, gated)
        new = _events(previous, info, t - T, t, gated)
        events.extend(new)
        ts.append(t), ps.append(state.p.copy()), vs.append(np.array(v)), ths.append(state.theta), fs.append(force)
        kinds = {e.kind for e in new}
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
    collision = any(e.kind in ("contact", "collision_unavoidable") for e in events)
    return PlanarRun(
        t=np.array(ts),
        p=np.array(ps),
        v=np.array(vs),
        theta=None if isinstance(robot, PointMass) else np.array(ths, dtype=float),
        force=np.array(fs),
        wheel_speeds=np.array(wheels) if wheels else None,
        events=tuple(events),
        collision=collision,
        stop_reason=reason,
        T=T,
        compute_delay=compute_delay,
    )


# ---------------------------------------------------------------- the velocity-gated wall


@dataclass(frozen=True)
class WallCycle:
    """The measured motion beside a velocity-gated wall (second half of the run).

    Attributes
    ----------
    mean_distance : float
        Mean clearance d, m.
    peak_to_peak : float
        max d − min d, m.
    heading_amplitude : float or None
        Half the peak-to-peak heading relative to the wall's direction, rad; None for a point mass.
    period : float or None
        Mean time between successive maxima of d, s; None when at rest (or fewer than two maxima).
    at_rest : bool
        peak_to_peak below `REST_TOLERANCE` (a point mass: below its sampling-chatter bound).
    touches_wall : bool
        The run ended by a contact or an unavoidable collision (GC2002 eq 12, D ≤ 0).
    min_distance : float
        Smallest clearance, m.
    duration : float
        Length of the measured half, s.
    """

    mean_distance: float
    peak_to_peak: float
    heading_amplitude: float | None
    period: float | None
    at_rest: bool
    touches_wall: bool
    min_distance: float
    duration: float

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units; undefined: None)."""
        return asdict(self)


def wall_cycle(repulsion, attraction, alpha, robot, *, T, compute_delay=1, duration=60.0, start_distance=None) -> WallCycle:
    """The non-smooth wall run of GC2002's velocity-gated repulsion: simulate, drop the transient, measure.

    The wall is the line x = 0 (normal +x, the robot at x = d > 0, travelling along +y);
    a constant pull of magnitude `attraction` (N per unit mass, the unit of the repulsion:
    a point mass is simulated with m = 1, its `a_max` kept) points towards a target at infinity at angle `alpha` from the wall
    normal, F_a(−cos α, sin α), and `repulsion` acts from the wall alone. The run lasts
    `duration`; its first half is discarded as the transient and the second half measured.

    Parameters
    ----------
    repulsion : VelocityGatedRepulsion
    attraction : float
        F_a, N, in (0, 1e9].
    alpha : float
        Angle of the target from the wall normal, rad, in (0, π/2).
    robot : PointMass, Steering or DiffDrive
    T : float
        Sampling period, s.
    compute_delay : {0, 1}
    duration : float
        s, at least 20 sampling periods.
    start_distance : float, optional
        Initial clearance, m; default the rest band's edge d_s = √(η/(F_a cos α)) (capped
        at ρ0; `VelocityGatedRepulsion.non_smooth_wall`). A point mass starts at rest, a
        steering or differential-drive robot heading along the wall.

    Returns
    -------
    WallCycle
    """
    check_type("repulsion", repulsion, VelocityGatedRepulsion, "a VelocityGatedRepulsion")
    Fa = check_number("attraction", attraction, 0.0, 1e9, high_open=False, unit="N")
    alpha = check_number("alpha", alpha, 0.0, math.pi / 2, unit="rad")
    check_type("robot", robot, (PointMass, Steering, DiffDrive), "a PointMass, Steering or DiffDrive")
    band = repulsion.non_smooth_wall(Fa, alpha)
    d0 = band.d_s if start_distance is None else check_number("start_distance", start_distance, 0.0, 1e6, unit="m")
    T = check_number("T", T, 0.0, 1e4, high_open=False, unit="s")
    duration = check_number("duration", duration, 0.0, 1e7, high_open=False, unit="s")
    if duration < 20 * T:
        raise ValueError(f"duration must be at least 20 sampling periods (20T = {20 * T:g} s); got {duration:g}")
    if isinstance(robot, PointMass):  # forces per unit mass: the motion does not depend on the mass
        robot = PointMass(1.0, robot.a_max)
    field = Field(Pull(Fa, math.pi - alpha), repulsion)
    world = World(obstacles=(Wall((0.0, 0.0), (1.0, 0.0)),))
    run = simulate_planar(robot, field, world, T=T, compute_delay=compute_delay, duration=duration,
                          start=Start((d0, 0.0), heading=math.pi / 2), on_collision="stop")
    return measure_wall_cycle(run)


def measure_wall_cycle(run: PlanarRun, mass: float = 1.0) -> WallCycle:
    """`WallCycle` of a run beside the wall x = 0 travelling along +y (the second half of the run; `mass`, kg, of a point mass).

    Parameters
    ----------
    run : PlanarRun
        A run beside the wall x = 0 travelling along +y.
    mass : float
        The point mass's mass, kg.
    """
    keep = run.t >= run.t[-1] / 2.0
    t, d = run.t[keep], run.p[keep, 0]
    span = float(d.max() - d.min())
    heading = None
    if run.theta is not None:
        relative = run.theta[keep] - math.pi / 2
        heading = float(relative.max() - relative.min()) / 2.0
    tolerance = REST_TOLERANCE
    if run.theta is None:  # a point mass: the sampled relay's chatter
        lateral = float(np.max(np.abs(run.force[keep, 0]))) / mass
        tolerance = max(tolerance, (2 + run.compute_delay) ** 2 * lateral * run.T**2)
    at_rest = span < tolerance
    period = None
    if not at_rest:
        turns = turning_points(d, HYSTERESIS * span)
        maxima = [i for i in turns if i > 0 and i < d.size - 1 and d[i] >= d[i - 1] and d[i] >= d[i + 1]]
        if len(maxima) >= 2:
            period = float(np.mean(np.diff(t[maxima])))
    touches = any(e.kind in ("contact", "collision_unavoidable") for e in run.events)
    return WallCycle(
        mean_distance=float(np.mean(d)),
        peak_to_peak=span,
        heading_amplitude=heading,
        period=period,
        at_rest=bool(at_rest),
        touches_wall=bool(touches),
        min_distance=float(d.min()),
        duration=float(t[-1] - t[0]),
    )
