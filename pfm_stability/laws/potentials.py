"""Attractive and repulsive potentials as functions of distances, and Ge & Cui's bounds on ξ/η.

Ge & Cui, "New potential functions for mobile robot path planning", IEEE
T-RA 16(5), 2000 ("GC2000"; equation numbers are theirs, docs/traps.md):

* attraction (eq 1): U_att = ½ ξ ρ_gᵐ, m ∈ {1, 2}; |F_att| = (m/2) ξ ρ_g^(m−1)
  (m = 1: a constant pull ξ/2; m = 2: a spring, F_att = ξ ρ_g);
* Khatib's repulsion (eq 3): U_rep = ½ η (1/ρ − 1/ρ0)² for ρ ≤ ρ0, else 0;
* goal-aware repulsion, "GNRON" (eq 8): U_rep = ½ η (1/ρ − 1/ρ0)² ρ_gⁿ, n > 0
  (n = 0 is Khatib's), with the force F_rep1 along n_OR (eq 10) and F_rep2
  towards the goal (eq 11);
* the smoothed form of eq (40): ρ → ρ + δ and ρ0 → ρ0 + δ (bounded force at the
  surface; ρ0 + δ keeps U continuous at ρ = ρ0).

Every function takes distances ρ (to an obstacle's nearest point) and ρ_g (to
the goal), in m, as numbers or numpy arrays (broadcast), and returns values of
the same shape; potentials are in units of ξ·m^m (or η·m^(n−2)), forces their
derivatives per m. The second derivatives (`attraction_derivatives`,
`repulsion_derivatives`) give a scene's exact gradient and Hessian by the
chain rule (`pfm_stability.analysis.traps`).

The bounds (GC2000 Sec IV): on the ray from the goal directly away from an
obstacle at distance r < ρ0 (robot, goal and nearest obstacle point collinear,
robot and obstacle on opposite sides of the goal, eq 19–24), the total force
points at the goal everywhere in the influence region iff ξ/η > k_n, the exact
bound (eq 25–28; closed form eq 29 for n = 2). `k_conservative` is the simpler
k′_n ≥ k_n of eq (31)–(37). `ray_stationary_points` solves that 1-D model
directly (Figs 2 and 6). Two extensions, stated in docs/traps.md: an
attraction exponent m ≠ 2 (the factor 2/m and (ρ − r)^(n−m)), and δ > 0, for
which the bounds are those of r + δ and ρ0 + δ.
"""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_number
from ..numerics.solve import bisect_root

__all__ = [
    "attraction_potential",
    "attraction_force",
    "attraction_derivatives",
    "khatib_potential",
    "khatib_force",
    "gnron_potential",
    "gnron_forces",
    "repulsion_derivatives",
    "rho_m",
    "bound_integrand",
    "k2_closed_form",
    "k_exact",
    "k_conservative",
    "ray_force",
    "ray_stationary_points",
]


def _distances(name, value):
    """`value` as a float array after checking every entry is finite and >= 0."""
    a = np.asarray(value, dtype=float) if not isinstance(value, (str, bytes)) else None
    if a is None or a.dtype.kind != "f" or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError(f"{name} must be a finite distance in [0, inf) m (number or array); got {value!r}")
    return a


def _exponent(name, value, allow_zero=True):
    return check_number(name, value, 0.0, 10.0, low_open=not allow_zero, high_open=False)


def _check_law(eta, rho0, delta):
    eta = check_number("eta", eta, 0.0, math.inf)
    rho0 = check_number("rho0", rho0, 0.0, math.inf, unit="m")
    delta = check_number("delta", delta, 0.0, math.inf, low_open=False, unit="m")
    return eta, rho0, delta


# ------------------------------------------------------------------ attraction
def attraction_potential(rho_g, xi, m=2):
    """U_att = ½ ξ ρ_gᵐ (GC2000 eq 1).

    Parameters
    ----------
    rho_g : float or array_like
        Distance to the goal, m (>= 0).
    xi : float
        Attractive scaling factor ξ > 0.
    m : float
        Attraction exponent, in [1, 10] (GC2000: 1 or 2).

    Returns
    -------
    ndarray or float
        The potential, in units of ξ·mᵐ.
    """
    return attraction_derivatives(rho_g, xi, m)[0]


