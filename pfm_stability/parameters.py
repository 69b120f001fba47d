"""Robot, controller and scenario parameters, every vocabulary and range, and the CARMEL preset.

The one place where names and ranges live: model names, sampled structures,
geometries, simulator environments and robot families, and `RANGES` (library,
vectorized code and CLI). The force laws, their parameters and who takes them
are declared in the law registry (`pfm_stability.laws.registry`), whose ranges
are the entries here. This module imports no numpy, so the command line
can validate input before loading it. The presets (``CARMEL``, `PRESETS`) are
the package's configuration files ``data/presets/*.yaml`` (docs/config.md),
each read on first use.

All quantities are SI (m, s, rad); degrees exist only at the edges: typed
angles come in through `Wall.from_degrees` (`to_radians` for arrays), and
reported ones go out through `to_degrees`.
Symbols follow Koren & Borenstein 1991 ("KB"): V, tau (τ, eq 6), k (eq 5),
W (eq 1), f (eq 13), n (eq 1, 8), T (eq 18), alpha (α, eq 9), L (eq 25).

Every dataclass validates itself on construction and raises :class:`ValueError`
with a one-line message naming the parameter and its allowed range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from .checks import check_choice, check_integer, check_number

__all__ = [
    "Range",
    "RANGES",
    "check_parameter",
    "describe_parameter",
    "Robot",
    "Controller",
    "Wall",
    "Corridor",
    "Preset",
    "CARMEL",
    "PRESETS",
    "get_preset",
    "HOLDS",
    "COMPUTE_DELAYS",
    "SAMPLED_STRUCTURES",
    "MODEL_NAMES",
    "GEOMETRIES",
    "ENVIRONMENTS",
    "DOOR_OBSTACLES",
    "TRAPS_RESOLUTION",
    "ROBOT_FAMILIES",
    "DERIVATION_LAWS",
    "DEGREES_PER_RADIAN",
    "RADIANS_PER_DEGREE",
    "to_degrees",
    "to_radians",
    "TAU_RESOLUTION",
    "T_RESOLUTION",
    "DEAD_TIME_RESOLUTION",
    "dead_time_split",
    "KB_PLANT",
    "plant_not_kb",
    "check_corridor_fits",
]

TAU_RESOLUTION = 1e-9
"""τ with τ·k below this is taken as 0, an ideal steering motor, by the models and the simulator
alike: the lag is 10⁹ times faster than the steering loop, below the resolution of either, and its
pole at −1/τ would leave floating point."""

DEAD_TIME_RESOLUTION = 1e-9
"""A dead time within this fraction of a period of a whole number of periods is taken as that whole number
(`dead_time_split`): D/T is rarely exact in floating point (0.1/0.05 is 2 to round-off, or just under), and a
sub-interval of 1e-9·T moves the robot by 1e-9 of a step while it adds a mode at z = 0 that the
simulator's linear-prediction fit and the sampled model would have to carry."""


KB_PLANT = {"plant_gain": 1.0, "dead_time": 0.0, "actuator_lag": 0.0, "slip_lag": 0.0}
"""KB's steering plant τω̇ + ω = u: plant gain 1, no dead time, no second lag, no slip (`Robot`'s and `models.Loop`'s
defaults)."""


def plant_not_kb(source) -> dict:
    """The fields of a steering plant that differ from KB's (`KB_PLANT`), in that order; {} for KB's plant.

    Parameters
    ----------
    source : Robot or models.Loop
        Anything with ``plant_gain``, ``dead_time`` (s), ``actuator_lag`` (s) and ``slip_lag`` (s).
    """
    return {name: getattr(source, name) for name, kb in KB_PLANT.items() if getattr(source, name) != kb}


