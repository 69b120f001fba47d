"""How the loop models differ: NV* against the sampling period and the gain, KB's error, root loci.

NV*τ depends on the dimensionless kτ and T/τ only (substitute s = p/τ in KB
eq 18, or scale time in the sampled loop), so one map over (kτ, T/τ) shows,
for every robot, where KB's criterion (eq 20) is optimistic (NV*_KB >
NV*_model: KB calls stable a loop that oscillates) or conservative
(docs/models.md).

* `critical_gain_vs_delay`, `critical_gain_vs_k`: NV* of every model against
  T/τ or k (`GainCurves`, one `GainCurve` per model);
* `kb_error_map`, `kb_error_maps`: KB's relative error over (kτ, T/τ)
  (`KBErrorMap`); `kb_relative_error` for one loop (the stability report's
  figure);
* `root_locus`: the Padé loop's root locus in NV with every model's
  imaginary-axis crossing (`RootLocus`).

Computation only; `pfm_stability.plots.comparison` and `plots.rlocus` draw (each result's ``.plot()``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_number, check_positive_axis
from ..models import Continuous, ExactDelay, KBFirstOrder, Loop, LoopModel, Pade, Sampled
from ..parameters import SAMPLED_STRUCTURES, check_parameter
from ..io.serialize import json_array

__all__ = [
    "GainCurve",
    "GainCurves",
    "KBErrorMap",
    "RootLocus",
    "critical_gain_vs_delay",
    "critical_gain_vs_k",
    "kb_error_map",
    "kb_error_maps",
    "kb_relative_error",
    "relative_error",
    "root_locus",
]


@dataclass(frozen=True)
class GainCurve:
    """NV* of one model against one loop parameter.

    Attributes
    ----------
    model : LoopModel
    x_name, x_unit : str
        E.g. ``"T/tau"``, ``""``.
    x : ndarray
    NV_critical : ndarray
        NV*, 1/s (``inf``: no finite boundary; 0: unstable for every NV).
    tau, T, k : float or None
        The fixed loop parameters (s, s, 1/s); the varied one is None.
    """

    model: LoopModel
    x_name: str
    x_unit: str
    x: np.ndarray
    NV_critical: np.ndarray
    tau: float | None = None
    T: float | None = None
    k: float | None = None

    def __repr__(self) -> str:
        return f"GainCurve({self.model.name}{self.model.options() or ''}: NV* vs {self.x_name}, {len(self.x)} points)"

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "model": self.model.name,
            "options": self.model.options(),
            "x_name": self.x_name,
            "x_unit": self.x_unit,
            "x": json_array(self.x),
            "NV_critical": json_array(self.NV_critical),
            "tau": self.tau,
            "T": self.T,
            "k": self.k,
        }


class GainCurves(list):
    """Every model's `GainCurve` against one loop parameter (T/τ or k): what `critical_gain_vs_delay` and `critical_gain_vs_k` return."""

    def plot(self, ax=None, **kwargs):
        """`plots.comparison.plot_critical_gain_vs_delay` (x = T/τ) or `plots.rlocus.plot_critical_gain_vs_k` (x = k); returns the figure."""
        if self[0].x_name == "k":
            from ..plots.rlocus import plot_critical_gain_vs_k

            return plot_critical_gain_vs_k(self, ax=ax, **kwargs)
        from ..plots.comparison import plot_critical_gain_vs_delay

        return plot_critical_gain_vs_delay(self, ax=ax, **kwargs)


