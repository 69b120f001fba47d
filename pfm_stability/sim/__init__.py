"""Time-domain simulator of the VFF algorithm driving a CARMEL-like robot (docs/simulator.md).

Koren & Borenstein 1991 (KB) §2 (VFF on a histogram grid, eq 1–5) drives the
synchro-drive robot of §3–4 (steering lag eq 6, |u| <= 120°/s; a real
robot's plant gain g and dead time D too, τω̇ + ω = g·u(t − D)), sampled
exactly as the `sampled` loop model (docs/models.md: ``hold="command"`` or
``"reference"``, ``compute_delay`` 0 or 1), so that in the linear regime the
simulated σ and ω equal the model's dominant pole to round-off. The
simulator imports none of the prediction modules (models, criteria,
regions, report): `pfm_stability.validation` is where the two meet.

Library API
-----------
``simulate(scenario_or_name, *, record="trajectory", **options) -> RunResult``
    One run; ``options`` go to `make_scenario`.
``simulate_batch(name, *, env="grid", robot=None, controller=None, record="offset", metrics=True, **arrays) -> BatchResult``
    Many parameter sets at once: each of ``V, tau, k, W, max_steering_rate,
    dead_time, plant_gain, f, n, T, hold, compute_delay, L, alpha (rad), offset, duration,
    cell_ratio, law, window_cells, cell_size, speed_law, seed,
    start_jitter`` may be a scalar or a 1-D array (one entry per member).
    ``BatchResult.stable / .oscillating / .collided`` are bool arrays
    (``stable``: the run settled, see `verdict`),
    ``.growth_rate / .angular_frequency`` masked arrays (masked = undefined,
    the reason is in ``.runs[i].metrics.reason``), ``.runs[i]`` the full
    `RunResult` (events, metrics, inputs, `to_dict`).
``simulated_verdict(run) -> (verdict, basis)`` / ``linearly_stable(batch)``
    The linear-stability verdict (sign of σ; collision: unstable), what the
    loop models predict — not the settled flag ``stable`` (module `verdict`).
``make_scenario(name, *, robot, controller, env, L, alpha, offset, duration, cell_ratio, law, window_cells, cell_size, speed_law, seed, start_jitter) -> Scenario``
    Presets: ``straight``, ``corridor``, ``wall`` (validation geometries,
    target at infinity) and ``kb-fig3``, ``kb-fig5``, ``kb-fig6-wide``,
    ``kb-fig6-narrow`` (KB's figures; geometry choices in
    `pfm_stability.sim.presets`).
``scenario_law(env, robot, controller, …) -> ForceLaw``
    The lateral law a straight wall of the environment exerts: the one place
    that decides it (`Scenario.effective_law`, the presets and the validation use it).
``measured_wall_force(law, d, angle)``
    A wall drawn into a grid, its VFF window summed: the check of `GridWallLaw`.
``run_batch(scenarios, *, record, metrics) -> BatchResult``
    The engine, for hand-built `Scenario` objects (own grids: `HistogramGrid`;
    analytic walls: `AnalyticEnvironment`).
``simulate_reference(scenario) -> (Trajectory, Event | None)``
    The same model in a plain per-robot Python loop (baseline, cross-check).

``simulate_planar(robot, field, world, *, T, compute_delay, duration, start) -> PlanarRun``
    Ge & Cui 2002's robots — `PointMass` (holonomic, a = F/m saturated at
    a_max), `Steering` (KB's robot) and `DiffDrive` (GC2002 §7) — in a
    velocity-aware field with fixed or moving targets and obstacles (`sim.movers`),
    events at v_RO = 0, D = ρ0 and D ≤ 0 (docs/simulator.md, "Planar robots").
``wall_cycle(repulsion, attraction, alpha, robot, *, T, …) -> WallCycle``
    The limit cycle (or rest) of a robot beside a wall with velocity-gated repulsion.
``simulate_planar_batch(members) -> PlanarBatch``
    Many `PlanarMember` runs stepped together in arrays (the two above are batches of one).
``simulate_tracking(scenarios) -> BatchResult``
    Nav2's controllers (`pfm_stability.controllers`: RPP, Graceful, MPPI, DWB) driving the same plant along a
    straight plan or corridor (`TrackingScenario`; docs/controllers.md).

Predictions for a scenario (`predict`) and the simulated stability boundary
(`boundary_by_bisection`) join simulations with the models: they are in
`pfm_stability.validation`.

Environments: ``env="grid"`` (cells of CV 15; the cell ratio ρ = F_cr/F_ct is
calibrated so that the grid's f_av equals the controller's f unless given,
`pfm_stability.laws.effective_force`) or ``env="analytic"`` (continuous walls with
KB's lumped power law, or ``law="grid"`` for the grid's averaged law without
quantization).

Modules: `grid` (histogram grid and drawing), `window` (occupied-cell lists
of the active windows), `vff` (KB eq 1–5, the measured wall force), `robot`
(exact steering solution, quadrature of the motion), `environment` (analytic
walls), `scenario` (and `scenario_law`), `presets`, `engine` (batched
stepping), `events`, `metrics` (docs/simulator.md, measuring oscillation),
`verdict`, `results`, `api`, `reference`; the planar simulator: `planar`,
`planar_batch` (batched stepping), `planar_field`, `planar_robots`, `movers`, `cycles`; Nav2's controllers on the
plant: `tracking`.
"""

from .api import simulate, simulate_batch
from .engine import run_batch
from .environment import AnalyticEnvironment, AnalyticWall
from .events import Event
from .grid import HistogramGrid
from .metrics import OscillationMetrics, oscillation_metrics
from .planar import DiffDrive, PlanarBatch, PlanarMember, PlanarRun, PointMass, Steering, WallCycle, simulate_planar, simulate_planar_batch, wall_cycle
from .presets import SCENARIO_NAMES, barely_avoiding_ratio, make_scenario
from .reference import simulate_reference
from .results import BatchResult, RunResult, Trajectory
from .scenario import MeasureAxis, Pose, Scenario, Target, scenario_law
from .tracking import TrackingScenario, simulate_tracking
from .verdict import linearly_stable, simulated_verdict
from .vff import measured_wall_force

__all__ = [
    "SCENARIO_NAMES",
    "AnalyticEnvironment",
    "AnalyticWall",
    "BatchResult",
    "DiffDrive",
    "Event",
    "HistogramGrid",
    "MeasureAxis",
    "OscillationMetrics",
    "PlanarBatch",
    "PlanarMember",
    "PlanarRun",
    "PointMass",
    "Pose",
    "RunResult",
    "Scenario",
    "Steering",
    "Target",
    "Trajectory",
    "TrackingScenario",
    "WallCycle",
    "barely_avoiding_ratio",
    "linearly_stable",
    "make_scenario",
    "measured_wall_force",
    "oscillation_metrics",
    "run_batch",
    "scenario_law",
    "simulate",
    "simulate_batch",
    "simulate_planar",
    "simulate_planar_batch",
    "simulate_reference",
    "simulate_tracking",
    "simulated_verdict",
    "wall_cycle",
]
