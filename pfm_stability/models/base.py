"""What every loop model shares: the loop families, the boundary result, verdicts.

Koren & Borenstein 1991 (KB) reduce robot + environment to a loop whose only
environment-dependent quantity is the product NV (eq 16–19): the characteristic
equation of every model here is a function of τ, T, k and the loop gain
K = kNV. A model therefore answers three questions for given (τ, T, k):

* `boundary`: the critical NV* (stable for 0 < NV < NV*) and the oscillation
  frequency there;
* `is_stable(NV, …)`: a verdict by a route that does not use the boundary
  (Routh, Schur–Cohn, a crossing count);
* `rightmost_root(NV, …)`: the dominant root as a continuous-time rate
  σ + jω (1/s, rad/s); sampled models convert z by s = ln(z)/T.

Every robot family closes a loop of one shape (docs/models.md, "Robot loop
families"): a(s) + (δ·s + K)·e^(−sT) = 0, with a plant a(s), a delayed rate
term δ·s and a loop gain K. `family.Characteristic` is that shape; `Loop` is KB's
steering robot (a(s) = τs³ + s² + ks, δ = kc, K = kNV; kinematic steering is
τ = 0) and `models.holonomic.HolonomicLoop` the holonomic one (a(s) = s²,
δ = c_h, K = κ). Each model (`continuous`, `kb_first_order`, `pade`,
`exact_delay`, `sampled`) is one implementation that reads the loop it is
given through `Characteristic` only, so it decides every family; a family's
`family.LoopFamily` names its gain and the equation each model solves
(`STEERING` here).

A heading gain c (`Loop.c`, docs/models.md "The heading gain") adds k·c·s to
the gain term: τs³ + s² + ks + k(cs + NV)·e^(−sT) = 0. c = 0 (the default)
is KB's loop and runs exactly the code it always ran. NV < 0 (N < 0: a field
that pushes the robot away from its equilibrium) is accepted by every query
and is unstable in every model (`divergent_reason`). NV = 0 (N = 0: no
restoring force) leaves a neutral lateral root at s = 0 (z = 1); every query
judges the other roots, the heading loop (`neutral_reason`, docs/models.md
"N = 0").
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from ..checks import check_choice, check_number
from ..parameters import HOLDS, RANGES, T_RESOLUTION, TAU_RESOLUTION, check_parameter
from ..numerics.crossings import Crossing, StabilityInterval, affine_crossings, stable_interval, stable_set, verdict_at
from ..io.serialize import json_number
from .family import Characteristic, LoopFamily, StableSet, _unchecked
from .verdicts import NV_MAX

__all__ = [
    "STEERING",
    "Loop",
    "Boundary",
    "LoopModel",
    "AffineGainModel",
    "gain_range",
    "checked",
    "check_heading_gain",
    "neutral_quotient",
    "HEADING_GAIN_RANGE",
]

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

def neutral_quotient(p, domain: str = "s") -> np.ndarray:
    """p(s)/s (``domain="s"``) or p(z)/(z − 1) (``"z"``): a characteristic polynomial at NV = 0 without its
    neutral lateral root (descending in and out; the quotient of the exact division).

    Every affine model's D has the root there exactly (D(0) = 0: the s⁰ coefficient is a product with
    the plant's zero constant term), so the s quotient drops that coefficient without arithmetic.

    Parameters
    ----------
    p : array_like
        The polynomial, descending.
    domain : str, optional
        ``"s"`` or ``"z"``.
    """
    p = np.trim_zeros(np.asarray(p, dtype=float), "f")
    if domain == "s":
        return p[:-1]
    return np.polydiv(p, [1.0, -1.0])[0]


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
        steering gain is g·k (`steering_gain`; `k` stays the controller's, k* is in it),
        the continuous-time models' delay T + D (`delay`).
    """

    tau: float
    T: float
    k: float
    c: float = field(default=0.0, kw_only=True)
    plant_gain: float = field(default=1.0, kw_only=True)
    dead_time: float = field(default=0.0, kw_only=True)

    def __post_init__(self):
        for name in ("tau", "T", "k"):
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        for name in [n for n, d in (("plant_gain", 1.0), ("dead_time", 0.0)) if getattr(self, n).__class__ is not float or getattr(self, n) != d]:
            object.__setattr__(self, name, check_parameter(name, getattr(self, name)))
        if self.tau * self.steering_gain < TAU_RESOLUTION:  # a lag 10⁹ times faster than the steering loop: an ideal motor
            object.__setattr__(self, "tau", 0.0)
        if self.T < T_RESOLUTION:  # faster than a picosecond: a continuous controller
            object.__setattr__(self, "T", 0.0)
        if self.c.__class__ is not float or self.c != 0.0:
            object.__setattr__(self, "c", check_heading_gain(self.c))

    @classmethod
    def of(cls, robot, controller, *, c: float = 0.0) -> "Loop":
        """The loop of a robot and its controller (τ, k, g, D; T), with heading gain `c`: the one constructor from them.

        Parameters
        ----------
        robot : parameters.Robot
        controller : parameters.Controller
        c : float
            Heading gain of the equilibrium (0: a static law, KB's loop).
        """
        return cls(robot.tau, controller.T, robot.k, c=c, plant_gain=robot.plant_gain, dead_time=robot.dead_time)

    @property
    def steering_gain(self) -> float:
        """g·k, 1/s: the loop's steering gain, the motor's rate per radian of heading error (k for KB's robot, g = 1)."""
        return self.plant_gain * self.k

    def replace(self, **changes) -> "Loop":
        """A copy with `changes` (field name → value), checked as the constructor checks."""
        return dataclasses.replace(self, **changes)

    @property
    def family(self) -> LoopFamily:
        """`STEERING`."""
        return STEERING

    @property
    def plant(self) -> np.ndarray:
        """a(s) = τs³ + s² + ks, descending (KB eq 17 without the gain term)."""
        k = self.steering_gain
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
        """τ, k, c, g and D with delay / period T, s (the dead time stays: T* is the controller's).

        Parameters
        ----------
        T : float
            Delay / sampling period, s, >= 0.
        """
        return Loop(self.tau, T, self.k, c=self.c, plant_gain=self.plant_gain, dead_time=self.dead_time)

    def _with_delay(self, T: float) -> "Loop":
        """`with_delay` unchecked (a probe of T in range, `Characteristic._with_delay`); T < `T_RESOLUTION` is 0."""
        T = float(T)
        return _unchecked(Loop, **{**vars(self), "T": T if T >= T_RESOLUTION else 0.0})  # τ, k, c, g and D kept

    def _with_steering_gain(self, k: float) -> "Loop":
        """τ, T and c with steering gain k, 1/s, unchecked (a probe of k in `gain_range`); τ with τk < 10⁻⁹ is 0."""
        k = float(k)
        return _unchecked(Loop, **{**vars(self), "tau": self.tau if self.tau * self.plant_gain * k >= TAU_RESOLUTION else 0.0, "k": k})

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
        """`state_space` for a `hold` already checked (`Characteristic._state_space`)."""
        tau, k = self.tau, self.steering_gain
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
        if self.c != 0.0:
            from .heading import kb_heading_interval  # only with a heading gain: KB's reports never compile it

            return kb_heading_interval(self.tau, self.delay, self.steering_gain, self.c)
        from ..numerics.delay import kb_critical_gain

        K, w = (float(x[0]) for x in kb_critical_gain(_one(self.tau), _one(self.delay), _one(self.steering_gain)))
        return StabilityInterval(K, w if math.isfinite(K) else None, (), ((0.0, K),))

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
        return self._count(K)[0]

    def delay_margin(self, K: float) -> float:
        """T*, s, of the crossing count (`delay.delay_verdicts_from_gain`): the margin of the delay T + D less D (`period_margin`).

        Parameters
        ----------
        K : float
            Loop gain K = g·k·NV, 1/s².
        """
        return self.period_margin(self._count(K)[2])


