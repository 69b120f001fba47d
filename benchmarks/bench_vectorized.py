"""Vectorized `exact_delay` verdicts against qpmr per point (docs/models.md).

Targets: >= 1,000,000 points/s on this 2-core machine, and >= 1000x faster per
point than calling qpmr (Vyhlidal & Zitek's QPmR, GPL, test-only extra) per
point, with identical verdicts on a 10,000-point random sample (points within
1e-6 relative of the boundary, measured by the delay margin T*/T - 1, excepted).
Run:

    python benchmarks/bench_vectorized.py [--points 2000000] [--sample 10000]
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings

import numpy as np

from pfm_stability.vectorized import exact_delay_verdicts


def random_corridors(count: int, seed: int) -> dict:
    """Uniform random corridor points over the ranges below (SI units), seeded."""
    rng = np.random.default_rng(seed)
    W = rng.uniform(0.3, 1.2, count)
    return dict(
        V=rng.uniform(0.1, 2.0, count),
        tau=rng.uniform(0.0, 1.0, count),
        T=rng.uniform(0.0, 0.3, count),
        k=rng.uniform(0.2, 10.0, count),
        f=rng.uniform(0.1, 5.0, count),
        n=rng.uniform(1.0, 3.0, count),
        W=W,
        L=W / 2 + rng.uniform(0.05, 2.5, count),
    )


def _rhp_radius(tau, k, K):
    """Roots with Re s >= 0 satisfy |a(s)| = K|e^(−sT)| <= K; |a(s)| >= τR³ − R² − kR
    (τ > 0) or R² − kR (τ = 0) on |s| = R, so every such root has |s| < R once that bound exceeds K."""
    def lower_bound(R):
        return tau * R**3 - R**2 - k * R if tau > 0 else R**2 - k * R

    R = 1.0
    while lower_bound(R) <= K:
        R *= 1.5
    return R


def qpmr_verdict(qpmr, tau, T, k, K) -> bool:
    """Stable according to qpmr: no root with Re s >= 0 in the right half-disc.

    Roots come in conjugate pairs and none is real and positive (a(s) > 0 and
    K e^(−sT) > 0 for real s > 0), so the upper half of the disc suffices."""
    R = _rhp_radius(tau, k, K) + 1.0
    coefs = np.array([[0.0, k, 1.0, tau], [K, 0.0, 0.0, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            roots, _ = qpmr.qpmr(coefs, np.array([0.0, T]), region=[-0.5, R, -0.5, R], e=1e-8, ds=R / 100)
        except ValueError:  # qpmr 0.1 raises when the region holds no root at all
            return True
    return bool(len(roots) == 0 or np.max(roots.real) < 0)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=2_000_000)
    parser.add_argument("--sample", type=int, default=10_000, help="points checked against qpmr (0: skip; ~35 ms each)")
    args = parser.parse_args(argv)

    data = random_corridors(args.points, seed=1)
    exact_delay_verdicts(**{key: v[:1000] for key, v in data.items()})  # warm-up
    start = time.perf_counter()
    exact_delay_verdicts(**data)
    elapsed = time.perf_counter() - start
    rate = args.points / elapsed
    print(f"vectorized exact_delay: {args.points:,} points in {elapsed:.3f} s = {rate:,.0f} points/s (target >= 1,000,000)")

    if args.sample <= 0:
        return 0 if rate >= 1e6 else 1
    try:
        import qpmr
    except ImportError:
        print("qpmr not installed (pip install '.[oracle-gpl]'): per-point comparison skipped")
        return 0 if rate >= 1e6 else 1

    sample = random_corridors(args.sample, seed=2)
    ours = exact_delay_verdicts(**sample)
    K = sample["k"] * ours.NV
    near = np.abs(ours.relative_delay_margin) <= 1e-6
    T = sample["T"]
    checked = np.flatnonzero(~near & (T > 0))
    start = time.perf_counter()
    theirs = np.array([qpmr_verdict(qpmr, sample["tau"][i], T[i], sample["k"][i], K[i]) for i in checked])
    qpmr_elapsed = time.perf_counter() - start
    qpmr_rate = len(checked) / qpmr_elapsed
    disagree = checked[theirs != ours.stable[checked]]
    print(f"qpmr per point:        {len(checked):,} points in {qpmr_elapsed:.1f} s = {qpmr_rate:,.0f} points/s")
    print(f"speed ratio vectorized / qpmr = {rate / qpmr_rate:,.0f}x (target >= 1000x)")
    print(f"verdicts: {len(checked) - len(disagree):,} of {len(checked):,} identical "
          f"({int(near.sum())} within 1e-6 of the boundary and {int((T == 0).sum())} with T = 0 excluded)")
    for i in disagree[:10]:
        print(f"  disagree at point {i}: tau={sample['tau'][i]:.4g} T={T[i]:.4g} k={sample['k'][i]:.4g} K={K[i]:.4g} ours={'stable' if ours.stable[i] else 'unstable'}")
    ok = rate >= 1e6 and rate / qpmr_rate >= 1000 and len(disagree) == 0
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