def dead_time_split(T: float, compute_delay: int, dead_time: float) -> tuple:
    """(m, ε): a command computed at t_k reaches the motor at t_k + d·T + D = t_k + m·T + ε, 0 <= ε < T.

    Over [t_k, t_k+1) the motor then sees u_(k−m−1) for the first ε seconds and
    u_(k−m) for the rest: the one rule of the simulator (`sim.robot.delay_split`) and
    of the `sampled` model (docs/models.md, "Plant gain and dead time"). ε within
    `DEAD_TIME_RESOLUTION`·T of 0 or of T is snapped to a whole period.

    Parameters
    ----------
    T : float
        Sampling period, s (> 0).
    compute_delay : int
        d, samples (0 or 1).
    dead_time : float
        D, s (>= 0).

    Returns
    -------
    m : int
        Whole periods, d included.
    eps : float
        The fraction of a period, s, in [0, T).
    """
    whole = math.floor(dead_time / T)
    eps = max(dead_time - whole * T, 0.0)
    if eps > (1.0 - DEAD_TIME_RESOLUTION) * T:
        whole, eps = whole + 1, 0.0
    elif eps < DEAD_TIME_RESOLUTION * T:
        eps = 0.0
    return int(compute_delay) + int(whole), eps


T_RESOLUTION = 1e-12
"""A loop delay / sampling period T (s) below this is taken as 0, a continuous controller, by the
loop models: no digital controller samples faster than a picosecond, and below ~1e-100 s the
models' crossing frequencies (√(k/T), π/T) leave floating point. Without it a period such as
1e-300 s gave overflow warnings instead of the continuous loop's answer."""

MODEL_NAMES = ("continuous", "kb_first_order", "pade", "exact_delay", "sampled")
"""The loop models, in order of fidelity (docs/models.md)."""

HOLDS = ("command", "reference")
"""What the sampled computer holds between samples: the whole steering command, or the reference δ."""

COMPUTE_DELAYS = (0, 1)
"""Samples from measurement to actuation."""

SAMPLED_STRUCTURES = tuple((hold, delay) for hold in HOLDS for delay in COMPUTE_DELAYS)
"""Every (hold, compute_delay) of the ``sampled`` model."""

GEOMETRIES = ("corridor", "wall")
"""The environments the analysis linearizes: the middle of a corridor, travel along a wall."""

ENVIRONMENTS = ("grid", "analytic")
"""Simulator environments: a histogram grid of cells, or continuous walls with a force law."""

TRAPS_RESOLUTION = 81
"""Default grid points of the stationary-point search along a scene's longer side (`traps`; in ``RANGES["resolution"]``)."""

DOOR_OBSTACLES = ("posts", "wall-ends")
"""What bounds a door (KB Fig 4; docs/door.md): two posts, or the ends of two walls."""

ROBOT_FAMILIES = ("steering", "kinematic", "holonomic")
"""Robot loop families of ``report --robot`` (docs/models.md, "Robot loop families"): KB's steering
robot, Ge & Cui 2002's kinematic steering (τ = 0, k = K_s) and the holonomic robot (force = acceleration)."""

DERIVATION_LAWS = ("power", "general")
"""Force laws of the symbolic derivation (`pfm_stability.analysis.derivation`, ``pfm-stability derive --law``):
KB's power law (eq 8, 13) and a general F_r(d) (docs/theory.md)."""

DEGREES_PER_RADIAN = 180.0 / math.pi
"""Degrees per radian, for output (`to_degrees`)."""

RADIANS_PER_DEGREE = math.pi / 180.0
"""Radians per degree, for input (`to_radians`, `Wall.from_degrees`)."""


def to_degrees(angle):
    """An angle in rad (a number or a numpy array) in degrees, for output.

    Bit for bit ``math.degrees`` and ``numpy.degrees`` (both multiply by 180/π),
    without importing numpy here.

    Parameters
    ----------
    angle : float or ndarray
        Angle, rad.
    """
    return angle * DEGREES_PER_RADIAN


def to_radians(angle_deg):
    """An angle in degrees (a number or a numpy array) in rad, for input.

    Bit for bit ``math.radians`` and ``numpy.radians`` (both multiply by π/180).
    Unchecked: a single wall angle goes through `Wall.from_degrees`, which checks it.

    Parameters
    ----------
    angle_deg : float or ndarray
        Angle, degrees.
    """
    return angle_deg * RADIANS_PER_DEGREE


@dataclass(frozen=True)
class Range:
    """Allowed values of one parameter (bounds, openness, unit).

    Attributes
    ----------
    low, high : float
        Bounds, in `unit`.
    low_open, high_open : bool
        Whether each bound is excluded.
    unit : str
        Unit shown in messages and help.
    """

    low: float
    high: float
    low_open: bool = True
    high_open: bool = False
    unit: str = ""

    def describe(self) -> str:
        """E.g. ``(0, 100] m/s``."""
        from .checks import describe_range

        return describe_range(self.low, self.high, self.low_open, self.high_open) + (f" {self.unit}" if self.unit else "")


