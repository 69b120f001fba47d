"""Occupancy maps (`pfm_stability.maps`, docs/maps.md): the reader, the field, the corridor verdicts, the speed mask.

Every verdict is checked against an independent route: the field against the
simulator's own window sum (`sim.vff.window_repulsion`), N and V* of a synthetic
corridor against `criteria.analyze_corridor` with the grid law (what
``report --law grid`` prints), the reader against the map_server rules written out
by hand on single pixels, and the mask against Nav2's decoding formula and Nav2's own
example mask.
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from pfm_stability.analysis.criteria import analyze_corridor
from pfm_stability.laws.fields import make_law
from pfm_stability.maps.analysis import analyze_map, sample_verdict
from pfm_stability.maps.reading.field import (
    HistogramMap,
    centre_field,
    histogram_of,
    window_force,
)
from pfm_stability.maps.reading.occupancy import load_map, occupancy_values
from pfm_stability.maps.deciding.outputs import percent_to_pixel, pixel_to_percent
from pfm_stability.models import Loop, models_for
from pfm_stability.parameters import CARMEL, Corridor
from pfm_stability.sim.grid import HistogramGrid
from pfm_stability.sim.vff import window_repulsion

MAPS = Path(str(resources.files("pfm_stability").joinpath("data", "maps")))
ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller


def write_map(directory: Path, pixels: np.ndarray, *, resolution=0.1, origin=(0.0, 0.0, 0.0), negate=0, occupied=0.65, free=0.196,
              mode=None, name="m", image_name=None) -> Path:
    """A map_server map (PGM + YAML) of `pixels` (row 0 at the top) in `directory`."""
    image_name = image_name or f"{name}.pgm"
    Image.fromarray(np.asarray(pixels, dtype=np.uint8)).save(directory / image_name)
    text = (f"image: {image_name}\nresolution: {resolution}\norigin: [{origin[0]}, {origin[1]}, {origin[2]}]\nnegate: {negate}\n"
            f"occupied_thresh: {occupied}\nfree_thresh: {free}\n" + (f"mode: {mode}\n" if mode else ""))
    path = directory / f"{name}.yaml"
    path.write_text(text)
    return path


def corridor_pixels(L: float, c: float = 0.1, length: int = 200) -> np.ndarray:
    """A straight corridor along y, one-cell walls at x = ±L on cell centres, nothing else (the window sees only the walls)."""
    half = round(L / c)
    img = np.full((length, 2 * half + 1), 254, dtype=np.uint8)
    img[:, 0] = img[:, -1] = 0
    return img


# ------------------------------------------------------------------ the reader
def test_single_occupied_pixel_lands_at_its_coordinates(tmp_path):
    """Row 0 of the image is the top (largest y): one black pixel at image (row 1, col 3) of a 5 x 4 map is cell (i=3, j=3)."""
    img = np.full((5, 4), 254, dtype=np.uint8)
    img[1, 3] = 0
    m = load_map(write_map(tmp_path, img, resolution=0.5, origin=(-1.0, 2.0, 0.0)))
    j, i = np.argwhere(m.occupied)[0]
    assert (m.width, m.height, int(i), int(j)) == (4, 5, 3, 3)
    x, y = -1.0 + (i + 0.5) * 0.5, 2.0 + (j + 0.5) * 0.5
    assert (x, y) == (0.75, 3.75) and m.occupied.sum() == 1
    assert m.cell_of(x, y) == (3, 3)


@pytest.mark.parametrize("negate", [0, 1])
def test_trinary_thresholds_and_negate(tmp_path, negate):
    """p = (255 − v)/255 (v/255 with negate): occupied above occupied_thresh, free below free_thresh, unknown between."""
    values = np.arange(256, dtype=np.uint8).reshape(16, 16)
    m = load_map(write_map(tmp_path, values, negate=negate, occupied=0.65, free=0.25))
    p = values[::-1].astype(float) / 255.0
    p = p if negate else 1.0 - p
    assert np.array_equal(m.occupied, p > 0.65) and np.array_equal(m.free, p < 0.25)
    assert np.array_equal(m.values[m.unknown], np.full(m.unknown.sum(), -1))


def test_scale_and_raw_modes(tmp_path):
    """scale: rint(100 (p − free)/(occ − free)) between the thresholds; raw: the pixel value itself if <= 100, else unknown."""
    values = np.array([[0, 60, 127, 200, 255]], dtype=np.uint8)
    scale = load_map(write_map(tmp_path, values, mode="scale", occupied=0.9, free=0.1, name="s"))
    p = 1.0 - values[0] / 255.0
    expected = np.where(p > 0.9, 100, np.where(p < 0.1, 0, np.rint((p - 0.1) / 0.8 * 100)))
    assert scale.values[0].tolist() == expected.astype(int).tolist()
    raw = load_map(write_map(tmp_path, values, mode="raw", name="r"))
    assert raw.values[0].tolist() == [0, 60, -1, -1, -1]


def test_nav2_example_mask_decodes_to_its_percentages():
    """Nav2's depot_speed mask (scale, free 0, occupied 1) holds 0, 20, 25, 50 and 100 %: our reader gives those values,
    and so does the formula our mask writer inverts (`pixel_to_percent`)."""
    m = load_map(MAPS / "depot_speed.yaml")
    assert sorted(np.unique(m.values).tolist()) == [0, 20, 25, 50, 100]
    pixels = np.array(Image.open(MAPS / "depot_speed.pgm"))[::-1]
    assert np.array_equal(pixel_to_percent(pixels), m.values)


def test_mask_encoding_is_exact_for_every_percentage():
    """Writing q as 255 − round(2.55 q) and reading it the way Nav2 does gives q back, for q = 0 … 100."""
    q = np.arange(101)
    assert np.array_equal(pixel_to_percent(percent_to_pixel(q)), q)
    assert np.array_equal(occupancy_values(percent_to_pixel(q) / 255.0, np.ones(101, bool), mode="scale", negate=False,
                                           occupied_thresh=1.0, free_thresh=0.0), q)


def test_unknown_as_occupied_or_free(tmp_path):
    """Unknown pixels are obstacles of the histogram grid by default, free space with unknown='free'."""
    img = np.full((10, 10), 254, dtype=np.uint8)
    img[:, :5] = 205
    m = load_map(write_map(tmp_path, img))
    assert histogram_of(m, 0.1).occupied.sum() == 50
    assert histogram_of(m, 0.1, unknown="free").occupied.sum() == 0


def test_histogram_reduction_coarser_than_the_map(tmp_path):
    """A 0.03 m map onto 0.1 m cells: a cell is occupied when the centre of an occupied pixel falls into it."""
    img = np.full((20, 20), 254, dtype=np.uint8)
    img[19, 10] = 0  # bottom row, column 10: centre x = 0.315 m -> cell i = 3, y = 0.015 -> j = 0
    g = histogram_of(load_map(write_map(tmp_path, img, resolution=0.03)), 0.1)
    assert g.shape == (6, 6) and np.argwhere(g.occupied).tolist() == [[3, 0]]


# ------------------------------------------------------------------ the field
def test_field_equals_the_simulators_window_sum_on_a_random_map():
    """At cell centres (FFT) and at random points (exact sum with its Jacobian) the field is the simulator's
    `window_repulsion` to round-off (1e-12 of the largest force: FFT round-off), with n = 3 and a 21-cell window
    to test more than CARMEL's numbers; the Jacobian matches central differences to 1e-5 (step 1e-6 m)."""
    rng = np.random.default_rng(7)
    law = make_law("grid", ROBOT.replace(W=0.5), CONTROLLER.replace(n=3.0), cell_size=0.1, window_cells=21, cell_ratio=0.37)
    nx, ny = 47, 38
    cv = np.where(rng.random((nx, ny)) < 0.15, 15, 0).astype(np.int16)
    hmap = HistogramMap(-1.3, 2.2, 0.1, cv)
    sim = HistogramGrid(-1.3, 2.2, nx * 0.1, ny * 0.1, cell_size=0.1)
    sim.cv[:] = cv
    sim.freeze()
    fx, fy = centre_field(hmap, law)
    i, j = np.nonzero(cv == 0)
    x, y = hmap.cell_center(i, j)
    rx, ry = window_repulsion(sim, x, y, ratio=law.ratio, n=law.n, W=law.W, window_cells=21)
    scale = np.abs(np.concatenate([rx, ry])).max()
    assert np.abs(fx[i, j] - rx).max() < 1e-12 * scale and np.abs(fy[i, j] - ry).max() < 1e-12 * scale
    px, py = rng.uniform(-3, 5, 3000), rng.uniform(0, 8, 3000)
    ex = window_force(hmap, law, px, py, jacobian=True)
    rx, ry = window_repulsion(sim, px, py, ratio=law.ratio, n=law.n, W=law.W, window_cells=21)
    ok = np.isfinite(rx)
    assert np.allclose(ex[0][ok], rx[ok], rtol=1e-12, atol=1e-13 * scale) and np.allclose(ex[1][ok], ry[ok], rtol=1e-12, atol=1e-13 * scale)
    h = 1e-6
    dfx = (window_force(hmap, law, px + h, py)[0] - window_force(hmap, law, px - h, py)[0]) / (2 * h)
    same_cell = ok & (np.floor((px + h + 1.3) / 0.1) == np.floor((px - h + 1.3) / 0.1))
    assert np.abs(dfx[same_cell] - ex[2][same_cell]).max() < 1e-5 * np.abs(ex[2][same_cell]).max()


