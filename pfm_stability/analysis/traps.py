"""Traps: every stationary point of a 2-D potential field, and Ge & Cui's bounds for it.

Koren & Borenstein's problem 1 (traps due to local minima) and the GNRON problem
of Ge & Cui, IEEE T-RA 16(5), 2000 (docs/traps.md), for a `pfm_stability.laws.scene.Scene`.
`find_stationary_points`: damped Newton on ∇U = 0 (`scene.field`, exact) from
every grid node and every cell where both components of ∇U change sign,
polished, de-duplicated, classified by the Hessian's eigenvalues; grid minima
Newton does not explain (the crease of a non-convex polygon's distance) refined
by Nelder–Mead; the goal handled analytically (U need not be C² there);
GC2000's bounds on ξ/η (eq 25–37) for each obstacle within ρ0 of the goal.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..checks import check_integer, check_type
from ..parameters import RANGES, TRAPS_RESOLUTION
from ..laws.potentials import k_conservative, k_exact, repulsion_derivatives
from ..laws.scene import Scene, field
from ..io.serialize import SCHEMA_VERSION, json_number, json_ready

__all__ = ["KINDS", "RESOLUTION_RANGE", "DEFAULT_RESOLUTION", "StationaryPoint", "GnronBound", "TrapAnalysis", "find_stationary_points", "gnron_bounds"]

KINDS = ("minimum", "saddle", "maximum", "degenerate")
"""Kinds of stationary points (by the signs of the Hessian's eigenvalues; "degenerate": one is ~0)."""
RESOLUTION_RANGE = (int(RANGES["resolution"].low), int(RANGES["resolution"].high))
"""Grid points along the longer side of the region (`find_stationary_points`)."""
DEFAULT_RESOLUTION = TRAPS_RESOLUTION


# ------------------------------------------------------------------ results
@dataclass(frozen=True)
class StationaryPoint:
    """A stationary point of the total potential: position (m), one of `KINDS`, U there.

    `hessian_eigenvalues` (ascending) is None where U is not twice
    differentiable: the goal for m = 1 or n < 2 with an obstacle within ρ0,
    a minimum on the crease of a non-convex polygon's distance (`smooth` False).

    Attributes
    ----------
    x, y : float
        Position, m.
    kind : str
        One of `KINDS`.
    hessian_eigenvalues : tuple of float or None
        Eigenvalues of U's Hessian there, ascending (None where U is not twice differentiable).
    potential : float
        The total potential U there.
    goal : bool
        True for the goal.
    smooth : bool
        False on the crease of a non-convex polygon's distance.
    """

    x: float
    y: float
    kind: str
    hessian_eigenvalues: tuple | None
    potential: float
    goal: bool = False
    smooth: bool = True

    def to_dict(self) -> dict:
        """JSON-ready: x, y, kind, hessian_eigenvalues (null if undefined), potential, goal, smooth."""
        return json_ready(asdict(self))


@dataclass(frozen=True)
class GnronBound:
    """GC2000's bounds on ξ/η for obstacle `index` (of type `kind`) at distance `r` (m) from the goal (eq 25–37).

    `k_exact` is k_n (eq 28/29), `k_conservative` k′_n (eq 34/37), both None
    for Khatib's law (n = 0, no finite bound; `reason` says so); `satisfied`
    is ξ/η > k_n (False without a finite bound).

    Attributes
    ----------
    index : int
        The obstacle's index in the scene.
    kind : str
        The obstacle's type (``circle``, ``segment``, ``polygon``).
    r : float
        Its distance to the goal, m.
    k_exact : float or None
        k_n (eq 28/29), dimensionless.
    k_conservative : float or None
        k′_n (eq 34/37), dimensionless.
    ratio : float
        The scene's ξ/η, dimensionless.
    satisfied : bool
        ξ/η > k_n.
    reason : str or None
        Why there is no finite bound.
    """

    index: int
    kind: str
    r: float
    k_exact: float | None
    k_conservative: float | None
    ratio: float
    satisfied: bool
    reason: str | None = None

    def to_dict(self) -> dict:
        """JSON-ready: obstacle {index, type}, r, k_exact, k_conservative, ratio, satisfied, reason."""
        return {"obstacle": {"index": self.index, "type": self.kind}, "r": self.r, "k_exact": json_number(self.k_exact),
                "k_conservative": json_number(self.k_conservative), "ratio": self.ratio, "satisfied": self.satisfied, "reason": self.reason}


@dataclass(frozen=True)
class TrapAnalysis:
    """Every stationary point found in a scene, the goal's verdict and the bounds (`find_stationary_points`).

    Attributes
    ----------
    scene : Scene
        The scene analysed.
    resolution : int
        Grid points along the region's longer side.
    stationary_points : tuple of StationaryPoint
        Goal first, then by kind and position.
    goal_is_global_minimum : bool
        True when the goal is a minimum and no other minimum found has a lower potential.
    gnron_bounds : tuple of GnronBound
        GC2000's bounds (`gnron_bounds`).
    """

    scene: Scene
    resolution: int
    stationary_points: tuple
    goal_is_global_minimum: bool
    gnron_bounds: tuple

    @property
    def traps(self) -> tuple:
        """The minima other than the goal."""
        return tuple(p for p in self.stationary_points if p.kind == "minimum" and not p.goal)

    @property
    def conclusion(self) -> str:
        """One line: "the goal is the only minimum" or where the traps are."""
        goal_ok = any(p.goal and p.kind == "minimum" for p in self.stationary_points)
        head = "" if goal_ok else "the goal is not a minimum; "
        if not self.traps:
            return head + ("the goal is the only minimum" if goal_ok else "no minimum in the region")
        return head + "; ".join(f"trap at ({p.x:.6g}, {p.y:.6g})" for p in self.traps)

    def plot(self, ax=None, **kwargs):
        """`plots.traps.plot_traps` of this analysis; returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; None: a new figure.
        **kwargs
            Passed on to `plots.traps.plot_traps`.
        """
        from ..plots.traps import plot_traps

        return plot_traps(self, ax=ax, **kwargs)

    def to_dict(self) -> dict:
        """JSON-ready, with schema_version, command "traps" and the scene under inputs."""
        return {"schema_version": SCHEMA_VERSION, "command": "traps", "inputs": {"scene": self.scene.to_dict(), "resolution": self.resolution},
                "stationary_points": [p.to_dict() for p in self.stationary_points], "goal_is_global_minimum": self.goal_is_global_minimum,
                "gnron_bounds": [b.to_dict() for b in self.gnron_bounds], "conclusion": self.conclusion}


# ------------------------------------------------------------------ the search
def _classify(h) -> tuple:
    lam = tuple(float(v) for v in np.linalg.eigvalsh(h))
    if max(map(abs, lam)) == 0 or min(map(abs, lam)) <= 1e-9 * max(map(abs, lam)):
        return "degenerate", lam
    return ("minimum" if lam[0] > 0 else "maximum" if lam[1] < 0 else "saddle"), lam


def _newton_step(grad, hess, limit):
    a, b, d = hess[:, 0, 0], hess[:, 0, 1], hess[:, 1, 1]
    det = a * d - b * b
    ok = np.abs(det) > 1e-14 * (a * a + d * d + b * b) + 1e-300
    safe = np.where(ok, det, 1.0)
    step = -np.stack([(d * grad[:, 0] - b * grad[:, 1]) / safe, (a * grad[:, 1] - b * grad[:, 0]) / safe], axis=1)
    gn = np.linalg.norm(grad, axis=1)
    fallback = -grad / np.where(gn > 0, gn, 1.0)[:, None] * limit  # singular Hessian: a descent step
    step = np.where((ok & np.all(np.isfinite(step), axis=1))[:, None], step, fallback)
    length = np.linalg.norm(step, axis=1)
    return step * np.minimum(1.0, limit / np.where(length > 0, length, 1.0))[:, None]


def _inside(scene, q, margin=0.0):
    (x0, y0), (x1, y1) = scene.region
    return (q[:, 0] >= x0 - margin) & (q[:, 0] <= x1 + margin) & (q[:, 1] >= y0 - margin) & (q[:, 1] <= y1 + margin)


def _newton(scene, q, limit, iterations):
    """Damped Newton on ∇U = 0 from every row of q at once; steps into obstacles or out of the region are halved."""
    q = q.copy()
    alive = np.ones(q.shape[0], dtype=bool)
    tiny = 1e-14 * scene.diagonal
    for _ in range(iterations):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        _, g, h, _, _ = field(scene, q[idx])
        step = _newton_step(g, h, limit)
        moving = np.linalg.norm(step, axis=1) > tiny
        new = q[idx] + step
        good = field(scene, new, hessian=False)[4] & _inside(scene, new, 2 * limit)
        for _ in range(8):
            bad = np.flatnonzero(~good)
            if bad.size == 0:
                break
            step[bad] *= 0.5
            new[bad] = q[idx[bad]] + step[bad]
            good[bad] = field(scene, new[bad], hessian=False)[4] & _inside(scene, new[bad], 2 * limit)
        q[idx] = np.where(good[:, None], new, q[idx])
        alive[idx] = good & moving
    return q


def _goal_point(scene):
    """The goal as a stationary point, analytically (None if it is not one)."""
    law, (x, y), eye = scene.law, scene.goal, np.eye(2)
    u, grad, mag, hess, influence = 0.0, np.zeros(2), 0.0, law.xi * eye if law.m == 2 else None, False
    for o in scene.obstacles:
        rho, un, kappa = (v[0] for v in o.geometry(np.array([scene.goal])))
        if rho < law.rho0:
            influence = True
            d = [float(v) for v in repulsion_derivatives(rho, 0.0, law.eta, law.rho0, law.n, law.delta)]
            if law.n == 0:  # Khatib's repulsion is smooth at the goal
                u, grad, mag = u + d[0], grad + d[1] * un, mag + abs(d[1])
            if hess is not None and law.n == 0:
                hess = hess + d[3] * np.outer(un, un) + d[1] * kappa * (eye - np.outer(un, un))
            elif hess is not None and law.n == 2:  # ½ηc²ρ_g² has the Hessian ηc²·I at the goal
                hess = hess + law.eta * (1.0 / (rho + law.delta) - 1.0 / (law.rho0 + law.delta)) ** 2 * eye
            elif law.n < 2:
                hess = None  # not C² at the goal
    if law.n > 0 or not influence:  # U >= 0 = U(goal): the global minimum
        return StationaryPoint(x, y, "minimum", None if hess is None else _classify(hess)[1], u, goal=True, smooth=hess is not None)
    if law.m == 1:  # a cone ½ξρ_g: a minimum iff the repulsion is weaker than the pull ξ/2
        return StationaryPoint(x, y, "minimum", None, u, goal=True, smooth=False) if np.linalg.norm(grad) < law.xi / 2 else None
    if np.linalg.norm(grad) > 1e-12 * mag:  # Khatib's forces at the goal do not cancel: not stationary
        return None
    return StationaryPoint(x, y, *_classify(hess), u, goal=True)


def _polish(scene, p, iterations=30):
    """Newton polish of one point: the point, or None if it leaves the free space or |∇U| stays > 1e-9·scale."""
    for _ in range(iterations):
        _, g, h, s, free = field(scene, p[None, :])
        rel = float(np.linalg.norm(g[0]) / (s[0] + 1e-300))
        if not free[0] or rel < 1e-13:
            break
        p = p + _newton_step(g, h, 0.01 * scene.diagonal)[0]
    return p if free[0] and rel <= 1e-9 else None


def _value(scene, p):
    u, free = (v[0] for v in field(scene, p[None, :], hessian=False)[::4])
    return float(u) if free else math.inf


def _crease_minima(scene, u, free, xs, ys, known, h):
    """Grid local minima of U not explained by a known minimum: Nelder–Mead, kept if U rises on a ring about them."""
    from scipy.optimize import minimize

    pad = np.pad(np.where(free, u, np.inf), 1, constant_values=np.inf)
    core = pad[1:-1, 1:-1]
    lower = free & np.isfinite(core)
    for dy, dx in ((dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dx or dy):
        lower &= core <= pad[1 + dy:pad.shape[0] - 1 + dy, 1 + dx:pad.shape[1] - 1 + dx]
    lower[[0, -1], :] = lower[:, [0, -1]] = False  # a minimum on the region's edge is not stationary
    out = []
    for iy, ix in zip(*np.nonzero(lower)):
        p0 = np.array([xs[ix], ys[iy]])
        if any(np.hypot(*(p0 - k)) < 3 * h for k in known + [np.array(scene.goal)] + [np.array((o.x, o.y)) for o in out]):
            continue
        tolerances = {"xatol": 1e-9 * scene.diagonal, "fatol": 1e-13 * (1 + abs(_value(scene, p0))), "maxiter": 2000}
        res = minimize(lambda p: _value(scene, p), p0, method="Nelder-Mead", options=tolerances)
        p, eps = np.round(res.x / (1e-11 * scene.diagonal)) * (1e-11 * scene.diagonal), 1e-6 * scene.diagonal  # NM is good to ~1e-9
        uu, _, _, _, ok = field(scene, [p + eps * np.array([math.cos(a), math.sin(a)]) for a in np.linspace(0, 6.2, 24)], hessian=False)
        if (np.hypot(*(p - np.array(scene.goal))) > 1e-5 * scene.diagonal and _inside(scene, p[None, :])[0] and ok.all()
                and np.all(uu >= _value(scene, p)) and not any(np.hypot(*(p - k)) < 1e-5 * scene.diagonal for k in known)):
            out.append(StationaryPoint(float(p[0]) + 0.0, float(p[1]) + 0.0, "minimum", None, _value(scene, p), smooth=False))
    return out


def _extra_starts(scene, nodes, h):
    """Starts a grid of spacing h misses: rings about the goal (U may not be C² there) and mid-gap points between two obstacles."""
    t = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    out = [(np.array(scene.goal) + np.geomspace(1e-4 * scene.diagonal, 3 * h, 12)[:, None, None] * np.stack([np.cos(t), np.sin(t)], 1)).reshape(-1, 2)]
    if len(scene.obstacles) > 1:  # the middle of the nearest points on the two nearest obstacles of every node
        rho, unit = (np.array(v) for v in zip(*((g[0], g[1]) for g in (o.geometry(nodes) for o in scene.obstacles))))
        i, j = np.argsort(rho, axis=0)[:2]
        n = np.arange(nodes.shape[0])
        mid = nodes - 0.5 * (rho[i, n, None] * unit[i, n] + rho[j, n, None] * unit[j, n])
        mid = mid[(rho[i, n] > 0) & (rho[j, n] < 2 * scene.law.rho0)]
        out.append(mid[np.unique(np.round(mid / (h / 8)), axis=0, return_index=True)[1]])  # one per h/8 cell, not moved
    return out


def find_stationary_points(scene: Scene, resolution: int = DEFAULT_RESOLUTION, *, iterations: int = 60) -> TrapAnalysis:
    """Every stationary point of the scene's total potential in its region (free space only), as a `TrapAnalysis`.

    `resolution` (`RESOLUTION_RANGE`) grid points along the region's longer
    side, the same spacing h along the other; Newton steps are at most 2h,
    `iterations` per start. Points are sorted goal first, then by kind and
    position. Two stationary points closer than ~h may be missed (docs/traps.md, "Limits").

    Parameters
    ----------
    scene : Scene
        Goal, obstacles, law and region.
    resolution : int
        Grid points along the region's longer side (`RESOLUTION_RANGE`).
    iterations : int
        Newton steps per start.
    """
    check_type("scene", scene, Scene, "a Scene")
    resolution = check_integer("resolution", resolution, *RESOLUTION_RANGE)
    xs, ys, h = scene.grid(resolution)
    X, Y = np.meshgrid(xs, ys)
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    u, g, _, _, free = field(scene, nodes, hessian=False)
    starts = [nodes[free]]
    gx, gy, fr = (a.reshape(X.shape) for a in (g[:, 0], g[:, 1], free))
    cells = fr[:-1, :-1] & fr[1:, :-1] & fr[:-1, 1:] & fr[1:, 1:]
    for c in (gx, gy):  # cells where both components change sign hold a zero of ∇U
        corners = np.stack([c[:-1, :-1], c[1:, :-1], c[:-1, 1:], c[1:, 1:]])
        cells &= (corners.min(axis=0) <= 0) & (corners.max(axis=0) >= 0)
    iy, ix = np.nonzero(cells)
    starts.append(np.column_stack([(xs[ix] + xs[ix + 1]) / 2, (ys[iy] + ys[iy + 1]) / 2]))
    q = _newton(scene, np.concatenate(starts + _extra_starts(scene, nodes[free], h)), 2 * h, iterations)
    _, gq, _, sq, fq = field(scene, q, hessian=False)
    goal = np.array(scene.goal)
    tol = 1e-6 * scene.diagonal
    keep = fq & _inside(scene, q) & (np.linalg.norm(gq, axis=1) <= 1e-5 * sq) & (np.linalg.norm(q - goal, axis=1) > tol)
    found: list[np.ndarray] = []
    for p in (p for p in (_polish(scene, p) for p in np.unique(np.round(q[keep] / tol) * tol, axis=0)) if p is not None):
        if _inside(scene, p[None, :])[0] and np.hypot(*(p - goal)) > tol and not any(np.hypot(*(p - k)) <= tol for k in found):
            found.append(p)
    points = []
    for p in found:
        value, _, hess, _, _ = field(scene, p[None, :])
        kind, eig = _classify(hess[0])
        p = np.where(np.abs(p) < 1e-13 * scene.diagonal, 0.0, p)  # Newton's last digits on a symmetry axis; no -0
        points.append(StationaryPoint(float(p[0]), float(p[1]), kind, eig, float(value[0])))
    known = [p for p, s in zip(found, points) if s.kind == "minimum"]
    points += _crease_minima(scene, u.reshape(X.shape), fr, xs, ys, known, h)
    points.sort(key=lambda s: (KINDS.index(s.kind), s.x, s.y))
    goal_point = _goal_point(scene)
    if goal_point is not None:
        points.insert(0, goal_point)
    others = [p.potential for p in points if p.kind == "minimum" and not p.goal]
    global_min = goal_point is not None and goal_point.kind == "minimum" and all(goal_point.potential <= v for v in others)
    return TrapAnalysis(scene, resolution, tuple(points), bool(global_min), gnron_bounds(scene))


def gnron_bounds(scene: Scene) -> tuple:
    """GC2000's bounds on ξ/η (eq 25–37) for every obstacle within ρ0 of the goal, as `GnronBound`s.

    The bound of obstacle i uses its distance r to the goal alone (the 1-D
    model on the ray from the goal away from its nearest point); δ enters as
    r + δ, ρ0 + δ (eq 40). For m = 1 the bound is our extension of eq (25)
    (factor 2/m, (ρ − r)^(n−m)).

    Parameters
    ----------
    scene : Scene
        Goal, obstacles and a GNRON (or Khatib) law.
    """
    law = scene.law
    ratio = law.xi / law.eta
    out = []
    for i, o in enumerate(scene.obstacles):
        r = float(o.geometry(np.array([scene.goal]))[0][0])
        if r >= law.rho0:
            continue
        if law.n == 0 and law.m == 2:
            reason = "Khatib's law (n = 0): no finite bound; the repulsion at the goal moves the minimum off it for every xi/eta"
            out.append(GnronBound(i, o.kind, r, None, None, ratio, False, reason))
            continue
        k = k_exact(r, law.rho0, law.n, law.m, law.delta)
        kc = k_conservative(r, law.rho0, law.n, law.m, law.delta)
        reason = "m = 1: eq (25) extended with the factor 2/m and (rho - r)^(n - m)" if law.m == 1 else None
        out.append(GnronBound(i, o.kind, r, k, kc, ratio, bool(ratio > k), reason))
    return tuple(out)
