"""Pictures of the validation: simulated verdicts over every model's boundary, and the random sweep.

`plot_boundary_overlay` draws a `BoundaryValidation`'s stability map: each
model's boundary curve (critical L, α, V or f against V, or against the
geometry when V is bisected; KB eq 20, 24, 25 generalized, docs/models.md) with
the simulated runs marked stable (○) or unstable (×) and the bisected
boundary (★). `plot_growth_rate` shows the measured σ against the bisected
parameter with every model's predicted boundary as a vertical line.
`plot_relative_errors` compares every model's error over many validations.
`plot_sweep` shows the random sweep: measured σ against NV/NV* of the
``sampled`` model, and where ``kb_first_order`` and ``exact_delay`` put the
same points. `plot_simulated_boundary` draws a `SimulatedBoundary`'s bisected
points with their brackets (and, if asked, its model curves).

Drawing only: every number comes from the results
(`pfm_stability.validation`), which also carry the configured models whose
labels and styles the legends use.
"""

from __future__ import annotations

import math

import numpy as np

from .common import MODEL_STYLE, figure_and_axes, model_label, model_style

__all__ = ["plot_boundary_overlay", "plot_growth_rate", "plot_validation", "plot_sweep", "plot_relative_errors", "plot_simulated_boundary"]

_AXIS = {"L": "L, corridor half-width", "alpha": "α, wall angle", "V": "V, speed", "f": "f, force ratio"}


def _axis_label(name, unit):
    return f"{_AXIS.get(name, name)} ({unit})" if unit else _AXIS.get(name, name)


def _labels(result, names):
    """Legend label of each model name: the result's configured model's (pade order, sampled structure), else the name."""
    models = {m.name: m for m in result.models}
    return {name: model_label(models[name]) if name in models else name for name in names}


def _styles(result, names):
    models = {m.name: m for m in result.models}
    return {name: model_style(models[name]) if name in models else dict(MODEL_STYLE[name]) for name in names}


def _verdict_markers(ax, xs, ys, verdicts, size=36):
    xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
    stable = np.array([v == "stable" for v in verdicts], dtype=bool)
    if stable.any():
        ax.scatter(xs[stable], ys[stable], s=size, facecolors="none", edgecolors="#2ca02c", lw=1.2, label="simulated: stable", zorder=4)
    if (~stable).any():
        ax.scatter(xs[~stable], ys[~stable], s=size, marker="x", color="#d62728", lw=1.4, label="simulated: unstable", zorder=4)