@dataclass(frozen=True)
class KBErrorMap:
    """How far KB's criterion (eq 20) is from another model, over (kτ, T/τ).

    Attributes
    ----------
    reference : LoopModel
        The model KB is compared with (usually ``sampled``).
    k_tau : ndarray, shape (nx,)
        Dimensionless steering gain kτ.
    T_over_tau : ndarray, shape (ny,)
        Dimensionless sampling period T/τ.
    NV_tau_kb : ndarray, shape (ny, nx)
        KB's NV*·τ = 1/(1 + T/τ) (eq 20).
    NV_tau_reference : ndarray, shape (ny, nx)
        The reference model's NV*·τ (0 where the loop is unstable for every
        NV > 0: the sampled steering loop alone is unstable).
    relative_error : ndarray, shape (ny, nx)
        NV*_KB/NV*_reference − 1: > 0 KB is optimistic (it calls stable a
        loop that oscillates), < 0 conservative; ``inf`` where NV*_reference = 0.
    """

    reference: LoopModel
    k_tau: np.ndarray
    T_over_tau: np.ndarray
    NV_tau_kb: np.ndarray
    NV_tau_reference: np.ndarray
    relative_error: np.ndarray

    @property
    def optimistic(self) -> np.ndarray:
        """True where KB's NV* exceeds the reference's (KB says stable, the loop oscillates)."""
        return self.relative_error > 0

    def at(self, k_tau: float, T_over_tau: float) -> float:
        """Relative error at one (kτ, T/τ), bilinear in (log kτ, log T/τ) between grid nodes.

        Parameters
        ----------
        k_tau : float
            Steering gain kτ (dimensionless), inside the map's range.
        T_over_tau : float
            Sampling period T/τ (dimensionless), inside the map's range.
        """
        from scipy.interpolate import RegularGridInterpolator

        values = np.where(np.isfinite(self.relative_error), self.relative_error, np.nan)
        f = RegularGridInterpolator((np.log(self.T_over_tau), np.log(self.k_tau)), values)
        return float(f([[math.log(T_over_tau), math.log(k_tau)]])[0])

    def exact(self, k_tau: float, T_over_tau: float) -> float:
        """Relative error at one (kτ, T/τ), computed exactly (`kb_relative_error` at τ = 1 s), not interpolated.

        Parameters
        ----------
        k_tau : float
            Steering gain kτ (dimensionless).
        T_over_tau : float
            Sampling period T/τ (dimensionless).
        """
        return kb_relative_error(Loop(1.0, float(T_over_tau), float(k_tau)), self.reference)

    def __repr__(self) -> str:
        e = self.relative_error[np.isfinite(self.relative_error)]
        return (
            f"KBErrorMap(vs {self.reference.name}{self.reference.options() or ''}: {self.relative_error.shape}, "
            f"KB optimistic on {100 * self.optimistic.mean():.0f} %, error {e.min():+.2f} … {e.max():+.2f})"
        )

    def plot(self, ax=None, **kwargs):
        """`plots.comparison.plot_kb_error_map` of this map; returns the figure."""
        from ..plots.comparison import plot_kb_error_map

        return plot_kb_error_map(self, ax=ax, **kwargs)

    def to_dict(self) -> dict:
        """Plain JSON types (arrays as lists, non-finite values as None)."""
        return {
            "reference": self.reference.name,
            "options": self.reference.options(),
            "k_tau": json_array(self.k_tau),
            "T_over_tau": json_array(self.T_over_tau),
            "NV_tau_kb": json_array(self.NV_tau_kb),
            "NV_tau_reference": json_array(self.NV_tau_reference),
            "relative_error": json_array(self.relative_error),
        }


def critical_gain_vs_delay(tau: float, k: float, T_over_tau=None, models=None, *, pade_order: int = 3) -> GainCurves:
    """NV* (1/s) of every model against the sampling period, T = (T/τ)·τ.

    Parameters
    ----------
    tau : float
        Steering time constant, s (> 0).
    k : float
        Steering gain, 1/s.
    T_over_tau : array_like, optional
        Sampling periods in units of τ (default 60 log-spaced values in [0.01, 3]).
    models : list of LoopModel, optional
        Default: continuous, kb_first_order, pade, exact_delay and ``sampled``
        in all four structures (`SAMPLED_STRUCTURES`).
    pade_order : int
        Order m of the ``pade`` model.

    Returns
    -------
    GainCurves
        x = T/τ (dimensionless).
    """
    tau = check_number("tau", tau, 0.0, unit="s")
    k = check_parameter("k", k)
    x = check_positive_axis("T_over_tau", np.geomspace(0.01, 3.0, 60) if T_over_tau is None else T_over_tau)
    models = _all_models(pade_order) if models is None else models
    curves = GainCurves()
    for model in models:
        values = np.array([model.boundary(Loop(tau, float(r) * tau, k)).NV_critical for r in x])
        curves.append(GainCurve(model, "T/tau", "", x, values, tau=tau, k=k))
    return curves


