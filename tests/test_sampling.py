"""`sampling`: the Latin hypercube and Sobol samples are SciPy's (`scipy.stats.qmc`), the same numbers for the same seed."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import qmc

from pfm_stability.numerics.sampling import latin_hypercube, sobol

RNG = np.random.default_rng(20261123)
CASES = [(1, 1, 0), (2000, 4, 0), (7, 9, 2**63 - 1)] + [
    (int(RNG.integers(1, 3000)), int(RNG.integers(1, 12)), int(RNG.integers(0, 2**62))) for _ in range(6)]


@pytest.mark.parametrize("n, d, seed", CASES)
def test_latin_hypercube_is_scipys(n, d, seed):
    """SciPy's points to 2 ULP of 1, and the defining property checked on its own: every axis has exactly one point
    in each of its n strata [i/n, (i+1)/n).

    The same generator and the same operations in the same order give, today, identical arrays; but they are two
    implementations (ours and SciPy's, whose release may reorder its arithmetic), so they are compared to a stated
    tolerance, not bit for bit: 2 ULP of 1 (4.4e-16) on points in [0, 1), while a wrong stratum, offset or draw
    moves a point by about 1/n or more."""
    ours = latin_hypercube(n, d, seed)
    assert ours.shape == (n, d)
    np.testing.assert_allclose(ours, qmc.LatinHypercube(d, seed=seed).random(n), rtol=0, atol=2 * np.finfo(float).eps)
    strata = np.floor(ours * n).astype(int)
    assert np.all(np.sort(strata, axis=0) == np.arange(n)[:, None])


@pytest.mark.parametrize("n, d, seed", [(64, 3, 2), (100, 5, 7)])
def test_sobol_is_scipys_without_its_warning(n, d, seed):
    """Scrambled Sobol points as SciPy draws them; n = 100 (not a power of two) gives no warning (callers note it)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ours = sobol(n, d, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # exact is legitimate: `sobol` is this very SciPy call, repeated in the same process with the same inputs
        assert np.array_equal(ours, qmc.Sobol(d, scramble=True, seed=seed).random(n))
