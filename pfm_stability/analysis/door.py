"""Passage between two closely spaced obstacles: does the robot get through a door? (KB 1991 §5.2, Fig 4)

Koren & Borenstein's problem 2, "no passage between closely spaced obstacles":
the repulsions of the two sides of an opening add up to a force that points
straight away from it, and if it beats the target-directed force the robot
stops in front of the opening, or turns away (KB Fig 4). docs/door.md derives
everything below.

The model. The robot approaches the gap along its axis, x = 0, from y < 0;
the gap plane is y = 0 and the target lies straight ahead through the gap, its
direction frozen (+y), its pull 1 (forces are in units of the attraction, as a
`ForceLaw` is). Two obstacles, each a point or a half-line thickened by
``post_radius`` (distances are measured to the surface):

* ``"posts"``: discs of radius r about (±w/2, 0);
* ``"wall-ends"``: the half-lines y = 0, |x| >= w/2 (thickened by r).

Each obstacle repels along the line from its nearest point with the law's
F_r(ρ) (``law.force``); a goal-directed part Q(ρ) (``law.goal_force``, Ge &
Cui's F_rep2; absent means 0) points at the target. For |x| < w/2 the nearest
point of a wall end is its end, so on and near the axis a wall end acts
exactly like a post at its end (the two kinds differ only beside the opening,
`door_field`). At a distance s = −y before the gap plane, with a = w/2,
c = √(a² + s²) and ρ = c − r:

    F_long(s) = 1 + 2Q(ρ) − 2F_r(ρ)·s/c      (the lateral parts cancel)

The robot passes iff F_long > 0 for every s > 0; the largest s with
F_long = 0 is where it stops (`door_passage`). The axis is an equilibrium
laterally; its stiffness there, −∂F_x/∂x = −2[F_r′(ρ)a²/c² + F_r(ρ)s²/c³],
says whether the robot at the stop is trapped (> 0) or slides sideways and
turns away (< 0). `smallest_passable_width` solves peak repulsion = 1 for w.

KB's power law f(W/d)ⁿ has a closed form: the peak of 2F_r·s/c lies where
n c³ − (n+1)a²c + a²r = 0 (for points, s = a/√n), and with points the
narrowest passable width is w* = 2W·[2f nⁿᐟ² /(n+1)^((n+1)/2)]^(1/n)
(`power_law_door_peak`, `power_law_door_width`).

Static only: the robot's dynamics are neglected, so a robot that the static
field stops may still pass by momentum (docs/door.md, "Limits").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_choice, check_number, check_type
from ..laws.force_law import ForceLaw
from ..io.serialize import json_number, json_ready, parse_json_number
from ..numerics.solve import bisect_root, expand_bracket

__all__ = [
    "OBSTACLES",
    "DoorGeometry",
    "DoorPassage",
    "approach_force",
    "door_field",
    "door_geometry",
    "door_passage",
    "power_law_door_peak",
    "power_law_door_width",
    "smallest_passable_width",
]

OBSTACLES = ("posts", "wall-ends")
"""Obstacle kinds on both sides of the opening: two posts, or the ends of two walls."""

_LAW_KINDS = "a ForceLaw (e.g. PowerLaw)"
_PER_DECADE = 200  # scan density of the approach (points per decade of s)
_GOAL_STEP = 1e-6  # relative step of the central difference of Q(ρ)


# ------------------------------------------------------------------ geometry
@dataclass(frozen=True)
class DoorGeometry:
    """The opening and the robot (build with `door_geometry`, which checks).

    Attributes
    ----------
    obstacle : {"posts", "wall-ends"}
    width : float
        w, m: the posts' centres (or the wall ends' axes) sit at x = ±w/2.
    post_radius : float
        r, m: radius of the posts, half-thickness of the walls (rounded ends).
    robot_width : float
        W, m: the robot's width (0: a point robot).
    """

    obstacle: str
    width: float
    post_radius: float
    robot_width: float

    @property
    def half_width(self) -> float:
        """a = w/2, m."""
        return self.width / 2.0

    @property
    def opening(self) -> float:
        """The clear opening w − 2r, m."""
        return self.width - 2.0 * self.post_radius

    @property
    def clearance(self) -> float:
        """Free space on each side of the robot in the gap plane, (w − 2r − W)/2, m."""
        return (self.opening - self.robot_width) / 2.0

    def to_dict(self) -> dict:
        """JSON-ready: the four attributes and the derived opening and clearance (m)."""
        return {
            "obstacle": self.obstacle,
            "width": json_number(self.width),
            "post_radius": json_number(self.post_radius),
            "robot_width": json_number(self.robot_width),
            "opening": json_number(self.opening),
            "clearance": json_number(self.clearance),
        }

    @classmethod
    def from_dict(cls, data: dict) -> DoorGeometry:
        """Inverse of `to_dict` (derived entries ignored).

        Parameters
        ----------
        data : dict
            The output of `to_dict`.
        """
        return cls(data["obstacle"], *(parse_json_number(data[k]) for k in ("width", "post_radius", "robot_width")))


def _check_shape(obstacle, post_radius, robot_width, law) -> tuple[str, float, float]:
    check_type("law", law, ForceLaw, _LAW_KINDS)
    check_choice("obstacle", obstacle, OBSTACLES)
    r = check_number("post_radius", post_radius, 0.0, math.inf, low_open=False, unit="m")
    if robot_width is None:
        robot_width = getattr(law, "W", 0.0)  # KB's power law carries the robot's width
    W = check_number("robot_width", robot_width, 0.0, math.inf, low_open=False, unit="m")
    return obstacle, r, W


def door_geometry(law: ForceLaw, width: float, *, obstacle: str = "posts", post_radius: float = 0.0, robot_width: float | None = None,
                  name: str = "width") -> DoorGeometry:
    """The checked geometry of a door.

    Parameters
    ----------
    law : ForceLaw
        Only read for the default robot width.
    width : float
        w, m, > W + 2r (the robot must fit through the opening).
    obstacle : {"posts", "wall-ends"}
    post_radius : float
        r >= 0, m.
    robot_width : float, optional
        W >= 0, m; default the law's ``W`` (KB's power law), else 0 (a point robot).
    name : str
        What the caller calls the width in its error messages (``"door"`` for ``report --door``).

    Raises
    ------
    ValueError
        Naming the argument: a law that is not a ForceLaw, an unknown obstacle,
        a negative or non-finite number, or a width the robot does not fit through.
    """
    obstacle, r, W = _check_shape(obstacle, post_radius, robot_width, law)
    w = check_number(name, width, 0.0, math.inf, unit="m")
    if not w > W + 2.0 * r:
        raise ValueError(
            f"{name} must be a finite number in (robot_width + 2*post_radius, inf) m = ({W + 2.0 * r:g}, inf) m "
            f"(the robot must fit through the opening); got {width!r}"
        )
    return DoorGeometry(obstacle, w, r, W)


# ------------------------------------------------------------------ forces
def _goal(law, rho):
    """Q(ρ), the law's goal-directed part (``goal_force``; 0 if the law has none), shaped like ρ."""
    goal = getattr(law, "goal_force", None)
    if not callable(goal):
        return np.zeros_like(rho)
    return np.broadcast_to(np.asarray(goal(rho), dtype=float), np.shape(rho)).astype(float)


