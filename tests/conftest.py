"""Shared fixtures: the CARMEL loop and seeded random parameter sets; hypothesis profiles.

Hypothesis profiles, chosen with the environment variable ``HYPOTHESIS_PROFILE``:

``ci`` (default)
    100 examples per test that does not set its own count, derandomized so
    that a run is reproducible and CI does not fail on an example no one
    changed code for; no deadline (CLI examples vary from 10 ms to seconds).
``dev``
    10x the examples, random seeds (new examples on every run): for a
    thorough local fuzz, e.g. ``HYPOTHESIS_PROFILE=dev pytest tests/test_cli_fuzz.py``.

Tests that fix ``max_examples`` themselves keep it; ``tests/test_cli_fuzz.py``
scales its budgets from the active profile's ``max_examples``.

BLAS runs on one thread in the suite, as `pfm-stability` itself runs it (``cli.main`` sets
``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS`` and ``MKL_NUM_THREADS`` to 1 before numpy loads,
unless the user set them): the package solves many small eigenvalue problems and matrix
exponentials, on which BLAS threads only spin. Under ``pytest -n 2`` on two cores each worker's
BLAS threads also compete with the other worker; a 2 × 2 ``scipy.linalg.expm`` took 0.7 ms of CPU
instead of 9 µs, and the suite three times as long. The variables are set here, before numpy is
imported (they reach the notebooks' kernels and the fresh processes of the CLI tests too), and
`threadpoolctl` pins the thread pools in case a plugin loaded numpy first. Numbers do not depend
on it (the recorded answers of tests/test_answers_unchanged.py replay to 1e-12 either way).

glibc's allocator keeps the memory numpy frees for the next array in the processes the suite starts (the xdist workers,
the notebooks' kernels, the CLI's fresh processes): ``MALLOC_MMAP_THRESHOLD_`` (32 MiB, glibc's largest) serves arrays up
to that size from the heap rather than from fresh ``mmap`` pages, and ``MALLOC_TRIM_THRESHOLD_`` (1 GiB) keeps the heap's
free top instead of returning it to the system after each large temporary. With glibc's defaults every large temporary
(the map analyses' window sums make many of tens of MB) was mapped, faulted in page by page and unmapped again: two
``map depot`` runs took 160 000 page faults and 1.0-1.6 s of system time, 38 000 and 0.3-0.4 s with these, the
same peak memory (630 MB) and the same user time. Other C libraries ignore the variables; numbers do not depend on
them. Set here unless set already (the process that reads this file keeps the allocator it started with).

The notebooks of ``analyses/`` run with ``PFM_STABILITY_QUICK=1`` (set here, unless set already; their kernels
inherit it): each then takes the same steps on coarser grids and fewer simulated boundary points (its first code
cell says which), so the suite checks that every cell still runs in a fraction of the time. Run normally (the
variable unset) a notebook draws its published figures as before; ``PFM_STABILITY_QUICK= pytest analyses`` runs
them in full here.

Bytecode: where ``PYTHONDONTWRITEBYTECODE`` is set (this development machine's environment sets it), every process
compiles each module it imports from source and pytest rewrites the asserts of every test module again in each xdist
worker, before the first test: 14 s of CPU per worker, 5-6 s with the bytecode kept (``pytest --collect-only``).
The suite's processes write their bytecode (``sys.dont_write_bytecode = False``, set here before the package is
imported; ``__pycache__/`` is ignored by git); the fresh processes they start keep the variable and read it.
``PFM_STABILITY_TEST_BYTECODE=0`` leaves Python's setting alone. Numbers do not depend on it.

Scheduling under ``pytest -n N`` (``--dist loadgroup`` in pyproject.toml):

* tests that share an expensive module fixture carry ``pytest.mark.xdist_group(name)``: a group runs
  on one worker, so its fixture is computed once per suite rather than once per worker that happens
  to get one of its tests (the experiments in quick mode, the verdict sweep, the grid validations,
  the random trap scenes, the symbolic derivation's sympy steps). xdist hands out the groups first,
  largest (most tests) first;
* then the tests marked ``slow`` (each a few seconds or more; the notebooks of ``analyses/`` are
  marked here), so that no long test starts last while the other worker idles;
* then the rest in collection order.
"""

import os
import sys

if os.environ.get("PFM_STABILITY_TEST_BYTECODE", "1") != "0":
    sys.dont_write_bytecode = False  # the rewritten test modules and the package compiled once, not per process (docstring)
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
for _variable, _value in (("MALLOC_MMAP_THRESHOLD_", "33554432"), ("MALLOC_TRIM_THRESHOLD_", "1073741824")):
    os.environ.setdefault(_variable, _value)  # glibc keeps freed memory for reuse (module docstring)
os.environ.setdefault("PFM_STABILITY_QUICK", "1")  # the notebooks' quick run (module docstring)

import numpy as np  # noqa: E402  (after the thread variables)
import pytest  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

threadpool_limits(1, user_api="blas")

from pfm_stability.models import Loop  # noqa: E402
from pfm_stability.parameters import CARMEL  # noqa: E402

settings.register_profile(
    "ci", max_examples=100, derandomize=True, deadline=None, print_blob=True, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile(
    "dev", max_examples=1000, deadline=None, print_blob=True, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture
def carmel_loop():
    """τ = 0.3 s, T = 0.065 s (KB §5.4), k = 2 1/s (the preset's assumption)."""
    return Loop(CARMEL.robot.tau, CARMEL.controller.T, CARMEL.robot.k)


def random_loops(count, seed, *, tau=(0.02, 1.0), T=(0.005, 0.5), k=(0.3, 10.0)):
    """Seeded (τ, T, k, K) sets with K spread around KB's boundary kNV = k/(τ+T)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        t = rng.uniform(*tau)
        d = rng.uniform(*T)
        g = np.exp(rng.uniform(np.log(k[0]), np.log(k[1])))
        K = rng.uniform(0.2, 3.0) * g / (t + d)
        out.append((t, d, g, K))
    return out


@pytest.hookimpl(trylast=True)  # after xdist's own group suffix, and after any plugin that reorders
def pytest_collection_modifyitems(config, items):
    """The notebooks are slow; the slow tests go first (a stable sort: otherwise collection order); each test of an
    ``xdist_group`` carries its group in its node id (`_join_group`)."""
    for item in items:
        if item.path.suffix == ".ipynb":
            item.add_marker(pytest.mark.slow)
        if config.getoption("loadgroup", default=False):  # set on xdist workers under --dist loadgroup
            _join_group(item)
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


def _join_group(item) -> None:
    """The ``@name`` suffix by which ``--dist loadgroup`` sends the tests of ``xdist_group(name)`` to one worker.

    pytest-xdist (3.8) adds it by setting ``item._nodeid``, which pytest 9.2 no longer reads (a node id is
    ``str(item._id)`` there): the suffix was lost without a word, every group's tests were spread over the workers
    and each worker that got one computed the group's module fixture again. Added here where it is missing, as
    xdist writes it (the names sorted, joined by ``_``).
    """
    names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default")) for m in item.iter_markers("xdist_group")})
    if not names:
        return
    suffix = "@" + "_".join(names)
    if item.nodeid.endswith(suffix):
        return  # xdist's own suffix took
    if isinstance(getattr(item, "_id", None), str) or not hasattr(item, "_id"):
        item._nodeid = item.nodeid + suffix
    else:
        item._id = type(item._id).parse(item.nodeid + suffix)

