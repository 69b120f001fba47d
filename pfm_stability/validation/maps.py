"""Map predictions checked by simulation: the engine of ``pfm-stability map --validate N`` (docs/validation.md).

A map analysis (docs/maps.md) predicts for each straight corridor segment the
lateral equilibrium offset, the gain N, the heading gain c, V* and the margin
NV*/NV − 1 (> 0 stable). `validate_map_segments` drives the simulator's VFF
robot (`pfm_stability.sim`) along chosen segments on the map's own histogram
grid and compares the sign of the measured growth rate σ with the verdict.

**Selection**: `validation.map_selection` (`select_segments`, seeded; `required_length`).

**Runs** (batched, `sim.engine.run_batch`): two per segment, started
`end_margin` (default two cells: the map analysis has already cut the
branch ends back by the junctions' radius, and the corridor model does not
hold near junctions) in from its start on the predicted equilibrium line (`offset`
along the left normal) plus and minus a lateral offset δ (`START_OFFSET`, at
most a quarter of the robot's room), heading along the segment, target at
infinity along it (the attraction is along the travel direction, as the
prediction assumes), stopped by the target's ``finish`` `end_margin` before
the end. The lateral deviations from the line (`sim.scenario.MeasureAxis`)
of the two runs are subtracted: the response forced by the map (cell
quantization, a staircase wall, an uneven equilibrium line: ±2 cm in a 30°
corridor, as large as δ) is common to both and cancels, leaving the free
oscillation from 2δ, measured by the simulator's own metrics
(`sim.metrics.oscillation_metrics`) and judged by its rule
(`sim.verdict.simulated_verdict`: sign of σ, a collision is unstable). A
stall (the "trapped" event) is not counted. A σ within the run's `resolution` has no
sign: it disagrees when the predicted σ̄ differs from it by more than that (`contradicts`),
else it is "not measurable (σ within resolution)". Each case is "agree", "disagree" or
"not measurable" (`MapCase.outcome`); the agreement is over the measured ones only.
A segment is driven over its judged part only (`maps.deciding.verdicts.judged_run`). Undefined values are
None with a reason, never NaN.

Each run senses a copy of the map's grid cropped to the segment's box widened
by the window's reach plus `LATERAL_SLACK` (the same cells in the window of
every position within that slack of the line), so the window tables
(`sim.window`) fit in memory for any map; batches keep them under
`TABLE_BUDGET` entries.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..checks import check_integer, check_number, check_type
from ..laws.effective_force import check_window_cells
from ..models import Sampled
from ..parameters import Controller, Robot
from ..io.serialize import json_number, json_ready
from ..sim.engine import run_batch
from ..sim.grid import HistogramGrid
from ..sim.metrics import linear_prediction, oscillation_metrics
from ..sim.scenario import MeasureAxis, Pose, Scenario, Target
from ..sim.verdict import simulated_verdict
from .map_selection import CLEAR_MARGIN, MIN_PERIODS, number, periods_omega, predicted, required_length, select_segments

__all__ = [
    "MapCase", "MapValidation", "validate_map_segments", "select_segments", "required_length", "crop_grid", "simulator_grid",
    "CLEAR_MARGIN", "START_OFFSET", "SIGMA_RESOLUTION", "MIN_EFOLDS", "resolution", "resolved", "contradicts", "MIN_PERIODS", "LATERAL_SLACK", "TABLE_BUDGET", "LINEAR_FRACTION", "linear_offset",
    "SHORT_RESIDUAL", "FIT_RESOLUTION", "short_record_fit",
]

START_OFFSET = 0.03
"""Lateral start offset δ from the predicted equilibrium, m (at most a quarter of the room):
small against a corridor's half-width (x/L of a few %: linear)."""

LINEAR_FRACTION = 0.25
"""Fraction of the steering rate limit the start offset may ask (`linear_offset`): the prediction is linear,
and a rate-limited loop (k·N·δ above the limit) grows or decays at another rate."""

