"""Model comparison plots: how the five loop models differ, and where KB's criterion errs (drawing only: each takes its result).

* `plot_critical_gain_vs_delay`: NV* against T/τ for every model and every
  sampled structure (hold × compute delay), `comparison.critical_gain_vs_delay`'s
  `GainCurves` (also its ``.plot()``). KB's eq (20) gives NV* = 1/(τ + T).
* `plot_kb_error_map`: NV*_KB/NV*_model − 1 over (kτ, T/τ) (`comparison.kb_error_map`, also ``KBErrorMap.plot()``):
  red where KB's criterion is optimistic (it calls stable a loop that
  oscillates), blue where it is conservative.
* `plot_kb_error_maps`: one map per reference model, one colour bar.
* `plot_model_comparison`: NV* versus k (`plots.rlocus.plot_critical_gain_vs_k`)
  and versus T/τ side by side, one legend below (both curve sets given).

Model styles follow `plots.common.MODEL_STYLE`; the four sampled structures
are told apart as in `plots.rlocus`: solid = command hold, dashed =
reference hold; thick = compute_delay 0, thin = 1. Broken lines are drawn
above solid ones (`plots.common.MODEL_ZORDER`), so ``pade`` stays visible
where it coincides with ``exact_delay``; legends sit outside the axes.
"""

from __future__ import annotations

import math

import numpy as np

from .common import MODEL_ZORDER, figure_and_axes, model_label, model_style, outside_legend

__all__ = [
    "plot_critical_gain_vs_delay",
    "plot_kb_error_map",
    "plot_kb_error_maps",
    "plot_model_comparison",
]

_RATIO_LIMIT = 2.0
"""Colour scale of the error maps: log2(NV*_KB/NV*) clipped to ±2 (KB off by 4×)."""


def plot_critical_gain_vs_delay(curves, *, mark: float | None = None, mark_label: str = "CARMEL", ax=None, legend: bool = True):
    """NV* (1/s) against the sampling period T/τ for all models (KB eq 20: NV* = 1/(τ + T)).

    Parameters
    ----------
    curves : comparison.GainCurves
        `comparison.critical_gain_vs_delay` (τ and k are read from it).
    mark : float, optional
        A T/τ to mark with a vertical line (e.g. CARMEL's 0.065/0.3).
    mark_label : str
        Who is marked.
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, (8.6, 4.6) if legend else (6.4, 4.6))
    for c in curves:
        values = np.where(np.isfinite(c.NV_critical) & (c.NV_critical > 0), c.NV_critical, np.nan)
        ax.plot(c.x, values, label=model_label(c.model), zorder=MODEL_ZORDER[c.model.name], **model_style(c.model))
    if mark is not None:
        ax.axvline(mark, color="k", lw=0.9, ls=":")
        ax.annotate(f"{mark_label}: T/τ = {mark:.3g}", (mark, 0.02), xycoords=("data", "axes fraction"), xytext=(4, 0), textcoords="offset points", fontsize=8)
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("sampling period T/τ (dimensionless)")
    ax.set_ylabel("critical NV* (1/s)")
    tau, k = curves[0].tau, curves[0].k
    ax.set_title(f"Critical gain vs sampling period: τ = {tau:g} s, k = {k:g} 1/s\nKB eq (20): NV* = 1/(τ + T)", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    if legend:
        outside_legend(ax)
    return fig


def _percent(r: float) -> str:
    return "0" if abs(r) < 1e-12 else f"{100 * r:+.0f} %"


def plot_kb_error_map(error_map, ax=None, *, mark: tuple[float, float] | None = None, mark_label: str = "CARMEL", colorbar: bool = True):
    """Where KB's criterion is optimistic (red) or conservative (blue) against one model.

    Colour: log2(NV*_KB/NV*_model), clipped to ±2; contours at 0 (KB exact),
    ±10 % and ±50 %; hatched where the model is unstable for every NV (the
    sampled steering loop alone is unstable, kT too large).

    Parameters
    ----------
    error_map : comparison.KBErrorMap
        From `comparison.kb_error_map`.
    ax : matplotlib Axes, optional
    mark : (k_tau, T_over_tau), optional
        A robot to mark, with its exact relative error.
    mark_label : str, optional
        Who is marked.
    colorbar : bool

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import TwoSlopeNorm

    fig, ax = figure_and_axes(ax, (6.0, 4.8))
    x, y = error_map.k_tau, error_map.T_over_tau
    ratio = error_map.relative_error + 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        level = np.log2(np.where(np.isfinite(ratio), ratio, np.nan))
    norm = TwoSlopeNorm(vmin=-_RATIO_LIMIT, vcenter=0.0, vmax=_RATIO_LIMIT)
    dead = ~np.isfinite(error_map.relative_error)
    # the model's NV*τ falls continuously to 0 at the edge of the hatched region: fill up to that edge
    filled = np.where(dead, _RATIO_LIMIT, np.clip(level, -_RATIO_LIMIT, _RATIO_LIMIT))
    mesh = ax.contourf(x, y, filled, levels=np.linspace(-_RATIO_LIMIT, _RATIO_LIMIT, 33), cmap="RdBu_r", norm=norm, extend="both")
    if dead.any():
        edge = error_map.NV_tau_reference
        ax.contourf(x, y, edge, levels=[-1.0, 1e-12], colors="white", hatches=["xx"])
        ax.contour(x, y, edge, levels=[1e-12], colors="0.3", linewidths=0.8)
    errors = (-0.5, -0.1, 0.1, 0.5)
    present = [e for e in errors if np.nanmin(level) < math.log2(1 + e) < np.nanmax(level)]
    if present:
        cs = ax.contour(x, y, level, levels=[math.log2(1 + e) for e in present], colors="0.25", linewidths=0.7, linestyles=":")
        ax.clabel(cs, fmt={math.log2(1 + e): _percent(e) for e in present}, fontsize=7)
    if np.nanmin(level) < 0 < np.nanmax(level):
        ax.contour(x, y, level, levels=[0.0], colors="k", linewidths=1.6)
    if mark is not None:
        kt, tt = mark
        err = error_map.exact(kt, tt)
        ax.plot([kt], [tt], marker="*", ms=15, mfc="gold", mec="k", ls="none", zorder=6)
        ax.annotate(f"{mark_label}: {_percent(err)}", (kt, tt), xytext=(7, 5), textcoords="offset points", fontsize=8,
                    bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.85))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("steering gain kτ (dimensionless)")
    ax.set_ylabel("sampling period T/τ (dimensionless)")
    ax.set_title(f"KB eq (20) vs {model_label(error_map.reference)}", fontsize=9)
    if colorbar:
        _colorbar(fig, mesh, ax)
    return fig


