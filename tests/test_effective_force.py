"""The grid's effective force law (docs/simulator.md, grid quantization; KB eq 1–2, 8, §4 f_av)."""

import contextlib
import io
import json
import math

import numpy as np
import pytest

from pfm_stability.cli import main
from pfm_stability.analysis.criteria import analyze_corridor, analyze_wall, critical_L
from pfm_stability.laws.effective_force import (
    GridWallLaw,
    calibrate_cell_ratio,
    check_window_cells,
    corridor_lateral_force,
    f_average,
    working_range,
)
from pfm_stability.laws.fields import make_law
from pfm_stability.laws.force_law import PowerLaw, corridor_gain
from pfm_stability.models import Loop, Sampled
from pfm_stability.report.stability import build_report
from pfm_stability.parameters import CARMEL, Corridor, Wall
from pfm_stability.sim.vff import measured_wall_force

RHO = calibrate_cell_ratio(0.8, 2.0, 0.8)


@pytest.mark.parametrize("n", [2.0, 1.5, 3.0])
def test_closed_form_equals_cell_sum(n):
    """KB eq 1–2 summed over the drawn wall cells, averaged along the wall, equals the closed form.

    The average over the robot's position in its cell turns the sum into an
    exact line integral (module docstring); Gauss–Legendre with 24 nodes is
    exact for the smooth in-cell dependence, so only round-off remains (1e-13).
    """
    law = GridWallLaw(0.01, n, 0.8)
    d = np.array([0.3, 0.45, 0.8, 1.2, 1.6, 1.64])
    assert np.allclose(measured_wall_force(law, d), law.force(d), rtol=1e-13, atol=0)


@pytest.mark.parametrize("n", [2.0, 1.5, 3.0])
def test_slope_matches_central_difference(n):
    """F′(d) closed form vs a central difference (step 1e-6 m: truncation ~1e-12, round-off ~1e-10 relative)."""
    law = GridWallLaw(RHO, n, 0.8)
    d = np.array([0.3, 0.6, 1.0, 1.5, 1.64, 2.0, 3.0])
    h = 1e-6
    numeric = (law.force(d + h) - law.force(d - h)) / (2 * h)
    assert np.allclose(law.slope(d), numeric, rtol=1e-8, atol=0)


def test_n2_form_and_one_over_d_behaviour():
    """n = 2: F = ρCW²(2/c)·Y/(d√(d²+Y²)) — ∝ 1/d for d ≪ Y (docs/simulator.md: 'pushes ∝ ~1/d').

    The local exponent is 1 + d²/(d² + Y²) (exact identity, 1e-12): 1.07 at
    contact (0.45 m), 1.19 at 0.8 m, 1.5 at the reach where d = Y — the
    design quoted ≈ 1–1.4 for the distances a robot usually keeps.
    """
    law = GridWallLaw(RHO, 2.0, 0.8)
    Y = law.half_length
    d = np.linspace(0.3, 1.6, 14)
    expected = RHO * 15 * 0.8**2 * (2 / 0.1) * Y / (d * np.sqrt(d * d + Y * Y))
    assert np.allclose(law.force(d), expected, rtol=1e-12)
    assert np.allclose(law.local_exponent(d), 1 + d**2 / (d**2 + Y**2), rtol=1e-12)
    lo, hi = working_range(0.8)
    exponents = law.local_exponent(np.array([lo, hi]))
    assert exponents[0] == pytest.approx(1.069, abs=1e-3)
    assert exponents[1] == pytest.approx(1.5, rel=1e-12)