def plot_boundary_overlay(validation, ax=None):
    """Every model's boundary curve with the simulated runs marked stable/unstable.

    Parameters
    ----------
    validation : BoundaryValidation
        With a `stability_map` (``validate_boundary(..., stability_map=(nx, ny))``);
        without one, `plot_growth_rate` is drawn instead.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    v = validation
    m = v.stability_map
    if m is None:
        return plot_growth_rate(v, ax=ax)
    fig, ax = figure_and_axes(ax, (6.4, 6.0))
    labels, styles = _labels(v, m.curves), _styles(v, m.curves)
    x = np.asarray(m.curve_x)
    for name, ys in m.curves.items():
        y = np.array([np.nan if y is None else y for y in ys], dtype=float)
        ax.plot(x, y, label=labels[name], **styles[name])
    if m.lumped_curves is not None:
        y = np.array([np.nan if y is None else y for y in m.lumped_curves["kb_first_order"]], dtype=float)
        ax.plot(x, y, color=MODEL_STYLE["kb_first_order"]["color"], ls=(0, (1, 2)), lw=1.4,
                label=f"kb_first_order, KB's lumped law (f_av = {v.inputs['f_av']:.3g})")
    _verdict_markers(ax, [p.x for p in m.points], [p.value for p in m.points], [p.verdict for p in m.points])
    ax.plot([m.nominal_x], [v.simulated_boundary], "*", color="k", ms=13, zorder=5,
            label=f"bisected boundary {v.simulated_boundary:.4g} {v.unit}".rstrip())
    ys = [p.value for p in m.points]
    pad = 0.06 * (max(ys) - min(ys))
    ax.set_ylim(min(ys) - pad, max(ys) + pad)
    ax.set_xlim(min(p.x for p in m.points) - 0.03 * np.ptp(x), max(p.x for p in m.points) + 0.03 * np.ptp(x))
    ax.set_xlabel(_axis_label(m.x_name, m.x_unit))
    ax.set_ylabel(_axis_label(m.y_name, m.y_unit))
    side = "above" if v.stable_above else "below"
    ax.set_title(f"{v.scenario} ({v.env}): stable {side} each curve\nlaw: {v.law}", fontsize=9)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, framealpha=0.85)
    ax.grid(True, lw=0.3, alpha=0.5)
    return fig


def plot_growth_rate(validation, ax=None):
    """Measured σ against the bisected parameter, with every model's predicted boundary.

    The bisection runs and the oscillation checks are marked stable/unstable;
    σ = 0 at the bisected boundary (★). Vertical lines: each model's
    prediction with the run's own law (the model styles of `plots.common`).

    Parameters
    ----------
    validation : Validation
        The simulated boundary and every model's.
    ax : matplotlib Axes, optional
        Axes to draw on; None: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    v = validation
    fig, ax = figure_and_axes(ax, (6.4, 5.6))
    labels, styles = _labels(v, v.predicted_boundary), _styles(v, v.predicted_boundary)
    pts = [p for p in v.points if p.growth_rate is not None]
    _verdict_markers(ax, [p.value for p in pts], [p.growth_rate for p in pts], [p.verdict for p in pts])
    checks = [c for c in v.oscillation if c.growth_rate is not None]
    if checks:
        ax.plot([c.value for c in checks], [c.predicted_growth_rate for c in checks], "s", mfc="none", color="#2ca02c",
                ms=9, label="sampled model's σ at the checks")
    values = [p.value for p in v.points]
    lo, hi = min(values), max(values)
    for name, value in v.predicted_boundary.items():
        if math.isfinite(value):
            ax.axvline(value, label=f"{labels[name]}: {value:.4g}", **styles[name])
            lo, hi = min(lo, value), max(hi, value)
    if v.lumped_predicted_boundary is not None and math.isfinite(v.lumped_predicted_boundary["kb_first_order"]):
        value = v.lumped_predicted_boundary["kb_first_order"]
        ax.axvline(value, color=MODEL_STYLE["kb_first_order"]["color"], ls=(0, (1, 2)), lw=1.4,
                   label=f"kb_first_order, KB's lumped law: {value:.4g}")
        lo, hi = min(lo, value), max(hi, value)
    ax.axhline(0.0, color="0.4", lw=0.8)
    ax.plot([v.simulated_boundary], [0.0], "*", color="k", ms=13, zorder=5, label=f"simulated: {v.simulated_boundary:.4g}")
    pad = 0.05 * (hi - lo)
    ax.set_xlim(lo - pad, hi + pad)
    ax.set_xlabel(_axis_label(v.parameter, v.unit))
    ax.set_ylabel("measured growth rate σ (1/s)")
    ax.set_title(f"{v.scenario} ({v.env}): growth rate of the bisection runs", fontsize=9)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, framealpha=0.85)
    ax.grid(True, lw=0.3, alpha=0.5)
    return fig