def test_the_field_does_not_depend_on_how_its_sum_is_chunked(monkeypatch):
    """`window_force` sums a chunk of points at a time (`field.CHUNK_ENTRIES` window cells): chunks of 37 cells —
    hundreds of chunks, and points with more cells than a chunk, alone in theirs — give the one-chunk answer to 4 ULP
    (each point's cells are summed in the same order either way, by one `np.bincount`), points off the grid included."""
    from pfm_stability.maps.reading import field

    rng = np.random.default_rng(11)
    law = make_law("grid", ROBOT, CONTROLLER, cell_size=0.1, window_cells=15)
    cv = np.where(rng.random((40, 30)) < 0.2, 15, 0).astype(np.int16)
    hmap = HistogramMap(0.0, 0.0, 0.1, cv)
    px, py = rng.uniform(-1.0, 5.0, 2000), rng.uniform(-1.0, 4.0, 2000)
    whole = window_force(hmap, law, px, py, jacobian=True)
    monkeypatch.setattr(field, "CHUNK_ENTRIES", 37)
    chunked = window_force(hmap, law, px, py, jacobian=True)
    for a, b in zip(whole, chunked):
        ok = np.isfinite(a)
        np.testing.assert_array_equal(np.isfinite(b), ok)
        assert np.all(np.abs(a[ok] - b[ok]) <= 4 * np.spacing(np.abs(a[ok]))) and np.abs(a[ok]).max() > 0


