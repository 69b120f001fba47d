"""Named scenarios: Koren & Borenstein 1991's figures and the validation geometries.

Every scenario is built for ``env="grid"`` (walls drawn as one-cell-thick
lines of CV-15 cells, KB §4: "a straight line of dots which indicate filled
cells") or ``env="analytic"`` (the same walls as continuous segments with a
lateral force law, `pfm_stability.sim.environment`), except ``kb-fig3`` whose
square obstacle exists in the grid only. Defaults are KB's CARMEL
(`pfm_stability.parameters.CARMEL`). X is lateral, Y forward.

Validation geometries (long, straight, target at infinity so α is constant):

``straight``
    No obstacles; start at the origin heading +Y, point target at (3, 10) m:
    the controller has to turn 17° and then reach it.
``corridor``
    Corridor along Y of half-width `L` (default 1 m), target straight ahead at
    infinity, start `offset` (default 0.02 m) right of the centre line. In
    the grid the walls sit on cell centres, so L is rounded to a multiple of
    c/2 (the value used is reported as ``L`` in the notes).
``wall``
    Wall along Y at X = 0, robot on its −X side, target at infinity at angle
    `alpha` (default 45°) from the wall normal (KB Fig 2, eq 9), start at the
    equilibrium distance d0 (KB eq 23, with the grid's effective law in the
    grid) plus `offset` (default 0.02 m) away from the wall.

Paper figures (geometry KB do not give is chosen to match their text):

``kb-fig3``
    Head-on approach at 0.8 m/s to a 40 × 40 cm obstacle (4 × 4 cells) whose
    centre is 4.45 m ahead; target 9 m ahead. The robot's line passes 5 cm
    (half a cell) beside the obstacle's centre: a 4-cell obstacle cannot be
    centred on a cell-centred path, and a perfectly symmetric approach would
    never turn. KB used this run to *set* F_cr/F_ct so that the robot "just
    barely" avoids the obstacle, so this preset does the same: unless
    `cell_ratio` is given, ρ = `barely_avoiding_ratio` (the smallest ratio
    that avoids it; f is not used) and the notes state its f_av. For CARMEL
    that is ρ = 0.00837, f_av = 2.15 — not the 0.8 KB report: the ratio with
    f_av = 0.8 (0.00311) collides in this run. On this model KB's two
    statements cannot both hold (their f_av averaging range is not given).
``kb-fig5``
    A wall with a corner: the robot follows a first wall section at α = 50°
    (stable), then the wall turns 30° towards the robot, so along the second
    section the same target direction makes α = 20° (KB: "a discontinuity in
    the wall (at α = 20°)"), below the grid's α* ≈ 33° (sampled model,
    command hold, one-sample delay, effective law). The second section lies
    along the grid's Y axis (its effective law is exact there); the first is
    drawn at 30°, a staircase of cells that pushes ≈ 1.33× harder, so the
    robot starts at that staircase's measured equilibrium
    (`pfm_stability.sim.vff.measured_equilibrium`). The target is at infinity
    so α is constant on each section.
``kb-fig6-wide`` / ``kb-fig6-narrow``
    KB §5.4: f_av = 0.8, n = 2, T = 0.065 s, τ = 0.3 s, V = 0.8 m/s. The
    robot starts on the centre line; at Y = 4 m the left wall steps 0.2 m into
    the passage (a jog drawn as a wall line) and stays there. Wide: 2.0 m →
    1.8 m (L = 0.9 m after the step); narrow: 1.4 m → 1.2 m (L = 0.6 m). With
    the grid's effective law the sampled model puts the boundary at
    L* = 0.69 m, so the wide corridor is stable with margin and the narrow one
    unstable; the corridor before the step is symmetric and unexcited.

Force ratio. In the grid, the controller's parameter is the cell ratio
ρ = F_cr/F_ct; KB's f is an output (f_av). Unless `cell_ratio` is given,
ρ = `calibrate_cell_ratio(f)`: the ρ whose grid wall has f_av = f averaged
over the window's working range d ∈ [(W + c)/2, (h + ½)c] = [0.45, 1.65] m
for CARMEL (ρ = 0.00311 for f = 0.8 with CV 15; `effective_force`). The law
of every preset's walls is `pfm_stability.sim.scenario.scenario_law`'s.
"""

from __future__ import annotations

import math
from functools import lru_cache

