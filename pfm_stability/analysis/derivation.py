"""Symbolic derivation of the Koren & Borenstein robot–environment loop, eq (5)–(25).

Koren & Borenstein 1991 ("KB") combine the steering model, the VFF force law and
the robot's kinematics into one differential equation and read their stability
conditions off it. This module re-derives every step with sympy instead of
transcribing the printed formulas, so that the closed forms used numerically
elsewhere (`criteria`, `force_law`, `models`) can be tested against it
(docs/theory.md: the derivation is the source of truth):

=====================  =======================================================
KB eq                  how it is obtained here
=====================  =======================================================
(5)–(7)                (5) and ω = θ̇ substituted into (6), solved for kδ
(8), (13)              F_r = F_cr Wⁿ/dⁿ with F_cr = f F_a substituted
(9)                    direction of R = repulsion + attraction (wall frame)
(10)–(12)              (9) differentiated in time (implicitly), solved for δ̇
(14)                   lateral component of the velocity V(sin θ, cos θ)
(15), (16) corrected   (7) differentiated once, (10) and (14) substituted
(17)                   Laplace transform of the linear ODE, zero initial state
(18)                   the loop delay's transfer function L{δ(t − T)} = e^(−sT)
(19)                   e^(−sT) replaced by its first-order Taylor polynomial
(18) with Padé(m, m)   Padé coefficients solved from the Taylor series
(20)                   first column of the Routh array of (19)
(21)                   (11) at δ = 0 substituted into (20), solved for d^(n+1)
(22)–(23)              (9) at δ = 0, solved for d
(24)                   d0 of (23) substituted into the boundary of (21)
(25)                   lateral force F_r(L + x) − F_r(L − x) linearized at x = 0
=====================  =======================================================

Every result accepts a *force law*: KB's power law F_r = f F_a Wⁿ/dⁿ (eq 8,
13; ``"power"``, the default), a general undefined function F_r(d)
(``"general"``; docs/theory.md, "Any force law": wall equilibrium
F_r(d0) = F_a cos α, N = −F_r′(d0)/(F_a sin α); corridor N = −2F_r′(L)/F_a),
or any ``sympy.Lambda`` d ↦ F_r(d) (a force, i.e. proportional to F_a).

KB misprints and OCR garbles handled (docs/theory.md)
-----------------------------------------------------
* (6): "α̇ is the steering-rate command" means the command u = k(δ − θ) of (5);
  KB overload α (steering-rate command in (5)–(6), target angle from (9) on).
  Here the command is ``u``.
* (8), (13), (23) and §3's text: F_π, F_σ, F_α and the "F_r" of (23) are OCR
  garbles of the force *constants* F_cr (repulsive, eq 1) and F_ct = F_a
  (attractive, eq 3); f = F_cr/F_a.
* (10) is printed δ̇ = −Nα̇ + Mα̇; the first term is −N ḋ (ḋ = V sin θ, eq 14).
* (15) and (16) are printed one derivative order short (τθ̈ + θ̇ + kθ + …);
  differentiating (7) gives τθ⃛ + θ̈ + kθ̇ + kNV sin θ = kMα̇, the form (17)
  is the characteristic equation of.
* (25) prints W* for Wⁿ.
* (21) and (24) print "≥": at equality the loop has a pair of roots on the
  imaginary axis (marginal), so the stable region is the strict inequality,
  as in (20); the relations returned here are strict.

Conventions: X is the wall normal pointing away from the wall (d grows with
X), Y runs along the wall; θ and δ are measured from +Y towards +X, so
ẋ = V sin θ (14) and tan δ = R_X/R_Y (9). KB's (18) puts the delay on the
environment path only (kNV e^(−sT)): the sampled reference δ is delayed, the
steering servo u = k(δ − θ) is continuous — the ``reference`` structure of
the ``sampled`` model (docs/models.md).

Symbols use the paper's names (docs/theory.md, Notation), all positive except the angles
θ, δ (real) and the lateral offset x (real): `tau` (s), `k` (1/s), `V` (m/s),
`T` (s), `f`, `n`, `W` (m), `alpha` (rad, in (0, π/2)), `d` (m), `L` (m),
`N` (1/m), `F_a` (force), and `NV_star` (NV*, 1/s) for a generic critical
loop gain. sympy cannot be told that α < π/2, so where powers of sin α,
cos α or tan α must be combined, `simplify_physical` replaces them by positive
symbols first (valid on the physical domain 0 < α < π/2).

Results are cached (the derivation is deterministic); the first full
derivation takes a few seconds. This module imports sympy at import time and
is only imported on demand (the CLI imports it inside ``derive``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from ..parameters import DERIVATION_LAWS
from ..numerics.routh import routh_array

__all__ = [
    "KINDS",
    "LAWS",
    "Linearization",
    "RouthCriterion",
    "Step",
    "characteristic_polynomial",
    "command_equation",
    "corridor_condition",
    "corridor_gain",
    "corridor_lateral_force",
    "delay_transfer",
    "derivation",
    "force_balance",
    "force_law",
    "kinematics",
    "linearization_gains",
    "linearized_ode",
    "motor_equation",
    "pade_approximant",
    "robot_environment_ode",
    "routh_condition",
    "routh_criterion",
    "simplify_physical",
    "steering_equation",
    "wall_balance",
    "wall_condition",
    "wall_equilibrium",
    "wall_equilibrium_gain",
    "wall_f_condition",
    "wall_gain",
    # symbols
    "t", "s", "tau", "k", "V", "T", "f", "n", "W", "L", "d", "alpha", "delta", "x",
    "N", "M", "F_a", "F_cr", "NV_star", "omega",
    "theta", "delta_t", "d_t", "alpha_t", "omega_t", "u", "F_r",
]

# ------------------------------------------------------------------ symbols
t = sp.Symbol("t", real=True)
"""Time, s."""
s = sp.Symbol("s")
"""Laplace variable, 1/s."""
tau, k, V, T = sp.symbols("tau k V T", positive=True)
f, n, W, L, d = sp.symbols("f n W L d", positive=True)
F_a, F_cr = sp.symbols("F_a F_cr", positive=True)
alpha = sp.Symbol("alpha", positive=True)
"""Target angle from the wall normal, rad, in (0, π/2) (eq 9)."""
delta = sp.Symbol("delta", real=True)
"""Commanded direction δ, rad (eq 5, 9), as a value (not a time function)."""
x = sp.Symbol("x", real=True)
"""Lateral offset from the corridor centre line, m (eq 25)."""
N = sp.Symbol("N", positive=True)
"""Environment gain, 1/m (eq 10–11)."""
M = sp.Symbol("M", real=True)
"""Gain of the target-angle rate, dimensionless (eq 10, 12)."""
NV_star = sp.Symbol("NV*", positive=True)
"""A critical loop gain NV*, 1/s (KB's 1/(τ + T) or any model's, docs/models.md)."""
omega = sp.Symbol("omega", positive=True)
"""Angular frequency, rad/s."""

theta = sp.Function("theta", real=True)
"""Direction of travel θ(t), rad (eq 5)."""
delta_t = sp.Function("delta", real=True)
"""Commanded direction δ(t), rad."""
d_t = sp.Function("d", positive=True)
"""Distance to the wall d(t), m."""
alpha_t = sp.Function("alpha", positive=True)
"""Target angle α(t), rad."""
omega_t = sp.Function("omega", real=True)
"""Actual steering rate ω(t), rad/s (eq 6)."""
u = sp.Function("u", real=True)
"""Steering-rate command u(t), rad/s (KB's overloaded α in eq 5–6)."""
F_r = sp.Function("F_r")
"""A general lateral repulsion law F_r(d), force units (docs/theory.md, "Any force law")."""

LAWS = DERIVATION_LAWS
"""Named force laws: KB's power law (eq 8, 13) and a general F_r(d) (`parameters.DERIVATION_LAWS`)."""

KINDS = ("continuous", "exact_delay", "kb_first_order", "pade")
"""Characteristic equations by loop-model name (docs/models.md): (17), (18), (19), (18)+Padé."""


# ------------------------------------------------------------------ results
@dataclass(frozen=True)
class Step:
    """One step of the derivation.

    Attributes
    ----------
    equation : str
        KB equation number(s), e.g. ``"7"`` or ``"15, corrected"``.
    title : str
        Short name of the step.
    expr : sympy.Basic
        The derived equation, relation or expression.
    explanation : str
        How it follows from the previous steps (one or two sentences).
    """

    equation: str
    title: str
    expr: sp.Basic
    explanation: str

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {"equation": self.equation, "title": self.title, "expr": sp.sstr(self.expr), "explanation": self.explanation}


@dataclass(frozen=True)
class Linearization:
    """δ̇ = −N ḋ + M α̇ (KB eq 10–12), from (9) differentiated in time.

    Attributes
    ----------
    rate : sympy.Eq
        δ̇ expressed through ḋ and α̇ with N and M written out.
    N : sympy.Expr
        Environment gain, 1/m, a function of (d, α, δ) (eq 11).
    M : sympy.Expr
        Target-angle gain, dimensionless, a function of (α, δ) (eq 12).
    """

    rate: sp.Eq
    N: sp.Expr
    M: sp.Expr


@dataclass(frozen=True)
class RouthCriterion:
    """Routh's verdict on a third-order characteristic polynomial (KB eq 17, 19–20).

    Attributes
    ----------
    kind : str
        ``"continuous"`` (eq 17) or ``"kb_first_order"`` (eq 19).
    coefficients : tuple
        Descending coefficients of the polynomial in s.
    table : tuple[tuple]
        Rows s³ … s⁰ of the Routh array.
    first_column : tuple
        First entry of every row.
    condition : sympy.Rel
        Stable ⇔ this holds (every first-column entry positive), e.g.
        1 − NV(τ + T) > 0 (eq 20).
    NV_critical : sympy.Expr
        NV*, 1/s: the loop gain where the condition's entry vanishes.
    omega_critical : sympy.Expr
        ω*, rad/s: the imaginary-axis root there, from the auxiliary
        polynomial of the s² row.
    """

    kind: str
    coefficients: tuple
    table: tuple
    first_column: tuple
    condition: sp.Rel
    NV_critical: sp.Expr
    omega_critical: sp.Expr

    def matrix(self) -> sp.ImmutableMatrix:
        """The array with a leading column of row labels s³ … s⁰ (for display)."""
        order = len(self.table) - 1
        return sp.ImmutableMatrix([[s**(order - i), *(sp.factor_terms(x) for x in row)] for i, row in enumerate(self.table)])


# ------------------------------------------------------------------ helpers
def simplify_physical(expr) -> sp.Expr:
    """`sympy.simplify` on the physical domain α ∈ (0, π/2).

    sympy cannot be told that α < π/2, so sin α, cos α and tan α are replaced
    by positive symbols (sin α/cos α for tan α) before simplifying and put back
    afterwards; every other symbol already carries its positivity. This lets
    powers such as (f/cos α)^(1/n) combine exactly, with no ``force=True``.

    Parameters
    ----------
    expr : sympy.Expr
        An expression in the derivation's symbols.
    """
    S, C = sp.Dummy("sin_alpha", positive=True), sp.Dummy("cos_alpha", positive=True)
    expr = sp.sympify(expr).subs(sp.tan(alpha), S / C).subs({sp.sin(alpha): S, sp.cos(alpha): C})
    return sp.simplify(expr).subs({S: sp.sin(alpha), C: sp.cos(alpha)})


def _check_law(law):
    if isinstance(law, sp.Lambda):
        return law
    if law not in LAWS:
        raise ValueError(f"law must be one of {LAWS} or a sympy Lambda d -> F_r(d); got {law!r}")
    return law


def _check_kind(kind: str) -> str:
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}; got {kind!r}")
    return kind


