"""JSON-ready numbers: strict JSON has no inf or NaN.

Every `to_dict` in the package writes numbers with `json_number`:

* a finite number is itself;
* +inf and −inf — "no finite value", e.g. NV* = inf when a loop is stable for
  every gain, or L* = inf when no corridor is wide enough — are the strings
  ``"inf"`` and ``"-inf"``;
* an undefined value (NaN, or None: e.g. no boundary frequency when NV* = 0)
  is ``null``.

`parse_json_number` reads them back; `json_ready` applies `json_number` to
every number of a nested structure (dicts, lists, tuples, numpy scalars and
arrays), for `to_dict` methods that pass on dicts built elsewhere.

`dumps` is how every command writes its JSON: strict JSON (``allow_nan=False``),
indented by 2, with `json_default` for the numpy scalars a `to_dict` may leave.
"""

from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["json_number", "json_array", "json_ready", "json_default", "dumps", "parse_json_number", "SCHEMA_VERSION"]

SCHEMA_VERSION = "1.0"
"""Version of the JSON output (`pfm_stability/schema/output.schema.json`)."""


def json_number(x):
    """``float(x)`` if finite, ``"inf"``/``"-inf"`` if infinite, None if undefined (NaN or None).

    Parameters
    ----------
    x : float or None
        A number.
    """
    if x is None:
        return None
    x = float(x)
    if math.isnan(x):
        return None
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def parse_json_number(value) -> float:
    """The float a `json_number` stands for (None → NaN).

    Parameters
    ----------
    value : float, str or None
        A `json_number`.
    """
    if value is None:
        return math.nan
    return float(value)


def json_array(a):
    """Nested lists of `json_number` values for an array of any dimension.

    Parameters
    ----------
    a : array_like
        Numbers.
    """
    a = np.asarray(a, dtype=float)
    if a.ndim == 0:
        return json_number(a)
    if a.ndim == 1:
        return [json_number(v) for v in a.tolist()]
    return [json_array(row) for row in a]


def json_ready(value):
    """`value` with every number written by `json_number` (recursively), ready for strict JSON.

    Dicts keep their keys (as str), lists and tuples become lists, numpy
    arrays nested lists (`json_array`), bools and integers (numpy's too) stay
    exact, other numbers go through `json_number`; str and None are kept.

    Parameters
    ----------
    value : object
        Numbers, strings, None and (nested) dicts, lists, tuples and arrays of them.

    Raises
    ------
    TypeError
        For a value JSON cannot represent (an object, a complex number).
    """
    if value is None or isinstance(value, (str, bool)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return json_number(value)
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_array(value) if value.dtype.kind == "f" else json_ready(value.tolist())
    raise TypeError(f"cannot write {type(value).__name__} as JSON")


def json_default(value):
    """`json.dumps` ``default=``: numpy scalars as Python numbers (floats through `json_number`).

    Parameters
    ----------
    value : object
        What `json.dumps` could not write.

    Raises
    ------
    TypeError
        For any other object (as `json.dumps` does without a ``default``).
    """
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return json_number(value)
    raise TypeError(f"cannot serialize {type(value).__name__}")


def dumps(data) -> str:
    """`data` as the commands print it: strict JSON, indent 2, numpy scalars by `json_default`.

    Parameters
    ----------
    data : object
        JSON-ready data (`json_ready`).
    """
    return json.dumps(data, indent=2, allow_nan=False, default=json_default)