def attraction_force(rho_g, xi, m=2):
    """|F_att| = dU_att/dρ_g = (m/2) ξ ρ_g^(m−1), directed at the goal (eq 2, 17); m = 1 gives ξ/2.

    Parameters
    ----------
    rho_g : float or ndarray
        Distance to the goal, m.
    xi : float
        Attractive scaling factor ξ.
    m : float, optional
        Attraction exponent.
    """
    return attraction_derivatives(rho_g, xi, m)[1]


def attraction_derivatives(rho_g, xi, m=2):
    """U_att, dU_att/dρ_g and d²U_att/dρ_g² at distances `rho_g` (m).

    Parameters
    ----------
    rho_g : float or ndarray
        Distance to the goal, m.
    xi : float
        Attractive scaling factor ξ.
    m : float, optional
        Attraction exponent.

    Returns
    -------
    tuple of ndarray
        (U, U_g, U_gg). At ρ_g = 0, U_g = 0 for m > 1 and U_gg = ξ for m = 2
        (the limits); for m < 2 U_gg is infinite there (U is not C² at the goal).
    """
    r = _distances("rho_g", rho_g)
    xi = check_number("xi", xi, 0.0, math.inf)
    m = check_number("m", m, 1.0, 10.0, low_open=False, high_open=False)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        u = 0.5 * xi * r**m
        ug = 0.5 * m * xi * r ** (m - 1.0)
        ugg = 0.5 * m * (m - 1.0) * xi * r ** (m - 2.0) if m != 1.0 else np.zeros_like(r)
    return u, ug, ugg


# ------------------------------------------------------------------ repulsion
def repulsion_derivatives(rho, rho_g, eta, rho0, n=0.0, delta=0.0):
    """The goal-aware repulsion (eq 8, 40) and its derivatives in (ρ, ρ_g).

    U = ½ η c² ρ_gⁿ for ρ <= ρ0 (0 beyond), c = 1/(ρ + δ) − 1/(ρ0 + δ);
    n = 0 is Khatib's law (eq 3).

    Parameters
    ----------
    rho : float or array_like
        Distance to the obstacle, m (> 0 unless δ > 0).
    rho_g : float or array_like
        Distance to the goal, m.
    eta : float
        Repulsive scaling factor η > 0.
    rho0 : float
        Influence distance ρ0 > 0, m.
    n : float
        Goal exponent, in [0, 10].
    delta : float
        Surface offset δ >= 0 of eq (40), m.

    Returns
    -------
    tuple of ndarray
        (U, U_ρ, U_g, U_ρρ, U_ρg, U_gg). −U_ρ = F_rep1 (eq 10), U_g = F_rep2
        (eq 11). Terms with a factor n vanish for n = 0 (also at ρ_g = 0).
    """
    rho, rg = _distances("rho", rho), _distances("rho_g", rho_g)
    eta, rho0, delta = _check_law(eta, rho0, delta)
    n = _exponent("n", n)
    rho, rg = np.broadcast_arrays(rho, rg)
    s = rho + delta
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # inf where the true value overflows
        inside = rho <= rho0
        c = np.where(inside, 1.0 / s - 1.0 / (rho0 + delta), 0.0)
        g = rg**n
        gn1 = n * rg ** (n - 1.0) if n else np.zeros_like(rg)
        gn2 = n * (n - 1.0) * rg ** (n - 2.0) if n not in (0.0, 1.0) else np.zeros_like(rg)
        acting = c != 0  # 0 beyond ρ0 also where ρ_g^(n−1) or ρ_g^(n−2) is infinite (the goal)
        u = 0.5 * eta * c * c * g
        u_r = np.where(inside, -eta * c * g / s**2, 0.0)
        u_g = np.where(acting, 0.5 * eta * c * c * gn1, 0.0)
        u_rr = np.where(inside, eta * g * (1.0 / s**4 + 2.0 * c / s**3), 0.0)
        u_rg = np.where(acting, -eta * c * gn1 / s**2, 0.0)
        u_gg = np.where(acting, 0.5 * eta * c * c * gn2, 0.0)
    return u, u_r, u_g, u_rr, u_rg, u_gg


