"""KB's steering loop τs³ + s² + gks + gk(cs + NV)·e^(−sT) and its boundary in NV: the parameters every model needs.

`Loop` is the steering robot's `family.Characteristic` (KB eq 17–19; kinematic steering is τ = 0), with the
plant's gain g, dead time D and second lag τ_a of a real drive (docs/models.md, "Plant gain and dead time"): D
delays the whole command, the heading term by D and the field's by T + D, a loop of two delays that the general
quasi-polynomial (`numerics.quasi`) decides; without D, τ_a and a sampled heading it is KB's loop and every model
runs the code it always ran (`Loop.kb_form`). `Boundary` is one model's answer in NV, `STEERING` the family's names.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import check_choice, check_number
from ..io.serialize import json_number
from ..numerics.crossings import StabilityInterval
from ..parameters import HOLDS, RANGES, T_RESOLUTION, TAU_RESOLUTION, check_parameter
from .family import Characteristic, LoopFamily, StableSet, _unchecked
from .verdicts import NV_MAX

__all__ = ["STEERING", "Loop", "Boundary", "steering_family", "gain_range", "check_heading_gain", "HEADING_GAIN_RANGE"]


_DELAY_RTOL = 1e-7
"""Relative bracket width at which `critical_delay` stops (reports show 4 digits)."""

HEADING_GAIN_RANGE = (-0.99, 100.0)
"""Closed range of the heading gain c (`Loop.c`, dimensionless).

