"""Collisions between two samples: the robot disc along its exact path (docs/simulator.md, events).

Between t_k and t_k+1 the robot follows the exact solution of its held
command or reference (`pfm_stability.sim.robot`) at constant speed, a path of
length ℓ = V·h. A collision is the first instant the disc (diameter W) on that
path touches an obstacle — not only a sample where it already overlaps one: at
T = 100 s a robot moves 80 m per period and would otherwise drive through a
wall unseen.

Two facts make the check cheap and certain:

* **Lipschitz.** The clearance is 1-Lipschitz in position, so along a path of
  length ℓ whose ends clear the obstacles by g₀ and g₁ (beyond W/2) it never
  falls below (g₀ + g₁ − ℓ)/2: a period with g₀ + g₁ > ℓ is clear.
* **Chord.** Every point of a path of length ℓ between points a and b lies
  in the ellipse with foci a, b and major axis ℓ, hence within
  B = √(ℓ² − |b − a|²)/2 of the chord [a, b] (`path_slack`; ~0.14·ℓ·Δθ for a
  heading that turns by Δθ). A period whose chord clears the obstacles by
  more than W/2 + B is clear.

A period that neither test clears is divided into `SCAN` equal parts, the exact
positions at their ends computed (`StepPath`), and each part tested in turn
with its own chord, down to parts shorter than `CONTACT_RESOLUTION`
(`first_contact`). The first end that overlaps an obstacle brackets the
contact, which `pfm_stability.numerics.solve.refine_sign_change` narrows to `TIME_RTOL`
of the period. A part shorter than `CONTACT_RESOLUTION` whose chord touches
while its ends are clear is a graze (depth at most its B, well under
a micrometre): its contact is put at its end nearer the obstacle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..numerics.solve import refine_sign_change
from .robot import constant_input, constant_input_modes, graded_rule, propagate, servo, servo_modes, slow_rate, advance_position

__all__ = [
    "SCAN",
    "CONTACT_RESOLUTION",
    "TIME_RTOL",
    "path_slack",
    "point_wall_gap",
    "chord_wall_gap",
    "point_cell_gap",
    "chord_cell_gap",
    "StepPath",
    "Contact",
    "first_contact",
]

SCAN = 64
"""Parts a suspect period (or part) is divided into per level of `first_contact`."""

CONTACT_RESOLUTION = 1e-4
"""Shortest part of a path that `first_contact` divides further, m."""

TIME_RTOL = 1e-12
"""Width of the final bracket of a contact time, relative to the period."""


def path_slack(length, chord):
    """B = √(ℓ² − c²)/2, m: every point of a path of length ℓ between two points c apart lies within B of their chord.

    (The path lies in the ellipse with those foci and major axis ℓ, whose
    points are all within its semi-minor axis B of the segment between the
    foci.) Round-off that makes c > ℓ gives 0.

    Parameters
    ----------
    length : ndarray or float
        Path length ℓ, m.
    chord : ndarray or float
        Distance c between the path's ends, m.
    """
    length = np.asarray(length, dtype=float)
    chord = np.asarray(chord, dtype=float)
    return 0.5 * np.sqrt(np.maximum(length * length - chord * chord, 0.0))


def _point_segment(px, py, ax, ay, bx, by):
    """Distance from points to segments [a, b] (broadcast), m."""
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(length2 > 0, ((px - ax) * dx + (py - ay) * dy) / np.where(length2 > 0, length2, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.hypot(px - (ax + t * dx), py - (ay + t * dy))


def point_wall_gap(walls: dict, px, py):
    """Distance from points (shape (…, 1)) to the nearest wall segment (last axis = walls), m; ``inf`` without walls.

    `walls` is `AnalyticEnvironment.arrays()` (optionally with a ``valid`` mask).

    Parameters
    ----------
    walls : dict
        `AnalyticEnvironment.arrays()` (optionally with a ``valid`` mask).
    px, py : ndarray, shape (…, 1)
        The points, m.
    """
    ax, ay = walls["p0x"], walls["p0y"]
    bx, by = ax + walls["length"] * walls["ux"], ay + walls["length"] * walls["uy"]
    d = np.where(walls.get("valid", True), _point_segment(px, py, ax, ay, bx, by), math.inf)
    return np.min(d, axis=-1, initial=math.inf)


def chord_wall_gap(walls: dict, ax, ay, bx, by):
    """Distance from chords [a, b] (shape (…, 1)) to the nearest wall segment (last axis), m: 0 where they cross.

    Parameters
    ----------
    walls : dict
        `AnalyticEnvironment.arrays()` (optionally with a ``valid`` mask).
    ax, ay, bx, by : ndarray, shape (…, 1)
        The chords' ends, m.
    """
    px, py = walls["p0x"], walls["p0y"]
    qx, qy = px + walls["length"] * walls["ux"], py + walls["length"] * walls["uy"]
    cross = lambda ox, oy, ux, uy, vx, vy: (ux - ox) * (vy - oy) - (uy - oy) * (vx - ox)
    o1, o2 = cross(ax, ay, bx, by, px, py), cross(ax, ay, bx, by, qx, qy)
    o3, o4 = cross(px, py, qx, qy, ax, ay), cross(px, py, qx, qy, bx, by)
    proper = (o1 * o2 < 0) & (o3 * o4 < 0)  # touching and collinear cases: an end lies on the other segment (below)
    d = np.minimum(
        np.minimum(_point_segment(ax, ay, px, py, qx, qy), _point_segment(bx, by, px, py, qx, qy)),
        np.minimum(_point_segment(px, py, ax, ay, bx, by), _point_segment(qx, qy, ax, ay, bx, by)),
    )
    d = np.where(proper, 0.0, d)
    return np.min(np.where(walls.get("valid", True), d, math.inf), axis=-1, initial=math.inf)


def point_cell_gap(cx, cy, half, px, py):
    """Distance from points (shape (…, 1)) to the nearest cell square (centres cx, cy, half-side `half`; last axis), m.

    Parameters
    ----------
    cx, cy : ndarray
        Cell centres (last axis), m.
    half : float
        Half the cell side, m.
    px, py : ndarray, shape (…, 1)
        The points, m.
    """
    gx = np.maximum(np.abs(px - cx) - half, 0.0)
    gy = np.maximum(np.abs(py - cy) - half, 0.0)
    return np.sqrt(np.min(gx * gx + gy * gy, axis=-1, initial=math.inf))


def chord_cell_gap(cx, cy, half, ax, ay, bx, by):
    """Distance from chords [a, b] (shape (…, 1)) to the nearest cell square (last axis), m: 0 where a chord enters one.

    Two disjoint convex sets are nearest at a vertex of one of them: the
    chord's ends against the squares, the squares' corners against the chord;
    a chord that enters a square (slab test) is at distance 0.

    Parameters
    ----------
    cx, cy : ndarray
        Cell centres (last axis), m.
    half : float
        Half the cell side, m.
    ax, ay, bx, by : ndarray, shape (…, 1)
        The chords' ends, m.
    """
    dx, dy = bx - ax, by - ay
    with np.errstate(invalid="ignore", divide="ignore"):
        tx1 = np.where(dx != 0, (cx - half - ax) / np.where(dx != 0, dx, 1.0), -math.inf)
        tx2 = np.where(dx != 0, (cx + half - ax) / np.where(dx != 0, dx, 1.0), math.inf)
        ty1 = np.where(dy != 0, (cy - half - ay) / np.where(dy != 0, dy, 1.0), -math.inf)
        ty2 = np.where(dy != 0, (cy + half - ay) / np.where(dy != 0, dy, 1.0), math.inf)
    inside_x = (dx != 0) | (np.abs(ax - cx) <= half)
    inside_y = (dy != 0) | (np.abs(ay - cy) <= half)
    lo = np.maximum(np.maximum(np.minimum(tx1, tx2), np.minimum(ty1, ty2)), 0.0)
    hi = np.minimum(np.minimum(np.maximum(tx1, tx2), np.maximum(ty1, ty2)), 1.0)
    enters = inside_x & inside_y & (lo <= hi)
    box = lambda px, py: np.hypot(np.maximum(np.abs(px - cx) - half, 0.0), np.maximum(np.abs(py - cy) - half, 0.0))
    d = np.minimum(box(ax, ay), box(bx, by))
    for sx in (-half, half):
        for sy in (-half, half):
            d = np.minimum(d, _point_segment(cx + sx, cy + sy, ax, ay, bx, by))
    return np.min(np.where(enters, 0.0, d), axis=-1, initial=math.inf)


@dataclass(frozen=True)
class StepPath:
    """One member's exact motion over one sampling period, as the engine advances it (`pfm_stability.sim.robot`).

    Attributes
    ----------
    tau, k, max_rate : float
        Steering lag (s; 0: an ideal motor), gain (1/s) and rate limit (rad/s).
    h : float
        The period, s.
    reference : bool
        Held reference (servo closed) rather than a held command.
    substepped : bool
        A servo the engine advanced in `substeps` sub-intervals (saturated).
    substeps : int
    theta, omega : float
        Heading (rad) and rate (rad/s) at the start.
    value : float
        The held command (rad/s, before the plant gain) or reference (rad).
    V : float
        Speed, m/s.
    x, y : float
        Position at the start, m.
    gain : float
        Plant gain g: the motor's input is g times the command (the servo closes g·k(δ̃ − θ)).
    switch : float
        ε, s: a held command whose dead time ends within the period (`robot.delay_split`) drives
        the motor with `earlier` over [0, ε) and with `value` after; 0: `value` throughout.
    earlier : float
        The command before the switch, rad/s (before the plant gain).
    """

    tau: float
    k: float
    max_rate: float
    h: float
    reference: bool
    substepped: bool
    substeps: int
    theta: float
    omega: float
    value: float
    V: float
    x: float
    y: float
    gain: float = 1.0
    switch: float = 0.0
    earlier: float = 0.0

    def _advance(self, solution, times, theta, omega, value, x, y):
        """(x, y, θ, ω) after `times` (s, shape (n,)) from states (n,) under the "constant" or "servo" solution.

        `value` is the motor's input (g·u) for "constant", the reference for "servo" (closed with g·k).
        """
        n = times.size
        tau, k = np.full(n, self.tau), np.full(n, self.gain * self.k)
        slow = slow_rate(np.full(n, self.k), np.full(n, self.max_rate), self.gain)
        if self.substepped:  # the sub-steps' rules resolve both solutions
            modes = tuple(np.concatenate(pair, axis=1) for pair in zip(servo_modes(tau, k), constant_input_modes(tau)))
        else:
            modes = servo_modes(tau, k) if solution == "servo" else constant_input_modes(tau)
        rule = graded_rule(times, *modes, slow)
        coef = servo(tau, k, rule) if solution == "servo" else constant_input(tau, rule)
        delta, correction, theta_end, omega_end = propagate(coef, theta, omega, value)
        x_end, y_end = advance_position(x, y, np.full(n, self.V), rule, theta, delta, correction)
        return x_end, y_end, theta_end, omega_end

    def at(self, times):
        """(x, y) at `times` s after the start of the period (0 < t <= h), m.

        Parameters
        ----------
        times : ndarray
            Times after the start of the period, s (0 < t <= h).
        """
        times = np.atleast_1d(np.asarray(times, dtype=float))
        n = times.size
        start = lambda v: np.full(n, float(v))
        if not self.reference and self.switch > 0:  # the dead time ends at ε: g·earlier before, g·value after
            before = times <= self.switch
            out_x, out_y = np.empty(n), np.empty(n)
            m = int(np.count_nonzero(before))
            if m:
                out_x[before], out_y[before], _, _ = self._advance(
                    "constant", times[before], *(np.full(m, v) for v in (self.theta, self.omega, self.gain * self.earlier, self.x, self.y)))
            if m < n:
                one = lambda v: np.array([float(v)])
                sx, sy, st, so = self._advance("constant", one(self.switch), *(one(v) for v in (self.theta, self.omega, self.gain * self.earlier, self.x, self.y)))
                r = n - m
                out_x[~before], out_y[~before], _, _ = self._advance(
                    "constant", times[~before] - self.switch, *(np.full(r, float(v[0])) for v in (st, so, one(self.gain * self.value), sx, sy)))
            return out_x, out_y
        if not self.reference:
            return self._advance("constant", times, start(self.theta), start(self.omega), start(self.gain * self.value), start(self.x), start(self.y))[:2]
        if not self.substepped:
            return self._advance("servo", times, start(self.theta), start(self.omega), start(self.value), start(self.x), start(self.y))[:2]
        # the engine's sub-steps: equal parts of h, each saturated (±max_rate) or servo, decided at its start
        part = self.h / self.substeps
        states, x, y, theta, omega = [], self.x, self.y, self.theta, self.omega
        for _ in range(self.substeps):
            u = self.k * (self.value - theta)
            clipped = abs(u) > self.max_rate
            states.append((x, y, theta, omega, clipped, self.gain * min(max(u, -self.max_rate), self.max_rate)))
            one = np.array([part])
            if clipped:
                xs, ys, ts, ws = self._advance("constant", one, *(np.array([v]) for v in (theta, omega, states[-1][5], x, y)))
            else:
                xs, ys, ts, ws = self._advance("servo", one, *(np.array([v]) for v in (theta, omega, self.value, x, y)))
            x, y, theta, omega = float(xs[0]), float(ys[0]), float(ts[0]), float(ws[0])
        index = np.minimum(np.floor(times / part).astype(int), self.substeps - 1)
        rest = times - index * part
        out_x, out_y = np.empty(n), np.empty(n)
        for j in np.unique(index):
            at = index == j
            sx, sy, st, so, clipped, u = states[j]
            m = int(np.count_nonzero(at))
            solution, value = ("constant", u) if clipped else ("servo", self.value)
            out_x[at], out_y[at], _, _ = self._advance(solution, rest[at], np.full(m, st), np.full(m, so), np.full(m, value), np.full(m, sx), np.full(m, sy))
        return out_x, out_y


@dataclass(frozen=True)
class Contact:
    """The first touch of an obstacle within a period.

    Attributes
    ----------
    t : float
        Time from the start of the period, s.
    x, y : float
        Robot centre at that time, m.
    gap : float
        Clearance minus W/2 there, m (<= 0, or a graze's few micrometres at most).
    """

    t: float
    x: float
    y: float
    gap: float


def first_contact(path: StepPath, end, gap, chord_gap, half_width: float) -> Contact | None:
    """The first instant in (0, h] at which the disc on `path` touches an obstacle, or None (`SCAN`, module docstring).

    Parameters
    ----------
    path : StepPath
    end : (float, float)
        Position at the end of the period, m.
    gap : callable
        (x, y) arrays of shape (n,) → clearance to the obstacles (m), shape (n,).
    chord_gap : callable
        (ax, ay, bx, by) arrays of shape (n,) → distance of the chords to the obstacles (m), shape (n,).
    half_width : float
        W/2, m.
    """
    g0 = float(gap(np.array([path.x]), np.array([path.y]))[0]) - half_width
    if g0 <= 0:
        return Contact(0.0, path.x, path.y, g0)
    return _scan(path, gap, chord_gap, half_width, 0.0, path.h, (path.x, path.y), np.asarray(end, dtype=float), g0)


def _scan(path, gap, chord_gap, half, t0, t1, start, end, g_start):
    times = np.linspace(t0, t1, SCAN + 1)
    x, y = path.at(times[1:])
    if t1 == path.h:  # the engine's own end point (the same numbers up to round-off)
        x[-1], y[-1] = end
    x, y = np.concatenate([[start[0]], x]), np.concatenate([[start[1]], y])
    g = np.asarray(gap(x, y), dtype=float) - half
    g[0] = g_start
    length = path.V * (times[1:] - times[:-1])
    bound = chord_gap(x[:-1], y[:-1], x[1:], y[1:]) - half - path_slack(length, np.hypot(x[1:] - x[:-1], y[1:] - y[:-1]))
    touch = np.flatnonzero(g[1:] <= 0)
    last = int(touch[0]) if touch.size else SCAN - 1
    lipschitz = g[:-1] + g[1:] > length
    for i in np.flatnonzero(~lipschitz[: last + 1] & (bound[: last + 1] <= 0)):
        if length[i] > CONTACT_RESOLUTION:
            found = _scan(path, gap, chord_gap, half, times[i], times[i + 1], (x[i], y[i]), np.array([x[i + 1], y[i + 1]]), g[i])
            if found is not None:
                return found
            continue
        if g[i + 1] <= 0:
            measure = lambda t: -(np.asarray(gap(*path.at(t)), dtype=float) - half)
            t = refine_sign_change(measure, float(times[i]), float(times[i + 1]), rtol=0.0, atol=TIME_RTOL * path.h)
            cx, cy = path.at([t])
            return Contact(t, float(cx[0]), float(cy[0]), float(gap(cx, cy)[0]) - half)
        if chord_gap(x[i : i + 1], y[i : i + 1], x[i + 1 : i + 2], y[i + 1 : i + 2])[0] <= half:  # a graze
            j = i if g[i] <= g[i + 1] else i + 1
            return Contact(float(times[j]), float(x[j]), float(y[j]), float(g[j]))
    return None