def _check_order(m) -> int:
    if isinstance(m, bool) or not isinstance(m, int) or m < 1:
        raise ValueError(f"pade order m must be an integer >= 1; got {m!r}")
    return m


def _default_NV(NV_critical):
    return routh_criterion("kb_first_order").NV_critical if NV_critical is None else sp.sympify(NV_critical)


def _resultant(lateral_repulsion, target_angle) -> sp.Matrix:
    """R = (repulsion, 0) + F_a(−cos α, sin α) in the wall frame (X, Y) (KB eq 4).

    The target pulls with F_a at angle α from the wall normal: towards the
    wall (−X) and along it (+Y); the repulsion pushes along +X.
    """
    return sp.Matrix([lateral_repulsion, 0]) + F_a * sp.Matrix([-sp.cos(target_angle), sp.sin(target_angle)])


def _tan_delta(lateral_repulsion, target_angle):
    """tan δ = R_X/R_Y, δ measured from +Y towards +X (KB eq 9)."""
    R = _resultant(lateral_repulsion, target_angle)
    return R[0] / R[1]


def _implicit_rate(tan_delta, coordinates) -> dict:
    """Differentiate tan δ(t) = G(q(t)) in time and solve for δ̇ (KB eq 10).

    Parameters
    ----------
    tan_delta : sympy.Expr
        G(q) in the symbols `coordinates`.
    coordinates : tuple of sympy.Symbol

    Returns
    -------
    dict
        q ↦ ∂δ̇/∂q̇, expressed in the plain symbols q and δ.
    """
    paths = {q: sp.Function(q.name)(t) for q in coordinates}
    rates = {q: sp.Dummy(f"{q.name}_dot") for q in coordinates}
    residual = sp.tan(delta_t(t)) - tan_delta.subs(paths)
    delta_rate = sp.solve(sp.diff(residual, t), sp.Derivative(delta_t(t), t))[0]
    delta_rate = delta_rate.subs({sp.Derivative(paths[q], t): rates[q] for q in coordinates})
    values = {**{paths[q]: q for q in coordinates}, delta_t(t): delta}
    return {q: sp.diff(delta_rate, rates[q]).subs(values).doit() for q in coordinates}