_ALPHA_MARGIN_DEG = 1e-6
# α within 1e-6° of 0 or 90° makes N (∝ 1/sin α, or the equilibrium distance
# ∝ (cos α)^(−1/n)) overflow what the root finders can represent; the answer
# there is the limit already reached at 1e-6° (unstable at 0, stable at 90°).

RANGES = {
    "V": Range(0.0, 100.0, unit="m/s"),
    "tau": Range(0.0, 100.0, low_open=False, unit="s"),
    "T": Range(0.0, 100.0, low_open=False, unit="s"),
    "k": Range(1e-6, 1e4, low_open=False, unit="1/s"),
    "W": Range(1e-3, 100.0, low_open=False, unit="m"),
    "f": Range(1e-6, 1e6, low_open=False),
    "n": Range(0.01, 10.0, low_open=False),
    "alpha": Range(_ALPHA_MARGIN_DEG * math.pi / 180, math.pi / 2 - _ALPHA_MARGIN_DEG * math.pi / 180, low_open=False, unit="rad"),
    "alpha_deg": Range(_ALPHA_MARGIN_DEG, 90.0 - _ALPHA_MARGIN_DEG, low_open=False, unit="deg"),
    "L": Range(0.0, 1e4, unit="m"),
    "max_steering_rate": Range(0.0, math.inf, high_open=True, unit="rad/s"),
    "dead_time": Range(0.0, 10.0, low_open=False, unit="s"),
    "plant_gain": Range(1e-3, 100.0, low_open=False),
    "actuator_lag": Range(0.0, 10.0, low_open=False, unit="s"),
    "slip_lag": Range(0.0, 10.0, low_open=False, unit="s"),
    "yaw_accel_limit": Range(0.0, math.inf, high_open=True, unit="rad/s^2"),
    # where a computation needs a narrower range than the parameter's own
    "T_sampled": Range(0.0, 100.0, unit="s"),
    # simulator and validation options
    "offset": Range(-100.0, 100.0, low_open=False, unit="m"),
    "duration": Range(0.0, 1e6, high_open=True, unit="s"),
    "cell_ratio": Range(0.0, 1e6),
    "cell_size": Range(0.01, 1.0, low_open=False, unit="m"),
    "start_jitter": Range(0.0, 100.0, low_open=False, unit="m"),
    "rtol": Range(0.0, 0.5, high_open=True),
    # potential-field laws (Ge & Cui 2000; docs/fields.md)
    "xi": Range(1e-6, 1e6, low_open=False),
    "eta": Range(1e-6, 1e6, low_open=False),
    "rho0": Range(1e-3, 1e4, low_open=False, unit="m"),
    "attraction_exponent": Range(1.0, 10.0, low_open=False),
    "goal_exponent": Range(0.0, 10.0, low_open=False),
    "goal_distance": Range(1e-3, 1e4, low_open=False, unit="m"),
    "delta": Range(0.0, 1e3, low_open=False, unit="m"),
    # robot loop families (docs/models.md, "Robot loop families")
    "c_h": Range(-1e15, 1e15, low_open=False, unit="1/s"),
    "kappa": Range(-1e12, 1e12, low_open=False, unit="1/s^2"),
    "mass": Range(0.0, 1e6, unit="kg"),
    "alpha_p": Range(0.0, 1e6, unit="N/m"),
    "alpha_v": Range(0.0, 1e6, low_open=False, unit="N s/m"),
    "a_max": Range(0.0, 1e6, unit="m/s^2"),  # GC2002 eq 11 (docs/velocity_and_fuzzy.md)
    "velocity_exponent": Range(0.0, 10.0, unit=""),  # n of GC2002's α_v‖ė‖ⁿ (docs/velocity_and_fuzzy.md)
    "step": Range(0.0, 1e6, unit="m"),
    "min_length": Range(0.0, 1e4, unit="m"),  # map: shortest segment analysed
    "dilate_upstream": Range(0.0, 1e6, unit="m/s^2"),  # map: braking deceleration of the mask's upstream dilation
    # a Nav2 controller's measured lateral gains (report --controller mppi|dwb, docs/path_tracking.md)
    "k_theta": Range(0.0, 1e4, unit="1/s"),
    "k_y": Range(-1e6, 1e6, low_open=False, unit="1/(m s)"),
    "k_theta_se": Range(0.0, 1e4, low_open=False, unit="1/s"),
    "k_y_se": Range(0.0, 1e6, low_open=False, unit="1/(m s)"),
    # integers (closed bounds, checked with `checks.check_integer`)
    "compute_delay": Range(0, 1, low_open=False, unit="samples"),
    "pade_order": Range(1, 12, low_open=False),
    "window_cells": Range(3, 1001, low_open=False, unit="cells"),
    "members": Range(3, 1000, low_open=False),
    "resolution": Range(10, 1000, low_open=False, unit="points per side"),
    "door": Range(0.0, 1e4, unit="m"),
    "post_radius": Range(0.0, 1e4, low_open=False, unit="m"),
    "wobble": Range(0.0, 1e4, unit="m"),  # report --wobble: the tolerance on the corridor's wobble (docs/wobble.md)
    "disturbance": Range(0.0, 1e4, unit="m"),  # report --disturbance: a start's offset from the equilibrium (docs/wobble.md)
    "sweep": Range(8, 100_000, low_open=False),
    "validate": Range(1, 1000, low_open=False),  # map: segments simulated
    "seed": Range(0, 2**63 - 1, low_open=False),
    "workers": Range(1, 4096, low_open=False),
    "chunk_size": Range(1, 100_000_000, low_open=False, unit="points"),
}
"""The one place where parameter ranges live (library, vectorized code and CLI).

Lower bounds are physical (V > 0, τ >= 0, a steering gain of at least
10⁻⁶ 1/s, a width of at least 1 mm, f >= 10⁻⁶, n >= 0.01 …); upper bounds
are generous caps (100 m/s, 100 s, 10⁴ 1/s …). Both keep every computation
inside floating point (f^(1/n) and Wⁿ of an equilibrium, a scan over k).

``dead_time``, ``plant_gain``
    The steering plant g·e^(−sD)/(τs + 1) of a real robot (docs/simulator.md,
    "Plant gain and dead time"): D in [0, 10] s — causal (``identify`` writes a
    negative estimate as 0), and 10 s is ten times the longest dead time
    ``identify`` searches, far past any steering robot; g in [10⁻³, 100] —
    achieved over commanded turning rate, positive (g <= 0 turns the other way
    or not at all: a sign error in the log, not a robot; ``identify`` refuses
    |g| < 0.05 as "did not follow the commands"), and the ends keep the loop
    gain g·k within [10⁻⁹, 10⁶] 1/s, inside floating point for every model.

Entries beyond the robot, controller and geometry:

``actuator_lag``, ``yaw_accel_limit``
    The drive beyond the first-order plant: a second lag τ_a of an actuator filter, the plant
    g·e^(−sD)/((τs + 1)(τ_a·s + 1)), in [0, 10] s (0: none, the first-order plant); and the largest rate of
    change of the commanded yaw rate the drive's velocity smoother lets through (Nav2's
    ``velocity_smoother`` ``max_accel`` on the angular axis), rad/s², > 0 (none by default: ``inf``,
    which is not typed but left out).

``T_sampled``
    T where the computation samples (simulator, validation, root locus of the
    delay loop): (0, 100] s, reported as ``T``; T = 0 (a continuous
    controller) is allowed by the analysis only.
``offset``
    Start offset from the equilibrium line, m, in [−100, 100].
``duration``
    Simulated time, s, in (0, 10⁶).
``cell_ratio``
    Histogram grid: ρ = F_cr/F_ct per cell, in (0, 10⁶].
``cell_size``
    Histogram grid cell side, m, in [0.01, 1] (KB: 0.1 m).
``start_jitter``
    Standard deviation of a random lateral start offset, m, in [0, 100].
``rtol``
    Relative width of a bisection's final bracket, in (0, 0.5).
``xi``, ``eta``
    Attractive and repulsive scaling factors ξ, η of Ge & Cui 2000 (eq 1, 3, 8),
    in [10⁻⁶, 10⁶] (docs/fields.md).
``rho0``
    Influence distance ρ0 of the repulsion, m, in [10⁻³, 10⁴].
``attraction_exponent``, ``goal_exponent``
    m of U_att = ½ξρ_gᵐ, in [1, 10] (Ge & Cui: 1 or 2); n of the goal-aware
    repulsion U_rep·ρ_gⁿ, in [0, 10] (0 is Khatib's law).
``goal_distance``
    ρ_g, the frozen distance to the goal, m, in [10⁻³, 10⁴].
``delta``
    The surface offset δ of Ge & Cui's eq (40), m, in [0, 10³].
``c_h``, ``kappa``
    The holonomic loop s² + (c_h·s + κ)e^(−sT) (docs/models.md, "Robot loop
    families"): damping c_h in [−10¹⁵, 10¹⁵] 1/s (the damping ranges' ends reach
    about 31/T for the Padé model, 3·10¹³ 1/s at the shortest delay, `T_RESOLUTION`), stiffness κ in
    [−10¹², 10¹²] 1/s² (κ = 0 is refused by the models: a root at s = 0).
``mass``, ``alpha_p``, ``alpha_v``
    Target tracking of Ge & Cui 2002 eq (33)–(36): mass m in (0, 10⁶] kg,
    position gain α_p in (0, 10⁶] N/m, velocity gain α_v in [0, 10⁶] N·s/m;
    ``velocity_exponent`` n of α_v‖ė‖ⁿ in (0, 10] (Ge & Cui 2002 eq 1).
``step``
    The gradient-step planner's step h = VT, m, in (0, 10⁶].
``compute_delay``, ``pade_order``, ``window_cells``, ``members``, ``sweep``, ``seed``
    Integers in closed ranges: samples from measurement to actuation [0, 1];
    Padé order m [1, 12]; grid window side [3, 1001] cells (odd, KB: 33);
    runs per bisection round [3, 1000]; random parameter sets of a sweep
    [8, 10⁵]; random seeds [0, 2⁶³ − 1].
``workers``, ``chunk_size``
    ``pfm-stability sweep`` (docs/sweeps.md): local threads or worker processes
    [1, 4096]; points per chunk [1, 10⁸].
"""


