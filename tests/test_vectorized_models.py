"""`vectorized.loop_verdicts` against the scalar models, model by model (docs/models.md).

The scalar route is ``model.boundary(Loop(τ, T, k, c=c))``, ``model.is_stable(NV, loop)``,
`verdict_label` and `gain_margin`. Scalar evaluation of 10⁵ points is too slow for the
suite, but the boundary depends only on the loop (τ, T, k, c and the model's options),
not on NV: each test draws a few hundred loops spread over decades (τ = 0, tiny T, kτ
beyond 2 + √3, heading gains), computes each scalar `Boundary` once, and gives each loop
≥ 100 values of NV (negative ones, values on both sides of NV* within 10⁻⁶, values
within 10⁻¹² — "undecided"). Against those boundaries every point's verdict and margin
must equal the scalar functions'; `stable` itself is checked against the scalar
`is_stable` (an independent route: eigenvalues, Routh, the crossing count) on a random
subsample, since reusing the boundary would not catch a wrong NV* used by both sides.
"""

import math
import zlib

import numpy as np
import pytest

from pfm_stability.models import Loop, gain_margin, make_model, verdict_label
from pfm_stability.models.verdicts import UNDECIDED_RTOL
from pfm_stability.vectorized import LoopVerdicts, loop_verdicts

NV_RTOL = {"continuous": 1e-12, "kb_first_order": 1e-12, "exact_delay": 1e-12, "pade": 1e-9, "sampled": 1e-7}
"""Relative agreement of NV* with the scalar model. Closed forms (continuous, kb_first_order)
and the same array code (exact_delay) agree to round-off. pade and sampled find the same
crossings by different root finders (the scalar route: np.roots on a polynomial in ω from
np.poly of Ψ's eigenvalues); for stiff sampled loops (τ ~ 10⁻⁴ s, T ~ 10⁻⁶…10⁻³ s, k up
to 10⁴ 1/s) the scalar route keeps only 7–9 digits: a 40-digit mpmath check of |z| − 1 at
both values (the closed-loop matrix from mpmath's expm) found the vectorized NV* on the
unit circle to 10⁻¹⁴ and the scalar one off by up to 4·10⁻⁹ (relative NV* gaps up to 4.4·10⁻⁸)."""


def _loops(rng, count, heading):
    tau = np.exp(rng.uniform(math.log(1e-4), math.log(10.0), count))
    tau[rng.random(count) < 0.1] = 0.0
    T = np.exp(rng.uniform(math.log(1e-6), math.log(10.0), count))
    T[rng.random(count) < 0.05] = 0.0
    k = np.exp(rng.uniform(math.log(1e-2), math.log(1e3), count))
    resonant = rng.random(count) < 0.15  # kτ > 2 + √3: the steering loop resonates
    k[resonant] = np.minimum((4.0 + rng.uniform(0, 50, resonant.sum())) / np.maximum(tau[resonant], 1e-3), 1e4)
    c = np.where(rng.random(count) < 0.6, rng.uniform(-0.99, 5.0, count), 0.0) if heading else np.zeros(count)
    return tau, T, k, c


def _gains(rng, boundaries, tau, T, per_loop):
    rows = []
    for b, t, d in zip(boundaries, tau, T):
        edges = [x for pair in b.stable_set for x in pair if 0 < x < math.inf] or [1.0 / max(t + d, 1e-3)]
        base = edges[rng.integers(len(edges))]
        nv = base * np.exp(rng.uniform(-4.0, 4.0, per_loop))
        nv[:3] = -nv[:3]
        nv[3:7] = base * np.array([1 - 1e-6, 1 + 1e-6, 1 - 1e-12, 1 + 1e-12])
        rows.append(nv)
    return np.array(rows)