# ------------------------------------------------------------------ corridors against report --law grid
@pytest.mark.parametrize("L, n, f", [(0.9, 2.0, 0.8), (1.2, 2.0, 0.8), (0.7, 1.5, 2.5)])
def test_straight_corridor_matches_the_report(tmp_path, L, n, f):
    """The middle of a straight axis-aligned corridor gives the equilibrium on its centre line, and N and V* of
    `analyze_corridor` with the grid law (what ``report --law grid`` prints) to 2e-3 (the brief's bar is 1 %): the map
    averages the window sum over the robot's position in its cell by Gauss–Legendre, the law integrates the same average
    in closed form (4 nodes: ~1e-6); what remains (up to 5e-4) is the segment's tilt — the skeleton's ends put it
    a few cm off the axis over 18 m — and the far ends of the 20 m corridor inside the window."""
    controller = CONTROLLER.replace(n=n, f=f)
    law = make_law("grid", ROBOT, controller)
    analysis = analyze_map(load_map(write_map(tmp_path, corridor_pixels(L))), ROBOT, controller, law)
    s = analysis.samples
    middle = np.isfinite(s.N) & (np.abs(s.y - 10.0) < 4.0)
    segment = analysis.segments[s.segment[middle][0]]
    length = segment.length
    normal_x = -(segment.y1 - segment.y0) / length  # the left normal's x component
    assert middle.sum() > 50 and np.abs(s.x[middle] + s.offset[middle] * normal_x - (L + 0.05)).max() < 1e-6  # on the centre line
    ref = analyze_corridor(ROBOT, controller, Corridor(L), ["sampled"], law=law)
    assert np.abs(s.N[middle] / ref.N - 1).max() < 2e-3
    boundary = models_for(controller, ["sampled"])[0].boundary(Loop(ROBOT.tau, controller.T, ROBOT.k))
    V_star = sample_verdict(float(np.mean(s.N[middle])), ROBOT.V, boundary, True).V_critical  # N > 0: the N = 0 verdict is not read
    assert V_star == pytest.approx(ref.models["sampled"].critical["V_critical"], rel=2e-3)