def khatib_potential(rho, eta, rho0, delta=0.0):
    """Khatib's repulsion U = ½ η (1/ρ − 1/ρ0)² for ρ <= ρ0, else 0 (eq 3; δ as eq 40), at distances `rho` (m).

    Parameters
    ----------
    rho : float or ndarray
        Distance to the obstacle, m.
    eta : float
        Repulsive scaling factor η.
    rho0 : float
        Influence distance, m.
    delta : float, optional
        Surface offset δ, m (eq 40).
    """
    return repulsion_derivatives(rho, 1.0, eta, rho0, 0.0, delta)[0]


def khatib_force(rho, eta, rho0, delta=0.0):
    """Magnitude of Khatib's repulsion, η (1/ρ − 1/ρ0)/ρ² (eq 4), along n_OR; 0 beyond ρ0.

    Parameters
    ----------
    rho : float or ndarray
        Distance to the obstacle, m.
    eta : float
        Repulsive scaling factor η.
    rho0 : float
        Influence distance, m.
    delta : float, optional
        Surface offset δ, m (eq 40).
    """
    return -repulsion_derivatives(rho, 1.0, eta, rho0, 0.0, delta)[1]


def gnron_potential(rho, rho_g, eta, rho0, n, delta=0.0):
    """Goal-aware repulsion U = ½ η (1/ρ − 1/ρ0)² ρ_gⁿ for ρ <= ρ0, else 0 (eq 8; δ as eq 40).

    Parameters
    ----------
    rho : float or ndarray
        Distance to the obstacle, m.
    rho_g : float or ndarray
        Distance to the goal, m.
    eta : float
        Repulsive scaling factor η.
    rho0 : float
        Influence distance, m.
    n : float
        Goal exponent.
    delta : float, optional
        Surface offset δ, m (eq 40).
    """
    return repulsion_derivatives(rho, rho_g, eta, rho0, n, delta)[0]


def gnron_forces(rho, rho_g, eta, rho0, n, delta=0.0):
    """(F_rep1, F_rep2): the goal-aware repulsion along n_OR (eq 10) and towards the goal (eq 11).

    F_rep1 = η (1/ρ − 1/ρ0) ρ_gⁿ/ρ², F_rep2 = (n/2) η (1/ρ − 1/ρ0)² ρ_g^(n−1),
    both 0 beyond ρ0 (with δ: ρ → ρ + δ, ρ0 → ρ0 + δ). F_rep2 is infinite at
    the goal for n < 1 (eq 12–13).

    Parameters
    ----------
    rho : float or ndarray
        Distance to the obstacle, m.
    rho_g : float or ndarray
        Distance to the goal, m.
    eta : float
        Repulsive scaling factor η.
    rho0 : float
        Influence distance, m.
    n : float
        Goal exponent.
    delta : float, optional
        Surface offset δ, m (eq 40).
    """
    d = repulsion_derivatives(rho, rho_g, eta, rho0, n, delta)
    return -d[1], d[2]


# ------------------------------------------------------------------ GC2000's bounds on ξ/η
def _check_bound(r, rho0, n, m, delta):
    rho0 = check_number("rho0", rho0, 0.0, math.inf, unit="m")
    r = check_number("r", r, 0.0, rho0, unit="m")
    n = _exponent("n", n)
    m = check_number("m", m, 1.0, 10.0, low_open=False, high_open=False)
    delta = check_number("delta", delta, 0.0, math.inf, low_open=False, unit="m")
    return r + delta, rho0 + delta, n, m  # eq (40): the bound of r + δ and ρ0 + δ