def _check_model(name, seed, count, per_loop, *, heading, extra_loops=(), subsample=250, **options):
    rng = np.random.default_rng(seed)
    tau, T, k, c = _loops(rng, count, heading)
    if extra_loops:
        tau, T, k, c = (np.concatenate([a, np.array(b, dtype=float)]) for a, b in zip((tau, T, k, c), zip(*extra_loops)))
    model = make_model(name, **options)
    loops = [Loop(*x[:3], c=x[3]) for x in zip(tau, T, k, c)]
    tau = np.array([loop.tau for loop in loops])  # τk < 1e-9 is stored as 0
    boundaries = [model.boundary(loop) for loop in loops]
    NV = _gains(rng, boundaries, tau, T, per_loop)
    got = loop_verdicts(name, tau[:, None], T[:, None], k[:, None], NV, c=c[:, None], **options)
    assert isinstance(got, LoopVerdicts) and got.stable.shape == NV.shape and got.stable.size >= count * per_loop
    expected_NV = np.array([b.NV_critical for b in boundaries])
    finite = np.isfinite(expected_NV) & (expected_NV > 0)
    assert np.array_equal(np.isfinite(got.NV_critical[:, 0]), np.isfinite(expected_NV))
    assert np.array_equal(got.NV_critical[~finite, 0], expected_NV[~finite])
    np.testing.assert_allclose(got.NV_critical[finite, 0], expected_NV[finite], rtol=NV_RTOL[name], atol=0)
    np.testing.assert_allclose(got.K_critical[:, 0], k * got.NV_critical[:, 0], rtol=1e-15)
    omega = np.array([math.nan if b.omega_critical is None else b.omega_critical for b in boundaries])
    np.testing.assert_allclose(got.omega_critical[:, 0], omega, rtol=max(NV_RTOL[name], 1e-11))
    mismatches = []
    for i, b in enumerate(boundaries):
        for j in range(per_loop):
            nv = float(NV[i, j])
            distance = min((abs(nv / x - 1) for pair in b.stable_set for x in pair if 0 < x < math.inf), default=math.inf)
            near = distance <= 2 * UNDECIDED_RTOL + NV_RTOL[name]
            stable = bool(got.stable[i, j]) if near else b.contains(nv)  # the boundary's own verdict off the edges
            if not near and stable != bool(got.stable[i, j]):
                mismatches.append(("stable", i, nv))
            # within NV_RTOL of an edge two NV* that differ by more than UNDECIDED_RTOL may disagree on "undecided"
            blurred = near and NV_RTOL[name] > UNDECIDED_RTOL
            if not blurred and verdict_label(nv, b, stable) != got.verdict[i, j]:
                mismatches.append(("verdict", i, nv, got.verdict[i, j]))
            margin = gain_margin(nv, b, stable)
            if not (margin == got.margin[i, j] or abs(margin - got.margin[i, j]) <= NV_RTOL[name] * (1 + abs(margin))):
                mismatches.append(("margin", i, nv, margin, got.margin[i, j]))
    assert not mismatches, mismatches[:5]
    # `stable` against the scalar is_stable (an independent route) on a subsample off the edges
    flat = rng.choice(NV.size, size=min(subsample, NV.size), replace=False)
    for index in flat:
        i, j = divmod(int(index), per_loop)
        if got.verdict[i, j] != "undecided" and not abs(NV[i, j] - got.NV_critical[i, 0]) <= 1e-6 * got.NV_critical[i, 0]:
            assert model.is_stable(float(NV[i, j]), loops[i]) == bool(got.stable[i, j]), (name, options, loops[i], NV[i, j])
    return got


@pytest.mark.parametrize("heading", [False, True])
@pytest.mark.parametrize("name", ["continuous", "kb_first_order", "exact_delay", "pade"])
def test_polynomial_and_delay_models_equal_the_scalar_route(name, heading):
    """250 loops × 200 NV = 5·10⁴ points per case (10⁵ per model), over the ranges of `_loops`.
    Tolerances: `NV_RTOL` (margins to the same relative size; verdicts exactly)."""
    got = _check_model(name, seed=zlib.crc32(f"{name}{heading}".encode()), count=250, per_loop=200, heading=heading)
    assert got.stable.any() and (~got.stable).any() and (got.verdict == "undecided").any()


@pytest.mark.parametrize("heading", [False, True])
@pytest.mark.parametrize("compute_delay", [0, 1])
@pytest.mark.parametrize("hold", ["command", "reference"])
def test_sampled_equals_the_scalar_route(hold, compute_delay, heading):
    """Both holds × compute delay 0/1 × with and without c: 120 random loops plus loops with
    τ = 0 and kT near 2 (stable sets that do not start at 0 or have a second interval,
    decided by the scalar model) × 105 NV, 1.3·10⁴ points per case (10⁵ in all)."""
    extra = [(0.0, 0.1, k, 0.0) for k in (19.0, 20.5, 21.0)] + [(0.0, 1.0, k, 0.0) for k in (1.95, 2.05, 2.1)]  # kT near 2, not 2
    got = _check_model("sampled", seed=7 + 2 * compute_delay + (hold == "command"), count=120, per_loop=105, heading=heading, extra_loops=extra, hold=hold, compute_delay=compute_delay)
    assert got.stable.any() and (~got.stable).any()


