"""Time-domain simulator of the VFF algorithm driving a CARMEL-like robot (DESIGN §5).

Koren & Borenstein 1991 (KB) §2 (VFF on a histogram grid, eq 1–5) drives the
synchro-drive robot of §3–4 (steering lag eq 6, |ω| <= 120°/s), sampled
exactly as the `sampled` loop model (DESIGN §4: ``hold="command"`` or
``"reference"``, ``compute_delay`` 0 or 1), so that in the linear regime the
simulated σ and ω equal the model's dominant pole to round-off.

Library API
-----------
``simulate(scenario_or_name, *, record="trajectory", **options) -> RunResult``
    One run; ``options`` go to `make_scenario`.
``simulate_batch(name, *, env="grid", robot=None, controller=None, record="offset", metrics=True, **arrays) -> BatchResult``
    Many parameter sets at once: each of ``V, tau, k, W, max_steering_rate,
    f, n, T, hold, compute_delay, L, alpha (rad), offset, duration,
    cell_ratio, law, window_cells, cell_size, speed_law, seed,
    start_jitter`` may be a scalar or a 1-D array (one entry per member).
    ``BatchResult.stable / .oscillating / .collided`` are bool arrays,
    ``.growth_rate / .angular_frequency`` masked arrays (masked = undefined,
    the reason is in ``.runs[i].metrics.reason``), ``.runs[i]`` the full
    `RunResult` (events, metrics, inputs, `to_dict`).
``boundary_by_bisection(name, parameter, lo, hi, *, env, rtol, members, **fixed) -> BoundaryEstimate``
    The value of L, alpha, V, f, … where the simulated run changes from
    stable to unstable, by batched bisection (each round simulates
    `members` values at once).
``make_scenario(name, *, robot, controller, env, L, alpha, offset, duration, cell_ratio, law, window_cells, cell_size, speed_law, seed, start_jitter) -> Scenario``
    Presets: ``straight``, ``corridor``, ``wall`` (validation geometries,
    target at infinity) and ``kb-fig3``, ``kb-fig5``, ``kb-fig6-wide``,
    ``kb-fig6-narrow`` (KB's figures; geometry choices in
    `pfm_stability.sim.presets`).
``predict(scenario) -> Prediction | None``
    The `sampled` model with the run's own force law (the grid's
    `GridWallLaw` in the grid) and KB's criterion, for corridor and wall
    geometries.
``run_batch(scenarios, *, record, metrics) -> BatchResult``
    The engine, for hand-built `Scenario` objects (own grids: `HistogramGrid`;
    analytic walls: `AnalyticEnvironment`).
``simulate_reference(scenario) -> (Trajectory, Event | None)``
    The same model in a plain per-robot Python loop (baseline, cross-check).

Environments: ``env="grid"`` (cells of CV 15; the cell ratio ρ = F_cr/F_ct is
calibrated so that the grid's f_av equals the controller's f unless given,
`pfm_stability.effective_force`) or ``env="analytic"`` (continuous walls with
KB's lumped power law, or ``law="grid"`` for the grid's averaged law without
quantization).

Modules: `grid` (histogram grid and drawing), `window` (occupied-cell lists
of the active windows), `vff` (KB eq 1–5), `robot` (exact steering solution,
quadrature of the motion), `environment` (analytic walls), `scenario`,
`presets`, `engine` (batched stepping), `events`, `metrics` (DESIGN §6),
`results`, `predict`, `bisect`, `api`, `reference`.
"""

from .api import simulate, simulate_batch
from .bisect import BoundaryEstimate, boundary_by_bisection
from .engine import run_batch
from .environment import AnalyticEnvironment, AnalyticWall
from .events import Event
from .grid import HistogramGrid
from .metrics import OscillationMetrics, oscillation_metrics
from .predict import Prediction, predict
from .presets import SCENARIO_NAMES, barely_avoiding_ratio, make_scenario
from .reference import simulate_reference
from .results import BatchResult, RunResult, Trajectory
from .scenario import MeasureAxis, Pose, Scenario, Target

__all__ = [
    "AnalyticEnvironment",
    "AnalyticWall",
    "BatchResult",
    "BoundaryEstimate",
    "Event",
    "HistogramGrid",
    "MeasureAxis",
    "OscillationMetrics",
    "Pose",
    "Prediction",
    "RunResult",
    "SCENARIO_NAMES",
    "Scenario",
    "Target",
    "Trajectory",
    "barely_avoiding_ratio",
    "boundary_by_bisection",
    "make_scenario",
    "oscillation_metrics",
    "predict",
    "run_batch",
    "simulate",
    "simulate_batch",
    "simulate_reference",
]
