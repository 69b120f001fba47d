"""Nav2's path-tracking laws linearised about a straight path: the gains k_θ, k_y and the speed they drive at.

On a straight path (or the centre line of a straight corridor of half-width L_c) the robot at lateral offset e_y
(m, to the left) with heading error e_θ (rad) is commanded the yaw rate

    ω = −k_θ·e_θ − k_y·e_y      (to first order),

at the forward speed V the controller itself chooses there. That is Koren & Borenstein's steering command
u = −kθ − K·y (y = x/V) with k = k_θ and K = k_y·V: the loop's NV = k_y·V/k_θ (`models.Loop`, heading sampled by the
controller). docs/path_tracking.md derives each law:

* **Regulated Pure Pursuit** (`PurePursuit`): the carrot at arc L along the path lies at y_L = −(e_y + L·e_θ) in
  the robot's frame, κ = 2·y_L/(x_L² + y_L²) = 2·y_L/L² to first order and ω = V·κ, so k_θ = 2V/L, k_y = 2V/L²:
  k = 2ρ and NV = ρ with ρ = V/L. L is ``lookahead_dist``, or clamp(V·``lookahead_time``, min, max) with
  ``use_velocity_scaled_lookahead_dist`` (V the measured speed: on the path, the regulated one), or
  ``curvature_lookahead_dist`` with ``use_fixed_curvature_lookahead`` (the curvature that steers is that carrot's).
  V is ``max_linear_vel`` regulated: the curvature heuristic is inactive on a straight path (κ = 0: the radius is
  infinite, and |κ| stays below 1/``regulated_linear_scaling_min_radius`` near it); the cost heuristic scales V by
  ``cost_scaling_gain``·d/``cost_scaling_dist`` when the distance d it reads from the costmap's cost at the robot is
  below ``cost_scaling_dist`` (`corridor_pose_cost`: in a corridor it depends on L_c through the inflation layer).
  The speed's first-order change with e_y multiplies κ = 0: it sets V, not the gains.
* **The Graceful controller** (`Graceful`): the motion target at arc L = ``max_lookahead`` (the farthest valid target:
  in a free straight corridor the first), its egocentric polar coordinates r ≈ L, φ ≈ e_y/L, δ ≈ e_θ + e_y/L, and
  the smooth control law κ = −[k_δ(δ + k_φ·φ) + (1 + k_φ)·δ]/r, so k_θ = V·(1 + k_φ + k_δ)/L and
  k_y = V·(1 + k_φ)(1 + k_δ)/L²: k = b·ρ, NV = a·ρ with b = 1 + k_φ + k_δ, a = (1 + k_φ)(1 + k_δ)/b. V is
  ``v_linear_max``/(1 + β·|κ|^λ) at κ = 0 (1/(1 + β) when λ = 0, as C's pow(0, 0) = 1), then
  min(·, ``v_linear_max``·L/``slowdown_radius``, √(2·L·``deceleration_max``)), clamped to [``v_linear_min``,
  ``v_linear_max``].
* **MPPI and DWB** (`MeasuredGains`): no closed form; k_θ and k_y (with their standard errors) are measured from the
  algorithm about the corridor's centre line at the speed V it drives, and given to the report.

For the two closed-form laws every loop quantity is a function of ρ = V/L alone (k = b·ρ, NV = a·ρ), and ρ is
non-decreasing in the cruising speed and non-increasing in the lookahead: the speed, lookahead and lookahead time at
which ρ reaches a model's critical ρ* are its critical values (`analysis.path_tracking`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..controllers.rpp import curvature_constraint
from ..controllers.costmap import FREE_SPACE, INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, Inflation
from ..parameters import check_parameter

__all__ = ["TrackingPoint", "PurePursuit", "Graceful", "MeasuredGains", "MEMORY_CYCLES", "algorithm_params", "corridor_pose_cost", "inflation_cost", "regulated_distance",
           "path_law"]

FREE, INSCRIBED, LETHAL = FREE_SPACE, INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE
"""The costmap's costs (``nav2_costmap_2d/cost_values.hpp``)."""


