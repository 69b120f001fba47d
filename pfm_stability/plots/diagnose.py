"""The picture of ``pfm-stability diagnose``: where the robot drove, the walls it saw, and its lateral offset against the prediction.

Left: the odometry's path (m, equal axes), each stretch's walls drawn along it (solid: judged; dashed: not
judged) and its number. Right: the lateral offset of every stretch over time (m), its span shaded (red:
oscillating, green: stable, grey: not judged), and the predicted envelope ±a0·e^(σ(t − t0)) of the matching
model (else ``sampled``) from the first measured swing. Drawing only: it takes a `validation.diagnose.Diagnosis`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["plot_diagnosis"]

_COLOURS = {"oscillating": "tab:red", "stable": "tab:green", None: "0.6"}


def _state(s) -> str | None:
    if not s.judged:
        return None
    return "stable" if s.measured.stable else "oscillating"


def plot_diagnosis(diagnosis, path=None, *, size=(12.0, 4.8)):
    """Draw `diagnosis` (module docstring); save it to `path` (PNG) if given.

    Parameters
    ----------
    diagnosis : validation.diagnose.Diagnosis
        What to draw.
    path : str, optional
        Where to save the figure (`io.files.save_figure`); None: return it open.
    size : tuple of float
        Figure size, inches.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib

    if path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, (top, lateral) = plt.subplots(1, 2, figsize=size, gridspec_kw={"width_ratios": [1, 1.4]})
    pose = diagnosis.pose
    top.plot(pose.x, pose.y, color="0.3", lw=0.8, label="odometry path")
    top.plot(pose.x[:1], pose.y[:1], "o", color="0.3", ms=4)
    for s in diagnosis.stretches:
        st = s.stretch
        inside = (pose.t >= st.start) & (pose.t <= st.end)
        if not inside.any():
            continue
        xs, ys = pose.x[inside], pose.y[inside]
        colour = _COLOURS[_state(s)]
        for wall in (st.left, st.right):
            if wall is None:
                continue
            n = np.array([math.cos(wall.normal), math.sin(wall.normal)])
            along = np.array([-n[1], n[0]])
            s_along = xs * along[0] + ys * along[1]
            ends = np.array([s_along.min(), s_along.max()])
            px, py = along[0] * ends + n[0] * wall.offset, along[1] * ends + n[1] * wall.offset
            top.plot(px, py, color=colour, lw=2.5, ls="-" if s.judged else "--", solid_capstyle="butt")
        top.annotate(str(st.index), (xs[xs.size // 2], ys[ys.size // 2]), fontsize=8, color=colour,
                     xytext=(4, 4), textcoords="offset points")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m, odometry frame)")
    top.set_ylabel("y (m)")
    top.set_title("path and walls seen", fontsize=10)

    for s in diagnosis.stretches:
        st = s.stretch
        colour = _COLOURS[_state(s)]
        lateral.axvspan(st.start, st.end, color=colour, alpha=0.12, lw=0)
        label = f"{st.index}: {st.kind}" + ("" if s.judged else " (not judged)")
        if s.offset is not None:
            lateral.plot(s.offset.t, s.offset.offset, color=colour, lw=1.0, label=label)
        model = s.predicted.get(s.matching or "sampled") if s.predicted else None
        if s.judged and model is not None and model.sigma is not None and s.envelope is not None:
            t0, a0 = s.envelope
            t = np.linspace(st.start, st.end, 200)
            envelope = a0 * np.exp(np.clip(model.sigma * (t - t0), -50, 50))
            lateral.plot(t, envelope, color="k", lw=0.9, ls="--")
            lateral.plot(t, -envelope, color="k", lw=0.9, ls="--",
                         label=f"predicted envelope ({model.model})")
    offsets = [np.max(np.abs(s.offset.offset)) for s in diagnosis.stretches if s.offset is not None]
    if offsets:
        reach = 1.6 * float(max(offsets))
        lateral.set_ylim(-reach, reach)  # an envelope growing past the measured swings leaves the frame
    handles, labels = lateral.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    if unique:
        lateral.legend(unique.values(), unique.keys(), fontsize=7, loc="upper left")
    lateral.axhline(0.0, color="0.5", lw=0.5)
    lateral.set_xlabel("time (s since the log's start)")
    lateral.set_ylabel("lateral offset (m)")
    lateral.set_title(f"{diagnosis.verdict}: measured offset and predicted envelope", fontsize=10)
    fig.tight_layout()
    if path is not None:
        from ..io.files import save_figure

        save_figure(fig, path, what="diagnosis figure")
    return fig