from ..checks import check_choice, check_number, describe_range
from ..laws.effective_force import GridWallLaw, f_average
from ..laws.force_law import ForceLaw, wall_equilibrium
from ..parameters import CARMEL, RANGES, Controller, Robot, Wall
from ..numerics.solve import bisect_batched
from .environment import AnalyticEnvironment, AnalyticWall
from .grid import HistogramGrid
from .scenario import LAW_NAMES, MeasureAxis, Pose, Scenario, Target, scenario_law
from .vff import measured_equilibrium

__all__ = ["SCENARIO_NAMES", "ENVS", "LAWS", "make_scenario", "barely_avoiding_ratio"]

SCENARIO_NAMES = ("straight", "corridor", "wall", "kb-fig3", "kb-fig5", "kb-fig6-wide", "kb-fig6-narrow")
ENVS = ("grid", "analytic")
LAWS = LAW_NAMES
"""Analytic-mode lateral laws: KB's lumped power law, or the grid's effective law (`scenario.LAW_NAMES`)."""

_MARGIN = 1.0
"""Grid margin around the scenario's walls, start and target, m."""

_FIG6 = {"kb-fig6-wide": 1.0, "kb-fig6-narrow": 0.7}
"""Half-width before the step, m."""
_FIG6_STEP = 0.2
_FIG6_Y = 4.0


# --------------------------------------------------------------- geometry
# A wall is (points, free_side): a polyline and the side of its direction where the robot is.


def _corridor_walls(L, y0, y1, centre=0.0):
    return [([(centre - L, y0), (centre - L, y1)], "right"), ([(centre + L, y0), (centre + L, y1)], "left")]


def _fig5_walls(length_before=6.0, length_after=14.0, turn=math.radians(30.0), corner=(0.0, 4.0)):
    cx, cy = corner
    start = (cx - length_before * math.sin(turn), cy - length_before * math.cos(turn))
    return [([start, corner, (cx, cy + length_after)], "left")]


def _fig6_walls(L1, step, y_step, y0, y1):
    left = [(-L1, y0), (-L1, y_step), (-L1 + step, y_step), (-L1 + step, y1)]
    return [(left, "right"), ([(L1, y0), (L1, y1)], "left")]


@lru_cache(maxsize=64)
def _grid(walls_key, blocks_key, bounds, cell_size) -> HistogramGrid:
    x_lo, x_hi, y_lo, y_hi = bounds
    grid = HistogramGrid.centred(x_lo, x_hi, y_lo, y_hi, cell_size=cell_size)
    for points, _ in walls_key:
        grid.draw_polyline(list(points))
    for x0, y0, x1, y1 in blocks_key:
        grid.draw_rectangle(x0, y0, x1, y1)
    return grid.freeze()


def _environment(env, walls, cell_size, extra_points=(), blocks=()):
    """A frozen HistogramGrid (shared between identical calls) or an AnalyticEnvironment."""
    if env == "analytic":
        segments = [
            AnalyticWall(p0, p1, side) for points, side in walls for p0, p1 in zip(points[:-1], points[1:])
        ]
        return AnalyticEnvironment(tuple(segments))
    xs = [p[0] for pts, _ in walls for p in pts] + [p[0] for p in extra_points] + [b[i] for b in blocks for i in (0, 2)]
    ys = [p[1] for pts, _ in walls for p in pts] + [p[1] for p in extra_points] + [b[i] for b in blocks for i in (1, 3)]
    bounds = (min(xs) - _MARGIN, max(xs) + _MARGIN, min(ys) - _MARGIN, max(ys) + _MARGIN)
    key = tuple((tuple(map(tuple, pts)), side) for pts, side in walls)
    return _grid(key, tuple(map(tuple, blocks)), tuple(round(b, 9) for b in bounds), cell_size)


# ---------------------------------------------------------------- builders
def _length(robot, duration) -> float:
    """How far walls extend ahead, m: past V·duration + 3 m, rounded up to 5 m so that
    batch members with similar speeds share one grid (one compiled window table)."""
    return 5.0 * math.ceil((robot.V * duration + 3.0) / 5.0)


def _grid_law(name, robot, controller, cell_ratio, window_cells, cell_size) -> tuple[GridWallLaw, str]:
    """The grid wall's law for this run (`scenario_law`) and how its cell ratio ρ = F_cr/F_ct was set."""
    if cell_ratio is not None:
        ratio, how = check_number("cell_ratio", cell_ratio, 0.0), "given"
    elif name == "kb-fig3":
        ratio = _fig3_ratio(robot, controller, window_cells, cell_size)
        how = "KB's Fig 3 procedure: the smallest ratio that avoids the obstacle (barely_avoiding_ratio)"
    else:
        ratio = None  # scenario_law calibrates
        how = f"calibrated: f_av = {controller.f:g} over d in [(W+c)/2, (h+1/2)c] (calibrate_cell_ratio)"
    return scenario_law("grid", robot, controller, window_cells, cell_size, cell_ratio=ratio), how


