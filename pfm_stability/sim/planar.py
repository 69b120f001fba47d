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

The engine is batched (`sim.planar_batch`): `simulate_planar_batch` steps many
`PlanarMember` runs together in arrays, each with its own robot, field, world, start, T,
compute delay and duration; `simulate_planar` and `wall_cycle` are batches of one, and
`wall_member` makes a wall run a member. This module gathers the planar simulator's names
(the scene of `sim.planar_field`, the robots of `sim.planar_robots`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..checks import check_number, check_type
from ..laws.velocity_laws import VelocityGatedRepulsion
from .metrics import HYSTERESIS, turning_points
from .movers import Pull, Wall
from .planar_batch import COLLISION_POLICIES, STOP_REASONS, PlanarBatch, PlanarEvent, PlanarMember, PlanarRun, simulate_planar_batch
from .planar_field import Field, Start, World
from .planar_robots import DiffDrive, PointMass, Steering

__all__ = [
    "COLLISION_POLICIES",
    "REST_TOLERANCE",
    "STOP_REASONS",
    "DiffDrive",
    "Field",
    "PlanarBatch",
    "PlanarEvent",
    "PlanarMember",
    "PlanarRun",
    "PointMass",
    "Pull",
    "Start",
    "Steering",
    "WallCycle",
    "World",
    "measure_wall_cycle",
    "simulate_planar",
    "simulate_planar_batch",
    "wall_cycle",
    "wall_member",
]

REST_TOLERANCE = 1e-3
"""Largest lateral peak-to-peak (m) of the measured half of a wall run for a robot to count as at rest.

A point mass resting in the Filippov band chatters at the sampling rate (the sampled relay:
its lateral velocity changes sign every 2 + d samples, d the compute delay), by at most
(2 + d)²·a·T² with a = max|F_x|/m over the measured half; its tolerance is the larger of
the two (5.3 mm measured at T = 0.065 s, d = 1, against a bound of 19 mm). A steering
robot's relay cycle has no such bound (its amplitude is ∝ T, tenths of a metre at KB's T)."""

def simulate_planar(robot, field: Field, world: World, *, T: float, compute_delay: int = 0, duration: float, start: Start, on_collision: str = "stop") -> PlanarRun:
    """Simulate one robot in a planar field, sampled with period T: a batch of one (`simulate_planar_batch`).

    Parameters
    ----------
    robot : PointMass, Steering or DiffDrive
        The robot.
    field : Field
        Attraction and repulsion.
    world : World
        Target and obstacles.
    T : float
        Sampling period, s, in (0, 1e4].
    compute_delay : {0, 1}
        Periods between a sample and the application of the command computed from it.
    duration : float
        s, in (0, 1e7]; the run has ⌈duration/T⌉ + 1 samples unless it stops earlier.
    start : Start
        Initial state.
    on_collision : {"stop", "continue"}
        At D ≤ 0 while approaching (the repulsion undefined): stop, or continue with
        that repulsion taken as 0. A contact (clearance ≤ 0) always stops the run.

    Returns
    -------
    PlanarRun
    """
    member = PlanarMember(robot, field, world, start, T=T, duration=duration, compute_delay=compute_delay, on_collision=on_collision)
    return simulate_planar_batch([member]).runs[0]


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


def wall_member(repulsion, attraction, alpha, robot, *, T, compute_delay=1, duration=60.0, start_distance=None) -> PlanarMember:
    """The batch member of GC2002's non-smooth wall run (`wall_cycle`), for `simulate_planar_batch`.

    The wall is the line x = 0 (normal +x, the robot at x = d > 0, travelling along +y);
    a constant pull of magnitude `attraction` (N per unit mass, the unit of the repulsion:
    a point mass is simulated with m = 1, its `a_max` kept) points towards a target at infinity at angle `alpha` from the wall
    normal, F_a(−cos α, sin α), and `repulsion` acts from the wall alone; the run stops at an
    unavoidable collision.

    Parameters
    ----------
    repulsion : VelocityGatedRepulsion
        The wall's repulsion.
    attraction : float
        F_a, N, in (0, 1e9].
    alpha : float
        Angle of the target from the wall normal, rad, in (0, π/2).
    robot : PointMass, Steering or DiffDrive
        The robot.
    T : float
        Sampling period, s.
    compute_delay : {0, 1}
        Periods between a sample and the application of its command.
    duration : float
        s, at least 20 sampling periods.
    start_distance : float, optional
        Initial clearance, m; default the rest band's edge d_s = √(η/(F_a cos α)) (capped
        at ρ0; `VelocityGatedRepulsion.non_smooth_wall`). A point mass starts at rest, a
        steering or differential-drive robot heading along the wall.
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
    return PlanarMember(robot, field, world, Start((d0, 0.0), heading=math.pi / 2), T=T, duration=duration,
                        compute_delay=compute_delay, on_collision="stop")


def wall_cycle(repulsion, attraction, alpha, robot, *, T, compute_delay=1, duration=60.0, start_distance=None) -> WallCycle:
    """The non-smooth wall run of GC2002's velocity-gated repulsion: simulate, drop the transient, measure.

    The run of `wall_member` lasts `duration`; its first half is discarded as the transient
    and the second half measured (`measure_wall_cycle`). Many runs at once:
    ``[measure_wall_cycle(r) for r in simulate_planar_batch([wall_member(...), ...]).runs]``.

    Parameters
    ----------
    repulsion : VelocityGatedRepulsion
        The wall's repulsion.
    attraction : float
        F_a, N, in (0, 1e9].
    alpha : float
        Angle of the target from the wall normal, rad, in (0, π/2).
    robot : PointMass, Steering or DiffDrive
        The robot.
    T : float
        Sampling period, s.
    compute_delay : {0, 1}
        Periods between a sample and the application of its command.
    duration : float
        s, at least 20 sampling periods.
    start_distance : float, optional
        Initial clearance, m (`wall_member`).

    Returns
    -------
    WallCycle
    """
    member = wall_member(repulsion, attraction, alpha, robot, T=T, compute_delay=compute_delay, duration=duration, start_distance=start_distance)
    return measure_wall_cycle(simulate_planar_batch([member]).runs[0])


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
