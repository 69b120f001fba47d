"""The simulated cycle of a non-smooth verdict (velocity-gated repulsion beside a wall).

GC2002's velocity-gated repulsion exerts nothing parallel to a wall, so the report
(`report.stability.build_report`, below this level) can give only the non-smooth verdict
and its Filippov rest band (docs/velocity_and_fuzzy.md). What the robot then does —
rest, chatter or a limit cycle — only a simulation says: `simulated_cycle` runs the
planar simulator (`sim.cycles.wall_cycle`) for the report's robot family and returns
the cycle's measures (mean distance, peak-to-peak, heading amplitude, period, …). The
CLI hands it to `build_report` (``report --law velocity-gated``, unless ``--no-simulate``).
"""

from __future__ import annotations

from ..checks import check_choice
from ..parameters import ROBOT_FAMILIES, Controller, Robot

__all__ = ["CYCLE_DURATION", "simulated_cycle"]

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