def _law_of(law, env, robot, controller, grid_law):
    """Analytic mode's lateral law (`scenario_law`): KB's power law, the grid's averaged law, or a given ForceLaw."""
    if env == "grid":
        if law is not None:
            raise ValueError("law applies to env=analytic only (the grid's law is its cells)")
        return None
    if isinstance(law, str) and law == "grid":  # the grid's law as drawn for this run (its ratio set by _grid_law)
        law = grid_law
    elif law is not None and not isinstance(law, ForceLaw):
        check_choice("law", law, LAWS)
    return scenario_law("analytic", robot, controller, law=law)


def _snap_L(L, cell_size):
    """Grid corridors: walls on cell centres → L a multiple of c/2; centre line at 0 or c/2."""
    halves = round(2 * L / cell_size)
    L_grid = halves * cell_size / 2
    centre = 0.0 if halves % 2 == 0 else cell_size / 2
    return L_grid, centre


def _check_fits(L, robot, env, cell_size, name="L", given=None):
    """The robot must fit between the walls: L > W/2 (analytic) or L − c/2 > W/2 (grid faces)."""
    face = cell_size / 2 if env == "grid" else 0.0
    low = robot.W / 2 + face
    if not L > low:
        where = "W/2 + c/2" if env == "grid" else "W/2"
        high = RANGES["L"].high
        got = f"{given!r} ({L:g} on the cell grid)" if given is not None and abs(given - L) > 1e-12 else f"{given if given is not None else L!r}"
        raise ValueError(f"{name} must be a finite number in ({where}, {high:g}] m = ({low:g}, {high:g}] m (the robot must fit); got {got}")


_DEFAULT_OFFSET = 0.02
"""Start offset from the equilibrium line when none is given, m (``corridor``, ``wall``)."""


def _offset(o, low: float, high: float, why: str) -> float:
    """The start offset, m: the given one, checked to lie in (low, high) — a start where the robot disc fits — or the
    default (0.02 m, or half the free play of a narrower corridor: never a value outside the range)."""
    given = o["offset"]
    if given is None:
        return min(_DEFAULT_OFFSET, 0.5 * high)
    try:
        return check_number("offset", given, low, high, unit="m")
    except ValueError:
        raise ValueError(f"offset must be a finite number in {describe_range(low, high, True, True)} m ({why}); got {given!r}") from None


def _corridor(o):
    L = check_number("L", o["L"] if o["L"] is not None else 1.0, 0.0, unit="m")
    env, c, robot = o["env"], o["cell_size"], o["robot"]
    notes = {}
    centre, given = 0.0, L
    if env == "grid":
        L, centre = _snap_L(L, c)
        notes["L"] = f"{L:g} m (walls on cell centres: L rounded to a multiple of c/2 = {c / 2:g} m from {given:g})"
    _check_fits(L, robot, env, c, given=given)
    face = c / 2 if env == "grid" else 0.0
    play = L - robot.W / 2 - face  # the robot disc touches a wall at |offset| = play
    drawn = " as drawn on the grid" if env == "grid" else ""
    offset = _offset(o, -play, play, f"the robot disc must lie inside the corridor, clear of its walls: |offset| < L - W/2"
                     f"{' - c/2' if face else ''} with L = {L:g} m{drawn}, W = {robot.W:g} m{f', c = {c:g} m' if face else ''}")
    duration = o["duration"] or 20.0
    walls = _corridor_walls(L, -3.0, _length(robot, duration), centre)
    start = Pose(centre + offset, 0.0, 0.0)
    target = Target.direction(0.0)
    measure = MeasureAxis((centre, 0.0), 0.0)
    notes["geometry"] = f"straight corridor along Y, half-width L = {L:g} m, target at infinity straight ahead (alpha constant)"
    return dict(walls=walls, start=start, target=target, duration=duration, measure=measure, notes=notes, analysis={"kind": "corridor", "L": L})


