"""The robots of the planar simulator and their exact motion over one sampling period (docs/simulator.md).

`PointMass`, `Steering` and `DiffDrive` are the parameter sets (`sim.planar` describes them);
the private dynamics classes hold one robot's state and advance it exactly under a held
command: constant acceleration, KB's steering solution of `sim.robot` (in KB's axes), or the
unicycle's arc.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_number
from ..parameters import HOLDS, TAU_RESOLUTION
from .robot import advance_position, constant_input, constant_input_modes, graded_rule, propagate, servo, servo_modes, slow_rate

__all__ = ["ROBOTS", "DiffDrive", "PointMass", "Steering", "positive"]

_BIG = 1e6


def _wrap(a: float) -> float:
    """a wrapped to [−π, π)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def positive(name, value, unit, high=_BIG):
    """`value` checked to lie in (0, high] (`unit` for the message).

    Parameters
    ----------
    name : str
        The name the message gives it.
    value : float
        The value to check.
    unit : str
        Its unit, for the message.
    high : float
        The largest allowed value.
    """
    return check_number(name, value, 0.0, high, high_open=False, unit=unit)


@dataclass(frozen=True)
class PointMass:
    """A holonomic point mass: m·a = F, |a| <= a_max (the conference paper's eq 22).

    Parameters
    ----------
    mass : float
        m_rob, kg, in (0, 1e6].
    a_max : float
        Largest acceleration, m/s², in (0, inf]; beyond it a = a_max·F/‖F‖.
    """

    mass: float = 1.0
    a_max: float = math.inf

    def __post_init__(self):
        object.__setattr__(self, "mass", positive("mass", self.mass, "kg"))
        if self.a_max != math.inf:
            object.__setattr__(self, "a_max", positive("a_max", self.a_max, "m/s^2", math.inf))


@dataclass(frozen=True)
class Steering:
    """KB's steering robot at constant speed V: τω̇ + ω = u, θ̇ = ω, u from δ = the force's direction.

    Parameters
    ----------
    V : float
        Speed, m/s, in (0, 1e6].
    tau : float
        Steering lag τ, s, in [0, 1e6] (τ·k below 1e-9 is an ideal motor, as in the models).
    k : float
        Steering gain, 1/s, in (0, 1e6].
    hold : {"reference", "command"}
        What is held between samples: δ (u = k(δ − θ) closed continuously) or u = k·wrap(δ − θ).
    max_rate : float
        |u| limit of a held command, rad/s, in (0, inf] (``hold="command"`` only).
    """

    V: float
    tau: float
    k: float
    hold: str = "reference"
    max_rate: float = math.inf

    def __post_init__(self):
        object.__setattr__(self, "V", positive("V", self.V, "m/s"))
        object.__setattr__(self, "tau", check_number("tau", self.tau, 0.0, _BIG, low_open=False, high_open=False, unit="s"))
        object.__setattr__(self, "k", positive("k", self.k, "1/s"))
        check_choice("hold", self.hold, HOLDS)
        if self.max_rate != math.inf:
            object.__setattr__(self, "max_rate", positive("max_rate", self.max_rate, "rad/s", math.inf))
            if self.hold != "command":
                raise ValueError("max_rate must be inf with hold='reference' (only a held command is clipped)")


@dataclass(frozen=True)
class DiffDrive:
    """GC2002 §7's differential-drive robot (eq 37–43).

    ω = K_s·wrap(θ_f − θ) (eq 42–43) with θ_f the force's direction, v = v_opt·min(1, ρ/ρ0)
    (eq 41) with ρ the nearest obstacle clearance, both held over a period. The wheel
    speeds are v_l = v − Lω/2 and v_r = v + Lω/2 for counter-clockwise ω; the printed
    eq (40) has the rows swapped (it reads v_l = v + Lω/2), which holds only for
    clockwise-positive ω.

    Parameters
    ----------
    K_s : float
        Heading gain, 1/s, in (0, 1e6].
    v_opt : float
        Cruise speed, m/s, in (0, 1e6].
    rho0_speed : float
        Clearance below which the speed is reduced (eq 41's ρ0), m, in (0, 1e6].
    axle : float
        Wheel separation L, m, in (0, 1e6] (GC2002's robots: 0.075).
    """

    K_s: float
    v_opt: float
    rho0_speed: float
    axle: float = 0.075

    def __post_init__(self):
        for name, unit in (("K_s", "1/s"), ("v_opt", "m/s"), ("rho0_speed", "m"), ("axle", "m")):
            object.__setattr__(self, name, positive(name, getattr(self, name), unit))