def _one(x) -> np.ndarray:
    return np.array([float(x)])


STEERING = LoopFamily(
    "steering",
    "NV",
    {
        "continuous": "tau s^3 + s^2 + k s + k N V = 0  (KB eq 17)",
        "kb_first_order": "tau s^3 + s^2 + k(1 - N V T) s + k N V = 0  (KB eq 19)",
        "pade": "(tau s^3 + s^2 + k s) Q_m(s) + k N V P_m(s) = 0  (KB eq 18, Pade(m,m))",
        "exact_delay": "tau s^3 + s^2 + k s + k N V exp(-s T) = 0  (KB eq 18)",
        "sampled": "det(zI - Phi_cl(kNV)) = 0, ZOH, period T",
    },
    ("order", "hold", "compute_delay"),
)
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


def _check_NV(NV) -> float:
    """NV as a float: finite (negative: N < 0, `divergent_reason`; 0: N = 0, `neutral_reason`; −0.0 becomes 0.0)."""
    return check_number("NV", NV, unit="1/s") + 0.0


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


def _check_loop(loop) -> Characteristic:
    if not isinstance(loop, Characteristic):
        raise ValueError(f"loop must be a Loop (tau, T, k) or a HolonomicLoop (T, c_h); got {loop!r}")
    return loop


