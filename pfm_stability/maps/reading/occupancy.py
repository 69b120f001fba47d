"""ROS ``map_server`` occupancy maps: the YAML file and its image, read exactly as Nav2 reads them.

A map is a YAML file (docs/maps.md, "Map files") with the keys

``image``
    The image file, relative to the YAML file (PGM, PNG, … : anything Pillow reads).
``resolution``
    Metres per pixel, > 0.
``origin``
    [x, y, yaw] of the lower-left pixel's lower-left corner (m, m, rad): three numbers,
    as Nav2's map_server requires (it refuses any other count). The yaw is read and kept
    (written back into a speed mask) but, as in most of Nav2, not applied.
``negate``
    0 or 1 (also true/false): whether white means occupied.
``occupied_thresh``, ``free_thresh``
    Probabilities in [0, 1] with free_thresh < occupied_thresh.
``mode``
    ``trinary`` (default), ``scale`` or ``raw``.

Every pixel becomes the value Nav2's map server puts into the ``OccupancyGrid``
(``nav2_map_server`` ``map_io``): with the shade x = mean of the colour channels / 255
(in trinary mode an alpha channel is averaged in as one more channel) and
p = 1 − x (x itself if ``negate``),

* trinary: 100 if p > occupied_thresh, 0 if p < free_thresh, −1 (unknown) otherwise;
* scale: −1 if the pixel is not opaque, 100 / 0 as in trinary, otherwise
  rint(100·(p − free_thresh)/(occupied_thresh − free_thresh));
* raw: the pixel value x·255 itself if it is in [0, 100], else −1.

Pixel row 0 is the top of the image, the largest y; `OccupancyMap.values` is stored
the other way up, row 0 at y = origin (the ``OccupancyGrid`` convention: cell (row j,
column i) covers [x0 + i·r, x0 + (i+1)·r) × [y0 + j·r, y0 + (j+1)·r)).

For the analysis every cell is occupied, free or unknown: value 100 or 0 in trinary
and scale mode (the values between are "unknown" there, exactly the pixels trinary
mode calls unknown), value/100 compared with the thresholds in raw mode.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ...checks import check_number
from ...extras import require
from ...io.yaml_files import InputError, YamlFile, leading_key, read_yaml

__all__ = ["MAP_KEYS", "MAX_PIXELS", "MODES", "OccupancyMap", "load_map", "occupancy_values"]

MODES = ("trinary", "scale", "raw")
"""``mode`` values of a map file (Nav2 ``map_server``)."""
MAP_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")
"""Keys a map file may have; all but ``mode`` are required."""
REQUIRED_KEYS = MAP_KEYS[:-1]
MAX_PIXELS = 100_000_000
"""Largest image read, pixels (10⁸: 100 MB of values; Nav2's own maps are a few million)."""
OCCUPIED, FREE, UNKNOWN = 100, 0, -1


@dataclass(frozen=True)
class OccupancyMap:
    """An occupancy map as Nav2's map server publishes it.

    Attributes
    ----------
    name : str
        The YAML file's stem (``depot``), for titles.
    resolution : float
        m per cell.
    origin : (float, float, float)
        x, y (m) of the lower-left corner and yaw (rad, kept but not applied).
    values : ndarray of int8, shape (height, width)
        ``OccupancyGrid`` values (−1 unknown, 0 … 100), row 0 at y = origin[1].
    occupied, free : ndarray of bool, shape (height, width)
        The classification used by the analysis (module docstring); a cell that is
        neither is unknown.
    mode : str
        trinary, scale or raw.
    negate : bool
    occupied_thresh, free_thresh : float
    """

    name: str
    resolution: float
    origin: tuple
    values: np.ndarray
    occupied: np.ndarray
    free: np.ndarray
    mode: str = "trinary"
    negate: bool = False
    occupied_thresh: float = 0.65
    free_thresh: float = 0.25

    @property
    def height(self) -> int:
        """Rows (cells along y)."""
        return int(self.values.shape[0])

    @property
    def width(self) -> int:
        """Columns (cells along x)."""
        return int(self.values.shape[1])

    @property
    def unknown(self) -> np.ndarray:
        """Cells neither occupied nor free."""
        return ~(self.occupied | self.free)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max), m."""
        x0, y0 = self.origin[0], self.origin[1]
        return (x0, x0 + self.width * self.resolution, y0, y0 + self.height * self.resolution)

    def cell_of(self, x, y):
        """(column i, row j) of the cells containing the points (may lie outside the map).

        Parameters
        ----------
        x, y : array_like
            Points in map coordinates, m.
        """
        r = self.resolution
        i = np.floor((np.asarray(x, dtype=float) - self.origin[0]) / r).astype(np.int64)
        j = np.floor((np.asarray(y, dtype=float) - self.origin[1]) / r).astype(np.int64)
        return i, j

    def to_dict(self) -> dict:
        """``width``, ``height`` (cells), ``resolution`` (m), ``origin`` [x, y, yaw]: the JSON ``map``."""
        return {"name": self.name, "width": self.width, "height": self.height, "resolution": self.resolution,
                "origin": [float(v) for v in self.origin]}


def occupancy_values(shade, opaque, *, mode: str, negate: bool, occupied_thresh: float, free_thresh: float) -> np.ndarray:
    """Nav2 ``OccupancyGrid`` values of pixels (module docstring), int8.

    Parameters
    ----------
    shade : ndarray
        Pixel shade in [0, 1] (mean of the channels / full scale).
    opaque : ndarray of bool
        Whether each pixel is fully opaque (scale mode makes the others unknown).
    mode, negate, occupied_thresh, free_thresh
        As in the map file.
    """
    shade = np.asarray(shade, dtype=float)
    if mode == "raw":
        value = np.rint(shade * 255.0)
        return np.where((value >= 0) & (value <= 100), value, UNKNOWN).astype(np.int8)
    p = shade if negate else 1.0 - shade
    occupied, free = p > occupied_thresh, p < free_thresh
    if mode == "trinary":
        middle = np.full(p.shape, UNKNOWN, dtype=float)
    else:
        middle = np.rint((p - free_thresh) / (occupied_thresh - free_thresh) * 100.0)
        middle = np.where(opaque, middle, UNKNOWN)
    out = np.where(occupied, OCCUPIED, np.where(free, FREE, middle))
    if mode == "scale":
        out = np.where(opaque, out, UNKNOWN)
    return out.astype(np.int8)


def _classify(values: np.ndarray, mode: str, occupied_thresh: float, free_thresh: float):
    """(occupied, free) masks of ``OccupancyGrid`` values."""
    if mode == "raw":
        known = values >= 0
        p = values.astype(float) / 100.0
        return known & (p > occupied_thresh), known & (p < free_thresh)
    return values == OCCUPIED, values == FREE


# ------------------------------------------------------------------ reading
def _fail(document: YamlFile, why: str, key=None):
    """Raise the map file's error: ``map FILE, line N: <why>``, at the line of `key` (default: the key `why` starts with)."""
    raise document.error(why, key if key is not None else leading_key(why))


