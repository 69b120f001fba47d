"""Stability regions and boundary curves (`pfm_stability.analysis.regions`, `pfm_stability.analysis.curves`).

Every curve is checked by routes that do not share its algebra:

* the force law (`force_law.wall_gain`: equilibrium of KB eq 22–23 and the
  slope of eq 11; `corridor_gain`, KB §5.4) must put N·V = NV* on each curve
  point, with NV* from the model's own `boundary`;
* the model's `is_stable` (Routh, Schur–Cohn/eigenvalues, crossing count —
  not the boundary) must flip across the curve, on the side the curve states;
* the dense `exact_delay` map (vectorized crossing count, `vectorized`; asked
  for with ``model="exact_delay"``, the maps shade the report's verdict model
  by default, see test_region_shading.py) must change verdict exactly where
  the `exact_delay` curve crosses each grid line, to the grid resolution;
* closed forms (power law) against the general-law bisection, and α* against
  `criteria.critical_alpha` (scalar bisection on α).

Tolerances: NV* is computed to ~1e-12 relative and the curves by closed forms
or bisection to round-off, so N·V = NV* holds to 1e-9 (the grid law's
incomplete-beta evaluation loses a few more digits than the power law).
"""

import json
import math

import numpy as np
import pytest

from pfm_stability.analysis.criteria import critical_alpha, critical_L
from pfm_stability.laws.effective_force import GridWallLaw, calibrate_cell_ratio
from pfm_stability.laws.force_law import ForceLaw, PowerLaw, corridor_gain, wall_gain
from pfm_stability.models import ExactDelay, KBFirstOrder, Loop, Sampled, make_models
from pfm_stability.parameters import CARMEL
from pfm_stability.analysis.comparison import critical_gain_vs_delay, kb_error_map, kb_relative_error
from pfm_stability.parameters import SAMPLED_STRUCTURES
from pfm_stability.analysis.curves import corridor_L_curves, corridor_V_curves, default_models, wall_alpha_curves, wall_f_curves
from pfm_stability.analysis.regions import corridor_region, wall_alpha_region, wall_f_region

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
LOOP = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
LAW = PowerLaw(CONTROLLER.f, CONTROLLER.n, ROBOT.W)
GRID_LAW = GridWallLaw(calibrate_cell_ratio(CONTROLLER.f, CONTROLLER.n, ROBOT.W), CONTROLLER.n, ROBOT.W)
MODELS = default_models(CONTROLLER)
V = np.array([0.1, 0.3, 0.8, 1.5, 2.5])


class Opaque(ForceLaw):
    """KB's power law behind the generic ForceLaw interface: forces the general-law code path."""

    def __init__(self, law):
        self.law, self.name = law, "opaque power law"

    @property
    def scale(self):
        return self.law.scale

    def force(self, d):
        return self.law.force(d)

    def slope(self, d):
        return self.law.slope(d)

    def with_scale(self, scale):
        return Opaque(self.law.with_scale(scale))


def test_default_models_are_the_five_design_models():
    """The five models: continuous, kb_first_order, pade, exact_delay, sampled (controller's structure)."""
    assert [m.name for m in MODELS] == ["continuous", "kb_first_order", "pade", "exact_delay", "sampled"]
    assert (MODELS[-1].hold, MODELS[-1].compute_delay) == (CONTROLLER.hold, CONTROLLER.compute_delay)


# ------------------------------------------------------------ N·V = NV* on every curve
@pytest.mark.parametrize("alpha_deg", [20.0, 45.0, 70.0])
def test_wall_f_curve_puts_NV_at_NV_star(alpha_deg):
    """f*(V) (KB eq 24 with each model's NV*): the equilibrium of eq 23 at f* has N·V = NV* (1e-9)."""
    alpha = math.radians(alpha_deg)
    for c in wall_f_curves(ROBOT, CONTROLLER, alpha, V, MODELS):
        for v, f in zip(c.x, c.y):
            N = wall_gain(PowerLaw(f, LAW.n, LAW.W), alpha)[1]
            assert N * v == pytest.approx(c.NV_critical, rel=1e-9), c.model.name