@dataclass(frozen=True)
class TrackingPoint:
    """A controller's linearised law at one cruising speed: ω = −k_θ·e_θ − k_y·e_y at forward speed V.

    Attributes
    ----------
    V_set : float
        The cruising speed parameter (``max_linear_vel``, ``v_linear_max``, ``vx_max``, ``max_vel_x``), m/s.
    V : float
        The speed the robot drives along the path (regulated), m/s.
    L : float or None
        The lookahead: the distance to the carrot or motion target, m (None: no lookahead in the law).
    k_theta : float
        −∂ω/∂e_θ, 1/s (the loop's steering gain k).
    k_y : float
        −∂ω/∂e_y, 1/(m·s).
    """

    V_set: float
    V: float
    L: float | None
    k_theta: float
    k_y: float

    @property
    def N(self) -> float:
        """k_y/k_θ, 1/m: the loop's environment gain."""
        return self.k_y / self.k_theta

    @property
    def NV(self) -> float:
        """k_y·V/k_θ, 1/s."""
        return self.k_y * self.V / self.k_theta

    @property
    def ratio(self) -> float | None:
        """ρ = V/L, 1/s (None without a lookahead)."""
        return None if self.L is None else self.V / self.L


def inflation_cost(distance: float, inflation_radius: float, cost_scaling_factor: float, inscribed_radius: float) -> int:
    """The inflation layer's cost at `distance` (m) from the nearest obstacle (``InflationLayer::computeCost``), as the
    costmap stores it: `controllers.costmap.Inflation.cost` truncated to an integer (the cast to ``unsigned char``).

    254 at the obstacle, 253 within the inscribed radius, ⌊252·exp(−cost_scaling_factor·(d − r))⌋ up to
    ``inflation_radius``, 0 (free) beyond.

    Parameters
    ----------
    distance : float
        m.
    inflation_radius, cost_scaling_factor, inscribed_radius : float
        m, 1/m, m.
    """
    return int(math.floor(Inflation(inflation_radius, cost_scaling_factor, inscribed_radius).cost(distance)))


def corridor_pose_cost(half_width: float | None, costmap: dict) -> int:
    """The cost at the centre of a straight corridor: the inflation of the walls at `half_width` (m); 0 in free space.

    The distance is the exact one (a grid of cells moves it by up to half a cell, docs/path_tracking.md).

    Parameters
    ----------
    half_width : float or None
        Centre line to each wall, m (None: no walls).
    costmap : dict
        ``inflation_radius`` (m), ``cost_scaling_factor`` (1/m) and ``inscribed_radius`` (m).
    """
    if half_width is None:
        return FREE
    return inflation_cost(half_width, costmap["inflation_radius"], costmap["cost_scaling_factor"], costmap["inscribed_radius"])


def regulated_distance(pose_cost: float, factor: float, inscribed_radius: float) -> float:
    """The distance to the obstacle RPP's cost heuristic reads from a cost: (f·r − ln c + ln 253)/f, m.

    (``include/nav2_regulated_pure_pursuit_controller/regulation_functions.hpp``, ``costConstraint``; f is RPP's
    ``inflation_cost_scaling_factor``, which should be the inflation layer's ``cost_scaling_factor``.)

    Parameters
    ----------
    pose_cost : float
        The cost at the robot, 1 … 254.
    factor : float
        1/m, > 0.
    inscribed_radius : float
        m.
    """
    return (factor * inscribed_radius - math.log(pose_cost) + math.log(253.0)) / factor


