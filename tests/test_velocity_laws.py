"""Ge & Cui 2002's velocity potentials as lateral laws (`velocity_laws`).

Gains are checked by an independent route: central differences of the full 2-D force
(position attraction with frozen direction, wall repulsion, and `VelocityAttraction.force`
evaluated at the robot's velocity V(sin θ, cos θ)), N = −∂F_x/∂x / F_y and c = −∂F_x/∂θ / F_y
(docs/velocity_and_fuzzy.md). Forces of the velocity-gated repulsion are checked against
finite differences of its potential. Printed numbers are compared to half a unit of their
last printed digit.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pfm_stability.laws.fields import GnronLaw, KhatibLaw
from pfm_stability.laws.velocity_laws import (
    VARIANTS,
    VelocityAttraction,
    VelocityGatedRepulsion,
    stall_band,
)


def _khatib(eta, rho0, Fa, rho_g):
    """Khatib's law in units of F_a: KhatibLaw divides by A = ξρ_g (m = 2), so ξ = F_a/ρ_g."""
    return KhatibLaw(Fa / rho_g, eta, rho0, 2.0, rho_g)


def test_damping_ratio_and_hard_landing():
    """GC2002 Fig 8 ζ labels (ζ = α_v/√(2α_p): 0, 0.2, 1, 2; ω_n = 0.1) and the Fig 12 closing speed 0.0625 m/s.

    The closing speed is also checked by integrating ẍ = α_p − 2α_v ẋ (m = 1, n = 2, 1-D, far
    from the target) for 60 s: the speed is then within e^(−0.8·60) of the terminal speed.
    """
    zetas = [VelocityAttraction(0.005, a).damping_ratio() for a in (0.0, 0.02, 0.1, 0.2)]
    np.testing.assert_allclose(zetas, [0.0, 0.2, 1.0, 2.0], rtol=1e-12)
    assert VelocityAttraction(0.005, 0.1).natural_frequency() == pytest.approx(0.1, rel=1e-12)
    att = VelocityAttraction(0.05, 0.4, m=1, n=2)
    assert att.hard_landing_speed() == pytest.approx(0.0625, abs=5e-5)

    def rhs(t, y):
        return [y[1], float(att.force((y[0], 0.0), (y[1], 0.0), (1e3, 0.0))[0])]

    sol = solve_ivp(rhs, (0, 60), [0.0, 0.0], rtol=1e-10, atol=1e-12)
    assert sol.y[1, -1] == pytest.approx(att.hard_landing_speed(), rel=1e-9)
    n3 = VelocityAttraction(0.05, 0.4, m=1, n=3)
    assert 3 * 0.4 * n3.hard_landing_speed() ** 2 == pytest.approx(0.05, rel=1e-12)
    with pytest.raises(ValueError, match="m must be 1"):
        VelocityAttraction(0.05, 0.4).hard_landing_speed()


def _fd_gains(att, law, Fa, alpha, V, x0, h=1e-6):
    """N and c of the full 2-D force by central differences (target direction frozen at angle α)."""

    def force(d, theta):
        P, Q = float(law.force(d)), float(law.goal_force(d))
        static = np.array([Fa * P - Fa * (1 + Q) * math.cos(alpha), Fa * (1 + Q) * math.sin(alpha)])
        v = V * np.array([math.sin(theta), math.cos(theta)])
        return static + att.force((0.0, 0.0), v)  # e = 0: only the velocity part

    Fy = force(x0, 0.0)[1]
    N = -(force(x0 + h, 0)[0] - force(x0 - h, 0)[0]) / (2 * h) / Fy
    c = -(force(x0, h)[0] - force(x0, -h)[0]) / (2 * h) / Fy
    return N, c


def test_velocity_attraction_force_is_the_printed_gradient():
    """F_att = mα_p‖e‖^(m−1) n_RT + nα_v‖ė‖^(n−1) n_VRT (eq 7–9) equals −∇_p U − ∇_v U of eq (1) (FD, rel 1e-7)."""
    rng = np.random.default_rng(11)
    for _ in range(5):
        att = VelocityAttraction(rng.uniform(0.01, 2), rng.uniform(0.01, 2), rng.uniform(1.2, 3), rng.uniform(1.2, 3))
        p, v, pt, vt = (rng.normal(size=2) for _ in range(4))

        def U(p, v):
            return att.alpha_p * np.linalg.norm(pt - p) ** att.m + att.alpha_v * np.linalg.norm(vt - v) ** att.n

        h = 1e-6
        grad = [(U(p + h * e, v) - U(p - h * e, v)) / (2 * h) + (U(p, v + h * e) - U(p, v - h * e)) / (2 * h) for e in np.eye(2)]
        np.testing.assert_allclose(att.force(p, v, pt, vt), -np.array(grad), rtol=1e-7, atol=1e-9)


