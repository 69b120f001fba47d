"""Run a sweep with Dask: chunks as tasks, each written as it finishes, resumable, retried (docs/sweeps.md, "Engine").

`run_sweep(spec, out)`:

1. checks the output path, draws a sample's points (a grid's chunks compute
   their own) and checks them, and connects to the scheduler — all before
   anything is written (an unreachable ``tcp://`` address is a ValueError);
2. splits the points into chunks of `chunk_size` consecutive indices and
   writes ``OUT.parts/manifest.json`` (the spec's digest, the chunk size, the
   number of points);
3. evaluates every chunk not already in ``OUT.parts`` as one Dask task
   (`evaluate.evaluate_chunk`) and writes ``OUT.parts/chunk-00012.parquet``
   as soon as it finishes (atomically: a temporary name, then a rename);
4. concatenates the parts in point order into ``OUT`` (atomically) and
   removes ``OUT.parts``.

Schedulers: without ``scheduler``, Dask's local scheduler on this machine:
``workers`` threads of this process without simulation (a vectorized sweep
is dominated by its arithmetic, which releases the GIL), ``workers`` worker
processes with ``simulate`` (the simulator holds the GIL); either way there
is no cluster to start and the chunks write their own parts. With
``scheduler="tcp://HOST:PORT"``, that ``dask.distributed`` cluster (its
workers need this version of pfm-stability): the workers return each
chunk's table and this process writes it, so the workers need no shared
file system.

Resume: with ``resume=True`` finished chunks whose manifest has this spec's
digest are kept (a different spec is a ValueError: nothing is overwritten);
without it a stale ``OUT.parts`` is removed first. A chunk that raises is
retried `RETRIES` times; if it still fails, `SweepError` names the chunk, its
points and the error, and the finished parts stay for ``--resume``.

Two hooks exist for tests of exactly these paths: ``stop_after_chunks=k``
(stop, as an interrupted run would, after k chunks are written:
`SweepInterrupted`) and ``fail_once=(i, …)`` (chunk i raises on its first
attempt; a marker file in ``OUT.parts`` makes that true across processes).
"""

from __future__ import annotations

import json
import os
import shutil
import threading
import time
from dataclasses import dataclass, field
from functools import partial

from ..checks import check_integer, check_output_path
from ..io.files import OutputError, write_text
from ..version import __version__
from .evaluate import evaluate_chunk
from .points import all_points, check_points, chunk_points, sobol_note
from .spec import SweepSpec
from .table import SweepStatistics, concatenate_parts, metadata, read_columns, statistics, to_arrow, write_part

__all__ = [
    "CONNECT_TIMEOUT",
    "RETRIES",
    "SIMULATION_CHUNK",
    "TAIL_CHUNKS",
    "VECTOR_CHUNK",
    "VECTOR_MIN_CHUNK",
    "SweepError",
    "SweepInterrupted",
    "SweepSummary",
    "check_output",
    "default_chunk_size",
    "parts_directory",
    "plan_chunks",
    "run_sweep",
]

RETRIES = 2
"""Retries of a failed chunk before the sweep fails."""

VECTOR_CHUNK = 250_000
"""Most points per chunk of a sweep without simulation by default (vectorized: large chunks, few tasks; `default_chunk_size`)."""

VECTOR_MIN_CHUNK = 10_000
"""Fewest points per chunk of a sweep without simulation by default (`default_chunk_size`)."""

SIMULATION_CHUNK = {"analytic": 200, "grid": 50}
"""Default points per chunk of a simulation sweep, per simulator environment: one batch each
(`validation.sweep.simulate_members` steps a chunk's members together, so larger chunks share the
per-step cost: a 2,000-point sweep took 30 s in chunks of 50 and 22 s in chunks of 200, one worker;
`benchmarks/bench_sweep.py`). The grid environment keeps 50: each member carries a histogram grid
(at 50 a worker already held 1.4 GB)."""

TAIL_CHUNKS = 2
"""A simulation sweep's last TAIL_CHUNKS·chunk_size points go in quarter-size chunks (`plan_chunks`)."""

CONNECT_TIMEOUT = 5.0
"""Seconds to wait for a ``tcp://`` scheduler before giving up (before any work)."""