def _rho_m(r, rho0, n):
    a = 1.0 - n / 2.0
    root = math.sqrt(a * a + 2.0 * n * r / rho0)
    return 2.0 * r / (a + root) if a >= 0 else rho0 / n * (root - a)  # both forms free of cancellation


def rho_m(r, rho0, n):
    """ρ_m of GC2000 eq (27): φ(ρ) <= 0 on (r, ρ_m], > 0 on (ρ_m, ρ0).

    ρ_m = 2r / [(1 − n/2) + √((1 − n/2)² + 2nr/ρ0)], the positive root of
    (n/2ρ0) ρ² + (1 − n/2) ρ − r = 0 (evaluated without cancellation for n > 2).

    Parameters
    ----------
    r : float
        Distance from the goal to the obstacle, m, in (0, ρ0).
    rho0 : float
        Influence distance, m.
    n : float
        Goal exponent, in [0, 10] (n = 0: ρ_m = r).

    Returns
    -------
    float
        ρ_m in m, r <= ρ_m (< ρ0 when φ(ρ0) > 0).
    """
    r, rho0, n, _ = _check_bound(r, rho0, n, 2.0, 0.0)
    return _rho_m(r, rho0, n)


def _integrand(rho, r, rho0, n, m):
    rho = np.asarray(rho, dtype=float)
    phi = (1.0 - n / 2.0) / rho - r / rho**2 + n / (2.0 * rho0)  # eq (26)
    with np.errstate(divide="ignore", invalid="ignore"):
        return (2.0 / m) * (1.0 / rho - 1.0 / rho0) * (rho - r) ** (n - m) * phi


def bound_integrand(rho, r, rho0, n, m=2.0):
    """The right-hand side of eq (24) as a function of ρ, whose sup over (r, ρ0) is k_n (eq 25).

    (2/m)(1/ρ − 1/ρ0)(ρ − r)^(n−m) φ(ρ), φ(ρ) = 1/ρ − r/ρ² − n/(2ρ) + n/(2ρ0)
    (eq 26); for m = 2 exactly GC2000's (25). Positive on (ρ_m, ρ0) only.

    Parameters
    ----------
    rho : float or array_like
        Obstacle distance ρ in (r, ρ0), m.
    r, rho0, n, m : float
        As in `k_exact`.

    Returns
    -------
    ndarray
        The ratio ξ/η the force balance needs at ρ (dimensionless for m = n).
    """
    r, rho0, n, m = _check_bound(r, rho0, n, m, 0.0)
    return _integrand(_distances("rho", rho), r, rho0, n, m)


def k2_closed_form(r, rho0):
    """k_2 of GC2000 eq (29): [2/(9ρ0²) + 2r/(27ρ0³)]√(1 + 3ρ0/r) − 2/(3ρ0²) + 2r/(27ρ0³).

    Evaluated in the equivalent form (2/(9ρ0²))(s − 2)²/(s − 1), s = √(1 + 3ρ0/r),
    attained at ρ* = 3ρ0/(1 + s).

    Parameters
    ----------
    r : float
        Distance from the goal to the obstacle, m.
    rho0 : float
        Influence distance, m.

    Returns
    -------
    float
        The exact lower bound of ξ/η for n = m = 2, 1/m².
    """
    r, rho0, _, _ = _check_bound(r, rho0, 2.0, 2.0, 0.0)
    s = math.sqrt(1.0 + 3.0 * rho0 / r)
    return 2.0 / (9.0 * rho0**2) * (s - 2.0) ** 2 / (s - 1.0)