SIGMA_RESOLUTION = 0.02
"""Smallest measured |σ| whose sign is read, 1/s: below it the estimators' scatter (`sim.metrics`) decides the sign."""

MIN_EFOLDS = 1.0
"""e-folds |σ|·duration the measured growth or decay must reach over the run for its sign to count."""


SHORT_RESIDUAL = 1e-3
"""Largest relative residual of the linear-prediction fit of a short difference record (`short_record_fit`).

The simulator's metrics accept a fit only below `sim.metrics.LINEAR_RESIDUAL` (1e-6, a run that stayed
linear to round-off) or take σ from >= 4 turning points (~2 periods). The ± difference of a map run is
linear to the cells' quantization: on the synthetic corridors of tests/test_map_validation.py its fit
leaves 2e-6 … 1e-3 over 1–1.5 periods and gives σ within 0.05 1/s of the `sampled` root, the sign right
for every |margin| > 10 % (docs/maps.md, "Validation")."""


def short_record_fit(x, order: int, T: float):
    """(σ 1/s, ω rad/s, relative residual) of the dominant root of the order-`order` linear-prediction fit of the
    difference record `x` (m, step T s: `sim.metrics`' fit), or None when the fit fails, its residual exceeds
    `SHORT_RESIDUAL`, or its dominant root does not oscillate (a monotone drift over a short record says nothing).

    Parameters
    ----------
    x : ndarray
        The difference record, m.
    order : int
        The fit's order (`sim.cycles.loop_order`).
    T : float
        Its step, s.
    """
    fit = linear_prediction(np.asarray(x, dtype=float), order, T)
    if fit is None or not fit[2] < SHORT_RESIDUAL or not fit[1] > 0:
        return None
    return fit


FIT_RESOLUTION = 0.05
"""Smallest |σ| (1/s) whose sign is read from the short-record fit (`short_record_fit`): its largest error on the
synthetic corridors of tests/test_map_validation.py (1–1.5 periods, straight and 30°) was 0.045 1/s."""


def resolution(duration: float, fitted: bool = False) -> float:
    """Smallest |σ| (1/s) a run of `duration` s resolves: max(`SIGMA_RESOLUTION`, `MIN_EFOLDS`/duration) (the peaks'
    scatter); `FIT_RESOLUTION` for σ from `short_record_fit` (it reads the root, not the amplitudes: no e-fold).

    Parameters
    ----------
    duration : float
        The run's length, s.
    fitted : bool
        σ comes from `short_record_fit`.
    """
    if fitted:
        return FIT_RESOLUTION
    return max(SIGMA_RESOLUTION, MIN_EFOLDS / duration) if duration > 0 else math.inf


def resolved(sigma: float, duration: float, fitted: bool = False) -> bool:
    """True if a measured σ (1/s) is outside the run's `resolution` (its sign is read); else σ ≈ 0 (`contradicts`).

    Parameters
    ----------
    sigma : float
        The measured σ, 1/s.
    duration : float
        The run's length, s.
    fitted : bool
        σ comes from `short_record_fit`.
    """
    return abs(sigma) >= resolution(duration, fitted)


def contradicts(predicted: float | None, sigma: float, duration: float, fitted: bool = False) -> bool:
    """True if a measured σ within the resolution (no sign) contradicts the predicted σ̄ (1/s): they differ by more than
    the run's `resolution`, so the run would have shown the predicted growth or decay (a disagreement). False: the
    prediction is within the resolution too, and the run decides nothing ("not measurable"; docs/maps.md, "Validation").

    Parameters
    ----------
    predicted : float or None
        The predicted σ̄, 1/s.
    sigma : float
        The measured σ, 1/s.
    duration : float
        The run's length, s.
    fitted : bool
        σ comes from `short_record_fit`.
    """
    return predicted is not None and math.isfinite(predicted) and abs(predicted - sigma) > resolution(duration, fitted)


