"""The robots of the planar simulator and their exact motion over one sampling period, in arrays (docs/simulator.md).

`PointMass`, `Steering` and `DiffDrive` are the parameter sets (`sim.planar` describes them).
`robot_groups` sorts a batch's members into groups of one kind (`MassGroup`, `SteeringGroup`
per hold, `DiffDriveGroup`), each holding its members' parameters as arrays; a group reads
and writes its members' rows of the batch's `PlanarState` and advances them exactly under
the held command: constant acceleration, KB's steering solution of `sim.robot` (in KB's
axes), or the unicycle's arc. Every operation is element-wise in the member (a member's
steering quadrature rule is its own, padded with zero weights summed last), so a member
moves alike alone or in any batch, to round-off (docs/simulator.md, "Batches").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_number
from ..parameters import HOLDS, TAU_RESOLUTION
from .robot import advance_position, constant_input, constant_input_modes, graded_rule, propagate, servo, servo_modes, slow_rate
from .vff import wrap_angle

__all__ = [
    "ROBOTS", "DiffDrive", "DiffDriveGroup", "MassGroup", "PlanarState", "PointMass", "RobotGroup", "Steering", "SteeringGroup", "positive",
    "robot_groups",
]

_BIG = 1e6


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


class PlanarState:
    """The state of a batch's members at a sample, arrays of shape (B,) (a group writes its members' rows).

    Attributes
    ----------
    px, py : ndarray
        Position, m.
    vx, vy : ndarray
        Velocity, m/s (a point mass's state; the others' V(cos θ, sin θ), refreshed by `velocity`).
    theta : ndarray
        Heading, rad from +x (unwrapped; 0 for a point mass).
    omega : ndarray
        Turning rate, rad/s (steering robots).
    speed : ndarray
        Speed, m/s (differential drive: the held speed of the last period).

    Parameters
    ----------
    position, velocity : ndarray, shape (B, 2)
        Start positions (m) and velocities (m/s).
    heading : ndarray, shape (B,)
        Start headings, rad.
    """

    __slots__ = ("px", "py", "vx", "vy", "theta", "omega", "speed")

    def __init__(self, position, velocity, heading):
        position, velocity = np.asarray(position, dtype=float), np.asarray(velocity, dtype=float)
        self.px, self.py = position[:, 0].copy(), position[:, 1].copy()
        self.vx, self.vy = velocity[:, 0].copy(), velocity[:, 1].copy()
        self.theta = np.asarray(heading, dtype=float).copy()
        self.omega = np.zeros_like(self.theta)
        self.speed = np.hypot(self.vx, self.vy)

    def finite(self) -> np.ndarray:
        """True per member whose state is finite."""
        return np.isfinite(self.px) & np.isfinite(self.py) & np.isfinite(self.vx) & np.isfinite(self.vy) & np.isfinite(self.theta) & np.isfinite(self.omega)


def _array(robots, name):
    return np.array([float(getattr(r, name)) for r in robots])


def _keep(running, new, old):
    """`new` where the member runs, else `old` (running None: every member runs)."""
    return new if running is None else np.where(running, new, old)


def _direction(fx, fy, theta):
    """The force's direction (rad from +x), or θ where the force is exactly 0."""
    return np.where((fx != 0.0) | (fy != 0.0), np.arctan2(fy, fx), theta)