def _ordered_sum(terms) -> sp.Expr:
    """An unevaluated sum that prints its terms in the given order (display only)."""
    terms = [term for term in terms if term != 0]
    return sp.Add(*terms, evaluate=False) if len(terms) > 1 else (terms[0] if terms else sp.Integer(0))


def _descending(poly, var) -> sp.Expr:
    """`poly` as c_n var^n + … + c_0 with factored coefficients (display only)."""
    coefficients = sp.Poly(sp.expand(poly), var).all_coeffs()
    degree = len(coefficients) - 1
    return _ordered_sum([sp.factor_terms(c) * var ** (degree - i) for i, c in enumerate(coefficients)])


def _cleared(poly) -> sp.Expr:
    """`poly` times the least common denominator of its rational coefficients (display only)."""
    return sp.fraction(sp.together(sp.expand(poly)))[0]


def _by_derivative_order(expr) -> sp.Expr:
    """Terms of an ODE side sorted by the order of the θ derivative, highest first (display only)."""

    def order(term):
        found = [a.derivative_count for a in term.atoms(sp.Derivative) if a.expr == theta(t)]
        return max(found) if found else (0 if term.has(theta(t)) else -1)

    return _ordered_sum(sorted(sp.Add.make_args(sp.expand(expr)), key=order, reverse=True))


