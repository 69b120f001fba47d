"""Shared plot helpers: axes creation, the model palette and the model labels (names as in `pfm_stability.models`)."""

from __future__ import annotations

__all__ = ["figure_and_axes", "MODEL_STYLE", "MODEL_ZORDER", "model_label", "model_description", "model_style", "outside_legend"]

MODEL_STYLE = {
    "continuous": dict(color="#7f7f7f", ls=":", lw=1.8),
    "kb_first_order": dict(color="#d62728", ls="--", lw=1.8),
    "pade": dict(color="#9467bd", ls="-.", lw=1.6),
    "exact_delay": dict(color="#1f77b4", ls="-", lw=2.6),
    "sampled": dict(color="#2ca02c", ls="-", lw=2.2),
}
"""Line style per model, used by every plot so a model looks the same everywhere."""

MODEL_ZORDER = {
    "sampled": 3.0,
    "exact_delay": 3.1,
    "continuous": 3.2,
    "kb_first_order": 3.3,
    "pade": 3.4,
}
"""Drawing order of the model lines: the broken (dashed, dotted) lines above the
solid ones, so that ``pade`` stays visible where it coincides with ``exact_delay``
(a Padé(3) delay gives nearly the exact NV* when T ≪ τ) and ``kb_first_order``
where it is close to both."""


def _with_options(model, formats: dict) -> str:
    """``name (…)``: the first of `formats` (option → template) whose option the model has; the name alone if none."""
    options = model.options()
    for option, template in formats.items():
        if option in options:
            return f"{model.name} ({template.format(**options)})"
    return model.name


def model_label(model) -> str:
    """Legend text: the model name plus its options (`LoopModel.options`): ``sampled (command, cd=1)``, ``pade (m=3)``.

    Parameters
    ----------
    model : LoopModel
        The model.
    """
    return _with_options(model, {"order": "m={order}", "hold": "{hold}, cd={compute_delay}"})


def model_description(model) -> str:
    """Longer text for titles and captions: ``sampled (command hold, compute delay 1)``, ``pade (order 3)``.

    Parameters
    ----------
    model : LoopModel
        The model.
    """
    return _with_options(model, {"order": "order {order}", "hold": "{hold} hold, compute delay {compute_delay}"})


def model_style(model) -> dict:
    """Line style of `model`: `MODEL_STYLE`, the four sampled structures told
    apart (command solid, reference dashed; compute delay 1 thinner).

    Parameters
    ----------
    model : LoopModel
        The model.
    """
    style = dict(MODEL_STYLE[model.name])
    options = model.options()
    if "hold" in options:
        style["ls"] = "-" if options["hold"] == "command" else "--"
        style["lw"] = 2.4 if options["compute_delay"] == 0 else 1.4
        style["alpha"] = 1.0 if options["compute_delay"] == 0 else 0.7
    return style


def figure_and_axes(ax=None, size=(6.0, 4.5)):
    """(figure, axes): the given axes' figure, or a new constrained-layout figure.

    Parameters
    ----------
    ax : matplotlib Axes, optional
        Axes to draw on; None: a new figure.
    size : (float, float), optional
        Size of a new figure, inches.
    """
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax.figure, ax
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    return fig, ax


def outside_legend(ax, handles=None, labels=None, *, fontsize=7, **kwargs):
    """Legend to the right of the axes, outside them: it can hide no curve, marker or arrow.

    Constrained layout (`figure_and_axes`) shrinks the axes to make room.

    Parameters
    ----------
    ax : matplotlib Axes
    handles, labels : list, optional
        Default: the axes' labelled artists.
    fontsize : float
        Points.
    **kwargs
        Passed to ``ax.legend``.

    Returns
    -------
    matplotlib.legend.Legend
    """
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    options = dict(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=fontsize, framealpha=0.9)
    options.update(kwargs)
    return ax.legend(handles, labels, **options)