def kb_error_map(k_tau, T_over_tau, reference: LoopModel | None = None) -> KBErrorMap:
    """NV*_KB/NV*_reference − 1 over (kτ, T/τ): where KB's eq (20) is optimistic (> 0) or conservative (< 0).

    NV*τ is a function of kτ and T/τ only (time scaled by τ), so the map
    holds for every τ; it is computed at τ = 1 s.

    Parameters
    ----------
    k_tau : array_like, shape (nx,)
        Dimensionless steering gains kτ.
    T_over_tau : array_like, shape (ny,)
        Dimensionless sampling periods T/τ.
    reference : LoopModel, optional
        Default ``Sampled("command", 1)`` (CARMEL's structure).

    Returns
    -------
    KBErrorMap
    """
    kx = check_positive_axis("k_tau", k_tau)
    ty = check_positive_axis("T_over_tau", T_over_tau)
    reference = Sampled("command", 1) if reference is None else reference
    ref = np.array([[reference.boundary(Loop(1.0, float(t), float(k))).NV_critical for k in kx] for t in ty])
    kb = np.broadcast_to(1.0 / (1.0 + ty[:, None]), ref.shape).copy()
    with np.errstate(divide="ignore"):
        err = np.where(ref > 0, kb / np.where(ref > 0, ref, 1.0) - 1.0, np.inf)
    return KBErrorMap(reference, kx, ty, kb, ref, err)


def kb_error_maps(k_tau, T_over_tau, structures=SAMPLED_STRUCTURES) -> list[KBErrorMap]:
    """`kb_error_map` against ``sampled`` for each (hold, compute_delay).

    Parameters
    ----------
    k_tau : array_like, shape (nx,)
        Dimensionless steering gains kτ.
    T_over_tau : array_like, shape (ny,)
        Dimensionless sampling periods T/τ.
    structures : sequence of (str, int)
        The (hold, compute_delay) pairs of the ``sampled`` references.
    """
    return [kb_error_map(k_tau, T_over_tau, Sampled(h, c)) for h, c in structures]


def kb_relative_error(loop: Loop, reference: LoopModel) -> float:
    """NV*_KB/NV*_reference − 1 for one loop (`relative_error`: > 0 KB's eq 20 optimistic; ``inf`` if NV*_reference = 0).

    Parameters
    ----------
    loop : Loop
        τ (s), T (s), k (1/s).
    reference : LoopModel
        The model KB's eq (20) is compared with.
    """
    return relative_error(KBFirstOrder().boundary(loop).NV_critical, reference.boundary(loop).NV_critical)


def relative_error(NV_kb: float, NV_reference: float) -> float:
    """NV*_KB/NV*_reference − 1: > 0 KB's eq (20) is optimistic, < 0 conservative.

    ``inf`` when the reference is unstable at every NV (NV*_reference = 0);
    ``nan`` when both are stable at every NV (no finite boundary to compare).

    Parameters
    ----------
    NV_kb : float
        KB's NV* (eq 20), 1/s.
    NV_reference : float
        The reference model's NV*, 1/s (``inf``: stable at every NV).
    """
    if NV_reference == 0:
        return math.inf
    if math.isinf(NV_reference) and math.isinf(NV_kb):
        return math.nan
    return NV_kb / NV_reference - 1.0


def _all_models(pade_order: int) -> list[LoopModel]:
    """continuous, kb_first_order, pade, exact_delay, and ``sampled`` in every structure."""
    return [Continuous(), KBFirstOrder(), Pade(pade_order), ExactDelay()] + [Sampled(h, c) for h, c in SAMPLED_STRUCTURES]