def test_rotated_corridor_matches_the_report_with_its_wall_density(tmp_path):
    """A corridor at 30° drawn as every cell its walls pass through (a staircase, like `HistogramGrid.draw_segment`)
    has (sin 30° + cos 30°)/c cells per metre of wall instead of 1/c: against the grid law with the cell ratio scaled
    by that density, N in its middle agrees to 3 % (what remains is the staircase's lateral quantization)."""
    L, angle, c = 0.9, math.radians(30), 0.1
    ny, nx = 260, 200
    img = np.full((ny, nx), 254, dtype=np.uint8)
    cx, cy = 10.0, 13.0
    t = np.linspace(-10 / math.cos(angle), 10 / math.cos(angle), 4000)
    for side in (-1, 1):
        x = cx + t * math.sin(angle) + side * L * math.cos(angle)
        y = cy + t * math.cos(angle) - side * L * math.sin(angle)
        img[ny - 1 - np.floor(y / c).astype(int), np.floor(x / c).astype(int)] = 0
    law = make_law("grid", ROBOT, CONTROLLER)
    analysis = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, law)
    s = analysis.samples
    u = (math.sin(angle), math.cos(angle))
    along = (s.x - cx) * u[0] + (s.y - cy) * u[1]
    across = (s.x - cx) * u[1] - (s.y - cy) * u[0]
    middle = np.isfinite(s.N) & (np.abs(along) < 5) & (np.abs(across) < 0.3)
    ref = analyze_corridor(ROBOT, CONTROLLER, Corridor(L), ["sampled"], law=law.with_scale(law.ratio * (math.sin(angle) + math.cos(angle))))
    assert middle.sum() > 20
    assert np.mean(s.N[middle]) == pytest.approx(ref.N, rel=0.03)


def one_cell_per_cell_length(x, y, c: float) -> np.ndarray:
    """(column, row) cells of a wall through the points (x, y) spaced c apart: each point marks the cell it falls in,
    or, when that cell is already marked, the nearest unmarked cell around it (so the wall has one cell per c of length)."""
    marked, cells = set(), []
    for px, py in zip(x, y):
        i0, j0 = math.floor(px / c), math.floor(py / c)
        around = sorted((((i + 0.5) * c - px) ** 2 + ((j + 0.5) * c - py) ** 2, i, j) for i in (i0 - 1, i0, i0 + 1) for j in (j0 - 1, j0, j0 + 1))
        i, j = next((i, j) for _, i, j in around if (i, j) not in marked)
        marked.add((i, j))
        cells.append((i, j))
    return np.array(cells)


def test_corridor_at_30_degrees_drawn_one_cell_per_cell_length_matches_the_report(tmp_path):
    """Diagonal walls (docs/maps.md): a corridor rotated by 30° whose walls have one occupied cell per cell length
    gives the N and V* of the plain grid law (same cell size, window and cell ratio; what ``report --law grid``
    prints) to 3 %: in its middle the mean sample N and its V*, and the segment's own N_eff and V*. The routes
    must also find it as one long segment although such walls touch themselves only at corners. What remains is the
    lateral quantization of the wall cells (±½ cell about the line) and, for the segment, N_eff being the uniform
    gain with the samples' mean growth rate."""
    L, angle, c = 0.9, math.radians(30), 0.1
    ny, nx = 260, 200
    img = np.full((ny, nx), 254, dtype=np.uint8)
    cx, cy = 10.05, 13.05
    t = np.arange(-11.5, 11.5, c)
    for side in (-1, 1):
        x = cx + t * math.sin(angle) + side * L * math.cos(angle)
        y = cy + t * math.cos(angle) - side * L * math.sin(angle)
        keep = (x > 0.2) & (x < nx * c - 0.2) & (y > 0.2) & (y < ny * c - 0.2)
        cells = one_cell_per_cell_length(x[keep], y[keep], c)
        assert len(cells) == keep.sum()  # one cell per cell length
        img[ny - 1 - cells[:, 1], cells[:, 0]] = 0
    law = make_law("grid", ROBOT, CONTROLLER)
    analysis = analyze_map(load_map(write_map(tmp_path, img)), ROBOT, CONTROLLER, law)
    ref = analyze_corridor(ROBOT, CONTROLLER, Corridor(L), ["sampled"], law=law)
    V_ref = ref.models["sampled"].critical["V_critical"]
    s = analysis.samples
    along = (s.x - cx) * math.sin(angle) + (s.y - cy) * math.cos(angle)
    across = (s.x - cx) * math.cos(angle) - (s.y - cy) * math.sin(angle)
    middle = np.isfinite(s.N) & (np.abs(along) < 5) & (np.abs(across) < 0.3)
    assert middle.sum() > 50
    assert np.mean(s.N[middle]) == pytest.approx(ref.N, rel=0.03)
    boundary = models_for(CONTROLLER, ["sampled"])[0].boundary(Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k))
    assert sample_verdict(float(np.mean(s.N[middle])), ROBOT.V, boundary, True).V_critical == pytest.approx(V_ref, rel=0.03)
    (segment,) = [g for g in analysis.segments if g.N is not None and g.length > 15]
    assert abs(math.atan2(segment.x1 - segment.x0, segment.y1 - segment.y0) % math.pi - angle) < math.radians(2)
    assert segment.V_critical == pytest.approx(V_ref, rel=0.03)
    assert segment.N == pytest.approx(ref.N, rel=0.04)


