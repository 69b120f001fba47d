"""The report of a Nav2 path-tracking controller: its inputs, every model's verdict, the remedies (docs/path_tracking.md).

`build_report(…, tracker=…)` (`report.stability`) hands a Nav2 controller (``report --controller rpp|graceful|mppi|dwb``)
to `path_report`: the controller's law linearised about a straight path or a corridor's centre line
(`analysis.path_laws`), decided by every model (`analysis.path_tracking`), with the single-parameter changes that
make each unstable model stable (`path_remedies`, the report's rule: each change alone works by the definition of its
critical value) and the inputs the report lists with their provenance (Nav2 file, Nav2's declared default ASSUMED,
user). The result is the one `StabilityReport`, its ``path`` set.
"""

from __future__ import annotations

from dataclasses import replace

from ..analysis.path_laws import MeasuredGains, PurePursuit, path_law
from ..analysis.path_tracking import PathTracking, analyze_path_tracking
from ..controllers.registry import get_controller
from ..models import models_for
from ..parameters import MODEL_NAMES, RANGES
from .remedy import change

__all__ = ["path_report", "path_remedies", "path_inputs", "path_json"]

PLANT = ("tau", "dead_time", "plant_gain", "actuator_lag", "slip_lag")
"""The robot's plant the loop closes through (`parameters.Robot`), listed for every path-tracking report."""


def path_remedies(result: PathTracking, verdict, values: dict, robot, controller) -> dict:
    """Single-parameter changes that make one model's unstable verdict stable, keyed by Nav2's (or the loop's) name.

    The cruising speed to V* (``max_linear_vel`` …), the lookahead that steers to L* (which parameter sets it:
    ``lookahead_dist``, ``curvature_lookahead_dist``, ``max_lookahead``; velocity-scaled: ``lookahead_time`` to
    lookahead_time*, ``min_lookahead_dist`` to L* when L* is within ``max_lookahead_dist``, ``max_lookahead_dist``
    to L* when the velocity-scaled lookahead already reaches it), the dead time to D* and the period T to T*.
    Empty when stable.

    Parameters
    ----------
    result : PathTracking
        The analysis.
    verdict : analysis.path_tracking.PathVerdict
        The model's.
    values : dict
        The controller's Nav2 parameters.
    robot, controller : parameters.Robot, parameters.Controller
        The present D and T.
    """
    if verdict.verdict == "stable":
        return {}
    entry = get_controller(result.controller)
    wanted = [(entry.speed, verdict.V_critical, "lower", result.point.V_set)]
    law, L_star = result.law, verdict.lookahead_critical
    if isinstance(law, PurePursuit):
        if law.steering == "fixed":
            wanted.append(("lookahead_dist", L_star, "raise", values["lookahead_dist"]))
        elif law.steering == "curvature":
            wanted.append(("curvature_lookahead_dist", L_star, "raise", values["curvature_lookahead_dist"]))
        else:
            wanted.append(("lookahead_time", verdict.lookahead_time_critical, "raise", values["lookahead_time"]))
            if L_star is not None and L_star <= values["max_lookahead_dist"]:
                wanted.append(("min_lookahead_dist", L_star, "raise", values["min_lookahead_dist"]))
            if L_star is not None and result.point.V * values["lookahead_time"] >= L_star:
                wanted.append(("max_lookahead_dist", L_star, "raise", values["max_lookahead_dist"]))
    elif L_star is not None:
        wanted.append(("max_lookahead", L_star, "raise", values["max_lookahead"]))
    if verdict.dead_time_critical is not None:
        wanted.append(("dead_time", verdict.dead_time_critical, "lower", robot.dead_time))
    wanted.append(("T", verdict.T_critical, "lower", controller.T))
    changes = ((name, change(name, target, direction, now)) for name, target, direction, now in wanted if target is not None)
    return {name: fix for name, fix in changes if fix is not None}