def test_some_sampled_loops_have_irregular_stable_sets():
    """The scalar fallback is exercised: a command-held loop with kT near 2.3 (found by a random
    search, 1 loop in 1200) is unstable for small NV and stable on (0.712, 1.118) 1/s only
    (docs/models.md); the array answers there equal the scalar ones exactly (verdicts,
    margins), and `regular` is False."""
    model = make_model("sampled", hold="command", compute_delay=0)
    tau, T, k = 0.06674483265995879, 1.3314726771528502, 1.7527997083573452
    loop = Loop(tau, T, k)
    b = model.boundary(loop)
    assert b.stable_set and b.stable_set[0][0] > 0
    NV = np.geomspace(1e-2, 1e2, 200)
    got = loop_verdicts("sampled", tau, T, k, NV)
    assert not got.regular.any() and got.stable.any()
    for nv, s, v, m in zip(NV, got.stable, got.verdict, got.margin):
        stable = model.is_stable(float(nv), loop)
        assert s == stable and v == verdict_label(float(nv), b, stable) and m == gain_margin(float(nv), b, stable)


def test_shapes_broadcast_and_scalars():
    """Scalars give 0-d arrays; arrays broadcast like numpy; dtypes are bool, str, float."""
    got = loop_verdicts("continuous", 0.3, 0.0, 2.0, 1.0)
    assert got.stable.shape == () and bool(got.stable) and str(got.verdict) == "stable"
    grid = loop_verdicts("sampled", np.array([0.1, 0.3])[:, None], 0.065, 2.0, np.array([1.0, 2.0, 10.0]), compute_delay=1)
    assert grid.stable.shape == grid.verdict.shape == grid.margin.shape == (2, 3)
    assert grid.stable.dtype == bool and grid.NV_critical.dtype == float and grid.verdict.dtype.kind == "U"


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(model="nope"), "model"),
        (dict(tau=[0.1, -1.0]), "tau"),
        (dict(T=np.nan), "T"),
        (dict(k=0.0), "k"),
        (dict(NV=[1.0, np.nan]), r"NV.*\(point 1\)"),
        (dict(NV=np.inf), "NV"),
        (dict(NV=2e12), "NV"),
        (dict(c=-1.5), "c"),
        (dict(hold="sample"), "hold"),
        (dict(compute_delay=2), "compute_delay"),
        (dict(pade_order=13), "pade_order"),
        (dict(tau="abc"), "tau"),
    ],
)
def test_bad_inputs_raise_value_error_naming_the_parameter(kwargs, message):
    """Every bad input is a one-line ValueError that names the parameter (as the scalar models'
    checks word it, with the point index for arrays); nothing is returned."""
    args = dict(model="sampled", tau=0.3, T=0.065, k=2.0, NV=1.0) | kwargs
    model = args.pop("model")
    with pytest.raises(ValueError, match=message) as info:
        loop_verdicts(model, **args)
    assert "\n" not in str(info.value)


def _edge_points(rng, name, count, per_loop, heading, **options):
    """Random loops of `_loops` and NV spread around each loop's array NV* (within 10⁻¹², 10⁻⁹,
    10⁻⁷, 10⁻⁶ of it and over ±4 decades, some negative)."""
    tau, T, k, c = _loops(rng, count, heading)
    edge = loop_verdicts(name, tau, T, k, 1.0, c=c, **options).NV_critical
    base = np.where(np.isfinite(edge) & (edge > 0), edge, 1.0 / np.maximum(tau + T, 1e-3))
    NV = base[:, None] * np.exp(rng.uniform(-4.0, 4.0, (count, per_loop)))
    NV[:, :12] = base[:, None] * (1.0 + np.array([-1e-12, 1e-12, -1e-9, 1e-9, -2e-9, 2e-9, -1e-7, 1e-7, -1e-6, 1e-6, -3e-6, 3e-6]))
    NV[:, 12:14] *= -1.0
    return tau[:, None], T[:, None], k[:, None], c[:, None], NV


