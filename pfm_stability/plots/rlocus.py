"""Root locus of the Padé loop and the critical gain versus k for every model.

KB (Koren & Borenstein 1991) conclude from eq (20) that stability does not
depend on the steering gain k. `plot_critical_gain_vs_k` shows NV* against k
for every model: flat only for `continuous` and `kb_first_order`.
`plot_root_locus` draws the closed-loop roots of the Padé(m) form of eq (18)
as NV grows (`comparison.root_locus`: python-control's ``root_locus_map``), with the imaginary-axis
crossings of the `pade`, `exact_delay`, `sampled` and `kb_first_order`
models marked; a model without a marker (NV* = 0 or infinite, or a crossing
outside the view) says why in the legend. Legends sit outside the axes.
"""

from __future__ import annotations

import math

import numpy as np

from .common import MODEL_STYLE, MODEL_ZORDER, figure_and_axes, model_label, model_style, outside_legend

__all__ = ["plot_root_locus", "plot_critical_gain_vs_k", "crossing_text"]


_MARKER_SIZE = {"pade": 13, "exact_delay": 10.5, "kb_first_order": 8, "sampled": 5.5}
"""Concentric markers: where crossings coincide (pade and exact_delay, often kb_first_order) every ring shows."""


def _intervals_text(stable_set) -> str:
    return " ∪ ".join(f"({lo:.4g}, {hi:.4g})" for lo, hi in stable_set)


def crossing_text(model, boundary, omega_max: float | None = None) -> tuple[str, bool]:
    """Legend text for a model's imaginary-axis crossing, and whether a marker is drawn.

    Parameters
    ----------
    model : LoopModel
    boundary : Boundary
        ``model.boundary(loop)``.
    omega_max : float, optional
        Largest |ω| in view, rad/s; a crossing beyond it gets no marker.

    Returns
    -------
    text : str
        ``pade (m=3): NV* = 2.768 1/s, ω* = 2.34 rad/s``, or why there is no
        marker: ``sampled (command, cd=0): unstable at any NV (NV* = 0; no
        marker)``, ``…: stable at every NV (NV* = ∞; no marker)``, ``…
        (outside the view: no marker)``. Stable intervals other than
        (0, NV*) are listed.
    marker : bool
        True when the crossing ±jω* is drawn.
    """
    label = model_label(model)
    NV, w = boundary.NV_critical, boundary.omega_critical
    stable_set = tuple(boundary.stable_set)
    others = [iv for iv in stable_set if not (iv[0] == 0.0 and iv[1] == NV)]
    extra = f";\nalso stable for NV in {_intervals_text(others)} 1/s" if others else ""
    if NV == 0:
        if others:
            return f"{label}: NV* = 0, stable only for NV in {_intervals_text(others)} 1/s (no marker)", False
        return f"{label}: unstable at any NV (NV* = 0; no marker)", False
    if math.isinf(NV):
        return f"{label}: stable at every NV (NV* = ∞; no marker)", False
    if w is None:
        return f"{label}: NV* = {NV:.4g} 1/s, no crossing frequency (no marker){extra}", False
    text = f"{label}: NV* = {NV:.4g} 1/s, ω* = {w:.3g} rad/s"
    if omega_max is not None and abs(w) > omega_max:
        return f"{text} (outside the view: no marker){extra}", False
    return text + extra, True


