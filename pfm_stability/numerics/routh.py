"""Routh–Hurwitz and Schur–Cohn (Jury) tests for polynomials of any degree.

`routh_array` builds the Routh array of a real polynomial, numerically (floats)
or symbolically (sympy expressions), and handles the two special cases:

* a zero in the first column of an otherwise non-zero row: replaced by a
  positive symbol ε, the signs taken in the limit ε → 0+. A float array
  cannot keep 1/ε and ε² apart once zero pivots chain, so numerically every
  entry carries a running error bound, and wherever a first-column sign is
  not certain (a zero, a cancellation, a zero row) the float coefficients are
  converted exactly to rationals and the symbolic array decides;
* a row of zeros (roots symmetric about the origin, e.g. a pair on the imaginary
  axis): replaced by the coefficients of the derivative of the auxiliary
  polynomial formed from the row above.

The number of sign changes in the first column equals the number of roots with
positive real part (Routh 1877; Gantmacher, *Matrix Theory* II, ch. XV). A row of
zeros marks roots symmetric about the origin, so the verdict is then at best
marginal: `RouthResult.marginal` is set.

`schur_cohn_stable` is the discrete-time counterpart used by the ``sampled``
model: all roots strictly inside the unit circle, by the Schur–Cohn step-down
recursion (Jury's table in reflection-coefficient form; Åström & Wittenmark,
*Computer-Controlled Systems*, 3rd ed., §3.3).

KB (Koren & Borenstein 1991) apply Routh to their eq (19) to obtain eq (20).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_number

__all__ = ["RouthResult", "real_coefficients", "routh_array", "routh_count", "routh_stable", "schur_cohn_stable", "strip_leading_zeros"]


@dataclass(frozen=True)
class RouthResult:
    """Routh array and what it says.

    Attributes
    ----------
    table : list[list]
        The rows s^n … s^0 (floats or sympy expressions).
    first_column : list
        First entry of every row (after ε and auxiliary-polynomial substitution).
    sign_changes : int
        Sign changes in the first column = roots with Re > 0 (exact unless
        `marginal`).
    marginal : bool
        A row of zeros (roots symmetric about the origin, possibly on the
        imaginary axis) or a zero last entry (a root at s = 0).
    epsilon_used : bool
        A zero first-column entry occurred (resolved by ε → 0+); the count is still exact when no root lies on the
        imaginary axis, but the polynomial is not Hurwitz (a Hurwitz
        polynomial has no zero in the first column).
    """

    table: list
    first_column: list
    sign_changes: int
    marginal: bool
    epsilon_used: bool = False

    @property
    def stable(self) -> bool:
        """True when every root has a negative real part."""
        return self.sign_changes == 0 and not self.marginal and not self.epsilon_used


def real_coefficients(coefficients, name: str = "coefficients") -> np.ndarray:
    """A 1-D float array of finite real polynomial coefficients, or ValueError naming `name`.

    Parameters
    ----------
    coefficients : array_like
        Polynomial coefficients, descending powers.
    name : str
        The name the error message gives them.
    """
    message = f"{name} must be a non-empty sequence of finite real numbers (descending powers); got {coefficients!r}"
    if isinstance(coefficients, (str, bytes)) or np.ndim(coefficients) != 1:
        raise ValueError(message)
    try:
        c = np.asarray(coefficients, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(message) from None
    if c.size == 0 or not np.all(np.isfinite(c)):
        raise ValueError(message)
    return c


def strip_leading_zeros(coefficients) -> np.ndarray:
    """Drop leading (highest-power) exact zeros of a descending coefficient array.

    Parameters
    ----------
    coefficients : array_like
        Real polynomial coefficients, descending powers, not all zero.
    """
    c = real_coefficients(coefficients)
    nonzero = np.flatnonzero(c)
    if nonzero.size == 0:
        raise ValueError("polynomial must have a non-zero coefficient; got all zeros")
    return c[nonzero[0]:]


def routh_array(coefficients) -> RouthResult:
    """Routh array of a polynomial given in descending powers.

    Parameters
    ----------
    coefficients : sequence of float or sympy expressions
        a_n, …, a_0 of a_n s^n + … + a_0 (a_n ≠ 0). If any entry is a sympy
        expression the array is built symbolically.

    Returns
    -------
    RouthResult
        For symbolic input, `sign_changes` is computed only when every
        first-column entry has a decidable sign (else -1).
    """
    if np.ndim(coefficients) == 1 and any(_is_sympy(c) for c in coefficients):
        return _routh_symbolic(list(coefficients))
    return _routh_numeric(strip_leading_zeros(coefficients))


def _first_two_rows(c):
    n = len(c) - 1
    width = n // 2 + 1
    row0 = [c[i] for i in range(0, n + 1, 2)]
    row1 = [c[i] for i in range(1, n + 1, 2)]
    zero = 0 * c[0]
    row0 += [zero] * (width - len(row0))
    row1 += [zero] * (width - len(row1))
    return row0, row1, width


def _next_row(upper, lower):
    # r_j = (lower0 * upper_{j+1} - upper0 * lower_{j+1}) / lower0
    width = len(upper)
    zero = 0 * upper[0]
    row = []
    for j in range(width):
        a = upper[j + 1] if j + 1 < width else zero
        b = lower[j + 1] if j + 1 < width else zero
        row.append((lower[0] * a - upper[0] * b) / lower[0])
    return row


def _auxiliary_derivative(upper, power):
    # auxiliary polynomial A(s) = sum upper[j] s^(power-2j); rows take dA/ds
    return [upper[j] * (power - 2 * j) for j in range(len(upper))]


def _next_row_numeric(upper, lower, upper_err, lower_err):
    """Next Routh row and a first-order bound on each entry's absolute error.

    r_j = a − u₀·b/l₀ (a = upper[j+1], b = lower[j+1]); the bound adds the
    propagated errors of a, u₀, b, l₀ and the rounding of the three operations
    (running error analysis, Higham, *Accuracy and Stability of Numerical
    Algorithms*, §3.3).
    """
    width = len(upper)
    l0, u0, e_l0, e_u0 = lower[0], upper[0], lower_err[0], upper_err[0]
    row, err = [], []
    for j in range(width):
        a, e_a = (upper[j + 1], upper_err[j + 1]) if j + 1 < width else (0.0, 0.0)
        b, e_b = (lower[j + 1], lower_err[j + 1]) if j + 1 < width else (0.0, 0.0)
        term = u0 * b / l0
        value = a - term
        bound = e_a + abs(b / l0) * e_u0 + abs(u0 / l0) * e_b + abs(term / l0) * e_l0
        row.append(value)
        err.append(bound + 3 * _EPS * (abs(a) + abs(term)))
    return row, err


_EPS = np.finfo(float).eps
_SIGN_MARGIN = 1e3
"""An entry whose magnitude is within this factor of its error bound has no certain sign."""


def _routh_numeric(c: np.ndarray) -> RouthResult:
    """Numeric Routh array; where floats cannot certify a sign, exact arithmetic.

    Every entry carries a running error bound. A first-column entry within
    1e3 of its bound — a zero pivot, a pivot lost to cancellation, a zero
    row — or an overflow hands the float coefficients, converted exactly to
    rationals, to the symbolic array, which takes ε → 0+ where a pivot is
    exactly zero (Gantmacher, ch. XV §6). A finite ε cannot stand in for that
    limit in floating point once zero pivots chain (1/ε and ε² must be kept
    apart).
    """
    if len(c) == 1:
        return RouthResult([[float(c[0])]], [float(c[0])], 0, False)
    result = _routh_table(c)
    if result is None:
        import sympy as sp

        return _routh_symbolic([sp.Rational(float(x)) for x in c])
    return result


def _routh_table(c: np.ndarray) -> RouthResult | None:
    """The float array, or None where a first-column sign is not certain."""
    n = len(c) - 1
    row0, row1, _ = _first_two_rows([float(x) for x in c])
    table = [row0, row1]
    errors = [[0.0] * len(row0), [0.0] * len(row1)]  # the coefficients are exact
    for _ in range(n - 1):
        upper, lower = table[-2], table[-1]
        if abs(lower[0]) <= _SIGN_MARGIN * errors[-1][0]:
            return None  # zero, or of unknown sign: zero row and ε cases included
        row, err = _next_row_numeric(upper, lower, errors[-2], errors[-1])
        if not all(math.isfinite(x) for x in row + err):
            return None
        table.append(row)
        errors.append(err)
    first = [row[0] for row in table]
    if any(abs(x) <= _SIGN_MARGIN * e[0] for x, e in zip(first, errors)):
        return None
    signs = [x > 0 for x in first]
    changes = sum(1 for a, b in zip(signs, signs[1:]) if a != b)
    return RouthResult(table, first, changes, False)


def _is_sympy(x) -> bool:
    return type(x).__module__.startswith("sympy")


def _routh_symbolic(c) -> RouthResult:
    import sympy as sp

    c = [sp.sympify(x) for x in c]
    while c and c[0] == 0:
        c.pop(0)
    n = len(c) - 1
    epsilon = sp.Symbol("epsilon", positive=True)
    if n == 0:
        return RouthResult([[c[0]]], [c[0]], 0, False)
    row0, row1, _ = _first_two_rows(c)
    table = [row0, row1]
    marginal = epsilon_used = False
    for power in range(n - 1, 0, -1):
        upper, lower = table[-2], table[-1]
        if all(sp.simplify(x) == 0 for x in lower):
            marginal = True
            lower = _auxiliary_derivative(upper, power + 1)
            table[-1] = lower
        if sp.simplify(lower[0]) == 0:
            epsilon_used = True
            lower = [epsilon] + list(lower[1:])
            table[-1] = lower
        table.append([sp.simplify(x) for x in _next_row(upper, lower)])
    first = [sp.simplify(row[0]) for row in table]
    # sign of each entry as ε → 0+ (ε itself counts as positive)
    limits = [sp.limit(sp.sign(x), epsilon, 0, "+") if x.has(epsilon) else x for x in first]
    signs = []
    for x in limits:
        if x.is_extended_positive:
            signs.append(1)
        elif x.is_extended_negative:
            signs.append(-1)
        elif x.is_zero:
            continue
        else:
            return RouthResult(table, first, -1, marginal, epsilon_used)
    changes = sum(1 for a, b in zip(signs, signs[1:]) if a != b)
    return RouthResult(table, first, changes, marginal, epsilon_used)


def routh_count(coefficients) -> int:
    """Number of roots with positive real part by Routh's sign changes.

    Parameters
    ----------
    coefficients : sequence of float
        Descending powers, leading coefficient non-zero.
    """
    return routh_array(coefficients).sign_changes


def routh_stable(coefficients) -> bool:
    """True when every root of the polynomial has a negative real part (Routh).

    A zero row or zero first-column entry (a root on, or symmetric about, the
    imaginary axis) counts as not stable.

    Parameters
    ----------
    coefficients : array_like
        Real polynomial coefficients, descending powers.
    """
    return routh_array(coefficients).stable


def schur_cohn_stable(coefficients, margin: float = 0.0) -> bool:
    """True when every root lies strictly inside the unit circle (Schur–Cohn).

    Step-down recursion on the reflection coefficients of the monic polynomial
    z^n + a_1 z^(n−1) + … + a_n: stable ⇔ every reflection coefficient
    κ_i satisfies |κ_i| < 1 (Jury's table in lattice form).

    Parameters
    ----------
    coefficients : sequence of float
        Descending powers of z, leading coefficient non-zero.
    margin : float
        Require |κ_i| < 1 − margin (0 by default).
    """
    a = strip_leading_zeros(coefficients)
    margin = check_number("margin", margin, 0.0, 1.0, low_open=False, high_open=True)
    a = a / a[0]
    while len(a) > 1:
        kappa = a[-1]
        if not abs(kappa) < 1.0 - margin:
            return False
        a = (a - kappa * a[::-1])[:-1] / (1.0 - kappa * kappa)
    return True