def plot_validation(validation):
    """Two panels: `plot_boundary_overlay` (when a map exists) and `plot_growth_rate`.

    Parameters
    ----------
    validation : Validation
        The simulated boundary and every model's.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    if validation.stability_map is None:
        return plot_growth_rate(validation)
    fig, (a, b) = plt.subplots(1, 2, figsize=(12.5, 6.2), layout="constrained")
    plot_boundary_overlay(validation, ax=a)
    plot_growth_rate(validation, ax=b)
    return fig


def plot_sweep(sweep, axes=None):
    """The random sweep: simulated σ against NV/NV* (``sampled``), and the other models' view of it.

    Left: measured σ against NV/NV* of the `sampled` model (log), corridor (●)
    and wall (▲), stable green / unstable red by the simulation; the excluded
    band shaded; disagreements ringed. Right: NV/NV* of ``kb_first_order``
    (KB eq 20) and ``exact_delay`` (eq 18) against the sampled one: points
    right of 1 and below 1 are robots those models call stable that oscillate.

    Parameters
    ----------
    sweep : SweepResult
    axes : (Axes, Axes), optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(12.5, 5.0), layout="constrained")
    else:
        fig = axes[0].figure
    a, b = axes
    pts = [p for p in sweep.points if math.isfinite(p.gain_ratio) and p.growth_rate is not None]
    for kind, marker in (("corridor", "o"), ("wall", "^")):
        for verdict, color in (("stable", "#2ca02c"), ("unstable", "#d62728")):
            sel = [p for p in pts if p.scenario == kind and p.simulated == verdict]
            if sel:
                a.scatter([p.gain_ratio for p in sel], [p.growth_rate for p in sel], marker=marker, s=16, color=color,
                          alpha=0.75, label=f"{kind}, simulated {verdict}")
    bad = [p for p in sweep.disagreements if math.isfinite(p.gain_ratio) and p.growth_rate is not None]
    if bad:
        a.scatter([p.gain_ratio for p in bad], [p.growth_rate for p in bad], s=110, facecolors="none", edgecolors="k",
                  label="disagrees with sampled")
    a.axvspan(1 - sweep.exclude, 1 + sweep.exclude, color="0.85", label=f"excluded (±{sweep.exclude:.0%} of NV*)")
    a.axvline(1.0, color="0.3", lw=0.8)
    a.axhline(0.0, color="0.3", lw=0.8)
    a.set_xscale("log")
    a.set_yscale("symlog", linthresh=0.05)
    a.set_xlabel("NV / NV* of the sampled model")
    a.set_ylabel("measured growth rate σ (1/s)")
    never = sum(1 for p in sweep.points if not math.isfinite(p.gain_ratio))
    a.set_title(
        f"{sweep.count} random sets ({sweep.env}, seed {sweep.seed}): sign of σ agrees with sampled on "
        f"{sweep.agreement:.1%} of {sweep.included}" + (f"\n({never} with NV* = 0, unstable at any NV, not drawn)" if never else ""),
        fontsize=9,
    )
    a.legend(fontsize=7, loc="upper left", framealpha=0.85)
    a.grid(True, lw=0.3, alpha=0.5)

    included = [p for p in sweep.points if not p.excluded and math.isfinite(p.gain_ratio)]
    for name, marker in (("kb_first_order", "o"), ("exact_delay", "s")):
        x = np.array([p.gain_ratio for p in included])
        y = np.array([p.NV / p.model_NV_critical[name] for p in included])
        wrong = np.array([(p.verdicts[name] == "stable") != (p.simulated == "stable") for p in included])
        style = MODEL_STYLE[name]
        b.scatter(x[~wrong], y[~wrong], marker=marker, s=14, facecolors="none", edgecolors=style["color"], alpha=0.5)
        b.scatter(x[wrong], y[wrong], marker=marker, s=22, color=style["color"],
                  label=f"{name}: wrong on {sweep.wrong_verdict_rate[name]:.1%} (filled)")
    b.axvline(1.0, color="0.3", lw=0.8)
    b.axhline(1.0, color="0.3", lw=0.8)
    b.set_xscale("log")
    b.set_yscale("log")
    b.text(0.98, 0.03, "model: stable\nrobot: oscillates", transform=b.transAxes, ha="right", va="bottom", fontsize=8, color="0.3")
    b.text(0.02, 0.97, "model: unstable\nrobot: stable", transform=b.transAxes, ha="left", va="top", fontsize=8, color="0.3")
    b.set_xlabel("NV / NV* of the sampled model (> 1: the simulated robot oscillates)")
    b.set_ylabel("NV / NV* of the model")
    b.set_title("verdicts of KB's eq (20) and the delay equation (18) for the sampled robot", fontsize=9)
    b.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, 0.88), framealpha=0.85)
    b.grid(True, lw=0.3, alpha=0.5)
    return fig


