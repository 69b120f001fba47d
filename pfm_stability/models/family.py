"""The shape every robot family's loop shares, a(s) + (δ·s + K)·e^(−sT) = 0, and how a family is named (docs/models.md).

`Characteristic` is what the five models (`continuous`, `kb_first_order`, `pade`,
`exact_delay`, `sampled`) read from the loop they judge, so that one implementation of
each decides every family: KB's steering robot (`models.loop.Loop`: a(s) = τs³ + s² + ks,
δ = kc, K = kNV; kinematic steering is τ = 0) and the holonomic robot
(`models.holonomic.HolonomicLoop`: a(s) = s², δ = c_h, K = κ). `LoopFamily` names a
family's gain and the equation each model solves for it; `StableSet` and `root_json` are
what every family's results share (a stable set of the gain, a rightmost root).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..io.serialize import json_number
from ..numerics.crossings import StabilityInterval

__all__ = ["LoopFamily", "Characteristic", "StableSet", "root_json"]


@dataclass(frozen=True)
class LoopFamily:
    """How one robot family's loop is named: its gain and the equation each model solves (docs/models.md).

    Attributes
    ----------
    name : str
        ``"steering"`` (KB's robot; kinematic steering is its τ = 0) or ``"holonomic"``.
    gain : str
        The loop gain the models take: ``"NV"`` (1/s) or ``"kappa"`` (1/s²).
    equations : dict
        Model name (`parameters.MODEL_NAMES`) → the characteristic equation it solves, as text.
    options : tuple of str
        The model options that configure this family's loop (`LoopModel.options`): a holonomic
        robot holds its acceleration command, so its ``sampled`` model shows no ``hold``.
    """

    name: str
    gain: str
    equations: dict
    options: tuple

    def describe(self, model) -> dict:
        """``{"equation": …, **options}``: `model` as a report lists it for this family.

        Parameters
        ----------
        model : LoopModel
            The model described (its ``name`` and `LoopModel.options`).
        """
        return {"equation": self.equations[model.name], **{k: v for k, v in model.options().items() if k in self.options}}


class Characteristic:
    """One loop of one robot family: a(s) + (δ·s + K)·e^(−sT) = 0 (docs/models.md, "Robot loop families").

    What every model reads from the loop it judges, so that one implementation of
    each model decides every family: the plant a(s) (`plant`, a(0) = 0), the
    delayed rate term δ·s (`damping`), the delay or period T, the loop gain K a
    user's gain makes (`loop_gain`), and the family's own answers where a model
    needs them (`delay_interval`, `state_space`, `delay_search`). Subclasses:
    `Loop` (KB's steering robot) and `models.holonomic.HolonomicLoop`.
    """

    family: LoopFamily
    T: float
    dead_time: float = 0.0
    """D, s: the plant's dead time beyond T (`models.loop.Loop.dead_time`; 0 for a family without one)."""

    @property
    def delay(self) -> float:
        """T + D, s: the delay the continuous-time models (`kb_first_order`, `pade`, `exact_delay`) take
        (docs/models.md, "Plant gain and dead time"); T itself when D = 0."""
        return self.T + self.dead_time if self.dead_time else self.T

    def period_margin(self, margin: float) -> float:
        """T*, s, from the margin of the whole delay T + D: max(margin − D, 0) (the margin itself when D = 0).

        Parameters
        ----------
        margin : float
            The largest stable delay T + D (its first crossing), s; ``inf`` stays ``inf``.
        """
        if not self.dead_time or math.isinf(margin):
            return margin
        return max(margin - self.dead_time, 0.0)

    @property
    def plant(self) -> np.ndarray:  # pragma: no cover - interface
        """a(s), descending, with a(0) = 0."""
        raise NotImplementedError

    @property
    def damping(self) -> float:  # pragma: no cover - interface
        """δ: the s-coefficient of the delayed term δ·s + K."""
        raise NotImplementedError

    @property
    def closed_plant(self) -> np.ndarray:  # pragma: no cover - interface
        """a(s) + δ·s, descending: the loop without delay and without K."""
        raise NotImplementedError

    @property
    def delayed(self) -> np.ndarray | None:
        """d(s) = δ·s, descending; None when δ = 0 (the delayed term is K alone)."""
        return np.array([self.damping, 0.0]) if self.damping != 0.0 else None

    def loop_gain(self, gain: float) -> float:  # pragma: no cover - interface
        """K, 1/s², for the family's gain (NV or κ).

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        """
        raise NotImplementedError

    def gain_of(self, K: float) -> float:  # pragma: no cover - interface
        """The family's gain for a loop gain K (the inverse of `loop_gain`).

        Parameters
        ----------
        K : float
            Loop gain K, 1/s².
        """
        raise NotImplementedError

    def check_gain(self, gain) -> float:  # pragma: no cover - interface
        """The family's gain as a float, or ValueError naming it.

        Parameters
        ----------
        gain : float
            The family's loop gain as the user gave it: NV (1/s) or κ (1/s²).
        """
        raise NotImplementedError

    def boundary_from(self, model: str, interval: StabilityInterval):  # pragma: no cover - interface
        """The family's boundary (`Boundary` in NV, `HolonomicBoundary` in κ) from a stable interval in K.

        Parameters
        ----------
        model : str
            The model's name (`parameters.MODEL_NAMES`).
        interval : StabilityInterval
            The stable loop gains K, 1/s², with K* and ω*.
        """
        raise NotImplementedError

    def with_delay(self, T: float) -> "Characteristic":  # pragma: no cover - interface
        """The same loop with delay / period T, s.

        Parameters
        ----------
        T : float
            Delay / sampling period, s, >= 0.
        """
        raise NotImplementedError

    def delay_search(self, gain: float) -> tuple:  # pragma: no cover - interface
        """(first T, relative tolerance, absolute tolerance) of the searched T* (`LoopModel.critical_delay`), s.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        """
        raise NotImplementedError

    def state_space(self, hold: str) -> tuple:  # pragma: no cover - interface
        """(A, B, F0, F1) of the sampled loop: ẋ = Ax + Bv between samples, v_k = −(F0 + K·F1)·x_k, lateral state last.

        Parameters
        ----------
        hold : str
            What the computer holds between samples: ``"command"`` or ``"reference"`` (`parameters.HOLDS`).
        """
        raise NotImplementedError

    def _with_delay(self, T: float) -> "Characteristic":
        """`with_delay` for an internal probe of this (checked) loop at a T a search keeps in range (a family may
        skip the checks: `Loop`, `HolonomicLoop`)."""
        return self.with_delay(T)

    def _state_space(self, hold: str) -> tuple:
        """`state_space` for a `hold` already checked (a model's own, `Sampled.hold`): a family may skip the check."""
        return self.state_space(hold)

    def delay_interval(self) -> StabilityInterval:  # pragma: no cover - interface
        """The stable gains K of the exact delay loop (every interval, K*, ω*), from the family's crossing structure."""
        raise NotImplementedError

    def quasi_polynomial(self):
        """a(s) + (δ·s + K)·e^(−sT) as a `delay.DelayLoop` (δ = 0: a(s) + K·e^(−sT))."""
        from ..numerics.delay import DelayLoop

        delayed = self.delayed
        return DelayLoop(self.plant, self.delay) if delayed is None else DelayLoop(self.plant, self.delay, delayed=delayed)

    def delay_stable(self, K: float) -> bool:
        """The exact delay loop's verdict at K: the crossing count (`DelayLoop.is_stable`).

        Parameters
        ----------
        K : float
            Loop gain K, 1/s².
        """
        return self.quasi_polynomial().is_stable(K)

    def delay_margin(self, K: float) -> float:
        """The exact delay loop's T* at K, s (`DelayLoop.delay_margin`).

        Parameters
        ----------
        K : float
            Loop gain K, 1/s².
        """
        return float(self.quasi_polynomial().delay_margin(K))

    def with_damping(self, damping: float) -> "Characteristic":
        """The same loop with δ = `damping` (a family whose δ is a parameter of its own: the holonomic c_h).

        Parameters
        ----------
        damping : float
            The damping δ of the delayed term δ·s, 1/s.
        """
        raise ValueError(f"damping_range applies to a holonomic loop (its damping c_h); got {self!r}")

    def delay_damping_range(self, K: float) -> tuple:
        """The exact delay loop's stable intervals of δ at K (a family whose δ is a parameter of its own).

        Parameters
        ----------
        K : float
            Loop gain K, 1/s².
        """
        raise ValueError(f"damping_range applies to a holonomic loop (its damping c_h); got {self!r}")


class StableSet:
    """What a boundary in any family's gain offers beside its critical value: its stable set (`stable_set`, ascending
    intervals of the gain), membership and JSON. Mixed into `models.base.Boundary` and `models.holonomic.HolonomicBoundary`."""

    stable_set: tuple

    def contains(self, gain: float) -> bool:
        """True when the gain lies strictly inside a stable interval.

        Parameters
        ----------
        gain : float
            The family's loop gain: NV (1/s) or κ (1/s²).
        """
        return any(lo < gain < hi for lo, hi in self.stable_set)

    def stable_set_json(self) -> list:
        """The stable set as JSON: [[lo, hi], …] (``"inf"`` for an unbounded end)."""
        return [[json_number(lo), json_number(hi)] for lo, hi in self.stable_set]


def _unchecked(cls, **fields):
    """An instance of the frozen dataclass `cls` with `fields` set as given, without its ``__post_init__`` checks.

    For a loop's internal probes only (`Characteristic._with_delay`, a k or T search): copies of an
    already-checked loop whose changed value the search keeps inside its range: re-checking every
    probe would only repeat the check of the public entry that made the loop.
    """
    obj = object.__new__(cls)
    for name, value in fields.items():
        object.__setattr__(obj, name, value)
    return obj


def root_json(root: complex | None) -> dict:
    """A model's rightmost root (`LoopModel.rightmost_root`) as JSON: {"sigma": 1/s, "omega": rad/s >= 0}; nulls when the
    model could not resolve it (None).

    Parameters
    ----------
    root : complex or None
        σ + jω, 1/s and rad/s; None when the model could not resolve it.
    """
    return {"sigma": json_number(root.real), "omega": json_number(abs(root.imag))} if root is not None else {"sigma": None, "omega": None}
