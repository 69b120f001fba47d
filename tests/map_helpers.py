"""One analysis per map and options in a test run: `shared_map_analyses`, for tests that read the same map twice.

A map's analysis (`maps.analysis.analyze_map`) takes seconds on a shipped map, and several tests ask for exactly the
same one through different outputs: ``map depot`` as JSON, as text, with ``--out-dir`` on a full disk, through
`MapAnalysis.plot`. Inside ``with shared_map_analyses():`` a call with the same map (its cells, resolution, origin and
thresholds), robot, controller, law and options as an earlier call in this process returns that call's analysis (a
frozen dataclass; nothing downstream changes it), with its warnings given to ``warn`` again as the first call gave
them. What each test checks is unchanged: every output is still rendered, written and read from the analysis; the
analysis itself is computed once by the same code. A call with a ``progress`` callback (its lines carry the stages'
timings) or with the user's own routes is computed afresh. That an analysis depends on nothing else (the process's
history, the time) is itself checked: tests/test_map_cli.py::test_json_is_deterministic compares a fresh analysis
with an earlier one.

Tests that share an analysis carry the same ``pytest.mark.xdist_group`` (tests/conftest.py), so that they run on one
worker under ``pytest -n``: the cache lives in the worker's process.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect

import numpy as np

import pfm_stability.maps.analysis as map_analysis

__all__ = ["shared_map_analyses"]

_ANALYSES: dict = {}
"""The analyses computed so far in this process, by `_key`."""


def _key(arguments: dict) -> str:
    """A digest of everything `analyze_map` reads: the map's cells and metadata, the parameters, the options."""
    digest = hashlib.sha256()
    occupancy = arguments.pop("occupancy")
    for cells in (occupancy.values, occupancy.occupied, occupancy.free):
        cells = np.ascontiguousarray(cells)
        digest.update(repr((cells.shape, cells.dtype.str)).encode())
        digest.update(cells.tobytes())
    digest.update(repr((occupancy.name, occupancy.resolution, tuple(occupancy.origin), occupancy.mode, occupancy.negate,
                        occupancy.occupied_thresh, occupancy.free_thresh)).encode())
    arguments.pop("warn")
    arguments["routes"] = tuple(arguments["routes"])  # () from the library's default, [] from the CLI
    digest.update(repr(sorted(arguments.items())).encode())
    return digest.hexdigest()


@contextlib.contextmanager
def shared_map_analyses():
    """Within the block, `maps.analysis.analyze_map` answers a repeated call from this process's cache (module docstring)."""
    compute = map_analysis.analyze_map
    signature = inspect.signature(compute)

    def analyze_map(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()
        if bound.arguments["progress"] is not None or tuple(bound.arguments["routes"]):
            return compute(*args, **kwargs)  # progress lines carry timings; a user's routes hold arrays (no short key)
        warn = bound.arguments["warn"]
        key = _key(dict(bound.arguments))
        if key not in _ANALYSES:
            _ANALYSES[key] = compute(*args, **kwargs)
        elif warn is not None:
            for line in _ANALYSES[key].warnings:
                warn(line)
        return _ANALYSES[key]

    map_analysis.analyze_map = analyze_map
    try:
        yield
    finally:
        map_analysis.analyze_map = compute