def plot_relative_errors(validations, labels=None, ax=None):
    """Each model's relative boundary error (predicted/simulated − 1) for several validations.

    Grouped bars, one group per validation, one bar per model (the model
    colours of `plots.common`); in the grid, KB's lumped-law ``kb_first_order`` is added as a
    hatched bar (KB eq 24/25 with f_av).

    Parameters
    ----------
    validations : sequence of BoundaryValidation
    labels : sequence of str, optional
        Group labels (default: scenario, env, parameter).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, (max(6.4, 1.2 * len(validations) + 2.0), 4.6))
    names = list(validations[0].predicted_boundary)
    width = 0.8 / (len(names) + 1)
    labels = labels or [f"{v.scenario} {v.parameter}\n({v.env})" for v in validations]
    for j, name in enumerate(names):
        errors = [100 * (v.relative_error[name] if v.relative_error[name] is not None else np.nan) for v in validations]
        ax.bar(np.arange(len(validations)) + (j - len(names) / 2) * width, errors, width, color=MODEL_STYLE[name]["color"], label=name)
    lumped = [100 * v.lumped_relative_error["kb_first_order"] if v.lumped_relative_error else np.nan for v in validations]
    if not np.all(np.isnan(lumped)):
        ax.bar(np.arange(len(validations)) + (len(names) / 2) * width, lumped, width, facecolor="white",
               edgecolor=MODEL_STYLE["kb_first_order"]["color"], hatch="///", label="kb_first_order, KB's lumped law")
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.set_xticks(np.arange(len(validations)))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylabel("predicted / simulated boundary − 1 (%)")
    ax.set_title("boundary error of each model against the simulated VFF robot", fontsize=9)
    ax.legend(fontsize=7, ncol=3, loc="best", framealpha=0.85)
    ax.grid(True, axis="y", lw=0.3, alpha=0.5)
    return fig


def plot_simulated_boundary(sim, ax=None, *, label: str | None = None, color="k", marker="o", curves: bool = False, **style):
    """Simulated boundary points (`validation.SimulatedBoundary`) with their bisection brackets.

    x = the values of ``sim.over``, y = the bisected ``sim.parameter``
    (angles drawn in degrees), so the points sit on `plots.regions.plot_corridor_region`
    (over L, bisected V) or `plots.regions.plot_wall_alpha_critical` (over V, bisected α).

    Parameters
    ----------
    sim : SimulatedBoundary
    ax : matplotlib Axes, optional
    label : str, optional
        Legend label of the points.
    color, marker
        Style of the points.
    curves : bool
        Also draw the model curves the result carries (``sim.curves``; KB's
        lumped law dotted in the grid), for a figure without region plots.
    **style
        More matplotlib style of the points.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax)
    sx = 180 / math.pi if sim.over == "alpha" else 1.0
    sy = 180 / math.pi if sim.parameter == "alpha" else 1.0
    if curves and sim.curves is not None:
        x = np.asarray(sim.curve_x, dtype=float) * sx
        labels, styles = _labels(sim, sim.curves), _styles(sim, sim.curves)
        for name, y in sim.curves.items():
            ax.plot(x, np.asarray(y, dtype=float) * sy, label=labels[name], **styles[name])
        if sim.lumped_curves is not None:
            ax.plot(x, np.asarray(sim.lumped_curves["kb_first_order"], dtype=float) * sy, color=MODEL_STYLE["kb_first_order"]["color"],
                    ls=(0, (1, 2)), lw=1.4, label="kb_first_order, KB's lumped law")
    x = sim.values * sx
    y = sim.critical * sy
    err = np.vstack([y - sim.lo * sy, sim.hi * sy - y])
    label = label if label is not None else f"simulated boundary ({sim.env}, {sim.scenario}; bisection on {sim.parameter})"
    ax.errorbar(x, y, yerr=err, ls="none", marker=marker, ms=7, mfc="white", mec=color, mew=1.8, ecolor=color, capsize=3, label=label, zorder=8, **style)
    return fig
