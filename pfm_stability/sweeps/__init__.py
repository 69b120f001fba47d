"""Parameter studies at scale: thousands to millions of points, every model's verdict, and the simulator's (docs/sweeps.md).

* `load_spec` / `spec_from_mapping` (module `spec`) — read and check a sweep
  specification (YAML) before any work: the fixed values (preset or config),
  the geometry, the law, the models, and a grid or a seeded sample;
* `points` — the points: a full factorial grid, or a Latin hypercube / Sobol
  sample (seeded; the draws of `scipy.stats.qmc`, `sampling`);
* `evaluate_chunk` (module `evaluate`) — one chunk of points → its columns:
  N and NV, every model's verdict, NV* and margin (`vectorized.loop_verdicts`)
  and, when asked, the simulator's σ and verdict (`validation.sweep.simulate_members`);
* `run_sweep` (module `engine`) — the chunks as Dask tasks, written as they
  finish, retried, resumable; local threads, local worker processes
  (simulation), or a running ``dask.distributed`` scheduler;
* `table` — Parquet parts, the output (Parquet or CSV) and its statistics;
* `summary_figure_data` (module `summary`) — the data of the summary figure
  (`pfm_stability.plots.sweep`).

Level 7, beside `validation`: it joins the vectorized predictions and,
when asked, simulations; it may import `validation`, never the other way.
CLI: ``pfm-stability sweep SPEC.yaml --out FILE.parquet``.
"""

from .engine import SweepError, SweepInterrupted, SweepSummary, run_sweep
from .evaluate import ChunkColumns, evaluate_chunk
from .spec import SweepSpec, load_spec, spec_from_mapping

__all__ = [
    "ChunkColumns",
    "SweepError",
    "SweepInterrupted",
    "SweepSpec",
    "SweepSummary",
    "evaluate_chunk",
    "load_spec",
    "run_sweep",
    "spec_from_mapping",
]