def critical_gain_vs_k(tau: float, T: float, ks=None, *, pade_order: int = 3, models=None) -> GainCurves:
    """NV* (1/s) of every model against the steering gain k (1/s), τ and T fixed.

    KB's eq (20) says NV* does not depend on k; only ``continuous`` and
    ``kb_first_order`` bear that out.

    Parameters
    ----------
    tau, T : float
        Steering time constant and sampling period, s.
    ks : array_like, optional
        Steering gains, 1/s (default 60 log-spaced values in [0.2, 30]).
    pade_order : int
        Order m of the ``pade`` model.
    models : list of LoopModel, optional
        Default: every model and every sampled structure.

    Returns
    -------
    GainCurves
        x = k (1/s).
    """
    tau = check_number("tau", tau, 0.0, unit="s")
    T = check_number("T", T, 0.0, unit="s")
    ks = check_positive_axis("k", np.geomspace(0.2, 30, 60) if ks is None else ks, "1/s")
    models = _all_models(pade_order) if models is None else models
    return GainCurves(
        GainCurve(model, "k", "1/s", ks, np.array([model.boundary(Loop(tau, T, float(k))).NV_critical for k in ks]), tau=tau, T=T)
        for model in models
    )


@dataclass(frozen=True)
class RootLocus:
    """The Padé loop's closed-loop roots as NV grows, and every model's boundary crossing.

    Attributes
    ----------
    loop : Loop
    pade_order : int
    gains : ndarray
        NV values, 1/s.
    loci : ndarray, complex, shape (len(gains), branches)
        Root positions, 1/s.
    poles, zeros : ndarray, complex
        Open-loop poles and zeros of k·P_m(s)/((τs³ + s² + ks)·Q_m(s)).
    crossings : tuple of (LoopModel, Boundary)
        ``pade``, ``exact_delay``, ``kb_first_order`` and ``sampled`` with
        their boundaries (NV*, ω*, stable set).
    omega_scale : float
        ω* of ``exact_delay`` (1 rad/s when it has none): the scale of the view.
    """

    loop: Loop
    pade_order: int
    gains: np.ndarray
    loci: np.ndarray
    poles: np.ndarray
    zeros: np.ndarray
    crossings: tuple
    omega_scale: float

    def plot(self, ax=None):
        """`plots.rlocus.plot_root_locus` of this locus; returns the figure."""
        from ..plots.rlocus import plot_root_locus

        return plot_root_locus(self, ax=ax)


def root_locus(loop: Loop, *, pade_order: int = 3, hold: str = "command", compute_delay: int = 0, NV_max: float | None = None,
               points: int = 400) -> RootLocus:
    """Closed-loop roots of the Padé loop for NV in [0, NV_max], with the models' crossings.

    The loop transfer function in the gain NV is G(s) = k·P_m(s)/((τs³ + s² + ks)·Q_m(s))
    (KB eq 18 with e^(−sT) ≈ P_m/Q_m), mapped by python-control's
    ``root_locus_map``.

    Parameters
    ----------
    loop : Loop
        τ (s), T (s, > 0), k (1/s).
    pade_order : int
        Order m of the Padé approximation of e^(−sT).
    hold, compute_delay
        Structure of the ``sampled`` model whose crossing is included.
    NV_max : float, optional
        Largest loop gain, 1/s (default 2.5·NV* of ``exact_delay``).
    points : int
        Gains on the locus.

    Returns
    -------
    RootLocus
    """
    import control

    d, e = Pade(pade_order).polynomials(loop)
    G = control.tf(loop.steering_gain * np.asarray(e), d)  # g·k: the loop's steering gain (k for KB's robot)
    exact = ExactDelay().boundary(loop)
    if NV_max is None:
        NV_max = 2.5 * exact.NV_critical
    data = control.root_locus_map(G, gains=np.linspace(0.0, NV_max, points))
    models = (Pade(pade_order), ExactDelay(), KBFirstOrder(), Sampled(hold, compute_delay))
    return RootLocus(
        loop,
        pade_order,
        np.asarray(data.gains),
        np.asarray(data.loci),
        np.asarray(G.poles()),
        np.asarray(G.zeros()),
        tuple((m, m.boundary(loop)) for m in models),
        exact.omega_critical or 1.0,
    )