def path_inputs(robot, controller, tracker, gains, L, pade_order: int, sources: dict) -> dict:
    """The report's inputs for a path tracker, in the order it lists them: the controller and its plugin, V (its cruising
    speed parameter), the plant, T, the sampled structure, the corridor, the Nav2 parameters the loop reads, the costmap's
    (with a corridor), and measured gains; each {"value", "unit", "source"}.

    Parameters
    ----------
    robot, controller : parameters.Robot, parameters.Controller
        The plant and V; T and the sampled structure.
    tracker : io.nav2.Nav2Tracker
        The controller and its parameters with their provenance.
    gains : analysis.path_laws.MeasuredGains or None
        Measured gains (MPPI, DWB).
    L : float or None
        The corridor's half-width, m.
    pade_order : int
        Order of the ``pade`` model.
    sources : dict
        Provenance of the robot's and the controller's values.
    """
    entry = get_controller(tracker.controller)
    out = {"controller": {"value": tracker.controller, "unit": "", "source": sources.get("controller", "user")},
           "plugin": {"value": tracker.plugin, "unit": "", "source": tracker.plugin_source}}

    def put(name, value, unit, source):
        out[name] = {"value": value, "unit": unit, "source": source}

    put("V", robot.V, "m/s", sources.get("V", "user"))
    for name in PLANT:
        put(name, getattr(robot, name), RANGES[name].unit, sources.get(name, "user"))
    put("T", controller.T, "s", sources.get("T", "user"))
    for name in ("hold", "compute_delay"):
        put(name, getattr(controller, name), "", sources.get(name, "user"))
    put("pade_order", pade_order, "", sources.get("pade_order", "default"))
    if L is not None:
        put("L", L, "m", sources.get("L", "user"))
    for p in entry.analysed:
        if p.name != entry.speed:
            setting = tracker.parameters[p.name]
            put(p.name, setting.value, p.unit, setting.source)
    if L is not None:
        for name, setting in tracker.costmap.items():
            if name != "resolution":
                put(name, setting.value, "1/m" if name == "cost_scaling_factor" else "m", setting.source)
    if gains is not None:
        for name, unit in (("k_theta", "1/s"), ("k_y", "1/(m s)"), ("k_theta_se", "1/s"), ("k_y_se", "1/(m s)")):
            put(name, getattr(gains, name), unit, "user")
    return out


def path_report(robot, controller, tracker, *, gains=None, L=None, models=MODEL_NAMES, pade_order: int = 3, sources=None):
    """(inputs, models, family, PathTracking, remedies) of a Nav2 controller's report (`report.stability.build_report`).

    Parameters
    ----------
    robot : parameters.Robot
        The plant (τ, g, D, τ_a) and V, the controller's cruising speed parameter.
    controller : parameters.Controller
        T, hold, compute delay.
    tracker : io.nav2.Nav2Tracker
        The controller and its Nav2 parameters (a file's, Nav2's defaults, the user's).
    gains : analysis.path_laws.MeasuredGains, optional
        MPPI's or DWB's measured gains.
    L : float, optional
        The corridor's half-width, m (None: a straight path in free space).
    models : sequence of str
        Model names.
    pade_order : int
        Order of the ``pade`` model.
    sources : dict, optional
        Provenance of the robot's and the controller's values.
    """
    sources = dict(sources or {})
    values = tracker.values()
    law = path_law(tracker.controller, values, costmap=tracker.costmap_values(), half_width=L, gains=gains)
    model_objs = tuple(models_for(controller, tuple(dict.fromkeys(models)), pade_order=pade_order))
    result = analyze_path_tracking(robot, controller, law, model_objs, V_set=robot.V, half_width=L, values=values)
    result = replace(result, notes=(*tracker.notes, *result.notes))
    remedies = {("path", name): path_remedies(result, v, values, robot, controller) for name, v in result.models.items()}
    inputs = path_inputs(robot, controller, tracker, gains if isinstance(law, MeasuredGains) else None, L, pade_order, sources)
    return inputs, model_objs, result.loop.family, result, remedies


def path_json(result: PathTracking, remedies: dict) -> tuple:
    """(environment entry, top-level verdicts) of a path-tracking result: ``environment.path`` (the controller, geometry, the
    linearised law, notes, MPPI's model delay) and ``path.<model>`` (each verdict with its ``to_stabilize``).

    Parameters
    ----------
    result : analysis.path_tracking.PathTracking
        The analysis.
    remedies : dict
        ("path", model) → the model's remedies (`path_remedies`).
    """
    env = result.to_dict()
    verdicts = env.pop("models")
    for name, v in verdicts.items():
        v["to_stabilize"] = remedies.get(("path", name), {})
    return env, verdicts
