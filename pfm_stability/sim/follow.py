"""Following a path: the pure-pursuit carrot of `Target.follow` targets, for a batch of robots.

A robot given a path (a polyline, m) keeps its progress s along it: the arc position of the nearest point of the
path ahead of it within one lookahead L, that is of the arc range [s, s + L] (the part behind is pruned, so s never
decreases, and a later part of the path that passes nearby is not taken for the robot's place). Its attraction
(KB eq 3) points at the carrot, the path's point at arc min(s + L, length) — the local planner's goal a global plan
hands it, as Nav2's pure-pursuit controllers take a lookahead point (docs/simulator.md, "What is simulated",
sensing). Progress towards the target, for the trap check, is s.

`pfm_stability.sim.reference` follows a path by its own per-robot loop over the segments; the tests compare the two.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PathFollower"]


class PathFollower:
    """The paths of a batch's path-target members and each robot's progress along its path.

    Parameters
    ----------
    targets : sequence of Target
        Path targets (`Target.follow`).
    """

    def __init__(self, targets):
        count = max(len(t.path) for t in targets)
        n = len(targets)
        self.vx, self.vy = np.zeros((n, count)), np.zeros((n, count))
        for m, t in enumerate(targets):  # a shorter path repeats its last vertex: zero-length segments, never chosen
            pts = np.pad(np.asarray(t.path, dtype=float), ((0, count - len(t.path)), (0, 0)), mode="edge")
            self.vx[m], self.vy[m] = pts[:, 0], pts[:, 1]
        self.dx, self.dy = np.diff(self.vx, axis=1), np.diff(self.vy, axis=1)
        self.seg = np.hypot(self.dx, self.dy)  # (n, count − 1) segment lengths, m
        self.arc = np.concatenate([np.zeros((n, 1)), np.cumsum(self.seg, axis=1)], axis=1)  # arc at each vertex, m
        self.length = self.arc[:, -1]
        self.lookahead = np.array([t.lookahead for t in targets], dtype=float)
        self.s = np.zeros(n)

    def advance(self, x, y) -> None:
        """Move each robot's progress s to the arc of its nearest path point within [s, s + L].

        Parameters
        ----------
        x, y : ndarray
            The robots' centres, m.
        """
        a0 = self.arc[:, :-1]
        safe = np.where(self.seg > 0, self.seg, 1.0)
        lo = np.clip((self.s[:, None] - a0) / safe, 0.0, 1.0)
        hi = np.clip((self.s[:, None] + self.lookahead[:, None] - a0) / safe, 0.0, 1.0)
        u = ((x[:, None] - self.vx[:, :-1]) * self.dx + (y[:, None] - self.vy[:, :-1]) * self.dy) / (safe * safe)
        u = np.clip(u, lo, hi)
        px, py = self.vx[:, :-1] + u * self.dx, self.vy[:, :-1] + u * self.dy
        d = np.hypot(px - x[:, None], py - y[:, None])
        inside = (a0 + self.seg >= self.s[:, None]) & (a0 <= self.s[:, None] + self.lookahead[:, None]) & (self.seg > 0)
        best = np.argmin(np.where(inside, d, np.inf), axis=1)
        rows = np.arange(self.s.size)
        self.s = np.maximum(self.s, a0[rows, best] + u[rows, best] * self.seg[rows, best])

    def carrot(self) -> tuple:
        """The points (m) each robot is pulled towards: arc min(s + L, length) along its path."""
        at = np.minimum(self.s + self.lookahead, self.length)
        rows = np.arange(self.s.size)
        k = np.minimum(np.sum(self.arc <= at[:, None], axis=1) - 1, self.seg.shape[1] - 1)
        seg = self.seg[rows, k]
        u = np.where(seg > 0, (at - self.arc[rows, k]) / np.where(seg > 0, seg, 1.0), 0.0)
        return self.vx[rows, k] + u * self.dx[rows, k], self.vy[rows, k] + u * self.dy[rows, k]
