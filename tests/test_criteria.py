"""Wall and corridor criteria (KB §5.3–5.4, eq 20–25) for every model."""

import math

import numpy as np
import pytest

from pfm_stability.analysis.criteria import analyze_corridor, analyze_wall, critical_alpha, critical_L, kb_critical_L
from pfm_stability.laws.force_law import ForceLaw, PowerLaw, corridor_gain, wall_gain
from pfm_stability.models import MODEL_NAMES, make_models
from pfm_stability.parameters import CARMEL, Corridor, Wall

MODELS = make_models(MODEL_NAMES, hold="command", compute_delay=1)


class GenericPowerLaw(ForceLaw):
    """KB's power law without its closed forms: forces the numerical paths."""

    def __init__(self, f, n, W):
        self.scale, self.n, self.W = f, n, W

    def force(self, d):
        return self.scale * (self.W / np.asarray(d, dtype=float)) ** self.n

    def slope(self, d):
        return -self.n * self.scale * self.W**self.n / np.asarray(d, dtype=float) ** (self.n + 1)

    def with_scale(self, scale):
        return GenericPowerLaw(scale, self.n, self.W)


def test_kb_figure5_alpha20_is_unstable():
    """KB Fig 5: CARMEL along a wall at α = 20° oscillates; (24) says unstable."""
    result = analyze_wall(CARMEL.robot, CARMEL.controller, Wall.from_degrees(20), MODELS)
    assert result.models["kb_first_order"].verdict == "unstable"
    f_star = result.models["kb_first_order"].critical["f_critical"]
    r, c = CARMEL.robot, CARMEL.controller
    expected = math.cos(math.radians(20)) * (c.n * r.V * (r.tau + c.T) / (r.W * math.tan(math.radians(20)))) ** c.n
    assert f_star == pytest.approx(expected, rel=1e-12)  # KB eq (24)
    assert f_star > c.f


def test_kb_corridor_half_width():
    """KB eq (25): L* = (2nWⁿV(T+τ)f)^(1/(n+1)) for kb_first_order."""
    r, c = CARMEL.robot, CARMEL.controller
    result = analyze_corridor(r, c, Corridor(0.9), MODELS)
    expected = (2 * c.n * r.W**c.n * r.V * (c.T + r.tau) * c.f) ** (1 / (c.n + 1))
    assert result.models["kb_first_order"].critical["L_critical"] == pytest.approx(expected, rel=1e-12)
    assert kb_critical_L(c.n, r.W, r.V, r.tau + c.T, c.f) == pytest.approx(expected, rel=1e-15)


@pytest.mark.parametrize("alpha_deg", [15.0, 30.0, 60.0])
def test_wall_critical_values_are_on_the_boundary(alpha_deg):
    """Each critical value, put back in, lands on NV = NV* (1e-9), and the verdict
    flips across it (±1 %): α*, f*, V* for every model."""
    r, c = CARMEL.robot, CARMEL.controller
    result = analyze_wall(r, c, Wall.from_degrees(alpha_deg), MODELS)
    for name, v in result.models.items():
        if not 0 < v.NV_critical < math.inf:
            continue
        law = PowerLaw(c.f, c.n, r.W)
        assert wall_gain(law, v.critical["alpha_critical"])[1] * r.V == pytest.approx(v.NV_critical, rel=1e-9)
        assert wall_gain(PowerLaw(v.critical["f_critical"], c.n, r.W), math.radians(alpha_deg))[1] * r.V == pytest.approx(v.NV_critical, rel=1e-9)
        assert result.N * v.critical["V_critical"] == pytest.approx(v.NV_critical, rel=1e-12)
        above = analyze_wall(r, c, Wall(min(v.critical["alpha_critical"] * 1.01, 1.5)), MODELS).models[name]
        below = analyze_wall(r, c, Wall(v.critical["alpha_critical"] * 0.99), MODELS).models[name]
        assert above.verdict == "stable" and below.verdict == "unstable"