LATERAL_SLACK = 1.0
"""How far the robot may stray from its line with the cropped grid still exact, m."""

TABLE_BUDGET = 1.5e7
"""Largest window-table size of one batch (rows × occupied cells per window), entries (24 bytes each)."""


# ------------------------------------------------------------------ results
@dataclass(frozen=True)
class MapCase:
    """One chosen segment: the prediction and what the simulation measured.

    Attributes
    ----------
    index : int
        Position of the segment in the list given.
    x0, y0, x1, y1, length : float
        Endpoints in map coordinates in the order of travel (from 0 to 1) and length, m.
    N, c : float
        Predicted environment gain (1/m) and heading gain.
    predicted_offset : float
        Predicted equilibrium offset along the left normal, m.
    predicted_margin, predicted_stable, V_critical
        NV*/NV − 1 (``inf``: stable at every speed), the verdict, V* (m/s).
    predicted_growth_rate : float or None
        Real part of the `sampled` model's dominant root at N·V, 1/s.
    required_length : float
        Length the measurement needs (2·end_margin + `min_periods` periods at V), m.
    direction : str
        "forward" (the segment's own start to end) or "reverse": the travel direction that decides
        the segment's verdict (`maps.analysis.MapSegment.direction`), the one simulated.
    measurable : bool
        The run decides: a measured sign, or a σ within the resolution contradicting the prediction (`contradicts`).
    growth_rate, angular_frequency : float or None
        Measured σ (1/s) and ω (rad/s) (None: undefined, see `reason`).
    method : str or None
        σ's estimator ("linear_prediction", "peaks", "none").
    verdict : str or None
        Measured "stable"/"unstable" (sign of σ; collision: unstable); None when σ is within the resolution.
    basis : str or None
        "growth_rate", "collision" or "metrics" (`sim.verdict.simulated_verdict`); "resolution" (`contradicts`).
    agree : bool or None
        Measured verdict == predicted (False for basis "resolution"); None when not measurable.
    event : str or None
        The event that ended the run ("collision", "target_reached", "trapped"), None: ran its duration.
    start_offset : float or None
        Lateral perturbation of the start, m (left normal).
    measured_offset : float or None
        Mean lateral position over the second half of the run, m along the left normal of the segment line.
    min_clearance : float or None
        Smallest gap robot–obstacle, m.
    reason : str or None
        Why the case is not measurable, or why a σ within the resolution disagrees.
    """

    index: int
    x0: float
    y0: float
    x1: float
    y1: float
    length: float
    N: float
    c: float
    predicted_offset: float
    predicted_margin: float
    predicted_stable: bool
    V_critical: float
    predicted_growth_rate: float | None
    required_length: float
    direction: str = "forward"
    measurable: bool = False
    growth_rate: float | None = None
    angular_frequency: float | None = None
    method: str | None = None
    verdict: str | None = None
    basis: str | None = None
    agree: bool | None = None
    event: str | None = None
    start_offset: float | None = None
    measured_offset: float | None = None
    min_clearance: float | None = None
    reason: str | None = None

    @property
    def predicted_verdict(self) -> str:
        """"stable" or "unstable"."""
        return "stable" if self.predicted_stable else "unstable"

    @property
    def outcome(self) -> str:
        """"agree", "disagree" or "not measurable" (`agree` True, False, None)."""
        return "not measurable" if self.agree is None else ("agree" if self.agree else "disagree")

    def to_dict(self) -> dict:
        """JSON form (SI units; ``"inf"`` for infinite values, null for undefined), with ``outcome``."""
        return json_ready({**self.__dict__, "predicted_verdict": self.predicted_verdict, "outcome": self.outcome})


