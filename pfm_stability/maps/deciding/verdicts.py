"""A segment's verdict from its mean growth rate: the lateral deviation grows by exp(∫σ(N(s)·V) ds/V).

Along a segment, N (1/m) is known at samples every ~cell (`equilibria.Samples`). It is
not uniform: near a segment's end, a gap or a post a single sample's N may be ten times
the segment's median, or negative. At speed V the robot spends ds/V on each piece ds
of the path, and while there its lateral deviation grows (or decays) at the chosen
model's rightmost-root real part σ(N(s)·V) (1/s; for a fixed loop (τ, T, k, c), σ
depends only on NV). Over the judged part the deviation changes by

    exp(∫ σ(N(s)·V) ds / V) = exp(σ̄ · duration),   σ̄ = mean over the samples of σ(N_i·V),

the slowly varying (WKB) reading of a modulated linear loop, and what the simulation
measures (`validation.maps`: the growth rate of the free response over the run). So a
travel direction is decided by the sign of its **mean growth rate** σ̄ (`mean_growth`,
over the samples with an equilibrium: a gap is not a gain):

* N_eff is the uniform gain with the same growth, σ(N_eff·V) = σ̄ (`effective_gain`),
  so the margin NV*/(N_eff·V) − 1 keeps its meaning. σ is not one-to-one on (0, NV*)
  (a small gain's real root decays slowly, the most damped gain lies in between), so
  for σ̄ < 0 N_eff is taken on the branch holding the samples' mean N·V (a window whose gain varies can
  decay faster than any uniform gain does: N_eff is then the most damped gain); for σ̄ >= 0 it
  is the gain above NV* — or, when the samples' mean N is negative (the field pushes
  the robot off the line on average), the negative gain with that divergence: unstable
  at any speed, V* = 0, margin −1 (docs/models.md, "N < 0").
* V* is the smallest speed with σ̄(V) = 0 (`critical_speed`). σ̄(V) ≈ −V·mean(N) at
  small V, so V* = 0 when the mean N is negative; otherwise V* is the first sign change
  of σ̄ on a geometric grid of speeds (local maxima refined, then bisected:
  `solve.first_crossing`). In practice σ̄(V) rises through 0 once (each positive
  sample's σ crosses 0 once, at NV*/N_i, and a negative sample's σ grows with V); were
  it not monotone, V* would still be its first crossing, and the verdict at the
  robot's V is the sign of σ̄ there, whatever V* says.

σ(NV) is tabulated once per analysis (`GrowthRate`): the model's rightmost root on a
geometric grid of |NV| around NV* (both signs, NV* itself a node), interpolated by a
shape-preserving cubic (PCHIP) in log |NV|; linear in NV below the grid, exact above it.
At NV = 0 σ is the growth of the lateral deviation with no restoring force: 0 (the neutral
lateral root) when the model's heading loop is stable, its dominant root's real part when
that grows (`models.neutral_reason`); below the grid σ runs linearly from there (the slow
real root −NV/(1 + c) → 0 as NV → 0).

A spike, a gap or a negative sample counts by the growth it causes while the robot
crosses it: a sample ten times the median over one cell adds its σ over the number of
samples to σ̄, not its N.

**End effects** (`judged_run`). The corridor model takes the forward force as the
attraction (F_t = 1 + F_r·t ≈ F_ct = 1, the repulsion lateral). Near a wall ahead or
behind (an aisle's end, a junction's far wall) the repulsion's component along the
travel direction F_r·t changes F_t, N = −F_n′/F_t grows or shrinks quickly along
the path, and the robot turns rather than oscillates about a line: the model does
not hold there. Samples with |F_r·t| > `END_FRACTION` (of the attraction) get no
verdict ("end effect"): the segment is judged over its longest run of samples
without one, and a segment whose judged run is shorter than one wavelength
λ = 2πV/ω* (half the segment, with no oscillation frequency) gets no verdict at all
("end effect").

**Tapering** (`drift_slope`). The linearisation is about a straight equilibrium path along the
travel direction. Where the space tapers or widens on one side the equilibrium offset s0 drifts
along the judged part: the path the robot follows turns by atan(ds0/ds) from the segment, the
attraction (along the segment) then has a lateral component sin θ·F_ct that the model does not
have, and the wall distances the samples' N comes from change along the path at a rate the corridor
model (walls parallel to the path) ignores. A judged part whose least-squares slope |ds0/ds| exceeds
`TAPER_SLOPE` gets no verdict ("tapering").

**Weak fields** (`is_weak`). A field whose effect on the lateral motion over the
judged part is less than one e-fold cannot be seen, and gets no verdict ("weak"):
|σ̄|·length/V < 1. This holds for a slow drift (a small gain's real root) and for a
gain near the boundary alike: σ̄ is the growth the robot (and the simulation) would
see, whichever root causes it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PchipInterpolator

from ...numerics.solve import bisect_root, first_crossing

__all__ = ["EFOLDS", "END_FRACTION", "TAPER_SLOPE", "drift_slope", "GrowthRate", "SegmentGain", "critical_speed", "effective_gain", "is_weak", "judged_run",
           "mean_growth", "segment_gain", "wavelength"]

EFOLDS = 1.0
"""e-folds of growth or decay over a segment (|σ̄|·length/V) below which it is "weak" (no verdict)."""


END_FRACTION = 0.5
"""Largest |F_r·t| (units of the attraction F_ct) where the corridor model is trusted. The model takes the forward
force as constant along the path; F_t = 1 ± F_r·t in [0.5, 1.5] keeps N = −F_n′/F_t within a factor 2 of its
value with the repulsion lateral, and the heading change the along-track force causes small against the lateral
loop's. Beyond it (a wall ahead at an aisle's end) the forward force collapses over a fraction of a wavelength
and the robot turns instead of oscillating. Sensitivity (docs/maps.md, "Validation"): 0.25 judges shorter parts,
too short to measure on the shipped maps' 1–2.5 m pieces."""