@pytest.mark.parametrize(
    "name, options",
    [("exact_delay", {}), ("pade", {}), ("sampled", {"hold": "command", "compute_delay": 0}), ("sampled", {"hold": "command", "compute_delay": 1}),
     ("sampled", {"hold": "reference", "compute_delay": 0}), ("sampled", {"hold": "reference", "compute_delay": 1})],
)
@pytest.mark.parametrize("heading", [False, True])
def test_verdict_only_path_equals_all_columns(name, options, heading):
    """``columns="verdict"`` decides without the boundary (three stability tests, or one crossing and
    its slope for exact_delay) and must give exactly the `stable` and `verdict` of the full path —
    on 300 random loops × 40 NV, a third of them within 10⁻¹²…3·10⁻⁶ of NV* (where the labels
    turn "undecided" and the shortcut must hand the point to the full path). Exact equality: both
    paths use the same arrays; no tolerance. The other fields are NaN (not computed)."""
    rng = np.random.default_rng(zlib.crc32(f"{name}{options}{heading}".encode()))
    tau, T, k, c, NV = _edge_points(rng, name, 300, 40, heading, **options)
    full = loop_verdicts(name, tau, T, k, NV, c=c, **options)
    fast = loop_verdicts(name, tau, T, k, NV, c=c, columns="verdict", **options)
    assert fast.stable.shape == full.stable.shape == NV.shape
    assert np.array_equal(fast.stable, full.stable)
    assert np.array_equal(fast.verdict, full.verdict)
    assert (full.verdict == "undecided").any() and full.stable.any() and (~full.stable).any()
    assert np.isnan(fast.NV_critical).all() and np.isnan(fast.margin).all()


def test_columns_option_is_checked():
    """An unknown ``columns`` is a one-line ValueError naming it."""
    with pytest.raises(ValueError, match="columns") as info:
        loop_verdicts("sampled", 0.3, 0.065, 2.0, 1.0, columns="some")
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("hold", ["command", "reference"])
def test_closed_form_zero_order_hold_equals_the_matrix_exponential(hold):
    """`vectorized.zoh.delta_entries` (φ-functions of the 2 × 2 servo block by Taylor series and
    doubling) against Ψ = (e^(AT) − I)/T and G = Γ/T from the stacked Padé exponential
    (`vectorized.sampled.delta_plants`, an independent route) on 3000 loops over τ 10⁻⁴…10 s,
    T 10⁻⁶…10 s, k 10⁻²…10³ 1/s, and τ = 0. Tolerance 10⁻⁸ of the largest entry: for T/τ ~ 10⁴…10⁵
    each route loses ~T/τ·ε (up to 20 doublings; a 50-digit check found the closed form within
    10⁻¹¹ and the Padé route within 10⁻¹⁶ there), measured worst 10⁻⁹."""
    from pfm_stability.vectorized.sampled import continuous_plants, delta_plants
    from pfm_stability.vectorized.zoh import delta_entries

    rng = np.random.default_rng(11)
    n = 3000
    T = np.exp(rng.uniform(math.log(1e-6), math.log(10.0), n))
    k = np.exp(rng.uniform(math.log(1e-2), math.log(1e3), n))
    for tau in (np.exp(rng.uniform(math.log(1e-4), math.log(10.0), n)), np.zeros(n)):
        A, B, _, _ = continuous_plants(tau, k, np.zeros(n), hold)
        Psi, G = delta_plants(A, B, T)
        got = delta_entries(tau, T, k, hold == "reference")
        names = ("P00", "P01", "P10", "P11", "P20", "P21") if tau[0] > 0 else ("P00", "P10")
        cells = ((0, 0), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1))
        for name, (i, j) in zip(names, cells if tau[0] > 0 else ((0, 0), (1, 0))):
            assert np.all(np.abs(got[name] - Psi[:, i, j]) <= 1e-8 * np.abs(Psi).max(axis=(1, 2))), name
        for i in range(G.shape[1]):
            assert np.all(np.abs(got[f"g{i}"] - G[:, i]) <= 1e-8 * np.abs(G).max(axis=1)), i