def _read_yaml(path) -> YamlFile:
    """The map file, read by the package's one YAML reader (`pfm_stability.io.yaml_files`), with its required keys."""
    document = read_yaml(path, "map")
    data = document.data
    if not isinstance(data, dict):
        _fail(document, f"must be a YAML mapping with keys {', '.join(REQUIRED_KEYS)}; got {type(data).__name__}", ())
    for key in REQUIRED_KEYS:
        if key not in data:
            _fail(document, f"key {key!r} is missing (a map file needs {', '.join(REQUIRED_KEYS)})", ())
    return document


def _number(document, key, value, low=-math.inf, high=math.inf, **kw) -> float:
    try:
        return check_number(key, value, low, high, **kw)
    except ValueError as exc:
        _fail(document, str(exc), key)


def _parameters(document: YamlFile) -> dict:
    data = document.data
    resolution = _number(document, "resolution", data["resolution"], 0.0, 1e3, unit="m")
    origin = data["origin"]
    if not isinstance(origin, (list, tuple)) or len(origin) != 3:  # map_server: "should have 3 elements"
        _fail(document, f"origin must be a list [x, y, yaw] of three finite numbers (m, m, rad), as Nav2's map_server requires; got {origin!r}")
    origin = tuple(_number(document, f"origin[{i}]", v, -1e7, 1e7) for i, v in enumerate(origin))
    negate = data["negate"]
    if negate not in (0, 1) or isinstance(negate, float):  # True/False and 0/1
        _fail(document, f"negate must be 0 or 1; got {negate!r}")
    occupied = _number(document, "occupied_thresh", data["occupied_thresh"], 0.0, 1.0, low_open=False, high_open=False)
    free = _number(document, "free_thresh", data["free_thresh"], 0.0, 1.0, low_open=False, high_open=False)
    if not free < occupied:
        _fail(document, f"free_thresh must be below occupied_thresh; got free_thresh {free:g} >= occupied_thresh {occupied:g}")
    mode = data.get("mode", "trinary")
    if mode not in MODES:
        _fail(document, f"mode must be one of {', '.join(MODES)}; got {mode!r}")
    image = data["image"]
    if not isinstance(image, str) or not image.strip():
        _fail(document, f"image must be a file name; got {image!r}")
    return {"resolution": resolution, "origin": origin, "negate": bool(negate), "occupied_thresh": occupied,
            "free_thresh": free, "mode": mode, "image": image}


