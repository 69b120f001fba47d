"""Shared fixtures: the CARMEL loop and seeded random parameter sets."""

import numpy as np
import pytest

from pfm_stability.models import Loop
from pfm_stability.parameters import CARMEL


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
