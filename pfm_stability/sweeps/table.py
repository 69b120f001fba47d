"""The sweep's table on disk: Arrow columns, Parquet parts, the final Parquet or CSV file, and its summary.

Column types: ``point`` int64; inputs, N, NV, NV*, margins and σ float64
(``inf`` kept as IEEE infinity; NaN only where a reason column says why);
``*_stable``, ``sim_collided`` bool; verdicts, bases and reasons strings
(null where none). The Parquet file's schema metadata carries
``pfm_stability.spec`` (the normalized spec, JSON) and
``pfm_stability.version``. A CSV writes the same columns (``inf``, empty for
null) and has no metadata.

Every file is written to a temporary name beside the target and renamed
(`files.atomic_file`): an interrupted write or a full disk leaves no
half-written output.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from ..io.files import atomic_file
from ..version import __version__
from .evaluate import ChunkColumns

__all__ = ["SweepStatistics", "concatenate_parts", "dictionary_columns", "metadata", "read_columns", "read_part", "statistics", "to_arrow", "write_part", "write_table"]


def to_arrow(columns: ChunkColumns, metadata: dict | None = None):
    """A pyarrow Table of the chunk's columns (object arrays become string columns).

    Parameters
    ----------
    columns : ChunkColumns
        The chunk's columns.
    metadata : dict, optional
        Schema metadata (`metadata`).
    """
    import pyarrow as pa

    arrays = []
    for a in columns.arrays:
        if a.dtype == object:
            arrays.append(pa.array(list(a), type=pa.string()))
        else:
            arrays.append(pa.array(a))
    table = pa.table(arrays, names=list(columns.names))
    return table.replace_schema_metadata(metadata) if metadata else table


def metadata(spec) -> dict:
    """The Parquet schema metadata of a sweep's table: the normalized spec (JSON) and the package version.

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    """
    return {"pfm_stability.spec": json.dumps(spec.to_dict(), sort_keys=True), "pfm_stability.version": __version__}


def dictionary_columns(schema) -> list:
    """The columns worth Parquet's dictionary encoding: the strings (verdicts, reasons: a few distinct values).

    Numbers are stored plainly: trying a dictionary on a column of distinct
    floats (a sample's inputs, NV*, margins) and giving up costs three times
    the rest of the write (0.18 of 0.26 s for 200,000 rows).

    Parameters
    ----------
    schema : pyarrow.Schema
        The table's schema.
    """
    import pyarrow as pa

    return [field.name for field in schema if pa.types.is_string(field.type)]


def write_part(table, path: str) -> None:
    """Write one chunk's table as Parquet, atomically (`files.atomic_file`).

    Parameters
    ----------
    table : pyarrow.Table
        The chunk's table.
    path : str
        Where to write it.
    """
    import pyarrow.parquet as pq

    with atomic_file(path, what="sweep chunk") as handle:
        pq.write_table(table, handle, use_dictionary=dictionary_columns(table.schema))


def read_part(path: str):
    """One chunk's table.

    Parameters
    ----------
    path : str
        The chunk's Parquet file.
    """
    import pyarrow.parquet as pq

    return pq.ParquetFile(path).read()


def concatenate_parts(paths, out: str, spec) -> None:
    """Concatenate the parts (in point order) into `out`: Parquet, or CSV when `out` ends in .csv (atomically).

    A single Parquet part that already carries the output's metadata is moved to `out` instead.

    Parameters
    ----------
    paths : sequence of str
        The parts' files, in point order.
    out : str
        The output path (.parquet or .csv).
    spec : SweepSpec
        The sweep (the output's metadata).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    if len(paths) == 1 and not out.lower().endswith(".csv") and pq.read_schema(paths[0]).metadata == {k.encode(): v.encode() for k, v in metadata(spec).items()}:
        os.replace(paths[0], out)  # one part with the output's metadata is the output: moved, not rewritten
        return
    meta = metadata(spec)
    with atomic_file(out, what="table") as handle:
        if out.lower().endswith(".csv"):
            import pyarrow.csv as pcsv

            writer = None
            for path in paths:
                table = pq.ParquetFile(path).read()
                if writer is None:
                    writer = pcsv.CSVWriter(handle, table.schema)
                writer.write_table(table)
            if writer is not None:
                writer.close()
        else:
            schema = pq.read_schema(paths[0]).with_metadata(meta) if paths else None
            with pq.ParquetWriter(handle, schema, use_dictionary=dictionary_columns(schema)) as writer:
                for path in paths:
                    writer.write_table(pa.Table.from_batches(pq.ParquetFile(path).read().to_batches(), schema=schema))


def write_table(table, out: str, spec) -> None:
    """Write a whole table to `out` (Parquet, or CSV for .csv), atomically.

    Parameters
    ----------
    table : pyarrow.Table
        The whole table.
    out : str
        The output path (.parquet or .csv).
    spec : SweepSpec
        The sweep (the output's metadata).
    """
    import pyarrow.parquet as pq

    tmp_part = f"{out}.part-{os.getpid()}.parquet"
    pq.write_table(table, tmp_part, use_dictionary=dictionary_columns(table.schema))
    try:
        concatenate_parts([tmp_part], out, spec)
    finally:
        os.remove(tmp_part)


def read_columns(path: str, columns=None):
    """The output file's table (Parquet or CSV), or only `columns`.

    Parameters
    ----------
    path : str
        The output file (.parquet or .csv).
    columns : list of str, optional
        Only these columns (default: all).
    """
    if path.lower().endswith(".csv"):
        import pyarrow.csv as pcsv

        table = pcsv.read_csv(path)
        return table.select(columns) if columns else table
    import pyarrow.parquet as pq

    return pq.ParquetFile(path).read(columns=columns)  # not pq.read_table: it loads pyarrow.dataset (0.2 s)


@dataclass(frozen=True)
class SweepStatistics:
    """What the summary says about the table.

    Attributes
    ----------
    points : int
    stable_fraction : dict
        Model → fraction of points it calls "stable" (``sim`` too when simulated).
    undecided : dict
        Model → points it calls "undecided".
    agreement : dict
        Model → model → fraction of points where both give the same verdict
        (points without a verdict count as disagreeing).
    simulation_agreement : dict or None
        Model → fraction of the simulated points where the model's verdict
        equals the simulator's (None when not simulated).
    without_verdict : int
        Points with no verdict (a reason says why).
    """

    points: int
    stable_fraction: dict
    undecided: dict
    agreement: dict
    simulation_agreement: dict | None
    without_verdict: int


def _strings(column):
    """An Arrow string column as a numpy object array (None for null)."""
    return column.to_numpy(zero_copy_only=False)


def _mean(mask, n: int) -> float:
    return float(mask.sum()) / n if n else float("nan")


def statistics(table, models, simulate: bool) -> SweepStatistics:
    """Per-model stable fractions and pairwise agreement of a sweep's table (numpy on the verdict columns).

    Parameters
    ----------
    table : pyarrow.Table
        The sweep's table.
    models : sequence of str
        The models whose verdict columns it has.
    simulate : bool
        It has the simulated verdicts too (``sim_verdict``).
    """
    n = table.num_rows
    verdicts = {m: _strings(table.column(f"{m}_verdict")) for m in models}
    missing = {m: np.equal(verdicts[m], None) for m in models}
    stable = {m: _mean(verdicts[m] == "stable", n) for m in models}
    undecided = {m: int((verdicts[m] == "undecided").sum()) for m in models}
    agreement = {a: {b: _mean((verdicts[a] == verdicts[b]) & ~missing[a], n) for b in models} for a in models}
    sim = None
    if simulate:
        simulated = _strings(table.column("sim_verdict"))
        have = ~np.equal(simulated, None)
        stable["sim"] = _mean(simulated == "stable", n)
        sim = {m: _mean((verdicts[m] == simulated) & have, int(have.sum())) for m in models}
    without = int(missing[models[0]].sum()) if models else 0
    return SweepStatistics(n, stable, undecided, agreement, sim, without)