@dataclass(frozen=True)
class MapValidation:
    """Predicted against simulated verdicts on chosen segments of a map.

    Attributes
    ----------
    agreement : float or None
        agreed / measured (None: none measured); a case not measurable is in neither.
    cases : tuple of MapCase
        One per chosen segment, in the order of their predicted margins.
    measured, agreed, disagreed, not_measurable : int
        Measured cases (agreed + disagreed), those that agree and those that do not (`contradicts` too), and the
        cases without a measurement (`MapCase.outcome`): agreed + disagreed + not_measurable cases in all.
    inputs : dict
        What defined the validation (V, count, seed, end margin, …).
    notes : dict
        Documented choices.
    seconds : float
        Wall-clock time, s.
    """

    agreement: float | None
    cases: tuple
    measured: int
    agreed: int
    disagreed: int = 0
    not_measurable: int = 0
    inputs: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)
    seconds: float = 0.0

    def to_dict(self) -> dict:
        """JSON form: ``agreement``, the four counts, ``cases``, ``inputs``, ``notes``; time under ``timing``."""
        return {
            "agreement": json_number(self.agreement),
            "measured": int(self.measured),
            "agreed": int(self.agreed),
            "disagreed": int(self.disagreed),
            "not_measurable": int(self.not_measurable),
            "cases": [c.to_dict() for c in self.cases],
            "inputs": json_ready(self.inputs),
            "notes": dict(self.notes),
            "timing": {"seconds": json_number(self.seconds)},
        }


# ------------------------------------------------------------------- runs
def linear_offset(robot: Robot, N: float) -> float:
    """Largest start offset that keeps the steering linear, m: the heading error N·δ it causes
    asks k·N·δ of the steering, at most `LINEAR_FRACTION` of the robot's rate limit.

    Parameters
    ----------
    robot : Robot
        k (1/s) and its rate limit (rad/s).
    N : float
        The segment's gain, 1/m.
    """
    if not N or not math.isfinite(N) or not math.isfinite(robot.max_steering_rate):
        return math.inf
    return LINEAR_FRACTION * robot.max_steering_rate / (robot.k * abs(N))


def stall_time(V: float) -> float:
    """Seconds without progress after which a map drive stalls (`Scenario.trap_time`): 10 s, or the time to cover
    1.5 m at V (m/s) when that is longer."""
    return max(10.0, 1.5 / V)


def simulator_grid(hmap) -> HistogramGrid:
    """The simulator's frozen `HistogramGrid` of a map's histogram grid (`maps.reading.field.HistogramMap`: same cells, same origin).

    Parameters
    ----------
    hmap : HistogramMap
        The map's histogram grid.
    """
    nx, ny = hmap.shape
    c = hmap.cell_size
    grid = HistogramGrid(hmap.x_min, hmap.y_min, nx * c, ny * c, cell_size=c)
    grid.cv[:] = hmap.cv
    return grid.freeze()


def crop_grid(grid: HistogramGrid, x_lo: float, x_hi: float, y_lo: float, y_hi: float) -> HistogramGrid:
    """A frozen copy of the cells of `grid` covering [x_lo, x_hi] × [y_lo, y_hi] (m), aligned with its cells.

    Parameters
    ----------
    grid : HistogramGrid
        The whole grid.
    x_lo, x_hi, y_lo, y_hi : float
        The area to keep, m.
    """
    c = grid.cell_size
    nx, ny = grid.shape
    i0 = min(max(math.floor((x_lo - grid.x_min) / c), 0), nx - 1)
    j0 = min(max(math.floor((y_lo - grid.y_min) / c), 0), ny - 1)
    i1 = min(max(math.ceil((x_hi - grid.x_min) / c), i0 + 1), nx)
    j1 = min(max(math.ceil((y_hi - grid.y_min) / c), j0 + 1), ny)
    out = HistogramGrid(grid.x_min + i0 * c, grid.y_min + j0 * c, (i1 - i0) * c, (j1 - j0) * c, cell_size=c, cv_max=grid.cv_max)
    out.cv[:] = grid.cv[i0:i1, j0:j1]
    return out.freeze()


