"""A 2-D potential-field scene: goal, obstacles, law, search region, and its exact field.

A `Scene` holds a goal, obstacles (`Circle`, `Segment`, closed `Polygon`), a
`FieldLaw` (Khatib's repulsion, Ge & Cui 2000 eq 3, or the goal-aware one, eq 8,
with the attraction ½ξρ_gᵐ) and a search region, read from YAML
(`Scene.load`; docs/traps.md, "Scene files") with every field checked (the file by the package's one YAML reader, `pfm_stability.io.yaml_files`:
errors name the file, the line and the field).
`field` gives U = ½ξρ_gᵐ + Σ_i U_rep(ρ_i, ρ_g), ρ_i the minimal distance to
obstacle i (`pfm_stability.laws.potentials`), with the exact gradient and Hessian
(∇ρ the unit vector from the nearest point, ∇²ρ = κ(I − ∇ρ∇ρᵀ), κ =
1/distance to a nearest vertex or circle centre, 0 on an edge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_number
from .potentials import attraction_derivatives, repulsion_derivatives

__all__ = ["LAW_NAMES", "FieldLaw", "Circle", "Segment", "Polygon", "Scene", "field"]

LAW_NAMES = ("khatib", "gnron")
"""Repulsion laws: Khatib's (GC2000 eq 3) and the goal-aware one (eq 8)."""
LENGTH, SCALE = 1e6, 1e12
"""Caps that keep every computation inside floating point: coordinates, radii, ρ0, δ within ±1e6 m (ρ0 >= 1e-6 m,
region sides >= 1e-3 m); ξ, η <= 1e12."""
LAW_KEYS = ("name", "xi", "eta", "rho0", "attraction_exponent", "goal_exponent", "delta")
SCENE_KEYS = ("law", "goal", "obstacles", "region")


def _mapping(name, value, keys, required):
    if not isinstance(value, dict):
        raise ValueError(f"{name} must be a mapping with keys {', '.join(keys)}; got {value!r}")
    for key in (k for k in value if k not in keys):
        raise ValueError(f"{name}.{key} is not an option; {name} takes {', '.join(keys)}")
    for key in (k for k in required if k not in value):
        raise ValueError(f"{name}.{key} is missing ({name} needs {', '.join(required)})")
    return value


def _point(name, value):
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise ValueError(f"{name} must be a point [x, y] of two finite numbers (m); got {value!r}")
    return tuple(check_number(f"{name}[{i}]", value[i], -LENGTH, LENGTH, low_open=False, high_open=False, unit="m") for i in (0, 1))