def plot_root_locus(locus, ax=None):
    """Root locus of the Padé(m) loop in NV with the critical crossings marked.

    Markers (concentric rings where they coincide): the Padé locus crossing
    at ±jω*; `exact_delay`'s ±jω* (KB eq 18 solved exactly); `sampled`'s
    boundary pole s = ln z/T on the axis (filled); KB's eq (19) crossing
    ±j√(k/(τ+T)). The legend, outside the axes, gives each model's NV* and
    ω*, or says why a model has no marker (unstable at any NV, stable at
    every NV, or a crossing outside the view; `crossing_text`).

    Parameters
    ----------
    locus : comparison.RootLocus
        `comparison.root_locus` (also ``RootLocus.plot()``).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    loop, poles, zeros = locus.loop, locus.poles, locus.zeros
    fig, ax = figure_and_axes(ax, (10.0, 5.4))
    for branch in locus.loci.T:
        ax.plot(branch.real, branch.imag, color="0.35", lw=1.1)
    w_star = locus.omega_scale
    omega_max = 2.5 * w_star
    ax.plot(poles.real, poles.imag, "x", color="k", ms=8, mew=1.6, label="open-loop poles (Padé loop)")
    if zeros.size:
        in_view = (zeros.real >= -4 * w_star) & (zeros.real <= 1.5 * w_star) & (np.abs(zeros.imag) <= omega_max)
        where = "" if in_view.all() else (" — outside the view" if not in_view.any() else f" — {np.count_nonzero(~in_view)} outside the view")
        ax.plot(zeros.real, zeros.imag, "o", mfc="none", color="k", ms=7, label=f"open-loop zeros (Padé numerator{where})")
    for model, boundary in locus.crossings:
        text, marked = crossing_text(model, boundary, omega_max)
        color = MODEL_STYLE[model.name]["color"]
        filled = model.name == "sampled"
        style = dict(ls="none", marker="o", ms=_MARKER_SIZE[model.name], mfc=color if filled else "none", mec=color, mew=2,
                     zorder=MODEL_ZORDER[model.name] + 2)
        if marked:
            w = boundary.omega_critical
            ax.plot([0, 0], [w, -w], label=text, **style)
        else:  # legend entry only: a faded marker that is drawn nowhere
            ax.plot([], [], label=text, alpha=0.35, **style)
    ax.axvline(0, color="k", lw=0.8)
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlim(-4 * w_star, 1.5 * w_star)
    ax.set_ylim(-omega_max, omega_max)
    ax.set_xlabel("Re s (1/s)")
    ax.set_ylabel("Im s (rad/s)")
    plant = (f", g = {loop.plant_gain:g}" if loop.plant_gain != 1.0 else "") + (f", D = {loop.dead_time:g} s" if loop.dead_time > 0 else "")
    ax.set_title(f"Root locus in NV, Padé({locus.pade_order}) of KB eq (18): τ = {loop.tau:g} s, T = {loop.T:g} s, k = {loop.k:g} 1/s{plant}",
                 fontsize=9)
    outside_legend(ax)
    ax.grid(alpha=0.3)
    return fig


def plot_critical_gain_vs_k(curves, ax=None, *, legend: bool = True):
    """NV* against k for all models: the k-dependence that KB's eq (20) hides.

    Parameters
    ----------
    curves : comparison.GainCurves
        `comparison.critical_gain_vs_k` (τ and T are read from it; also its ``.plot()``).
    ax : matplotlib Axes, optional
    legend : bool
        Draw the legend outside the axes, on the right.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, (8.6, 4.6) if legend else (6.4, 4.6))
    tau, T = curves[0].tau, curves[0].T
    for curve in curves:
        shown = np.where(np.isfinite(curve.NV_critical) & (curve.NV_critical > 0), curve.NV_critical, np.nan)
        ax.plot(curve.x, shown, label=model_label(curve.model), zorder=MODEL_ZORDER[curve.model.name], **model_style(curve.model))
    ax.set_xscale("log")
    ax.set_xlabel("steering gain k (1/s)")
    ax.set_ylabel("critical NV* (1/s)")
    ax.set_title(f"Critical gain vs k: τ = {tau:g} s, T = {T:g} s (KB eq 20 says no dependence)", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    if legend:
        outside_legend(ax)
    if not math.isnan(np.nanmax([np.nanmax(np.where(np.isfinite(c.NV_critical), c.NV_critical, np.nan)) for c in curves])):
        ax.set_ylim(bottom=0)
    return fig
