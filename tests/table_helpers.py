"""Helpers shared by the sweep tests: a written table without its metadata, and table equality with NaN equal to NaN."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq


def read(path):
    """The Parquet table at `path`, its schema metadata (spec, version) dropped."""
    return pq.read_table(path).replace_schema_metadata(None)


def same(a, b) -> bool:
    """pyarrow table equality, with NaN equal to NaN (Table.equals calls a table holding a NaN unequal to itself)."""
    if a.schema != b.schema:
        return False
    for name in a.column_names:
        x, y = a.column(name), b.column(name)
        if x.type == "double":
            if not np.array_equal(x.to_numpy(), y.to_numpy(), equal_nan=True):
                return False
        elif not x.equals(y):
            return False
    return True