@pytest.mark.parametrize("law", [LAW, GRID_LAW], ids=["power", "grid"])
def test_wall_alpha_curve_puts_NV_at_NV_star(law):
    """α*(V): wall_gain(law, α*)·V = NV* (1e-9), for KB's law and the grid's effective law."""
    for c in wall_alpha_curves(ROBOT, CONTROLLER, V, MODELS, law=law):
        for v, a in zip(c.x, c.y):
            assert wall_gain(law, a)[1] * v == pytest.approx(c.NV_critical, rel=1e-9), c.model.name


def test_wall_f_curve_general_law_puts_NV_at_NV_star():
    """Grid law: the scale c* returned has wall_gain(law.with_scale(c*), α)·V = NV* (1e-9)."""
    alpha = math.radians(40.0)
    for c in wall_f_curves(ROBOT, CONTROLLER, alpha, V[:4], MODELS, law=GRID_LAW):
        for v, scale in zip(c.x, c.y):
            assert wall_gain(GRID_LAW.with_scale(scale), alpha)[1] * v == pytest.approx(c.NV_critical, rel=1e-9)


@pytest.mark.parametrize("law", [LAW, GRID_LAW], ids=["power", "grid"])
def test_corridor_curves_put_NV_at_NV_star(law):
    """V*(L) and L*(V) (KB eq 25 with each model's NV*): corridor_gain·V = NV* (1e-9)."""
    L = np.array([0.45, 0.6, 0.9, 1.4])
    for c in corridor_V_curves(ROBOT, CONTROLLER, L, MODELS, law=law):
        assert corridor_gain(law, 0.9) * c.y[2] == pytest.approx(c.NV_critical, rel=1e-9)
        np.testing.assert_allclose([corridor_gain(law, l) * v for l, v in zip(c.x, c.y)], c.NV_critical, rtol=1e-9)
    for c in corridor_L_curves(ROBOT, CONTROLLER, V, MODELS, law=law):
        np.testing.assert_allclose([corridor_gain(law, l) * v for v, l in zip(c.x, c.y)], c.NV_critical, rtol=1e-9)


# ------------------------------------------------------------ verdicts flip across the curves
def _nv_wall(f, alpha, v):
    return wall_gain(PowerLaw(f, LAW.n, LAW.W), alpha)[1] * v


@pytest.mark.parametrize("model", MODELS + [Sampled(h, c) for h, c in SAMPLED_STRUCTURES], ids=lambda m: repr(m))
def test_model_verdict_flips_across_its_curves(model):
    """1 % on either side of each curve, the model's own is_stable (not its boundary) agrees with `stable_side`."""
    alpha = math.radians(45.0)
    v = 0.8
    (fc,) = wall_f_curves(ROBOT, CONTROLLER, alpha, [v], [model])
    assert fc.stable_side == "above"
    assert model.is_stable(_nv_wall(1.01 * fc.y[0], alpha, v), LOOP)
    assert not model.is_stable(_nv_wall(0.99 * fc.y[0], alpha, v), LOOP)
    (ac,) = wall_alpha_curves(ROBOT, CONTROLLER, [v], [model])
    assert model.is_stable(wall_gain(LAW, 1.01 * ac.y[0])[1] * v, LOOP)
    assert not model.is_stable(wall_gain(LAW, 0.99 * ac.y[0])[1] * v, LOOP)
    (vc,) = corridor_V_curves(ROBOT, CONTROLLER, [0.9], [model])
    assert vc.stable_side == "below"
    assert model.is_stable(corridor_gain(LAW, 0.9) * 0.99 * vc.y[0], LOOP)
    assert not model.is_stable(corridor_gain(LAW, 0.9) * 1.01 * vc.y[0], LOOP)
    (lc,) = corridor_L_curves(ROBOT, CONTROLLER, [v], [model])
    assert model.is_stable(corridor_gain(LAW, 1.01 * lc.y[0]) * v, LOOP)
    assert not model.is_stable(corridor_gain(LAW, 0.99 * lc.y[0]) * v, LOOP)