def test_single_crossing_verdicts_equal_the_crossing_count():
    """`vectorized.delay_verdicts.single_crossing_verdicts` (one root, one arctangent) against the
    full crossing count `delay.delay_verdicts_from_gain` on 2·10⁴ points over τ 0…3 s (resonant
    loops included), T 0…20 s, k 0.05…100 1/s, K over eight decades (some negative): equal
    verdicts wherever the point is neither `near` an edge nor has three crossings (those go to
    the full count). Exact: both evaluate the same formula up to round-off far from the edge."""
    from pfm_stability.numerics.delay import delay_verdicts_from_gain
    from pfm_stability.vectorized.delay_verdicts import single_crossing_verdicts

    rng = np.random.default_rng(5)
    n = 20000
    tau = np.exp(rng.uniform(math.log(1e-6), math.log(3.0), n))
    tau[:1000] = 0.0
    T = np.exp(rng.uniform(math.log(1e-4), math.log(20.0), n))
    T[1000:1500] = 0.0
    k = np.exp(rng.uniform(math.log(0.05), math.log(100.0), n))
    K = np.exp(rng.uniform(math.log(1e-4), math.log(1e4), n))
    K[:300] *= -1.0
    stable, near, three = single_crossing_verdicts(tau, T, k, K, 1e-6)
    expected = delay_verdicts_from_gain(tau, T, k, K)[0]
    decided = ~near & ~three
    assert three.any() and stable[decided].any() and (~stable[decided]).any() and decided.mean() > 0.9
    assert np.array_equal(stable[decided], expected[decided])


def test_last_hurwitz_determinant_in_gain_equals_the_hurwitz_matrix():
    """`hurwitz_gain.hurwitz_determinant_in_gain` (Δ_{n−1} of D + K·E expanded in K from products of
    the affine columns) against det of the (n − 1) × (n − 1) leading block of the Hurwitz matrix of
    D + K·E, built entry by entry, for random polynomials of degree 2…4 and random K (an
    independent route). Tolerance 10⁻⁹ of the sum of |terms|: both are sums of a few products of
    O(1) numbers."""
    from pfm_stability.vectorized.hurwitz_gain import hurwitz_determinant_in_gain

    rng = np.random.default_rng(3)
    for n in (2, 3, 4):
        D, E = rng.normal(size=(200, n + 1)), rng.normal(size=(200, n + 1))
        K = rng.uniform(-3.0, 3.0, 200)
        coefficients = hurwitz_determinant_in_gain(list(D.T), list(E.T))
        got = np.sum(coefficients * K[:, None] ** np.arange(coefficients.shape[1]), axis=1)
        for i in range(200):
            q = D[i] + K[i] * E[i]
            H = np.array([[q[2 * col - row + 1] if 0 <= 2 * col - row + 1 <= n else 0.0 for col in range(n - 1)] for row in range(n - 1)]).T
            expected = np.linalg.det(H)
            scale = np.prod(np.sort(np.abs(q))[::-1][: n - 1] + 1.0) * 10
            assert abs(got[i] - expected) <= 1e-9 * scale, (n, i, got[i], expected)