class SweepError(RuntimeError):
    """A chunk failed after its retries; the finished parts are kept for ``resume``."""


class SweepInterrupted(RuntimeError):
    """The sweep stopped after ``stop_after_chunks`` chunks (a test hook that simulates an interruption)."""


@dataclass(frozen=True)
class SweepSummary:
    """What a finished sweep did and found.

    Attributes
    ----------
    out : str
        The output file (Parquet or CSV).
    format : {"parquet", "csv"}
    points : int
    chunks : int
    chunk_size : int
    reused_chunks : int
        Chunks taken from an earlier, interrupted run (``resume``).
    scheduler : str
        ``"threads (N)"``, ``"local processes (N)"`` or the address.
    statistics : SweepStatistics
    seconds : float
        Wall clock of `run_sweep`, s.
    notes : tuple of str
    spec : SweepSpec
    """

    out: str
    format: str
    points: int
    chunks: int
    chunk_size: int
    reused_chunks: int
    scheduler: str
    statistics: SweepStatistics
    seconds: float
    notes: tuple = ()
    spec: SweepSpec | None = field(default=None, repr=False)

    @property
    def rate(self) -> float:
        """Points per second (all points over the whole run, reused chunks included)."""
        return self.points / self.seconds if self.seconds > 0 else float("inf")

    def to_dict(self) -> dict:
        """Plain JSON form (`serialize.json_ready` numbers); wall-clock values under ``timing``."""
        from ..io.serialize import json_ready

        s = self.statistics
        return json_ready({
            "spec": self.spec.path if self.spec is not None else None,
            "out": self.out,
            "format": self.format,
            "points": self.points,
            "chunks": self.chunks,
            "chunk_size": self.chunk_size,
            "reused_chunks": self.reused_chunks,
            "scheduler": self.scheduler,
            "varying": list(self.spec.varying) if self.spec is not None else [],
            "geometry": self.spec.geometry if self.spec is not None else None,
            "models": list(s.agreement),
            "stable_fraction": s.stable_fraction,
            "undecided": s.undecided,
            "agreement": s.agreement,
            "simulation_agreement": s.simulation_agreement,
            "without_verdict": s.without_verdict,
            "notes": list(self.notes),
            "timing": {"seconds": self.seconds, "rate": self.rate},
        })


