"""c = 0 is KB's loop: the answers of the code before the heading gain existed, kept to a stated tolerance.

The heading gain c (docs/models.md, "The heading gain") was added to every loop model with the
promise that c = 0 leaves KB's loop as it was. `data/c_zero_reference.npz` holds what the code
*before* c existed (commit e634b1b) answered on 200 seeded loops for every model (NV*, ω*, K*, the
stable set, the verdict at one NV, the rightmost root, T* and k*) and on 20,000 seeded crossing-count
verdicts. It was recorded with ``python tests/test_c_zero_reference.py --record`` under
``OPENBLAS_CORETYPE=Haswell NPY_DISABLE_CPU_FEATURES="X86_V4 AVX512_ICL"``, the floating point of
the machine that recorded that commit's SHA-256 digests (which these values reproduce bit for bit);
the digests are kept below as the record's provenance.

Today's code is compared with those values to a tolerance, not bit for bit: eigenvalue and
polynomial-root routines (LAPACK, numpy's SIMD kernels) round differently on other CPUs and builds.
Measured across OpenBLAS kernels (Haswell vs SkylakeX) and numpy's AVX2 vs AVX-512 kernels, the
largest relative difference of any value is 2.3e-12 (a rightmost root's real part near zero). The
tolerances, each far below what a report prints (4 significant digits) and far above that noise:

* boundaries (NV*, ω*, K*, stable-set edges): 1e-9 relative;
* rightmost roots: |Δr| <= 1e-9·|r|;
* T* and k*: 1e-6 relative (both are bisections stopped at 1e-7 relative bracket width, so two
  builds may stop one bracket apart);
* verdicts, crossing counts: exactly equal (no loop of the set lies within 1e-6 of its boundary,
  checked below, so rounding cannot flip one).
"""

import argparse
import hashlib
import math
from pathlib import Path

import numpy as np
import pytest

from pfm_stability.numerics.delay import delay_verdicts_from_gain
from pfm_stability.models import Loop, make_model

REFERENCE = Path(__file__).parent / "data" / "c_zero_reference.npz"

MODELS = {
    "continuous": {},
    "kb_first_order": {},
    "pade-3": {"pade_order": 3},
    "exact_delay": {},
    "sampled-command-0": {"hold": "command", "compute_delay": 0},
    "sampled-command-1": {"hold": "command", "compute_delay": 1},
    "sampled-reference-0": {"hold": "reference", "compute_delay": 0},
    "sampled-reference-1": {"hold": "reference", "compute_delay": 1},
}

RECORDED_SHA256 = {
    "continuous": "c303e5d79d940737eb1e5d7a156af7cd4c06bf7af2f87e2498eac2619d7c1dfb",
    "kb_first_order": "12b5590fd40eee1a3ef0e916b136ae9c2dfb85881b923d867b5a7e73d988f8ac",
    "pade-3": "335a84c2ab3334d797bb88a6c4986466ab032528fdcdb153218923aedbad199f",
    "exact_delay": "f0972526d4830db8b9c2025a7f18c429de1e0c1c857921ebf7fbb1c89a5f6904",
    "sampled-command-0": "4ee7ce6e4a028b857f5560a079a0f17aa7bfd1b36e2f788051cbcd803572a53c",
    "sampled-command-1": "d7ecb3968e1518d4c66c045b2eeb9329f9612d21d803fccd2cb98d066fbb277f",
    "sampled-reference-0": "a24365e5bf3f50e5eea682ca2b965f0b5cb3ca2561aa49fba65d6e011b08ba4a",
    "sampled-reference-1": "5b5dd3a1911e580b873c2af5cb30e8645ccd2802d5f35e4712810af87cfe88d3",
    "vectorized": "5330ddb1126c0e010577a8e555cbb8584c33528f73d425f82225db2f11c117fa",
}
"""SHA-256 of the recorded values, as the code before c gave them (the provenance of the .npz)."""

ROOTS_CHECKED = {"exact_delay": 40}
"""Rightmost roots on the first 40 loops for exact_delay (about 20 ms each), on all 200 otherwise."""

DELAY_AND_GAIN_CHECKED = 4
"""T* and k* on the first four loops (each is a search over a whole range)."""