@dataclass(frozen=True)
class PurePursuit:
    """Regulated Pure Pursuit about a straight path (module docstring).

    Attributes
    ----------
    values : dict
        Its Nav2 parameters (`controllers.registry`, name → value).
    pose_cost : int
        The costmap's cost at the robot on the path (`corridor_pose_cost`; 0 in free space).
    inscribed_radius : float
        The costmap's inscribed radius, m.
    half_width : float or None
        The corridor's half-width L_c the cost is that of, m (None: free space).
    curvature : float
        The path's curvature the regulation reads, 1/m (0: a straight path). Along a bend of a map's route
        (`maps.deciding.tracking`) the curvature heuristic scales V by R/R_min where R = 1/|κ| < ``regulated_linear_scaling_min_radius``;
        the gains stay the straight path's (docs/path_tracking.md, "Regulated speed").
    """

    values: dict
    pose_cost: int = FREE
    inscribed_radius: float = 0.1
    half_width: float | None = None
    curvature: float = 0.0

    name = "rpp"
    shape = (1.0, 2.0)
    """(a, b): NV = a·ρ, k = b·ρ."""

    @property
    def steering(self) -> str:
        """Which lookahead steers: ``"curvature"`` (``use_fixed_curvature_lookahead``), ``"velocity-scaled"`` or ``"fixed"``."""
        v = self.values
        if v["use_fixed_curvature_lookahead"]:
            return "curvature"
        return "velocity-scaled" if v["use_velocity_scaled_lookahead_dist"] else "fixed"

    def cost_scale(self) -> float | None:
        """The cost heuristic's speed factor gain·d/cost_scaling_dist at the robot, or None when it is inactive."""
        v = self.values
        f = v["inflation_cost_scaling_factor"]
        if not v["use_cost_regulated_linear_velocity_scaling"] or f <= 0 or self.pose_cost in (FREE, 255):
            return None
        d = regulated_distance(self.pose_cost, f, self.inscribed_radius)
        return v["cost_scaling_gain"] * d / v["cost_scaling_dist"] if d < v["cost_scaling_dist"] else None

    def speed(self, V_set: float) -> float:
        """The regulated speed on the path, m/s (``applyConstraints`` with κ = 0, far from the goal).

        Parameters
        ----------
        V_set : float
            ``max_linear_vel``, m/s.
        """
        scale = self.cost_scale()
        cost_v = V_set if scale is None else V_set * scale
        v = self.values
        curvature_v = (curvature_constraint(V_set, self.curvature, v["regulated_linear_scaling_min_radius"])
                       if v["use_regulated_linear_velocity_scaling"] else V_set)
        speed = max(min(cost_v, curvature_v, V_set), v["regulated_linear_scaling_min_speed"])
        return min(abs(speed), V_set)

    def lookahead(self, V: float) -> float:
        """The lookahead that steers at the regulated (measured) speed V, m.

        Parameters
        ----------
        V : float
            m/s.
        """
        v = self.values
        if v["use_fixed_curvature_lookahead"]:
            return v["curvature_lookahead_dist"]
        if v["use_velocity_scaled_lookahead_dist"]:
            return min(max(abs(V) * v["lookahead_time"], v["min_lookahead_dist"]), v["max_lookahead_dist"])
        return v["lookahead_dist"]

    def point(self, V_set: float) -> TrackingPoint:
        """The law at cruising speed `V_set` (m/s): k_θ = 2V/L, k_y = 2V/L².

        Parameters
        ----------
        V_set : float
            m/s.
        """
        V = self.speed(V_set)
        L = self.lookahead(V)
        return TrackingPoint(V_set, V, L, 2.0 * V / L, 2.0 * V / (L * L))

    def with_lookahead(self, name: str, value: float) -> "PurePursuit":
        """The same controller with the lookahead parameter `name` set to `value` (m or s).

        Parameters
        ----------
        name : str
            ``lookahead_dist``, ``min_lookahead_dist``, ``max_lookahead_dist``, ``lookahead_time`` or
            ``curvature_lookahead_dist``.
        value : float
            Its value.
        """
        return PurePursuit({**self.values, name: value}, self.pose_cost, self.inscribed_radius, self.half_width, self.curvature)

    @property
    def lookahead_parameter(self) -> str:
        """The Nav2 parameter that sets the steering lookahead from below: ``lookahead_dist``, ``curvature_lookahead_dist``
        or, velocity-scaled, ``min_lookahead_dist`` (the clamp's lower end)."""
        return {"fixed": "lookahead_dist", "curvature": "curvature_lookahead_dist"}.get(self.steering, "min_lookahead_dist")


