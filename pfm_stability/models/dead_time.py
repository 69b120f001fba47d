"""D*: the largest dead time of the steering plant an operating point tolerates (docs/models.md, "Plant gain and dead time").

The robot's plant g·e^(−sD)/(τs + 1) (`Loop.plant_gain`, `Loop.dead_time`): with
T and the rest fixed, the loop is stable for every D in [0, D*). `search_dead_time`
finds D* as `LoopModel.critical_delay` finds T*: the dominant growth rate on a
geometric grid of D, every local maximum before the first sign change refined, the
first sign change narrowed to 1e-7 relative (`numerics.solve.first_crossing` through `LoopModel.first_loss`). 0 if
the gain is unstable already without a dead time; ``inf`` if it stays stable up to the
largest allowed D (10 s). `exact_delay` has the exact route instead (the crossing
count's margin of the whole delay T + D, less T) and `continuous` does not depend on D.
"""

from __future__ import annotations

from ..parameters import RANGES

__all__ = ["search_dead_time"]


def search_dead_time(model, gain: float, loop, high: float | None = None) -> float:
    """D*, s, of `model` at `gain` for `loop` (its own D replaced), by the search of T* over D.

    Parameters
    ----------
    model : LoopModel
        The model whose growth rates are searched (`LoopModel.searched_growth_rates`).
    gain : float
        Loop gain NV, 1/s, already checked.
    loop : Loop
        τ, T, k, c and g.
    high : float, optional
        The longest dead time searched, s (default the largest allowed, 10 s; ``inf`` is returned when the gain is
        stable up to it): a model that carries at most so many periods in flight searches no further.
    """
    def search():
        start, rtol, atol = loop.delay_search(gain)
        return start, RANGES["dead_time"].high if high is None else high, {"rtol": rtol, "atol": atol}

    return model.first_loss(gain, lambda D: loop.replace(dead_time=float(D)), 0.0, search)