def default_chunk_size(spec: SweepSpec, workers: int) -> int:
    """`SIMULATION_CHUNK` of the spec's environment when simulating; else the points shared over the `workers` threads,
    ⌈count/workers⌉, within [`VECTOR_MIN_CHUNK`, `VECTOR_CHUNK`] (one chunk would keep one core busy).

    The table does not depend on it (every point is evaluated on its own), and a
    resumed sweep takes the chunk size of the interrupted run.

    Parameters
    ----------
    spec : SweepSpec
        The sweep (its point count, whether it simulates, its environment).
    workers : int
        Worker threads or processes.
    """
    if spec.simulate:
        return SIMULATION_CHUNK[spec.env]
    return min(VECTOR_CHUNK, max(VECTOR_MIN_CHUNK, -(-spec.count // workers)))


def plan_chunks(count: int, chunk_size: int, *, fine_tail: bool = False) -> list:
    """[(index, start, stop), …]: consecutive point ranges of at most `chunk_size`.

    With ``fine_tail`` (simulation sweeps, whose chunks take seconds) the last
    ``TAIL_CHUNKS * chunk_size`` points go in chunks a quarter as large, so that
    the workers finish together instead of one waiting for the other's last
    full chunk. The plan depends on `count` and `chunk_size` only (never on the
    number of workers): resumed and re-run sweeps see the same chunks.

    Parameters
    ----------
    count : int
        Points in the sweep.
    chunk_size : int
        Largest chunk, points.
    fine_tail : bool
        Quarter-size chunks at the end.
    """
    sizes, left = [], count
    small = max(1, -(-chunk_size // 4))
    while left > 0:
        size = chunk_size if not fine_tail or left > TAIL_CHUNKS * chunk_size else small
        sizes.append(min(size, left))
        left -= sizes[-1]
    chunks, start = [], 0
    for index, size in enumerate(sizes):
        chunks.append((index, start, start + size))
        start += size
    return chunks


def parts_directory(out: str) -> str:
    """``OUT.parts``: where the chunks are written before the output.

    Parameters
    ----------
    out : str
        The output path.
    """
    return f"{out}.parts"


def check_output(out) -> str:
    """`out` if a ``.parquet`` or ``.csv`` file can be written there (`checks.check_output_path`), else ValueError.

    Parameters
    ----------
    out : str
        The output path.
    """
    text = os.fspath(out) if isinstance(out, os.PathLike) else out
    suffix = ".csv" if isinstance(text, str) and text.lower().endswith(".csv") else ".parquet"
    try:
        return check_output_path("out", text, suffix)
    except ValueError as exc:
        raise ValueError(str(exc).replace(f"ending in {suffix}", "ending in .parquet or .csv")) from None


def _part_path(parts: str, index: int, chunks: int) -> str:
    return os.path.join(parts, f"chunk-{index:0{max(5, len(str(chunks - 1)))}d}.parquet")


def _manifest(spec: SweepSpec, chunk_size: int) -> dict:
    return {"digest": spec.digest, "chunk_size": chunk_size, "points": spec.count, "version": __version__}


def _prepare_parts(spec: SweepSpec, out: str, chunk_size: int | None, resume: bool, workers: int) -> tuple[int, dict | None]:
    """(chunk size, the manifest to keep or None): checks a resumed run's manifest before anything is written."""
    parts = parts_directory(out)
    path = os.path.join(parts, "manifest.json")
    old = None
    if resume and os.path.isfile(path):
        try:
            with open(path, encoding="utf-8") as handle:
                old = json.load(handle)
        except (OSError, ValueError):
            old = None
        if old is None or old.get("digest") != spec.digest:
            raise ValueError(f"resume: {parts} holds the chunks of a different sweep (another spec, its config or "
                             f"pfm-stability version); run without --resume to start again, or remove {parts}")
        if chunk_size is not None and chunk_size != old.get("chunk_size"):
            raise ValueError(f"chunk-size: the interrupted sweep in {parts} used chunks of {old.get('chunk_size')} points; "
                             f"resume with that size (or omit --chunk-size)")
        chunk_size = int(old["chunk_size"])
    return (chunk_size if chunk_size is not None else default_chunk_size(spec, workers)), old


def _fail_marker(parts: str, index: int, fail_once) -> str | None:
    return os.path.join(parts, f".fail-once-{index}") if index in fail_once else None


def evaluate_task(spec: SweepSpec, index: int, start: int, stop: int, sample, fail_marker: str | None = None):
    """One chunk as a Dask task: its pyarrow table (the ``fail_once`` test hook raises on the first attempt)."""
    if fail_marker is not None and not os.path.exists(fail_marker):
        with open(fail_marker, "w", encoding="utf-8") as handle:
            handle.write("failed once\n")
        raise RuntimeError(f"chunk {index}: injected failure (fail_once test hook)")
    return to_arrow(evaluate_chunk(spec, start, stop, sample), metadata(spec))


def _chunk_error(index: int, start: int, stop: int, exc: BaseException) -> SweepError:
    return SweepError(f"chunk {index} (points {start}-{stop - 1}) failed after {RETRIES} retries: "
                      f"{type(exc).__name__}: {exc}; the finished chunks are kept, rerun with --resume")


def _local_task(spec, index, start, stop, sample, path, marker):
    """Evaluate, retry, write: one chunk in a thread or worker process of this machine; its `SweepError` (returned, so the other chunks still finish) or None."""
    error = None
    for _ in range(RETRIES + 1):
        try:
            table = evaluate_task(spec, index, start, stop, sample, marker)
            break
        except Exception as exc:  # noqa: BLE001 - any failure of a chunk is retried, then reported with its chunk
            error = exc
    else:
        return _chunk_error(index, start, stop, error)
    write_part(table, path)
    return None


def _local_key(index: int) -> tuple:
    """The Dask key of chunk `index` on the local schedulers, named so that they start the chunks in index order.

    They start independent tasks in the order of `dask.order`, which for such
    tasks is the descending order of the keys' text (dask 2026.8; tested:
    `tests/test_sweeps.py`): ``("chunk", "1000000000000000")`` for chunk 0
    comes first, so the full chunks run before the fine tail (`plan_chunks`)
    and the workers finish together.
    """
    return ("chunk", f"{10**15 - index:016d}")


def _run_local(todo, spec, sample, paths, parts, fail_once, workers, report):
    """Every chunk of `todo` on Dask's local scheduler: `workers` threads, or worker processes when the spec simulates.

    The chunks write their own parts (this machine's file system); `report` is
    called here, in this process, as each chunk finishes (a Dask callback).
    """
    from dask.callbacks import Callback

    graph, sizes = {}, {}
    for index, start, stop in todo:
        key = _local_key(index)
        graph[key] = (partial(_local_task, spec, index, start, stop, _slice(spec, sample, start, stop), paths[index],
                              _fail_marker(parts, index, fail_once)),)
        sizes[key] = stop - start

    def finished(key, result, _dsk, _state, _worker_id) -> None:  # dask's posttask callback signature
        if result is None:
            report(sizes[key])

    with Callback(posttask=finished):
        if spec.simulate:
            from concurrent.futures.process import BrokenProcessPool

            from dask.multiprocessing import get

            try:
                results = get(graph, list(graph), num_workers=workers, chunksize=1)  # one chunk per dispatch: both workers to the end
            except BrokenProcessPool:
                raise SweepError("a worker process died without an answer (killed: out of memory, kill -9?); "
                                 "the finished chunks are kept, rerun with --resume") from None
        else:
            from dask.threaded import get

            from ..vectorized import loop_verdicts

            results = get(graph, list(graph), num_workers=workers)
    errors = [e for e in results if e is not None]
    if errors:
        raise errors[0]


def _slice(spec: SweepSpec, sample, start: int, stop: int):
    return chunk_points(spec, start, stop, sample) if sample is not None else None


def _connect(scheduler: str, timeout: float):
    """A distributed Client of the running scheduler at `scheduler` (ValueError if it cannot be reached within `timeout` s)."""
    from distributed import Client

    try:
        return Client(scheduler, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ValueError(f"scheduler: cannot connect to {scheduler} within {timeout:g} s ({type(exc).__name__}: {exc})") from None


def _run_cluster(client, todo, spec, sample, paths, parts, fail_once, stop_after, report):
    from distributed import as_completed

    futures = {}
    for index, start, stop in todo:
        future = client.submit(evaluate_task, spec, index, start, stop, _slice(spec, sample, start, stop),
                               _fail_marker(parts, index, fail_once), key=f"pfm-sweep-{spec.digest[:16]}-{index}-{time.time_ns()}",
                               retries=RETRIES, pure=False)
        futures[future] = (index, start, stop)
    done = 0
    try:
        for future in as_completed(list(futures)):
            index, start, stop = futures[future]
            if future.status == "error":
                raise _chunk_error(index, start, stop, future.exception())
            write_part(future.result(), paths[index])
            report(stop - start)
            done += 1
            if stop_after is not None and done >= stop_after:
                raise SweepInterrupted(f"stopped after {done} chunks (stop_after_chunks)")
    finally:
        for future in futures:
            future.cancel()


def run_sweep(
    spec: SweepSpec,
    out,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    chunk_size: int | None = None,
    resume: bool = False,
    progress=None,
    connect_timeout: float | None = None,
    stop_after_chunks: int | None = None,
    fail_once=(),
) -> SweepSummary:
    """Evaluate every point of `spec` and write the table to `out` (module docstring).

    Parameters
    ----------
    spec : SweepSpec
    out : str or os.PathLike
        ``.parquet`` (default) or ``.csv`` file.
    scheduler : str, optional
        ``tcp://HOST:PORT`` of a running ``dask.distributed`` scheduler.
    workers : int, optional
        Local threads (no simulation) or worker processes (simulation); default: the number of cores.
    chunk_size : int, optional
        Points per chunk (default `default_chunk_size`; on resume the interrupted run's).
    resume : bool
        Keep the finished chunks of an interrupted run of the same spec.
    progress : callable, optional
        ``progress(points_done, points_total, chunks_done, chunks_total)`` after each chunk.
    connect_timeout : float, optional
        s, for ``scheduler`` (default `CONNECT_TIMEOUT`).
    stop_after_chunks, fail_once
        Test hooks (module docstring).

    Returns
    -------
    SweepSummary

    Raises
    ------
    ValueError
        Bad output path, chunk size or workers, a point outside the model's
        domain (a corridor narrower than the robot), an unreachable
        scheduler, or a resume of another spec — all before anything is written.
    SweepError
        A chunk failed after `RETRIES` retries.
    """
    started = time.perf_counter()
    out = check_output(out)
    if chunk_size is not None:
        chunk_size = check_integer("chunk-size", chunk_size, 1, 10**8)
    workers = check_integer("workers", workers if workers is not None else (os.cpu_count() or 1), 1, 4096)
    if scheduler is not None and not (isinstance(scheduler, str) and scheduler.startswith("tcp://") and ":" in scheduler[6:]):
        raise ValueError(f"scheduler must be an address tcp://HOST:PORT; got {scheduler!r}")
    sample = all_points(spec)
    check_points(spec, sample)
    chunk_size, manifest = _prepare_parts(spec, out, chunk_size, resume, workers)
    chunks = plan_chunks(spec.count, chunk_size, fine_tail=spec.simulate)
    parts = parts_directory(out)
    paths = {index: _part_path(parts, index, len(chunks)) for index, _, _ in chunks}
    client = None
    if scheduler is not None:
        client = _connect(scheduler, CONNECT_TIMEOUT if connect_timeout is None else connect_timeout)
    try:
        if manifest is None:
            shutil.rmtree(parts, ignore_errors=True)
            try:
                os.makedirs(parts)
            except OSError as exc:
                raise OutputError(f"could not create {parts}: {exc.strerror or exc}") from None
            write_text(os.path.join(parts, "manifest.json"), json.dumps(_manifest(spec, chunk_size), indent=2), what="sweep manifest")
        todo = [c for c in chunks if not os.path.isfile(paths[c[0]])]
        reused = len(chunks) - len(todo)
        pending = {c[0] for c in todo}
        state = {"points": sum(stop - start for i, start, stop in chunks if i not in pending), "chunks": reused}
        lock = threading.Lock()

        def report(points: int) -> None:
            with lock:
                state["points"] += points
                state["chunks"] += 1
                if progress is not None:
                    progress(state["points"], spec.count, state["chunks"], len(chunks))

        if progress is not None:
            progress(state["points"], spec.count, state["chunks"], len(chunks))
        if client is not None:
            _run_cluster(client, todo, spec, sample, paths, parts, set(fail_once), stop_after_chunks, report)
            where = scheduler
        else:
            if stop_after_chunks is not None:
                todo, stopped = todo[:stop_after_chunks], True
            else:
                stopped = False
            _run_local(todo, spec, sample, paths, parts, set(fail_once), workers, report)
            if stopped:
                raise SweepInterrupted(f"stopped after {len(todo)} chunks (stop_after_chunks)")
            where = f"local processes ({workers})" if spec.simulate else f"threads ({workers})"
        concatenate_parts([paths[i] for i, _, _ in chunks], out, spec)
    except OutputError as exc:  # a full disk: what is finished stays for --resume
        kept = f"; the finished chunks are kept in {parts}: rerun with --resume" if os.path.isdir(parts) else ""
        raise OutputError(f"{exc}{kept}") from None
    finally:
        if client is not None:
            client.close()
    shutil.rmtree(parts, ignore_errors=True)
    columns = [f"{m}_verdict" for m in spec.models] + (["sim_verdict"] if spec.simulate else [])
    stats = statistics(read_columns(out, columns), spec.models, spec.simulate)
    notes = tuple(n for n in (sobol_note(spec),) if n)
    return SweepSummary(out, "csv" if out.lower().endswith(".csv") else "parquet", spec.count, len(chunks), chunk_size, reused,
                        where, stats, time.perf_counter() - started, notes, spec)