@dataclass(frozen=True)
class Graceful:
    """The Graceful controller about a straight path (module docstring).

    Attributes
    ----------
    values : dict
        Its Nav2 parameters (`controllers.registry`).
    """

    values: dict
    name = "graceful"

    def __post_init__(self):
        if self.values["v_angular_max"] <= 0:
            raise ValueError(f"v_angular_max must be > 0 for the Graceful controller to steer; got {self.values['v_angular_max']!r}")

    @property
    def shape(self) -> tuple:
        """(a, b): NV = a·ρ, k = b·ρ with b = 1 + k_φ + k_δ, a = (1 + k_φ)(1 + k_δ)/b."""
        kp, kd = self.values["k_phi"], self.values["k_delta"]
        b = 1.0 + kp + kd
        return (1.0 + kp) * (1.0 + kd) / b, b

    steering = "fixed"

    def speed(self, V_set: float, L: float | None = None) -> float:
        """The control law's forward speed on the path at the motion target's distance L (default ``max_lookahead``), m/s.

        Parameters
        ----------
        V_set : float
            ``v_linear_max``, m/s.
        L : float, optional
            m.
        """
        v = self.values
        L = v["max_lookahead"] if L is None else L
        speed = V_set / (1.0 + v["beta"]) if v["lambda"] == 0 else V_set  # |κ|^λ at κ = 0: 0, or C's pow(0, 0) = 1
        speed = min(V_set * (L / v["slowdown_radius"]), speed)
        speed = min(math.sqrt(2.0 * L * v["deceleration_max"]), speed)
        return min(max(speed, v["v_linear_min"]), V_set)

    def lookahead(self, V: float) -> float:
        """``max_lookahead``, m (the motion target's distance does not depend on the speed).

        Parameters
        ----------
        V : float
            m/s (unused).
        """
        return self.values["max_lookahead"]

    def point(self, V_set: float) -> TrackingPoint:
        """The law at cruising speed `V_set` (m/s).

        Parameters
        ----------
        V_set : float
            m/s.
        """
        L = self.values["max_lookahead"]
        V = self.speed(V_set, L)
        a, b = self.shape
        return TrackingPoint(V_set, V, L, b * V / L, a * b * V / (L * L))

    def with_lookahead(self, name: str, value: float) -> "Graceful":
        """The same controller with ``max_lookahead`` = `value`, m.

        Parameters
        ----------
        name : str
            ``max_lookahead``.
        value : float
            m.
        """
        return Graceful({**self.values, name: value})


MEMORY_CYCLES = 16
"""Cycles of a measured controller's response the prediction carries (`MeasuredGains.measure`): MPPI's answer to a
one-cycle pose error keeps moving its next commands through its warm-started sequence and Savitzky–Golay filter (taps
1.53, 0.84, 0.57, 0.19 … of the first, summing to 2.4 times it), and with its static one-step gains the predicted
largest dead time was twice the simulated one; over 16 cycles the taps have died out and the prediction is within the
simulation's spread (docs/controllers.md, experiments/nav2_controllers.py)."""


@dataclass(frozen=True)
class MeasuredGains:
    """A controller linearised numerically (MPPI, DWB): its gains at the speed they were measured, and its memory.

    Attributes
    ----------
    name : str
        ``mppi`` or ``dwb``.
    k_theta, k_y : float
        1/s and 1/(m·s), > 0.
    V : float
        The speed the robot drove when they were measured, m/s.
    k_theta_se, k_y_se : float
        Their standard errors over the draws (0: exact).
    memory : tuple or None
        The response over the following cycles to a one-cycle perturbation, ((θ_j 1/s), (y_j 1/(m·s)), (w_j)),
        j = 0 … J − 1 (`controllers.linearize.ImpulseResponse`; None: the one-step gains alone, e.g. typed).
    """

    name: str
    k_theta: float
    k_y: float
    V: float
    k_theta_se: float = 0.0
    k_y_se: float = 0.0
    memory: tuple | None = None

    shape = None
    steering = None

    def __post_init__(self):
        for name in ("k_theta", "k_y", "V", "k_theta_se", "k_y_se"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))

    @classmethod
    def from_linearisation(cls, gains) -> "MeasuredGains":
        """From a numeric linearisation of the algorithm (the ``LateralGains`` of ``controllers.linearize``: its
        ``controller``, ``V``, ``k_theta``, ``k_y``, their standard errors and ``memory``, read by name).

        Parameters
        ----------
        gains : object
            The linearisation's result.
        """
        memory = getattr(gains, "memory", None)
        taps = None if memory is None else (tuple(memory.theta), tuple(memory.y), tuple(memory.w))
        return cls(gains.controller, gains.k_theta, gains.k_y, gains.V, gains.k_theta_se, gains.k_y_se, taps)

    @classmethod
    def measure(cls, name: str, given: dict, costmap: dict, *, V: float, T: float, half_width: float | None = None,
                seed: int = 0, memory_cycles: int = MEMORY_CYCLES) -> "MeasuredGains":
        """The gains measured from the algorithm as Nav2 runs it (`controllers.linearize`: seeded draws, their standard
        errors and the response over `memory_cycles` cycles), about the centre line of the corridor (or a straight path).

        The parameters are the algorithm's defaults (Nav2's declarations; bringup's where the source declares none a
        controller can run with, `controllers.mppi.BRINGUP_DEFAULTS`) with the values a Nav2 file gave (`algorithm_params`).

        Parameters
        ----------
        name : str
            ``mppi`` or ``dwb``.
        given : dict
            The Nav2 parameters a file gave, registry name → value (assumed defaults left out).
        costmap : dict
            ``inflation_radius``, ``cost_scaling_factor``, ``inscribed_radius`` (m, 1/m, m) and ``resolution`` (m).
        V, T : float
            The cruising speed (m/s) and the controller's period (s).
        half_width : float, optional
            The corridor's half-width, m (None: free space).
        seed : int
            The first draw's seed.
        memory_cycles : int
            Cycles of the response measured.
        """
        from ..controllers.costmap import CorridorCostmap
        from ..controllers.linearize import configure, linearize

        params = configure(name, algorithm_params(name, given), V=V, T=T)
        grid = CorridorCostmap(half_width=half_width, resolution=costmap["resolution"],
                               inflation=Inflation(costmap["inflation_radius"], costmap["cost_scaling_factor"], costmap["inscribed_radius"]))
        return cls.from_linearisation(linearize(name, params, grid, T=T, seed=seed, memory_cycles=memory_cycles))

    def point(self, V_set: float | None = None) -> TrackingPoint:
        """The gains as measured (`V_set` ignored: the gains hold at the speed they were measured).

        Parameters
        ----------
        V_set : float, optional
            Unused.
        """
        return TrackingPoint(self.V, self.V, None, self.k_theta, self.k_y)

    def corners(self, spread: float) -> tuple:
        """The four (k_θ, k_y) at ±`spread` standard errors, each k_θ kept above 1e-9 of itself.

        Parameters
        ----------
        spread : float
            Standard errors.
        """
        out = []
        for dt in (-1.0, 1.0):
            for dy in (-1.0, 1.0):
                out.append((max(self.k_theta + dt * spread * self.k_theta_se, 1e-9 * self.k_theta), self.k_y + dy * spread * self.k_y_se))
        return tuple(out)


