"""Helpers shared by the experiment scripts: output folder, JSON, figures, command line.

Every experiment script has ``run(out, quick=False) -> dict`` (writes its PNG
and JSON into `out` and returns the JSON content, including ``rows`` for the
results table of ``experiments/README.md``) and ``main(argv=None)``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

__all__ = ["output_dir", "write_json", "save_figure", "parse_args", "row", "jsonable", "run_summary", "script_main", "boundary_row"]

HERE = Path(__file__).resolve().parent
DEFAULT_OUT = HERE / "results"


def output_dir(out) -> Path:
    """The output folder as a Path, created if missing."""
    path = Path(out)
    path.mkdir(parents=True, exist_ok=True)
    return path


def jsonable(value):
    """Plain JSON: numpy scalars → Python, non-finite floats → None, tuples → lists."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path: Path, data: dict) -> Path:
    path.write_text(json.dumps(jsonable(data), indent=2, allow_nan=False) + "\n")
    return path


def save_figure(fig, path: Path, dpi: int = 110) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def parse_args(description: str, argv=None):
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", default=str(DEFAULT_OUT), help="output folder (default: experiments/results)")
    parser.add_argument("--quick", action="store_true", help="reduced run for CI smoke tests")
    return parser.parse_args(argv)


def row(experiment: str, quantity: str, kb: str, predicted: str, simulated: str, note: str = "") -> dict:
    """One line of the README results table."""
    return {"experiment": experiment, "quantity": quantity, "kb": kb, "predicted": predicted, "simulated": simulated, "note": note}


def boundary_row(experiment: str, quantity: str, kb: str, v, digits: int, simulated: str) -> dict:
    """Results row of a grid boundary validation `v` (`validate_boundary`): the
    sampled, kb_first_order (grid law and KB's lumped law) and exact_delay
    predictions, and their relative errors; values shown with `digits` decimals."""
    p, lumped = v.predicted_boundary, v.lumped_predicted_boundary
    e = v.relative_error
    return row(
        experiment, quantity, kb,
        f"sampled {p['sampled']:.{digits}f}; kb_first_order {p['kb_first_order']:.{digits}f} "
        f"(grid law), {lumped['kb_first_order']:.{digits}f} (lumped f_av = 0.8); exact_delay {p['exact_delay']:.{digits}f}",
        simulated,
        f"sampled {100 * e['sampled']:+.2f} %, kb_first_order {100 * e['kb_first_order']:+.1f} % "
        f"(lumped {100 * v.lumped_relative_error['kb_first_order']:+.1f} %)",
    )


def share_limits(axes, runs) -> None:
    """Give trajectory panels one scale, and draw every grid cell inside the common limits.

    `plot_trajectory` draws only the cells near its own path; with a shared
    scale the walls would seem to stop where a short run ended.
    """
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    limits = [ax.get_xlim() + ax.get_ylim() for ax in axes]
    x0, x1 = min(l[0] for l in limits), max(l[1] for l in limits)
    y0, y1 = min(l[2] for l in limits), max(l[3] for l in limits)
    for ax, run in zip(axes, runs):
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        if run.scenario.env != "grid":
            continue
        grid = run.scenario.environment
        ox, oy, _ = grid.occupied()
        c = grid.cell_size
        keep = (ox > x0 - c) & (ox < x1 + c) & (oy > y0 - c) & (oy < y1 + c)
        cells = [Rectangle((x - c / 2, y - c / 2), c, c) for x, y in zip(ox[keep], oy[keep])]
        ax.add_collection(PatchCollection(cells, facecolor="0.15", edgecolor="none"))


def run_summary(run, prediction, key: str) -> dict:
    """JSON summary of one simulated run beside its prediction (`pfm_stability.validation.predict`).

    ``key`` names the varied quantity (``"L"`` in m, ``"alpha_deg"``), whose
    value is the prediction's.
    """
    m = run.metrics
    e = run.events[0] if run.events else None
    return {
        key: prediction.value,
        "event": e.type if e else None,
        "t_event": e.t if e else None,
        "collided": run.collided,
        "measured": {
            "growth_rate": m.growth_rate, "angular_frequency": m.angular_frequency, "oscillating": m.oscillating,
            "stable": m.stable, "method": m.method, "turning_points": m.turning_points, "reason": m.reason,
        },
        "predicted": prediction.to_dict(),
    }


def script_main(run, doc: str, argv=None) -> int:
    """Command line of an experiment script: ``--out DIR [--quick]``; prints the finding."""
    args = parse_args(doc.splitlines()[0], argv)
    result = run(args.out, quick=args.quick)
    print(result["finding"])
    return 0