def _goal_slope(law, rho):
    """dQ/dρ: the law's own ``goal_slope`` where its class defines one, else a central difference of Q."""
    if not callable(getattr(law, "goal_force", None)):
        return np.zeros_like(rho)
    own = getattr(type(law), "goal_slope", None)
    if own is not None and own is not getattr(ForceLaw, "goal_slope", None):
        return np.broadcast_to(np.asarray(law.goal_slope(rho), dtype=float), np.shape(rho)).astype(float)
    h = _GOAL_STEP * rho
    return (_goal(law, rho + h) - _goal(law, rho - h)) / (2.0 * h)


def door_field(law: ForceLaw, width: float, x, y, *, obstacle: str = "posts", post_radius: float = 0.0):
    """The planar force (F_x, F_y) on a robot at (x, y) in front of, in or behind the door.

    Attraction (0, 1) (target straight ahead, frozen), plus for each obstacle
    F_r(ρ) along the unit vector from its nearest point to the robot and Q(ρ)
    along +y. Nearest points: the post's centre (ρ = distance − r), or for
    the wall end at x >= w/2 the point (max(x, w/2), 0) (and its mirror).
    NaN where the robot's centre is inside an obstacle (ρ <= 0).

    Parameters
    ----------
    law : ForceLaw
    width : float
        w, m, > 2r (only the obstacles are checked here, not the robot's fit).
    x, y : float or array_like
        Robot position, m (broadcast); the gap plane is y = 0.
    obstacle, post_radius
        As in `door_geometry`.

    Returns
    -------
    (ndarray, ndarray)
        F_x and F_y in units of the attraction.
    """
    obstacle, r, _ = _check_shape(obstacle, post_radius, 0.0, law)
    w = check_number("width", width, 2.0 * r, math.inf, unit="m")
    a = w / 2.0
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    fx, fy = np.zeros(x.shape), np.ones(x.shape)
    for side in (1.0, -1.0):
        qx = side * a if obstacle == "posts" else side * np.maximum(side * x, a)
        dx, dy = x - qx, y
        dist = np.hypot(dx, dy)
        rho = dist - r
        inside = ~(rho > 0)
        p, q = np.full(x.shape, np.nan), np.full(x.shape, np.nan)
        p[~inside] = law.force(rho[~inside])
        q[~inside] = _goal(law, rho[~inside])
        with np.errstate(divide="ignore", invalid="ignore"):
            fx = fx + p * dx / dist
            fy = fy + p * dy / dist + q
    return fx, fy