def _wall(o):
    alpha = Wall(o["alpha"]).alpha if o["alpha"] is not None else math.radians(45.0)
    alpha_deg = math.degrees(alpha)
    env, robot, c = o["env"], o["robot"], o["cell_size"]
    law = o["law_object"] or o["grid_law"]
    d0 = wall_equilibrium(law, alpha)  # the nearest of a non-monotone law's equilibria (docs/fields.md)
    contact = robot.W / 2 + (c / 2 if env == "grid" else 0.0)
    if not (math.isfinite(d0) and d0 > contact):
        raise ValueError(
            f"alpha must give an equilibrium distance d0 > {contact:g} m (robot clear of the wall); "
            f"alpha = {alpha_deg:g} deg gives d0 = {d0:.3g} m"
        )
    offset = _offset(o, contact - d0, math.inf, f"the robot disc must start clear of the wall: d0 + offset > W/2"
                     f"{' + c/2' if env == 'grid' else ''} = {contact:g} m with d0 = {d0:.4g} m")
    duration = o["duration"] or 20.0
    walls = [([(0.0, -3.0), (0.0, _length(robot, duration))], "left")]
    notes = {
        "geometry": f"wall along Y at X = 0, robot on the -X side, target at infinity at alpha = {alpha_deg:g} deg from the wall normal",
        "d0": f"{d0:.4f} m equilibrium distance (KB eq 22-23 with the {law.name})",
    }
    if env == "grid" and d0 > law.reach:
        raise ValueError(
            f"alpha = {alpha_deg:g} deg puts the grid wall's equilibrium at d0 = {d0:.4g} m, beyond the active window's "
            f"reach {law.reach:g} m, where the grid wall exerts no force: choose a smaller alpha, a larger f or "
            f"cell ratio, a larger window, or env=analytic"
        )
    return dict(
        walls=walls,
        start=Pose(-d0 - offset, 0.0, 0.0),
        target=Target.direction(math.pi / 2 - alpha),
        duration=duration,
        measure=MeasureAxis((-d0, 0.0), 0.0),
        notes=notes,
        analysis={"kind": "wall", "alpha": alpha},
    )


def _straight(o):
    return dict(
        walls=[],
        start=Pose(0.0, 0.0, 0.0),
        target=Target.point(3.0, 10.0, radius=0.2),
        duration=o["duration"] or 20.0,
        measure=MeasureAxis(),
        notes={"geometry": "open field, start at the origin heading +Y, point target at (3, 10) m"},
    )


def _fig3(o):
    if o["env"] != "grid":
        raise ValueError("env must be grid for kb-fig3 (its square obstacle is a block of cells)")
    block = (-0.2, 4.3, 0.1, 4.6)  # cell centres of a 4 x 4-cell block: 40 x 40 cm, centre (-0.05, 4.45)
    return dict(
        walls=[],
        blocks=[block],
        start=Pose(0.0, 0.0, 0.0),
        target=Target.point(0.0, 9.0, radius=0.2),
        duration=o["duration"] or 16.0,
        measure=MeasureAxis(),
        notes={
            "geometry": "40 x 40 cm obstacle (4 x 4 cells) centred at (-0.05, 4.45) m, 5 cm beside the start-target line; "
            "start (0, 0) heading +Y at 0.8 m/s, target (0, 9) m",
        },
    )


def _fig5(o):
    walls = _fig5_walls()
    env = o["env"]
    law = o["law_object"] or o["grid_law"]
    alpha1 = math.radians(50.0)
    turn = math.radians(30.0)
    if env == "grid":  # the first section is a 30° staircase of cells: its own (stronger) law
        d0 = measured_equilibrium(law, turn, math.cos(alpha1))
    else:
        d0 = law.distance_for(math.cos(alpha1))
    # start 5 m before the corner, d0 from the first section, heading along it
    along = 5.0
    sx = 0.0 - along * math.sin(turn) - d0 * math.cos(turn)
    sy = 4.0 - along * math.cos(turn) + d0 * math.sin(turn)
    target_angle = math.pi / 2 - math.radians(20.0)  # alpha = 20 deg from the second section's normal (+X)
    return dict(
        walls=walls,
        start=Pose(sx, sy, turn),
        target=Target.direction(target_angle),
        duration=o["duration"] or 20.0,
        measure=MeasureAxis((0.0, 4.0), 0.0, along_from=0.5),
        analysis={"kind": "wall", "alpha": math.radians(20.0)},
        notes={
            "geometry": "wall section 1 at 30 deg to Y ending at the corner (0, 4) m, section 2 along +Y from the corner; "
            "target at infinity 70 deg right of +Y: alpha = 50 deg on section 1, 20 deg on section 2",
            "start": f"5 m before the corner at the section-1 equilibrium distance d0 = {d0:.3f} m "
            + ("(measured on the drawn 30-deg staircase, measured_wall_force)" if env == "grid" else ""),
            "measure": "lateral offset along section 2, from 0.5 m past the corner",
        },
    )