def test_uncalibrated_grid_pushes_about_ten_times_harder():
    """docs/simulator.md: with each cell as strong as KB's lumped constant (ρ·C = f) the grid pushes ~10× harder.

    Over the working range the ratio to f(W/d)² is 2·Y·d/(c√(d²+Y²)): 8.5 at
    0.45 m to 23 at 1.65 m for CARMEL (exact values; bounds 5–30 leave room
    only for a wrong formula, not for a different design).
    """
    f = 0.8
    raw = GridWallLaw(f / 15, 2.0, 0.8)
    d = np.linspace(*working_range(0.8), 20)
    ratio = raw.window_force(d) / PowerLaw(f, 2.0, 0.8).force(d)
    assert 5 < ratio.min() and ratio.max() < 30
    assert ratio[len(d) // 3] == pytest.approx(2 * raw.half_length * d[len(d) // 3] / (0.1 * math.hypot(d[len(d) // 3], raw.half_length)))


def test_tail_beyond_reach_is_c1_and_decreasing():
    """Beyond the window's reach the law continues C¹ and strictly decreasing; the grid's true force is 0.

    Continuity at the reach to 1e-12 relative (both sides are closed forms).
    """
    law = GridWallLaw(RHO, 2.0, 0.8)
    R = law.reach
    assert R == pytest.approx(1.65)
    eps = 1e-9
    assert law.force(R + eps) == pytest.approx(float(law.force(R - eps)), rel=1e-8)
    assert law.slope(R + eps) == pytest.approx(float(law.slope(R - eps)), rel=1e-8)
    d = np.linspace(0.05, 10, 500)
    assert np.all(np.diff(law.force(d)) < 0) and np.all(law.slope(d) < 0)
    assert law.window_force(R + 0.01) == 0.0


def test_f_average_and_calibration():
    """KB §4: f_av is the mean of f(d) = F(d)(d/W)^n over the working range; ρ is calibrated to give f_av = f.

    64 Gauss–Legendre nodes equal 256 to round-off (f(d) is smooth); the
    calibration is linear in ρ, so f_av of the calibrated law equals the
    target to round-off (1e-12).
    """
    law = GridWallLaw(1.0, 2.0, 0.8)
    assert f_average(law) == pytest.approx(f_average(law, points=256), rel=1e-13)
    assert working_range(0.8) == pytest.approx((0.45, 1.65))
    for target in (0.4, 0.8, 2.0):
        rho = calibrate_cell_ratio(target, 2.0, 0.8)
        assert f_average(GridWallLaw(rho, 2.0, 0.8)) == pytest.approx(target, rel=1e-12)
    assert calibrate_cell_ratio(0.8, 2.0, 0.8) == pytest.approx(2 * calibrate_cell_ratio(0.4, 2.0, 0.8), rel=1e-14)


def test_equivalent_f_brackets_f_av():
    """f(d) rises across the working range (F ∝ ~1/d against KB's 1/d²), so f_av lies strictly inside it."""
    law = GridWallLaw(RHO, 2.0, 0.8)
    lo, hi = working_range(0.8)
    f = law.equivalent_f(np.array([lo, hi]), 2.0, 0.8)
    assert f[0] < 0.8 < f[1]


def test_corridor_force_and_gain():
    """Corridor: F_x(x) = F(L+x) − F(L−x) is odd in x and its slope at 0 is −N = 2F′(L) (docs/theory.md)."""
    law = GridWallLaw(RHO, 2.0, 0.8)
    L = 0.8
    x = np.array([0.01, 0.05, 0.2])
    assert np.allclose(corridor_lateral_force(law, L, x), -corridor_lateral_force(law, L, -x), rtol=1e-14)
    h = 1e-6
    slope = (corridor_lateral_force(law, L, h) - corridor_lateral_force(law, L, -h)) / (2 * h)
    assert slope == pytest.approx(-corridor_gain(law, L), rel=1e-7)


def test_criteria_accept_the_grid_law():
    """analyze_corridor/analyze_wall(..., law=GridWallLaw) give finite verdicts and critical values inside the window.

    L* by the general-law root finder must satisfy N(L*)·V = NV* of the
    sampled model to the finder's precision (1e-10).
    """
    law = GridWallLaw(RHO, 2.0, 0.8)
    robot, controller = CARMEL.robot, CARMEL.controller
    model = Sampled(controller.hold, controller.compute_delay)
    corridor = analyze_corridor(robot, controller, Corridor(0.8), [model], law=law)
    L_star = corridor.models["sampled"].critical["L_critical"]
    NV_star = model.boundary(Loop(robot.tau, controller.T, robot.k)).NV_critical
    assert corridor_gain(law, L_star) * robot.V == pytest.approx(NV_star, rel=1e-10)
    assert 0.45 < L_star < law.reach
    wall = analyze_wall(robot, controller, Wall(math.radians(45)), [model], law=law)
    assert wall.models["sampled"].verdict == "stable"
    assert 0.45 < wall.d0 < law.reach
    assert critical_L(law, robot.V, NV_star) == pytest.approx(L_star)


def _grid_report(robot, controller, **geometry):
    """`build_report` with the grid law calibrated from the controller's f (KB §4), as ``--law grid`` builds it."""
    return build_report(robot, controller, law=make_law("grid", robot, controller), **geometry)


@pytest.mark.parametrize("geometry, robot, f", [({"L": 0.4}, CARMEL.robot.replace(W=0.4), 1.5), ({"alpha_deg": 20.0}, CARMEL.robot, 0.8),
                                                 ({"L": 0.9}, CARMEL.robot, 0.8)], ids=["config corridor", "carmel wall", "carmel corridor"])
def test_grid_law_f_critical_and_remedy_are_in_f(geometry, robot, f):
    """With ``--law grid`` the user's f is KB's lumped f_av and the law's scale the cell ratio: f* and "to stabilize f"
    are in f (docs/fields.md). Oracle, per model: the report rebuilt (library call) at f*·(1 ∓ 1e-6), the cell ratio
    calibrated from that f, has opposite verdicts, the stable one on f*'s stated side (wall: above, corridor: below);
    1e-6 is far above the closed form's or bisection's round-off and far below any other change. The remedy's "to"
    is f*, its percentage against the user's f."""
    controller = CARMEL.controller.replace(f=f)
    scenario = "corridor" if "L" in geometry else "wall"
    report = _grid_report(robot, controller, models=["continuous", "kb_first_order", "sampled"], **geometry)
    analysis = getattr(report, scenario)
    for name, verdict in analysis.models.items():
        f_star = verdict.critical["f_critical"]
        side = verdict.critical.stable_side("f_critical")
        assert side == ("below" if scenario == "corridor" else "above") and 1e-3 < f_star < 1e3
        verdicts = {}
        for where, x in (("below", f_star * (1 - 1e-6)), ("above", f_star * (1 + 1e-6))):
            verdicts[where] = getattr(_grid_report(robot, controller.replace(f=x), models=[name], **geometry), scenario).models[name].stable
        assert verdicts[side] and not verdicts[{"below": "above", "above": "below"}[side]], (name, f_star, verdicts)
        remedy = report.remedies[(scenario, name)].get("f")
        if not verdict.stable:
            assert remedy["to"] == f_star and remedy["change_percent"] == pytest.approx((f_star / f - 1) * 100, rel=1e-9)


def test_grid_law_f_critical_of_the_config_example_in_text_and_json():
    """The reported case (a config file with ``law: grid``, f = 1.5, W = 0.4 m; ``--L 0.4``): f* of sampled is about 1
    (was printed as the cell ratio 0.0043, "-100 %"); text and JSON show the same f*, and the text's remedy lowers f
    to it (about −32 %)."""
    robot, controller = CARMEL.robot.replace(W=0.4), CARMEL.controller.replace(f=1.5)
    f_star = _grid_report(robot, controller, L=0.4).corridor.models["sampled"].critical["f_critical"]
    assert 0.9 < f_star < 1.1
    argv = ["report", "--law", "grid", "--W", "0.4", "--f", "1.5", "--L", "0.4", "--model", "sampled"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main([*argv, "--format", "json"]) == 0
    assert json.loads(out.getvalue())["corridor"]["sampled"]["f_critical"] == pytest.approx(f_star, rel=1e-12)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    assert f"lower f to <= {f_star:.4g} ({(f_star / 1.5 - 1) * 100:+.0f} %)" in out.getvalue()


def test_staircase_wall_pushes_harder():
    """A wall drawn at 30° is a staircase with more cells per metre: measured ≈ 1.25–1.4× the axis-aligned law.

    (1/cos 30° ≈ 1.15 more cells per metre plus the staircase's teeth; the
    measured ratio is 1.33 at d = 1 m — a loose band, since only the
    direction of the effect is a design fact.)
    """
    law = GridWallLaw(RHO, 2.0, 0.8)
    ratio = measured_wall_force(law, [1.0], angle=math.radians(30)) / law.force(1.0)
    assert 1.2 < ratio[0] < 1.45
    assert measured_wall_force(law, [1.0], angle=0.0)[0] == pytest.approx(float(law.force(1.0)), rel=1e-13)


@pytest.mark.parametrize("bad", [32, 1, 0, -3, 33.0, "33", True])
def test_window_cells_must_be_odd_integer(bad):
    with pytest.raises(ValueError, match="window_cells must be an odd integer"):
        check_window_cells(bad)


def test_invalid_law_parameters():
    with pytest.raises(ValueError, match="cell_ratio must be"):
        GridWallLaw(0.0, 2.0, 0.8)
    with pytest.raises(ValueError, match="W must be"):
        working_range(4.0)
    assert GridWallLaw(RHO, 2, 0.8).with_scale(2 * RHO).force(1.0) == pytest.approx(2 * GridWallLaw(RHO, 2, 0.8).force(1.0))