TAPER_SLOPE = 0.25
"""Largest |ds0/ds| (least-squares slope of the equilibrium offset along the judged part) with a verdict.
0.25 is a path turned by atan 0.25 = 14° from the travel direction: the attraction's lateral component
sin 14° = 0.24 F_ct, a quarter of the forward force, half the along-track force the end rule
(`END_FRACTION`) tolerates; cos 14° = 0.97 leaves the forward force as modelled. Sensitivity: docs/maps.md, "Validation"."""


def drift_slope(position: np.ndarray, offset: np.ndarray) -> float:
    """|ds0/ds|: the least-squares slope of the equilibrium offsets `offset` (m) against `position` (m) along the
    segment, over the finite samples (0 with fewer than two).

    Parameters
    ----------
    position : ndarray
        Positions along the segment, m.
    offset : ndarray
        Equilibrium offsets s0, m (nan: none).
    """
    position, offset = np.asarray(position, dtype=float), np.asarray(offset, dtype=float)
    ok = np.isfinite(offset) & np.isfinite(position)
    if ok.sum() < 2 or np.ptp(position[ok]) == 0:
        return 0.0
    return float(abs(np.polyfit(position[ok], offset[ok], 1)[0]))


def judged_run(along: np.ndarray, fraction: float = END_FRACTION) -> tuple:
    """(first, stop): the longest run of consecutive samples with |F_r·t| <= `fraction` (nan: no equilibrium, kept).

    Parameters
    ----------
    along : ndarray
        F_r·t at each sample, units of F_ct.
    fraction : float
        `END_FRACTION` by default.

    Returns
    -------
    tuple of int
        Sample indices [first, stop) (first == stop: every sample is an end effect).
    """
    along = np.asarray(along, dtype=float)
    ok = ~(np.abs(along) > fraction)
    best, start = (0, 0), None
    for i, flag in enumerate(np.append(ok, False)):
        if flag and start is None:
            start = i
        elif not flag and start is not None:
            if i - start > best[1] - best[0]:
                best = (start, i)
            start = None
    return best


def wavelength(V: float, omega: float | None) -> float:
    """One oscillation wavelength 2π·V/ω, m (inf when the model has no oscillation frequency).

    Parameters
    ----------
    V : float
        Speed, m/s.
    omega : float or None
        Oscillation frequency, rad/s (None or 0: no oscillation).
    """
    if omega is None or not omega > 0 or not math.isfinite(omega):
        return math.inf
    return 2.0 * math.pi * V / omega