class RobotGroup:
    """Members of a batch with robots of one kind: their parameters as arrays, their command and exact motion.

    A group reads the force of its members from the batch's arrays and returns the value it
    holds over the next period as two arrays (`command`); `advance` applies the batch's
    applied values (the command of this sample or, with a compute delay, of the previous one)
    to the running members. Subclasses: `MassGroup`, `SteeringGroup`, `DiffDriveGroup`.

    Parameters
    ----------
    index : ndarray of int or slice
        The group's members in the batch.
    robots : sequence
        Their parameters (`PointMass`, `Steering` of one hold, or `DiffDrive`).
    T : ndarray, shape (n,)
        Their sampling periods, s.
    """

    heading = True
    """Whether the robot has a heading (recorded as θ; a point mass has none)."""

    def __init__(self, index, robots, T):
        self.index = index
        self.T = np.asarray(T, dtype=float)
        self._compile(list(robots))

    def _compile(self, robots):  # pragma: no cover - interface
        raise NotImplementedError

    def _rows(self, first, second, running):
        """The group's rows of the batch's applied values and running mask."""
        i = self.index
        return first[i], second[i], (None if running is None else running[i])

    def velocity(self, state: PlanarState) -> None:
        """Write the members' velocity (m/s) into the state's velocity rows, from their heading and speed.

        Parameters
        ----------
        state : PlanarState
            The batch's state.
        """
        i = self.index
        theta, speed = state.theta[i], self._speed(state)
        state.vx[i], state.vy[i] = speed * np.cos(theta), speed * np.sin(theta)

    def command(self, state: PlanarState, fx, fy, clearance):  # pragma: no cover - interface
        """The value held over the next period, as two arrays of the group's members.

        Parameters
        ----------
        state : PlanarState
            The batch's state.
        fx, fy : ndarray, shape (B,)
            The field's force on every member, N.
        clearance : ndarray, shape (B,)
            Every member's nearest clearance ρ, m (inf without obstacles).
        """
        raise NotImplementedError

    def advance(self, state: PlanarState, first, second, running) -> None:  # pragma: no cover - interface
        """Advance the running members over one period under the applied values (the state updated in place).

        Parameters
        ----------
        state : PlanarState
            The batch's state.
        first, second : ndarray, shape (B,)
            The batch's applied values (`command`'s two arrays).
        running : ndarray of bool, shape (B,), or None
            Which members advance (None: all).
        """
        raise NotImplementedError


class MassGroup(RobotGroup):
    """Point masses (`PointMass`): a = F/m scaled down to |a| = a_max beyond it (the conference paper's eq 22),
    held; p += vT + aT²/2 and v += aT, exact under the constant acceleration. The command is (a_x, a_y), m/s².

    Parameters
    ----------
    index : ndarray of int or slice
        The group's members in the batch.
    robots : sequence of PointMass
        Their parameters.
    T : ndarray, shape (n,)
        Their sampling periods, s.
    """

    heading = False

    def _compile(self, robots):
        self.mass, self.a_max = _array(robots, "mass"), _array(robots, "a_max")
        self.saturates = bool(np.any(np.isfinite(self.a_max)))

    def velocity(self, state: PlanarState) -> None:
        pass  # a point mass's velocity is its state

    def command(self, state: PlanarState, fx, fy, clearance):
        i = self.index
        ax, ay = fx[i] / self.mass, fy[i] / self.mass
        if self.saturates:
            norm = np.hypot(ax, ay)
            over = norm > self.a_max
            if np.any(over):
                scale = self.a_max / np.where(over, norm, 1.0)
                ax, ay = np.where(over, ax * scale, ax), np.where(over, ay * scale, ay)
        return ax, ay

    def advance(self, state: PlanarState, first, second, running) -> None:
        i, T = self.index, self.T
        first, second, running = self._rows(first, second, running)
        px, py, vx, vy = state.px[i], state.py[i], state.vx[i], state.vy[i]
        state.px[i] = _keep(running, px + vx * T + 0.5 * first * T * T, px)
        state.py[i] = _keep(running, py + vy * T + 0.5 * second * T * T, py)
        state.vx[i] = _keep(running, vx + first * T, vx)
        state.vy[i] = _keep(running, vy + second * T, vy)


class SteeringGroup(RobotGroup):
    """KB's steering robots of one hold (`Steering`) at constant speed V: the exact solutions of `sim.robot`.

    The command is (u, 0) with u = k·wrap(δ − θ) clipped to ±max_rate (``hold="command"``) or
    (δ̃, 0) with δ̃ = θ + wrap(δ − θ), closed by the servo u = k(δ̃ − θ) (``hold="reference"``),
    δ the force's direction. KB's axes swap x and y (ẋ' = V sin θ, ẏ' = V cos θ with θ from
    +y'); with x' = y and y' = x the heading from +x is the same θ.

    Parameters
    ----------
    index : ndarray of int or slice
        The group's members in the batch.
    robots : sequence of Steering
        Their parameters (one hold).
    T : ndarray, shape (n,)
        Their sampling periods, s.
    """

    def _compile(self, robots):
        self.hold = robots[0].hold
        self.V, self.k, self.max_rate = _array(robots, "V"), _array(robots, "k"), _array(robots, "max_rate")
        tau = _array(robots, "tau")
        tau = np.where(tau * self.k >= TAU_RESOLUTION, tau, 0.0)  # an ideal motor, as the models take it
        slow = slow_rate(self.k, np.where(np.isfinite(self.max_rate), self.max_rate, _BIG))
        if self.hold == "command":
            self.coef = constant_input(tau, graded_rule(self.T, *constant_input_modes(tau), slow))
        else:
            self.coef = servo(tau, self.k, graded_rule(self.T, *servo_modes(tau, self.k), slow))
        self.clips = bool(np.any(np.isfinite(self.max_rate)))

    def _speed(self, state):
        return self.V

    def command(self, state: PlanarState, fx, fy, clearance):
        i = self.index
        theta = state.theta[i]
        error = wrap_angle(_direction(fx[i], fy[i], theta) - theta)
        if self.hold == "command":
            value = self.k * error
            if self.clips:
                value = np.minimum(np.maximum(value, -self.max_rate), self.max_rate)
        else:
            value = theta + error
        return value, np.zeros_like(value)

    def advance(self, state: PlanarState, first, second, running) -> None:
        i = self.index
        first, second, running = self._rows(first, second, running)
        theta, omega, px, py = state.theta[i], state.omega[i], state.px[i], state.py[i]
        delta, correction, theta_end, omega_end = propagate(self.coef, theta, omega, first)
        y, x = advance_position(py, px, self.V, self.coef.rule, theta, delta, correction)
        state.px[i], state.py[i] = _keep(running, x, px), _keep(running, y, py)
        state.theta[i], state.omega[i] = _keep(running, theta_end, theta), _keep(running, omega_end, omega)