def test_steering_gains_by_finite_differences_random():
    """N = N_static/(1 − q), c = q/(1 − q) against central differences of the 2-D force at random parameters.

    Laws: Khatib and Ge & Cui's goal-aware law (Q ≠ 0), n = 1.5…3, V up to where q < 0.9.
    h = 1e-6 on forces of order F_a: FD error ~1e-9 relative; tolerance 1e-6 relative.
    """
    rng = np.random.default_rng(5)
    done = 0
    for i in range(8):
        rho_g, rho0 = rng.uniform(0.5, 5), rng.uniform(0.5, 4)
        alpha_p, m, n = rng.uniform(0.01, 1), rng.uniform(1, 3), rng.uniform(1.5, 3)
        Fa = m * alpha_p * rho_g ** (m - 1)
        law = _khatib(rng.uniform(0.05, 2), rho0, Fa, rho_g) if i % 2 else GnronLaw(Fa / rho_g, rng.uniform(0.05, 2), rho0, 2.0, 1.0, rho_g)
        alpha, V = math.radians(rng.uniform(20, 80)), rng.uniform(0.1, 3.0)
        q_static = rng.uniform(0.05, 0.9)  # α_v chosen so that q (without Q) is this
        att = VelocityAttraction(alpha_p, q_static * Fa * math.sin(alpha) / (n * V ** (n - 1)), m, n)
        for e in att.steering_wall_equilibria(law, alpha, V, rho_g):
            N, c = _fd_gains(att, law, Fa, alpha, V, e.x0)
            assert e.N == pytest.approx(N, rel=1e-6) and e.c == pytest.approx(c, rel=1e-6, abs=1e-9)
            done += 1
    assert done >= 8


def test_steering_q_closed_form_and_no_forward_force():
    """n = 2: q = 2α_vV/(F_a sin α) exactly as stated; q ≥ 1 is a ValueError naming V."""
    att = VelocityAttraction(0.5, 0.2)
    rho_g, alpha, V = 2.0, math.radians(60), 0.8
    Fa = att.position_force(rho_g)
    law = _khatib(0.3, 1.5, Fa, rho_g)
    (static,) = [e for e in __import__("pfm_stability.laws.force_law", fromlist=["x"]).wall_equilibria(law, alpha)]
    (e,) = att.steering_wall_equilibria(law, alpha, V, rho_g)
    q = 2 * 0.2 * V / (Fa * math.sin(alpha))
    assert e.N == pytest.approx(static.N / (1 - q), rel=1e-12) and e.c == pytest.approx(q / (1 - q), rel=1e-12)
    (mid,) = [x for x in att.steering_corridor_equilibria(law, 0.5, V, rho_g) if x.x0 == 0.0]
    assert mid.c == pytest.approx(2 * 0.2 * V / (Fa - 2 * 0.2 * V), rel=1e-12)
    with pytest.raises(ValueError, match="^V must be below"):
        att.steering_wall_equilibria(law, alpha, Fa * math.sin(alpha) / 0.4 * 1.01, rho_g)


def test_holonomic_gains():
    """Khatib corridor η = 0.3, ρ0 = 2, L = 0.5, α_v = 0.1: κ = 24, c_h = 0.2 (exact); FD route for n = 3 at V = 0.7."""
    att = VelocityAttraction(0.005, 0.1)
    rho_g = 3.0
    Fa = att.position_force(rho_g)
    law = _khatib(0.3, 2.0, Fa, rho_g)
    mid = [g for g in att.holonomic_corridor_gains(law, 0.5, rho_g) if g.x0 == 0.0][0]
    assert mid.kappa == pytest.approx(24.0, rel=1e-12) and mid.c_h == pytest.approx(0.2, rel=1e-12)
    att3 = VelocityAttraction(0.005, 0.1, n=3)
    (g,) = att3.holonomic_wall_gains(law, math.radians(40), rho_g, mass=2.0, V=0.7)
    h = 1e-6
    fx = lambda d: Fa * float(law.force(d)) - Fa * math.cos(math.radians(40))
    assert g.kappa == pytest.approx(-(fx(g.x0 + h) - fx(g.x0 - h)) / (2 * h) / 2.0, rel=1e-6)
    fv = lambda vx: att3.force((0, 0), (vx, 0.7), (0, 5.0))[0]
    assert g.c_h == pytest.approx(-(fv(h) - fv(-h)) / (2 * h) / 2.0, rel=1e-6)
    with pytest.raises(ValueError, match="^V must be > 0"):
        att3.holonomic_wall_gains(law, 0.5, rho_g)


