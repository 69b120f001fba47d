"""Where the validation's drives met an obstacle, and what the map said there (docs/maps.md, "Where the drives
collided").

Every drive that ended in a collision (`sim.contact`: the robot's disc touched an occupied cell) is located — the
robot's centre at the first touch — and set beside the map's prediction along its routes: the nearest route sample
within the match distance (`JudgeThresholds.match_distance`, at least the robot's width) and its verdict and cause.
A collision is **foreseen** when a sample predicted unstable with cause "collision course" lies within that distance,
and **near a weave** when one predicted unstable by any other cause does; the rest met an obstacle where the map's
routes say nothing of it (off every route, or on a stretch called stable: the VFF robot cutting a corner towards its
carrot, which the loop driven along the route does not model).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_number, json_ready

__all__ = ["Collision", "CollisionSummary", "locate_collisions"]


@dataclass(frozen=True)
class Collision:
    """One drive's collision.

    Attributes
    ----------
    drive : int
        The drive's index.
    x, y : float
        The robot's centre at the first touch, m.
    route : int or None
        The nearest route of the map within the match distance (None: none).
    distance : float or None
        Its distance from the nearest route sample, m.
    verdict : str or None
        That sample's verdict ("stable", "unstable" or a reason it is unjudged).
    cause : str or None
        Its cause where unstable.
    foreseen : bool
        A sample with cause "collision course" lies within the match distance.
    near_weave : bool
        A sample unstable by another cause lies within it.
    """

    drive: int
    x: float
    y: float
    route: int | None
    distance: float | None
    verdict: str | None
    cause: str | None
    foreseen: bool
    near_weave: bool

    def to_dict(self) -> dict:
        """JSON form."""
        return json_ready(dict(self.__dict__))


@dataclass(frozen=True)
class CollisionSummary:
    """The drives' collisions against the map's prediction (`locate_collisions`).

    Attributes
    ----------
    collisions : tuple of Collision
    match_distance : float
        m.
    """

    collisions: tuple
    match_distance: float

    @property
    def foreseen(self) -> int:
        """Collisions within the match distance of a predicted collision course."""
        return sum(c.foreseen for c in self.collisions)

    @property
    def near_weave(self) -> int:
        """Collisions not foreseen but within the match distance of a stretch predicted to weave."""
        return sum(c.near_weave and not c.foreseen for c in self.collisions)

    @property
    def elsewhere(self) -> int:
        """Collisions near a route but neither foreseen nor near a predicted weave (the route called stable there, or
        unjudged)."""
        return sum(c.route is not None and not (c.foreseen or c.near_weave) for c in self.collisions)

    @property
    def off_routes(self) -> int:
        """Collisions farther than the match distance from every route."""
        return sum(c.route is None for c in self.collisions)

    def to_dict(self) -> dict:
        """JSON form: the counts and every collision."""
        return {"count": len(self.collisions), "foreseen": self.foreseen, "near_weave": self.near_weave,
                "elsewhere": self.elsewhere, "off_routes": self.off_routes, "match_distance": json_number(self.match_distance),
                "collisions": [c.to_dict() for c in self.collisions]}


def locate_collisions(pv, contacts, match_distance: float) -> CollisionSummary:
    """Each drive's collision beside the map's prediction (module docstring).

    Parameters
    ----------
    pv : PathVerdicts
        The map's routes and their verdicts (`maps.deciding.paths`).
    contacts : sequence of (int, float, float)
        (drive index, x, y) of each drive that ended in a collision, m.
    match_distance : float
        m (> 0).
    """
    from scipy.spatial import cKDTree

    from ..maps.deciding.decide import CAUSES, PATH_VERDICTS

    x, y = pv.samples.x, pv.samples.y
    if not contacts:
        return CollisionSummary((), float(match_distance))
    tree = cKDTree(np.column_stack([x, y])) if x.size else None
    course, unstable = pv.cause == CAUSES.index("collision course"), pv.code == PATH_VERDICTS.index("unstable")
    found = []
    for drive, cx, cy in contacts:
        near = np.asarray(tree.query_ball_point([cx, cy], match_distance), dtype=int) if tree is not None else np.zeros(0, dtype=int)
        if near.size == 0:
            found.append(Collision(int(drive), float(cx), float(cy), None, None, None, None, False, False))
            continue
        nearest = int(near[np.argmin(np.hypot(x[near] - cx, y[near] - cy))])
        cause = CAUSES[pv.cause[nearest]] if pv.cause[nearest] >= 0 else None
        found.append(Collision(int(drive), float(cx), float(cy), int(pv.samples.segment[nearest]),
                               float(np.hypot(x[nearest] - cx, y[nearest] - cy)), PATH_VERDICTS[pv.code[nearest]], cause,
                               bool(course[near].any()), bool((unstable[near] & ~course[near]).any())))
    return CollisionSummary(tuple(found), float(match_distance))
