"""KB's figures as presets (docs/simulator.md, scenarios), and invalid scenario parameters."""

import math

import pytest

from pfm_stability.laws.effective_force import GridWallLaw, calibrate_cell_ratio, f_average
from pfm_stability.parameters import CARMEL
from pfm_stability.sim import SCENARIO_NAMES, make_scenario, simulate
from pfm_stability.validation import predict


def test_fig6_narrow_oscillates_and_wide_settles():
    """KB Fig 6 (f_av = 0.8, n = 2, T = 0.065 s, τ = 0.3 s, V = 0.8 m/s): after the step at Y = 4 m the
    narrow corridor oscillates with growing amplitude into a collision; the wide one settles.

    Both as predicted by the sampled model with the grid's effective law
    (L* = 0.69 m; narrow L = 0.6 m, wide L = 0.9 m after the step).
    """
    narrow, wide = simulate("kb-fig6-narrow"), simulate("kb-fig6-wide")
    assert narrow.metrics.oscillating and narrow.metrics.growth_rate > 0 and narrow.collided
    assert narrow.event("collision").t > 6.0  # after the step at Y = 4 m (t = 5 s) and a growing swing
    assert wide.metrics.stable and not wide.metrics.oscillating and not wide.events
    assert wide.metrics.growth_rate < 0
    assert predict(narrow.scenario).matching.verdict == "unstable"
    assert predict(wide.scenario).matching.verdict == "stable"


def test_fig5_discontinuity_makes_the_wall_run_unstable():
    """KB Fig 5: fairly straight along the first wall section (α = 50°), oscillation after the corner (α = 20°)
    that grows until the robot collides."""
    run = simulate("kb-fig5")
    collision = run.event("collision")
    assert collision is not None
    corner_time = 5.0 / 0.8  # the start is 5 m before the corner
    assert collision.t > corner_time
    tr = run.trajectory
    before = tr.t < corner_time - 1.0
    # straight: lateral excursion from the first section's line stays within 5 cm
    u = (math.sin(math.radians(30)), math.cos(math.radians(30)))
    lateral = (tr.x[before] - tr.x[0]) * u[1] - (tr.y[before] - tr.y[0]) * u[0]
    assert max(abs(lateral)) < 0.05
    assert predict(run.scenario).matching.verdict == "unstable"


def test_fig3_calibration_barely_avoids_and_f_av_calibration_collides():
    """KB Fig 3: the preset's ratio is KB's procedure (smallest avoiding ratio) and clears the block by < 1 cm;
    the ratio with f_av = 0.8 collides — the discrepancy reported in the preset's notes."""
    run = simulate("kb-fig3")
    assert [e.type for e in run.events] == ["target_reached"]
    assert 0 < run.min_clearance < 0.01
    rho = run.scenario.cell_ratio
    assert f_average(GridWallLaw(rho, 2.0, 0.8)) > 1.5
    weaker = simulate("kb-fig3", cell_ratio=calibrate_cell_ratio(0.8, 2.0, 0.8))
    assert weaker.collided


def test_presets_document_their_choices():
    """Every preset records its geometry and how F_cr/F_ct was set (presets quoting f = 0.8; docs/simulator.md)."""
    for name in SCENARIO_NAMES:
        s = make_scenario(name)
        assert "geometry" in s.notes and "cell_ratio" in s.notes
    notes = make_scenario("kb-fig6-narrow").notes
    assert "f_av = 0.8" in notes["cell_ratio"] and notes["f_av"].startswith("0.8")


def test_analytic_variants_exist():
    for name in ("corridor", "wall", "kb-fig5", "kb-fig6-wide", "kb-fig6-narrow", "straight"):
        assert make_scenario(name, env="analytic").env == "analytic"
    assert make_scenario("corridor", env="analytic", law="grid").effective_law().name.startswith("grid wall")


@pytest.mark.parametrize(
    "kwargs,message",
    [
        (dict(name="corridor", L=0.35), r"L must be a finite number in \(W/2 \+ c/2"),
        (dict(name="corridor", L=0.35, env="analytic"), r"L must be a finite number in \(W/2, 10000\]"),
        (dict(name="corridor", controller=CARMEL.controller.replace(T=0.0)), r"T must be a finite number in \(0, 100\] s"),
        (dict(name="corridor", window_cells=32), "window_cells must be an odd integer"),
        (dict(name="corridor", window_cells=1), "window_cells must be an odd integer"),
        (dict(name="kb-fig3", env="analytic"), "env must be grid for kb-fig3"),
        (dict(name="kb-fig3", L=1.0), "L does not apply"),
        (dict(name="corridor", offset=0.7), r"offset must be a finite number in \(-0.55, 0.55\) m .*; got 0.7"),
        (dict(name="wall", env="analytic", controller=CARMEL.controller.replace(f=0.1)), "alpha must give an equilibrium"),
        (dict(name="maze"), "scenario must be one of"),
        (dict(name="corridor", env="sky"), "env must be one of"),
        (dict(name="corridor", env="analytic", cell_ratio=0.01), "cell_ratio applies to env=grid"),
        (dict(name="corridor", law="grid"), "law applies to env=analytic only"),
        (dict(name="corridor", robot=CARMEL.robot.replace(W=4.0)), "W must be a finite number in"),
        (dict(name="kb-fig6-narrow", robot=CARMEL.robot.replace(W=1.2)), "corridor half-width after the step must be"),
    ],
)
def test_invalid_scenarios_raise_clear_errors(kwargs, message):
    name = kwargs.pop("name")
    with pytest.raises(ValueError, match=message):
        make_scenario(name, **kwargs)


def test_target_inside_an_obstacle_is_rejected():
    from pfm_stability.sim import HistogramGrid, Pose, Scenario, Target

    grid = HistogramGrid.centred(-3, 3, -1, 6).draw_rectangle(-0.5, 3.0, 0.5, 4.0)
    with pytest.raises(ValueError, match="target must not lie inside an obstacle"):
        Scenario("box", CARMEL.robot, CARMEL.controller, grid, Pose(0, 0), Target.point(0.0, 3.5), 10.0)