def _obstacles(rng):
    """A random point, ball and wall around the origin, each with its `where`/radius."""
    c = rng.uniform(0.6, 1.5, 2) * rng.choice([-1, 1], 2)
    normal = -c / np.linalg.norm(c)
    return [("point", c, 0.0), ("ball", c, rng.uniform(0.05, 0.4)), ("wall", np.array([c, normal]), 0.0)]


def test_repulsion_is_the_gradient_of_its_potential():
    """F = −∇_p U − ∇_v U (eq 13) for point, ball and wall, against FD of U (h = 1e-7, rel 1e-5).

    Only states where the repulsion is active and stays active within ±h are used. The ball's
    tangential part uses the centre distance; the printed eq (20) (clearance ρ_s) is shown to differ.
    """
    rng = np.random.default_rng(17)
    counted = {"point": 0, "ball": 0, "wall": 0}
    for _ in range(60):
        rep = VelocityGatedRepulsion(rng.uniform(0.05, 1), rng.uniform(1, 4), rng.uniform(0.5, 3), robot_radius=rng.uniform(0, 0.1))
        for kind, where, r in _obstacles(rng):
            v, vo = rng.normal(scale=0.6, size=2), rng.normal(scale=0.2, size=2)
            res = rep.evaluate((0, 0), v, kind, where, r, vo)
            if res.status != "active" or res.D < 0.05 or rep.rho0 - res.D < 1e-3 or res.closing_speed < 1e-3:
                continue
            h = 1e-7
            U = lambda p, v: rep.evaluate(p, v, kind, where, r, vo).potential
            g = [(U(h * e, v) - U(-h * e, v) + U((0, 0), v + h * e) - U((0, 0), v - h * e)) / (2 * h) for e in np.eye(2)]
            np.testing.assert_allclose(res.force, -np.array(g), rtol=1e-5, atol=1e-7 * np.abs(res.force).max())
            counted[kind] += 1
    assert min(counted.values()) >= 3
    # the printed eq (20) for a ball divides by ρ_s: it overestimates the tangential part by (ρ_s + r)/ρ_s
    rep = VelocityGatedRepulsion(0.5, 3.0, 1.0)
    res = rep.evaluate((0, 0), (0.4, 0.3), "ball", (1.0, 0.2), 0.3)
    n = np.array([1.0, 0.2]) / math.hypot(1.0, 0.2)
    tang = res.force - (res.force @ n) * n
    R = math.hypot(1.0, 0.2)
    assert np.linalg.norm(tang) * R / (R - 0.3) > 1.3 * np.linalg.norm(tang)


def test_wall_has_no_tangential_part():
    """A wall's repulsion lies along its normal with magnitude η(1 + v_RO/a_max)/D² (F_rep2 ≡ 0), exact to rounding."""
    rep = VelocityGatedRepulsion(0.2, 2.0, 1.5)
    res = rep.evaluate((0.3, 0.0), (0.5, 0.9), "wall", ((1.0, 0.0), (-1.0, 0.0)))
    D = 0.7 - 0.5**2 / 3.0
    np.testing.assert_allclose(res.force, [-0.2 * (1 + 0.5 / 1.5) / D**2, 0.0], rtol=1e-14, atol=0)


def test_events_never_nan():
    """The jumps at v_RO = 0 (by η/ρ_s²) and at D = ρ0; collision is flagged; a random sweep including extremes gives no NaN."""
    rep = VelocityGatedRepulsion(0.2, 2.0, 1.0)
    wall = ((1.0, 0.0), (-1.0, 0.0))
    assert rep.evaluate((0, 0), (0.0, 1.0), "wall", wall).status == "inactive"
    just = rep.evaluate((0, 0), (1e-12, 1.0), "wall", wall)
    assert just.status == "active" and -just.force[0] == pytest.approx(0.2 / 1.0**2, rel=1e-9)
    edge_in = rep.evaluate((-0.999999, 0), (1e-9, 0), "wall", wall)
    edge_out = rep.evaluate((-1.000001, 0), (1e-9, 0), "wall", wall)
    assert edge_in.status == "active" and edge_out.status == "inactive"
    assert -edge_in.force[0] == pytest.approx(0.2 / 4.0, rel=1e-5)  # the jump at D = ρ0: η/ρ0²
    hit = rep.evaluate((0, 0), (2.0, 0), "wall", wall)
    assert hit.collision and hit.force is None and hit.D <= 0
    with pytest.raises(ValueError, match="collision"):
        rep.potential((0, 0), (2.0, 0), "wall", wall)
    rng = np.random.default_rng(1)
    for _ in range(300):
        for variant in VARIANTS:
            r = VelocityGatedRepulsion(10 ** rng.uniform(-6, 6), 10 ** rng.uniform(-3, 4), 10 ** rng.uniform(-3, 6), variant)
            kind, where, rad = _obstacles(rng)[rng.integers(3)]
            out = r.evaluate((0, 0), rng.normal(scale=10 ** rng.uniform(-6, 3), size=2), kind, where, rad)
            assert out.status in ("active", "inactive", "collision")
            if out.force is not None:
                assert np.all(np.isfinite(out.force)) and math.isfinite(out.potential)


