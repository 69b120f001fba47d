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
"""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from pfm_stability.models import Loop
from pfm_stability.parameters import CARMEL

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