The steering command is k(δ − θ) = −k(N·x + (1 + c)·θ): c <= −1 removes or
reverses the loop's heading feedback, and the continuous loop
τs³ + s² + k(1 + c)s + kNV is then unstable at every NV (Routh: its s¹
coefficient is <= 0). Such a c is refused rather than answered, with that
reason; −0.99 keeps 1 + c >= 0.01. 100 is a generous cap (a heading term a
hundred times the steering loop's own)."""

@dataclass(frozen=True)
class Loop(Characteristic):
    """KB's steering loop τs³ + s² + ks + k(cs + NV)·e^(−sT) = 0: the parameters every model needs.

    Parameters
    ----------
    tau : float
        Steering time constant τ, s, >= 0 (KB eq 6); τ with τk < 10⁻⁹ is
        stored as 0 (`TAU_RESOLUTION`).
    T : float
        Sampling period / loop delay, s, >= 0 (KB eq 18); T < 10⁻¹² s is
        stored as 0, a continuous controller (`T_RESOLUTION`).
    k : float
        Steering gain, 1/s, > 0 (KB eq 5).
    c : float, keyword only
        Heading gain, dimensionless, in `HEADING_GAIN_RANGE` ([−0.99, 100]);
        default 0 (KB's loop). The linearized reference is
        δ = −N·(x − x0) − c·θ, so the gain term of every model becomes
        k(cs + NV) (delayed by e^(−sT) with the rest of the sensor data);
        docs/models.md, "The heading gain".
    plant_gain, dead_time : float, keyword only
        g (in [10⁻³, 100], default 1) and D (s, in [0, 10], default 0) of the motor
        τω̇ + ω = g·u(t − D) (docs/models.md, "Plant gain and dead time"): the loop's
        steering gain is g·k (`steering_gain`; `k` stays the controller's, k* is in it).
        D delays the whole command k(δ − θ): the heading term by D, the field's by T + D.
        D < 10⁻¹² s is stored as 0 (`T_RESOLUTION`, as T).
    actuator_lag : float, keyword only
        τ_a, s, in [0, 10] (default 0): a second lag of the drive, the plant
        g·e^(−sD)/((τs + 1)(τ_a·s + 1)); τ_a with τ_a·g·k < 10⁻⁹ is 0. The two lags are
        interchangeable: τ = 0 with τ_a > 0 is stored as τ = τ_a, τ_a = 0.
    heading_sampled : bool, keyword only
        Whether the sampled controller computes the heading feedback too (a path tracker
        computing ω from the pose: the heading term is delayed by T + D, as the field's),
        or the drive closes it (KB eq 18: delayed by D only). Default False. The `sampled`
        model does not read it (its ``hold`` says what is sampled).
    slip_lag : float, keyword only
        τ_s, s, in [0, 10] (default 0): the course χ (the direction the robot moves in) follows the heading through
        τ_s·χ̇ + χ = θ and ẋ = V·χ (a base that slides sideways in a turn). Only the field's path sees it: every term
        but the field's is multiplied by (τ_s·s + 1) — (τ_s s + 1)(p0(s) + gk·s·e^(−s·h₁)) + gkNV·e^(−s(T + D)) = 0
        (docs/models.md, "A base that slides"); τ_s with τ_s·g·k < 10⁻⁹ is 0.
    """

    tau: float
    T: float
    k: float
    c: float = field(default=0.0, kw_only=True)
    plant_gain: float = field(default=1.0, kw_only=True)
    dead_time: float = field(default=0.0, kw_only=True)
    actuator_lag: float = field(default=0.0, kw_only=True)
    heading_sampled: bool = field(default=False, kw_only=True)
    slip_lag: float = field(default=0.0, kw_only=True)

    def __post_init__(self):
        for name in ("tau", "T", "k"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        defaults = (("plant_gain", 1.0), ("dead_time", 0.0), ("actuator_lag", 0.0), ("slip_lag", 0.0))
        for name in [n for n, d in defaults if getattr(self, n).__class__ is not float or getattr(self, n) != d]:
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        if self.heading_sampled.__class__ is not bool:
            raise ValueError(f"heading_sampled must be True or False; got {self.heading_sampled!r}")
        for name in ("tau", "actuator_lag", "slip_lag"):  # a lag 10⁹ times faster than the steering loop: none
            if getattr(self, name) * self.steering_gain < TAU_RESOLUTION:
                object.__setattr__(self, name, 0.0)
        if self.tau == 0.0 and self.actuator_lag > 0.0:  # one lag: it is the motor's (the plant is the same)
            object.__setattr__(self, "tau", self.actuator_lag)
            object.__setattr__(self, "actuator_lag", 0.0)
        if self.T < T_RESOLUTION:  # faster than a picosecond: a continuous controller
            object.__setattr__(self, "T", 0.0)
        if self.dead_time < T_RESOLUTION:  # a picosecond of dead time is none (its Padé coefficients D^m would underflow)
            object.__setattr__(self, "dead_time", 0.0)
        if self.c.__class__ is not float or self.c != 0.0:
            object.__setattr__(self, "c", check_heading_gain(self.c))

    @classmethod
    def of(cls, robot, controller, *, c: float = 0.0, heading_sampled: bool = False) -> "Loop":
        """The loop of a robot and its controller (τ, k, g, D, τ_a, τ_s; T), with heading gain `c`: the one constructor from them.

        Parameters
        ----------
        robot : parameters.Robot
        controller : parameters.Controller
        c : float
            Heading gain of the equilibrium (0: a static law, KB's loop).
        heading_sampled : bool
            Whether the controller computes the heading feedback too (`Loop.heading_sampled`).
        """
        return cls(robot.tau, controller.T, robot.k, c=c, plant_gain=robot.plant_gain, dead_time=robot.dead_time,
                   actuator_lag=robot.actuator_lag, heading_sampled=heading_sampled, slip_lag=robot.slip_lag)

    @property
    def kb_form(self) -> bool:
        """True for KB's loop τs³ + s² + gks + gk(cs + NV)·e^(−sT) (one delay: no dead time, no second lag, no slip, the
        heading closed by the drive): the models run the code they always ran. False: the general loop (`quasi_terms`)."""
        return self.dead_time == 0.0 and self.actuator_lag == 0.0 and self.slip_lag == 0.0 and not self.heading_sampled

    @property
    def lags(self) -> np.ndarray:
        """p0(s) = s²·(τs + 1)·(τ_a·s + 1)·(τ_s·s + 1), descending: the drive's lags, the course's and the two
        integrations (θ, x)."""
        p = np.array([1.0, 0.0, 0.0])
        for lag in (self.tau, self.actuator_lag, self.slip_lag):
            if lag > 0:
                p = np.polymul([lag, 1.0], p)
        return p

    @property
    def heading_delay(self) -> float:
        """h₁, s: the heading term's delay, D (+ T when `heading_sampled`)."""
        return self.dead_time + self.T if self.heading_sampled else self.dead_time

    @property
    def slip(self) -> np.ndarray:
        """(τ_s·s + 1), descending ([1] without slip): the factor of every term but the field's (`slip_lag`)."""
        return np.array([self.slip_lag, 1.0]) if self.slip_lag > 0 else np.array([1.0])

    def quasi_terms(self):
        """The loop as p0(s) + gk·s·(τ_s s + 1)·e^(−s·h₁) + gkc·s·(τ_s s + 1)·e^(−s(T + D)) + K·e^(−s(T + D))
        (`numerics.quasi.QuasiPolynomial`; p0 carries the course's lag too: `lags`)."""
        from ..numerics.quasi import DelayedTerm, QuasiPolynomial

        k, slip = self.steering_gain, self.slip
        terms = [DelayedTerm(tuple(np.polymul([k, 0.0], slip)), self.heading_delay)]
        if self.c != 0.0:
            terms.append(DelayedTerm(tuple(np.polymul([self.heading, 0.0], slip)), self.delay))
        return QuasiPolynomial(self.lags, terms, self.delay)

    @property
    def steering_gain(self) -> float:
        """g·k, 1/s: the loop's steering gain, the motor's rate per radian of heading error (k for KB's robot, g = 1)."""
        return self.plant_gain * self.k

    def replace(self, **changes) -> "Loop":
        """A copy with `changes` (field name → value), checked as the constructor checks."""
        return dataclasses.replace(self, **changes)

    @property
    def family(self) -> LoopFamily:
        """`STEERING` for KB's loop; with a plant (g, D, τ_a) or a sampled heading the equations it solves (`steering_family`)."""
        if self.kb_form and self.plant_gain == 1.0:
            return STEERING
        return steering_family(self.dead_time > 0, self.actuator_lag > 0, self.heading_sampled, self.slip_lag > 0)

    @property
    def plant(self) -> np.ndarray:
        """a(s) = τs³ + s² + ks, descending (KB eq 17 without the gain term); the general loop's p0(s) + gk·s (its
        delays left out: what `continuous` sees)."""
        k = self.steering_gain
        if not self.kb_form:
            return np.polyadd(self.lags, np.polymul([k, 0.0], self.slip))
        return np.array([self.tau, 1.0, k, 0.0]) if self.tau > 0 else np.array([1.0, k, 0.0])

    @property
    def heading(self) -> float:
        """g·kc, 1/s: the s-coefficient of the gain term gk(cs + NV) (0 for KB's loop)."""
        return self.steering_gain * self.c

    @property
    def damping(self) -> float:
        """δ = kc (`heading`), 1/s."""
        return self.heading

    @property
    def closed_plant(self) -> np.ndarray:
        """a(s) + kc·s = τs³ + s² + k(1 + c)s, descending: the loop without delay and without NV.

        ``plant`` itself when c = 0 (the same array, the same floats).
        """
        if self.c == 0.0:
            return self.plant
        k = self.steering_gain
        if not self.kb_form:
            return np.polyadd(self.lags, np.polymul([k * (1.0 + self.c), 0.0], self.slip))
        return np.array([self.tau, 1.0, k * (1.0 + self.c), 0.0]) if self.tau > 0 else np.array([1.0, k * (1.0 + self.c), 0.0])

    def loop_gain(self, NV: float) -> float:
        """K = gkNV, 1/s² (g = 1: KB's kNV).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        """
        return self.steering_gain * NV

    def gain_of(self, K: float) -> float:
        """NV = K/(gk), 1/s.

        Parameters
        ----------
        K : float
            Loop gain K, 1/s².
        """
        return K / self.steering_gain

    def check_gain(self, NV) -> float:
        """NV (1/s) as a float in [−`NV_MAX`, `NV_MAX`] (−0.0 becomes 0.0), or ValueError naming NV.

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        """
        return check_number("NV", NV, -NV_MAX, NV_MAX, low_open=False, high_open=False, unit="1/s") + 0.0

    def boundary_from(self, model: str, interval: StabilityInterval) -> "Boundary":
        """`Boundary` in NV (K/(gk)).

        Parameters
        ----------
        model : str
            The model's name (`parameters.MODEL_NAMES`).
        interval : StabilityInterval
            The stable loop gains K, 1/s², with K* and ω*.
        """
        return Boundary.from_interval(model, interval, self.steering_gain)

    def with_delay(self, T: float) -> "Loop":
        """Every field but T kept, with delay / period T, s (the dead time stays: T* is the controller's).

        Parameters
        ----------
        T : float
            Delay / sampling period, s, >= 0.
        """
        return dataclasses.replace(self, T=T)

    def _with_delay(self, T: float) -> "Loop":
        """`with_delay` unchecked (a probe of T in range, `Characteristic._with_delay`); T < `T_RESOLUTION` is 0."""
        T = float(T)
        return _unchecked(Loop, **{**vars(self), "T": T if T >= T_RESOLUTION else 0.0})  # τ, k, c, g and D kept

    def _with_steering_gain(self, k: float) -> "Loop":
        """Every field but k kept, with steering gain k, 1/s, unchecked (a probe of k in `gain_range`); τ and τ_a with
        their product with g·k below 10⁻⁹ are 0, and a lone τ_a is τ, as the constructor stores them."""
        k = float(k)
        tau, lag, slip = (x if x * self.plant_gain * k >= TAU_RESOLUTION else 0.0 for x in (self.tau, self.actuator_lag, self.slip_lag))
        if tau == 0.0 and lag > 0.0:
            tau, lag = lag, 0.0
        return _unchecked(Loop, **{**vars(self), "tau": tau, "actuator_lag": lag, "slip_lag": slip, "k": k})

    def delay_search(self, NV: float) -> tuple:
        """T* searched from 1 % of the loop's fastest time scale to 1e-7 relative (a report shows 4 digits).

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        """
        scale = _time_scale(self, NV)
        return scale * 1e-2, _DELAY_RTOL, 1e-12 * scale

    def state_space(self, hold: str) -> tuple:
        """(A, B, F0, F1) of the sampled steering loop (`models.sampled`): states (ω, θ, y), (θ, y) for τ = 0; y = x/V.

        The held input is v_k = −(F0 + K·F1)·state_k; the heading gain c adds kc to F0's θ entry.

        Parameters
        ----------
        hold : str
            What the computer holds between samples: ``"command"`` or ``"reference"`` (`parameters.HOLDS`).
        """
        return self._state_space(check_choice("hold", hold, HOLDS))

    def _state_space(self, hold: str) -> tuple:
        """`state_space` for a `hold` already checked (`Characteristic._state_space`); with a slip the course χ before y."""
        A, B, F0, F1 = self._drive_state_space(hold)
        return _with_course(A, B, F0, F1, self.slip_lag) if self.slip_lag > 0 else (A, B, F0, F1)

    def _drive_state_space(self, hold: str) -> tuple:
        """(A, B, F0, F1) without the course's lag: states (z,) (ω,) θ, y."""
        tau, k = self.tau, self.steering_gain
        if self.actuator_lag > 0:
            return _two_lag_state_space(self.actuator_lag, tau, k, self.heading, hold)
        if tau > 0:
            if hold == "command":
                A = np.array([[-1 / tau, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
                F0 = np.array([0.0, k, 0.0])
            else:
                A = np.array([[-1 / tau, -k / tau, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
                F0 = np.zeros(3)
            B = np.array([[1 / tau], [0.0], [0.0]])
            F1 = np.array([0.0, 0.0, 1.0])
        else:
            if hold == "command":
                A = np.array([[0, 0], [1, 0]], dtype=float)
                F0 = np.array([k, 0.0])
            else:
                A = np.array([[-k, 0], [1, 0]], dtype=float)
                F0 = np.zeros(2)
            B = np.array([[1.0], [0.0]])
            F1 = np.array([0.0, 1.0])
        if self.c != 0.0:  # δ_k = −(K/k)·y_k − c·θ_k: the sampled θ enters with kc more
            F0[-2] += self.heading
        return A, B, F0, F1

    def delay_interval(self) -> StabilityInterval:
        """KB's delay loop: K* among three phase levels (`delay.kb_critical_gain`); with c ≠ 0 every gain crossing
        that can bound the stable set (`models.heading.kb_heading_interval`)."""
        if not self.kb_form:
            if self.delay == 0:  # no delay at all (T = D = 0): the polynomial loop, `continuous`'s
                from ..numerics.crossings import first_stable_interval

                return first_stable_interval(self.closed_plant, [1.0], "s")
            return self.quasi_terms().stable_gains(self.steering_gain * NV_MAX)
        if self.c != 0.0:
            from .heading import kb_heading_interval  # only with a heading gain: KB's reports never compile it

            return kb_heading_interval(self.tau, self.delay, self.steering_gain, self.c)
        from ..numerics.delay import kb_critical_gain

        K, w = (float(x[0]) for x in kb_critical_gain(_one(self.tau), _one(self.delay), _one(self.steering_gain)))
        return StabilityInterval(K, w if math.isfinite(K) else None, (), ((0.0, K),))

    def quasi_polynomial(self):
        """KB's a(s) + (gkc·s + K)·e^(−sT) as a `delay.DelayLoop`; the general loop's `quasi_terms`."""
        return Characteristic.quasi_polynomial(self) if self.kb_form else self.quasi_terms()

    def _count(self, K: float):
        """(stable, unstable roots, T*) of the delay loop at K by the crossing count, in KB's array route."""
        from ..numerics.delay import delay_verdicts_from_gain

        heading = () if self.c == 0.0 else (_one(self.c),)
        stable, Z, margin = delay_verdicts_from_gain(_one(self.tau), _one(self.delay), _one(self.steering_gain), _one(K), *heading)
        return bool(stable[0]), int(Z[0]), float(margin[0])

    def delay_stable(self, K: float) -> bool:
        """The crossing count Z(T) = 0 (`delay.delay_verdicts_from_gain`; K = 0: the heading loop's).

        Parameters
        ----------
        K : float
            Loop gain K = kNV, 1/s².
        """
        if not self.kb_form:  # the argument principle (`numerics.quasi`); K = 0: the heading loop's roots
            quasi = self.quasi_terms()
            return quasi.heading().is_stable(0.0) if K == 0 else quasi.is_stable(K)
        return self._count(K)[0]

    def delay_margin(self, K: float) -> float:
        """T*, s, of the crossing count (`delay.delay_verdicts_from_gain`): the margin of the delay T + D less D (`period_margin`).

        Parameters
        ----------
        K : float
            Loop gain K = g·k·NV, 1/s².
        """
        if not self.kb_form:
            return self.shift_margin(K, "T")
        return self.period_margin(self._count(K)[2])

    def shift_margin(self, K: float, which: str) -> float:
        """T* (``which="T"``, D fixed) or D* (``"D"``, T fixed) of the general loop at K, s: exact
        (`numerics.quasi.QuasiPolynomial.shift_margin` from T = 0 or D = 0; 0 when unstable there).

        Parameters
        ----------
        K : float
            Loop gain K = g·k·NV, 1/s² (0: the heading loop's).
        which : {"T", "D"}
            The delay that grows.
        """
        base = self.replace(T=0.0) if which == "T" else self.replace(dead_time=0.0)
        if not base.delay_stable(K):
            return 0.0
        heading_moves = which == "D" or self.heading_sampled
        flags = [heading_moves] + ([True] if self.c != 0.0 else []) + [True]
        if base.kb_form:  # D = 0 and the heading's delay does not move: build the terms of the general form anyway
            from ..numerics.quasi import DelayedTerm, QuasiPolynomial

            k = base.steering_gain
            terms = [DelayedTerm((k, 0.0), 0.0)] + ([DelayedTerm((base.heading, 0.0), base.delay)] if base.c != 0.0 else [])
            quasi = QuasiPolynomial(base.lags, terms, base.delay)
        else:
            quasi = base.quasi_terms()
        return float(quasi.shift_margin(K, flags))


def _one(x) -> np.ndarray:
    return np.array([float(x)])


def _with_course(A, B, F0, F1, slip: float) -> tuple:
    """(A, B, F0, F1) with the course χ as a first state: τ_s·χ̇ + χ = θ, ẏ = χ instead of θ (y = x/V; `Loop.slip_lag`).
    The heading and the lateral offset stay the last two states (θ, y) and the yaw rate the one before them; the feedback
    reads θ and y as before (the controller senses its heading and its position); χ feeds nothing back."""
    n = A.shape[0]
    out = np.zeros((n + 1, n + 1))
    out[1:, 1:] = A
    out[n, n - 1], out[n, 0] = 0.0, 1.0  # ẏ = χ (the drive's own ẏ = θ dropped)
    out[0, n - 1], out[0, 0] = 1.0 / slip, -1.0 / slip
    first = lambda v: np.concatenate([[0.0], v])  # noqa: E731
    return out, np.vstack([[[0.0]], B]), first(F0), first(F1)


def _two_lag_state_space(lag: float, tau: float, k: float, heading: float, hold: str) -> tuple:
    """(A, B, F0, F1) of the drive with two lags: states (z, ω, θ, y), τ_a·ż + z = v (− g·k·θ with a held reference),
    τω̇ + ω = z, θ̇ = ω, ẏ = θ; the command held is v = −(F0 + K·F1)·state (`Loop.state_space`)."""
    A = np.array([[-1 / lag, 0, 0, 0], [1 / tau, -1 / tau, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]], dtype=float)
    F0 = np.array([0.0, 0.0, k if hold == "command" else 0.0, 0.0])
    if hold == "reference":
        A[0, 2] = -k / lag
    F0[2] += heading
    return A, np.array([[1 / lag], [0.0], [0.0], [0.0]]), F0, np.array([0.0, 0.0, 0.0, 1.0])


@functools.lru_cache(maxsize=16)
def steering_family(delayed: bool, second_lag: bool, heading_sampled: bool, slip: bool = False) -> LoopFamily:
    """The steering loop's family with the equations each model solves for a plant with a dead time D
    (`delayed`), a second lag τ_a (`second_lag`), the heading sampled by the controller and a course that lags the
    heading (`slip`, `Loop.slip_lag`; docs/models.md).

    Parameters
    ----------
    delayed, second_lag, heading_sampled, slip : bool
        Which of the general loop's features the equations show.
    """
    lags = "(tau s + 1)(tau_a s + 1) s^2" if second_lag else "tau s^3 + s^2"
    h1 = ("(T + D)" if delayed else "T") if heading_sampled else ("D" if delayed else None)
    hK = "(T + D)" if delayed else "T"
    if not (delayed or second_lag or heading_sampled or slip):  # only a plant gain: KB's equations with g k
        return LoopFamily("steering", "NV", _kb_equations("g k"), ("order", "hold", "compute_delay"))
    field_term = "N V"  # with a heading gain c read (c s + N V), as KB's equations read k N V
    delayed_heading = f"g k s exp(-s {h1})" if h1 else "g k s"
    first = f"g k s (1 - {h1} s)" if h1 else "g k s"
    slipping = (lambda rest: f"(tau_s s + 1)({rest})") if slip else (lambda rest: rest)
    equations = {
        "continuous": f"{slipping(f'{lags} + g k s')} + g k N V = 0  (no delay)",
        "kb_first_order": f"{slipping(f'{lags} + {first}')} + g k {field_term} (1 - {hK} s) = 0  (each delay to first order, KB eq 19)",
        "pade": f"{slipping(f'{lags} + {delayed_heading}')} + g k {field_term} exp(-s {hK}) = 0, each exp(-s h) by Pade(m,m)",
        "exact_delay": f"{slipping(f'{lags} + {delayed_heading}')} + g k {field_term} exp(-s {hK}) = 0",
        "sampled": "det(zI - Phi_cl(gkNV)) = 0, ZOH, period T" + (", the commands on their way for D (modified z-transform)" if delayed else "")
                   + (", the course's lag tau_s a state" if slip else ""),
    }
    return LoopFamily("steering", "NV", equations, ("order", "hold", "compute_delay"))


def _kb_equations(k: str) -> dict:
    """KB's equations (17)–(19) with the steering gain written `k` ("k", or "g k" for a plant gain)."""
    return {
        "continuous": f"tau s^3 + s^2 + {k} s + {k} N V = 0  (KB eq 17)",
        "kb_first_order": f"tau s^3 + s^2 + {k}(1 - N V T) s + {k} N V = 0  (KB eq 19)",
        "pade": f"(tau s^3 + s^2 + {k} s) Q_m(s) + {k} N V P_m(s) = 0  (KB eq 18, Pade(m,m))",
        "exact_delay": f"tau s^3 + s^2 + {k} s + {k} N V exp(-s T) = 0  (KB eq 18)",
        "sampled": f"det(zI - Phi_cl({k.replace(' ', '')}NV)) = 0, ZOH, period T",
    }


STEERING = LoopFamily("steering", "NV", _kb_equations("k"), ("order", "hold", "compute_delay"))
"""KB's steering robot (kinematic steering: τ = 0): the gain NV, KB's equations (17)–(19)."""


@dataclass(frozen=True)
class Boundary(StableSet):
    """Stability boundary of one model for one loop (τ, T, k, c).

    Attributes
    ----------
    model : str
        Model name (`parameters.MODEL_NAMES`, docs/models.md).
    NV_critical : float
        NV*, 1/s: stable for every 0 < NV < NV* (``inf``: stable for every
        NV; 0: unstable at every NV close to 0 — "unstable at any speed").
    omega_critical : float or None
        Angular frequency of the oscillation that starts at NV*, rad/s (None
        when NV* is 0 or infinite).
    K_critical : float
        K* = k·NV*, 1/s².
    stable_set : tuple of (float, float)
        Every interval of NV (1/s) on which the loop is stable, ascending. The
        first is (0, NV*) when NV* > 0; a sampled loop can have more, or one
        that does not start at 0.
    """

    model: str
    NV_critical: float
    omega_critical: float | None
    K_critical: float
    stable_set: tuple = ()

    @classmethod
    def from_interval(cls, model: str, interval, k: float) -> "Boundary":
        """From a `crossings.StabilityInterval` in gain K = kNV.

        Parameters
        ----------
        model : str
            The model's name (`parameters.MODEL_NAMES`).
        interval : StabilityInterval
            The stable loop gains K, 1/s², with K* and ω*.
        k : float
            Steering gain, 1/s.
        """
        intervals = tuple((lo / k, hi / k) for lo, hi in interval.intervals)
        return cls(model, interval.gain / k, interval.frequency, interval.gain, intervals)

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "model": self.model,
            "NV_critical": json_number(self.NV_critical),
            "omega_critical": self.omega_critical,
            "K_critical": json_number(self.K_critical),
            "stable_set": self.stable_set_json(),
        }


def check_heading_gain(c) -> float:
    """c as a float if it is finite and in `HEADING_GAIN_RANGE`, else ValueError (with the reason for c <= −1).

    Parameters
    ----------
    c : float
        Heading gain, dimensionless.
    """
    low, high = HEADING_GAIN_RANGE
    try:
        return check_number("c", c, low, high, low_open=False, high_open=False)
    except ValueError as exc:
        if isinstance(c, (int, float)) and not isinstance(c, bool) and c <= -1:
            raise ValueError(f"{exc} (c <= -1 removes the heading feedback: unstable at any NV)") from None
        raise


def _time_scale(loop: Loop, NV: float) -> float:
    """The loop's fastest time scale, s: min(τ, 1/k, 1/NV) (τ counts when > 0, 1/NV when NV != 0)."""
    scales = [1.0 / loop.steering_gain] + ([1.0 / abs(NV)] if NV != 0 else []) + ([loop.tau] if loop.tau > 0 else [])
    return min(scales)


def gain_range(loop: Loop) -> tuple[float, float]:
    """(k_lo, k_hi), 1/s: where `critical_gain_k` searches, inside k's range (`RANGES["k"]`).

    k_lo = 1e-3·k, but never below the smallest allowed k (a loop with a k
    outside its range cannot be built: the search would fail on its own probe).

    Parameters
    ----------
    loop : Loop
        The steering loop (its k, 1/s, sets the search's lower end).
    """
    return max(1e-3 * loop.k, RANGES["k"].low), RANGES["k"].high