def test_non_smooth_wall_and_corridor():
    """d_s = √(η/(F_a cos α)) = 0.4472 m (η = 0.1, F_a = 1, α = 60°); other variants by bisection; corridor friction η/(L ∓ x)²."""
    rep = VelocityGatedRepulsion(0.1, 2.0, 1.0)
    ns = rep.non_smooth_wall(1.0, math.radians(60))
    assert ns.verdict == "non-smooth" and ns.d_s == pytest.approx(0.4472, abs=5e-5) and ns.rest_band == (0.0, ns.d_s)
    # at the edge the repulsion at v_RO = 0+ equals the pull, for every variant (independent check)
    for variant in ("squared", "paper_eq23"):
        r = VelocityGatedRepulsion(0.5, 2.0, 1.0, variant)
        e = r.non_smooth_wall(0.3, math.radians(50))
        assert float(r.at_rest_force(e.d_s)) == pytest.approx(0.3 * math.cos(math.radians(50)), rel=1e-9)
    assert VelocityGatedRepulsion(100.0, 0.5, 1.0).non_smooth_wall(1.0, 1.0).d_s == 0.5  # capped at ρ0
    c = rep.non_smooth_corridor(0.5, [-0.2, 0.0, 0.3])
    np.testing.assert_allclose(c.friction_left, 0.1 / (0.5 + np.array([-0.2, 0.0, 0.3])) ** 2, rtol=1e-14)
    np.testing.assert_allclose(c.friction_right, 0.1 / (0.5 - np.array([-0.2, 0.0, 0.3])) ** 2, rtol=1e-14)
    with pytest.raises(ValueError, match="offsets"):
        rep.non_smooth_corridor(0.5, [0.6])


@pytest.mark.parametrize("variant, lo", [("gradient", -1.5), ("squared", -0.90344), ("paper_eq23", -0.35650)])
def test_eq23_stall_bands(variant, lo):
    """GC2002 eq (23) with ρ_TO = 0.5, α_p = 0.005, α_v = 0.1, η = 0.2, ρ0 = 2: bands (lo, 0), lo to 5 decimals.

    Independent check: at lo the pull 2α_p|x| equals the repulsion (except reading A, whose band
    is cut by the influence region at ρ_TO − ρ0 = −1.5).
    """
    rep = VelocityGatedRepulsion(0.2, 2.0, 1.0, variant)
    band = stall_band(rep, VelocityAttraction(0.005, 0.1), 0.5)
    assert len(band.intervals) == 1
    a, b = band.intervals[0]
    assert a == pytest.approx(lo, abs=5e-6) and b == 0.0
    if variant != "gradient":
        assert float(rep.at_rest_force(0.5 - a)) == pytest.approx(0.01 * abs(a), rel=1e-9)


def test_bad_inputs():
    """Every constructor and method rejects bad input with a ValueError naming the parameter."""
    for kwargs, name in [({"alpha_p": 0.0, "alpha_v": 0.1}, "alpha_p"), ({"alpha_p": 1.0, "alpha_v": -1}, "alpha_v"),
                         ({"alpha_p": 1.0, "alpha_v": 0.1, "n": 0}, "n"), ({"alpha_p": 1.0, "alpha_v": 0.1, "m": math.nan}, "m")]:
        with pytest.raises(ValueError, match=f"^{name} "):
            VelocityAttraction(**kwargs)
    with pytest.raises(ValueError, match="^a_max "):
        VelocityGatedRepulsion(0.1, 1.0, 0.0)
    with pytest.raises(ValueError, match="^variant "):
        VelocityGatedRepulsion(0.1, 1.0, 1.0, "B")
    rep = VelocityGatedRepulsion(0.1, 1.0, 1.0)
    with pytest.raises(ValueError, match="^obstacle "):
        rep.evaluate((0, 0), (1, 0), "cube", (1, 0))
    with pytest.raises(ValueError, match="^where "):
        rep.evaluate((0, 0), (1, 0), "wall", ((1, 0), (-2, 0)))
    with pytest.raises(ValueError, match="^v "):
        rep.evaluate((0, 0), (math.nan, 0), "point", (1, 0))
    with pytest.raises(ValueError, match="^alpha "):
        rep.non_smooth_wall(1.0, 2.0)
    with pytest.raises(ValueError, match="^law "):
        VelocityAttraction(1.0, 0.1).steering_wall_equilibria("khatib", 1.0, 0.5, 1.0)
