"""Seeded samples of the unit hypercube [0, 1)^d: the Latin hypercube and the Sobol sequence.

Both are the samples of `scipy.stats.qmc`, with the same seed giving the same
numbers:

* `latin_hypercube` is ``scipy.stats.qmc.LatinHypercube(d, seed=seed).random(n)``
  (its default form: each of the n strata of every axis holds one point, placed
  uniformly at random inside it), to a few ULP — a test compares them. It is
  written out here, in numpy alone, because importing ``scipy.stats`` loads
  every distribution of SciPy and takes about a second: a fixed cost paid by
  every sampled sweep and every ``validate --sweep`` before any work, for five
  lines of arithmetic.
* `sobol` is ``scipy.stats.qmc.Sobol(d, scramble=True, seed=seed).random(n)``
  (its direction numbers are SciPy's); it imports ``scipy.stats``.
"""

from __future__ import annotations

import warnings

import numpy as np

__all__ = ["latin_hypercube", "sobol"]


def latin_hypercube(n: int, d: int, seed: int) -> np.ndarray:
    """A Latin hypercube sample: ``n`` points in [0, 1)^d, one in each of the n strata of every axis.

    The draws are SciPy's (``LatinHypercube(d, seed=seed).random(n)``): a
    ``numpy.random.default_rng(seed)`` first gives the (n, d) offsets inside
    the strata, then shuffles each axis's strata 1 … n in turn; point i of axis j
    is ``(stratum − offset) / n``.

    Parameters
    ----------
    n : int
        Number of points, ≥ 1.
    d : int
        Dimension, ≥ 1.
    seed : int
        Seed of the generator (the same seed gives the same points on every machine).

    Returns
    -------
    ndarray, shape (n, d)
    """
    rng = np.random.default_rng(seed)
    offsets = rng.uniform(size=(n, d))
    strata = np.tile(np.arange(1, n + 1), (d, 1))
    for axis in strata:
        rng.shuffle(axis)
    return (strata.T - offsets) / n


def sobol(n: int, d: int, seed: int) -> np.ndarray:
    """``n`` scrambled Sobol points in [0, 1)^d (``scipy.stats.qmc.Sobol(d, scramble=True, seed=seed)``).

    Sobol points are balanced only when n is a power of two; SciPy's warning
    about another n is silenced here (callers say it their own way).

    Parameters
    ----------
    n : int
        Number of points, ≥ 1.
    d : int
        Dimension, 1 … 21201.
    seed : int

    Returns
    -------
    ndarray, shape (n, d)
    """
    from scipy.stats import qmc

    engine = qmc.Sobol(d, scramble=True, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return engine.random(n)
