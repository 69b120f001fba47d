"""Every starred value says on which side the loop is stable (docs/models.md, "Critical values").

`stable_side` (JSON: a verdict's ``stable_side``) is "below" for NV*, V*, T*, k*, "above"
for α* and L*, "above" for a wall's f* and "below" for a corridor's, and for a value
found as the nearest change of verdict (a law that is not monotone) the side on which
the verdict is stable just past it. The oracle is the definition itself: the analysis
is run again with that one input moved a relative 1e-6 to either side of the critical
value (or, for NV*, the model's own `is_stable` there), and the verdict must be stable
on the stated side and not on the other. 1e-6 is far above the searches' tolerances
(1e-7 relative for T* and k*, 1e-9 or exact for the rest) and far below any band.
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from cli_helpers import report_json, run
from pfm_stability.analysis.criteria import analyze_corridor, analyze_wall, loop_of
from pfm_stability.laws.fields import GnronLaw, make_law
from pfm_stability.models import models_for
from pfm_stability.parameters import CARMEL, Corridor, Wall

STEP = 1e-6
ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller
GNRON = GnronLaw(1.0, 1.0, 0.8, 2.0, 0.5, 0.02)
"""docs/fields.md table 3: three wall equilibria at α = 60°, the nearest changes of verdict on either side."""


def _verdict(geometry, model, robot, controller, value, law):
    """The model's verdict (stable or not) with everything else as given; at a wall, that of equilibrium `index` of `count`
    (equilibria keep their order until two merge: the first stays the first, another needs the same count)."""
    if geometry == "corridor":
        return analyze_corridor(robot, controller, Corridor(value), models=[model], law=law).models[model].stable
    (index, count), alpha = value
    analysis = analyze_wall(robot, controller, Wall.from_degrees(alpha), models=[model], law=law)
    assert index == 0 or len(analysis.equilibria) == count
    return analysis.equilibria[index].models[model].stable


def _moved(key, x, geometry, at, law):
    """(robot, controller, geometry value, law) with the input of critical value `key` set to x."""
    robot, controller = ROBOT, CONTROLLER
    if key == "V_critical":
        robot = robot.replace(V=x)
    elif key == "T_critical":
        controller = controller.replace(T=x)
    elif key == "k_critical":
        robot = robot.replace(k=x)
    elif key == "tau_plus_T_critical":
        controller = controller.replace(T=x - robot.tau)
    elif key == "f_critical":
        controller = controller.replace(f=x)
        law = law if law is None else make_law(law.key, robot, controller) if law.key == "grid" else law.with_scale(x)
    elif key == "alpha_critical_deg":
        at = (at[0], x)
    elif key == "L_critical":
        at = x
    elif key in ("eta_critical", "rho0_critical", "xi_critical"):
        law = dataclasses.replace(law, **{key.removesuffix("_critical"): x})
    return robot, controller, at, law


def _check_sides(geometry, model, verdict, at, law=None):
    loop = loop_of(ROBOT, CONTROLLER)
    m = models_for(CONTROLLER, [model])[0]
    if verdict.NV > 0 and 0 < verdict.NV_critical < math.inf:
        assert m.is_stable(verdict.NV_critical * (1 - STEP), loop) and not m.is_stable(verdict.NV_critical * (1 + STEP), loop)
    checked = 0
    for key, side in verdict.critical.stable_sides().items():
        x = verdict.critical[key]
        if key == "alpha_critical" or side is None or not 0 < x < math.inf or (key == "alpha_critical_deg" and x >= 90):
            continue  # rad (its degrees are checked), undefined, or an end of the range ("no value helps" / "no limit")
        if key == "tau_plus_T_critical" and x * (1 - STEP) <= ROBOT.tau:
            continue
        results = {}
        for where, y in (("below", x * (1 - STEP)), ("above", x * (1 + STEP))):
            robot, controller, value, moved = _moved(key, y, geometry, at, law)
            results[where] = _verdict(geometry, model, robot, controller, value, moved)
        assert results[side] and not results[{"below": "above", "above": "below"}[side]], (geometry, model, key, x, side, results)
        checked += 1
    return checked


@pytest.mark.parametrize("model", ["kb_first_order", "sampled"])
def test_power_law_sides_carmel(model):
    """KB's power law, CARMEL, α = 20° (unstable) and L = 0.9 m (sampled: unstable; kb_first_order: stable):
    V*, α*, f* (wall: above), L*, f* (corridor: below), T*, k*, (τ + T)* and NV* each flip the verdict on the stated side."""
    wall = analyze_wall(ROBOT, CONTROLLER, Wall.from_degrees(20.0), models=[model])
    corridor = analyze_corridor(ROBOT, CONTROLLER, Corridor(0.9), models=[model])
    count = _check_sides("wall", model, wall.models[model], ((0, 1), 20.0))
    count += _check_sides("corridor", model, corridor.models[model], 0.9)
    assert count >= 5
    assert corridor.models[model].critical.stable_side("f_critical") == "below" and wall.models[model].critical.stable_side("f_critical") == "above"


def test_grid_law_sides():
    """The histogram grid's law (monotone, f in the user's units: f_av), CARMEL at α = 30° and L = 1 m, sampled."""
    law = make_law("grid", ROBOT, CONTROLLER)
    wall = analyze_wall(ROBOT, CONTROLLER, Wall.from_degrees(30.0), models=["sampled"], law=law)
    corridor = analyze_corridor(ROBOT, CONTROLLER, Corridor(1.0), models=["sampled"], law=law)
    assert _check_sides("wall", "sampled", wall.models["sampled"], ((0, 1), 30.0), law) >= 2
    assert _check_sides("corridor", "sampled", corridor.models["sampled"], 1.0, law) >= 3


@pytest.mark.parametrize("index", [0, 2])
def test_goal_aware_wall_sides_per_equilibrium(index):
    """The goal-aware law's three wall equilibria (docs/fields.md table 3), the stable first and the unstable third:
    α*, η*, ρ0*, ξ* are nearest changes whose side differs between them (α*: above at the first, below at the
    third), each checked by moving the input and taking the same equilibrium again (the same place in the order)."""
    analysis = analyze_wall(ROBOT, CONTROLLER, Wall.from_degrees(60.0), models=["kb_first_order"], law=GNRON)
    e = analysis.equilibria[index]
    verdict = e.models["kb_first_order"]
    assert verdict.critical.stable_side("alpha_critical_deg") == ("above" if index == 0 else "below")
    assert _check_sides("wall", "kb_first_order", verdict, ((index, 3), 60.0), GNRON) >= 4


def test_sides_in_json_text_and_markdown():
    """JSON: every verdict's ``stable_side`` names each starred key (schema-checked); text and Markdown: the footnote
    names the sides of the fixed columns and a law's nearest changes are shown as "<= x"/">= x"."""
    d = report_json(["--alpha", "20", "--L", "0.9"])
    for geometry, sides in (("wall", {"alpha_critical_deg": "above", "f_critical": "above"}), ("corridor", {"L_critical": "above", "f_critical": "below"})):
        for v in d[geometry].values():
            assert {k: v["stable_side"][k] for k in sides} == sides
            assert v["stable_side"]["V_critical"] == v["stable_side"]["T_critical"] == v["stable_side"]["NV_critical"] == "below"
    argv = ["report", "--law", "gnron", "--goal-distance", "0.02", "--goal-exponent", "0.5", "--eta", "1", "--alpha", "60", "--model", "sampled"]
    for form in ("text", "markdown"):
        code, out, _ = run([*argv, "--format", form])
        assert code == 0
        assert "above alpha* and L*, above a wall's f* and below a corridor's f*" in out.replace("\n", " ")
        assert "<= 46.25" in out and ">= 0.9355" in out  # equilibrium 3: alpha* below, rho0* above (docs/fields.md table 3)
