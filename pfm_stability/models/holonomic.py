"""Robot loop families beside KB's steering loop: the holonomic robot and kinematic steering.

**Holonomic robot, force = acceleration** (Ge & Cui 2002 §6 and its conference
form §V). The robot obeys m·ẍ = F_x(x, ẋ); linearised about an equilibrium,
with the force computed from sensor data that are T old (docs/models.md,
"Robot loop families"):

    s² + (c_h·s + κ)·e^(−sT) = 0,   κ = −∂F_x/∂x / m  (1/s²),   c_h = −∂F_x/∂v_x / m  (1/s).

It is the shape every family shares, a(s) + (δ·s + K)·e^(−sT) (`family.Characteristic`),
with a(s) = s², δ = c_h and K = κ: `HolonomicLoop` is that characteristic, and the
five models of KB's loop (`continuous`, `kb_first_order`, `pade`, `exact_delay`,
`sampled`) decide it as they decide the steering loop:

================  ==========================================  ===========================
name              characteristic equation                     decided by
================  ==========================================  ===========================
continuous        s² + c_h s + κ = 0                           Routh: c_h > 0 and κ > 0
kb_first_order    s² + (c_h s + κ)(1 − sT) = 0                 Routh
pade              s² Q_m(s) + (c_h s + κ) P_m(s) = 0           Routh; axis crossings
exact_delay       s² + (c_h s + κ) e^(−sT) = 0                 crossing count (`delay`)
sampled           ZOH of u_k = −κx_k − c_h v_k, 0/1 delay      eigenvalues; bilinear + Routh
================  ==========================================  ===========================

Each model answers `boundary` (κ* and the stable set in κ at fixed T, c_h:
`HolonomicBoundary`), `is_stable`, `rightmost_root`, `critical_delay` (T*: stable
for every T in [0, T*)) and `damping_range` (the stable set in c_h at fixed κ, T).
κ < 0 is unstable in every model (a real root s > 0, as NV < 0); κ = 0 is refused
(a root at s = 0); c_h <= 0 is unstable in every model (c_h = 0: the undamped
oscillator, which any delay destabilises, T* = 0). What the holonomic family
has and the steering one has not lives here: the exact delay's crossings in
closed form (`HolonomicLoop.delay_interval`, `HolonomicLoop.delay_damping_range`)
and a model's verdict in κ (`holonomic_verdict`).

The exact delay, a(s) + (d(s) + K)e^(−sT) with a(s) = s², d(s) = c_h·s and K = κ:
the crossing polynomial F(y) = y² − c_h²y − κ² (y = ω²) has one positive root,
ω² = (c_h² + √(c_h⁴ + 4κ²))/2, where F′ > 0: every crossing as T grows
destabilises, so the loop is stable exactly when c_h > 0, κ > 0 and
T < T* = atan2(c_h ω, κ)/ω. T* decreases strictly in κ (from π/(2c_h) at κ → 0),
so the stable set in κ is one interval (0, κ*): at κ* a root is at jω with
ω sin ωT = c_h and κ* = ω² cos ωT, ωT ∈ (0, π/2) (ω sin ωT increases there; none
when c_hT >= π/2). In c_h, T* rises from 0 and falls back to 0, so the stable
set is one interval whose ends solve ω² cos ωT = κ on either side of the maximum
of ω² cos ωT (x tan x = 2, x = ωT), c_h = ω sin ωT there; empty when κT² exceeds
that maximum, ≈ 0.5498. Every interval is checked by the crossing count
(`crossings.stable_set`).

The sampled model is the double integrator ẋ = v, v̇ = u with a zero-order hold
of the acceleration command u_k = −κx_k − c_h v_k, applied at once
(compute_delay = 0) or one period later (1): KB's sampled loop with τ = 0 and
the command held, its heading feedback k(1 + c) replaced by c_h. Jury's
conditions for d = 0 give T* = min(2/c_h, 2c_h/κ) (the tests' closed form).

**Kinematic steering** (Ge & Cui 2002 §7: ω = K_s(θ_f − θ), no motor lag) is
KB's steering loop with τ = 0 and k = K_s, s² + K_s s + K_s(cs + NV)e^(−sT):
`kinematic_loop` builds that `Loop`, which every steering model takes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..checks import check_number
from ..numerics.crossings import Crossing, StabilityInterval, stable_interval, stable_set
from ..numerics.solve import bisect_root
from ..parameters import RANGES, T_RESOLUTION, check_parameter
from ..io.serialize import json_number
from .base import LoopModel
from .loop import Loop
from .verdicts import interval_margin, interval_verdict
from .continuous import Continuous
from .family import Characteristic, LoopFamily, StableSet, _unchecked, root_json

__all__ = [
    "BEST_CURVATURE_PRODUCT",
    "HOLONOMIC",
    "HolonomicBoundary",
    "HolonomicLoop",
    "HolonomicVerdict",
    "check_kappa",
    "holonomic_verdict",
    "kinematic_loop",
]

_DELAY_RTOL = 1e-9
"""Relative bracket width at which the searched `critical_delay` stops."""


def _curvature_peak() -> float:
    """x0 with x·tan x = 2 on (0, π/2): where ω² cos ωT peaks (x = ωT)."""
    return bisect_root(lambda x: x * math.tan(x) - 2.0, 1e-9, math.pi / 2 - 1e-12, rtol=1e-15)


_X0 = _curvature_peak()
BEST_CURVATURE_PRODUCT = _X0 * _X0 * math.cos(_X0)
"""max over ω of ω²T²·cos ωT (≈ 0.5498): no damping stabilises κ with κT² at or above it (exact delay)."""

HOLONOMIC = LoopFamily(
    "holonomic",
    "kappa",
    {
        "continuous": "s^2 + c_h s + kappa = 0",
        "kb_first_order": "s^2 + (c_h s + kappa)(1 - s T) = 0",
        "pade": "s^2 Q_m(s) + (c_h s + kappa) P_m(s) = 0  (Pade(m,m))",
        "exact_delay": "s^2 + (c_h s + kappa) exp(-s T) = 0",
        "sampled": "det(zI - Phi_cl(kappa, c_h)) = 0, ZOH of the acceleration, period T",
    },
    ("order", "compute_delay"),
)
"""The holonomic robot (Ge & Cui 2002 §6): the gain κ, the equations of the table above."""


def check_kappa(kappa) -> float:
    """κ (1/s²) as a float: finite, in ``RANGES["kappa"]``, non-zero (κ = 0 puts a root at s = 0).

    Parameters
    ----------
    kappa : float
        Stiffness κ, 1/s².
    """
    kappa = check_parameter("kappa", kappa)
    if kappa == 0.0:
        raise ValueError("kappa must be a finite non-zero number 1/s^2 (kappa = 0: no force gradient, a root at s = 0); got 0.0")
    return kappa


@dataclass(frozen=True)
class HolonomicBoundary(StableSet):
    """Stability boundary in κ of one model for one holonomic loop (T, c_h).

    Attributes
    ----------
    model : str
        Model name.
    kappa_critical : float
        κ*, 1/s²: stable for every 0 < κ < κ* (``inf``: for every κ > 0;
        0: unstable at every small κ).
    omega_critical : float or None
        Frequency of the oscillation that starts at κ*, rad/s (None when κ*
        is 0 or infinite).
    stable_set : tuple of (float, float)
        Every interval of κ (1/s²) on which the loop is stable, ascending.
    """

    model: str
    kappa_critical: float
    omega_critical: float | None
    stable_set: tuple = ()

    def to_dict(self) -> dict:
        """The fields as a JSON-ready dict (SI units)."""
        return {
            "model": self.model,
            "kappa_critical": json_number(self.kappa_critical),
            "omega_critical": self.omega_critical,
            "stable_set": self.stable_set_json(),
        }


@dataclass(frozen=True)
class HolonomicLoop(Characteristic):
    """The holonomic loop s² + (c_h·s + κ)e^(−sT) = 0: its parameters (everything but the gain κ).

    Parameters
    ----------
    T : float
        Loop delay / sampling period, s, in [0, 100] (``RANGES["T"]``); below `T_RESOLUTION` (10⁻¹² s) stored as 0.
    c_h : float
        Damping c_h = −∂F_x/∂v_x / m, 1/s, in [−10¹⁵, 10¹⁵] (``RANGES["c_h"]``).
        c_h <= 0 is accepted and unstable in every model.
    """

    T: float
    c_h: float

    def __post_init__(self):
        object.__setattr__(self, "T", check_parameter("T", self.T))
        if self.T < T_RESOLUTION:  # faster than a picosecond: a continuous controller, as `Loop`
            object.__setattr__(self, "T", 0.0)
        object.__setattr__(self, "c_h", check_parameter("c_h", self.c_h))

    @classmethod
    def of(cls, controller, *, c_h: float) -> "HolonomicLoop":
        """The loop of a controller (its T) at an equilibrium of damping c_h, 1/s: the one constructor from them.

        Parameters
        ----------
        controller : Controller
            The controller; its period / delay T, s, is the loop's.
        c_h : float, keyword only
            Damping of the equilibrium, 1/s.
        """
        return cls(controller.T, c_h)

    @property
    def family(self) -> LoopFamily:
        """`HOLONOMIC`."""
        return HOLONOMIC

    @property
    def plant(self) -> np.ndarray:
        """a(s) = s², descending."""
        return np.array([1.0, 0.0, 0.0])

    @property
    def damping(self) -> float:
        """δ = c_h, 1/s."""
        return self.c_h

    @property
    def closed_plant(self) -> np.ndarray:
        """s² + c_h s, descending."""
        return np.array([1.0, self.c_h, 0.0])

    def loop_gain(self, kappa: float) -> float:
        """K = κ, 1/s².

        Parameters
        ----------
        kappa : float
            Stiffness κ, 1/s².
        """
        return kappa

    def gain_of(self, K: float) -> float:
        """κ = K, 1/s².

        Parameters
        ----------
        K : float
            Loop gain K, 1/s².
        """
        return K

    def check_gain(self, kappa) -> float:
        """`check_kappa`.

        Parameters
        ----------
        kappa : float
            Stiffness κ, 1/s².
        """
        return check_kappa(kappa)

    def boundary_from(self, model: str, interval: StabilityInterval) -> HolonomicBoundary:
        """`HolonomicBoundary` in κ (= K).

        Parameters
        ----------
        model : str
            The model's name (`parameters.MODEL_NAMES`).
        interval : StabilityInterval
            The stable loop gains K = κ, 1/s², with K* and ω*.
        """
        return HolonomicBoundary(model, interval.gain, interval.frequency, tuple(interval.intervals))

    def with_delay(self, T: float) -> "HolonomicLoop":
        """c_h with delay / period T, s.

        Parameters
        ----------
        T : float
            Delay / sampling period, s, >= 0.
        """
        return replace(self, T=T)

    def _with_delay(self, T: float) -> "HolonomicLoop":
        """`with_delay` unchecked (a probe of T in range, `Characteristic._with_delay`); T < `T_RESOLUTION` is 0."""
        T = float(T)
        return _unchecked(HolonomicLoop, T=T if T >= T_RESOLUTION else 0.0, c_h=self.c_h)

    def with_damping(self, damping: float) -> "HolonomicLoop":
        """T with damping c_h = `damping`, 1/s.

        Parameters
        ----------
        damping : float
            Damping c_h, 1/s.
        """
        return replace(self, c_h=damping)

    def delay_search(self, kappa: float) -> tuple:
        """T* searched from 10⁻³ of the loop's time scale min(1/|c_h|, 1/√|κ|) to 1e-9 relative, however small T* is:
        a delay below `T_RESOLUTION` is T = 0, so T* >= 10⁻¹² s and the bracket's absolute floor, 10⁻⁹·10⁻¹² s,
        never decides first.

        Parameters
        ----------
        kappa : float
            Stiffness κ, 1/s².
        """
        scale = min(1.0 / abs(self.c_h), 1.0 / math.sqrt(abs(kappa)))
        return scale * 1e-3, _DELAY_RTOL, _DELAY_RTOL * T_RESOLUTION

    def state_space(self, hold: str) -> tuple:
        """(A, B, F0, F1) of the double integrator, states (v, x), the acceleration held: v_k = −(c_h v_k + κ x_k).

        Parameters
        ----------
        hold : str
            What the computer holds between samples; only ``"command"`` (the acceleration) applies.

        Raises
        ------
        ValueError
            ``hold="reference"``: a holonomic robot has no servo closing a held reference.
        """
        if hold != "command":
            raise ValueError(f"hold must be command for a holonomic loop (the acceleration command is held; no servo closes a reference); got {hold!r}")
        return np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[1.0], [0.0]]), np.array([self.c_h, 0.0]), np.array([0.0, 1.0])

    def delay_interval(self) -> StabilityInterval:
        """The stable κ of the exact delay loop: one interval (0, κ*), κ* = ω² cos ωT where ω sin ωT = c_h (module docstring)."""
        if self.T == 0:
            return Continuous().stable_gains(self)
        if self.c_h <= 0:
            return StabilityInterval(0.0, None, (), ())
        crossings = []
        if self.c_h * self.T < math.pi / 2:
            T, c = self.T, self.c_h
            w = bisect_root(lambda x: x * math.sin(x * T) - c, 0.0, math.pi / (2 * T), rtol=1e-15)
            crossings.append(Crossing(w * w * math.cos(w * T), w))
        return stable_interval(crossings, self.delay_stable)

    def delay_damping_range(self, kappa: float) -> tuple:
        """Every interval of c_h (1/s) stable at κ in the exact delay loop: one interval whose ends solve ω² cos ωT = κ on
        either side of the peak of ω² cos ωT, c_h = ω sin ωT there; ``()`` when κT² >= `BEST_CURVATURE_PRODUCT`.

        Parameters
        ----------
        kappa : float
            Stiffness κ, 1/s².
        """
        if self.T == 0:
            return Continuous().damping_range(kappa, self)
        T = self.T
        if kappa * T * T >= BEST_CURVATURE_PRODUCT:
            return ()
        g = lambda x: x * x * math.cos(x * T) - kappa
        # the second root near ωT = π/2 in v = π/2 − ωT: cos(ωT) = sin(v) keeps its digits where cos(π/2) rounds to 6e-17
        h = lambda v: ((0.5 * math.pi - v) / T) ** 2 * math.sin(v) - kappa
        v = bisect_root(h, 0.0, 0.5 * math.pi - _X0, rtol=1e-15)
        ends = [bisect_root(g, 0.0, _X0 / T, rtol=1e-15), (0.5 * math.pi - v) / T]
        crossings = [Crossing(w * math.sin(w * T), w) for w in ends]
        return stable_set(crossings, lambda c: self.with_damping(c).delay_stable(kappa))


def kinematic_loop(K_s, T, c=0.0) -> Loop:
    """KB's steering `Loop` of Ge & Cui 2002 §7's kinematic robot: τ = 0, k = K_s.

    ω = K_s(θ_f − θ) with no motor lag gives s² + K_s s + K_s(cs + NV)e^(−sT) = 0;
    every steering model (`continuous`, …, `sampled`) takes the result.

    Parameters
    ----------
    K_s : float
        Heading gain, 1/s, in ``RANGES["k"]``.
    T : float
        Delay / sampling period, s.
    c : float
        Heading gain of the field (`Loop.c`), dimensionless.
    """
    low, high = RANGES["k"].low, RANGES["k"].high
    K_s = check_number("K_s", K_s, low, high, low_open=False, high_open=False, unit="1/s")
    return Loop(0.0, T, K_s, c=c)


# ------------------------------------------------------------------ a model's verdict in κ
@dataclass(frozen=True)
class HolonomicVerdict:
    """One model's answer at one holonomic equilibrium: s² + (c_h s + κ)e^(−sT) (docs/models.md).

    Attributes
    ----------
    model : str
    kappa : float
        κ, 1/s².
    kappa_critical : float
        κ*, 1/s²: stable for 0 < κ < κ* (``inf``: every κ > 0; 0: none).
    omega_critical : float or None
        rad/s at κ*.
    margin : float
        κ_edge/κ − 1 (as the steering gain margin, docs/models.md): > 0 stable, < 0 unstable.
    verdict : str
        "stable", "unstable" or "undecided" (within 1e-9 of an edge of the stable set).
    T_critical : float
        T*, s: stable for every delay / period in [0, T*) (0: unstable already at T = 0).
    damping_range : tuple of (float, float)
        Every interval of c_h (1/s) that makes this κ stable at the loop's T.
    rightmost_root : complex or None
    """

    model: str
    kappa: float
    kappa_critical: float
    omega_critical: float | None
    margin: float
    verdict: str
    T_critical: float
    damping_range: tuple
    rightmost_root: complex | None

    @property
    def stable(self) -> bool:
        """True only when the verdict is "stable"."""
        return self.verdict == "stable"

    def to_dict(self, remedy: dict | None = None) -> dict:
        """The fields as a JSON-ready dict (SI units) with `remedy` (``to_stabilize``); κ* and T* are stable below.

        Parameters
        ----------
        remedy : dict, optional
            What would stabilize the loop (the report's ``to_stabilize``); None: no remedy key's value.
        """
        return {
            "stable": self.stable,
            "verdict": self.verdict,
            "kappa": self.kappa,
            "kappa_critical": json_number(self.kappa_critical),
            "margin": json_number(self.margin),
            "omega_critical": json_number(self.omega_critical),
            "rightmost_root": root_json(self.rightmost_root),
            "T_critical": json_number(self.T_critical),
            "damping_range": [[json_number(lo), json_number(hi)] for lo, hi in self.damping_range],
            "stable_side": {"kappa_critical": "below", "T_critical": "below"},  # stable for 0 < κ < κ*, for T in [0, T*)
            "to_stabilize": remedy or {},
        }


def holonomic_verdict(model: LoopModel, kappa: float, loop: HolonomicLoop) -> HolonomicVerdict:
    """`model`'s verdict at κ (1/s²) in the holonomic loop (T, c_h): κ*, the margin in κ, T*, the c_h range, the rightmost root.

    The margin and the verdict are the steering report's rules in κ (`models.interval_margin`,
    `models.interval_verdict`); κ < 0 (no restoring force) has margin −1 and, within 1e-9 of an
    edge of the stable set, the verdict is "undecided" with margin 0.

    Parameters
    ----------
    model : LoopModel
        The model judging the loop.
    kappa : float
        Stiffness κ, 1/s².
    loop : HolonomicLoop
        The holonomic loop (T, s; c_h, 1/s).
    """
    boundary = model.boundary(loop)
    stable = model.is_stable(kappa, loop)
    if kappa <= 0:
        margin, verdict = -1.0, "stable" if stable else "unstable"
    else:
        verdict = interval_verdict(kappa, boundary.stable_set, boundary.kappa_critical, stable)
        margin = 0.0 if verdict == "undecided" else interval_margin(kappa, boundary.stable_set, boundary.kappa_critical, stable)
    return HolonomicVerdict(model.name, kappa, boundary.kappa_critical, boundary.omega_critical, margin, verdict,
                            model.critical_delay(kappa, loop), model.damping_range(kappa, loop), model.rightmost_root(kappa, loop))