SHOWN_AS = {"alpha_deg": "alpha", "T_sampled": "T"}
"""Range entries that stand for a parameter the user knows under another name."""


def describe_parameter(key: str) -> str:
    """``RANGES[key]`` for a help text, e.g. ``(0, 100] m/s``; an integer range exactly, ``[3, 1001] cells``.

    Parameters
    ----------
    key : str
        A key of `RANGES`.
    """
    r = RANGES[key]
    if isinstance(r.low, int) and isinstance(r.high, int):
        return f"[{r.low}, {r.high}]" + (f" {r.unit}" if r.unit else "")
    return r.describe()


def check_parameter(name: str, value) -> float:
    """`value` as a float if it lies in ``RANGES[name]``, else ValueError.

    The message names the parameter as the user knows it (``alpha_deg`` is
    reported as ``alpha``), the range with its unit, and the value.

    Parameters
    ----------
    name : str
        A key of `RANGES`.
    value : object
        The value to check.
    """
    r = RANGES[name]
    shown = SHOWN_AS.get(name, name)
    return check_number(shown, value, r.low, r.high, low_open=r.low_open, high_open=r.high_open, unit=r.unit)



@dataclass(frozen=True)
class Robot:
    """A synchro-drive robot with a first-order steering-rate lag (KB eq 6), a plant gain and a dead time.

    Parameters
    ----------
    V : float
        Travel speed, m/s, in (0, 100].
    tau : float
        Steering-motor time constant τ, s, in [0, 100] (KB eq 6; 0 = ideal motor).
    k : float
        Steering gain, 1/s, in [10⁻⁶, 10⁴] (KB eq 5: u = k(δ − θ)).
    W : float
        Robot width, m, in [10⁻³, 100] (KB eq 1).
    max_steering_rate : float
        Largest commanded steering rate |u|, rad/s, > 0 (CARMEL: 120°/s). Used by the
        simulator only; the linear analysis assumes no saturation. It limits the
        command, before the plant gain: the motor reaches at most g·max_steering_rate.
    dead_time : float
        Dead time D of the steering plant, s, in [0, 10]: a command reaches the
        motor D after the controller applies it (docs/simulator.md, "Plant gain
        and dead time"; 0 = KB's robot).
    plant_gain : float
        Plant gain g, achieved over commanded turning rate, in [10⁻³, 100]
        (1 = KB's robot): the motor is τω̇ + ω = g·u(t − D).
    actuator_lag : float
        A second lag τ_a of the drive (an actuator filter), s, in [0, 10]: the plant is
        g·e^(−sD)/((τs + 1)(τ_a·s + 1)) (0 = KB's first-order plant; docs/models.md).
    yaw_accel_limit : float
        The largest rate of change of the commanded yaw rate, rad/s², > 0 (a velocity smoother's angular
        acceleration limit); ``inf`` (the default) = none. Nonlinear: the linear models do not see it.
    slip_lag : float
        The lag τ_s of the robot's course (its direction of travel) behind its heading, s, in [0, 10]: a base that
        slides sideways in a turn (a skid-steer, soft tyres) moves along χ with τ_s·χ̇ + χ = θ, ẋ = V·χ (0 = it goes
        where it points, KB's robot; docs/models.md, "A base that slides").
    """

    V: float
    tau: float
    k: float
    W: float
    max_steering_rate: float = math.radians(120.0)
    dead_time: float = 0.0
    plant_gain: float = 1.0
    actuator_lag: float = 0.0
    yaw_accel_limit: float = math.inf
    slip_lag: float = 0.0

    def __post_init__(self):
        for name in ("V", "tau", "k", "W", "max_steering_rate", "dead_time", "plant_gain", "actuator_lag", "slip_lag"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        if self.yaw_accel_limit != math.inf:  # inf: no limit (the default, never typed)
            object.__setattr__(self, "yaw_accel_limit", check_parameter("yaw_accel_limit", self.yaw_accel_limit))

    def replace(self, **changes) -> "Robot":
        """Return a copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class Controller:
    """The VFF potential-field controller and how it samples.

    Parameters
    ----------
    f : float
        Repulsive/attractive force-constant ratio, in [10⁻⁶, 10⁶] (KB eq 13).
    n : float
        Repulsion exponent, in [0.01, 10] (KB eq 1, 8).
    T : float
        Sampling period, s, in [0, 100] (KB eq 18; 0 = continuous controller).
    hold : {"command", "reference"}
        What the sampled computer holds between samples (docs/models.md, `sampled`):
        ``"command"`` holds u = k(δ_k − θ_k); ``"reference"`` holds δ_k and the
        steering servo closes k(δ − θ) continuously.
    compute_delay : {0, 1}
        Samples between measuring at t_k and applying the result.
    """

    f: float
    n: float
    T: float
    hold: str = "command"
    compute_delay: int = 0

    def __post_init__(self):
        for name in ("f", "n", "T"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        check_choice("hold", self.hold, HOLDS)
        object.__setattr__(self, "compute_delay", check_integer("compute_delay", self.compute_delay, 0, 1))

    def replace(self, **changes) -> "Controller":
        """Return a copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class Wall:
    """Travel along a long wall with the target at angle α (KB Fig 2, eq 9).

    Parameters
    ----------
    alpha : float
        Angle between the wall normal (towards the wall) and the target
        direction, rad, in [1e-6°, 90° − 1e-6°]; π/2 = target straight ahead
        along the wall.
    """

    alpha: float

    def __post_init__(self):
        object.__setattr__(self, "alpha", check_parameter("alpha", self.alpha))

    @classmethod
    def from_degrees(cls, alpha_deg: float) -> "Wall":
        """Build from α in degrees, with the range stated in degrees on error.

        Parameters
        ----------
        alpha_deg : float
            Target angle from the wall normal, degrees.
        """
        alpha_deg = check_parameter("alpha_deg", alpha_deg)
        r = RANGES["alpha"]
        return cls(min(max(to_radians(alpha_deg), r.low), r.high))  # round-off at the ends

    @property
    def alpha_deg(self) -> float:
        """α in degrees (`to_degrees`), for output."""
        return to_degrees(self.alpha)


@dataclass(frozen=True)
class Corridor:
    """Travel down the middle of a corridor, target straight ahead (KB §5.4).

    Parameters
    ----------
    L : float
        Half-width: robot centre line to each wall, m, in (W/2, 10⁴] (KB eq 25).
    """

    L: float

    def __post_init__(self):
        object.__setattr__(self, "L", check_parameter("L", self.L))


def check_corridor_fits(corridor: Corridor, robot: Robot) -> None:
    """Raise ValueError unless the robot fits: L > W/2.

    Parameters
    ----------
    corridor : Corridor
        The corridor (L, m).
    robot : Robot
        The robot (W, m).

    Raises
    ------
    ValueError
        ``"L must be a finite number in (W/2, inf) m = (0.4, inf) m; got 0.3"``.
    """
    if not corridor.L > robot.W / 2:
        high = RANGES["L"].high
        raise ValueError(f"L must be a finite number in (W/2, {high:g}] m = ({robot.W / 2:g}, {high:g}] m; got {corridor.L!r}")


@dataclass(frozen=True)
class Preset:
    """A named robot + controller with the provenance of every value.

    Attributes
    ----------
    name : str
        Preset name used by the CLI (``--preset``).
    robot : Robot
    controller : Controller
    assumed : dict[str, str]
        Parameters the source does not give, with why the value was chosen.
    source : str
        Where the other values come from.
    cell_size : float
        Histogram-grid cell size, m (KB §2: 0.1 m).
    window_cells : int
        Active-window side w_s, cells (KB §2: 33).
    """

    name: str
    robot: Robot
    controller: Controller
    assumed: dict = field(default_factory=dict)
    source: str = ""
    cell_size: float = 0.1
    window_cells: int = 33


PRESET_DIRECTORY = Path(__file__).resolve().parent / "data" / "presets"
"""The shipped presets, one configuration file each (``carmel.yaml``; docs/config.md)."""


class _Presets(Mapping):
    """The shipped presets by name, each read from its YAML file on first use.

    The names come from the file names, so listing them (``--preset`` choices,
    ``--help``) reads no file and imports no YAML parser.
    """

    def __init__(self, directory: Path):
        self._directory = directory
        self._loaded = {}

    def _names(self) -> tuple:
        return tuple(sorted(p.stem for p in self._directory.glob("*.yaml")))

    def __getitem__(self, name):
        if name not in self._loaded:
            if name not in self._names():
                raise KeyError(name)
            self._loaded[name] = _read_preset(self._directory / f"{name}.yaml")
        return self._loaded[name]

    def __iter__(self):
        return iter(self._names())

    def __len__(self):
        return len(self._names())


def _read_preset(path: Path) -> Preset:
    """The `Preset` of a shipped file (docs/config.md: ``name``, ``source``, ``robot``, ``controller``, ``assumed``).

    Read by the package's one YAML reader (`pfm_stability.io.yaml_files`); the file's values are checked
    by `Robot` and `Controller`, and a key they do not take is an error naming the file and its line.
    (User files go through the stricter `pfm_stability.io.config`.)
    """
    from .io.yaml_files import read_yaml

    document = read_yaml(path, "preset")
    data = document.data
    robot = dict(data["robot"])
    if "max_steering_rate" in robot:  # deg/s in the file, as angles everywhere at the edges
        robot["max_steering_rate"] = math.radians(robot["max_steering_rate"])
    built = {}
    for section, cls, values in (("robot", Robot, robot), ("controller", Controller, data["controller"])):
        try:
            built[section] = cls(**values)
        except (TypeError, ValueError) as exc:  # an unknown key, a value out of range
            raise document.error(f"{section}: {exc}", section) from None
    return Preset(
        name=data.get("name", path.stem), robot=built["robot"], controller=built["controller"],
        assumed=dict(data.get("assumed") or {}), source=data.get("source", ""),
    )


PRESETS = _Presets(PRESET_DIRECTORY)
"""The shipped presets by name (a read-only mapping; each file is read on first use)."""


def get_preset(name: str) -> Preset:
    """Return the preset called `name` (``"carmel"``), read from ``data/presets/<name>.yaml``.

    Parameters
    ----------
    name : str
        A preset of `PRESETS`.

    Raises
    ------
    ValueError
        If no preset has that name.
    """
    check_choice("preset", name, tuple(PRESETS))
    return PRESETS[name]


def __getattr__(name):
    """``CARMEL``: the shipped preset ``carmel.yaml``, read when first asked for (PEP 562)."""
    if name == "CARMEL":
        return get_preset("carmel")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