def k_exact(r, rho0, n, m=2.0, delta=0.0, *, scan=2049):
    """The exact lower bound k_n of ξ/η (GC2000 eq 25–28; eq 29 for n = m = 2).

    k_n = sup over ρ_m < ρ < ρ0 of `bound_integrand`. The sup is found by a
    dense scan (uniform, plus geometric towards both ends, where the peak
    sits for small n) for sign changes of the integrand's analytic
    log-derivative, each refined by bisection (`solve.bisect_root`), the
    largest value kept. For n = m = 2 the closed form (29) is returned.

    Parameters
    ----------
    r : float
        Distance from the goal to the obstacle, m, in (0, ρ0).
    rho0 : float
        Influence distance, m.
    n : float
        Goal exponent in [0, 10]. n = 0 (Khatib's law) gives inf for m > 1:
        the integrand grows like (ρ − r)^(1−m) at the goal, no ratio
        suffices; for m = 1 its sup is the limit 2(1/r − 1/ρ0)/r² at ρ → r.
    m : float
        Attraction exponent in [1, 10] (GC2000: 2; other m is our extension).
    delta : float
        δ of eq (40), m: the bound of r + δ and ρ0 + δ.
    scan : int
        Points of the scan.

    Returns
    -------
    float
        k_n (units m^(m−n−2)); ξ/η > k_n means no stationary point on the ray.
    """
    r, rho0, n, m = _check_bound(r, rho0, n, m, delta)
    if n == 0.0:  # ρ_m = r and the integrand is (2/m)(1/ρ − 1/ρ0)(ρ − r)^(1−m)/ρ²
        return 2.0 * (1.0 / r - 1.0 / rho0) / r**2 if m == 1.0 else math.inf
    if n == 2.0 and m == 2.0:
        s = math.sqrt(1.0 + 3.0 * rho0 / r)
        return 2.0 / (9.0 * rho0**2) * (s - 2.0) ** 2 / (s - 1.0)
    lo, hi = _rho_m(r, rho0, n), rho0
    if not lo < hi:
        return 0.0
    t = np.unique(np.concatenate([np.linspace(0.0, 1.0, scan), np.geomspace(1e-12, 0.5, 200), 1.0 - np.geomspace(1e-12, 0.5, 200)]))
    x = lo + (hi - lo) * t[1:-1]
    x = x[(x > lo) & (x < hi)]

    def slope(rho):  # d/dρ log of the integrand (all three factors > 0 on (ρ_m, ρ0))
        rho = np.asarray(rho, dtype=float)
        phi = (1.0 - n / 2.0) / rho - r / rho**2 + n / (2.0 * rho0)
        dphi = -(1.0 - n / 2.0) / rho**2 + 2.0 * r / rho**3
        return -1.0 / (rho**2 * (1.0 / rho - 1.0 / rho0)) + (n - m) / (rho - r) + dphi / phi

    d = slope(x)
    peaks = [float(x[np.argmax(_integrand(x, r, rho0, n, m))])]
    for i in np.flatnonzero((d[:-1] > 0) & (d[1:] <= 0)):
        peaks.append(bisect_root(lambda p: float(slope(p)), float(x[i]), float(x[i + 1]), rtol=1e-15))
    return float(np.max(_integrand(np.array(peaks), r, rho0, n, m)))


def k_conservative(r, rho0, n, m=2.0, delta=0.0):
    """The conservative bound k′_n >= k_n of GC2000 eq (31)–(37).

    k′_n = (2/m)(1/ρ_m − 1/ρ0) · sup (ρ − r)^(n−m) · sup φ over (ρ_m, ρ0):

    * sup (ρ − r)^(n−m) = (ρ_m − r)^(n−m) for n < m (eq 32), (ρ0 − r)^(n−m) otherwise (eq 35);
    * sup φ = n/(2ρ0) + (1 − n/2)²/(4r) if n < 2 and r/ρ0 <= ½ − n/4 (eq 33,
      attained at ρ = 4r/(2 − n)), else φ(ρ0) = (ρ0 − r)/ρ0² (eq 33, 36; n = 2 too).

    For m = 2 this is eq (34) (n < 2) and eq (37) (n > 2).

    Parameters
    ----------
    r, rho0, n, m, delta : float
        As in `k_exact`.

    Returns
    -------
    float
        k′_n; inf for n = 0.
    """
    r, rho0, n, m = _check_bound(r, rho0, n, m, delta)
    if n == 0.0:
        return math.inf
    rm = _rho_m(r, rho0, n)
    power = (rm - r) ** (n - m) if n < m else (rho0 - r) ** (n - m)
    if n < 2.0 and r / rho0 <= 0.5 - n / 4.0:
        phi = n / (2.0 * rho0) + (1.0 - n / 2.0) ** 2 / (4.0 * r)
    else:
        phi = (rho0 - r) / rho0**2
    return (2.0 / m) * (1.0 / rm - 1.0 / rho0) * power * phi