def _fig6(o):
    L1 = _FIG6[o["name"]]
    env, robot = o["env"], o["robot"]
    duration = o["duration"] or 16.0
    walls = _fig6_walls(L1, _FIG6_STEP, _FIG6_Y, -3.0, _length(robot, duration))
    L2 = L1 - _FIG6_STEP / 2
    _check_fits(L2, robot, env, o["cell_size"], name="corridor half-width after the step")
    return dict(
        walls=walls,
        start=Pose(0.0, 0.0, 0.0),
        target=Target.direction(0.0),
        duration=duration,
        measure=MeasureAxis((_FIG6_STEP / 2, _FIG6_Y), 0.0, along_from=0.0),
        analysis={"kind": "corridor", "L": L2},
        notes={
            "geometry": f"corridor {2 * L1:g} m wide; at Y = {_FIG6_Y:g} m the left wall steps {_FIG6_STEP:g} m into the "
            f"passage: {2 * L2:g} m wide (L = {L2:g} m) after the step; target at infinity straight ahead",
            "measure": f"lateral offset from Y = {_FIG6_Y:g} m on",
        },
    )


_BUILDERS = {
    "straight": (_straight, ()),
    "corridor": (_corridor, ("L", "offset")),
    "wall": (_wall, ("alpha", "offset")),
    "kb-fig3": (_fig3, ()),
    "kb-fig5": (_fig5, ()),
    "kb-fig6-wide": (_fig6, ()),
    "kb-fig6-narrow": (_fig6, ()),
}


def make_scenario(
    name: str,
    *,
    robot: Robot | None = None,
    controller: Controller | None = None,
    env: str = "grid",
    L: float | None = None,
    alpha: float | None = None,
    offset: float | None = None,
    duration: float | None = None,
    cell_ratio: float | None = None,
    law=None,
    window_cells: int = 33,
    cell_size: float = 0.1,
    speed_law: bool = False,
    seed: int | None = None,
    start_jitter: float = 0.0,
    damping: float = 0.0,
) -> Scenario:
    """Build the named scenario (module docstring) for one robot and controller.

    Parameters
    ----------
    name : str
        One of `SCENARIO_NAMES`.
    robot, controller : Robot, Controller
        Default: KB's CARMEL (`pfm_stability.parameters.CARMEL`).
    env : {"grid", "analytic"}
    L : float, optional
        ``corridor``: half-width, m (default 1).
    alpha : float, optional
        ``wall``: target angle from the wall normal, rad (default 45°).
    offset : float, optional
        ``corridor``/``wall``: start offset from the equilibrium line, m
        (positive = right of the corridor centre, away from the wall). The
        robot disc must start inside the corridor, clear of both walls:
        |offset| < L − W/2 (− c/2 in the grid, L as drawn); beside a wall,
        clear of it: offset > W/2 (+ c/2) − d0. Default 0.02, or half the
        free play L − W/2 (− c/2) of a narrower corridor.
    duration : float, optional
        s (default per scenario).
    cell_ratio : float, optional
        Grid: ρ = F_cr/F_ct (default: calibrated to f_av = controller.f).
        Analytic with ``law="grid"``: the ratio of that law.
    law : {"power", "grid"} or ForceLaw, optional
        Analytic: KB's lumped power law (default) or the grid's effective law.
    window_cells, cell_size
        Grid window side (odd) and cell size (m).
    speed_law : bool
        VFF speed law instead of constant speed.
    seed, start_jitter
        Random lateral start offset with standard deviation `start_jitter` m.
    damping : float
        β of a velocity-dependent force −β·v (F_ct per m/s, >= 0): a field
        with a heading gain c = βV/F_y (docs/fields.md).

    Raises
    ------
    ValueError
        Unknown name, an option the scenario does not take, or an impossible
        geometry (robot wider than the corridor, …).
    """
    check_choice("scenario", name, SCENARIO_NAMES)
    check_choice("env", env, ENVS)
    robot = robot if robot is not None else CARMEL.robot
    controller = controller if controller is not None else CARMEL.controller
    builder, accepted = _BUILDERS[name]
    for option, value in (("L", L), ("alpha", alpha), ("offset", offset)):
        if value is not None and option not in accepted:
            raise ValueError(f"{option} does not apply to scenario {name}")
    cell_size = check_number("cell_size", cell_size, 0.0, unit="m")
    if duration is not None:
        duration = check_number("duration", duration, 0.0, 1e6, unit="s")
    grid_law = calibration = None
    uses_grid_law = env == "grid" or (isinstance(law, str) and law == "grid")
    if cell_ratio is not None and not uses_grid_law:
        raise ValueError("cell_ratio applies to env=grid, or to env=analytic with law=grid")
    if uses_grid_law:
        grid_law, calibration = _grid_law(name, robot, controller, cell_ratio, window_cells, cell_size)
    law_object = _law_of(law, env, robot, controller, grid_law)
    options = dict(
        name=name, robot=robot, controller=controller, env=env, L=L, alpha=alpha, offset=offset,
        duration=duration, cell_size=cell_size, law_object=law_object, grid_law=grid_law,
    )
    spec = builder(options)
    extra = [(spec["start"].x, spec["start"].y)]
    if spec["target"].is_point:
        extra.append((spec["target"].x, spec["target"].y))
    environment = _environment(env, spec["walls"], cell_size, extra, spec.get("blocks", ()))
    notes = dict(spec["notes"])
    if env == "grid":
        notes["cell_ratio"] = f"F_cr/F_ct = {grid_law.ratio:.6g} (CV {grid_law.cv}), {calibration}"
        notes["f_av"] = f"{f_average(grid_law):.4g} (KB's lumped f of this grid over its working range)"
    else:
        notes["law"] = law_object.name
    return Scenario(
        name=name,
        robot=robot,
        controller=controller,
        environment=environment,
        start=spec["start"],
        target=spec["target"],
        duration=spec["duration"],
        cell_ratio=grid_law.ratio if env == "grid" else None,
        law=law_object,
        window_cells=window_cells,
        measure=spec["measure"],
        speed_law=speed_law,
        analysis=spec.get("analysis"),
        seed=seed,
        start_jitter=start_jitter,
        damping=check_number("damping", damping, 0.0, 1e6, low_open=False, unit="F_ct s/m"),
        notes=notes,
    )