def digest_loops(count=200, seed=2024):
    """(τ, T, k, NV): τ = 0 on every tenth loop, T = 0 on every tenth (offset 5), NV spread around KB's boundary."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        tau = 0.0 if i % 10 == 0 else float(np.exp(rng.uniform(np.log(0.01), np.log(3.0))))
        T = 0.0 if i % 10 == 5 else float(np.exp(rng.uniform(np.log(0.002), np.log(2.0))))
        k = float(np.exp(rng.uniform(np.log(0.2), np.log(40.0))))
        out.append((tau, T, k, float(rng.uniform(0.2, 3.0) / (tau + T + 0.05))))
    return out


def model_answers(key):
    """One row per loop: [NV*, ω* (−1: none), K*, stable-set edges…, verdict, root.real, root.imag, T*, k*].

    The root is absent past `ROOTS_CHECKED`, T* and k* past `DELAY_AND_GAIN_CHECKED`; the row
    layout is the one the recorded digests hash (float64 bytes in this order).
    """
    name = key.split("-")[0]
    model = make_model(name, **MODELS[key])
    roots = ROOTS_CHECKED.get(name, 200)
    rows = []
    for i, (tau, T, k, NV) in enumerate(digest_loops()):
        loop = Loop(tau, T, k)
        b = model.boundary(loop)
        values = [b.NV_critical, -1.0 if b.omega_critical is None else b.omega_critical, b.K_critical]
        values += [x for pair in b.stable_set for x in pair] + [float(model.is_stable(NV, loop))]
        if i < roots:
            r = model.rightmost_root(NV, loop)
            values += [-2.0] if r is None else [r.real, r.imag]
        if i < DELAY_AND_GAIN_CHECKED:
            values += [model.critical_delay(NV, loop), model.critical_gain_k(NV, loop)]
        rows.append(np.array(values, dtype=float))
    return rows


def vector_inputs():
    """20,000 seeded (τ, T, k, K) over extreme ranges; τ = 0 on 500, T = 0 on 300."""
    rng = np.random.default_rng(7)
    n = 20000
    tau = np.exp(rng.uniform(np.log(1e-6), np.log(3), n))
    tau[:500] = 0
    T = np.exp(rng.uniform(np.log(1e-4), np.log(20), n))
    T[500:800] = 0
    k = np.exp(rng.uniform(np.log(0.05), np.log(100), n))
    K = np.exp(rng.uniform(np.log(1e-3), np.log(1e3), n))
    return tau, T, k, K


def _sha256(arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def record(path: Path) -> None:
    """Write today's answers to `path` (rows padded with NaN, their lengths beside them)."""
    data = {}
    for key in MODELS:
        rows = model_answers(key)
        width = max(len(r) for r in rows)
        data[f"{key}/values"] = np.array([np.pad(r, (0, width - len(r)), constant_values=np.nan) for r in rows])
        data[f"{key}/lengths"] = np.array([len(r) for r in rows])
        print(key, _sha256(rows) == RECORDED_SHA256[key])
    stable, count, margin = delay_verdicts_from_gain(*vector_inputs())
    data.update({"vectorized/stable": stable, "vectorized/count": count, "vectorized/margin": margin})
    print("vectorized", _sha256((stable, count, margin)) == RECORDED_SHA256["vectorized"])
    np.savez_compressed(path, **data)


@pytest.fixture(scope="module")
def reference():
    with np.load(REFERENCE) as data:
        return {name: data[name] for name in data.files}


def _recorded_rows(reference, key):
    values, lengths = reference[f"{key}/values"], reference[f"{key}/lengths"]
    return [row[:n] for row, n in zip(values, lengths)]


def test_the_reference_is_the_code_before_the_heading_gain(reference):
    """The stored values hash to the SHA-256 digests the code before c gave (its provenance)."""
    for key in MODELS:
        assert _sha256(_recorded_rows(reference, key)) == RECORDED_SHA256[key], key
    vector = (reference["vectorized/stable"], reference["vectorized/count"], reference["vectorized/margin"])
    assert _sha256(vector) == RECORDED_SHA256["vectorized"]


def _close(a: float, b: float, rtol: float) -> bool:
    """Equal infinities/sentinels, else |a − b| <= rtol·|b|."""
    return a == b or abs(a - b) <= rtol * abs(b)


@pytest.mark.parametrize("key", list(MODELS))
def test_c_zero_gives_the_answers_of_the_code_before_the_heading_gain(reference, key):
    """Every model at c = 0 answers as before c existed (tolerances in the module docstring)."""
    name = key.split("-")[0]
    roots = ROOTS_CHECKED.get(name, 200)
    for i, (now, then) in enumerate(zip(model_answers(key), _recorded_rows(reference, key))):
        assert len(now) == len(then), f"loop {i}: the stable set has another number of intervals"
        edges = len(now) - 1 - (2 if i < roots else 0) - (2 if i < DELAY_AND_GAIN_CHECKED else 0)
        for j in range(edges):  # NV*, ω*, K*, stable-set edges
            assert _close(now[j], then[j], 1e-9), (i, j, now[j], then[j])
        assert now[edges] == then[edges], f"loop {i}: verdict"
        if i < roots:
            r_now, r_then = complex(now[edges + 1], now[edges + 2]), complex(then[edges + 1], then[edges + 2])
            assert abs(r_now - r_then) <= 1e-9 * abs(r_then), (i, r_now, r_then)
        if i < DELAY_AND_GAIN_CHECKED:
            for j in (-2, -1):
                assert _close(now[j], then[j], 1e-6), (i, j, now[j], then[j])


def test_the_verdicts_are_far_from_their_boundaries():
    """No loop's NV lies within 1e-6 of an edge of its stable set, so exact verdict equality is fair."""
    for key in MODELS:
        model = make_model(key.split("-")[0], **MODELS[key])
        for tau, T, k, NV in digest_loops():
            edges = [x for pair in model.boundary(Loop(tau, T, k)).stable_set for x in pair if 0 < x < math.inf]
            assert all(abs(NV / edge - 1) > 1e-6 for edge in edges), (key, tau, T, k, NV)


def test_c_zero_vectorized_verdicts_are_unchanged(reference):
    """20,000 crossing-count verdicts and counts exactly, delay margins to 1e-9 relative."""
    stable, count, margin = delay_verdicts_from_gain(*vector_inputs())
    assert np.array_equal(stable, reference["vectorized/stable"])  # booleans
    assert np.array_equal(count, reference["vectorized/count"])  # integers
    then = reference["vectorized/margin"]
    same = (margin == then) | (np.isnan(margin) & np.isnan(then))
    assert np.all(same | (np.abs(margin - then) <= 1e-9 * np.abs(then)))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Record the c = 0 reference (see the module docstring).")
    parser.add_argument("--record", type=Path, default=REFERENCE)
    record(parser.parse_args().record)
