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

from .io.files import check_writable

__all__ = ["check_number", "check_choice", "check_integer", "check_output_path", "check_output_dir", "check_type", "check_positive_axis", "describe_range"]


def describe_range(low: float, high: float, low_open: bool, high_open: bool) -> str:
    """Interval notation, e.g. ``(0, 100]``.

    Parameters
    ----------
    low, high : float
        Interval bounds.
    low_open, high_open : bool
        Whether each bound is excluded.
    """
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

    Parameters
    ----------
    name : str
        Parameter name as the user knows it.
    value : object
        The value to check (an integral number; bools and non-integral floats are rejected).
    low, high : int
        Closed bounds.

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

    Parameters
    ----------
    name : str
        Parameter name as the user knows it.
    value : object
        The value to check.
    choices : sequence
        The allowed values.

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
    writable: a temporary file is created there and removed (`files.check_writable`:
    root passes `os.access` in ``/proc``, where nothing can be created). An existing
    file is replaced, not written into (`files.atomic_file`), so only the
    directory must take new files.

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
    reason = check_writable(parent)
    if reason is not None:
        fail(f"nothing can be created in {parent}: {reason}")
    if os.path.exists(text) and not os.path.isfile(text):
        fail("an existing file that cannot be overwritten")
    return text


def check_output_dir(name: str, path) -> str:
    """Return `path` after checking output files can be created in it, before any work.

    An existing directory must take new files; a missing one is created when the
    outputs are written (`files.atomic_directory`), so its parent must exist and
    take new entries. A temporary file is created there and removed
    (`files.check_writable`).

    Parameters
    ----------
    name : str
        Option name as the user knows it (``--out``).
    path : str or path-like
        The directory (created if missing).

    Raises
    ------
    ValueError
        ``"out-dir must be a writable directory; got '/proc/x' (nothing can be created in /proc: No such file or directory)"``.
    """
    text = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None

    def fail(why):
        raise ValueError(f"{name} must be a writable directory; got {path!r} ({why})")

    if text is None or not text.strip():
        fail("empty")
    if "\0" in text:
        fail("contains a NUL character")
    if os.path.exists(text) and not os.path.isdir(text):
        fail("an existing file")
    existing = os.path.abspath(text) if os.path.isdir(text) else os.path.dirname(os.path.abspath(text))
    if not os.path.isdir(existing):
        fail(f"its parent {existing} does not exist")
    reason = check_writable(existing)
    if reason is not None:
        fail(f"nothing can be created in {existing}: {reason}")
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

    Parameters
    ----------
    name : str
        Parameter name as the user knows it.
    values : array_like
        The axis values.
    unit : str, optional
        Unit shown in the message.

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