def test_sample_verdicts_agree_with_the_models_own_stability_test():
    """The per-sample verdict reads the stable set of the boundary; the model's eigenvalue test (`is_stable`, another
    route) agrees at random N on both sides of the boundary, for two sampled structures; N < 0 is unstable at any speed."""
    rng = np.random.default_rng(3)
    for controller in (CONTROLLER, CONTROLLER.replace(hold="reference", compute_delay=0, T=0.2)):
        model = models_for(controller, ["sampled"])[0]
        loop = Loop(ROBOT.tau, controller.T, ROBOT.k)
        boundary = model.boundary(loop)
        for N in rng.uniform(0.05, 3 * boundary.NV_critical / ROBOT.V, 12):
            j = sample_verdict(N, ROBOT.V, boundary, model.is_stable(0.0, loop))
            V_star, margin, stable, label = j.V_critical, j.margin, j.stable, j.verdict
            assert stable == model.is_stable(N * ROBOT.V, loop) and (margin > 0) == stable
            assert V_star == pytest.approx(boundary.NV_critical / N)
    j = sample_verdict(-0.5, 0.8, boundary, True)
    assert (j.V_critical, j.margin, j.stable, j.verdict) == (0.0, -1.0, False, "unstable")


def test_power_law_on_a_corridor(tmp_path):
    """With KB's power law the map's N is −2P′(L), L the mean distance to the walls' inner faces (at L − c/2 from the
    centre line) along the normal; rays find a face to 1/16 pixel (6 mm here), and N ∝ L^-3 then moves by < 2 %."""
    L = 1.0
    analysis = analyze_map(load_map(write_map(tmp_path, corridor_pixels(L))), ROBOT, CONTROLLER, make_law("power", ROBOT, CONTROLLER))
    s = analysis.samples
    middle = np.isfinite(s.N) & (np.abs(s.y - 10.0) < 4.0)
    ref = analyze_corridor(ROBOT, CONTROLLER, Corridor(L - 0.05), ["sampled"])
    assert middle.sum() > 50 and np.abs(s.N[middle] / ref.N - 1).max() < 0.02


# ------------------------------------------------------------------ bad maps and laws
def test_law_without_a_map_meaning_is_refused(tmp_path):
    """A goal-aware law needs the goal's distance, which a map does not give: ValueError naming the law."""
    law = make_law("khatib", ROBOT, CONTROLLER, goal_distance=5.0)
    with pytest.raises(ValueError, match="law must be one of grid, power"):
        analyze_map(load_map(write_map(tmp_path, corridor_pixels(1.0))), ROBOT, CONTROLLER, law)


def test_no_free_space_and_no_route(tmp_path):
    """All occupied: "no free space"; free but too narrow for the robot: "no route long enough"."""
    law = make_law("grid", ROBOT, CONTROLLER)
    with pytest.raises(ValueError, match="no free space"):
        analyze_map(load_map(write_map(tmp_path, np.zeros((20, 20)), name="a")), ROBOT, CONTROLLER, law)
    with pytest.raises(ValueError, match="no route long enough"):
        analyze_map(load_map(write_map(tmp_path, corridor_pixels(0.3), name="b")), ROBOT, CONTROLLER, law)


# ------------------------------------------------------------ segment verdicts (maps.deciding.verdicts)
def _random_loop(rng):
    """A random sampled loop far from CARMEL too: (model, loop, boundary, exact σ(NV))."""
    from pfm_stability.models import Sampled

    while True:  # a loop with a finite, positive NV* (one stable at small gains)
        model = Sampled(("command", "reference")[int(rng.integers(2))], int(rng.integers(2)))
        loop = Loop(float(rng.uniform(0.02, 1.0)), float(rng.uniform(0.01, 0.2)), float(rng.uniform(1.0, 40.0)))
        boundary = model.boundary(loop)
        if 0 < boundary.NV_critical < math.inf:
            return model, loop, boundary, lambda NV: model.rightmost_root(float(NV), loop).real


