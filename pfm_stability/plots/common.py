"""Shared plot helpers: axes creation and the model palette (names as in DESIGN §4)."""

from __future__ import annotations

__all__ = ["figure_and_axes", "MODEL_STYLE", "model_label", "model_style"]

MODEL_STYLE = {
    "continuous": dict(color="#7f7f7f", ls=":", lw=1.8),
    "kb_first_order": dict(color="#d62728", ls="--", lw=1.8),
    "pade": dict(color="#9467bd", ls="-.", lw=1.6),
    "exact_delay": dict(color="#1f77b4", ls="-", lw=2.0),
    "sampled": dict(color="#2ca02c", ls="-", lw=2.2),
}
"""Line style per model, used by every plot so a model looks the same everywhere."""


def model_label(model) -> str:
    """Legend text: the DESIGN §4 name plus its options (``sampled (command, cd=1)``)."""
    name = model.name
    if name == "pade":
        return f"pade (m={model.order})"
    if name == "sampled":
        return f"sampled ({model.hold}, cd={model.compute_delay})"
    return name


def model_style(model) -> dict:
    """Line style of `model`: `MODEL_STYLE`, the four sampled structures told
    apart (command solid, reference dashed; compute delay 1 thinner)."""
    style = dict(MODEL_STYLE[model.name])
    if model.name == "sampled":
        style["ls"] = "-" if model.hold == "command" else "--"
        style["lw"] = 2.4 if model.compute_delay == 0 else 1.4
        style["alpha"] = 1.0 if model.compute_delay == 0 else 0.7
    return style


def figure_and_axes(ax=None, size=(6.0, 4.5)):
    """(figure, axes): the given axes' figure, or a new constrained-layout figure."""
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax.figure, ax
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    return fig, ax
