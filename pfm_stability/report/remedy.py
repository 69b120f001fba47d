"""One remedy of the report: a single parameter moved to its critical value, when that change alone makes the loop stable.

The rule every geometry's remedies follow (`report.stability.remedies`, `report.path.path_remedies`): a change is
given only towards the stable side of a finite, positive critical value that lies beyond the present value.
"""

from __future__ import annotations

import math

__all__ = ["change"]


def change(name: str, target: float, direction: str | None, now: float | None) -> dict | None:
    """One remedy: move `name` from `now` to `target` ("raise" or "lower"), or None when that is no change that helps.

    None when there is no direction, the target is not finite and positive, or it lies on the wrong side of the
    present value (on the boundary). The report's rule for every geometry (`report.stability`).

    Parameters
    ----------
    name : str
        The parameter.
    target : float
        Its critical value.
    direction : {"raise", "lower"} or None
        Where the stable side is.
    now : float or None
        Its present value.
    """
    if direction is None or not math.isfinite(target) or target <= 0 or (name == "alpha_deg" and target >= 90):
        return None
    if now is not None and (target >= now if direction == "lower" else target <= now):
        return None
    entry = {"to": target, "direction": direction}
    if now:
        entry["change_percent"] = (target / now - 1.0) * 100
    return entry