class GrowthRate:
    """σ(NV), the real part of a loop model's rightmost root (1/s) at loop gain NV (1/s), tabulated (module docstring).

    Parameters
    ----------
    root_of : callable
        ``root_of(NV) -> complex``: the model's rightmost root for the robot's loop, 1/s.
    NV_critical : float
        NV* of that loop, 1/s: the grid's centre and one of its nodes (1 when 0 or infinite).
    decades : float
        The grid spans NV*·10^±decades, for each sign.
    per_decade : int
        Grid points per decade.

    Attributes
    ----------
    lo, hi : float
        The grid's ends, 1/s.
    NV_least : float
        The positive grid NV with the most negative σ (the most damped uniform gain), 1/s.
    zero : float
        σ at NV = 0, 1/s: max(0, the heading loop's growth rate ``root_of(0).real``) (module docstring).
    """

    def __init__(self, root_of, NV_critical: float, decades: float = 4.0, per_decade: int = 40):
        self.root_of = root_of
        centre = NV_critical if 0 < NV_critical < math.inf else 1.0
        grid = np.unique(np.append(centre * np.logspace(-decades, decades, int(2 * decades * per_decade) + 1), centre))
        self.lo, self.hi = float(grid[0]), float(grid[-1])
        self.positive = np.array([root_of(float(x)).real for x in grid])
        self.negative = np.array([root_of(-float(x)).real for x in grid])
        self._pos = PchipInterpolator(np.log(grid), self.positive)
        self._neg = PchipInterpolator(np.log(grid), self.negative)
        self.NV_least = float(grid[int(np.argmin(self.positive))])
        self.zero = max(0.0, float(root_of(0.0).real))

    def __call__(self, NV):
        """σ at every NV (array or float), 1/s; `zero` at NV = 0."""
        shape = np.shape(NV)
        NV = np.atleast_1d(np.asarray(NV, dtype=float))
        x = np.abs(NV)
        inside = (x >= self.lo) & (x <= self.hi)
        log_x = np.log(np.where(inside, x, 1.0))
        out = np.where(inside & (NV > 0), self._pos(log_x), self.zero)
        out = np.where(inside & (NV < 0), self._neg(log_x), out)
        below = (x > 0) & (x < self.lo)
        out = np.where(below & (NV > 0), self.zero + (self.positive[0] - self.zero) * x / self.lo, out)
        out = np.where(below & (NV < 0), self.zero + (self.negative[0] - self.zero) * x / self.lo, out)
        out = np.array(out, dtype=float)
        for i in zip(*np.nonzero(x > self.hi)):
            out[i] = self.root_of(float(NV[i])).real
        return out.reshape(shape)


def mean_growth(N: np.ndarray, V: float, growth: GrowthRate) -> float:
    """σ̄: the mean of σ(N_i·V) over the samples with a finite N (1/m) at speed V (m/s), 1/s (nan without one).

    Parameters
    ----------
    N : ndarray
        Per-sample gains, 1/m (nan: no equilibrium).
    V : float
        Speed, m/s.
    growth : GrowthRate
        The model's σ(NV).
    """
    N = np.asarray(N, dtype=float)
    N = N[np.isfinite(N)]
    return float(np.mean(growth(N * V))) if N.size else math.nan


def effective_gain(sigma: float, mean_N: float, V: float, growth: GrowthRate, NV_critical: float) -> float:
    """N_eff (1/m): the uniform gain whose σ(N_eff·V) is `sigma`, on the branch the module docstring gives.

    Parameters
    ----------
    sigma : float
        The mean growth rate σ̄, 1/s.
    mean_N : float
        The samples' mean N, 1/m (picks the branch).
    V : float
        Speed, m/s.
    growth : GrowthRate
    NV_critical : float
        NV* of the loop, 1/s.
    """
    finite = 0 < NV_critical < math.inf
    if sigma >= 0 and (mean_N < 0 or not finite):  # the negative gain with that divergence (σ(−x) rises from 0)
        return -_rising(lambda x: float(growth(-x)) - sigma, 0.0, growth.lo) / V
    f = lambda NV: float(growth(NV)) - sigma  # noqa: E731
    if sigma >= 0:  # above NV*, where σ rises through 0
        return _rising(f, NV_critical, NV_critical) / V
    least = growth.NV_least
    top = NV_critical if finite else growth.hi
    if f(least) > 0:  # a window whose gain varies can decay faster than any uniform gain: the fastest one's
        return least / V
    if mean_N * V > least and f(top) >= 0:  # the oscillating branch: σ rises from its least value to 0 at NV*
        return bisect_root(f, least, top) / V
    return bisect_root(f, 0.0, least) / V  # the slow real root's branch: σ falls from 0 (f(0) = −σ̄ > 0)


