"""``pfm-stability sweep``: every model's verdict (and the simulator's) over a grid or a sample of parameters (docs/sweeps.md).

    pfm-stability sweep SPEC.yaml --out FILE.parquet [--config FILE] [--scheduler tcp://HOST:PORT] [--workers N]
                        [--chunk-size N] [--resume] [--plot FILE.png] [--quiet] [--format text|json]

SPEC names the fixed values (``preset`` or ``config``; ``--config FILE``
replaces them), the geometry, the law, the models and the points (``grid``
or ``sample``); the robot's values come from it, not from options. The table (one row per point) goes to
``--out`` (Parquet, or CSV for ``.csv``); the summary (points, seconds,
points/s, each model's stable fraction, the models' pairwise agreement,
the simulator's agreement with each model, where the output went) to
stdout, as text or as JSON (`pfm_stability/schema/output.schema.json`,
command "sweep"). A bad spec, output path or scheduler exits with status 2
before any work; a chunk that fails after its retries exits with status 1,
naming it, and keeps the finished chunks for ``--resume`` (as Ctrl-C does,
status 130).
"""

from __future__ import annotations

import sys

from .options import describe, input_file, integer, output_path

FORMATS = ("text", "json")


def _scheduler(text: str) -> str:
    import argparse

    host = text[len("tcp://"):] if text.startswith("tcp://") else ""
    if not host or ":" not in host or not host.rsplit(":", 1)[1].isdigit():
        raise argparse.ArgumentTypeError(f"scheduler must be an address tcp://HOST:PORT; got {text!r}")
    return text


_scheduler.kind = "address"  # a tcp:// address, checked here and connected to before any work


def _out(text: str) -> str:
    return output_path("out", ".csv" if text.lower().endswith(".csv") else ".parquet")(text)


_out.__name__ = "out"
_out.kind, _out.suffix = "path", ".parquet"  # or .csv


def add_parser(sub) -> None:
    p = sub.add_parser(
        "sweep",
        help="parameter study: every model's verdict (and the simulator's) over a grid or a sample, to Parquet",
        description="Evaluate a sweep spec (docs/sweeps.md): a full factorial grid or a seeded Latin-hypercube/Sobol sample "
        "of V, tau, T, k, f, n, W, alpha or L and the law's parameters; every model's verdict, NV* and margin per point "
        "and, with simulate: true, the simulator's growth rate and verdict. Runs on local threads, local worker "
        "processes (simulation), or a running dask.distributed scheduler; resumable.",
    )
    p.add_argument("spec", metavar="SPEC", help="sweep spec, a YAML file (docs/sweeps.md)")
    p.add_argument("--config", type=input_file("config"), metavar="FILE",
                   help="robot, controller and law from this configuration file (docs/config.md), instead of the spec's "
                   "preset or config")
    p.add_argument("--out", required=True, type=_out, metavar="FILE",
                   help="output table: FILE.parquet, or FILE.csv (in an existing writable directory)")
    p.add_argument("--scheduler", type=_scheduler, metavar="tcp://HOST:PORT",
                   help="a running dask.distributed scheduler (its workers need this pfm-stability version)")
    p.add_argument("--workers", type=integer("workers"),
                   help=f"local threads, or worker processes when simulating, {describe('workers')} (default: the number of cores)")
    p.add_argument("--chunk-size", type=integer("chunk_size"),
                   help=f"points per task, {describe('chunk_size')} (default: without simulation the points shared over the workers, 10000 to 250000; with, 200, or 50 for env grid; "
                   "on --resume the interrupted run's)")
    p.add_argument("--resume", action="store_true", help="keep the finished chunks of an interrupted run of the same spec")
    p.add_argument("--plot", type=output_path("plot"), metavar="PNG",
                   help="summary figure: the verdict map over the two parameters that vary most, or the models' agreement")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--format", choices=FORMATS, default="text")
    p.set_defaults(run=run)


def _progress(quiet: bool):
    """``progress(points, total, chunks, total_chunks)`` drawing a tqdm bar on a terminal, else None; and its closer."""
    from .progress import stderr_is_terminal

    if quiet or not stderr_is_terminal():
        return None, lambda: None
    from tqdm import tqdm

    bars = []

    def update(points: int, total: int, chunks: int, total_chunks: int) -> None:
        if not bars:  # drawn at the first report, when the totals are known
            bars.append(tqdm(file=sys.stderr, dynamic_ncols=True, desc="sweep", unit="point", unit_scale=True, total=total))
        bars[0].set_postfix_str(f"chunks {chunks}/{total_chunks}", refresh=False)
        bars[0].update(points - bars[0].n)

    def close() -> None:
        for bar in bars:
            bar.close()

    return update, close


def run(args) -> int:
    from ..extras import require

    require("sweep", "pfm-stability sweep")
    from ..io.serialize import SCHEMA_VERSION, dumps
    from ..sweeps import SweepError, load_spec, run_sweep
    from .render import render_parameter_sweep_text

    spec = load_spec(args.spec, config=args.config)
    progress, close = _progress(args.quiet)
    try:
        summary = run_sweep(spec, args.out, scheduler=args.scheduler, workers=args.workers, chunk_size=args.chunk_size,
                            resume=args.resume, progress=progress)
    except SweepError as exc:
        close()
        print(f"pfm-stability: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        close()
        print(f"pfm-stability: interrupted; the finished chunks are in {args.out}.parts: rerun with --resume", file=sys.stderr)
        return 130
    close()
    if args.plot:
        _plot(summary, args.plot)
    if args.format == "json":
        print(dumps({"schema_version": SCHEMA_VERSION, "command": "sweep", **summary.to_dict(), "plot": args.plot}))
    else:
        print(render_parameter_sweep_text(summary, args.plot), end="")
    return 0


def _plot(summary, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")

    from ..plots.sweep import plot_sweep_summary
    from ..sweeps.summary import summary_figure_data

    from ..io.files import save_figure

    save_figure(plot_sweep_summary(summary_figure_data(summary)), path, dpi=110, what="plot")