@pytest.mark.parametrize("hold, compute_delay", [("command", 0), ("command", 1), ("reference", 1)])
def test_hurwitz_gain_sets_equal_the_crossing_route(hold, compute_delay):
    """`hurwitz_gain.hurwitz_gain_sets` (edges from q₀, q_n and Δ_{n−1} in K, one Liénard–Chipart test per
    stretch) against `polynomial.affine_stable_sets` (crossing frequencies from Im(D·conj E) = 0,
    Routh probes) on 4000 random sampled loops over decades (τ = 0 included, heading gains): equal
    regularity and finiteness of K*, K* and ω* to 10⁻⁹ where the route is conclusive (two root
    finders on the same polynomials: measured ≤ 10⁻¹¹), and few inconclusive rows."""
    from pfm_stability.vectorized.hurwitz_gain import hurwitz_gain_sets
    from pfm_stability.vectorized.polynomial import affine_stable_sets
    from pfm_stability.vectorized.sampled import bilinear_columns

    rng = np.random.default_rng(zlib.crc32(f"{hold}{compute_delay}".encode()))
    tau, T, k, c = _loops(rng, 4000, True)
    T = np.maximum(T, 1e-6)
    for rows in (np.flatnonzero(tau > 0), np.flatnonzero(tau == 0)):
        t = T[rows]
        Dc, Ec = bilinear_columns(tau[rows], t, k[rows], c[rows], hold, compute_delay)

        def mapping(w):
            return 2.0 * np.arctan(w * t[:, None] / 2.0) / t[:, None]

        sets, unsure = hurwitz_gain_sets(Dc, Ec, math.pi / t, mapping)
        D, E = np.stack(Dc, axis=1), np.stack(Ec, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            drop = -D[:, :1] / E[:, :1]
        drop = np.where((E[:, :1] != 0) & (drop > 0), drop, np.nan)
        expected = affine_stable_sets(D, E, drop, np.broadcast_to(math.pi / t[:, None], drop.shape), mapping)
        ok = ~unsure
        assert ok.mean() > 0.85
        assert np.array_equal(sets.regular[ok], expected.regular[ok])
        K, K_ref = sets.K_critical[ok], expected.K_critical[ok]
        assert np.array_equal(np.isfinite(K), np.isfinite(K_ref)) and np.array_equal(K == 0, K_ref == 0)
        edge = np.isfinite(K_ref) & (K_ref > 0)
        np.testing.assert_allclose(K[edge], K_ref[edge], rtol=1e-9)
        np.testing.assert_allclose(sets.frequency[ok][edge], expected.frequency[ok][edge], rtol=1e-9)


def test_closed_form_cubic_root_equals_the_newton_iteration():
    """`delay_verdicts._root` (Cardano / trigonometric start, two Newton steps, fallback) against
    `delay._newton_cubic_roots` (Newton from a Fourier start, iterated to round-off) on 10⁶ random
    loops over the whole parameter box (τk from 10⁻⁹, k from 10⁻⁶ to 10⁴, K from 10⁻⁸ to 10¹⁶) with
    one positive root. Both are accurate to a few ulps where the root is simple (the only root of
    a cubic with F(0) < 0 and one sign change of F is simple): relative agreement 10⁻¹²; and the
    closed form itself, not its fallback iteration, must serve at least 99% of these extreme
    points (about 0.06% fall back: the speed of the verdict path rests on that)."""
    from pfm_stability.numerics import delay
    from pfm_stability.vectorized import delay_verdicts

    rng = np.random.default_rng(20240611)
    n = 1_000_000
    tau, k, K = 10.0 ** rng.uniform(-13, 2, n), 10.0 ** rng.uniform(-6, 4, n), 10.0 ** rng.uniform(-8, 16, n)
    a, b, c, K2 = tau * tau, 1.0 - 2.0 * k * tau, k * k, K * K
    keep = (tau * k >= 1e-9) & (tau <= 100.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = np.sqrt(np.maximum(b * b - 3.0 * a * c, 0.0))
        c2 = (disc - b) / (3.0 * a)
        c1 = c / (3.0 * a * c2)
    dip = (k * tau > 2.0 + math.sqrt(3.0)) & (((a * c1 + b) * c1 + c) * c1 > K2) & (((a * c2 + b) * c2 + c) * c2 < K2)
    keep &= ~dip
    tau, k, K2 = tau[keep], k[keep], K2[keep]
    fallback = []
    iteration = delay_verdicts._newton_cubic_roots
    try:
        delay_verdicts._newton_cubic_roots = lambda *args: (fallback.append(args[0].size), iteration(*args))[1]
        y = delay_verdicts._root(tau, k, K2)
    finally:
        delay_verdicts._newton_cubic_roots = iteration
    expected = delay._newton_cubic_roots(tau * tau, 1.0 - 2.0 * k * tau, k * k, K2)[:, 0]
    assert np.all(expected > 0) and np.all(np.isfinite(y))
    np.testing.assert_allclose(y, expected, rtol=1e-12, atol=0.0)
    assert sum(fallback) < tau.size / 100


@pytest.mark.parametrize("plant, message", [({"plant_gain": 0.0}, r"plant_gain must be .*\[0.001, 100\].*got 0.0"),
                                            ({"dead_time": -0.1}, r"dead_time must be .*\[0, 10\] s.*got -0.1")])
def test_a_plant_out_of_its_range_is_refused_by_name(plant, message):
    """`loop_verdicts` takes the steering plant's gain and dead time (the sweep's config) with the scalar models' ranges
    and words (`parameters.RANGES`)."""
    with pytest.raises(ValueError, match=message):
        loop_verdicts("sampled", 0.3, 0.065, 2.0, 1.0, **plant)
