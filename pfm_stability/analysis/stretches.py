"""Where a robot drove along a wall or through a corridor, from its log's scans and odometry (docs/diagnose.md, "Stretches").

Each laser scan is reduced as it streams past (`wall_lines`, a scan reducer for `io.logs.read_log`, or
`wall_lines_batch` on batches of scans at once: the same numbers, much faster): the
beams on each side of the robot within `WINDOW` m ahead and behind are fitted with one straight line (total
least squares, refitted twice without the points farther than max(`SPREAD`·rms, `TRIM`) from it), kept when it
runs alongside (its direction within `ALONGSIDE` of the heading), holds `MIN_POINTS` points and fits them to
`MAX_RMS` m, and reaches `COVER` m ahead of and behind the sensor. A line is (ρ, φ): the distance from the sensor (m) and the direction of its normal in the sensor
frame (rad); the laser is taken to sit at the base's origin looking forward.

`find_stretches` places every scan's lines in the odometry frame with the pose at the scan's time
(`io.logs.pose_at`: Φ = φ + yaw, P = ρ + n·(x, y)) and groups consecutive scans of a moving robot (speed
above `MIN_SPEED`) that see the same walls (both sides: a corridor; one side: a wall) at the same place
(each line within `SAME_ANGLE` and `SAME_OFFSET` of the stretch's median line). A gap of at most `GAP` s
without a matching scan (a dropped scan, a door in the wall) does not end a stretch. Each stretch's
walls are the median lines of its scans.

`lateral_offset` is the robot's lateral deviation there, at the odometry's samples: in a corridor the
offset from the centre line, (d_right − d_left)/2 (positive towards the left wall) with the half-width
L = (d_left + d_right)/2; beside a wall d − d0 with d0 the median distance. KB's L and d0 (eq 23, 25) are
the robot centre's distances, as these are.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.logs import PoseSeries, Scan, pose_at
from ..io.serialize import json_number

__all__ = ["WallLine", "Stretch", "LateralOffset", "wall_lines", "wall_lines_batch", "find_stretches", "lateral_offset", "travel_speed",
           "WINDOW", "COVER", "ALONGSIDE", "MIN_POINTS", "MAX_RMS", "TRIM", "SPREAD", "MIN_SPEED", "SAME_ANGLE", "SAME_OFFSET", "GAP",
           "MIN_DURATION", "MIN_LISTED", "BIN", "LINE_FIELDS"]

WINDOW = 2.0
"""Beams whose point is within this distance (m) ahead of or behind the sensor are fitted."""
ALONGSIDE = math.radians(40.0)
"""A fitted line runs alongside when its direction is within this angle (rad) of the heading."""
COVER = 0.3
"""A line's points must reach at least this far (m) both ahead of and behind the sensor: a wall beside the robot, not
one it approaches or has left."""
MIN_POINTS = 12
"""A side needs this many points for a line."""
MAX_RMS = 0.05
"""A line must fit its kept points to this rms distance (m)."""
TRIM = 0.03
SPREAD = 2.5
"""Points farther than max(SPREAD·rms, TRIM) m from a fitted line (rms: of the points it was fitted to) are dropped
before refitting; three fits."""
MIN_SPEED = 0.05
"""A robot moving slower than this (m/s) is not driving along anything (standing, turning in place)."""
SAME_ANGLE = math.radians(8.0)
"""A scan's wall belongs to a stretch when its normal is within this angle (rad) of the stretch's ..."""
SAME_OFFSET = 0.15
"""... and its offset P within this distance (m)."""
GAP = 1.0
"""Scans that do not match for at most this long (s) do not end a stretch."""
BIN = 0.1
"""The lateral offset is averaged over bins of this length (s; the odometry's interval if longer): a 50 Hz odometry's
white noise drops √5-fold, while an oscillation slower than 2 rad/s·… keeps its amplitude to 0.1 % (sinc(ω·BIN/2))."""
MIN_LISTED = 1.0
"""A run of matching scans shorter than this (s) is no stretch (a stray fit, a glimpse of a wall while turning)."""
MIN_DURATION = 5.0
"""A stretch shorter than this (s) is listed but not judged."""
LINE_FIELDS = ("rho_left", "phi_left", "rms_left", "rho_right", "phi_right", "rms_right")
"""The six numbers `wall_lines` returns per scan (NaN where a side has no line)."""


def _fit_lines(px: np.ndarray, py: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(ρ, φ, rms) per row of the points (px, py)[mask] (rows: scans), refitted twice; NaN where a row has no line.

    Total least squares through the masked points' moments (the covariance's main axis), the normal pointing away from
    the origin; points farther than max(`SPREAD`·rms, `TRIM`) are dropped and the line refitted (module docstring).
    """
    keep = mask
    for _ in range(3):
        w = keep.astype(float)
        n = np.maximum(w.sum(axis=1), 1.0)
        mx, my = (w * px).sum(axis=1) / n, (w * py).sum(axis=1) / n
        dx, dy = (px - mx[:, None]) * w, (py - my[:, None]) * w
        sxx, syy, sxy = (dx * dx).sum(axis=1), (dy * dy).sum(axis=1), (dx * dy).sum(axis=1)
        angle = 0.5 * np.arctan2(2 * sxy, sxx - syy)  # the line's direction
        nx, ny = -np.sin(angle), np.cos(angle)
        residual = (px - mx[:, None]) * nx[:, None] + (py - my[:, None]) * ny[:, None]
        rms = np.sqrt((w * residual * residual).sum(axis=1) / n)
        keep = mask & (np.abs(residual) <= np.maximum(SPREAD * rms, TRIM)[:, None])
    count = keep.sum(axis=1)
    rho = mx * nx + my * ny
    flip = rho < 0
    nx, ny, rho = np.where(flip, -nx, nx), np.where(flip, -ny, ny), np.abs(rho)
    rms = np.sqrt(np.where(keep, residual ** 2, 0.0).sum(axis=1) / np.maximum(count, 1))
    behind = np.where(keep, px, np.inf).min(axis=1)
    ahead = np.where(keep, px, -np.inf).max(axis=1)
    phi = np.arctan2(ny, nx)
    good = ((count >= MIN_POINTS) & (rms <= MAX_RMS) & (behind <= -COVER) & (ahead >= COVER)
            & (np.abs(np.sin(phi)) >= math.cos(ALONGSIDE)))  # a normal across the heading is no wall alongside
    return np.where(good[:, None], np.stack([rho, phi, rms], axis=1), np.nan)


def wall_lines_batch(scans) -> np.ndarray:
    """The walls on the left and right of each scan, in the sensor frame: a batched scan reducer (``scan_batch``).

    Parameters
    ----------
    scans : sequence of Scan
        Laser scans (angles rad, ranges m).

    Returns
    -------
    ndarray
        (scans, 6): the numbers of `LINE_FIELDS` per scan (`wall_lines`).
    """
    out = np.full((len(scans), 6), np.nan)
    groups = {}
    for i, scan in enumerate(scans):  # the scans of one layout are reduced together
        key = (scan.angle_min, scan.angle_increment, np.size(scan.ranges), scan.range_min, scan.range_max)
        groups.setdefault(key, []).append(i)
    for (a_min, a_inc, beams, r_min, r_max), rows in groups.items():
        r = np.stack([np.asarray(scans[i].ranges, dtype=float) for i in rows])
        a = a_min + a_inc * np.arange(beams)
        ok = np.isfinite(r) & (r > r_min) & (r < r_max)
        r = np.where(ok, r, 0.0)
        for side, columns in ((0, np.sin(a) > 0), (3, np.sin(a) < 0)):  # the left half of the beams, the right half
            rc, ac = r[:, columns], a[columns]
            px, py = rc * np.cos(ac), rc * np.sin(ac)
            out[rows, side:side + 3] = _fit_lines(px, py, ok[:, columns] & (np.abs(px) <= WINDOW))
    return out


def wall_lines(scan: Scan) -> np.ndarray:
    """The walls on the left and right of one scan, in the sensor frame: a scan reducer for `io.logs.read_log`.

    Parameters
    ----------
    scan : Scan
        One laser scan (angles rad, ranges m).

    Returns
    -------
    ndarray
        The six numbers of `LINE_FIELDS`: for each side the line's distance ρ (m), its normal's direction φ (rad,
        sensor frame) and the fit's rms (m); NaN for a side without a line (module docstring).
    """
    return wall_lines_batch([scan])[0]


@dataclass(frozen=True)
class WallLine:
    """A wall in the odometry frame: the points p with n·p = offset, n = (cos normal, sin normal).

    Attributes
    ----------
    normal : float
        The direction of the normal pointing from the robot to the wall, rad.
    offset : float
        The wall's distance from the frame's origin along the normal, m.
    """

    normal: float
    offset: float

    def distance(self, x, y):
        """Signed distance (m) of the points (x, y) to the wall, positive on the robot's side.

        Parameters
        ----------
        x, y : array_like
            Positions in the odometry frame, m.
        """
        return self.offset - (np.cos(self.normal) * np.asarray(x) + np.sin(self.normal) * np.asarray(y))

    def to_dict(self) -> dict:
        """``{normal, offset}`` (rad, m)."""
        return {"normal": json_number(self.normal), "offset": json_number(self.offset)}


@dataclass(frozen=True)
class Stretch:
    """A stretch of the log along a wall or through a corridor.

    Attributes
    ----------
    index : int
        Its number in the log (0 first).
    kind : {"corridor", "wall"}
    start, end : float
        Its first and last scan's time, s since the log's start.
    left, right : WallLine or None
        The walls seen (a wall stretch has one).
    scans : int
        Scans in it.
    """

    index: int
    kind: str
    start: float
    end: float
    left: WallLine | None
    right: WallLine | None
    scans: int

    @property
    def duration(self) -> float:
        """end − start, s."""
        return self.end - self.start

    def to_dict(self) -> dict:
        """The stretch as JSON: index, kind, start, end, duration (s), scans, walls {left, right}."""
        return {"index": self.index, "kind": self.kind, "start": json_number(self.start), "end": json_number(self.end),
                "duration": json_number(self.duration), "scans": self.scans,
                "walls": {"left": self.left.to_dict() if self.left else None, "right": self.right.to_dict() if self.right else None}}


@dataclass(frozen=True)
class LateralOffset:
    """The robot's lateral deviation over one stretch, sampled uniformly.

    Attributes
    ----------
    t : ndarray
        s, step `step`.
    offset : ndarray
        m: from the corridor's centre line (positive towards the left wall) or from d0 (positive away from the wall).
    step : float
        s: `BIN`, or the odometry's median interval if longer (each sample is the mean of the odometry's in its bin).
    geometry : float
        L (corridor half-width) or d0 (the median distance to the wall), m.
    samples : int
        Odometry samples inside the stretch.
    longest_gap : float
        The longest interval between them, s (dropped messages are interpolated over).
    """

    t: np.ndarray
    offset: np.ndarray
    step: float
    geometry: float
    samples: int
    longest_gap: float


def _median_line(normals: np.ndarray, offsets: np.ndarray) -> WallLine:
    mean = math.atan2(float(np.median(np.sin(normals))), float(np.median(np.cos(normals))))
    return WallLine(mean, float(np.median(offsets)))


def travel_speed(pose: PoseSeries, t) -> np.ndarray:
    """The robot's speed (m/s) at times `t`: its displacement over ±0.25 s in the odometry's pose.

    Parameters
    ----------
    pose : PoseSeries
        The odometry's pose.
    t : array_like
        Times, s.
    """
    t = np.asarray(t, dtype=float)
    x1, y1, _ = pose_at(pose, t + 0.25)
    x0, y0, _ = pose_at(pose, t - 0.25)
    span = np.clip(t + 0.25, pose.t[0], pose.t[-1]) - np.clip(t - 0.25, pose.t[0], pose.t[-1])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(span > 0, np.hypot(x1 - x0, y1 - y0) / np.where(span > 0, span, 1.0), 0.0)


def find_stretches(scan_t: np.ndarray, lines: np.ndarray, pose: PoseSeries) -> tuple[Stretch, ...]:
    """The stretches along a wall or through a corridor (module docstring).

    Parameters
    ----------
    scan_t : ndarray
        The scans' times, s.
    lines : ndarray
        (scans, 6): `wall_lines` of each scan.
    pose : PoseSeries
        The odometry's pose.

    Returns
    -------
    tuple of Stretch
        In time order, every one found (the short ones too: `MIN_DURATION` is the judge's).
    """
    scan_t = np.asarray(scan_t, dtype=float)
    lines = np.asarray(lines, dtype=float).reshape(-1, 6)
    if scan_t.size == 0:
        return ()
    x, y, yaw = pose_at(pose, scan_t)
    inside = (scan_t >= pose.t[0]) & (scan_t <= pose.t[-1])
    moving = (travel_speed(pose, scan_t) > MIN_SPEED) & inside
    normals = np.stack([lines[:, 1] + yaw, lines[:, 4] + yaw], axis=1)
    offsets = np.stack([lines[:, 0] + np.cos(normals[:, 0]) * x + np.sin(normals[:, 0]) * y,
                        lines[:, 3] + np.cos(normals[:, 1]) * x + np.sin(normals[:, 1]) * y], axis=1)
    seen = np.isfinite(lines[:, [0, 3]]) & moving[:, None]
    stretches, current = [], None

    def close(c):
        if c is None or scan_t[c["members"][-1]] - scan_t[c["members"][0]] < MIN_LISTED:
            return
        m = np.asarray(c["members"])
        walls = [_median_line(normals[m, s], offsets[m, s]) if c["sides"][s] else None for s in (0, 1)]
        kind = "corridor" if all(c["sides"]) else "wall"
        stretches.append(Stretch(len(stretches), kind, float(scan_t[m[0]]), float(scan_t[m[-1]]), walls[0], walls[1], int(m.size)))

    def matches(c, i, s):
        ref = c["ref"][s]
        return (seen[i, s] and abs(math.remainder(normals[i, s] - ref[0], 2 * math.pi)) <= SAME_ANGLE
                and abs(offsets[i, s] - ref[1]) <= SAME_OFFSET)

    for i in range(scan_t.size):
        if current is not None:
            if all(matches(current, i, s) for s in (0, 1) if current["sides"][s]) and \
                    not any(_new_side_lasts(seen, i, s) for s in (0, 1) if not current["sides"][s]):
                current["members"].append(i)
                current["recent"].append(i)
                if len(current["recent"]) in (5, 20, 50):  # the reference settles on the median of the first scans
                    m = np.asarray(current["recent"])
                    current["ref"] = [(_median_line(normals[m, s], offsets[m, s]).normal, float(np.median(offsets[m, s])))
                                      if current["sides"][s] else None for s in (0, 1)]
                continue
            opens = any(_new_side_lasts(seen, i, s) for s in (0, 1) if not current["sides"][s])
            if scan_t[i] - scan_t[current["members"][-1]] <= GAP and not opens:
                continue  # a dropped or stray scan, a door in the wall: the stretch goes on
            close(current)
            current = None
        if seen[i].any():
            sides = (bool(seen[i, 0]), bool(seen[i, 1]))
            current = {"sides": sides, "members": [i], "recent": [i],
                       "ref": [(normals[i, s], offsets[i, s]) if sides[s] else None for s in (0, 1)]}
    close(current)
    return tuple(stretches)


def _new_side_lasts(seen: np.ndarray, i: int, s: int, scans: int = 10) -> bool:
    """Whether side s, seen at scan i, is seen on most of the next `scans` scans (a wall that begins, not a stray fit)."""
    return bool(seen[i, s]) and seen[i: i + scans, s].mean() > 0.7


def lateral_offset(stretch: Stretch, pose: PoseSeries) -> LateralOffset | None:
    """The robot's lateral deviation over `stretch` at the odometry's samples, uniformly resampled (module docstring).

    Parameters
    ----------
    stretch : Stretch
        A stretch of `find_stretches`.
    pose : PoseSeries
        The odometry's pose.

    Returns
    -------
    LateralOffset or None
        None when fewer than 2 odometry samples fall inside the stretch.
    """
    inside = (pose.t >= stretch.start) & (pose.t <= stretch.end)
    t = pose.t[inside]
    if t.size < 2:
        return None
    x, y = pose.x[inside], pose.y[inside]
    if stretch.kind == "corridor":
        d_left, d_right = stretch.left.distance(x, y), stretch.right.distance(x, y)
        offset, geometry = (d_right - d_left) / 2, float(np.median((d_left + d_right) / 2))
    else:
        wall = stretch.left or stretch.right
        d = wall.distance(x, y)
        geometry = float(np.median(d))
        offset = d - geometry
    gaps = np.diff(t)
    step = max(float(np.median(gaps)), BIN)
    edges = np.arange(t[0], t[-1] + step, step)
    which = np.minimum(((t - t[0]) / step).astype(int), edges.size - 2)
    count = np.bincount(which, minlength=edges.size - 1)
    filled = count > 0
    centres = (edges[:-1] + step / 2)[filled]
    means = np.bincount(which, weights=offset, minlength=edges.size - 1)[filled] / count[filled]
    uniform = edges[:-1] + step / 2
    return LateralOffset(uniform, np.interp(uniform, centres, means), step, geometry, int(t.size), float(gaps.max()))
