"""The simulated cycle of a non-smooth verdict (velocity-gated repulsion beside a wall).

GC2002's velocity-gated repulsion exerts nothing parallel to a wall, so the report
(`family_report.build_family_report`, level 8) can give only the non-smooth verdict
and its Filippov rest band (docs/velocity_and_fuzzy.md). What the robot then does —
rest, chatter or a limit cycle — only a simulation says: `simulated_cycle` runs the
planar simulator (`sim.cycles.wall_cycle`) for the report's robot family and returns
the cycle's measures (mean distance, peak-to-peak, heading amplitude, period, …), and
`fill_cycles` puts them into a report. The CLI calls it (``report --law velocity-gated``,
unless ``--no-simulate``).
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..checks import check_choice
from ..parameters import ROBOT_FAMILIES, Controller, Robot

__all__ = ["CYCLE_DURATION", "simulated_cycle", "fill_cycles"]

CYCLE_DURATION = 60.0
"""Simulated time of one cycle measurement, s."""


def _planar_robot(family: str, robot: Robot, controller: Controller, mass: float, a_max: float):
    """The simulator's robot for a report's family: KB's steering robot (τ = 0 for kinematic) or a point mass."""
    from ..sim.planar import PointMass, Steering

    if family == "holonomic":
        return PointMass(mass, a_max)
    tau = 0.0 if family == "kinematic" else robot.tau
    return Steering(robot.V, tau, robot.k, hold=controller.hold)


def simulated_cycle(family: str, robot: Robot, controller: Controller, law, alpha: float, *, mass: float = 1.0,
                    duration: float = CYCLE_DURATION) -> dict:
    """The simulated motion beside a wall under the velocity-gated repulsion, as a JSON-ready dict.

    Parameters
    ----------
    family : {"steering", "kinematic", "holonomic"}
    robot, controller : Robot, Controller
        V, τ, k (steering; kinematic: τ = 0, k = K_s), T and the compute delay.
    law : family_report.FamilyLaw
        The ``velocity-gated`` law: η, ρ0, a_max and the attraction F_a.
    alpha : float
        The target's angle from the wall normal, rad.
    mass : float
        The holonomic robot's mass, kg.
    duration : float
        Simulated time, s.

    Returns
    -------
    dict
        `sim.cycles.WallCycle.to_dict()`: mean_distance, peak_to_peak, heading_amplitude,
        period, at_rest, touches_wall, min_distance, duration.
    """
    from ..sim.cycles import wall_cycle

    check_choice("robot", family, ROBOT_FAMILIES)
    planar = _planar_robot(family, robot, controller, mass, law.parameters["a_max"])
    cycle = wall_cycle(law.gated(), law.attraction, alpha, planar, T=controller.T, compute_delay=controller.compute_delay, duration=duration)
    return cycle.to_dict()


def fill_cycles(report, family: str, robot: Robot, controller: Controller, law, *, mass: float = 1.0, duration: float = CYCLE_DURATION):
    """`report` with the wall's non-smooth scene carrying its simulated cycle.

    A corridor has none (the simulator measures wall cycles only), nor has a continuous
    controller (T = 0): the cycle stays None there.

    Parameters
    ----------
    report : StabilityReport
        The report of a non-smooth law.
    family : str
        The report's robot family (`parameters.ROBOT_FAMILIES`).
    robot, controller : Robot, Controller
        The robot and its controller.
    law : ForceLaw
        The non-smooth law.
    mass : float
        The point mass's mass, kg.
    duration : float
        Simulated time, s.
    """
    scenes = report.extras.get("scenes", {})
    wall = scenes.get("wall")
    if wall is None or not hasattr(wall, "cycle") or controller.T == 0:  # T = 0: a continuous controller, nothing sampled to simulate
        return report
    cycle = simulated_cycle(family, robot, controller, law, math.radians(wall.value), mass=mass, duration=duration)
    extras = {**report.extras, "scenes": {**scenes, "wall": replace(wall, cycle=cycle)}}
    return replace(report, extras=extras)
