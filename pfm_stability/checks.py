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

__all__ = ["check_number", "check_choice", "check_integer", "describe_range"]


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