@pytest.mark.parametrize("seed", range(3))
def test_growth_table_equals_the_models_root(seed):
    """`GrowthRate` (PCHIP in log |NV|) against the model's own rightmost root at random NV of both signs over six
    decades about NV*, random loops. Tolerance 2 % of max(|σ|, 0.1·|σ at the most damped gain|): the table's
    40 points per decade miss only the corner where two real roots merge (measured ≤ 0.4 %); at NV* (a node) σ is 0
    to round-off."""
    from pfm_stability.maps.deciding.verdicts import GrowthRate

    rng = np.random.default_rng(seed)
    model, loop, boundary, sigma = _random_loop(rng)
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), boundary.NV_critical)
    NV = boundary.NV_critical * np.exp(rng.uniform(-3, 3, 60) * math.log(10)) * rng.choice([-1, 1], 60)
    exact = np.array([sigma(x) for x in NV])
    scale = np.maximum(np.abs(exact), 0.1 * abs(sigma(growth.NV_least)))
    assert np.all(np.abs(growth(NV) - exact) <= 0.02 * scale)
    assert abs(float(growth(boundary.NV_critical))) < 1e-9 * boundary.omega_critical


@pytest.mark.parametrize("seed", range(3))
def test_segment_critical_speed_is_where_the_exact_mean_growth_turns_positive(seed):
    """V* of a segment against the exact mean growth rate (the model's roots, no table): σ̄ < 0 just below V* and
    at 40 speeds below it, σ̄ > 0 just above, for random gain profiles with spikes, gaps and negative samples and
    random loops. Tolerance: ±1 % of V* (the table's σ error moves the crossing by less)."""
    from pfm_stability.maps.deciding.verdicts import GrowthRate, critical_speed

    rng = np.random.default_rng(seed)
    model, loop, boundary, sigma = _random_loop(rng)
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), boundary.NV_critical)
    n = int(rng.integers(3, 12))
    N = rng.lognormal(1.0, 0.6, n)
    spike, gap, negative = rng.permutation(n)[:3]
    N[spike] *= rng.uniform(3, 20)
    N[gap] = np.nan
    N[negative] *= -0.3
    V_star = critical_speed(N, growth, boundary.NV_critical)
    finite = N[np.isfinite(N)]
    exact = lambda V: np.mean([sigma(x * V) for x in finite])  # noqa: E731
    assert 0 < V_star < math.inf
    assert exact(V_star * 0.99) < 0 < exact(V_star * 1.01)
    assert all(exact(V) < 0 for V in np.linspace(V_star / 40, V_star * 0.99, 40))


def test_uniform_segment_is_decided_like_a_single_sample():
    """With the same N at every sample σ̄ = σ(N·V): N_eff = N and V* = NV*/N (`sample_verdict`, the report's route)
    on both branches of σ (a small gain's real root, an oscillating gain, an unstable one); tolerance 1e-7 (the
    bisections' widths; NV* is a node of the table)."""
    from pfm_stability.maps.deciding.verdicts import GrowthRate, critical_speed, segment_gain

    model = models_for(CONTROLLER, ["sampled"])[0]
    loop = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
    boundary = model.boundary(loop)
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), boundary.NV_critical)
    for N0 in (0.05, 0.3, 2.0, 17.0):
        N = np.full(25, N0)
        g = segment_gain(N, ROBOT.V, boundary.omega_critical, growth, boundary.NV_critical)
        assert g.N_eff == pytest.approx(N0, rel=1e-7)
        assert (g.sigma < 0) == boundary.contains(N0 * ROBOT.V)
        assert critical_speed(N, growth, boundary.NV_critical) == pytest.approx(sample_verdict(N0, ROBOT.V, boundary, True).V_critical, rel=1e-7)