def checked(method):
    """Validate a public model method's (gain, loop) arguments: ValueError naming the bad one.

    The gain is the loop's family's (`Characteristic.check_gain`): NV for a steering
    loop, capped at |NV| <= `NV_MAX` here only (internal probes, a stable interval
    checked beyond the last crossing gain, may go further); NV < 0 is accepted
    (N < 0, `divergent_reason`), and NV = 0 (N = 0: the heading loop is judged,
    `neutral_reason`). κ for a holonomic loop (non-zero).

    Parameters
    ----------
    method : callable
        A model method ``method(self, gain, loop, ...)``.
    """

    @functools.wraps(method)
    def wrapper(self, gain, loop, *args, **kwargs):
        loop = _check_loop(loop)
        return method(self, loop.check_gain(gain), loop, *args, **kwargs)

    return wrapper


def _steering(loop: Characteristic, what: str) -> Loop:
    """`loop` if it is a steering loop; ValueError for a query that has none in another family (k*: the steering gain)."""
    if not isinstance(loop, Loop):
        raise ValueError(f"loop must be a Loop (tau, T, k) for {what}: a {loop.family.name} loop has no steering gain k; got {loop!r}")
    return loop


@lru_cache(maxsize=8192)
def _cached_boundary(model: "LoopModel", loop: Characteristic):
    return model.compute_boundary(loop)