# ------------------------------------------------------------------ the law and the obstacles
@dataclass(frozen=True)
class FieldLaw:
    """Attraction ½ξρ_gᵐ plus, per obstacle, ½η(1/(ρ+δ) − 1/(ρ0+δ))²ρ_gⁿ within ρ0 (GC2000 eq 1, 3, 8, 40).

    Attributes: `name` "khatib" (n = 0) or "gnron" (n in (0, 10]); `xi`, `eta`
    (ξ, η > 0); `rho0` (ρ0 > 0, m); `m` (attraction exponent, 1: constant pull
    ξ/2, 2: spring); `n` (goal exponent); `delta` (δ >= 0 of eq 40, m).

    Attributes
    ----------
    name : str
        ``"khatib"`` or ``"gnron"``.
    xi : float
        Attractive scaling factor ξ.
    eta : float
        Repulsive scaling factor η.
    rho0 : float
        Influence distance ρ0, m.
    m : float
        Attraction exponent.
    n : float
        Goal exponent (0 for khatib).
    delta : float
        Surface offset δ, m (eq 40).
    """

    name: str
    xi: float
    eta: float
    rho0: float
    m: float = 2.0
    n: float = 0.0
    delta: float = 0.0

    def __post_init__(self):
        check_choice("law.name", self.name, LAW_NAMES)
        for key, low, high, unit in (("xi", 0.0, SCALE, ""), ("eta", 0.0, SCALE, ""), ("rho0", 1e-6, LENGTH, "m"), ("delta", 0.0, LENGTH, "m")):
            check_number(f"law.{key}", getattr(self, key), low, high, low_open=key in ("xi", "eta"), high_open=False, unit=unit)
        if isinstance(self.m, bool) or self.m not in (1, 2):
            raise ValueError(f"law.attraction_exponent must be 1 or 2; got {self.m!r}")
        if self.name == "khatib" and (isinstance(self.n, bool) or self.n != 0):
            raise ValueError(f"law.goal_exponent must be 0 (or left out) for khatib; got {self.n!r}")
        check_number("law.goal_exponent", self.n, 0.0, 10.0, low_open=self.name == "gnron", high_open=False)
        for key in ("xi", "eta", "rho0", "m", "n", "delta"):
            object.__setattr__(self, key, float(getattr(self, key)))

    @classmethod
    def from_dict(cls, data) -> FieldLaw:
        """The law from a scene's ``law:`` mapping (keys `LAW_KEYS`; goal_exponent only for gnron).

        Parameters
        ----------
        data : dict
            A scene's ``law:`` mapping.
        """
        required = ("name", "xi", "eta", "rho0", "attraction_exponent") + (("goal_exponent",) if isinstance(data, dict) and data.get("name") == "gnron" else ())
        d = _mapping("law", data, LAW_KEYS, required)
        return cls(d["name"], d["xi"], d["eta"], d["rho0"], d["attraction_exponent"], d.get("goal_exponent", 0.0), d.get("delta", 0.0))

    def to_dict(self) -> dict:
        """The law as in a scene file."""
        return {"name": self.name, "xi": self.xi, "eta": self.eta, "rho0": self.rho0, "attraction_exponent": self.m,
                "goal_exponent": self.n, "delta": self.delta}

    def describe(self) -> str:
        """One line, e.g. ``gnron: xi = 1, eta = 25, rho0 = 2 m, m = 2, n = 2``."""
        text = f"{self.name}: xi = {self.xi:g}, eta = {self.eta:g}, rho0 = {self.rho0:g} m, m = {self.m:g}"
        text += f", n = {self.n:g}" if self.name == "gnron" else ""
        return text + (f", delta = {self.delta:g} m" if self.delta else "")


def _edge_geometry(q, a, b, inside):
    """(ρ, ∇ρ, κ) at points q (N, 2) from the nearest of the edges a→b (K, 2); ρ = 0 where `inside`."""
    d = b - a
    t = np.clip(np.einsum("nkj,kj->nk", q[:, None, :] - a[None], d) / np.einsum("kj,kj->k", d, d), 0.0, 1.0)
    p = a[None] + t[..., None] * d[None]
    dist = np.linalg.norm(q[:, None, :] - p, axis=2)
    j = np.argmin(dist, axis=1)
    rows = np.arange(q.shape[0])
    rho, near, tj = np.where(inside, 0.0, dist[rows, j]), p[rows, j], t[rows, j]
    safe = np.where(rho > 0, rho, 1.0)
    return rho, (q - near) / safe[:, None], np.where((tj > 0) & (tj < 1), 0.0, 1.0 / safe)  # κ: an edge is flat, a vertex curves


@dataclass(frozen=True)
class Circle:
    """A disc of `radius` (m) about `center` (m); ρ = |q − c| − R, 0 inside.

    Attributes
    ----------
    center : tuple of float
        Centre (x, y), m.
    radius : float
        Radius, m.
    """

    center: tuple
    radius: float
    kind = "circle"

    def geometry(self, q):
        """(ρ, ∇ρ, κ) at points q (N, 2): distance, unit normal from the surface, curvature factor of ∇²ρ.

        Parameters
        ----------
        q : ndarray, shape (N, 2)
            Points, m.
        """
        v = q - np.asarray(self.center)
        dc = np.linalg.norm(v, axis=1)
        return np.maximum(dc - self.radius, 0.0), v / np.where(dc > 0, dc, 1.0)[:, None], 1.0 / np.where(dc > 0, dc, 1.0)

    def to_dict(self) -> dict:
        """``{"circle": {"center": [x, y], "radius": R}}``."""
        return {"circle": {"center": list(self.center), "radius": self.radius}}