def _rising(g, lo: float, hi: float) -> float:
    """The x >= lo where g rises through 0: the bracket [lo, hi] grown tenfold until g(hi) >= 0 (inf if never)."""
    if g(lo) >= 0:
        return lo
    for _ in range(60):
        if g(hi) >= 0:
            return bisect_root(g, lo, hi)
        hi *= 10.0
    return math.inf


@dataclass(frozen=True)
class SegmentGain:
    """The mean growth of one travel direction of a segment at one speed.

    Attributes
    ----------
    N_eff : float or None
        The uniform gain with the same growth, 1/m (None: no sample with an equilibrium).
    sigma : float or None
        σ̄, the mean growth rate, 1/s.
    mean_N : float or None
        The samples' mean N, 1/m.
    stretch : int
        Samples averaged (those with an equilibrium).
    wavelength : float
        λ = 2πV/ω* at the speed, m (inf: no oscillation frequency).
    """

    N_eff: float | None
    sigma: float | None
    mean_N: float | None
    stretch: int
    wavelength: float


def segment_gain(N: np.ndarray, V: float, omega: float | None, growth: GrowthRate, NV_critical: float) -> SegmentGain:
    """σ̄ and N_eff of a travel direction with per-sample gains `N` (1/m) at speed V (m/s); ω* (rad/s) gives λ only.

    Parameters
    ----------
    N : ndarray
        Per-sample gains, 1/m (nan: no equilibrium).
    V : float
        Speed, m/s.
    omega : float or None
        The model's ω*, rad/s (None: no oscillation frequency).
    growth : GrowthRate
        The model's σ(NV).
    NV_critical : float
        The model's NV*, 1/s.
    """
    N = np.asarray(N, dtype=float)
    N = N[np.isfinite(N)]
    lam = wavelength(V, omega)
    if N.size == 0:
        return SegmentGain(None, None, None, 0, lam)
    sigma, mean_N = mean_growth(N, V, growth), float(np.mean(N))
    return SegmentGain(effective_gain(sigma, mean_N, V, growth, NV_critical), sigma, mean_N, int(N.size), lam)


def critical_speed(N: np.ndarray, growth: GrowthRate, NV_critical: float) -> float:
    """V* (m/s): the smallest V with σ̄(V) = mean σ(N_i·V) >= 0 (module docstring).

    0 when the mean N is negative (σ̄ > 0 at every small V) or NV* = 0; inf without a
    sample with an equilibrium, or when NV* is infinite and no N is negative.

    Parameters
    ----------
    N : ndarray
        Per-sample gains, 1/m (nan: no equilibrium).
    growth : GrowthRate
        The model's σ(NV).
    NV_critical : float
        The model's NV*, 1/s.
    """
    N = np.asarray(N, dtype=float)
    N = N[np.isfinite(N) & (N != 0)]
    if N.size == 0 or (NV_critical == math.inf and not (N < 0).any()):
        return math.inf
    if np.mean(N) < 0 or not NV_critical > 0:
        return 0.0
    scale = NV_critical if NV_critical < math.inf else growth.hi
    lo = 1e-2 * scale / float(np.max(np.abs(N)))
    hi = 10.0 * scale / float(N[N > 0].min())
    measure = lambda V: growth(np.multiply.outer(np.atleast_1d(V), N)).mean(axis=-1)  # noqa: E731
    return first_crossing(measure, lo, hi, start=0.0, rtol=1e-9)


def is_weak(sigma: float, length: float, V: float) -> bool:
    """True if the mean growth rate changes the lateral deviation by less than `EFOLDS` e-folds over the segment.

    Parameters
    ----------
    sigma : float
        σ̄, the mean growth rate, 1/s.
    length : float
        Length judged, m.
    V : float
        Speed, m/s.
    """
    return abs(sigma) * length / V < EFOLDS