ROBOTS = (PointMass, Steering, DiffDrive)


class _MassDynamics:
    def __init__(self, robot: PointMass, T, start):
        self.r, self.T = robot, T
        self.p, self.v = np.array(start.position), np.array(start.velocity)
        self.theta = None

    def velocity(self):
        return self.v

    def command(self, force, clearance):
        a = force / self.r.mass
        norm = math.hypot(*a)
        if norm > self.r.a_max:
            a = a * (self.r.a_max / norm)
        return a

    def advance(self, a):
        T = self.T
        self.p = self.p + self.v * T + 0.5 * a * T * T
        self.v = self.v + a * T


class _SteeringDynamics:
    """KB's steering solution over one period (`sim.robot`), in KB's axes (x' = y, y' = x: ẋ' = V sin θ, ẏ' = V cos θ)."""

    def __init__(self, robot: Steering, T, start):
        self.r, self.T = robot, T
        one = lambda value: np.array([float(value)])
        tau = robot.tau if robot.tau * robot.k >= TAU_RESOLUTION else 0.0
        slow = slow_rate(one(robot.k), one(robot.max_rate if robot.max_rate < math.inf else _BIG))
        if robot.hold == "command":
            self.rule = graded_rule(one(T), *constant_input_modes(one(tau)), slow)
            self.coef = constant_input(one(tau), self.rule)
        else:
            self.rule = graded_rule(one(T), *servo_modes(one(tau), one(robot.k)), slow)
            self.coef = servo(one(tau), one(robot.k), self.rule)
        self.p = np.array(start.position)
        self.theta, self.omega = float(start.heading), 0.0

    def velocity(self):
        return self.r.V * np.array([math.cos(self.theta), math.sin(self.theta)])

    def command(self, force, clearance):
        fx, fy = force
        delta = math.atan2(fy, fx) if (fx or fy) else self.theta
        error = _wrap(delta - self.theta)
        if self.r.hold == "command":
            return min(max(self.r.k * error, -self.r.max_rate), self.r.max_rate)
        return self.theta + error

    def advance(self, value):
        arr = lambda x: np.array([float(x)])
        delta, correction, theta, omega = propagate(self.coef, arr(self.theta), arr(self.omega), arr(value))
        y, x = advance_position(arr(self.p[1]), arr(self.p[0]), arr(self.r.V), self.rule, arr(self.theta), delta, correction)
        self.p = np.array([float(x[0]), float(y[0])])
        self.theta, self.omega = float(theta[0]), float(omega[0])


class _DiffDriveDynamics:
    def __init__(self, robot: DiffDrive, T, start):
        self.r, self.T = robot, T
        self.p = np.array(start.position)
        self.theta = float(start.heading)
        self.speed = math.hypot(*start.velocity)

    def velocity(self):
        return self.speed * np.array([math.cos(self.theta), math.sin(self.theta)])

    def command(self, force, clearance):
        fx, fy = force
        heading = math.atan2(fy, fx) if (fx or fy) else self.theta
        omega = self.r.K_s * _wrap(heading - self.theta)
        speed = self.r.v_opt * min(1.0, clearance / self.r.rho0_speed)
        return max(speed, 0.0), omega

    def advance(self, command):
        speed, omega = command
        turn = omega * self.T
        chord = speed * self.T * float(np.sinc(turn / (2.0 * math.pi)))
        mid = self.theta + 0.5 * turn
        self.p = self.p + chord * np.array([math.cos(mid), math.sin(mid)])
        self.theta += turn
        self.speed = speed


_DYNAMICS = {PointMass: _MassDynamics, Steering: _SteeringDynamics, DiffDrive: _DiffDriveDynamics}