# ------------------------------------------------------------------ steering
def command_equation() -> sp.Eq:
    """KB eq (5): the steering-rate command u = k(δ − θ), rad/s."""
    return sp.Eq(u(t), k * (delta_t(t) - theta(t)))


def motor_equation() -> sp.Eq:
    """KB eq (6): the steering motor τω̇ + ω = u (KB print the command as α / α̇)."""
    return sp.Eq(tau * sp.Derivative(omega_t(t), t) + omega_t(t), u(t))


@lru_cache(maxsize=None)
def steering_equation() -> sp.Eq:
    """KB eq (7): τθ̈ + θ̇ + kθ = kδ.

    (5) and ω = θ̇ substituted into (6), then solved for kδ.
    """
    motor = motor_equation()
    residual = (motor.lhs - motor.rhs).subs(u(t), command_equation().rhs)
    residual = residual.subs(omega_t(t), sp.Derivative(theta(t), t)).doit()
    reference = sp.solve(residual, delta_t(t))[0]
    return sp.Eq(sp.expand(k * reference), k * delta_t(t))


# ------------------------------------------------------------------ force law
@lru_cache(maxsize=None)
def force_law(law="power") -> sp.Lambda:
    """The lateral repulsion F_r(d) as a ``sympy.Lambda`` (force units).

    Parameters
    ----------
    law : {"power", "general"} or sympy.Lambda
        ``"power"``: KB eq (8) F_r = F_cr Wⁿ/dⁿ with F_cr = f F_a (eq 13);
        ``"general"``: an undefined function F_r(d); a Lambda is returned as is.
    """
    law = _check_law(law)
    if isinstance(law, sp.Lambda):
        return law
    if law == "general":
        return sp.Lambda(d, F_r(d))
    eq8 = F_cr * W**n / d**n
    eq13 = sp.Eq(f, F_cr / F_a)
    return sp.Lambda(d, eq8.subs(F_cr, sp.solve(eq13, F_cr)[0]))


@lru_cache(maxsize=None)
def force_balance(law="power") -> sp.Eq:
    """KB eq (9): tan δ = (F_r − F_a cos α)/(F_a sin α).

    δ is the direction of the resultant R of the repulsion F_r(d) (along the
    wall normal, away from the wall) and the attraction F_a towards a target
    at angle α from the wall normal.
    """
    return sp.Eq(sp.tan(delta), _tan_delta(force_law(law)(d), alpha))


@lru_cache(maxsize=None)
def linearization_gains(law="power") -> Linearization:
    """KB eq (10)–(12): δ̇ = −N ḋ + M α̇.

    (9) with d, α, δ functions of time, differentiated and solved for δ̇:
    N = −∂δ̇/∂ḋ = −F_r′(d)cos²δ/(F_a sin α) (eq 11 for the power law:
    nWⁿf cos²δ/(d^(n+1) sin α)) and M = ∂δ̇/∂α̇ with F_r eliminated through
    (9), M = (1 − tan δ/tan α)cos²δ (eq 12, independent of the law).

    Parameters
    ----------
    law : {"power", "general"} or sympy.Lambda

    Returns
    -------
    Linearization
        N in 1/m, M dimensionless.
    """
    general = force_balance("general")
    rate = _implicit_rate(general.rhs, (d, alpha))
    N_law = sp.powsimp(sp.simplify((-rate[d]).subs(F_r, force_law(law)).doit()))
    force = sp.solve(general, F_r(d))[0]
    M_ratio = sp.simplify(rate[alpha].subs(F_r(d), force) / sp.cos(delta) ** 2)
    M_law = M_ratio * sp.cos(delta) ** 2
    dot = {q: sp.Derivative(q_t(t), t) for q, q_t in ((d, d_t), (alpha, alpha_t))}
    equation = sp.Eq(sp.Derivative(delta_t(t), t), -N_law * dot[d] + M_law * dot[alpha])
    return Linearization(equation, N_law, M_law)


def kinematics() -> sp.Eq:
    """KB eq (14): ḋ = V sin θ, m/s — the X component of the velocity V(sin θ, cos θ)."""
    velocity = V * sp.Matrix([sp.sin(theta(t)), sp.cos(theta(t))])
    return sp.Eq(sp.Derivative(d_t(t), t), velocity[0])


# ------------------------------------------------------------------ the ODE
@lru_cache(maxsize=None)
def robot_environment_ode() -> sp.Eq:
    """KB eq (15), corrected: τθ⃛ + θ̈ + kθ̇ + kNV sin θ = kMα̇.

    (7) differentiated once in time, δ̇ replaced by (10) and ḋ by (14); the
    α̇ term is moved to the right. KB print this one derivative order short.
    N = N(d, α, δ) and M = M(α, δ) are kept as the symbols of (10).
    """
    s7 = steering_equation()
    residual = sp.diff(s7.lhs - s7.rhs, t)
    residual = residual.subs(sp.Derivative(delta_t(t), t), -N * sp.Derivative(d_t(t), t) + M * sp.Derivative(alpha_t(t), t))
    residual = residual.subs(kinematics().lhs, kinematics().rhs)
    alpha_rate = sp.Derivative(alpha_t(t), t)
    forcing = -sp.diff(residual, alpha_rate) * alpha_rate
    return sp.Eq(sp.expand(residual + forcing), forcing)


