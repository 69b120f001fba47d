"""Input checks shared by the library and the CLI.

Every check raises :class:`ValueError` with one line that names the parameter,
its allowed range and unit, and the value received, e.g.::

    V must be a finite number in (0, inf) m/s; got -1.0

The CLI prints exactly this message and exits with status 2, so the library and
the command line speak with one voice.
"""

from __future__ import annotations

import math
import numbers
import os

__all__ = ["check_number", "check_choice", "check_integer", "check_output_path", "check_type", "check_positive_axis", "describe_range"]


def describe_range(low: float, high: float, low_open: bool, high_open: bool) -> str:
    """Interval notation, e.g. ``(0, 100]``."""
    left = "(" if low_open else "["
    right = ")" if high_open else "]"
    return f"{left}{_fmt(low)}, {_fmt(high)}{right}"


def _fmt(x: float) -> str:
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return f"{x:.12g}"


def check_number(
    name: str,
    value,
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_open: bool = True,
    high_open: bool = True,
    unit: str = "",
) -> float:
    """Return `value` as a float after checking it lies in the allowed interval.

    Parameters
    ----------
    name : str
        Parameter name as the user knows it (``"V"``, ``"alpha"``).
    value : object
        The value to check; bools, strings, NaN and infinities are rejected
        (an infinite bound is always open).
    low, high : float
        Interval bounds.
    low_open, high_open : bool
        Whether each bound is excluded.
    unit : str
        Unit shown in the message (``"m/s"``).

    Returns
    -------
    float
        The checked value.

    Raises
    ------
    ValueError
        ``"<name> must be a finite number in <range> <unit>; got <value>"``.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(_number_message(name, value, low, high, low_open, high_open, unit))
    x = float(value)
    below = x <= low if low_open else x < low
    above = x >= high if high_open else x > high
    if below or above or not math.isfinite(x):
        raise ValueError(_number_message(name, value, low, high, low_open, high_open, unit))
    return x


def _number_message(name, value, low, high, low_open, high_open, unit) -> str:
    allowed = describe_range(low, high, low_open, high_open)
    return f"{name} must be a finite number in {allowed}{' ' + unit if unit else ''}; got {value!r}"


def check_integer(name: str, value, low: int, high: int) -> int:
    """Return `value` as an int after checking ``low <= value <= high``.

    Raises
    ------
    ValueError
        ``"<name> must be an integer in [low, high]; got <value>"``.
    """
    message = f"{name} must be an integer in [{low}, {high}]; got {value!r}"
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(message)
    if not low <= int(value) <= high:
        raise ValueError(message)
    return int(value)


def check_choice(name: str, value, choices) -> str:
    """Return `value` after checking it is one of `choices`.

    Raises
    ------
    ValueError
        ``"<name> must be one of a, b; got <value>"``.
    """
    if value not in choices:
        allowed = ", ".join(str(c) for c in choices)
        raise ValueError(f"{name} must be one of {allowed}; got {value!r}")
    return value


def check_output_path(name: str, path, suffix: str = ".png") -> str:
    """Return `path` after checking a file can be written there, before any work is done.

    The path must be non-empty, end in `suffix` (case-insensitive), not be an
    existing directory, and name a file whose directory exists and is
    writable (an existing file must be writable too). Nothing is created.

    Parameters
    ----------
    name : str
        Option name as the user knows it (``"out"``, ``"plot"``).
    path : str or os.PathLike
        The output path.
    suffix : str
        Required file-name ending, e.g. ``".png"``.

    Returns
    -------
    str
        The path, unchanged.

    Raises
    ------
    ValueError
        ``"<name> must be a writable file path ending in .png; got 'x' (no .png ending)"``.
    """
    text = os.fspath(path) if isinstance(path, (str, os.PathLike)) else path
    if not isinstance(text, str):
        raise ValueError(f"{name} must be a writable file path ending in {suffix}; got {path!r}")

    def fail(why: str):
        raise ValueError(f"{name} must be a writable file path ending in {suffix}; got {text!r} ({why})")

    if not text.strip():
        fail("empty")
    if "\0" in text:
        fail("contains a NUL character")
    if os.path.isdir(text):
        fail("an existing directory")
    if not text.lower().endswith(suffix.lower()):
        fail(f"the file name must end in {suffix}")
    if os.path.basename(text).lower() == suffix.lower():
        fail(f"no file name before {suffix}")
    parent = os.path.dirname(os.path.abspath(text))
    if not os.path.isdir(parent):
        fail(f"directory {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        fail(f"directory {parent} is not writable")
    if os.path.exists(text) and not (os.path.isfile(text) and os.access(text, os.W_OK)):
        fail("an existing file that cannot be overwritten")
    return text


def check_type(name: str, value, kinds, what: str):
    """Return `value` after checking it is an instance of `kinds`.

    Parameters
    ----------
    name : str
        Argument name as the user knows it (``"robot"``).
    value : object
    kinds : type or tuple of types
    what : str
        What is expected, for the message (``"a Robot"``).

    Raises
    ------
    ValueError
        ``"robot must be a Robot; got 'x'"``.
    """
    if not isinstance(value, kinds):
        raise ValueError(f"{name} must be {what}; got {value!r}")
    return value


def check_positive_axis(name: str, values, unit: str = ""):
    """Return `values` as a 1-D float ndarray after checking it is non-empty, finite and positive.

    For the axes of curves and maps (speeds, periods, gains). numpy is imported
    here, not at module level, so the CLI can check scalars before loading it.

    Raises
    ------
    ValueError
        ``"T_over_tau must be a non-empty 1-D array of positive finite numbers"``.
    """
    import numpy as np

    x = np.atleast_1d(np.asarray(values, dtype=float))
    if x.ndim != 1 or x.size == 0 or not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ValueError(f"{name} must be a non-empty 1-D array of positive finite numbers{' (' + unit + ')' if unit else ''}")
    return x