def _table_size(grid: HistogramGrid, h: int) -> tuple[int, int]:
    """(robot cells of the padded grid, most occupied cells in one window): a bound on its window table."""
    occupied = np.pad((grid.cv > 0).astype(np.int64), h)
    s = np.pad(occupied.cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    w = 2 * h + 1
    counts = s[w:, w:] - s[:-w, w:] - s[w:, :-w] + s[:-w, :-w]
    return occupied.size, int(counts.max()) if counts.size else 0


@dataclass(frozen=True)
class _Run:
    """A prepared case: its two scenarios (start offset +δ and −δ) and the window table's size."""

    case: MapCase
    scenarios: tuple
    table: tuple


def _prepare(case: MapCase, grid, robot, controller, cell_ratio, window_cells, end_margin, slack) -> _Run | MapCase:
    """The two scenarios of one case, or the case marked not measurable with the reason."""
    dx, dy = case.x1 - case.x0, case.y1 - case.y0
    ux, uy = dx / case.length, dy / case.length
    nx, ny = -uy, ux  # left normal
    s0 = case.predicted_offset
    ex, ey = case.x0 + end_margin * ux + s0 * nx, case.y0 + end_margin * uy + s0 * ny
    room = float(grid.clearance([ex], [ey])[0]) - robot.W / 2
    if not room > 0:
        return _not_measurable(case, f"the predicted equilibrium line at the start ({ex:.3f}, {ey:.3f}) m leaves the robot no room ({room:.3g} m)")
    delta = min(START_OFFSET, room / 4, linear_offset(robot, case.N))
    usable = case.length - 2 * end_margin
    reach = (window_cells // 2 + 1) * grid.cell_size + slack + abs(s0)
    xs, ys = (case.x0, case.x1), (case.y0, case.y1)
    local = crop_grid(grid, min(xs) - reach, max(xs) + reach, min(ys) - reach, max(ys) + reach)
    heading = math.atan2(dx, dy)  # rad from +Y towards +X
    scenarios = tuple(
        Scenario(
            name=f"map segment {case.index} ({'+' if sign > 0 else '-'})",
            robot=robot,
            controller=controller,
            environment=local,
            start=Pose(ex + sign * delta * nx, ey + sign * delta * ny, heading),
            target=Target.direction(heading, finish=usable),
            duration=1.25 * usable / robot.V + 10 * controller.T,
            cell_ratio=cell_ratio,
            window_cells=window_cells,
            measure=MeasureAxis((ex, ey), heading, along_from=0.0),
            trap_time=stall_time(robot.V),
        )
        for sign in (1, -1)
    )
    return _Run(_with(case, start_offset=delta), scenarios, _table_size(local, window_cells // 2))


def _with(case: MapCase, **changes) -> MapCase:
    return MapCase(**{**case.__dict__, **changes})


def _not_measurable(case: MapCase, reason: str, **changes) -> MapCase:
    return _with(case, measurable=False, agree=None, reason=reason, **changes)


@dataclass(frozen=True)
class _Difference:
    """The free response of a case: the ± runs' lateral offsets subtracted, as `simulated_verdict` reads a run."""

    collided: bool
    metrics: object


def _measured(run: _Run, plus, minus) -> MapCase:
    """The case with what its pair of runs measured (not measurable if one stalled).

    The offsets of the runs started at +δ and −δ are subtracted over their
    common samples: the response forced by the map (quantization ripple, an
    uneven equilibrium line) is the same in both and cancels, leaving the
    free oscillation from 2δ, whose σ the simulator's metrics measure
    (`oscillation_metrics`); their mean gives the measured equilibrium.
    A collision of either run is unstable (`simulated_verdict`).
    """
    n = min(plus.offset.size, minus.offset.size)
    t = plus.offset_t[:n]
    collisions = [r.event("collision").t for r in (plus, minus) if r.collided]
    m = oscillation_metrics(t, minus.offset[:n] - plus.offset[:n], run.scenarios[0].controller.T, order=_order(run.scenarios[0]),
                            collision_time=min(collisions) if collisions else None)
    fitted = False
    if m.growth_rate is None and not collisions:  # too few turning points for the peaks: the fit of the short record
        fit = short_record_fit(minus.offset[:n] - plus.offset[:n], _order(run.scenarios[0]), run.scenarios[0].controller.T)
        if fit is not None:
            m = replace(m, growth_rate=fit[0], angular_frequency=fit[1], method="linear_prediction", fit_residual=fit[2], reason=None)
            fitted = True
    mean = (plus.offset[:n] + minus.offset[:n]) / 2
    events = [r.events[0].type for r in (plus, minus) if r.events]
    common = dict(
        growth_rate=m.growth_rate,
        angular_frequency=m.angular_frequency,
        method=m.method,
        event="collision" if collisions else ("trapped" if "trapped" in events else (events[0] if events else None)),
        measured_offset=run.case.predicted_offset - float(np.mean(mean[n // 2:])) if n else None,  # MeasureAxis: right of the line
        min_clearance=min((r.min_clearance for r in (plus, minus) if r.min_clearance is not None), default=None),
    )
    stalled = [r for r in (plus, minus) if r.event("trapped") is not None]
    if stalled and not collisions:
        e = stalled[0].event("trapped")
        return _not_measurable(run.case, f"the robot stalled (no progress in {run.scenarios[0].trap_time:g} s) at ({e.x:.2f}, {e.y:.2f}) m", **common)
    duration = float(t[-1] - t[0]) if n > 1 else 0.0
    if not collisions and m.growth_rate is not None and n > 1 and not resolved(m.growth_rate, duration, fitted):
        within = (f"|sigma| = {abs(m.growth_rate):.3g} 1/s, {abs(m.growth_rate) * duration:.2g} e-folds over the {duration:.1f} s run "
                  f"(resolves {resolution(duration, fitted):.3g} 1/s: " + (f"the short-record fit's {FIT_RESOLUTION:g})" if fitted else
                  f">= {SIGMA_RESOLUTION:g} 1/s and >= {MIN_EFOLDS:g} e-fold)"))
        predicted = run.case.predicted_growth_rate
        if contradicts(predicted, m.growth_rate, duration, fitted):  # the run would have shown the predicted σ̄
            return _with(run.case, measurable=True, verdict=None, basis="resolution", agree=False, reason=f"predicted sigma "
                         f"{predicted:+.3g} 1/s not seen: {within}", **common)
        return _not_measurable(run.case, f"not measurable (sigma within resolution): {within}, predicted sigma "
                               + (f"{predicted:+.3g} 1/s within it too" if predicted is not None else "undefined"), **common)
    if not collisions and m.growth_rate is None:  # the settled flag of a record this short decides nothing
        return _not_measurable(run.case, f"not measurable (sigma undefined): {m.reason}", **common)
    verdict, basis = simulated_verdict(_Difference(bool(collisions), m))
    return _with(run.case, measurable=True, verdict=verdict, basis=basis, agree=verdict == run.case.predicted_verdict, reason=None, **common)


def _order(scenario: Scenario) -> int:
    """State dimension of the sampled loop, the linear-prediction order (`sim.metrics`): `Scenario.loop_order`."""
    return scenario.loop_order()


def _batches(runs: list) -> list:
    """Runs grouped so that each batch's stacked window tables stay under `TABLE_BUDGET` entries."""
    out, current, rows, width = [], [], 0, 0
    for r in runs:
        cells, k = r.table
        if current and (rows + cells) * max(width, k) > TABLE_BUDGET:
            out.append(current)
            current, rows, width = [], 0, 0
        current.append(r)
        rows, width = rows + cells, max(width, k)
    if current:
        out.append(current)
    return out


def _judged_ends(s) -> tuple:
    """([x0, y0, x1, y1], length) of the segment's judged part (`maps.deciding.verdicts.judged_run`; the whole segment without one), m."""
    ends = [float(s.x0), float(s.y0), float(s.x1), float(s.y1)]
    length = float(s.length)
    a, b = number(getattr(s, "judged_from", None)), number(getattr(s, "judged_to", None))
    if a is None or b is None or not 0 <= a < b <= length + 1e-9 or (a == 0 and b >= length):
        return ends, length
    ux, uy = (ends[2] - ends[0]) / length, (ends[3] - ends[1]) / length
    return [ends[0] + a * ux, ends[1] + a * uy, ends[0] + b * ux, ends[1] + b * uy], b - a


def _case(i: int, s, robot, controller, model, end_margin, min_periods) -> MapCase:
    """The prediction of segment `s` (index `i`) as a case, with the length its measurement needs."""
    omega, sigma, oscillates = periods_omega(s, robot, controller, model)
    ends, length = _judged_ends(s)
    offset = number(getattr(s, "offset", 0.0)) or 0.0
    reverse = getattr(s, "direction", None) == "reverse"
    if reverse:  # drive the direction that decides the verdict; the left normal flips with it
        ends, offset = ends[2:] + ends[:2], -offset
    return MapCase(
        index=i, x0=ends[0], y0=ends[1], x1=ends[2], y1=ends[3], length=length, direction="reverse" if reverse else "forward",
        N=float(s.N), c=number(getattr(s, "c", 0.0)) or 0.0, predicted_offset=offset,
        predicted_margin=float(s.margin), predicted_stable=bool(s.stable),
        V_critical=number(getattr(s, "V_critical", None)), predicted_growth_rate=sigma,
        required_length=required_length(omega, robot.V, end_margin, min_periods, None if oscillates else sigma),
    )


# --------------------------------------------------------------------- API
def _check_inputs(grid, segments, robot, controller, cell_ratio, window_cells, count, seed):
    if not isinstance(grid, HistogramGrid):
        raise ValueError(f"grid must be a frozen pfm_stability.sim.grid.HistogramGrid; got {type(grid).__name__}")
    if not grid.frozen:
        raise ValueError("grid must be frozen (HistogramGrid.freeze()): the runs share it")
    try:
        segments = list(segments)
    except TypeError:
        raise ValueError(f"segments must be a sequence of map segments; got {type(segments).__name__}") from None
    if not segments:
        raise ValueError("segments must hold at least one segment; got an empty list")
    check_type("robot", robot, Robot, "a Robot")
    check_type("controller", controller, Controller, "a Controller")
    if not controller.T > 0:
        raise ValueError(f"T must be a finite number in (0, 100] s (the simulator samples); got {controller.T!r}")
    cell_ratio = check_number("cell_ratio", cell_ratio, 0.0)
    window_cells = check_window_cells(window_cells)
    count = check_integer("count", count, 1, 100_000)
    seed = check_integer("seed", seed, 0, 2**63 - 1)
    return segments, cell_ratio, window_cells, count, seed


def validate_map_segments(
    grid: HistogramGrid,
    segments,
    robot: Robot,
    controller: Controller,
    *,
    cell_ratio: float,
    window_cells: int,
    count: int,
    seed: int = 0,
    progress=None,
    end_margin: float | None = None,
    min_periods: float = MIN_PERIODS,
) -> MapValidation:
    """Simulate the VFF robot along `count` chosen segments of a map and compare each verdict with the prediction.

    Parameters
    ----------
    grid : HistogramGrid
        The map's histogram grid, frozen.
    segments : sequence
        Objects with ``x0, y0, x1, y1, length`` (m, map coordinates), ``N``
        (1/m), ``c``, ``V_critical`` (m/s), ``margin``, ``stable`` and
        ``offset`` (mean equilibrium offset, m, along the left normal of
        (x1 − x0, y1 − y0)). Segments without a margin or a bool ``stable``
        (open areas, no equilibrium) are not chosen.
    robot, controller : Robot, Controller
        The robot drives at ``robot.V``; the sampled structure is the controller's.
    cell_ratio : float
        ρ = F_cr/F_ct of the grid's cells, > 0.
    window_cells : int
        Active window side (odd, >= 3).
    count : int
        Segments to simulate, >= 1.
    seed : int
        Seed of the selection (`select_segments`).
    progress : callable, optional
        Called with one line of text after each batch of runs.
    end_margin : float, optional
        Distance kept from each end of a segment, m (default two cells).
    min_periods : float
        Oscillation periods a run must cover to be measured (> 0).

    Returns
    -------
    MapValidation

    Raises
    ------
    ValueError
        Bad input, with one line naming the parameter.
    """
    started = time.perf_counter()
    segments, cell_ratio, window_cells, count, seed = _check_inputs(grid, segments, robot, controller, cell_ratio, window_cells, count, seed)
    end_margin = check_number("end_margin", end_margin if end_margin is not None else 2 * grid.cell_size, 0.0, low_open=False, unit="m")
    min_periods = check_number("min_periods", min_periods, 0.0, 1000.0)
    model = Sampled(controller.hold, controller.compute_delay)

    candidates = [i for i, s in enumerate(segments) if predicted(s)]
    order = [_case(i, segments[i], robot, controller, model, end_margin, min_periods) for i in candidates]
    chosen = select_segments(
        [c.predicted_margin for c in order], [c.predicted_stable for c in order],
        [c.length >= c.required_length and c.length > 0 for c in order], count, seed=seed,
    )
    chosen = [order[k] for k in chosen]
    if progress:
        progress(f"map validation: {len(chosen)} of {len(segments)} segments chosen ({len(candidates)} with a prediction)")

    results, runs = {}, []
    for case in chosen:
        if case.length < case.required_length:
            results[case.index] = _not_measurable(
                case, f"segment too short to measure: {case.length:.2f} m < {case.required_length:.2f} m "
                f"(2 x {end_margin:g} m end margin + {min_periods:g} oscillation periods at V = {robot.V:g} m/s)",
            )
            continue
        prepared = _prepare(case, grid, robot, controller, cell_ratio, window_cells, end_margin, LATERAL_SLACK)
        if isinstance(prepared, MapCase):
            results[case.index] = prepared
        else:
            runs.append(prepared)
    batches = _batches(runs)
    for b, batch in enumerate(batches, 1):
        outcome = run_batch([s for r in batch for s in r.scenarios], record="offset", metrics=False)
        for k, r in enumerate(batch):
            results[r.case.index] = _measured(r, outcome.runs[2 * k], outcome.runs[2 * k + 1])
        if progress:
            progress(f"map validation: batch {b}/{len(batches)}: {len(batch)} runs")

    out = tuple(results[c.index] for c in chosen)
    measured = [c for c in out if c.agree is not None]
    agreed = sum(1 for c in measured if c.agree)
    inputs = {
        "V": robot.V, "count": count, "seed": seed, "cell_ratio": cell_ratio, "window_cells": window_cells,
        "cell_size": grid.cell_size, "end_margin": end_margin, "min_periods": min_periods,
        "hold": controller.hold, "compute_delay": controller.compute_delay, "segments": len(segments),
    }
    notes = {
        "verdict": "sign of the growth rate sigma of the difference of the lateral deviations of the runs started at +delta and "
        "-delta from the predicted equilibrium line (the response forced by the map cancels; collision: unstable)",
        "start": f"{end_margin:g} m in from the segment start on the predicted equilibrium line plus a lateral offset of "
        f"+/- min({START_OFFSET:g} m, room/4), heading along the segment; target at infinity along it; stop {end_margin:g} m before the end",
        "selection": f"prefer |margin| > {CLEAR_MARGIN:g} and long enough segments; stable and unstable both represented; margin quantile bins",
    }
    agreement = agreed / len(measured) if measured else None
    return MapValidation(agreement, out, len(measured), agreed, len(measured) - agreed, len(out) - len(measured), inputs, notes,
                         time.perf_counter() - started)
