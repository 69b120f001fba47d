"""Any potential field in the KB loop (docs/fields.md): Khatib's and Ge & Cui's goal-aware law.

Ge & Cui, IEEE T-RA 16(5) 2000 ("GC2000", their equation numbers): the laws
P(d) = F_rep1/A and Q(d) = F_rep2/A (eq 1, 4, 8–11, 40) in units of the
attraction, every wall equilibrium, the gains N and c, the corridor's gain,
the frozen-goal convention and the 1/ρ_g term, the critical values of a law's
own parameters, N < 0 verdicts, and `pfm-stability report --law`.

Two routes are compared: the package's (`force_law.wall_equilibria`,
`corridor_gain`, in the ratio form R = P/(1 + Q)) and a 2-D force field built
here from `potentials` (F = F_rep1·n_OR + (F_att + F_rep2)·u, eq 9 and 18),
whose equilibria come from `scipy.optimize.brentq` and whose N is the finite
difference −∂δ/∂x of the force direction δ = atan2(F_x, F_y) (KB eq 9–11).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from pfm_stability.cli import main
from pfm_stability.analysis.criteria import analyze_corridor, analyze_wall
from pfm_stability.laws.fields import GnronLaw, KhatibLaw, finite_goal_gain, make_law
from pfm_stability.laws.force_law import PowerLaw, corridor_equilibria, corridor_gain, wall_equilibria, wall_gain
from pfm_stability.parameters import CARMEL, Corridor, Wall
from pfm_stability.laws.potentials import attraction_force, gnron_forces

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
SEC6 = {"xi": 1.0, "eta": 0.1, "rho0": 0.8, "m": 2.0}
"""GC2000 Sec VI gains (ξ = 1, η = 0.1, ρ0 = 0.8 m, m = n = 2)."""


def gnron(rho_g, n=2.0, **changes):
    p = {**SEC6, **changes}
    return GnronLaw(p["xi"], p["eta"], p["rho0"], p["m"], n, rho_g, p.get("delta", 0.0))


def khatib(rho_g, **changes):
    p = {**SEC6, **changes}
    return KhatibLaw(p["xi"], p["eta"], p["rho0"], p["m"], rho_g)


# ------------------------------------------------------------------ the 2-D field, built from the potentials
def field_2d(law, x, y_direction, walls):
    """(F_x, F_y) of the 2-D field at lateral positions x (arrays), the goal direction frozen (a unit vector).

    `walls`: (position of the wall's surface on the x axis, sign of its normal n_OR);
    each wall at distance ρ = |x − x_w| repels along n_OR with F_rep1 and pushes
    towards the goal with F_rep2 (GC2000 eq 9–11, 40), the attraction pulls with
    (m/2)ξρ_g^(m−1) (eq 1). Nothing here uses `pfm_stability.laws.fields`.
    """
    x = np.asarray(x, dtype=float)
    n = getattr(law, "n", 0.0)
    delta = getattr(law, "delta", 0.0)
    toward = attraction_force(law.rho_g, law.xi, law.m)
    Fx = np.zeros_like(x) + toward * y_direction[0]
    Fy = np.zeros_like(x) + toward * y_direction[1]
    for xw, normal in walls:
        rep1, rep2 = gnron_forces(np.abs(x - xw), law.rho_g, law.eta, law.rho0, n, delta)
        Fx = Fx + rep1 * normal + rep2 * y_direction[0]
        Fy = Fy + rep2 * y_direction[1]
    return Fx, Fy


def wall_reference(law, alpha):
    """Equilibria (brentq on a dense scan of F_x) and N = −dδ/dx (central difference) of a wall at x = 0, target at α."""
    u = (-math.cos(alpha), math.sin(alpha))
    walls = [(0.0, 1.0)]
    x = np.unique(np.concatenate([np.geomspace(1e-6 * law.rho0, law.rho0, 20001), law.rho0 * (1 - np.geomspace(1e-10, 0.5, 2000))]))
    Fx = field_2d(law, x, u, walls)[0]
    roots = [brentq(lambda s: float(field_2d(law, s, u, walls)[0]), x[i], x[i + 1], xtol=1e-300, rtol=1e-15)
             for i in np.flatnonzero(np.sign(Fx[:-1]) * np.sign(Fx[1:]) < 0)]
    out = []
    for d0 in roots:
        h = 1e-5 * min(d0, law.rho0 - d0)  # the law bends on the scale of the distance to ρ0 near its reach
        Fx2, Fy2 = field_2d(law, np.array([d0 - h, d0 + h]), u, walls)
        delta = np.arctan2(Fx2, Fy2)
        out.append((d0, -(delta[1] - delta[0]) / (2 * h)))
    return out


def corridor_reference(law, L, finite_goal=False):
    """N = −dδ/dx at the middle of a corridor (walls at ±L), target straight ahead: frozen, or a goal point at ρ_g ahead."""
    h = 1e-6 * L
    xs = np.array([-h, h])
    if not finite_goal:
        Fx, Fy = field_2d(law, xs, (0.0, 1.0), [(-L, 1.0), (L, -1.0)])
    else:  # the goal at (0, ρ_g): its direction and distance change with x
        Fx, Fy = np.zeros(2), np.zeros(2)
        for i, x in enumerate(xs):
            rg = math.hypot(x, law.rho_g)
            moved = dataclasses.replace(law, rho_g=rg)
            fx, fy = field_2d(moved, np.array([x]), (-x / rg, law.rho_g / rg), [(-L, 1.0), (L, -1.0)])
            Fx[i], Fy[i] = fx[0], fy[0]
    delta = np.arctan2(Fx, Fy)
    return -(delta[1] - delta[0]) / (2 * h)


# ------------------------------------------------------------------ the laws themselves
def test_khatib_local_exponent_and_the_wall_identity():
    """Khatib's ν(d) = −dP′/P = (3 − 2d/ρ0)/(1 − d/ρ0) (docs/fields.md), and N = cot α·ν(d0)/d0 at its wall
    equilibrium (Q = 0): both closed forms of the law, so to round-off (1e-12)."""
    law = khatib(2.0)
    d = np.linspace(0.05, 0.79, 50)
    np.testing.assert_allclose(law.local_exponent(d), (3 - 2 * d / law.rho0) / (1 - d / law.rho0), rtol=1e-12)
    for alpha_deg in (20.0, 45.0, 70.0):
        alpha = math.radians(alpha_deg)
        (e,) = wall_equilibria(law, alpha)
        assert e.N == pytest.approx(float(law.local_exponent(e.d0)) / e.d0 / math.tan(alpha), rel=1e-12)
        assert e.c == 0.0


def test_power_law_identity_and_unchanged_gains():
    """KB's power law: N = cot α·n/d0 (ν = n, KB eq 11 with eq 23) to round-off, one equilibrium, the same
    numbers as `wall_gain` (bit for bit: the closed path is kept), and Q = 0, c = 0."""
    law = PowerLaw(0.8, 2.0, 0.8)
    for alpha in (0.2, 0.7, 1.2):
        (e,) = wall_equilibria(law, alpha)
        assert (e.d0, e.N) == wall_gain(law, alpha)
        assert e.N == pytest.approx(law.n / e.d0 / math.tan(alpha), rel=1e-13)
    assert corridor_equilibria(law, 0.9, 0.8) == (corridor_equilibria(law, 0.9, 0.8)[0],)
    assert corridor_gain(law, 0.9) == -2.0 * law.slope(0.9)
    assert float(law.goal_force(0.5)) == 0.0 and not law.has_goal_part


def test_only_the_ratio_eta_over_xi_enters():
    """P and Q scale with η/ξ (GC2000 eq 1, 10, 11 over A): the basis of ξ* = ξη/η* (1e-13)."""
    a, b = gnron(1.7, n=1.3, delta=0.01), gnron(1.7, n=1.3, delta=0.01, xi=3.0, eta=0.3)
    d = np.linspace(0.01, 0.79, 40)
    for fa, fb in zip(a.terms(d), b.terms(d)):
        np.testing.assert_allclose(fa, fb, rtol=1e-13)


def test_make_law_and_its_errors():
    """`make_law` builds every law of FORCE_LAWS; a parameter a law does not take, or a missing goal distance, is a ValueError naming it."""
    assert make_law("power", ROBOT, CONTROLLER) == PowerLaw(CONTROLLER.f, CONTROLLER.n, ROBOT.W)
    assert make_law("khatib", ROBOT, CONTROLLER, goal_distance=2.0) == khatib(2.0)
    assert make_law("gnron", ROBOT, CONTROLLER, goal_distance=2.0, delta=None) == gnron(2.0)
    assert make_law("grid", ROBOT, CONTROLLER, cell_ratio=0.01).ratio == 0.01
    with pytest.raises(ValueError, match=r"^xi applies to khatib or gnron, not to law power$"):
        make_law("power", ROBOT, CONTROLLER, xi=1.0)
    with pytest.raises(ValueError, match=r"^delta applies to gnron, not to law khatib$"):
        make_law("khatib", ROBOT, CONTROLLER, goal_distance=1.0, delta=0.1)
    with pytest.raises(ValueError, match=r"^law gnron needs goal_distance"):
        make_law("gnron", ROBOT, CONTROLLER)
    with pytest.raises(ValueError, match=r"^eta must be a finite number in \[1e-06, 1000000\]"):
        make_law("khatib", ROBOT, CONTROLLER, goal_distance=1.0, eta=0.0)


# ------------------------------------------------------------------ GC2000 in the KB loop: the tables of docs/fields.md
CORRIDOR_TABLE = [  # ρ_g, N conventional, N goal-aware, τNV of both (L = 0.4 m, Sec VI gains, m = n = 2; τ = 0.3 s, V = 0.8 m/s)
    (0.5, 31.25, 5.952, 7.50, 1.43),
    (1.0, 15.625, 11.905, 3.75, 2.86),
    (1.1456, 13.639, 13.638, 3.27, 3.27),
    (2.0, 7.8125, 23.810, 1.88, 5.71),
    (5.0, 3.125, 59.524, 0.75, 14.3),
    (10.0, 1.5625, 119.05, 0.375, 28.6),
]


@pytest.mark.parametrize("rho_g, conventional, goal_aware, tau_conv, tau_gc", CORRIDOR_TABLE)
def test_corridor_table(rho_g, conventional, goal_aware, tau_conv, tau_gc):
    """The corridor gain with Khatib's law (N_conv = −2P′(L)) and the goal-aware law (N_GC = −2P′/(1 + 2Q)) at
    L = 0.4 m (docs/fields.md, table 1): to the table's 5 digits (rel 1e-4); τNV at τ = 0.3 s, V = 0.8 m/s to its
    3 digits (rel 4e-3); N_finite_goal = N + 1/ρ_g (exactly, by definition)."""
    Nk, Ng = corridor_gain(khatib(rho_g), 0.4), corridor_gain(gnron(rho_g), 0.4)
    assert Nk == pytest.approx(conventional, rel=1e-4) and Ng == pytest.approx(goal_aware, rel=1e-4)
    assert 0.3 * 0.8 * Nk == pytest.approx(tau_conv, rel=4e-3) and 0.3 * 0.8 * Ng == pytest.approx(tau_gc, rel=4e-3)
    assert finite_goal_gain(gnron(rho_g), Ng) == Ng + 1 / rho_g and finite_goal_gain(PowerLaw(1, 2, 1), 3.0) is None


def test_corridor_crossover():
    """For n = m = 2 the two laws give the same corridor N at ρ_g* = √(1 + 2ηc(L)²/ξ), c = 1/L − 1/ρ0
    (docs/fields.md): 1.14564 at L = 0.4 m; equal there to 1e-12, and the goal-aware N is the larger beyond."""
    c = 1 / 0.4 - 1 / 0.8
    star = math.sqrt(1 + 2 * 0.1 * c**2 / 1.0)
    assert star == pytest.approx(1.1456, abs=5e-5)
    assert corridor_gain(gnron(star), 0.4) == pytest.approx(corridor_gain(khatib(star), 0.4), rel=1e-12)
    assert corridor_gain(gnron(1.01 * star), 0.4) > corridor_gain(khatib(1.01 * star), 0.4)
    assert corridor_gain(gnron(0.99 * star), 0.4) < corridor_gain(khatib(0.99 * star), 0.4)


WALL_TABLE = [  # ρ_g, α (deg), Khatib d0 / N, goal-aware d0 / N (Sec VI gains)
    (2, 30, 0.32488, 19.640, 0.45150, 14.979),
    (2, 60, 0.37571, 5.9708, 0.51450, 5.1000),
    (2, 80, 0.48433, 1.6508, 0.62686, 1.8317),
    (5, 30, 0.25116, 23.844, 0.55541, 15.837),
    (5, 60, 0.29364, 7.0388, 0.61302, 5.7978),
    (5, 80, 0.38951, 1.7876, 0.70313, 2.5603),
]


@pytest.mark.parametrize("rho_g, alpha_deg, dk, Nk, dg, Ng", WALL_TABLE)
def test_wall_table(rho_g, alpha_deg, dk, Nk, dg, Ng):
    """Wall equilibria and gains of both laws with the goal frozen (docs/fields.md, table 2): one equilibrium each,
    to the table's 5 digits (d0 to 1e-5 m, N to rel 1e-4)."""
    alpha = math.radians(alpha_deg)
    for law, d0, N in ((khatib(rho_g), dk, Nk), (gnron(rho_g), dg, Ng)):
        (e,) = wall_equilibria(law, alpha)
        assert e.d0 == pytest.approx(d0, abs=1e-5) and e.N == pytest.approx(N, rel=1e-4)


THREE = {"xi": 1.0, "eta": 1.0, "rho0": 0.8, "m": 2.0}


def test_three_equilibria_and_the_unstable_one():
    """n = 0.5, ξ = η = 1, ρ0 = 0.8, ρ_g = 0.02, α = 60°: R = P/(1 + Q) is not monotone and the wall has three
    equilibria (docs/fields.md, table 3), to the table's 5 digits. The middle one has N < 0: every model says
    "unstable" with the reason, margin −1 and V* = T* = k* = 0; the others are decided by the models."""
    law = gnron(0.02, n=0.5, **THREE)
    got = wall_equilibria(law, math.radians(60))
    assert [round(e.d0, 5) for e in got] == [0.22074, 0.59944, 0.76832]
    for e, N in zip(got, (1.6264, -1.4487, 13.261)):
        assert e.N == pytest.approx(N, rel=1e-4)
    result = analyze_wall(ROBOT, CONTROLLER, Wall.from_degrees(60), models=("continuous", "sampled"), law=law)
    assert [e.d0 for e in result.equilibria] == [e.d0 for e in got] and result.d0 == got[0].d0
    middle = result.equilibria[1]
    for v in middle.models.values():
        assert v.verdict == "unstable" and v.margin == -1.0 and "N < 0" in v.reason
        assert (v.critical.V_critical, v.critical.T_critical, v.critical.k_critical) == (0.0, 0.0, 0.0)
        assert v.critical.alpha_critical_deg == 90.0 and math.isnan(v.critical.eta_critical)
        assert v.rightmost_root is None or v.rightmost_root.real > 0
    assert {v.verdict for v in result.equilibria[0].models.values()} == {"stable"}
    assert {v.verdict for v in result.equilibria[2].models.values()} == {"unstable"}
    assert all(v.reason is None for e in (result.equilibria[0], result.equilibria[2]) for v in e.models.values())


# ------------------------------------------------------------------ the independent route: the 2-D field
RNG = np.random.default_rng(20000516)


def _random_law(kind):
    """Random laws far from the paper's gains: ξ, η over four decades, ρ0 from 0.2 to 5 m, m and n not 2, δ sometimes."""
    xi, eta = 10 ** RNG.uniform(-2, 2), 10 ** RNG.uniform(-2, 2)
    rho0, m, rho_g = RNG.uniform(0.2, 5.0), float(RNG.choice([1.0, 1.5, 2.0, 3.3])), 10 ** RNG.uniform(-1.3, 1.3)
    if kind == "khatib":
        return KhatibLaw(xi, eta, rho0, m, rho_g)
    return GnronLaw(xi, eta, rho0, m, RNG.uniform(0.2, 4.0), rho_g, float(RNG.choice([0.0, 0.0, 0.05 * rho0])))


LAWS = [_random_law(kind) for kind in ("khatib", "gnron") for _ in range(10)]


@pytest.mark.parametrize("law", LAWS, ids=[f"{law.key}{i}" for i, law in enumerate(LAWS)])
def test_wall_against_the_2d_field(law):
    """Every wall equilibrium and its N against the 2-D field at three angles: the equilibria to 1e-9 relative
    (both routes narrow to round-off; 1e-9 allows the field's own cancellation), N to 1e-6 (a central difference
    with h = 1e-5 of the distance to the wall or to ρ0, whichever is smaller: truncation ~1e-10, round-off
    ~1e-10 relative, times the conditioning of δ near an equilibrium close to ρ0). The package's scan
    resolves roots a factor 1.037 apart: a reference root closer than that to another is allowed to be missed."""
    for alpha_deg in (15.0, 50.0, 80.0):
        alpha = math.radians(alpha_deg)
        ours, ref = wall_equilibria(law, alpha), wall_reference(law, alpha)
        for e in ours:
            d_ref, N_ref = min(ref, key=lambda r: abs(r[0] - e.d0))
            assert e.d0 == pytest.approx(d_ref, rel=1e-9)
            assert e.N == pytest.approx(N_ref, rel=1e-6, abs=1e-9 * abs(N_ref) + 1e-9)
        matched = {min(ref, key=lambda r: abs(r[0] - e.d0))[0] for e in ours}
        for d_ref, _ in ref:
            if d_ref not in matched:
                assert any(0 < abs(math.log(d_ref / other)) < math.log(1.04) for other, _ in ref if other != d_ref)
        signs = [e.N > 0 for e in ours]
        assert all(a != b for a, b in zip(signs, signs[1:]))  # stable and unstable equilibria alternate


@pytest.mark.parametrize("law", LAWS[::2], ids=[f"{law.key}{2 * i}" for i, law in enumerate(LAWS[::2])])
def test_corridor_against_the_2d_field(law):
    """The middle of a corridor: N = −2P′(L)/(1 + 2Q(L)) against −dδ/dx of two walls' field (frozen goal), and
    N_finite_goal = N + 1/ρ_g against a goal point ρ_g straight ahead (its direction and distance follow the robot):
    both to 1e-6 (central differences, as above), at two half-widths inside ρ0."""
    for L in (0.3 * law.rho0, 0.8 * law.rho0):
        N = corridor_gain(law, L)
        assert N == pytest.approx(corridor_reference(law, L), rel=1e-6)
        assert finite_goal_gain(law, N) == pytest.approx(corridor_reference(law, L, finite_goal=True), rel=1e-6)
    assert corridor_equilibria(law, 0.5 * law.rho0)[0].x0 == 0.0


def test_corridor_off_centre_equilibria():
    """A law that rises over part of its range gives equilibria off the centre line, in ± pairs: P(d) = d e^(−d/0.1)
    (not a potential of GC2000: a law built in code to exercise the scan) in a corridor of half-width 0.15 m,
    checked against brentq on F_x (1e-12: both narrow to round-off). They are unstable (N < 0), the middle stable."""

    class Bump(PowerLaw):
        monotone = False

        def force(self, d):
            d = np.asarray(d, dtype=float)
            return d * np.exp(-d / 0.1)

        def slope(self, d):
            d = np.asarray(d, dtype=float)
            return (1 - d / 0.1) * np.exp(-d / 0.1)

    law = Bump(1.0, 1.0, 1.0)
    got = corridor_equilibria(law, 0.15, 0.0)
    ref = brentq(lambda x: float(law.force(0.15 + x) - law.force(0.15 - x)), 0.01, 0.1499, xtol=1e-300, rtol=1e-15)
    assert [e.x0 for e in got] == pytest.approx([-ref, 0.0, ref], rel=1e-12, abs=1e-15)
    assert got[0].N == got[2].N < 0 < got[1].N


# ------------------------------------------------------------------ critical values of the law's parameters
def _following_gain(law, alpha, d0, name, value, steps=60):
    """N of the wall equilibrium at d0 followed as `name` (a law parameter, or "alpha") moves to `value` in
    60 small steps, the nearest root each step: a tracker independent of `fields.Branch`."""
    start = alpha if name == "alpha" else getattr(law, name)

    def at(p, polish):
        if name == "alpha":
            return wall_equilibria(law, p, polish=polish)
        return wall_equilibria(dataclasses.replace(law, **{name: p}), alpha, polish=polish)

    for t in np.linspace(0.0, 1.0, steps + 1)[1:-1]:
        p = start + t * (value - start) if name == "alpha" else start * (value / start) ** t
        d0 = min(at(p, False), key=lambda e: abs(e.d0 - d0)).d0
    return min(at(value, True), key=lambda e: abs(e.d0 - d0)).N


def test_critical_values_put_back():
    """η*, ρ0*, ξ*, α* and V* of a wall (goal-aware law, three equilibria) and L*, η*, ρ0* of a corridor, put back,
    give N·V = NV* of that model (1e-7: the crossing is narrowed to 1e-9 in the parameter) on the equilibrium
    followed, and the verdict there changes across ±1 % of the value."""
    law, alpha, V = gnron(0.02, n=0.5, **THREE), math.radians(60), ROBOT.V
    result = analyze_wall(ROBOT, CONTROLLER, Wall(alpha), models=("sampled",), law=law)
    for e in (result.equilibria[0], result.equilibria[2]):
        v = e.models["sampled"]
        target = v.NV_critical / V
        c = v.critical
        changes = {"eta": c.eta_critical, "rho0": c.rho0_critical, "xi": c.xi_critical}
        for name, value in changes.items():
            if math.isfinite(value):
                assert _following_gain(law, alpha, e.d0, name, value) == pytest.approx(target, rel=1e-7), name
                sides = {_following_gain(law, alpha, e.d0, name, value * f) * V < v.NV_critical for f in (0.99, 1.01)}
                assert sides == {True, False}, name
        assert _following_gain(law, alpha, e.d0, "alpha", c.alpha_critical) == pytest.approx(target, rel=1e-7)
        assert e.N * c.V_critical == pytest.approx(v.NV_critical, rel=1e-12)
    corridor = analyze_corridor(ROBOT, CONTROLLER, Corridor(0.6), models=("sampled",), law=gnron(2.0))
    v = corridor.models["sampled"]
    assert corridor_gain(gnron(2.0), v.critical.L_critical) * V == pytest.approx(v.NV_critical, rel=1e-7)
    assert corridor_gain(gnron(2.0, eta=v.critical.eta_critical), 0.6) * V == pytest.approx(v.NV_critical, rel=1e-7)
    assert corridor_gain(gnron(2.0, xi=v.critical.xi_critical), 0.6) * V == pytest.approx(v.NV_critical, rel=1e-7)
    assert corridor.N_finite_goal == pytest.approx(corridor.N + 0.5, rel=1e-15)


def test_no_value_helps_and_no_limit():
    """Where no value of a parameter gives stability the answer says so: Khatib's wall at 60° (ρ_g = 2) has
    N >= cot α·min ν(d)/d > NV*/V for every η (min of (3 − 2u)/((1 − u)uρ0) is 9.33/m): η* and ξ* are NaN
    (JSON null); a model stable at every NV (continuous with τ = 0) gives η* = inf ("no limit") and α* = 0."""
    law = khatib(2.0)
    v = analyze_wall(ROBOT, CONTROLLER, Wall.from_degrees(60), models=("continuous",), law=law).models["continuous"]
    assert v.verdict == "unstable" and math.isnan(v.critical.eta_critical) and math.isnan(v.critical.xi_critical)
    assert "eta" not in analyze_report_remedy(law)
    stable = analyze_wall(ROBOT.replace(tau=0.0), CONTROLLER.replace(T=0.0), Wall.from_degrees(60), models=("continuous",), law=law)
    c = stable.models["continuous"].critical
    assert (c.alpha_critical, c.eta_critical, c.rho0_critical, c.xi_critical) == (0.0, math.inf, math.inf, math.inf)


def analyze_report_remedy(law):
    from pfm_stability.report.stability import build_report

    report = build_report(ROBOT, CONTROLLER, alpha_deg=60.0, models=("continuous",), law=law)
    return report.remedies[("wall", "continuous")]


# ------------------------------------------------------------------ the command line
def _run(*argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def test_report_law_option_json_and_text():
    """`report --law gnron`: the three equilibria in environment.wall.equilibria (sorted by d0, each with every
    model's verdict), the top-level wall verdicts are the first's, the law and its parameters are listed, the
    corridor carries c and N_finite_goal, and the text shows each equilibrium with the reason of the unstable one."""
    argv = ["report", "--law", "gnron", "--goal-distance", "0.02", "--goal-exponent", "0.5", "--eta", "1", "--alpha", "60",
            "--L", "0.6", "--model", "sampled"]
    code, out, err = _run(*argv, "--format", "json")
    assert code == 0, err
    data = json.loads(out)
    eqs = data["environment"]["wall"]["equilibria"]
    assert [round(e["d0"], 5) for e in eqs] == [0.22074, 0.59944, 0.76832] and eqs[1]["N"] < 0
    assert eqs[0]["models"] == data["wall"] and "reason" in eqs[1]["models"]["sampled"]
    assert data["law"]["name"] == "gnron" and data["law"]["parameters"]["goal_exponent"] == 0.5
    assert "f" not in data["inputs"] and data["inputs"]["rho0"]["source"].startswith("default")
    corridor = data["environment"]["corridor"]
    assert corridor["c"] == 0.0 and corridor["N_finite_goal"] == pytest.approx(corridor["N"] + 50.0)
    assert {"eta_critical", "rho0_critical", "xi_critical"} <= set(data["corridor"]["sampled"])
    code, text, _ = _run(*argv)
    assert code == 0 and "equilibrium 2 of 3" in text and "N < 0" in text and "Force law: goal-aware" in text


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--xi", "1"], "--xi applies to --law khatib or gnron, not to --law power"),
        (["--law", "khatib"], "--law khatib needs --goal-distance"),
        (["--law", "khatib", "--goal-distance", "1", "--goal-exponent", "1"], "--goal-exponent applies to --law gnron or fuzzy, not to --law khatib"),
        (["--law", "gnron", "--goal-distance", "1", "--f", "2"], "--f applies to --law power or grid, not to --law gnron"),
        (["--law", "grid", "--rho0", "1"], "--rho0 applies to --law khatib, gnron, velocity, velocity-gated or fuzzy, not to --law grid"),
        (["--law", "power", "--cell-ratio", "0.1"], "--cell-ratio applies to --law grid, not to --law power"),
    ],
)
def test_law_option_errors(argv, message):
    """A law option with a law that does not take it, or a missing goal distance: exit 2, one line naming the option
    (its range: tests/test_cli_fuzz.py::test_every_range_end_is_accepted_or_rejected_as_stated)."""
    code, out, err = _run("report", "--L", "1", *argv)
    assert code == 2 and out == "" and err.count("\n") == 1 and message in err