# ------------------------------------------------------------ independent routes agree
def test_alpha_curve_equals_scalar_bisection_on_alpha():
    """α*(V) (bisection in d0) equals criteria.critical_alpha (bisection in α) to 1e-10 rad."""
    for law in (LAW, GRID_LAW):
        for c in wall_alpha_curves(ROBOT, CONTROLLER, V[:4], MODELS[:2] + MODELS[-1:], law=law):
            np.testing.assert_allclose(c.y, [critical_alpha(law, v, c.NV_critical) for v in c.x], atol=1e-10)


def test_general_law_route_equals_power_law_closed_forms():
    """The general-law bisections reproduce KB's closed forms (eq 24, 25) for the power law (1e-10 relative)."""
    opaque = Opaque(LAW)
    alpha = math.radians(30.0)
    for a, b in zip(wall_f_curves(ROBOT, CONTROLLER, alpha, V, MODELS), wall_f_curves(ROBOT, CONTROLLER, alpha, V, MODELS, law=opaque)):
        np.testing.assert_allclose(b.y, a.y, rtol=1e-10)
    for a, b in zip(corridor_L_curves(ROBOT, CONTROLLER, V, MODELS), corridor_L_curves(ROBOT, CONTROLLER, V, MODELS, law=opaque)):
        np.testing.assert_allclose(b.y, a.y, rtol=1e-10)
        np.testing.assert_allclose(a.y, [critical_L(LAW, v, a.NV_critical) for v in V], rtol=1e-12)


def test_general_law_region_equals_vectorized_power_law_region():
    """Region maps through the general-law route (delay_verdicts_from_gain) equal exact_delay_verdicts point by point."""
    opaque = Opaque(LAW)
    Vg, fg = np.linspace(0.05, 2, 40), np.geomspace(0.01, 100, 30)
    ag, Lg = np.radians(np.linspace(2, 88, 30)), np.linspace(0.45, 2, 30)
    for a, b in [
        (wall_f_region(ROBOT, CONTROLLER, math.radians(30), Vg, fg, model="exact_delay"), wall_f_region(ROBOT, CONTROLLER, math.radians(30), Vg, fg, law=opaque, model="exact_delay")),
        (wall_alpha_region(ROBOT, CONTROLLER, Vg, ag, model="exact_delay"), wall_alpha_region(ROBOT, CONTROLLER, Vg, ag, law=opaque, model="exact_delay")),
        (corridor_region(ROBOT, CONTROLLER, Lg, Vg, model="exact_delay"), corridor_region(ROBOT, CONTROLLER, Lg, Vg, law=opaque, model="exact_delay")),
    ]:
        np.testing.assert_allclose(b.NV, a.NV, rtol=1e-12)
        assert np.array_equal(a.stable, b.stable)


# ------------------------------------------------------------ shaded edge = exact_delay curve
def _edge_brackets_curve(stable, grid, curve, stable_above):
    """Each column flips verdict once, between the two grid values that bracket the curve."""
    for j in range(stable.shape[1]):
        col = stable[:, j]
        star = curve[j]
        if not np.isfinite(star) or star <= grid[0] or star >= grid[-1]:
            assert col.all() or not col.any()
            continue
        flips = np.flatnonzero(col[1:] != col[:-1])
        assert len(flips) == 1, j
        i = flips[0]
        assert grid[i] <= star <= grid[i + 1], (j, grid[i], star, grid[i + 1])
        assert col[i + 1] == stable_above