# ------------------------------------------------------------------ the 1-D model on the ray
def ray_force(rho_g, r, xi, eta, rho0, n=0.0, m=2.0, delta=0.0):
    """dU/dρ_g on the goal–obstacle ray: F_att − F_rep1 + F_rep2 (GC2000 eq 20, 22).

    The robot at distance ρ_g from the goal, the obstacle (a point or a
    flat surface) at ρ = ρ_g + r on the other side (eq 6–7 for n = 0).
    Positive: the total force pulls the robot towards the goal.

    Parameters
    ----------
    rho_g : float or array_like
        Distance from the goal, m (> 0).
    r : float
        Goal–obstacle distance, m (> 0).
    xi, eta, rho0, n, m, delta : float
        The law (`attraction_derivatives`, `repulsion_derivatives`).

    Returns
    -------
    ndarray
        The derivative of the total potential along the ray.
    """
    rg = _distances("rho_g", rho_g)
    r = check_number("r", r, 0.0, math.inf, unit="m")
    att = attraction_derivatives(rg, xi, m)[1]
    rep = repulsion_derivatives(rg + r, rg, eta, rho0, n, delta)
    return att + rep[1] + rep[2]


def ray_stationary_points(r, xi, eta, rho0, n=0.0, m=2.0, delta=0.0, *, scan=4001):
    """Every stationary point of the total potential on the goal–obstacle ray, 0 < ρ_g < ρ0 − r.

    The 1-D model of GC2000 Figs 1, 2 and 6 and of the bounds (eq 19–24):
    roots of `ray_force`, found by a scan (geometric towards the goal and
    the influence edge, uniform between) and bisection. Beyond ρ0 − r only
    the attraction acts, so there is none.

    Parameters
    ----------
    r : float
        Distance from the goal to the obstacle, m.
    xi : float
        Attractive scaling factor ξ.
    eta : float
        Repulsive scaling factor η.
    rho0 : float
        Influence distance, m.
    n : float, optional
        Goal exponent (0: Khatib's law).
    m : float, optional
        Attraction exponent.
    delta : float, optional
        Surface offset δ, m (eq 40).
    scan : int, optional
        Points of the scan along the ray before the roots are refined.

    Returns
    -------
    list of tuple
        (ρ_g, kind) with kind "minimum" (force changes from pushing away to
        pulling in) or "maximum", ordered by ρ_g.
    """
    r = check_number("r", r, 0.0, math.inf, unit="m")
    rho0 = check_number("rho0", rho0, 0.0, math.inf, unit="m")
    span = rho0 - r
    if span <= 0:
        return []
    t = np.unique(np.concatenate([np.linspace(0.0, 1.0, scan), np.geomspace(1e-9, 0.5, 300), 1.0 - np.geomspace(1e-12, 0.5, 300)]))
    x = span * t[(t > 0) & (t < 1)]
    f = ray_force(x, r, xi, eta, rho0, n, m, delta)
    out = []
    for i in np.flatnonzero(((f[:-1] < 0) & (f[1:] >= 0)) | ((f[:-1] > 0) & (f[1:] <= 0))):  # a zero on the scan counts once
        root = bisect_root(lambda p: float(ray_force(p, r, xi, eta, rho0, n, m, delta)), float(x[i]), float(x[i + 1]), rtol=1e-15)
        out.append((root, "minimum" if f[i] < 0 else "maximum"))
    return out