def test_power_law_option_is_the_default():
    """`--law power` is the default: the same bytes."""
    assert _run("report", "--alpha", "20", "--L", "0.9", "--format", "json") == _run("report", "--alpha", "20", "--L", "0.9", "--law", "power", "--format", "json")


def test_curves_refuse_what_is_not_one_curve():
    """Boundary curves invert N in d0 or in the law's strength; for a law where that is not monotone they say so
    (ValueError naming the quantity) instead of drawing one branch; V*(L) where a law with a reach gives N = 0 is
    inf, without a numpy warning; α*(V) of a goal-aware law that is monotone there puts N·V on NV* (1e-9)."""
    import warnings

    from pfm_stability.analysis.curves import corridor_V_curves, wall_alpha_curves, wall_f_curves

    with pytest.raises(ValueError, match="is not monotone for goal-aware repulsion"):
        wall_f_curves(ROBOT, CONTROLLER, 1.0, np.array([0.5]), law=gnron(2.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert corridor_V_curves(ROBOT, CONTROLLER, np.array([0.5, 1.0]), models=None, law=khatib(2.0))[0].y[1] == math.inf
    V = np.array([0.3, 0.8])
    for curve in wall_alpha_curves(ROBOT, CONTROLLER, V, law=gnron(2.0)):
        for v, alpha in zip(V, curve.y):
            assert wall_equilibria(gnron(2.0), alpha)[0].N * v == pytest.approx(curve.NV_critical, rel=1e-9)