def _axis(law, a, r, s):
    """2F_r(ρ)s/c − 2Q(ρ): the net push back from the gap at distances s before it."""
    c = np.hypot(a, s)
    rho = c - r
    return 2.0 * np.asarray(law.force(rho), dtype=float) * s / c - 2.0 * _goal(law, rho)


def _axis_slope(law, a, r, s):
    """d/ds of `_axis`: 2[F_r′ s²/c² + F_r a²/c³] − 2Q′ s/c."""
    c = np.hypot(a, s)
    rho = c - r
    p = np.asarray(law.force(rho), dtype=float)
    dp = np.asarray(law.slope(rho), dtype=float)
    return 2.0 * (dp * s * s / (c * c) + p * a * a / c**3) - 2.0 * _goal_slope(law, rho) * s / c


def _lateral_stiffness(law, a, r, s) -> float:
    """−∂F_x/∂x on the axis at distance s: −2[F_r′(ρ)a²/c² + F_r(ρ)s²/c³] (1/m)."""
    c = math.hypot(a, s)
    rho = c - r
    return float(-2.0 * (law.slope(rho) * a * a / (c * c) + law.force(rho) * s * s / c**3))


def approach_force(law: ForceLaw, width: float, distance, *, obstacle: str = "posts", post_radius: float = 0.0):
    """F_long(s) = 1 + 2Q(ρ) − 2F_r(ρ)s/c on the axis at distances s before the gap plane.

    The same for both obstacle kinds (the nearest point of a wall end, seen
    from the axis, is its end).

    Parameters
    ----------
    law : ForceLaw
    width : float
        w, m, > 2r.
    distance : float or array_like
        s >= 0, m (the robot at (0, −s)).
    obstacle, post_radius
        As in `door_geometry`.

    Returns
    -------
    ndarray
        The longitudinal force in units of the attraction (> 0: forward).
    """
    _, r, _ = _check_shape(obstacle, post_radius, 0.0, law)
    w = check_number("width", width, 2.0 * r, math.inf, unit="m")
    s = np.asarray(distance, dtype=float)
    if not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ValueError(f"distance must be finite distances in [0, inf) m (number or array); got {distance!r}")
    return 1.0 - _axis(law, w / 2.0, r, s)


# ------------------------------------------------------------------ the approach
@dataclass(frozen=True)
class _Approach:
    peak: float  # max over s > 0 of 2F_r s/c − 2Q (0 if negative: its sup is the limit at s → inf)
    peak_distance: float
    stop: float | None
    goal_force: bool