def test_wall_f_shading_edge_matches_exact_delay_curve():
    """(V, f) map at α = 30°: the exact_delay verdicts flip between the f grid values bracketing f*(V)."""
    alpha = math.radians(30.0)
    Vg, fg = np.linspace(0.02, 2.0, 120), np.geomspace(0.01, 100.0, 150)
    region = wall_f_region(ROBOT, CONTROLLER, alpha, Vg, fg, model="exact_delay")
    (curve,) = wall_f_curves(ROBOT, CONTROLLER, alpha, Vg, [ExactDelay()])
    _edge_brackets_curve(region.stable, fg, curve.y, stable_above=True)


def test_wall_alpha_shading_edge_matches_exact_delay_curve():
    """(V, α) map: the verdicts flip between the α grid values bracketing α*(V), for both laws."""
    Vg, ag = np.linspace(0.02, 2.0, 80), np.radians(np.linspace(0.5, 89.5, 120))
    for law in (None, GRID_LAW):
        region = wall_alpha_region(ROBOT, CONTROLLER, Vg, ag, law=law, model="exact_delay")
        (curve,) = wall_alpha_curves(ROBOT, CONTROLLER, Vg, [ExactDelay()], law=law)
        _edge_brackets_curve(region.stable, ag, curve.y, stable_above=True)


def test_corridor_shading_edge_matches_exact_delay_curve():
    """(L, V) map: the verdicts flip between the V grid values bracketing V*(L) (stable below)."""
    Lg, Vg = np.linspace(0.41, 2.0, 100), np.linspace(0.02, 2.0, 130)
    region = corridor_region(ROBOT, CONTROLLER, Lg, Vg, model="exact_delay")
    (curve,) = corridor_V_curves(ROBOT, CONTROLLER, Lg, [ExactDelay()])
    _edge_brackets_curve(region.stable, Vg, curve.y, stable_above=False)


# ------------------------------------------------------------ model comparison
def test_critical_gain_vs_delay_matches_closed_forms():
    """NV* vs T/τ: continuous 1/τ (KB eq 17), kb_first_order 1/(τ + T) (eq 20), to 1e-12."""
    x = np.array([0.01, 0.2, 1.0, 3.0])
    curves = {c.model.name: c for c in critical_gain_vs_delay(0.3, 2.0, x, make_models(("continuous", "kb_first_order")))}
    np.testing.assert_allclose(curves["continuous"].NV_critical, 1 / 0.3, rtol=1e-12)
    np.testing.assert_allclose(curves["kb_first_order"].NV_critical, 1 / (0.3 + 0.3 * x), rtol=1e-12)


def test_kb_error_map_is_dimensionless():
    """NV*τ depends on (kτ, T/τ) only: the τ = 1 s map equals direct loops with τ = 0.3 s and 2 s.

    Compared as the ratio NV*_KB/NV*_sampled to 1e-9: the sampled NV* comes
    from unit-circle crossings of a polynomial whose roots crowd near z = 1
    for small T, measured 1.6e-10 apart between the three τ at T/τ = 0.05.
    """
    kt, tt = np.array([0.3, 0.6, 4.0]), np.array([0.05, 0.2167, 1.0])
    m = kb_error_map(kt, tt)
    np.testing.assert_allclose(m.NV_tau_kb[:, 0], 1 / (1 + tt), rtol=1e-14)
    for tau in (0.3, 2.0):
        direct = [[kb_relative_error(Loop(tau, t * tau, k / tau), Sampled("command", 1)) for k in kt] for t in tt]
        np.testing.assert_allclose(1 + m.relative_error, 1 + np.array(direct), rtol=1e-9)