@lru_cache(maxsize=16)
def _fig3_ratio(robot, controller, window_cells, cell_size) -> float:
    return barely_avoiding_ratio(robot, controller, window_cells=window_cells, cell_size=cell_size)


def barely_avoiding_ratio(
    robot: Robot | None = None,
    controller: Controller | None = None,
    *,
    window_cells: int = 33,
    cell_size: float = 0.1,
    members: int = 24,
    rounds: int = 3,
) -> float:
    """KB's own calibration (their Fig 3): the smallest cell ratio with which the head-on run avoids the obstacle.

    `pfm_stability.numerics.solve.bisect_batched` on ρ = F_cr/F_ct in [1e-4, 0.1]
    (geometric), `rounds` rounds: the first simulates `members` ratios across
    the bracket (its ends included) in one batch, each later one the
    `members` − 2 inside the current bracket; each keeps the interval between
    the largest colliding and the smallest avoiding ratio.

    Parameters
    ----------
    robot, controller : Robot, Controller, optional
        Default CARMEL.
    window_cells : int
        The active window's side, cells (odd).
    cell_size : float
        Cell side, m.
    members : int
        Ratios simulated per round.
    rounds : int
        Rounds of the bisection.

    Returns
    -------
    float
        ρ, the bracket's avoiding end, to a relative precision of about
        (bracket ratio)^(1/(members − 1)^rounds).

    Raises
    ------
    ValueError
        If every ratio in [1e-4, 0.1] collides, or none does.
    """
    from .engine import run_batch

    batches = []

    def avoids(ratios):
        scenarios = [
            make_scenario("kb-fig3", robot=robot, controller=controller, cell_ratio=float(r), window_cells=window_cells, cell_size=cell_size)
            for r in ratios
        ]
        batches.append(~run_batch(scenarios, record="offset", metrics=False).collided)
        return batches[-1]

    try:
        bracket = bisect_batched(avoids, 1e-4, 1e-1, members=members, geometric=True, rtol=0.0, max_rounds=rounds)
    except ValueError:
        if len(batches) == 1 and batches[0][0] == batches[0][-1]:  # the same outcome at both ends
            raise ValueError("kb-fig3: no sign change of the collision over cell ratios in [1e-4, 0.1]") from None
        raise
    return bracket.hi