class LoopModel:
    """Base class: a named loop model, for the loop of any family (`Characteristic`). Subclasses implement the queries.

    Each query takes the family's gain (NV for a `Loop`, κ for a `HolonomicLoop`) and the
    loop; a boundary is the family's (`Boundary` in NV, `HolonomicBoundary` in κ). Models are
    immutable and hashable, so `boundary` is cached per (model, loop): a report asks for
    the same boundary many times.
    """

    name: str = ""

    def options(self) -> dict:
        """The options that configure this model, in the order JSON writes them.

        ``{}`` for a model without options; ``{"order": m}`` for `Pade`,
        ``{"hold": …, "compute_delay": …}`` for `Sampled` (docs/models.md).
        """
        return {}

    def boundary(self, loop: Characteristic):
        """The critical gain (NV* or κ*), the boundary frequency and the stable set for the loop (cached).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return _cached_boundary(self, _check_loop(loop))

    def compute_boundary(self, loop: Characteristic):  # pragma: no cover - interface
        """`boundary`, uncached.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    @checked
    def is_stable(self, gain: float, loop: Characteristic) -> bool:
        """Verdict at the gain (NV 1/s, κ 1/s²) by a route independent of `boundary`.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return self._stable(gain, loop)

    def _stable(self, gain: float, loop: Characteristic) -> bool:  # pragma: no cover - interface
        """`is_stable` without the public argument checks (internal probes)."""
        raise NotImplementedError

    @checked
    def rightmost_root(self, gain: float, loop: Characteristic) -> complex:  # pragma: no cover - interface
        """Dominant root σ + jω (1/s, rad/s, ω >= 0); sampled models map z by ln(z)/T.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    def growth_rates(self, gain: float, loops) -> np.ndarray:
        """Real part of the dominant root, 1/s, at the gain for each loop of a sequence.

        At NV = 0 the heading loop's (`neutral_reason`: the neutral lateral
        root left out), as `rightmost_root`. Models override `_growth_rates`
        with a vectorized version where they can.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loops : sequence of Characteristic
            The loops, one growth rate each.
        """
        return self._growth_rates(_check_NV(gain), loops)

    def _growth_rates(self, gain: float, loops) -> np.ndarray:
        """`growth_rates` of a gain already checked (the searches of `critical_delay` and `critical_gain_k`)."""
        return np.array([self.rightmost_root(gain, loop).real for loop in loops])

    @checked
    def critical_delay(self, gain: float, loop: Characteristic) -> float:
        """T*: the smallest sampling period / delay at which the gain loses stability (the rest fixed), s.

        The operating point's delay margin, the same definition in every
        model: stable for every T in [0, T*). 0 if the gain is unstable already
        at T → 0; ``inf`` if it stays stable up to the largest allowed T
        (100 s). Found by `solve.first_crossing` on the dominant growth rate
        over T (a geometric grid with its local maxima refined, then
        bisection to the family's tolerance, `Characteristic.delay_search`:
        1e-7 relative for a steering loop, 1e-9 for a holonomic one); models
        with an exact route override it.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged; its own T, s, is replaced by the searched ones.
        """
        def search():  # probes of the checked loop: T in [start, RANGES["T"].high]
            start, rtol, atol = loop.delay_search(gain)
            return start, RANGES["T"].high, {"rtol": rtol, "atol": atol}

        return self._first_loss(gain, loop._with_delay, 0.0, search)

    @checked
    def critical_gain_k(self, NV: float, loop: Loop) -> float:
        """k*: the smallest steering gain at which NV loses stability (τ, T fixed), 1/s; a steering loop's only.

        Stable for every k in (0, k*): lowering k below k* is a remedy that
        works. 0 if no k is small enough; ``inf`` if NV stays stable up to the
        largest allowed k (10⁴ 1/s). Same search as `critical_delay`, over k.

        Parameters
        ----------
        NV : float
            Loop gain N·V, 1/s.
        loop : Loop
            The steering loop judged; its own k is replaced by the searched ones.
        """
        loop = _steering(loop, "critical_gain_k")
        lo, hi = gain_range(loop)  # probes of the checked loop: k in gain_range
        return self._first_loss(NV, loop._with_steering_gain, lo, lambda: (lo, hi, {"start": lo, "rtol": _DELAY_RTOL, "atol": 1e-12 * lo}))

    def _first_loss(self, gain: float, probe, origin: float, search) -> float:
        """The first value x > `origin` at which the gain loses stability, the loop `probe(x)` (T*, k*, D*): 0 when
        unstable already at `origin` (or gain < 0), else `solve.first_crossing` of the growth rate on the interval
        ``search()`` gives, ``(low, high, first_crossing's keywords)`` (asked only then; ``inf``: stable up to high)."""
        from ..numerics.solve import first_crossing

        if gain < 0 or self._searched_growth_rates(gain, [probe(origin)])[0] >= 0:
            return 0.0
        low, high, options = search()
        return first_crossing(lambda xs: self._searched_growth_rates(gain, [probe(x) for x in xs]), low, high, **options)

    def _searched_growth_rates(self, gain: float, loops) -> np.ndarray:
        """The growth rates (1/s) the searches for T*, k* and D* measure: `_growth_rates` (`sampled`'s has a stand-in)."""
        return self._growth_rates(gain, loops)

    @checked
    def critical_dead_time(self, gain: float, loop: Loop) -> float:
        """D*: the largest dead time of the steering plant the gain tolerates, T fixed, s (`dead_time.search_dead_time`).

        Parameters
        ----------
        gain : float
            Loop gain NV, 1/s.
        loop : Loop
            τ, T, k, c and g (its own D is replaced).
        """
        from .dead_time import search_dead_time

        return search_dead_time(self, gain, _steering(loop, "critical_dead_time"))

    @checked
    def damping_range(self, gain: float, loop: Characteristic) -> tuple:  # pragma: no cover - interface
        """Every interval of the damping δ (the holonomic c_h, 1/s) that makes the gain stable at the loop's T.

        Parameters
        ----------
        gain : float
            The family's loop gain (κ, 1/s², of a holonomic loop).
        loop : Characteristic
            The loop judged; its T, s, is kept and its own damping ignored.
        """
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and vars(self) == vars(other)

    def __hash__(self) -> int:
        return hash((type(self).__name__, tuple(sorted(vars(self).items()))))


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


