"""The stability-region panels' data: one model's verdicts on a grid and every model's boundary curve (KB §5.3–5.4).

A `RegionPanel` is what one region picture shows: the shaded model's verdicts (`regions`: by
default the report's verdict model, ``sampled`` with the controller's hold and compute delay,
`regions.verdict_model`), every model's boundary curve (`curves`), the loop in words and the
view. The builders compute it:

* `wall_f_panel`: the (V, f) plane at one α; stable above f*(V) (KB eq 24);
* `wall_alpha_panel`: α*(V); stable above (KB eq 21, 23);
* `corridor_V_panel`: the (L, V) plane; stable below V*(L) (KB eq 25);
* `corridor_L_panel`: L*(V); stable above (KB eq 25);
* `wall_panels`, `corridor_panels`: the panels of one figure (`RegionPanels`; the figures of ``analyses/``).

``.plot()`` draws a panel (`pfm_stability.plots.regions`, which only draws).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..laws.force_law import ForceLaw, PowerLaw
from ..parameters import Controller, Robot
from .curves import corridor_L_curves, corridor_V_curves, default_models, wall_alpha_curves, wall_f_curves
from .regions import RegionGrid, corridor_region, region_model, verdict_model, wall_alpha_region, wall_f_region

__all__ = [
    "RegionPanel",
    "RegionPanels",
    "corridor_L_panel",
    "corridor_V_panel",
    "corridor_panels",
    "shading_text",
    "wall_alpha_panel",
    "wall_f_panel",
    "wall_panels",
]

KINDS = ("wall_f", "wall_alpha", "corridor_V", "corridor_L")
"""What a `RegionPanel` shows: (V, f) at one α, α*(V), (L, V), L*(V)."""


@dataclass(frozen=True)
class RegionPanel:
    """One stability-region panel: the shaded model's verdicts on a grid and every model's boundary curve.

    Attributes
    ----------
    kind : {"wall_f", "wall_alpha", "corridor_V", "corridor_L"}
        (V, f) at one α (stable above f*(V)); α*(V) (stable above); (L, V) (stable below V*(L));
        L*(V) (stable above).
    robot, controller : Robot, Controller
        The robot and controller of the loop (its operating point is marked).
    curves : tuple of curves.BoundaryCurve
        Every model's boundary.
    region : regions.RegionGrid or None
        The shaded model's verdicts over the panel's axes (x across, y up); None when not shaded.
    shaded : str or None
        What the shading shows (`shading_text`); None when not shaded.
    loop : str
        The loop and the law in words, for the title.
    x, y : ndarray
        The panel's axes (V and f; V and α, rad; L and V; V and L, m/s, m), whose ends bound the view.
    alpha : float or None
        The wall's target angle, rad (``wall_f``).
    """

    kind: str
    robot: Robot
    controller: Controller
    curves: tuple
    region: RegionGrid | None
    shaded: str | None
    loop: str
    x: np.ndarray
    y: np.ndarray
    alpha: float | None = None

    def plot(self, ax=None, **kwargs):
        """The panel (`plots.regions.PANELS`: `plot_wall_f_region`, `plot_wall_alpha_critical`, `plot_corridor_region`,
        `plot_corridor_L_critical`); returns the figure.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; None: a new figure.
        **kwargs
            Passed on to the panel's plotting function.
        """
        from ..plots.regions import PANELS

        return PANELS[self.kind](self, ax=ax, **kwargs)


class RegionPanels(list):
    """The panels of one figure (`wall_panels`: (V, f) at each α and α*(V); `corridor_panels`: (L, V) and L*(V)).

    Parameters
    ----------
    iterable : iterable of RegionPanel
        The figure's panels, in drawing order.
    """

    def plot(self):
        """`plots.regions.plot_wall_regions` or `plot_corridor_regions`: the panels side by side, one legend; returns the figure."""
        from ..plots.regions import plot_corridor_regions, plot_wall_regions

        return plot_wall_regions(self) if self[0].kind.startswith("wall") else plot_corridor_regions(self)


def shading_text(model, controller: Controller) -> str:
    """What a shaded map shows, for titles and legends.

    E.g. ``sampled (command hold, compute delay 1) — the report's verdict``
    when `model` is the report's verdict model (`regions.verdict_model`),
    ``exact_delay (vectorized crossing count)`` for ``exact_delay``.

    Parameters
    ----------
    model : LoopModel
    controller : Controller
        Decides the report's verdict model (its hold and compute delay).

    Returns
    -------
    str
    """
    from ..plots.common import model_description

    text = model_description(model)
    if model == verdict_model(controller):
        return f"{text} — the report's verdict"
    if model.name == "exact_delay":
        return f"{text} (vectorized crossing count)"
    return text


def _loop_text(robot: Robot, controller: Controller, law: ForceLaw | None = None) -> str:
    """τ, T, k, W and the law (f and n for KB's power law, else the law's name)."""
    law_text = f"f = {controller.f:g}, n = {controller.n:g}" if law is None or isinstance(law, PowerLaw) else f"{law.name}"
    return f"τ = {robot.tau:g} s, T = {controller.T:g} s, k = {robot.k:g} 1/s, W = {robot.W:g} m, {law_text}"


def _speeds(V, resolution: int) -> np.ndarray:
    """The speed axis, m/s (default `resolution` points in [0.02, 2])."""
    return np.linspace(0.02, 2.0, resolution) if V is None else np.asarray(V, dtype=float)


def _shading(controller: Controller, shaded, region_of, shade: bool = True) -> tuple:
    """(region, text) of the shaded model (`regions.region_model`, `shading_text`): ``region_of(model)``; (None, None) unshaded."""
    if not shade:
        return None, None
    model = region_model(controller, shaded)
    return region_of(model), shading_text(model, controller)


def wall_f_panel(robot: Robot, controller: Controller, alpha: float, *, V=None, f=None, models=None, shaded=None,
               resolution: int = 300) -> RegionPanel:
    """Stable and unstable regions along a wall in the (V, f) plane at one target angle α (KB's power law).

    Shading: the verdicts of the `shaded` model (`regions.wall_f_region`); curves: f*(V) of
    every model (`curves.wall_f_curves`, KB eq 24 with the model's NV*); stable above the curves.

    Parameters
    ----------
    robot, controller : Robot, Controller
        The robot (τ, k, W) and controller (n, T, hold, compute delay).
    alpha : float
        Target angle from the wall normal, rad (KB eq 9).
    V : array_like, optional
        Speeds, m/s (default `resolution` points in [0.02, 2] m/s).
    f : array_like, optional
        Force ratios (default `resolution` log-spaced points in [0.01, 100]).
    models : list of LoopModel, optional
        Curves drawn; default `curves.default_models(controller)`.
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (`regions.region_model`); default the report's
        verdict model, ``sampled`` with the controller's hold and compute delay.
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    RegionPanel
    """
    V = _speeds(V, resolution)
    f = np.geomspace(0.01, 100.0, resolution) if f is None else np.asarray(f, dtype=float)
    models = default_models(controller) if models is None else models
    region, text = _shading(controller, shaded, lambda model: wall_f_region(robot, controller, alpha, V, f, model=model))
    curves = tuple(wall_f_curves(robot, controller, alpha, V, models))
    return RegionPanel("wall_f", robot, controller, curves, region, text, _loop_text(robot, controller), V, f, alpha)


def wall_alpha_panel(robot: Robot, controller: Controller, *, V=None, models=None, law: ForceLaw | None = None, shaded=None, shade: bool = True,
                   resolution: int = 300) -> RegionPanel:
    """Critical target angle α*(V) along a wall: stable above every model's curve (KB eq 21, 23).

    Parameters
    ----------
    robot, controller : Robot, Controller
    V : array_like, optional
        Speeds, m/s (default [0.02, 2]).
    models : list of LoopModel, optional
    law : ForceLaw, optional
        Default KB's power law with the controller's f; e.g. the grid's effective law to
        compare with the grid simulator.
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict model, see `wall_f_panel`).
    shade : bool
        Shade the `shaded` model's verdicts.
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    RegionPanel
        y: α, rad (`resolution` points in [0.2°, 89.8°]).
    """
    V = _speeds(V, resolution)
    models = default_models(controller) if models is None else models
    alpha = np.radians(np.linspace(0.2, 89.8, resolution))
    region, text = _shading(controller, shaded, lambda model: wall_alpha_region(robot, controller, V, alpha, law=law, model=model), shade)
    curves = tuple(wall_alpha_curves(robot, controller, V, models, law=law))
    return RegionPanel("wall_alpha", robot, controller, curves, region, text, _loop_text(robot, controller, law), V, alpha)


def corridor_V_panel(robot: Robot, controller: Controller, *, L=None, V=None, models=None, law: ForceLaw | None = None, shaded=None,
                   shade: bool = True, resolution: int = 300) -> RegionPanel:
    """Stable and unstable regions in the middle of a corridor, (L, V) plane: stable below V*(L) (KB eq 25).

    Shading: the verdicts of the `shaded` model (`regions.corridor_region`); curves:
    V*(L) = NV*/N(L) of every model (`curves.corridor_V_curves`).

    Parameters
    ----------
    robot, controller : Robot, Controller
    L : array_like, optional
        Half-widths, m (default (W/2, 2] m).
    V, models, law, shaded, shade, resolution
        As `wall_alpha_panel`.

    Returns
    -------
    RegionPanel
    """
    L = np.linspace(robot.W / 2 * 1.0005, 2.0, resolution) if L is None else np.asarray(L, dtype=float)
    V = _speeds(V, resolution)
    models = default_models(controller) if models is None else models
    region, text = _shading(controller, shaded, lambda model: corridor_region(robot, controller, L, V, law=law, model=model), shade)
    curves = tuple(corridor_V_curves(robot, controller, L, models, law=law))
    return RegionPanel("corridor_V", robot, controller, curves, region, text, _loop_text(robot, controller, law), L, V)


def corridor_L_panel(robot: Robot, controller: Controller, *, V=None, models=None, law: ForceLaw | None = None, shaded=None, shade: bool = True,
                   resolution: int = 300) -> RegionPanel:
    """Critical corridor half-width L*(V): stable above every model's curve (KB eq 25).

    Parameters
    ----------
    robot, controller : Robot, Controller
    V, models, law, shaded, shade, resolution
        As `wall_alpha_panel`.

    Returns
    -------
    RegionPanel
        y: L, m, from W/2 to 1.15 times the largest finite L* (at least 1.6 m).
    """
    V = _speeds(V, resolution)
    models = default_models(controller) if models is None else models
    curves = tuple(corridor_L_curves(robot, controller, V, models, law=law))
    top = max(1.6, 1.15 * max(float(np.nanmax(np.where(np.isfinite(c.y), c.y, np.nan))) for c in curves))
    L = np.linspace(robot.W / 2 * 1.0005, top, resolution)

    def across(model):  # the grid is (V rows, L columns): L up, V across
        grid = corridor_region(robot, controller, L, V, law=law, model=model)
        return replace(grid, x=grid.y, y=grid.x, stable=grid.stable.T)

    region, text = _shading(controller, shaded, across, shade)
    return RegionPanel("corridor_L", robot, controller, curves, region, text, _loop_text(robot, controller, law), V, L)


def wall_panels(robot: Robot, controller: Controller, alphas_deg=(20.0, 45.0, 70.0), *, models=None, shaded=None, resolution: int = 300) -> RegionPanels:
    """(V, f) at each α and α*(V), one shaded model (KB §5.3): the panels of `plots.regions.plot_wall_regions`.

    Parameters
    ----------
    robot, controller : Robot, Controller
    alphas_deg : sequence of float
        Target angles of the (V, f) panels, deg.
    models : list of LoopModel, optional
        Curves drawn (default every model).
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict model, ``sampled``
        with the controller's structure).
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    RegionPanels
    """
    shaded = region_model(controller, shaded)
    panels = [wall_f_panel(robot, controller, math.radians(a), models=models, shaded=shaded, resolution=resolution) for a in alphas_deg]
    return RegionPanels([*panels, wall_alpha_panel(robot, controller, models=models, shaded=shaded, resolution=resolution)])


def corridor_panels(robot: Robot, controller: Controller, *, models=None, shaded=None, resolution: int = 300) -> RegionPanels:
    """(L, V) and L*(V), one shaded model (KB §5.4): the panels of `plots.regions.plot_corridor_regions`.

    Parameters
    ----------
    robot, controller : Robot, Controller
    models : list of LoopModel, optional
        Curves drawn (default every model).
    shaded : LoopModel or str, optional
        The model whose verdicts are shaded (default the report's verdict model).
    resolution : int
        Grid points per axis of the shading.

    Returns
    -------
    RegionPanels
    """
    shaded = region_model(controller, shaded)
    return RegionPanels([corridor_V_panel(robot, controller, models=models, shaded=shaded, resolution=resolution),
                          corridor_L_panel(robot, controller, models=models, shaded=shaded, resolution=resolution)])