def _colorbar(fig, mesh, ax):
    """Colour bar in percent; `mesh` None: a mappable with the maps' common norm."""
    if mesh is None:
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import TwoSlopeNorm

        mesh = ScalarMappable(norm=TwoSlopeNorm(vmin=-_RATIO_LIMIT, vcenter=0.0, vmax=_RATIO_LIMIT), cmap="RdBu_r")
    ticks = np.arange(-_RATIO_LIMIT, _RATIO_LIMIT + 0.5, 1.0)
    cb = fig.colorbar(mesh, ax=ax, ticks=ticks, shrink=0.85)
    cb.ax.set_yticklabels([_percent(2.0**t - 1.0) for t in ticks])
    cb.set_label("NV*_KB / NV*_model − 1\nred: KB optimistic (misses oscillation), blue: KB conservative", fontsize=8)
    return cb


def plot_kb_error_maps(maps, *, mark: tuple[float, float] | None = None, mark_label: str = "CARMEL", ncols: int = 3):
    """One `plot_kb_error_map` per reference model, one colour bar; hatched: the model is never stable.

    Parameters
    ----------
    maps : sequence of KBErrorMap
        One map per reference model (`comparison.kb_error_maps`).
    mark : (float, float), optional
        An operating point (kτ, T/τ) to mark.
    mark_label : str, optional
        Who is marked.
    ncols : int, optional
        Panels per row.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    from matplotlib.lines import Line2D

    cols = min(ncols, len(maps))
    rows = math.ceil(len(maps) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.3 * cols + 1.3, 3.8 * rows + 1.0), layout="constrained", squeeze=False)
    axes = axes.ravel()
    for ax, m in zip(axes, maps):
        plot_kb_error_map(m, ax=ax, mark=mark, mark_label=mark_label, colorbar=False)
    for ax in axes[len(maps):]:
        ax.axis("off")
    if len(axes) > len(maps):
        axes[len(maps)].text(
            0.02, 0.5,
            "How to read a map\n\n"
            "KB's eq (20) allows NV up to NV*_KB = 1/(τ + T).\n"
            "Red: NV*_KB > NV*_model — KB calls stable a loop\n"
            "that oscillates (optimistic).\n"
            "Blue: NV*_KB < NV*_model — KB is conservative.\n\n"
            "NV*τ depends on kτ and T/τ only, so each map\n"
            "holds for every robot; the star's value is exact.",
            transform=axes[len(maps)].transAxes, va="center", fontsize=9,
        )
    _colorbar(fig, None, list(axes[: len(maps)]))
    handles = [
        Line2D([], [], color="k", lw=1.6),
        Line2D([], [], color="0.25", lw=0.7, ls=":"),
        Patch(fc="white", ec="0.3", hatch="xx"),
        Line2D([], [], marker="*", ms=12, mfc="gold", mec="k", ls="none"),
    ]
    labels = ["KB exact (NV*_KB = NV*_model)", "KB off by ±10 %, ±50 %", "model unstable for every NV (steering loop alone)", f"{mark_label} (exact value)"]
    fig.legend(handles, labels, loc="outside lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle("Where KB's criterion NV(τ + T) < 1 is optimistic (red) or conservative (blue): NV*τ depends on kτ and T/τ only", fontsize=10)
    return fig


def plot_model_comparison(by_k, by_delay):
    """NV* versus k and versus T/τ for all models, side by side, the operating point marked, one legend below.

    Parameters
    ----------
    by_k : comparison.GainCurves
        `comparison.critical_gain_vs_k` at the robot's τ and T (the left panel).
    by_delay : comparison.GainCurves
        `comparison.critical_gain_vs_delay` at the robot's τ and k (the right panel).
        The operating point is k (the right panel's) on the left, T/τ (the left panel's) on the right.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    from .rlocus import plot_critical_gain_vs_k

    k, T, tau = by_delay[0].k, by_k[0].T, by_k[0].tau
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5.4), layout="constrained")
    plot_critical_gain_vs_k(by_k, ax=a, legend=False)
    a.axvline(k, color="k", lw=0.9, ls=":")
    a.annotate(f"k = {k:g} 1/s", (k, 0.02), xycoords=("data", "axes fraction"), xytext=(4, 0), textcoords="offset points", fontsize=8)
    plot_critical_gain_vs_delay(by_delay, mark=T / tau, ax=b, legend=False)
    fig.legend(*a.get_legend_handles_labels(), loc="outside lower center", ncol=4, fontsize=8, frameon=False)
    return fig