class DiffDriveGroup(RobotGroup):
    """GC2002 §7's differential-drive robots (`DiffDrive`): (v, ω) held, the unicycle's arc exact.

    The command is v = v_opt·min(1, ρ/ρ0) ≥ 0 (eq 41, ρ the nearest clearance) and
    ω = K_s·wrap(θ_f − θ) (eq 42–43); over a period the robot moves along the chord
    vT·sinc(ωT/2π) in the direction θ + ωT/2 and turns by ωT.

    Parameters
    ----------
    index : ndarray of int or slice
        The group's members in the batch.
    robots : sequence of DiffDrive
        Their parameters.
    T : ndarray, shape (n,)
        Their sampling periods, s.
    """

    def _compile(self, robots):
        self.K_s, self.v_opt = _array(robots, "K_s"), _array(robots, "v_opt")
        self.rho0, self.axle = _array(robots, "rho0_speed"), _array(robots, "axle")

    def _speed(self, state):
        return state.speed[self.index]

    def command(self, state: PlanarState, fx, fy, clearance):
        i = self.index
        theta = state.theta[i]
        omega = self.K_s * wrap_angle(_direction(fx[i], fy[i], theta) - theta)
        speed = self.v_opt * np.minimum(1.0, clearance[i] / self.rho0)
        return np.maximum(speed, 0.0), omega

    def wheels(self, speed, omega):
        """(v_l, v_r) = v ∓ Lω/2 of the group's members, m/s (GC2002 eq 40, rows in counter-clockwise order).

        Parameters
        ----------
        speed, omega : ndarray, shape (B,)
            The applied speed (m/s) and turning rate (rad/s) of the batch.
        """
        speed, omega = speed[self.index], omega[self.index]
        return speed - self.axle * omega / 2.0, speed + self.axle * omega / 2.0

    def advance(self, state: PlanarState, first, second, running) -> None:
        i, T = self.index, self.T
        first, second, running = self._rows(first, second, running)
        theta, px, py = state.theta[i], state.px[i], state.py[i]
        turn = second * T
        chord = first * T * np.sinc(turn / (2.0 * math.pi))
        mid = theta + 0.5 * turn
        state.px[i], state.py[i] = _keep(running, px + chord * np.cos(mid), px), _keep(running, py + chord * np.sin(mid), py)
        state.theta[i] = _keep(running, theta + turn, theta)
        state.speed[i] = _keep(running, first, state.speed[i])


def robot_groups(robots, T) -> tuple:
    """The batch's members sorted into groups of one kind (and one hold), each with its parameters as arrays.

    A group covering the whole batch indexes it with ``slice(None)`` (views, no copies).

    Parameters
    ----------
    robots : sequence of PointMass, Steering or DiffDrive
        One per member.
    T : ndarray, shape (B,)
        The members' sampling periods, s.
    """
    keys = [(type(r), getattr(r, "hold", "")) for r in robots]
    makers = {PointMass: MassGroup, Steering: SteeringGroup, DiffDrive: DiffDriveGroup}
    groups = []
    for key in dict.fromkeys(keys):
        members = np.array([m for m, k in enumerate(keys) if k == key])
        index = slice(None) if members.size == len(robots) else members
        groups.append(makers[key[0]](index, [robots[m] for m in members], np.asarray(T, dtype=float)[members]))
    return tuple(groups)