def test_a_one_sample_spike_counts_by_its_growth_not_its_gain():
    """A single sample 20x the rest: the local worst would call the segment unstable; the mean growth rate is
    ((n−1)·σ(N·V) + σ(20N·V))/n, computed here from the model's roots, and N_eff has that σ (to 2 % of σ̄, the
    table's accuracy). A mean N below 0 makes the segment unstable at any speed (V* = 0)."""
    from pfm_stability.maps.deciding.verdicts import GrowthRate, critical_speed, segment_gain

    model = models_for(CONTROLLER, ["sampled"])[0]
    loop = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
    boundary = model.boundary(loop)
    growth = GrowthRate(lambda NV: model.rightmost_root(NV, loop), boundary.NV_critical)
    V = 0.5 * boundary.NV_critical / 2.0
    N = np.full(30, 2.0)
    N[15] = 40.0
    sigma = lambda NV: model.rightmost_root(NV, loop).real  # noqa: E731
    expected = (29 * sigma(2.0 * V) + sigma(40.0 * V)) / 30
    g = segment_gain(N, V, boundary.omega_critical, growth, boundary.NV_critical)
    assert g.sigma == pytest.approx(expected, rel=0.02) and g.sigma < 0
    assert sigma(g.N_eff * V) == pytest.approx(expected, rel=0.02)
    assert critical_speed(N, growth, boundary.NV_critical) > V
    N[:25] = -2.0  # mean N = (−50 + 4·2 + 40)/30 < 0
    assert critical_speed(N, growth, boundary.NV_critical) == 0.0
    g = segment_gain(N, V, boundary.omega_critical, growth, boundary.NV_critical)
    assert g.N_eff < 0 and g.sigma > 0 and sigma(g.N_eff * V) == pytest.approx(g.sigma, rel=0.02)


def test_weak_segments_change_by_less_than_one_efold():
    """A segment is weak when its mean growth rate changes the deviation by less than one e-fold over it: a tiny N
    (slow real root σ ≈ −N·V) and a gain 0.1 % from the boundary (a slowly growing oscillation) both are over 2 m,
    a clearly stable or unstable gain is not. Checked against the model's own root: |σ|·length/V vs 1."""
    from pfm_stability.maps.deciding.verdicts import is_weak

    model = models_for(CONTROLLER, ["sampled"])[0]
    loop = Loop(ROBOT.tau, CONTROLLER.T, ROBOT.k)
    boundary = model.boundary(loop)
    for NV in (0.02 * ROBOT.V, -0.05 * ROBOT.V, 0.5 * ROBOT.V, 1.001 * boundary.NV_critical, 0.5 * boundary.NV_critical,
               3 * boundary.NV_critical):
        sigma = model.rightmost_root(NV, loop).real
        for length in (0.5, 2.0, 10.0):
            assert is_weak(sigma, length, ROBOT.V) == (abs(sigma) * length / ROBOT.V < 1)
    assert is_weak(model.rightmost_root(1.001 * boundary.NV_critical, loop).real, 2.0, ROBOT.V)
    assert not is_weak(model.rightmost_root(3 * boundary.NV_critical, loop).real, 2.0, ROBOT.V)


def test_directional_gains_divide_by_each_directions_forward_force():
    """N one way is −dF_n/ds/(1 + F_r·t), the other −dF_n/ds/(1 − F_r·t); the per-sample N is the larger."""
    from pfm_stability.maps.deciding.equilibria import Samples

    slope, ft = np.array([3.0, 2.0, 1.0]), np.array([0.4, -0.2, 0.0])
    forward = 1 - np.abs(ft)
    z = np.zeros(3)
    s = Samples(z, z, z.astype(int), z, slope / forward, forward, z.astype(int), z.astype(bool), ft)
    fwd, rev = s.directional(np.arange(3))
    assert fwd == pytest.approx(slope / (1 + ft)) and rev == pytest.approx(slope / (1 - ft))
    assert np.maximum(fwd, rev) == pytest.approx(s.N)


# ------------------------------------------------------------ tapering (maps.deciding.verdicts.drift_slope, TAPER_SLOPE)
@pytest.mark.parametrize("seed", range(3))
def test_drift_slope_is_the_exact_slope_of_a_linear_offset(seed):
    """`drift_slope` of s0 = a + b·s (noise-free, random a, b of both signs, random spacing, gaps as nan) is |b| to
    1e-9 (a least-squares line through points on a line: round-off only); a constant offset gives 0, and so do
    fewer than two finite samples."""
    from pfm_stability.maps.deciding.verdicts import drift_slope

    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-0.5, 0.5), rng.uniform(-2.0, 2.0)
    s = np.cumsum(rng.uniform(0.02, 0.2, 40))
    offset = a + b * s
    offset[rng.permutation(40)[:5]] = np.nan
    assert drift_slope(s, offset) == pytest.approx(abs(b), abs=1e-9)
    assert drift_slope(s, np.full(40, a)) == pytest.approx(0.0, abs=1e-12)
    assert drift_slope(s[:1], offset[:1]) == 0.0 and drift_slope(s, np.full(40, np.nan)) == 0.0


