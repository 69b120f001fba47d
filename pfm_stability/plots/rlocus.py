"""Root locus of the Padé loop and the critical gain versus k for every model.

KB (Koren & Borenstein 1991) conclude from eq (20) that stability does not
depend on the steering gain k. `plot_critical_gain_vs_k` shows NV* against k
for every model: flat only for `continuous` and `kb_first_order`.
`plot_root_locus` draws the closed-loop roots of the Padé(m) form of eq (18)
as NV grows (python-control's ``root_locus_map``), with the imaginary-axis
crossings of the `pade`, `exact_delay` and `sampled` models marked.
"""

from __future__ import annotations

import math

import numpy as np

from ..models import ExactDelay, KBFirstOrder, Loop, Pade, Sampled, make_models
from .common import MODEL_STYLE, figure_and_axes, model_label, model_style

__all__ = ["root_locus_data", "plot_root_locus", "critical_gain_vs_k", "plot_critical_gain_vs_k"]


def root_locus_data(loop: Loop, pade_order: int = 3, NV_max: float | None = None, points: int = 400):
    """Closed-loop roots of the Padé loop for NV in (0, NV_max].

    The loop transfer function in the gain NV is G(s) = k·P_m(s)/((τs³ + s² + ks)·Q_m(s))
    (KB eq 18 with e^(−sT) ≈ P_m/Q_m), computed by python-control's
    ``root_locus_map``.

    Returns
    -------
    gains : ndarray
        NV values, 1/s.
    loci : ndarray, complex, shape (len(gains), branches)
        Root positions, 1/s.
    open_loop : (poles, zeros)
    """
    import control

    d, e = Pade(pade_order).polynomials(loop)
    G = control.tf(loop.k * np.asarray(e), d)
    if NV_max is None:
        NV_max = 2.5 * ExactDelay().boundary(loop).NV_critical
    gains = np.linspace(0.0, NV_max, points)
    data = control.root_locus_map(G, gains=gains)
    return np.asarray(data.gains), np.asarray(data.loci), (np.asarray(G.poles()), np.asarray(G.zeros()))


def plot_root_locus(loop: Loop, *, pade_order: int = 3, hold: str = "command", compute_delay: int = 0, NV_max=None, ax=None):
    """Root locus of the Padé(m) loop in NV with the critical crossings marked.

    Markers: the Padé locus crossing at ±jω*; `exact_delay`'s ±jω* (KB eq 18
    solved exactly); `sampled`'s boundary pole s = ln z/T on the axis; KB's
    eq (19) crossing ±j√(k/(τ+T)). The legend gives each model's NV*.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, (6.4, 5.2))
    gains, loci, (poles, zeros) = root_locus_data(loop, pade_order, NV_max)
    for branch in loci.T:
        ax.plot(branch.real, branch.imag, color="0.35", lw=1.1)
    ax.plot(poles.real, poles.imag, "x", color="k", ms=8, mew=1.6, label="open-loop poles (Padé loop)")
    if zeros.size:
        ax.plot(zeros.real, zeros.imag, "o", mfc="none", color="k", ms=7, label="open-loop zeros (Padé numerator)")
    for model in (Pade(pade_order), ExactDelay(), Sampled(hold, compute_delay), KBFirstOrder()):
        b = model.boundary(loop)
        if b.omega_critical is None:
            continue
        style = MODEL_STYLE[model.name]
        w = b.omega_critical
        ax.plot([0, 0], [w, -w], ls="none", marker="o", ms=9 if model.name == "pade" else 7, mfc="none" if model.name != "sampled" else style["color"], mec=style["color"], mew=2, label=f"{model_label(model)}: NV* = {b.NV_critical:.4g} 1/s, ω* = {w:.3g} rad/s")
    ax.axvline(0, color="k", lw=0.8)
    ax.axhline(0, color="k", lw=0.5)
    w_star = ExactDelay().boundary(loop).omega_critical or 1.0
    ax.set_xlim(-4 * w_star, 1.5 * w_star)
    ax.set_ylim(-2.5 * w_star, 2.5 * w_star)
    ax.set_xlabel("Re s (1/s)")
    ax.set_ylabel("Im s (rad/s)")
    ax.set_title(f"Root locus in NV, Padé({pade_order}) of KB eq (18): τ = {loop.tau:g} s, T = {loop.T:g} s, k = {loop.k:g} 1/s", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(alpha=0.3)
    return fig


def critical_gain_vs_k(tau: float, T: float, ks, *, pade_order: int = 3, structures=(("command", 0), ("command", 1), ("reference", 0), ("reference", 1))):
    """NV* (1/s) of every model for each steering gain k (1/s).

    Returns
    -------
    dict
        Model label → ndarray of NV* (``inf`` where no finite boundary).
    """
    models = make_models(("continuous", "kb_first_order", "pade", "exact_delay"), pade_order=pade_order)
    models += [Sampled(h, c) for h, c in structures]
    return {model_label(m): np.array([m.boundary(Loop(tau, T, k)).NV_critical for k in ks]) for m in models}, models


def plot_critical_gain_vs_k(tau: float, T: float, ks=None, *, pade_order: int = 3, ax=None):
    """NV* against k for all models: the k-dependence that KB's eq (20) hides.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, (6.4, 4.6))
    ks = np.geomspace(0.2, 30, 60) if ks is None else np.asarray(ks, dtype=float)
    curves, models = critical_gain_vs_k(tau, T, ks, pade_order=pade_order)
    for model, (label, values) in zip(models, curves.items()):
        style = model_style(model)
        shown = np.where(np.isfinite(values) & (values > 0), values, np.nan)
        ax.plot(ks, shown, label=label, **style)
    ax.set_xscale("log")
    ax.set_xlabel("steering gain k (1/s)")
    ax.set_ylabel("critical NV* (1/s)")
    ax.set_title(f"Critical gain vs k: τ = {tau:g} s, T = {T:g} s (KB eq 20 says no dependence)", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    if not math.isnan(np.nanmax([np.nanmax(np.where(np.isfinite(v), v, np.nan)) for v in curves.values()])):
        ax.set_ylim(bottom=0)
    return fig