def _scan(law, a, r) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The approach on a geometric grid of s from 1e-6·(a − r) to 1e6·a: s, push back, its slope."""
    lo, hi = 1e-6 * (a - r), 1e6 * a
    s = np.geomspace(lo, hi, int(_PER_DECADE * math.log10(hi / lo)) + 1)
    with np.errstate(over="ignore", under="ignore"):
        c = np.hypot(a, s)
        has_goal = bool(np.any(_goal(law, c - r) != 0))
        return s, _axis(law, a, r, s), _axis_slope(law, a, r, s), has_goal


def _approach(law, a, r, with_stop: bool = True) -> _Approach:
    """Peak push back (every local maximum of the scan refined on the slope's root) and, if asked, the stop."""
    s, g, d, has_goal = _scan(law, a, r)
    slope = lambda x: float(_axis_slope(law, a, r, x))
    push = lambda x: float(_axis(law, a, r, x))
    points = [float(s[int(np.argmax(g))])]
    for i in np.flatnonzero((d[:-1] > 0) & (d[1:] <= 0)):
        points.append(bisect_root(slope, float(s[i]), float(s[i + 1]), rtol=1e-11))  # the peak's value: ~1e-22
    beyond = math.inf
    if d[-1] > 0:  # still rising at the scan's end: follow the slope outwards
        bracket = expand_bracket(slope, float(s[-1]), factor=10.0, steps=40)
        if bracket is not None:
            points.append(bisect_root(slope, *bracket, rtol=1e-11))
        else:
            beyond = float(g[-1])  # never turns: the sup is approached at s → inf
    values = [push(p) for p in points]
    k = int(np.argmax(values))
    peak, where = values[k], points[k]
    if beyond != math.inf and beyond >= peak:
        peak, where = beyond, math.inf
    if peak <= 0.0:  # no push back anywhere (or the goal part wins): its sup is the limit 0 far away
        peak, where = 0.0, math.inf
    stop = None
    if peak >= 1.0 and with_stop:
        xs = np.concatenate([s, np.asarray(points)])
        order = np.argsort(xs)
        xs, gs = xs[order], np.concatenate([g, np.asarray(values)])[order]
        j = int(np.flatnonzero(gs >= 1.0)[-1])
        stop = float(xs[j]) if j == xs.size - 1 else bisect_root(lambda x: push(x) - 1.0, float(xs[j]), float(xs[j + 1]), rtol=1e-14)
    return _Approach(peak, where, stop, has_goal)


@dataclass(frozen=True)
class DoorPassage:
    """Whether the robot passes the door, and if not, where it stops (`door_passage`).

    Attributes
    ----------
    geometry : DoorGeometry
    law : str
        The law's name.
    passes : bool
        F_long > 0 on the whole approach.
    stop_distance : float or None
        s at the first zero of F_long on the approach, m before the gap plane; None if it passes.
    peak_repulsion : float
        Largest net push back from the gap, max over s of 2F_r(ρ)s/c − 2Q(ρ)
        (units of the attraction; it passes iff this is < 1).
    peak_distance : float
        Where it peaks, m before the gap plane (inf: the sup is the limit far away).
    margin : float
        min over the approach of F_long = 1 − peak_repulsion (> 0: passes).
    lateral_stiffness : float or None
        −∂F_x/∂x at the stop, 1/m (units of the attraction per m): > 0 the
        axis pulls the robot back (it is trapped there), < 0 it slides off
        sideways (KB Fig 4: it turns away). None if it passes.
    goal_force : bool
        Whether the law had a non-zero goal-directed part.
    law_parameters : dict
        The law's ``parameters()`` by name, SI units ({} if it has none).
    smallest_passable_width : float or None
        `smallest_passable_width` for the same law and obstacles, m, when asked for.
    """

    geometry: DoorGeometry
    law: str
    passes: bool
    stop_distance: float | None
    peak_repulsion: float
    peak_distance: float
    margin: float
    lateral_stiffness: float | None
    goal_force: bool
    law_parameters: dict = field(default_factory=dict)
    smallest_passable_width: float | None = None

    @property
    def at_stop(self) -> str | None:
        """What the stop is: ``"trapped"`` (stable laterally), ``"turns away"`` (unstable), ``"neutral"``; None if it passes."""
        if self.lateral_stiffness is None:
            return None
        if self.lateral_stiffness > 0:
            return "trapped"
        return "turns away" if self.lateral_stiffness < 0 else "neutral"

    def to_dict(self) -> dict:
        """JSON-ready (`serialize.json_number`; inf as ``"inf"``, None as null)."""
        return {
            "geometry": self.geometry.to_dict(),
            "law": self.law,
            "passes": self.passes,
            "stop_distance": json_number(self.stop_distance),
            "peak_repulsion": json_number(self.peak_repulsion),
            "peak_distance": json_number(self.peak_distance),
            "margin": json_number(self.margin),
            "lateral_stiffness": json_number(self.lateral_stiffness),
            "at_stop": self.at_stop,
            "goal_force": self.goal_force,
            "law_parameters": json_ready(self.law_parameters),
            "smallest_passable_width": json_number(self.smallest_passable_width),
        }

    @classmethod
    def from_dict(cls, data: dict) -> DoorPassage:
        """Inverse of `to_dict` (``at_stop`` is derived).

        Parameters
        ----------
        data : dict
            The output of `to_dict`.
        """

        def optional(key):
            return None if data[key] is None else parse_json_number(data[key])

        return cls(
            DoorGeometry.from_dict(data["geometry"]), data["law"], bool(data["passes"]), optional("stop_distance"),
            parse_json_number(data["peak_repulsion"]), parse_json_number(data["peak_distance"]), parse_json_number(data["margin"]),
            optional("lateral_stiffness"), bool(data["goal_force"]),
            {k: parse_json_number(v) for k, v in data.get("law_parameters", {}).items()}, optional("smallest_passable_width"),
        )


def _parameters(law) -> dict:
    """The law's ``parameters()`` if it has them (numbers only), else {}."""
    get = getattr(law, "parameters", None)
    values = get() if callable(get) else {}
    return {str(k): float(v) for k, v in values.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}


def door_passage(
    law: ForceLaw,
    width: float,
    *,
    obstacle: str = "posts",
    post_radius: float = 0.0,
    robot_width: float | None = None,
    find_smallest: bool = False,
    name: str = "width",
) -> DoorPassage:
    """Does a robot heading straight through a door pass it, and if not, where does it stop? (KB Fig 4)

    The push back 2F_r(ρ)s/c − 2Q(ρ) is scanned over s (geometric grid, 200
    points per decade from 10⁻⁶(a − r) to 10⁶a), every local maximum refined
    on the root of its analytic slope (`solve.bisect_root`; the slope of Q by
    a central difference), and the stop, the largest s where it reaches 1,
    refined likewise.

    Parameters
    ----------
    law : ForceLaw
        F_r(d)/F_a (``force``, ``slope``) and, if it has one, the goal-directed
        part Q(d)/F_a (``goal_force``).
    width, obstacle, post_radius, robot_width
        As in `door_geometry`.
    find_smallest : bool
        Also solve for `smallest_passable_width` (about 50 more scans).
    name : str
        As in `door_geometry`: the name error messages give `width`.

    Returns
    -------
    DoorPassage

    Raises
    ------
    ValueError
        Naming the argument, for bad input (`door_geometry`).
    """
    geometry = door_geometry(law, width, obstacle=obstacle, post_radius=post_radius, robot_width=robot_width, name=name)
    a, r = geometry.half_width, geometry.post_radius
    ap = _approach(law, a, r)
    stiffness = None if ap.stop is None else _lateral_stiffness(law, a, r, ap.stop)
    smallest = smallest_passable_width(law, obstacle=obstacle, post_radius=r, robot_width=geometry.robot_width) if find_smallest else None
    return DoorPassage(
        geometry, getattr(law, "name", type(law).__name__), ap.stop is None, ap.stop, ap.peak, ap.peak_distance,
        1.0 - ap.peak, stiffness, ap.goal_force, _parameters(law), smallest,
    )


def smallest_passable_width(
    law: ForceLaw,
    *,
    obstacle: str = "posts",
    post_radius: float = 0.0,
    robot_width: float | None = None,
    rtol: float = 1e-12,
) -> float:
    """The narrowest width w (m) the robot passes: peak repulsion(w) = 1.

    A width the robot does not fit through (w <= W + 2r) counts as blocked;
    from w = 2(W + 2r) (1 m for a point robot between points) the width is
    doubled or halved until the verdict changes (`solve.expand_bracket`),
    then the boundary is bisected (`solve.bisect_root`). If every width the
    robot fits through passes, the answer is the fit limit W + 2r itself
    (any larger width passes). For a law with a goal-directed part the peak
    need not fall monotonically with w; the boundary found is then the one
    next to the first bracket.

    Parameters
    ----------
    law, obstacle, post_radius, robot_width
        As in `door_passage`.
    rtol : float
        Relative width of the final bracket, in (0, 0.5).

    Returns
    -------
    float
        w*, m; ``inf`` if no width up to 2²⁰⁰ times the start passes.

    Raises
    ------
    ValueError
        Naming the argument, for bad input.
    """
    _, r, W = _check_shape(obstacle, post_radius, robot_width, law)
    rtol = check_number("rtol", rtol, 0.0, 0.5)
    fit = W + 2.0 * r

    def excess(w: float) -> float:  # > 0: blocked
        return 1.0 if w <= fit else _approach(law, w / 2.0, r, with_stop=False).peak - 1.0

    start = 2.0 * fit if fit > 0 else 1.0
    blocked = excess(start) > 0
    bracket = expand_bracket(excess, start, upward=blocked)
    if bracket is None:
        return math.inf if blocked else fit
    w = bisect_root(excess, *bracket, rtol=rtol)
    return fit if w <= fit * (1.0 + 2.0 * rtol) else w  # converged onto the fit limit: every width that fits passes


# ------------------------------------------------------------------ KB's power law in closed form
def power_law_door_peak(f: float, n: float, W: float, width: float, post_radius: float = 0.0) -> tuple[float, float]:
    """(peak, s*) of KB's power law between two posts, in closed form.

    The push back 2f(W/ρ)ⁿ s/c (ρ = c − r, c² = a² + s², a = w/2) peaks where
    d/dc log[√(c² − a²)/(c(c − r)ⁿ)] = 0, i.e. at the root c* > a of the cubic
    n c³ − (n + 1)a²c + a²r = 0 (three real roots; the largest, by the
    trigonometric formula). For points (r = 0): s* = a/√n and
    peak = 2f(W/a)ⁿ nⁿᐟ²/(n + 1)^((n+1)/2).

    Parameters
    ----------
    f, n, W : float
        KB's law (KB eq 8, 13): f > 0, n > 0, W > 0 m.
    width : float
        w > 2r, m.
    post_radius : float
        r >= 0, m.

    Returns
    -------
    (float, float)
        The peak push back (units of the attraction) and where, m before the gap plane.
    """
    f = check_number("f", f, 0.0)
    n = check_number("n", n, 0.0)
    W = check_number("W", W, 0.0, unit="m")
    r = check_number("post_radius", post_radius, 0.0, math.inf, low_open=False, unit="m")
    a = check_number("width", width, 2.0 * r, math.inf, unit="m") / 2.0
    if r == 0.0:
        c = a * math.sqrt((n + 1.0) / n)
    else:  # c³ + pc + q = 0, p = −(n+1)a²/n, q = a²r/n: largest of three real roots
        p, q = -(n + 1.0) * a * a / n, a * a * r / n
        m = 2.0 * math.sqrt(-p / 3.0)
        c = m * math.cos(math.acos(max(-1.0, min(1.0, 3.0 * q / (p * m)))) / 3.0)
    s = math.sqrt(c * c - a * a)
    return 2.0 * f * (W / (c - r)) ** n * s / c, s


def power_law_door_width(f: float, n: float, W: float) -> float:
    """The narrowest passable width between two point posts for KB's power law, m, in closed form.

    Setting the peak of `power_law_door_peak` to 1:
    w* = 2W·[2f nⁿᐟ²/(n + 1)^((n+1)/2)]^(1/n); for n = 2, w* = 2W√(4f/(3√3)).
    A robot of width W needs w > W as well: the narrowest it passes is max(w*, W) (W itself excluded).

    Parameters
    ----------
    f : float
        Force-law strength (dimensionless).
    n : float
        Force-law exponent (dimensionless).
    W : float
        Robot width, m.
    """
    f = check_number("f", f, 0.0)
    n = check_number("n", n, 0.0)
    W = check_number("W", W, 0.0, unit="m")
    return 2.0 * W * (2.0 * f * n ** (n / 2.0) / (n + 1.0) ** ((n + 1.0) / 2.0)) ** (1.0 / n)