def tapering_corridor(directory: Path, angle_deg: float = 4.0) -> Path:
    """A 10 m corridor: a thin wall at x = 1 m and, 2.2 m across, a solid block whose face converges on it at
    `angle_deg` (the block pushes harder than the thin wall, by an amount that changes as the gap narrows, so the
    equilibrium line drifts away from the medial axis the segment follows)."""
    c, ny, nx = 0.1, 100, 60
    img = np.full((ny, nx), 254, dtype=np.uint8)
    img[:, 10] = 0
    for row in range(ny):
        y = (ny - 1 - row) * c
        img[row, int((3.2 - math.tan(math.radians(angle_deg)) * y) / c):] = 0
    return write_map(directory, img, name=f"taper{angle_deg:g}")


def _judged_slope(analysis, k: int) -> float:
    """|ds0/ds| of segment k's judged samples, by hand (np.polyfit on the samples' offsets against their positions)."""
    s, S = analysis.segments[k], analysis.samples
    mine = np.flatnonzero(S.segment == k)
    spacing = s.length / mine.size
    first, stop = round(s.judged_from / spacing), round(s.judged_to / spacing)
    pos, off = (np.arange(first, stop) + 0.5) * spacing, S.offset[mine[first:stop]]
    ok = np.isfinite(off)
    return abs(np.polyfit(pos[ok], off[ok], 1)[0])


def test_tapering_rule_withholds_the_verdict_above_the_threshold(tmp_path):
    """A corridor converging at 4°: its long segment's judged offsets drift (slope computed here by hand); with
    `taper_slope` at half that slope the segment is "tapering" (no N, no V*), at twice it the verdict is the one
    without the rule (`taper_slope=inf`), the same segment in every run. The default 0.25 (14°) lets this gentle
    taper through. Bad `taper_slope` values raise ValueError naming it."""
    law = make_law("grid", ROBOT, CONTROLLER)
    occupancy = load_map(tapering_corridor(tmp_path))
    free = analyze_map(occupancy, ROBOT, CONTROLLER, law, taper_slope=math.inf)
    k = max(range(len(free.segments)), key=lambda i: free.segments[i].length if free.segments[i].judged_from is not None else 0)
    slope = _judged_slope(free, k)
    assert free.segments[k].length > 5 and free.segments[k].verdict in ("stable", "unstable", "weak") and 0.01 < slope < 0.25
    strict = analyze_map(occupancy, ROBOT, CONTROLLER, law, taper_slope=slope / 2).segments[k]
    assert strict.verdict == "tapering" and strict.N is None and strict.V_critical is None and "ds0/ds" in strict.reason
    loose = analyze_map(occupancy, ROBOT, CONTROLLER, law, taper_slope=2 * slope).segments[k]
    assert loose == free.segments[k]
    assert analyze_map(occupancy, ROBOT, CONTROLLER, law).segments[k] == free.segments[k]
    for bad in (0, -0.1, float("nan"), "0.25", True, None):
        with pytest.raises(ValueError, match="^taper_slope "):
            analyze_map(occupancy, ROBOT, CONTROLLER, law, taper_slope=bad)


def test_picture_legend_lists_only_the_kinds_on_the_map(tmp_path):
    """The legend of `plot_map_stability` has one grey entry per kind of no-verdict segment drawn (tapering among
    them, in its own style) and none for kinds the map lacks; no "unstable" entry without an unstable segment, no
    "unknown" without unknown cells. Checked against the verdicts counted here."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    from pfm_stability.plots.map import (
        NO_VERDICT_LABELS,
        NO_VERDICT_STYLES,
        plot_map_stability,
    )

    assert set(NO_VERDICT_STYLES) == set(NO_VERDICT_LABELS) and "tapering" in NO_VERDICT_STYLES
    law = make_law("grid", ROBOT, CONTROLLER)
    occupancy = load_map(tapering_corridor(tmp_path))
    for taper in (math.inf, 1e-3):
        analysis = analyze_map(occupancy, ROBOT, CONTROLLER, law, taper_slope=taper)
        verdicts = {s.verdict for s in analysis.segments}
        fig = plot_map_stability(analysis)
        labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
        plt.close(fig)
        kinds = {"open" if v == "no equilibrium" else v for v in verdicts if v in NO_VERDICT_STYLES or v == "no equilibrium"}
        assert {k for k in NO_VERDICT_LABELS if NO_VERDICT_LABELS[k] in labels} == kinds
        assert ("unstable segment" in labels) == ("unstable" in verdicts)
        assert ("unknown" in labels) == bool(occupancy.unknown.any())
    assert "tapering" in verdicts
