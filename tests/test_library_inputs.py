"""Bad input to the library: a `ValueError` naming the argument, never AttributeError/TypeError,
NaN, a negative or a complex number (what the command line turns into exit status 2).

Every public entry point is called with values of the wrong type and outside its range; the
test fails on any other exception and on a returned NaN, complex or negative critical value.
"""

import math

import numpy as np
import pytest

import pfm_stability as P
from pfm_stability import CARMEL

R, C = CARMEL.robot, CARMEL.controller
LAW = P.PowerLaw(0.8, 2.0, 0.8)
LOOP = P.Loop(0.3, 0.065, 2.0)
BAD = [None, "x", -1.0, 0.0, float("nan"), float("inf"), 1e300, True, 3j, [1.0, 2.0], np.array([1.0, -1.0])]

CALLS = {
    "kb_critical_L n": (lambda a: P.kb_critical_L(a, 0.8, 0.8, 0.365, 0.8), "n"),
    "kb_critical_L f": (lambda a: P.kb_critical_L(2.0, 0.8, 0.8, 0.365, a), "f"),
    "kb_critical_L V": (lambda a: P.kb_critical_L(2.0, 0.8, a, 0.365, 0.8), "V"),
    "kb_critical_f_wall alpha": (lambda a: P.kb_critical_f_wall(a, 0.8, 0.365, 2.0, 0.8), "alpha"),
    "kb_critical_f_wall n": (lambda a: P.kb_critical_f_wall(0.5, 0.8, 0.365, a, 0.8), "n"),
    "wall_gain alpha": (lambda a: P.wall_gain(LAW, a), "alpha"),
    "wall_gain law": (lambda a: P.wall_gain(a, 0.5), "law"),
    "corridor_gain L": (lambda a: P.corridor_gain(LAW, a), "L"),
    "corridor_gain law": (lambda a: P.corridor_gain(a, 0.9), "law"),
    "analyze_wall robot": (lambda a: P.analyze_wall(a, C, P.Wall(0.5)), "robot"),
    "analyze_wall controller": (lambda a: P.analyze_wall(R, a, P.Wall(0.5)), "controller"),
    "analyze_wall wall": (lambda a: P.analyze_wall(R, C, a), "wall"),
    "analyze_wall models": (lambda a: P.analyze_wall(R, C, P.Wall(0.5), a), "model"),
    "analyze_wall law": (lambda a: P.analyze_wall(R, C, P.Wall(0.5), None, a), "law"),
    "analyze_corridor corridor": (lambda a: P.analyze_corridor(R, C, a), "corridor"),
    "build_report robot": (lambda a: P.build_report(a, C, L=0.9), "robot"),
    "build_report models": (lambda a: P.build_report(R, C, L=0.9, models=a), "model"),
    "build_report L": (lambda a: P.build_report(R, C, L=a), "L"),
    "build_report alpha_deg": (lambda a: P.build_report(R, C, alpha_deg=a), "alpha"),
    "make_models": (lambda a: P.make_models(a), "names"),
    "boundary loop": (lambda a: P.ExactDelay().boundary(a), "loop"),
    "is_stable NV": (lambda a: P.Sampled().is_stable(a, LOOP), "NV"),
    "rightmost_root NV": (lambda a: P.ExactDelay().rightmost_root(a, LOOP).real, "NV"),  # NV < 0 is valid (N < 0 diverges): the root is complex-typed
    "critical_delay loop": (lambda a: P.Pade().critical_delay(1.0, a), "loop"),
    "DelayLoop a": (lambda a: P.DelayLoop(a, 0.1), "a"),
    "DelayLoop K": (lambda a: P.DelayLoop([1.0, 1.0, 0.0], 0.1).is_stable(a), "K"),
    "routh_array": (lambda a: P.routh_array(a), "coefficients"),
    "schur_cohn_stable": (lambda a: P.schur_cohn_stable(a), "coefficients"),
    "exact_delay_verdicts V": (lambda a: P.exact_delay_verdicts(a, 0.3, 0.065, 2.0, 0.8, 2.0, 0.8, L=0.9), "V"),
}


@pytest.mark.parametrize("name", sorted(CALLS))
def test_bad_arguments_raise_value_errors_naming_them(name):
    """Each bad value either gives a clean answer (a finite, non-negative, real number where the
    value happens to be valid, e.g. an array for the vectorized API) or a ValueError whose
    message names the argument."""
    call, argument = CALLS[name]
    for value in BAD:
        try:
            out = call(value)
        except ValueError as exc:
            assert argument in str(exc), f"{name}({value!r}): message does not name {argument!r}: {exc}"
            continue
        values = out.NV if hasattr(out, "NV") else (out.first_column if hasattr(out, "first_column") else out)
        for x in np.atleast_1d(np.asarray(values, dtype=object)).ravel():
            if isinstance(x, (int, float, complex, np.number)):
                assert not isinstance(x, complex) and not math.isnan(float(x)), f"{name}({value!r}) returned {out!r}"


def test_closed_forms_accept_symbols_and_reject_bad_numbers():
    """kb_critical_L / kb_critical_f_wall stay plain arithmetic for sympy symbols (compared exactly
    with the derivation elsewhere) but check numbers: no NaN, complex or negative result."""
    import sympy as sp

    n, W, V, t, f = sp.symbols("n W V t f", positive=True)
    assert P.kb_critical_L(n, W, V, t, f) == (2 * n * W**n * V * t * f) ** (1 / (n + 1))
    for bad in (-1.0, 0.0, float("nan")):
        with pytest.raises(ValueError, match="f must be"):
            P.kb_critical_L(2.0, 0.8, 0.8, 0.365, bad)
    assert P.kb_critical_L(2.0, 0.8, 0.8, 0.365, 0.8) == pytest.approx((2 * 2 * 0.64 * 0.8 * 0.365 * 0.8) ** (1 / 3), rel=1e-15)


def test_extreme_laws_give_a_named_error_not_an_overflow():
    """A force law so extreme that N·V leaves floating point: a ValueError that says so, no NaN."""
    controller = C.replace(f=1e-6, n=0.1)
    with pytest.raises(ValueError, match="N\\*V|outside floating point"):
        P.analyze_wall(R, controller, P.Wall.from_degrees(1e-6))