def test_corridor_critical_values_are_on_the_boundary():
    """L*, V*, f* put back in give NV = NV*; L slightly wider is stable, narrower is not."""
    r, c = CARMEL.robot, CARMEL.controller
    result = analyze_corridor(r, c, Corridor(0.9), MODELS)
    for name, v in result.models.items():
        if not 0 < v.NV_critical < math.inf:
            continue
        law = PowerLaw(c.f, c.n, r.W)
        L_star = v.critical["L_critical"]
        assert corridor_gain(law, L_star) * r.V == pytest.approx(v.NV_critical, rel=1e-12)
        assert corridor_gain(PowerLaw(v.critical["f_critical"], c.n, r.W), 0.9) * r.V == pytest.approx(v.NV_critical, rel=1e-12)
        if L_star > r.W / 2 / 0.99:
            assert analyze_corridor(r, c, Corridor(L_star * 1.01), MODELS).models[name].verdict == "stable"
            assert analyze_corridor(r, c, Corridor(L_star * 0.99), MODELS).models[name].verdict == "unstable"


def test_general_force_law_reproduces_power_law_closed_forms():
    """General force law (docs/theory.md, "Any force law"): the numerical solution with a law that
    hides its closed form gives KB's closed forms (1e-9 relative: bisection
    stops at 1e-13–1e-14 relative in the solved variable)."""
    r, c = CARMEL.robot, CARMEL.controller
    generic = GenericPowerLaw(c.f, c.n, r.W)
    for alpha in (0.2, 0.7, 1.2):
        closed = analyze_wall(r, c, Wall(alpha), MODELS)
        numeric = analyze_wall(r, c, Wall(alpha), MODELS, law=generic)
        assert numeric.d0 == pytest.approx(closed.d0, rel=1e-12)
        for name in closed.models:
            for key in ("alpha_critical", "f_critical", "V_critical"):
                assert numeric.models[name].critical[key] == pytest.approx(closed.models[name].critical[key], rel=1e-9)
    closed = analyze_corridor(r, c, Corridor(1.1), MODELS)
    numeric = analyze_corridor(r, c, Corridor(1.1), MODELS, law=generic)
    for name in closed.models:
        for key in ("L_critical", "f_critical", "V_critical"):
            assert numeric.models[name].critical[key] == pytest.approx(closed.models[name].critical[key], rel=1e-9)


def test_extreme_angles_are_defined():
    """α → 0: the robot hugs the wall (N → ∞), unstable; α → 90°: N → 0, stable."""
    r, c = CARMEL.robot, CARMEL.controller
    near_zero = analyze_wall(r, c, Wall.from_degrees(1e-6), MODELS)
    near_ninety = analyze_wall(r, c, Wall.from_degrees(90 - 1e-6), MODELS)
    for name in near_zero.models:
        assert near_zero.models[name].verdict == "unstable"
        assert near_ninety.models[name].verdict == "stable"
    assert critical_alpha(PowerLaw(1, 2, 1), 1.0, math.inf) == 0.0
    assert critical_alpha(PowerLaw(1, 2, 1), 1.0, 0.0) == math.pi / 2
    assert critical_L(PowerLaw(1, 2, 1), 1.0, math.inf) == 0.0


def test_bad_scenarios_raise_value_errors():
    r, c = CARMEL.robot, CARMEL.controller
    with pytest.raises(ValueError, match=r"L must be a finite number in \(W/2, 10000\] m = \(0.4, 10000\] m; got 0.3"):
        analyze_corridor(r, c, Corridor(0.3), MODELS)
    with pytest.raises(ValueError, match=r"alpha must be a finite number in \[1e-06, 89.999999\] deg; got 90"):
        Wall.from_degrees(90)
    with pytest.raises(ValueError, match=r"alpha must be a finite number in \[1.74532925199e-08, 1.57079630934\] rad"):
        Wall(0.0)