def algorithm_params(name: str, given: dict):
    """The algorithm's parameters (`controllers.<name>`) with the values a Nav2 file gave: a registry name is a field
    (``vx_max``) or a critic's (``CostCritic.cost_weight``: that critic's field); a list becomes a tuple; names the
    algorithm does not read are left out.

    Parameters
    ----------
    name : str
        ``rpp``, ``graceful``, ``mppi`` or ``dwb``.
    given : dict
        Registry name → value, as the file gave them.
    """
    from dataclasses import fields, replace

    from ..controllers.base import default_params

    params = default_params(name)
    own = {f.name for f in fields(params)}
    for key, value in given.items():
        value = tuple(value) if isinstance(value, list) else value
        head, _, tail = key.partition(".")
        if tail and head in own:
            part = getattr(params, head)
            if tail in {f.name for f in fields(part)}:
                params = replace(params, **{head: replace(part, **{tail: value})})
        elif not tail and key in own:
            params = replace(params, **{key: value})
    return params


def path_law(controller: str, values: dict, *, costmap: dict, half_width: float | None = None, gains=None):
    """The law of `controller` with Nav2 parameters `values`: `PurePursuit`, `Graceful` or `MeasuredGains`.

    Parameters
    ----------
    controller : str
        ``rpp``, ``graceful``, ``mppi`` or ``dwb``.
    values : dict
        Its Nav2 parameters (every one of the registry's, name → value).
    costmap : dict
        ``inflation_radius``, ``cost_scaling_factor``, ``inscribed_radius`` (m, 1/m, m).
    half_width : float, optional
        The corridor's half-width L_c, m (None: a straight path in free space).
    gains : MeasuredGains, optional
        MPPI's or DWB's measured gains (required for them).

    Raises
    ------
    ValueError
        A corridor the robot does not fit in (L_c <= the inscribed radius), or MPPI/DWB without gains.
    """
    if half_width is not None and half_width <= costmap["inscribed_radius"]:
        raise ValueError(f"L must exceed the robot's inscribed radius {costmap['inscribed_radius']:g} m for the robot to fit in the "
                         f"corridor; got {half_width:g} m")
    if controller == "rpp":
        return PurePursuit(dict(values), corridor_pose_cost(half_width, costmap), costmap["inscribed_radius"], half_width)
    if controller == "graceful":
        return Graceful(dict(values))
    if gains is None:
        raise ValueError(f"--controller {controller} has no closed-form linearisation: give its gains, --k-theta and --k-y "
                         "(measured from the algorithm about the corridor's centre line, docs/path_tracking.md)")
    return gains