@pytest.mark.parametrize("hold,delay", SAMPLED_STRUCTURES)
def test_kb_error_sign_means_optimistic_or_conservative(hold, delay):
    """Where the map says KB is optimistic (> 0), an NV between the two NV* is stable for KB (eq 19, Routh)
    and unstable for the sampled loop (eigenvalues); conservative (< 0) the other way round."""
    kt, tt = np.geomspace(0.1, 10, 5), np.geomspace(0.02, 1.5, 5)
    m = kb_error_map(kt, tt, Sampled(hold, delay))
    kb, ref = KBFirstOrder(), m.reference
    checked = 0
    for i, t in enumerate(tt):
        for j, k in enumerate(kt):
            e = m.relative_error[i, j]
            if not np.isfinite(e) or abs(e) < 1e-3:
                continue
            loop = Loop(1.0, t, k)
            NV = math.sqrt(m.NV_tau_kb[i, j] * m.NV_tau_reference[i, j])  # strictly between the two NV*
            assert kb.is_stable(NV, loop) == (e > 0)
            assert ref.is_stable(NV, loop) == (e < 0)
            checked += 1
    assert checked >= 10


def test_carmel_kb_error_against_its_sampled_loop():
    """CARMEL (command hold, one-sample delay): KB's NV* = 1/(τ+T) exceeds the sampled NV* (KB optimistic)."""
    e = kb_relative_error(LOOP, Sampled("command", 1))
    NV_s = Sampled("command", 1).boundary(LOOP).NV_critical
    assert e == pytest.approx(1 / (LOOP.tau + LOOP.T) / NV_s - 1, rel=1e-12)
    assert e > 0


# ------------------------------------------------------------ results, errors
def test_results_are_json_serializable():
    """to_dict of every result type gives plain JSON (inf → null)."""
    curve = wall_alpha_curves(ROBOT, CONTROLLER, V[:2], MODELS)[-1]
    region = corridor_region(ROBOT, CONTROLLER, [0.5, 1.0], [0.5, 1.0])
    gain = critical_gain_vs_delay(0.3, 2.0, [0.1, 0.2], [KBFirstOrder()])[0]
    emap = kb_error_map([0.5, 50.0], [0.1, 2.0], Sampled("command", 0))
    assert not np.isfinite(emap.relative_error).all()  # kT = 100: the held steering loop alone is unstable
    for r in (curve, region, gain, emap):
        json.dumps(r.to_dict())
        assert repr(r)
    assert curve.to_dict()["options"] == {"hold": "command", "compute_delay": 1}


@pytest.mark.parametrize(
    "call",
    [
        lambda: corridor_V_curves(ROBOT, CONTROLLER, [0.3, 1.0]),
        lambda: corridor_region(ROBOT, CONTROLLER, [0.3, 1.0], [0.5]),
        lambda: wall_f_curves(ROBOT, CONTROLLER, math.radians(30), [-1.0]),
        lambda: wall_f_curves(ROBOT, CONTROLLER, 2.0, [1.0]),
        lambda: kb_error_map([0.0, 1.0], [0.1]),
    ],
)
def test_bad_inputs_raise_value_error(call):
    """L <= W/2, V <= 0, α outside (0, π/2) and kτ = 0 are rejected with ValueError."""
    with pytest.raises(ValueError):
        call()


def test_simulated_boundary_on_the_sampled_curve():
    """Analytic corridor (KB's law), bisection on V at L = 0.8, 1.0 m: within 2e-3 of V*(L) of `sampled`
    (the bracket is rtol = 1e-3 wide; the analytic simulator matches the sampled model to ~1e-4, test_sim_validation)."""
    from pfm_stability.validation import simulated_boundary

    sim = simulated_boundary("corridor", "V", 0.2, 2.0, over="L", values=[0.8, 1.0], env="analytic", rtol=1e-3, offset=1e-6, duration=20.0)
    (pred,) = corridor_V_curves(ROBOT, CONTROLLER, sim.values, [Sampled("command", 1)])
    np.testing.assert_allclose(sim.critical, pred.y, rtol=2e-3)
    assert not sim.stable_above.any()  # faster is less stable
    json.dumps(sim.to_dict())