@lru_cache(maxsize=None)
def linearized_ode() -> sp.Eq:
    """KB eq (16), corrected: τθ⃛ + θ̈ + kθ̇ + kNVθ = kα̇ (small θ and δ).

    sin θ replaced by its first-order Taylor polynomial θ and M by its value
    at δ = 0, M = 1 (eq 12); N = N(α) is then a constant for a slowly varying α.
    """
    ode = robot_environment_ode()
    theta_value = sp.Dummy("theta")
    sin_linear = sp.series(sp.sin(theta_value), theta_value, 0, 2).removeO().subs(theta_value, theta(t))
    M_small = linearization_gains("general").M.subs(delta, 0)
    return sp.Eq(ode.lhs.subs(sp.sin(theta(t)), sin_linear), ode.rhs.subs(M, M_small))


# ------------------------------------------------------------------ characteristic equations
@lru_cache(maxsize=None)
def _laplace_parts() -> tuple:
    """(D(s), E(s)): the Laplace transform of the homogeneous (α̇ = 0) linear ODE
    with zero initial state, divided by Θ(s), split into the steering part
    τs³ + s² + ks and the environment feedback kNV (the term with N)."""
    lhs = linearized_ode().lhs
    environment = N * sp.diff(lhs, N)
    Theta = sp.Dummy("Theta")

    def per_theta(expr):
        transform = sp.laplace_transform(expr, t, s, noconds=True)
        # linear in Θ; the initial-state terms do not depend on Θ, so d/dΘ drops them
        return sp.expand(sp.diff(transform.subs(sp.LaplaceTransform(theta(t), t, s), Theta), Theta))

    return per_theta(sp.expand(lhs - environment)), per_theta(environment)


@lru_cache(maxsize=None)
def pade_approximant(m: int) -> tuple:
    """Padé(m, m) approximant P_m(s)/Q_m(s) of e^(−sT), Q_m(0) = 1.

    Solves Q(z)e^(−z) − P(z) = O(z^(2m+1)) for the 2m + 1 unknown coefficients
    (z = sT). Used for the ``pade`` form of KB eq (18).

    Returns
    -------
    (P, Q) : tuple of sympy.Expr
        Polynomials in s and T.
    """
    m = _check_order(m)
    z = sp.Dummy("z")
    p = sp.symbols(f"p0:{m + 1}")
    q = sp.symbols(f"q1:{m + 1}")
    P = sum(p[j] * z**j for j in range(m + 1))
    Q = 1 + sum(q[j - 1] * z**j for j in range(1, m + 1))
    residual = sp.expand(Q * sp.series(sp.exp(-z), z, 0, 2 * m + 1).removeO() - P)
    solution = sp.solve([residual.coeff(z, j) for j in range(2 * m + 1)], p + q, dict=True)[0]
    return P.subs(solution).subs(z, s * T), Q.subs(solution).subs(z, s * T)


@lru_cache(maxsize=None)
def delay_transfer(kind: str = "exact_delay", m: int = 2) -> sp.Expr:
    """The loop delay's transfer function in each model (docs/models.md).

    ``continuous``: 1; ``exact_delay``: L{δ(t − T)}(s) = e^(−sT) (eq 18);
    ``kb_first_order``: its first-order Taylor polynomial 1 − sT (KB §3,
    before eq 19); ``pade``: P_m/Q_m.
    """
    kind = _check_kind(kind)
    if kind == "continuous":
        return sp.Integer(1)
    exact = sp.laplace_transform(sp.DiracDelta(t - T), t, s, noconds=True)
    if kind == "exact_delay":
        return exact
    if kind == "kb_first_order":
        return sp.series(exact, s, 0, 2).removeO()
    P, Q = pade_approximant(m)
    return P / Q


@lru_cache(maxsize=None)
def characteristic_polynomial(kind: str = "continuous", m: int = 2) -> sp.Expr:
    """Left side of the characteristic equation of each loop model (= 0).

    Parameters
    ----------
    kind : {"continuous", "exact_delay", "kb_first_order", "pade"}
        (17) τs³ + s² + ks + kNV; (18) τs³ + s² + ks + kNV e^(−sT);
        (19) τs³ + s² + k(1 − NVT)s + kNV; (18) with Padé(m, m):
        (τs³ + s² + ks)Q_m(s) + kNV P_m(s).
    m : int
        Padé order (``kind="pade"`` only).

    Returns
    -------
    sympy.Expr
        Expanded; a polynomial in s except for ``exact_delay`` (a quasi-polynomial).
    """
    kind = _check_kind(kind)
    plant, environment = _laplace_parts()
    if kind == "pade":
        P, Q = pade_approximant(_check_order(m))
        return sp.expand(plant * Q + environment * P)
    return sp.expand(plant + environment * delay_transfer(kind, m))


