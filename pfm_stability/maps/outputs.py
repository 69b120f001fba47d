"""The files of ``pfm-stability map --out-dir``: segments.csv and a Nav2 Speed Filter mask (their contents; the CLI writes them atomically with `files.atomic_directory`).

The speed mask (docs/maps.md, "The speed mask") has the input map's size, resolution
and origin. Each cell holds a speed limit as a percentage of the robot's V, for the
Nav2 speed filter with ``type: 1`` (percentage), ``base: 0``, ``multiplier: 1``:

* cells within W/2 of a segment whose V* is below V: 100·V*/V rounded down (never
  above what is stable), at least 1 (the filter reads 0 as "no limit");
* every other cell — free, occupied or unknown — 100: the robot may drive at V.
  Occupied cells are never driven through, and 100 % is the filter's "no
  reduction"; no cell is written as unknown (−1), which the filter ignores
  without resetting a previous limit.

The PGM is read in ``mode: scale`` with ``negate: 0``, ``free_thresh: 0``,
``occupied_thresh: 1``: Nav2 turns a pixel value v into
rint(100·(255 − v)/255). Writing v = 255 − round(2.55·q) for a percentage q gives
back q exactly (the rounding error 0.5/2.55 ≈ 0.2 % stays below the 0.5 of rint):
`percent_to_pixel` and `pixel_to_percent`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "OUTPUT_FILES",
    "percent_to_pixel",
    "pixel_to_percent",
    "segments_csv",
    "speed_limits",
    "speed_mask_yaml",
    "speed_mask_pgm",
]

OUTPUT_FILES = ("stability.png", "segments.csv", "speed_mask.pgm", "speed_mask.yaml")
"""What ``--out-dir`` receives."""
CSV_COLUMNS = ("x0", "y0", "x1", "y1", "length", "N", "c", "V_critical", "margin", "stable", "verdict", "offset", "samples", "analysed",
               "N_max", "V_critical_local", "wavelength")
MIN_PERCENT = 1
"""Lowest limit written (the speed filter reads a mask value of 0 as "no limit")."""


def _csv_value(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "inf" if v == math.inf else f"{v:.6g}"
    return str(v)


def segments_csv(analysis) -> str:
    """One row per segment: end points (m, map coordinates), length, N (N_eff), c, V*, margin, stable, verdict, offset,
    samples, and the local worst (N_max, V_critical_local) with the averaging wavelength (m).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis whose segments are written.
    """
    lines = [",".join(CSV_COLUMNS)]
    for s in analysis.segments:
        lines.append(",".join(_csv_value(getattr(s, k)) for k in CSV_COLUMNS))
    return "\n".join(lines) + "\n"


def percent_to_pixel(percent) -> np.ndarray:
    """PGM value (uint8) of a percentage 0 … 100 in the mask's scale mode (module docstring).

    Parameters
    ----------
    percent : array_like
        Speed limits, % of V (0 … 100).
    """
    q = np.asarray(percent, dtype=float)
    return (255 - np.round(2.55 * q)).astype(np.uint8)


def pixel_to_percent(value) -> np.ndarray:
    """Nav2's reading of a PGM value in the mask's scale mode: rint(100·(255 − v)/255).

    Parameters
    ----------
    value : array_like of int
        PGM values (0 … 255).
    """
    return np.rint(100.0 * (255.0 - np.asarray(value, dtype=float)) / 255.0).astype(np.int64)


def speed_limits(analysis) -> np.ndarray:
    """Speed limit per map cell, % of V (int, shape (height, width), row 0 at y = origin).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (map, segments and their verdicts).
    """
    occupancy = analysis.occupancy
    V, half = analysis.robot.V, analysis.robot.W / 2
    limits = np.full(occupancy.values.shape, 100, dtype=np.int64)
    r = occupancy.resolution
    ox, oy = occupancy.origin[0], occupancy.origin[1]
    for s in analysis.segments:
        if s.V_critical is None or not s.V_critical < V:
            continue
        percent = max(MIN_PERCENT, min(100, math.floor(100.0 * s.V_critical / V)))
        i0, j0 = occupancy.cell_of(min(s.x0, s.x1) - half, min(s.y0, s.y1) - half)
        i1, j1 = occupancy.cell_of(max(s.x0, s.x1) + half, max(s.y0, s.y1) + half)
        i0, j0 = max(int(i0), 0), max(int(j0), 0)
        i1, j1 = min(int(i1), occupancy.width - 1), min(int(j1), occupancy.height - 1)
        if i1 < i0 or j1 < j0:
            continue
        jj, ii = np.mgrid[j0:j1 + 1, i0:i1 + 1]
        px, py = ox + (ii + 0.5) * r, oy + (jj + 0.5) * r
        near = _distance_to_segment(px, py, s) <= half
        block = limits[j0:j1 + 1, i0:i1 + 1]
        block[near] = np.minimum(block[near], percent)
    return limits


def _distance_to_segment(px, py, s):
    dx, dy = s.x1 - s.x0, s.y1 - s.y0
    t = np.clip(((px - s.x0) * dx + (py - s.y0) * dy) / (dx * dx + dy * dy), 0.0, 1.0)
    return np.hypot(px - s.x0 - t * dx, py - s.y0 - t * dy)


def speed_mask_yaml(occupancy, image: str = "speed_mask.pgm") -> str:
    """The mask's map_server YAML: the map's resolution and origin, scale mode, thresholds that make the mapping exact.

    Parameters
    ----------
    occupancy : OccupancyMap
        The map (resolution, origin).
    image : str
        The PGM file's name, relative to the YAML file.
    """
    origin = ", ".join(f"{v:.12g}" for v in occupancy.origin)
    return (f"image: {image}\nmode: scale\nresolution: {occupancy.resolution:.12g}\norigin: [{origin}]\nnegate: 0\n"
            "occupied_thresh: 1.0\nfree_thresh: 0.0\n")


def speed_mask_pgm(analysis) -> bytes:
    """The mask image as a binary PGM (P5, 8 bits, row 0 at the top, as map_server reads it).

    Parameters
    ----------
    analysis : MapAnalysis
        The analysis (`speed_limits`).
    """
    pixels = percent_to_pixel(speed_limits(analysis))[::-1]
    height, width = pixels.shape
    return f"P5\n{width} {height}\n255\n".encode("ascii") + np.ascontiguousarray(pixels).tobytes()
