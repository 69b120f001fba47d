"""JSON-ready numbers: strict JSON has no inf or NaN.

Every `to_dict` in the package turns a non-finite value into ``None`` ("no
finite value": e.g. NV* = inf when a loop is stable for every gain) with these
two helpers.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["json_number", "json_array"]


def json_number(x):
    """``float(x)`` if finite, else None (also for None)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def json_array(a):
    """Nested lists of `json_number` values for an array of any dimension."""
    a = np.asarray(a, dtype=float)
    if a.ndim == 0:
        return json_number(a)
    if a.ndim == 1:
        return [json_number(v) for v in a.tolist()]
    return [json_array(row) for row in a]