# ------------------------------------------------------------------ Routh
@lru_cache(maxsize=None)
def routh_criterion(kind: str = "kb_first_order") -> RouthCriterion:
    """Routh's stability condition for (17) or (19) (KB eq 20).

    The Routh array of the cubic has first column τ, 1, (s¹ entry), kNV. With
    τ, k, N, V > 0 only the s¹ entry can change sign; it is linear in N and
    positive at N = 0, so stable ⇔ N < N*, the root of that entry:
    NV* = 1/(τ + T) for (19) (eq 20) and 1/τ for (17). At NV* the s¹ row
    vanishes and the auxiliary polynomial of the s² row, s² + kNV*, gives the
    imaginary-axis pair ±jω*.

    Parameters
    ----------
    kind : {"continuous", "kb_first_order"}
    """
    if kind not in ("continuous", "kb_first_order"):
        raise ValueError(f"kind must be 'continuous' or 'kb_first_order' (cubic forms); got {kind!r}")
    coefficients = tuple(sp.Poly(characteristic_polynomial(kind), s).all_coeffs())
    result = routh_array(list(coefficients))
    undecided = [entry for entry in result.first_column if not entry.is_positive]
    if len(undecided) != 1 or not undecided[0].subs(N, 0).is_positive:
        raise RuntimeError(f"unexpected Routh first column for {kind}: {result.first_column}")
    N_critical = sp.solve(undecided[0], N)[0]
    NV_critical = sp.simplify(N_critical * V)
    condition = sp.StrictGreaterThan(1 - N * V / NV_critical, 0)
    s2_row = result.table[-3]
    auxiliary = (s2_row[0] * s**2 + s2_row[1]).subs(N, N_critical)
    omega_critical = sp.solve(auxiliary.subs(s, sp.I * omega), omega)[0]
    return RouthCriterion(
        kind,
        coefficients,
        tuple(tuple(row) for row in result.table),
        tuple(result.first_column),
        condition,
        NV_critical,
        sp.simplify(omega_critical),
    )


def routh_condition() -> sp.Rel:
    """KB eq (20): 1 − NV(τ + T) > 0, from the Routh array of (19)."""
    return routh_criterion("kb_first_order").condition


def _gain_condition(gain, NV_critical) -> sp.Rel:
    """(20) with N = `gain` and NV* = `NV_critical`: 1 − gain·V/NV* > 0."""
    return sp.StrictGreaterThan(1 - gain * V / NV_critical, 0)


# ------------------------------------------------------------------ wall
@lru_cache(maxsize=None)
def wall_gain(law="power") -> sp.Expr:
    """N at δ = 0 (eq 11 with cos δ = 1), 1/m, as a function of d and α.

    Power law: nWⁿf/(d^(n+1) sin α); general: −F_r′(d)/(F_a sin α).
    """
    return linearization_gains(law).N.subs(delta, 0)


@lru_cache(maxsize=None)
def wall_balance(law="power") -> sp.Eq:
    """KB eq (22)–(23): F_r(d) = F_a cos α — (9) at the steady state δ = 0.

    tan δ = 0 ⇔ the X component R_X of the resultant vanishes; returned as
    F_r(d) = F_r(d) − R_X.
    """
    repulsion = force_law(law)(d)
    lateral = _resultant(repulsion, alpha)[0]
    return sp.Eq(repulsion, sp.expand(repulsion - lateral))


@lru_cache(maxsize=None)
def wall_equilibrium(law="power") -> sp.Expr:
    """KB eq (23) solved: the equilibrium distance d0, m.

    Power law: d0 = W (f/cos α)^(1/n). Raises `ValueError` when (22) has no
    closed-form solution (``"general"``: d0 is defined implicitly by (22)).
    """
    try:
        solutions = sp.solve(wall_balance(law), d)
    except NotImplementedError:
        solutions = []
    if len(solutions) != 1:
        raise ValueError(f"no unique closed-form equilibrium for law {law!r}: d0 solves {wall_balance(law)}")
    return simplify_physical(solutions[0])


@lru_cache(maxsize=None)
def wall_equilibrium_gain(law="power") -> sp.Expr:
    """N(α) = N(d0(α), α), 1/m: (11) at δ = 0 with d0 of (23).

    Power law: n (cos α/f)^(1/n)/(W tan α) = n cos^((n+1)/n)α/(W f^(1/n) sin α)
    (the N(α) of `criteria`).
    """
    return simplify_physical(wall_gain(law).subs(d, wall_equilibrium(law)))


@lru_cache(maxsize=None)
def wall_condition(law="power", NV_critical=None) -> sp.Rel:
    """KB eq (21): stable along a wall at distance d.

    (11) at δ = 0 substituted into (20). For the power law N ∝ d^(−(n+1)), so
    the condition is solved for d^(n+1):
    d^(n+1) > nV(τ + T)Wⁿf/sin α. Other laws: 1 − N(d)V/NV* > 0.

    Parameters
    ----------
    law : {"power", "general"} or sympy.Lambda
    NV_critical : sympy.Expr, optional
        Critical loop gain NV*, 1/s; KB's 1/(τ + T) from (20) by default
        (pass `NV_star` for the generic form used with any model).
    """
    NV_critical = _default_NV(NV_critical)
    gain = wall_gain(law)
    if law != "power":
        return _gain_condition(gain, NV_critical)
    boundary = sp.solve(gain * V - NV_critical, d)[0]
    return sp.StrictGreaterThan(d ** (n + 1), simplify_physical(boundary ** (n + 1)))


