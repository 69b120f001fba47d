"""The user's own routes: a Nav2 path, a CSV of x, y, or waypoints in YAML (docs/maps.md, "Your own routes").

`read_routes` reads one file into `routes.RoutePath`s, judged like the skeleton's routes (`maps.deciding.paths`):

* a Nav2 path — a ``nav_msgs/Path`` as YAML (``ros2 topic echo --once /plan > plan.yaml``): ``poses``, each
  ``pose: {position: {x, y}}`` (a ``PoseStamped``; a bare ``position`` is accepted too), optionally under a
  top-level ``path``; one route;
* waypoints in YAML: ``waypoints`` (or ``route``) — a list of ``[x, y]`` pairs or of ``{x, y}`` mappings — one route;
  or ``routes``: a list of such lists, one route each;
* a CSV (``.csv``): rows of x, y (m; a header row of non-numbers is skipped; further columns ignored); one route.

Coordinates are the map's (m). Goals between which the simulated robot drives are read the same way
(`read_points`) and driven by `validation.map_drives.goal_routes`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .routes import RoutePath, path_of

__all__ = ["read_points", "read_routes"]


def _point(item, where: str) -> tuple:
    """(x, y) of a waypoint: [x, y, ...], {x, y}, {position: {x, y}} or {pose: {position: {x, y}}}."""
    if isinstance(item, dict):
        if "pose" in item:
            return _point(item["pose"], where)
        if "position" in item:
            return _point(item["position"], where)
        if "x" in item and "y" in item:
            item = [item["x"], item["y"]]
    if isinstance(item, (list, tuple)) and len(item) >= 2:
        try:
            x, y = float(item[0]), float(item[1])
        except (TypeError, ValueError):
            pass
        else:
            if math.isfinite(x) and math.isfinite(y):
                return x, y
    raise ValueError(f"{where}: a point must be [x, y] or {{x: .., y: ..}} (finite numbers, m); got {item!r}")


def _lists(document, where: str) -> list:
    """The point lists of a YAML document (module docstring)."""
    if isinstance(document, dict) and isinstance(document.get("path"), dict):
        document = document["path"]
    if isinstance(document, dict) and "poses" in document:
        return [document["poses"]]
    if isinstance(document, dict):
        for key in ("waypoints", "route", "goals"):
            if key in document:
                return [document[key]]
        if "routes" in document and isinstance(document["routes"], list):
            return list(document["routes"])
    if isinstance(document, list):
        return [document]
    raise ValueError(f"{where}: expected a Nav2 path (poses), waypoints, route, goals or routes; "
                     f"got {sorted(document) if isinstance(document, dict) else type(document).__name__}")


def read_points(path) -> list:
    """The point lists of a route file, each a (n, 2) array (m) (module docstring).

    Parameters
    ----------
    path : str or Path
        A YAML (Nav2 path, waypoints, routes, goals) or CSV file.
    """
    path = Path(path)
    where = f"route file {path.name}"
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{where}: cannot be read ({exc.__class__.__name__})") from None
    if path.suffix.lower() == ".csv":
        rows = []
        for number, line in enumerate(text.splitlines(), 1):
            cells = [c.strip() for c in line.replace(";", ",").split(",")]
            if not line.strip():
                continue
            try:
                rows.append(_point([float(cells[0]), float(cells[1])], f"{where}, line {number}"))
            except (ValueError, IndexError):
                if rows:  # a header only before the first row
                    raise ValueError(f"{where}, line {number}: expected x, y (m); got {line.strip()!r}") from None
        return [np.array(rows, dtype=float).reshape(-1, 2)]
    import yaml

    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise ValueError(f"{where}{f', line {mark.line + 1}' if mark else ''}: not YAML") from None
    return [np.array([_point(p, f"{where}, point {i + 1}") for i, p in enumerate(points or [])], dtype=float).reshape(-1, 2)
            for points in _lists(document, where)]


def read_routes(path, first: int = 0) -> list[RoutePath]:
    """The routes of a route file as `RoutePath`s (source "path", "waypoints" or "csv"; module docstring).

    Parameters
    ----------
    path : str or Path
        The file.
    first : int
        Index of its first route (after the skeleton's).
    """
    path = Path(path)
    source = "csv" if path.suffix.lower() == ".csv" else "path"
    out = []
    for k, points in enumerate(read_points(path)):
        try:
            out.append(path_of(points, first + k, source))
        except ValueError as exc:
            raise ValueError(f"route file {path.name}: {exc}") from None
    return out

