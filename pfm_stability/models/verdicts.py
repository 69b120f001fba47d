"""The one rule that turns a model's answers into a verdict, for a single loop gain and for arrays of them.

A loop model answers two things about a loop gain G (NV of a steering robot, κ of
a holonomic one): whether G is stable, by its own independent test (Routh,
Schur–Cohn, a crossing count), and its boundary — the stable set of G and the
critical value G* (docs/models.md, "Verdicts and margins"). Everything a user
reads follows from those by this module, in one place:

* the **verdict**: "stable" or "unstable", or "undecided" within `UNDECIDED_RTOL`
  of an edge of the stable set (`interval_verdict`, `verdict_label`);
* the **margin**: the relative distance to the nearest edge, G_edge/G − 1
  (`interval_margin`, `gain_margin`); ``inf`` or −1 at G = 0;
* the **gain limits**: N < 0 diverges in every model (`divergent_reason`; margin −1,
  V* = 0, no T or k helps); N = 0 leaves the lateral mode neutral and each model
  judges its heading loop (`neutral_reason`); a gain beyond `NV_MAX` is not one the
  models represent (`check_loop_gain`, `beyond_reason`);
* the **critical speed** V* = NV*/N (`critical_speed`).

`judge` is the scalar form (the report's criteria and the map's samples),
`judge_arrays` the array form (sweeps, vectorized verdicts); both give the same
answers (tests/test_verdict_rule.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
import numpy as np

from .family import StableSet

__all__ = [
    "UNDECIDED_RTOL",
    "NV_MAX",
    "DIVERGENT_REASON",
    "NEUTRAL_REASON",
    "divergent_reason",
    "neutral_reason",
    "beyond_reason",
    "check_loop_gain",
    "interval_verdict",
    "interval_margin",
    "verdict_label",
    "gain_margin",
    "critical_speed",
    "in_stable_set",
    "inside",
    "Judgement",
    "judge",
    "judge_arrays",
]

NV_MAX = 1e12
"""Largest loop gain NV (1/s) a model accepts: beyond it the root finders leave floating point."""

UNDECIDED_RTOL = 1e-9
"""|NV/NV* − 1| below this is reported as "undecided" (on the boundary)."""


DIVERGENT_REASON = (
    "N < 0: this equilibrium is unstable in the field itself (the lateral force pushes away from it); "
    "k*N*V < 0 gives a positive real root in every model, at every speed, delay and gain"
)
"""Why every model says "unstable" for NV < 0 (`divergent_reason`)."""


NEUTRAL_REASON = "N = 0: the lateral mode is neutral (no restoring force); the verdict is the heading loop's"
"""Why a verdict at NV = 0 is the heading loop's, when it is not told which (`neutral_reason`; a sweep's reason column)."""

_NEUTRAL_REASONS = {
    True: "N = 0: the lateral mode is neutral (no restoring force); the heading loop is stable",
    False: "N = 0: the lateral mode is neutral (no restoring force) and the heading loop is unstable by itself",
}


def neutral_reason(NV: float, stable: bool | None = None) -> str | None:
    """Why the verdict at NV = 0 is what it is; None for NV != 0.

    At N = 0 the field exerts no restoring force: the characteristic
    function of every model is s·D1(s) (a root at z = 1 for `sampled`),
    and the lateral root stays at s = 0 whatever V, T, k and c are — the
    robot drifts sideways, it does not oscillate. Every model then judges
    the other roots, D1 — the heading loop: τs² + s + k(1 + c) for
    `continuous`, τs² + s + k + kc·e^(−sT) for `exact_delay`, the sampled
    loop without its lateral state (the whole command k(δ − θ) held can
    make it unstable even with c = 0). `is_stable` is the heading loop's
    verdict, `rightmost_root` its dominant root, `critical_delay` and
    `critical_gain_k` its T* and k*; the margin is ``inf`` when it is
    stable and −1 when it is not (`interval_margin`), never "undecided".

    Parameters
    ----------
    NV : float
        Loop gain, 1/s.
    stable : bool, optional
        The model's verdict at NV = 0 (`LoopModel.is_stable`); None:
        `NEUTRAL_REASON`, which does not say it (several models in one row).
    """
    if NV != 0:
        return None
    return NEUTRAL_REASON if stable is None else _NEUTRAL_REASONS[bool(stable)]



def divergent_reason(NV: float) -> str | None:
    """`DIVERGENT_REASON` when NV < 0, else None.

    With N < 0 the field pushes the robot away from its equilibrium: the
    characteristic function of every model is kNV < 0 at s = 0 (z = 1 for
    `sampled`) and positive for large real s (z), so it has a real root
    s > 0 (a real pole z > 1) whatever V, T, k and c are (the one exception,
    `kb_first_order` with τ = 0 and kcT > 1, has coefficients of both signs
    and is unstable at every NV anyway). Every model's `is_stable` is then
    False, `critical_delay` and `critical_gain_k` are 0 (no T and no k
    helps), `rightmost_root` is that real root (or an oscillating pair
    further right, in a loop unstable at every NV anyway), `gain_margin` is
    −1 and `verdict_label` "unstable". A verdict can show this string as the
    reason (docs/models.md, "N < 0").

    Parameters
    ----------
    NV : float
        Loop gain N·V, 1/s.
    """
    return DIVERGENT_REASON if NV < 0 else None



def _edges(stable_set, critical: float):
    """Finite positive edges of the stable set (the critical value alone if the set is unknown)."""
    if stable_set:
        return [x for pair in stable_set for x in pair if 0 < x < math.inf]
    return [critical] if 0 < critical < math.inf else []


def interval_verdict(gain: float, stable_set, critical: float, stable: bool, rtol: float = UNDECIDED_RTOL) -> str:
    """"stable", "unstable" or "undecided" (within `rtol` of an edge of `stable_set`) for any loop gain (NV, κ).

    Parameters
    ----------
    gain : float
        The loop gain: NV (1/s) or κ (1/s²).
    stable_set : sequence of (float, float)
        Stable intervals of the gain, ascending; empty: only `critical` is an edge.
    critical : float
        The critical gain (NV* or κ*).
    stable : bool
        The model's own verdict at the gain.
    rtol : float, optional
        Relative distance to an edge reported as "undecided"; default `UNDECIDED_RTOL`.
    """
    if any(abs(gain / edge - 1.0) <= rtol for edge in _edges(stable_set, critical)):
        return "undecided"
    return "stable" if stable else "unstable"


def interval_margin(gain: float, stable_set, critical: float, stable: bool) -> float:
    """Relative distance to the nearest boundary below or above, gain_edge/gain − 1, for any loop gain (NV, κ).

    Stable: the edge is the upper end of the stable interval that holds the
    gain (``inf`` if unbounded), so the margin is how much the gain may grow.
    Unstable: the upper end of the nearest stable interval below, so the
    (negative) margin is how much it must shrink; −1 when no smaller gain is
    stable. With the usual stable set (0, critical) both are critical/gain − 1.

    Gain 0 (N = 0, `neutral_reason`): ``inf`` when stable, −1 when not — the
    limits of critical/gain − 1 as the gain → 0+ (no gain below 0 exists).

    Parameters
    ----------
    gain : float
        The loop gain: NV (1/s) or κ (1/s²).
    stable_set : sequence of (float, float)
        Stable intervals of the gain, ascending; empty: (0, `critical`) is assumed.
    critical : float
        The critical gain (NV* or κ*).
    stable : bool
        The model's own verdict at the gain.
    """
    if gain == 0:
        return math.inf if stable else -1.0
    intervals = stable_set or (((0.0, critical),) if critical > 0 else ())
    if stable:
        holding = [hi for lo, hi in intervals if lo <= gain <= hi]
        edge = holding[0] if holding else critical
    else:
        below = [hi for lo, hi in intervals if hi <= gain * (1 + UNDECIDED_RTOL)]
        edge = max(below) if below else 0.0
    return edge / gain - 1.0


def verdict_label(NV: float, boundary: StableSet, stable: bool, rtol: float = UNDECIDED_RTOL) -> str:
    """"stable", "unstable" or "undecided" (within `rtol` of an edge of the stable set): `interval_verdict` in NV.

    Parameters
    ----------
    NV : float
        Loop gain N·V, 1/s.
    boundary : Boundary
        The model's boundary for the loop (`LoopModel.boundary`).
    stable : bool
        The model's own verdict at NV.
    rtol : float, optional
        Relative distance to an edge reported as "undecided"; default `UNDECIDED_RTOL`.
    """
    return interval_verdict(NV, boundary.stable_set, boundary.NV_critical, stable, rtol)


def gain_margin(NV: float, boundary: StableSet, stable: bool) -> float:
    """NV_edge/NV − 1 (`interval_margin` in NV): with the usual stable set (0, NV*), NV*/NV − 1.

    Parameters
    ----------
    NV : float
        Loop gain N·V, 1/s.
    boundary : Boundary
        The model's boundary for the loop (`LoopModel.boundary`).
    stable : bool
        The model's own verdict at NV.
    """
    return interval_margin(NV, boundary.stable_set, boundary.NV_critical, stable)


def beyond_reason(NV: float, where: str | None = None) -> str:
    """Why a loop gain beyond `NV_MAX` (or not finite) gets no verdict; `where` names the geometry (the report's message).

    Parameters
    ----------
    NV : float
        Loop gain N·V, 1/s.
    where : str, optional
        The geometry the gain belongs to (e.g. "wall"); None: not named.
    """
    at = f" at the {where}" if where else ""
    return (f"N*V = {NV:g} 1/s{at} exceeds what the loop models represent (<= {NV_MAX:g} 1/s); "
            f"choose a less extreme force law (f, n), angle or width")


def check_loop_gain(NV: float, where: str) -> float:
    """NV after checking it is finite and |NV| <= `NV_MAX`; otherwise ValueError (`beyond_reason`, naming the geometry).

    Parameters
    ----------
    NV : float
        Loop gain N·V, 1/s.
    where : str
        The geometry the gain belongs to, named in the error.
    """
    if not (math.isfinite(NV) and abs(NV) <= NV_MAX):
        raise ValueError(beyond_reason(NV, where))
    return NV


def critical_speed(N: float, NV_critical: float, stable: bool) -> float:
    """V* = NV*/N, m/s, for a gain N (1/m): 0 when N < 0 (no speed helps); at N = 0 ``inf`` when the heading loop
    is `stable` and 0 when not (NV = 0 at every speed).

    Parameters
    ----------
    N : float
        Environment gain, 1/m.
    NV_critical : float
        Critical loop gain NV*, 1/s.
    stable : bool
        The model's verdict (used at N = 0: the heading loop's).
    """
    if N > 0:
        return NV_critical / N
    return math.inf if N == 0 and stable else 0.0


def in_stable_set(stable_set, NV) -> np.ndarray:
    """True where NV lies strictly inside one of the intervals (`Boundary.contains` for arrays), shaped like `NV`.

    Parameters
    ----------
    stable_set : sequence of (float, float)
        NV intervals (lo, hi), 1/s (`Boundary.stable_set`); empty: (0, NV*) is not known, nothing is inside.
    NV : array_like
        Loop gains, 1/s.
    """
    NV = np.asarray(NV, dtype=float)
    stable = np.zeros(NV.shape, dtype=bool)
    for lo, hi in stable_set:
        stable |= (NV > lo) & (NV < hi)
    return stable


def inside(boundary, NV: float) -> bool:
    """NV strictly inside the boundary's stable set, or in (0, NV*) when the boundary has no set.

    Parameters
    ----------
    boundary : Boundary
        The model's boundary for the loop (`LoopModel.boundary`).
    NV : float
        Loop gain N·V, 1/s.
    """
    if boundary.stable_set:
        return boundary.contains(NV)
    return 0 < NV < boundary.NV_critical


@dataclass(frozen=True)
class Judgement:
    """The verdict of one loop gain (`judge`).

    Attributes
    ----------
    stable : bool
        The model's own test (False for N < 0).
    verdict : str
        "stable", "unstable" or "undecided".
    margin : float
        NV_edge/NV − 1 (`interval_margin`); −1 for N < 0.
    V_critical : float
        V*, m/s (`critical_speed`).
    reason : str or None
        Why the verdict is what it is when the loop gain is not a regular one
        (N < 0: `DIVERGENT_REASON`; N = 0: `neutral_reason`), else None.
    """

    stable: bool
    verdict: str
    margin: float
    V_critical: float
    reason: str | None


def judge(NV: float, N: float, boundary, stable) -> Judgement:
    """The verdict, margin, V* and reason of the loop gain NV (1/s), of environment gain N (1/m), for one model's `boundary`.

    Parameters
    ----------
    NV : float
        Loop gain N·V, 1/s.
    N : float
        Environment gain, 1/m (V* = NV*/N).
    boundary : Boundary
        The model's boundary for the loop (`LoopModel.boundary`).
    stable : bool or callable
        The model's own verdict at NV, or ``stable(NV) -> bool`` (called only where
        needed: never for N < 0).

    Returns
    -------
    Judgement
    """
    if N < 0:
        return Judgement(False, "unstable", -1.0, 0.0, DIVERGENT_REASON)
    stable = bool(stable(NV) if callable(stable) else stable)
    return Judgement(stable, verdict_label(NV, boundary, stable), gain_margin(NV, boundary, stable),
                     critical_speed(N, boundary.NV_critical, stable), neutral_reason(NV, stable))


def judge_arrays(NV, NV_critical, stable):
    """(verdict, margin) of loop gains NV whose stable set is (0, NV*) (or empty), in arrays: `verdict_label` and
    `gain_margin` elementwise, with NV = 0 giving margin ``inf`` or −1 and NV < 0 "unstable", −1.

    Parameters
    ----------
    NV, NV_critical : ndarray of float
        Loop gains and their models' NV*, 1/s.
    stable : ndarray of bool
        The models' own verdicts at NV.

    Returns
    -------
    verdict : ndarray of str
    margin : ndarray of float
    """
    NV, NV_critical, stable = np.asarray(NV, float), np.asarray(NV_critical, float), np.asarray(stable, bool)
    edge = (NV_critical > 0) & np.isfinite(NV_critical)
    with np.errstate(divide="ignore", invalid="ignore"):
        undecided = edge & (np.abs(NV / np.where(edge, NV_critical, 1.0) - 1.0) <= UNDECIDED_RTOL)
        verdict = np.where(undecided, "undecided", np.where(stable, "stable", "unstable"))
        below = (NV_critical > 0) & (NV_critical <= NV * (1 + UNDECIDED_RTOL))
        margin = np.where(stable | below, NV_critical, 0.0) / NV - 1.0
    zero, negative = NV == 0, NV < 0
    margin[zero] = np.where(stable[zero], np.inf, -1.0)
    verdict[negative], margin[negative] = "unstable", -1.0
    return verdict, margin