def _read_image(document: YamlFile, image_path: str):
    """`_channels` of the image file, rows as in the file (row 0 = top)."""
    require("maps", "reading a map image")
    from PIL import Image, UnidentifiedImageError

    if not os.path.isfile(image_path):
        _fail(document, f"image {image_path!r} does not exist")
    try:
        with Image.open(image_path) as im:
            if im.width * im.height > MAX_PIXELS:
                _fail(document, f"image {image_path!r} has {im.width} x {im.height} pixels, more than {MAX_PIXELS:.0e}")
            im.load()
            image = im.copy()
    except InputError:
        raise
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as exc:
        _fail(document, f"image {image_path!r} is not a readable image (PGM, PNG, ...): {exc}")
    return _channels(document, image_path, image)


def _channels(document, image_path, im):
    """(shade, opaque, alpha, colour channels) of a Pillow image: shade the mean of the colour channels in [0, 1]."""
    mode = im.mode
    if mode == "P":
        im, mode = im.convert("RGBA"), "RGBA"
    elif mode == "1":
        im, mode = im.convert("L"), "L"
    if mode in ("L", "LA", "RGB", "RGBA"):
        a = np.asarray(im, dtype=float) / 255.0
    elif mode in ("I;16", "I;16B", "I;16L", "I"):
        a = np.asarray(im, dtype=float) / 65535.0
    else:
        _fail(document, f"image {image_path!r} has pixel mode {mode}; a map is grey, RGB or with alpha (L, LA, RGB, RGBA, P, 16-bit)")
    if a.ndim == 2:
        return a, np.ones(a.shape, dtype=bool), None, 1
    has_alpha = mode in ("LA", "RGBA")
    colour = a[..., :-1] if has_alpha else a
    alpha = a[..., -1] if has_alpha else None
    opaque = alpha >= 1.0 if has_alpha else np.ones(colour.shape[:2], dtype=bool)
    return colour.mean(axis=-1), opaque, alpha, colour.shape[-1]


def load_map(path, name: str | None = None) -> OccupancyMap:
    """Read a ``map_server`` map: the YAML file `path` and its image.

    Parameters
    ----------
    path : str or os.PathLike
        The YAML file.
    name : str, optional
        Name for titles (default: the file's stem).

    Raises
    ------
    ValueError
        One line naming the file, the line of the key concerned and the problem (`pfm_stability.io.yaml_files`):
        unreadable YAML, a missing key,
        resolution <= 0, an origin that is not three finite numbers, thresholds outside
        [0, 1] or free_thresh >= occupied_thresh, an unknown mode, a missing or
        unreadable image, an empty map.
    """
    path = os.fspath(path)
    document = _read_yaml(path)
    params = _parameters(document)
    image_path = os.path.join(os.path.dirname(os.path.abspath(path)), params.pop("image"))
    shade, opaque, alpha, channels = _read_image(document, image_path)
    if shade.size == 0:
        _fail(document, f"image {image_path!r} has no pixels")
    if params["mode"] == "trinary" and alpha is not None:  # Nav2 averages the alpha in as one more channel
        shade = (shade * channels + alpha) / (channels + 1)
    values = occupancy_values(shade, opaque, mode=params["mode"], negate=params["negate"],
                              occupied_thresh=params["occupied_thresh"], free_thresh=params["free_thresh"])[::-1].copy()
    occupied, free = _classify(values, params["mode"], params["occupied_thresh"], params["free_thresh"])
    for a in (values, occupied, free):
        a.flags.writeable = False
    stem = os.path.splitext(os.path.basename(path))[0]
    return OccupancyMap(name or stem, params["resolution"], params["origin"], values, occupied, free, params["mode"],
                        params["negate"], params["occupied_thresh"], params["free_thresh"])