@lru_cache(maxsize=None)
def wall_f_condition(NV_critical=None) -> sp.Rel:
    """KB eq (24): f > cos α [nV(τ + T)/(W tan α)]ⁿ (power law).

    d0 of (23) substituted into the boundary of (21) and solved for f; at
    equilibrium N ∝ f^(−1/n), so larger f is stable.

    Parameters
    ----------
    NV_critical : sympy.Expr, optional
        NV*, 1/s; KB's 1/(τ + T) by default.
    """
    boundary = wall_condition("power", NV_critical).rhs
    solutions = sp.solve(sp.Eq(wall_equilibrium("power") ** (n + 1), boundary), f)
    if len(solutions) != 1:
        raise RuntimeError(f"expected one positive f on the (24) boundary; got {solutions}")
    # the same value in KB's shape cos α [·]ⁿ, the bracket nV(τ+T)/(W tan α) written with tan α
    bracket = simplify_physical((solutions[0] / sp.cos(alpha)) ** (1 / n))
    bracket = bracket.subs(sp.sin(alpha), sp.cos(alpha) * sp.tan(alpha))
    return sp.StrictGreaterThan(f, sp.cos(alpha) * bracket**n)


# ------------------------------------------------------------------ corridor
@lru_cache(maxsize=None)
def corridor_lateral_force(law="power") -> sp.Expr:
    """Net lateral repulsion at offset x from the centre of a corridor of half-width L.

    x points away from wall 1 (distance L + x, pushes +x) towards wall 2
    (distance L − x, pushes −x): F_r(L + x) − F_r(L − x). (With x measured the
    other way the expression changes sign together with ẋ = V sin θ.)
    """
    law = force_law(law)
    return law(L + x) - law(L - x)


@lru_cache(maxsize=None)
def corridor_gain(law="power") -> sp.Expr:
    """N in the middle of a corridor, 1/m (KB §5.4).

    (9) with the corridor's lateral force and the target straight ahead
    (α = π/2), differentiated in time as for (10) and evaluated at x = 0,
    δ = 0: N = −2F_r′(L)/F_a; power law: 2nfWⁿ/L^(n+1).
    """
    tan_delta = _tan_delta(corridor_lateral_force(law), sp.pi / 2)
    rate = _implicit_rate(tan_delta, (x,))[x]
    return sp.powsimp(sp.simplify(-rate.subs({x: 0, delta: 0}).doit()))


@lru_cache(maxsize=None)
def corridor_condition(law="power", NV_critical=None) -> sp.Rel:
    """KB eq (25): L^(n+1) > 2nWⁿV(T + τ)f (W* misprinted for Wⁿ).

    The corridor gain substituted into (20); for the power law N ∝
    L^(−(n+1)), so the condition is solved for L^(n+1). Other laws:
    1 − N(L)V/NV* > 0.

    Parameters
    ----------
    law : {"power", "general"} or sympy.Lambda
    NV_critical : sympy.Expr, optional
        NV*, 1/s; KB's 1/(τ + T) by default.
    """
    NV_critical = _default_NV(NV_critical)
    gain = corridor_gain(law)
    if law != "power":
        return _gain_condition(gain, NV_critical)
    boundary = sp.solve(gain * V - NV_critical, L)[0]
    return sp.StrictGreaterThan(L ** (n + 1), simplify_physical(boundary ** (n + 1)))