@dataclass(frozen=True)
class Segment:
    """A straight wall from `start` to `end` (m), no thickness.

    Attributes
    ----------
    start, end : tuple of float
        The wall's ends (x, y), m.
    """

    start: tuple
    end: tuple
    kind = "segment"

    def geometry(self, q):
        """(ρ, ∇ρ, κ) at points q (N, 2), as `Circle.geometry`.

        Parameters
        ----------
        q : ndarray, shape (N, 2)
            Points, m.
        """
        return _edge_geometry(q, np.asarray([self.start]), np.asarray([self.end]), np.zeros(q.shape[0], dtype=bool))

    def to_dict(self) -> dict:
        """``{"segment": {"from": [x, y], "to": [x, y]}}``."""
        return {"segment": {"from": list(self.start), "to": list(self.end)}}


@dataclass(frozen=True)
class Polygon:
    """A closed polygon (the last vertex joins the first), m; ρ = 0 inside (even–odd rule).

    Attributes
    ----------
    vertices : tuple of (float, float)
        The corners, m, in order.
    """

    vertices: tuple
    kind = "polygon"

    def contains(self, q):
        """True where points q (N, 2) lie inside the polygon (even–odd rule).

        Parameters
        ----------
        q : ndarray, shape (N, 2)
            Points, m.
        """
        a, x, y = np.asarray(self.vertices), q[:, :1], q[:, 1:]
        b = np.roll(a, -1, axis=0)
        straddle = (a[None, :, 1] > y) != (b[None, :, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            cross = a[None, :, 0] + (y - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (b[None, :, 1] - a[None, :, 1])
        return np.count_nonzero(straddle & (x < cross), axis=1) % 2 == 1

    def geometry(self, q):
        """(ρ, ∇ρ, κ) at points q (N, 2), as `Circle.geometry`.

        Parameters
        ----------
        q : ndarray, shape (N, 2)
            Points, m.
        """
        return _edge_geometry(q, np.asarray(self.vertices), np.roll(self.vertices, -1, axis=0), self.contains(q))

    def to_dict(self) -> dict:
        """``{"polygon": [[x, y], ...]}``."""
        return {"polygon": [list(v) for v in self.vertices]}


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _obstacle(i, data):
    name = f"obstacles[{i}]"
    if not isinstance(data, dict) or len(data) != 1 or next(iter(data)) not in ("circle", "segment", "polygon"):
        raise ValueError(f"{name} must be one of {{circle: {{center, radius}}}}, {{segment: {{from, to}}}}, {{polygon: [[x, y], ...]}}; got {data!r}")
    (kind, body), name = next(iter(data.items())), f"{name}.{next(iter(data))}"
    if kind == "circle":
        d = _mapping(name, body, ("center", "radius"), ("center", "radius"))
        return Circle(_point(name + ".center", d["center"]), check_number(name + ".radius", d["radius"], 0.0, LENGTH, high_open=False, unit="m"))
    if kind == "segment":
        d = _mapping(name, body, ("from", "to"), ("from", "to"))
        a, b = _point(name + ".from", d["from"]), _point(name + ".to", d["to"])
        if a == b:
            raise ValueError(f"{name} is degenerate: from and to are the same point {list(a)}")
        return Segment(a, b)
    if not isinstance(body, (list, tuple)) or len(body) < 3:
        raise ValueError(f"{name} must be a list of at least 3 vertices [[x, y], ...]; got {body!r}")
    v, k = tuple(_point(f"{name}[{j}]", p) for j, p in enumerate(body)), len(body)
    for j in range(k):
        if v[j] == v[(j + 1) % k]:
            raise ValueError(f"{name} is degenerate: vertices {j} and {(j + 1) % k} coincide at {list(v[j])}")
    for j, i in ((j, i) for j in range(k) for i in range(j + 2, k) if not (j == 0 and i == k - 1)):  # non-adjacent edges
        p1, p2, p3, p4 = v[j], v[(j + 1) % k], v[i], v[(i + 1) % k]
        if _cross(p1, p2, p3) * _cross(p1, p2, p4) < 0 and _cross(p3, p4, p1) * _cross(p3, p4, p2) < 0:
            raise ValueError(f"{name} intersects itself (edges {j} and {i} cross)")
    if abs(sum(_cross((0.0, 0.0), v[j], v[(j + 1) % k]) for j in range(k))) == 0:
        raise ValueError(f"{name} is degenerate: zero area")
    return Polygon(v)


@dataclass(frozen=True)
class Scene:
    """A 2-D scene: goal, obstacles, law and the search region [[xmin, ymin], [xmax, ymax]] (m).

    Build it with `Scene.from_dict` (a scene file's content) or `Scene.load`
    (a YAML file); both check everything and raise one-line ValueErrors that
    name the field (docs/traps.md, "Scene files").

    Attributes
    ----------
    goal : tuple of float
        The goal (x, y), m.
    obstacles : tuple
        The `Circle`, `Segment` and `Polygon` obstacles.
    law : FieldLaw
        The potential field.
    region : tuple
        The search region [[xmin, ymin], [xmax, ymax]], m.
    """

    goal: tuple
    obstacles: tuple
    law: FieldLaw
    region: tuple

    @classmethod
    def from_dict(cls, data) -> Scene:
        """The scene from a mapping with keys law, goal, obstacles, region.

        Parameters
        ----------
        data : dict
            The scene's mapping (keys law, goal, obstacles, region).
        """
        d = _mapping("scene", data, SCENE_KEYS, SCENE_KEYS)
        law = FieldLaw.from_dict(d["law"])
        goal = _point("goal", d["goal"])
        if not isinstance(d["region"], (list, tuple)) or len(d["region"]) != 2:
            raise ValueError(f"region must be [[xmin, ymin], [xmax, ymax]] (m); got {d['region']!r}")
        lo, hi = _point("region[0]", d["region"][0]), _point("region[1]", d["region"][1])
        if not (hi[0] - lo[0] >= 1e-3 and hi[1] - lo[1] >= 1e-3):
            raise ValueError(f"region must have xmin < xmax and ymin < ymax, sides of at least 1e-3 m; got {d['region']!r}")
        if not (lo[0] < goal[0] < hi[0] and lo[1] < goal[1] < hi[1]):
            raise ValueError(f"goal must lie inside region {d['region']!r}; got {list(goal)}")
        if not isinstance(d["obstacles"], (list, tuple)):
            raise ValueError(f"obstacles must be a list (possibly empty); got {d['obstacles']!r}")
        obstacles = tuple(_obstacle(i, o) for i, o in enumerate(d["obstacles"]))
        for i, o in enumerate(obstacles):  # an obstacle touching the goal makes U(goal) infinite
            if o.geometry(np.array([goal]))[0][0] <= 1e-9 * math.hypot(hi[0] - lo[0], hi[1] - lo[1]):
                raise ValueError(f"obstacles[{i}].{o.kind} covers the goal {list(goal)} (or lies within 1e-9 of the region's diagonal of it)")
        return cls(goal, obstacles, law, (lo, hi))

    @classmethod
    def load(cls, path) -> Scene:
        """The scene in the YAML file `path`, read by the package's one YAML reader (`pfm_stability.io.yaml_files`).

        Parameters
        ----------
        path : str or path-like
            The scene's YAML file.

        Raises
        ------
        ValueError
            `from_dict`'s message prefixed by the file and the line of the field it names
            (``scene hall.yaml, line 4: law.rho0 must be …``), or the file unreadable or not YAML.
        """
        from ..io.yaml_files import read_yaml

        document = read_yaml(path, "scene")
        try:
            return cls.from_dict(document.data)
        except ValueError as exc:
            raise document.refuse(exc) from None

    def to_dict(self) -> dict:
        """The scene as in a scene file."""
        return {"law": self.law.to_dict(), "goal": list(self.goal), "obstacles": [o.to_dict() for o in self.obstacles],
                "region": [list(self.region[0]), list(self.region[1])]}

    def grid(self, points: int):
        """(xs, ys, h): a grid over the region with `points` nodes along its longer side, and that side's spacing h, m.

        Parameters
        ----------
        points : int
            Nodes along the region's longer side.
        """
        (x0, y0), (x1, y1) = self.region
        h = max(x1 - x0, y1 - y0) / (points - 1)
        return np.linspace(x0, x1, max(2, round((x1 - x0) / h) + 1)), np.linspace(y0, y1, max(2, round((y1 - y0) / h) + 1)), h

    @property
    def diagonal(self) -> float:
        """Length of the region's diagonal, m: the length scale of the search's tolerances."""
        return math.hypot(*(high - low for low, high in zip(*self.region)))


# ------------------------------------------------------------------ the field
def field(scene: Scene, q, hessian: bool = True):
    """(U, ∇U, ∇²U or None, scale, free) at points q (N, 2): the total potential, its exact gradient and Hessian.

    `scale` sums the magnitudes of the cancelling forces (|∇U| is measured
    against it); `free` is False inside an obstacle (values there are
    meaningless) and at the goal itself (ρ_g = 0, handled by `_goal_point`).

    Parameters
    ----------
    scene : Scene
        The scene.
    q : ndarray, shape (N, 2)
        Points, m.
    hessian : bool, optional
        Whether to compute ∇²U (False: None).
    """
    q, law, eye = np.atleast_2d(np.asarray(q, dtype=float)), scene.law, np.eye(2)
    dg = q - np.asarray(scene.goal)
    rg = np.linalg.norm(dg, axis=1)
    free = rg > 0
    rg_safe = np.where(free, rg, 1.0)
    ug = dg / rg_safe[:, None]
    u, ug_sum, ugg_sum = (np.where(free, v, 0.0) if k else v for k, v in enumerate(attraction_derivatives(rg, law.xi, law.m)))
    scale, grad, hess = np.abs(ug_sum), np.zeros_like(q), np.zeros((q.shape[0], 2, 2)) if hessian else None
    for obstacle in scene.obstacles:
        rho, un, kappa = obstacle.geometry(q)
        ok = rho > 0
        free &= ok
        d = repulsion_derivatives(np.where(ok, rho, 1.0), rg, law.eta, law.rho0, law.n, law.delta)
        r0, r_r, r_g, r_rr, r_rg, r_gg = (np.where(ok & np.isfinite(x), x, 0.0) for x in d)
        u, ug_sum, ugg_sum, scale = u + r0, ug_sum + r_g, ugg_sum + r_gg, scale + np.abs(r_r) + np.abs(r_g)
        grad += r_r[:, None] * un
        if hessian:
            nn = un[:, :, None] * un[:, None, :]
            cross = un[:, :, None] * ug[:, None, :]
            hess += r_rr[:, None, None] * nn + (r_r * kappa)[:, None, None] * (eye - nn) + r_rg[:, None, None] * (cross + cross.transpose(0, 2, 1))
    grad += ug_sum[:, None] * ug
    free &= np.isfinite(grad).all(axis=1)  # beyond floating point (a hair from a surface): not searched
    if hessian:
        gg = ug[:, :, None] * ug[:, None, :]
        hess += ugg_sum[:, None, None] * gg + (ug_sum / rg_safe)[:, None, None] * (eye - gg)
    return u, grad, hess, scale, free