def _aligned(*polys) -> tuple:
    """The polynomials (descending) padded with leading zeros to one length."""
    polys = [np.asarray(p, dtype=float) for p in polys]
    n = max(len(p) for p in polys)
    return tuple(np.pad(p, (n - len(p), 0)) for p in polys)


class AffineGainModel(LoopModel):
    """A model whose characteristic polynomial is affine in the loop gain and in the damping: P0 + δ·P1 + K·P2.

    Subclasses provide `polynomials(loop) -> (D, E)`, D + K·E in descending powers
    of s (``domain = "s"``) or z (``domain = "z"``), and `parts(loop) -> (P0, P1, P2)`
    in s (Tustin's μ for the sampled model), one length. The boundary: every gain
    at which a root crosses the imaginary axis (`crossings.affine_crossings`) or
    leaves through infinity (the degree of the polynomial drops), each stretch
    between them decided by the model's own verdict (`crossings.stable_interval`);
    the damping range is the same in δ.
    """

    domain = "s"

    def polynomials(self, loop: Characteristic):  # pragma: no cover - interface
        """(D, E), descending coefficients: the characteristic polynomial is D + K·E.

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    def parts(self, loop: Characteristic):  # pragma: no cover - interface
        """(P0, P1, P2), descending, one length: the characteristic polynomial P0 + δ·P1 + K·P2 (s; μ for `sampled`).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        raise NotImplementedError

    @checked
    def characteristic(self, gain: float, loop: Characteristic) -> np.ndarray:
        """Characteristic polynomial D + K·E, descending coefficients.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        d, e = _aligned(*self.polynomials(loop))
        return np.trim_zeros(d + loop.loop_gain(_check_NV(gain)) * e, "f")

    def _frequency(self, raw: float, loop: Characteristic) -> float:
        """The crossing frequency in rad/s from that of the polynomial's variable (identity in s)."""
        return raw

    def _infinite_frequency(self, loop: Characteristic) -> float:
        """The frequency at which a root leaves when the degree drops: s = ∞ (``inf``)."""
        return math.inf

    def _crossings(self, d, e, loop: Characteristic) -> list | None:
        """Every gain g > 0 at which a root of d + g·e crosses the imaginary axis or passes through infinity, sorted;
        None when d·conj(e) is real on the whole axis (a root pair that stays on it: no crossing is isolated)."""
        d, e = _aligned(d, e)
        try:
            found = affine_crossings(d, e, "s")
        except ValueError:
            return None
        out = [Crossing(c.gain, self._frequency(c.frequency, loop)) for c in found]
        if e[0] != 0.0 and -d[0] / e[0] > 0:  # the degree drops: a root passes through infinity (z = −1 for `sampled`)
            out.append(Crossing(float(-d[0] / e[0]), self._infinite_frequency(loop)))
        return sorted(out, key=lambda c: (c.gain, c.frequency))

    def _interval(self, d, e, stable, loop: Characteristic) -> StabilityInterval:
        """The stable gains from the crossings of d + K·e in s, each stretch decided by ``stable(K)``."""
        crossings = self._crossings(d, e, loop)
        return StabilityInterval(0.0, None, (), ()) if crossings is None else stable_interval(crossings, stable)

    def stable_gains(self, loop: Characteristic) -> StabilityInterval:
        """Every stable loop gain K (1/s²), K* and ω*, uncached (`boundary` gives them in the family's gain).

        Parameters
        ----------
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        d, e = self.polynomials(loop)
        return self._interval(d, e, lambda K: verdict_at(d, e, K, self.domain), loop)

    def compute_boundary(self, loop: Characteristic):
        return loop.boundary_from(self.name, self.stable_gains(loop))

    def _stable(self, gain: float, loop: Characteristic) -> bool:
        """`is_stable` without the public argument checks (internal probes); NV = 0: D's quotient by its neutral root."""
        d, e = self.polynomials(loop)
        if gain == 0:
            return verdict_at(neutral_quotient(d, self.domain), [0.0], 0.0, self.domain)
        return verdict_at(d, e, loop.loop_gain(gain), self.domain)

    @checked
    def damping_range(self, gain: float, loop: Characteristic) -> tuple:
        """Every interval of the damping δ (1/s) that makes the gain stable at the loop's T, ascending.

        A holonomic loop's c_h (`HolonomicLoop`; ``loop.c_h`` itself is ignored);
        ``()`` when no damping helps (a negative gain, or a delay too long for it).

        Parameters
        ----------
        gain : float
            The family's loop gain (κ, 1/s², of a holonomic loop).
        loop : Characteristic
            The loop judged; its T, s, is kept and its own damping ignored.
        """
        loop.with_damping(0.0)  # a family whose damping is a parameter of its own
        if gain < 0:
            return ()
        p0, p1, p2 = self.parts(loop)
        crossings = self._crossings(p0 + loop.loop_gain(gain) * p2, p1, loop)
        if crossings is None:  # pragma: no cover - only δ·P1 real on the axis, not met
            return ()
        return stable_set(crossings, lambda damping: self._stable(gain, loop.with_damping(damping)))

    @checked
    def roots(self, gain: float, loop: Characteristic) -> np.ndarray:
        """All roots of the characteristic polynomial (s or z).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        return np.roots(self.characteristic(gain, loop))

    def batch_polynomials(self, loops):
        """(D, E) of each loop as two arrays of rows of one length (descending; leading zeros allowed).

        Parameters
        ----------
        loops : sequence of Characteristic
            The loops, one row each.
        """
        pairs = [self.polynomials(loop) for loop in loops]
        width = max(max(len(d), len(e)) for d, e in pairs)
        D = np.array([np.pad(d, (width - len(d), 0)) for d, _ in pairs])
        E = np.array([np.pad(e, (width - len(e), 0)) for _, e in pairs])
        return D, E

    def _growth_rates(self, gain: float, loops) -> np.ndarray:
        """max Re s (1/s) at the gain for each loop: eigenvalues of the companion matrices, batched by degree
        (NV = 0: of D/s, the heading loop; −inf for a constant)."""
        loops = list(loops)
        D, E = self.batch_polynomials(loops)
        P = D + np.array([loop.loop_gain(gain) for loop in loops])[:, None] * E
        if gain == 0:  # D(0) = 0 exactly: drop the neutral lateral root
            P = P[:, :-1]
        polys = [row[np.flatnonzero(row)[0]:] for row in P]
        out = np.empty(len(polys))
        for degree in {len(p) - 1 for p in polys}:
            rows = [i for i, p in enumerate(polys) if len(p) - 1 == degree]
            if degree == 0:
                out[rows] = -np.inf
                continue
            monic = np.array([polys[i][1:] / polys[i][0] for i in rows])
            companion = np.zeros((len(rows), degree, degree))
            companion[:, 0, :] = -monic
            companion[:, np.arange(1, degree), np.arange(degree - 1)] = 1.0
            out[rows] = np.linalg.eigvals(companion).real.max(axis=1)
        return out

    @checked
    def rightmost_root(self, gain: float, loop: Characteristic) -> complex:
        """Dominant root σ + jω (1/s, rad/s; of a pair the one with ω > 0); NV = 0: the heading loop's (−inf when only
        the neutral root is left).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        loop : Characteristic
            The loop judged (`Loop`, `HolonomicLoop`).
        """
        if gain == 0:
            roots = np.roots(neutral_quotient(self.characteristic(gain, loop), self.domain))
            if roots.size == 0:
                return complex(-math.inf, 0.0)
        else:
            roots = self.roots(gain, loop)
        if roots.size == 0:  # pragma: no cover - a constant polynomial: degree 0 only at c_h·T = 1 and κ = c_h/T together
            return complex(-math.inf, 0.0)
        if self.domain == "z":
            z = roots[np.argmax(np.abs(roots))]
            return complex(np.log(z) / loop.T)
        return _dominant(roots)


def _dominant(roots) -> complex:
    """The root of largest real part; of roots level with it to round-off, the one of largest imaginary part (ω > 0)."""
    top = roots[roots.real >= roots.real.max() - 1e-12 * max(1.0, np.abs(roots).max())]
    return complex(top[np.argmax(top.imag)])