# ------------------------------------------------------------------ the whole derivation
def derivation(law="power", pade_order: int = 2) -> tuple:
    """Every step from KB eq (5) to (25), in order.

    Parameters
    ----------
    law : {"power", "general"} or sympy.Lambda
        Force law for the wall and corridor steps (eq 8 onwards).
    pade_order : int
        Order m of the Padé form of (18) shown.

    Returns
    -------
    tuple of Step
        Expressions arranged for reading (descending powers, ODE terms by
        derivative order); the named functions return canonical forms.
    """
    _check_law(law)
    power = law == "power"
    lin = linearization_gains(law)
    ode = robot_environment_ode()
    lin_ode = linearized_ode()
    routh = routh_criterion("kb_first_order")
    continuous = routh_criterion("continuous")
    P, Q = pade_approximant(_check_order(pade_order))
    d0 = sp.Symbol("d_0", positive=True)
    steps = [
        Step("5", "Steering-rate command", command_equation(), "The controller steers towards the direction delta of the resultant force R (KB write the command u as alpha)."),
        Step("6", "Steering motor", motor_equation(), "First-order lag between the command u and the actual steering rate omega (KB's 'alpha-dot' here is the command u)."),
        Step("7", "Steering equation", sp.Eq(_by_derivative_order(steering_equation().lhs), steering_equation().rhs), "(5) and omega = d(theta)/dt substituted into (6)."),
        Step("8, 13", "Force law", sp.Eq(F_r(d), force_law(law)(d)) if power else force_law(law)(d), "KB's lumped repulsion F_cr W^n/d^n with f = F_cr/F_a (13)." if power else "A general decreasing lateral repulsion F_r(d)."),
        Step("9", "Force balance", force_balance(law), "delta is the direction of R = F_r (away from the wall) + F_a towards a target at angle alpha from the wall normal."),
        Step("10", "Rate of the command", sp.Eq(sp.Derivative(delta_t(t), t), -N * sp.Derivative(d_t(t), t) + M * sp.Derivative(alpha_t(t), t)), "(9) differentiated in time with d, alpha, delta functions of t and solved for d(delta)/dt (KB's OCR prints alpha-dot for d-dot in the first term)."),
        Step("11", "Environment gain N", sp.Eq(N, lin.N), "N = -d(delta-dot)/d(d-dot)" + ("." if power else " = -F_r'(d) cos^2(delta)/(F_a sin(alpha)).")),
        Step("12", "Target-angle gain M", sp.Eq(M, lin.M), "M = d(delta-dot)/d(alpha-dot), F_r eliminated through (9); M = 1 and N = N(d, alpha) for small delta."),
        Step("14", "Kinematics", kinematics(), "Lateral component of the velocity V(sin theta, cos theta)."),
        Step("15, corrected", "Robot-environment equation", sp.Eq(_by_derivative_order(ode.lhs), ode.rhs), "(7) differentiated once, (10) and (14) substituted. KB print (15) one derivative order short."),
        Step("16, corrected", "Linearized equation", sp.Eq(_by_derivative_order(lin_ode.lhs), lin_ode.rhs), "Small theta and delta: sin(theta) ~ theta, M = 1; N constant for slowly varying alpha (then k alpha-dot = 0)."),
        Step("17", "Characteristic equation (continuous)", sp.Eq(_descending(characteristic_polynomial("continuous"), s), 0), "Laplace transform of (16) with zero initial state and alpha-dot = 0."),
        Step("18", "With the loop delay T", sp.Eq(_ordered_sum([_descending(characteristic_polynomial("continuous") - k * N * V, s), k * N * V * delay_transfer("exact_delay")]), 0), "The sampled reference delta is delayed by T: the environment term kNV is multiplied by L{delta(t - T)} = exp(-sT)."),
        Step(f"18, Pade({pade_order},{pade_order})", "Pade form of (18)", sp.Eq(_descending(_cleared(characteristic_polynomial("pade", pade_order)), s), 0), f"exp(-sT) ~ P/Q with P = {sp.sstr(_descending(_cleared(P), s), order='none')}, Q = {sp.sstr(_descending(_cleared(Q), s), order='none')} (denominators cleared); (18) multiplied through by Q."),
        Step("19", "First-order delay approximation", sp.Eq(_descending(characteristic_polynomial("kb_first_order"), s), 0), "exp(-sT) replaced by its Taylor polynomial 1 - sT in (18)."),
        Step("19-20", "Routh array of (19)", routh.matrix(), "Rows s^3 ... s^0; with tau, k, N, V > 0 only the s^1 entry can change sign."),
        Step("20", "KB stability condition", routh.condition, f"The s^1 entry of the first column positive: NV < NV* = {sp.sstr(routh.NV_critical)}; at NV* the s^2 row's auxiliary polynomial gives omega* = {sp.sstr(routh.omega_critical)}. Without delay, (17) gives NV* = {sp.sstr(continuous.NV_critical)}, omega* = {sp.sstr(continuous.omega_critical)}."),
        Step("21", "Wall: distance condition", wall_condition(law), "N of (11) at delta = 0 (cos(delta) = 1) substituted into (20)" + (", solved for d^(n+1)." if power else ".")),
        Step("22", "Wall: steady state", wall_balance(law), "(9) with delta = 0: the lateral forces cancel."),
    ]
    if power:
        steps += [
            Step("23", "Wall: equilibrium distance", sp.Eq(d0, W * simplify_physical(wall_equilibrium(law) / W)), "(22) with the power law solved for d."),
            Step("24", "Wall: force-ratio condition", wall_f_condition(), "d0 of (23) substituted into the boundary of (21) and solved for f."),
        ]
    else:
        steps += [
            Step("23, general", "Wall: gain at equilibrium", sp.Eq(N, wall_gain(law)), "At the d0 solving (22); (24) needs the law's form to be solved for its strength."),
        ]
    steps += [
        Step("25", "Corridor: lateral force", sp.Eq(sp.Symbol("F_x"), corridor_lateral_force(law)), "Offset x from the centre line of a corridor of half-width L; the target is straight ahead (alpha = pi/2)."),
        Step("25", "Corridor: environment gain", sp.Eq(N, corridor_gain(law)), "tan(delta) = F_x/F_a differentiated as for (10) and evaluated at x = 0, delta = 0."),
        Step("25", "Corridor: stability condition", corridor_condition(law), "The corridor N substituted into (20)" + (", solved for L^(n+1) (KB's OCR prints W* for W^n)." if power else ".")),
    ]
    return tuple(steps)
