"""Every stationary point of a 2-D scene (`pfm_stability.analysis.traps`) and the ``traps`` command.

Ge & Cui, IEEE T-RA 16(5), 2000 ("GC2000"; docs/traps.md). Checked:

* the paper's 2-D numbers on the shipped scenes (Figs 3, 4, Sec VI.B), each
  with its tolerance and why;
* the exact gradient and Hessian against finite differences of the potential
  itself (an independent route), for every obstacle type and law;
* random scenes far from the paper's values: every point found has ∇U = 0
  (relative to the forces that cancel there), its kind agrees with a
  finite-difference Hessian of U, the goal's verdict agrees with a
  brute-force grid minimum, and the search is complete by the Poincaré–Hopf
  count: #minima − #saddles + #maxima = 1 − (number of obstacles) when U → ∞
  at every obstacle and at infinity and every stationary point lies in the
  region (all lie within ρ0 of an obstacle, or at the goal);
* scene files: every kind of bad scene is a one-line ValueError naming the
  field, the command exits 2 with it; the JSON output validates against the
  shipped schema.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from jsonschema import Draft202012Validator

from pfm_stability.cli import main
from pfm_stability.io.schema import load_schema
from pfm_stability.laws.scene import Scene, field
from pfm_stability.analysis.traps import find_stationary_points

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "pfm_stability" / "data" / "scenes"
VALIDATOR = Draft202012Validator(load_schema())
RNG_SEED = 1605


def scene(law=None, goal=(0.0, 0.0), obstacles=None, region=((-3.0, -3.0), (4.0, 3.0))) -> Scene:
    law = law or {"name": "gnron", "xi": 1.0, "eta": 1.0, "rho0": 2.0, "attraction_exponent": 2, "goal_exponent": 2}
    obstacles = [{"circle": {"center": [1.0, 0.0], "radius": 0.5}}] if obstacles is None else obstacles
    return Scene.from_dict({"law": law, "goal": list(goal), "obstacles": obstacles, "region": [list(region[0]), list(region[1])]})


def kinds(analysis):
    return sorted((p.kind, p.goal) for p in analysis.stationary_points)


def poincare_hopf(analysis) -> int:
    return sum({"minimum": 1, "saddle": -1, "maximum": 1}.get(p.kind, 0) for p in analysis.stationary_points)


# ------------------------------------------------------------------ the paper's 2-D numbers
def test_fig3_only_the_goal_and_a_saddle():
    """GC2000 Fig 3 (gc2000_fig3.yaml): no local minimum; only the goal (Hessian [ξ + η(1/r − 1/ρ0)²]·I = 3.25·I)
    and a saddle at (2.5, 0) behind the obstacle (Newton to 1e-13 relative: tolerance 1e-9)."""
    a = find_stationary_points(Scene.load(SCENES / "gc2000_fig3.yaml"))
    assert kinds(a) == [("minimum", True), ("saddle", False)] and a.goal_is_global_minimum and a.traps == ()
    goal, saddle = a.stationary_points
    assert goal.hessian_eigenvalues == pytest.approx((3.25, 3.25), rel=1e-12)
    assert (saddle.x, saddle.y) == pytest.approx((2.5, 0.0), abs=1e-9)
    assert a.conclusion == "the goal is the only minimum"
    [b] = a.gnron_bounds
    assert b.k_exact == pytest.approx(0.0549637342, abs=1e-10) and b.satisfied and b.ratio == 1.0


def test_fig4_local_minimum():
    """GC2000 Fig 4 (η = 25): a minimum at (−1.078088, 0) (paper (−1.08, 0); 7 digits quoted: 1e-6), Hessian
    eigenvalues (0.6962, 2.3216) (4 decimals: 1e-4), a saddle at (−0.620823, 0) (1e-6); ξ/η = 0.04 < k₂."""
    a = find_stationary_points(Scene.load(SCENES / "gc2000_fig4.yaml"))
    [trap] = a.traps
    assert (trap.x, trap.y) == pytest.approx((-1.078088, 0.0), abs=1e-6)
    assert trap.hessian_eigenvalues == pytest.approx((0.6962, 2.3216), abs=1e-4)
    saddles = sorted(p.x for p in a.stationary_points if p.kind == "saddle")
    assert saddles[0] == pytest.approx(-0.620823, abs=1e-6) and len(saddles) == 2  # and one behind the obstacle
    assert a.goal_is_global_minimum and not a.gnron_bounds[0].satisfied
    assert poincare_hopf(a) == 0  # plane minus one disc


def test_sec6b_conventional_trap_and_goal_aware_law():
    """GC2000 Sec VI.B as a 2-D scene (one wide rectangle, edge 0.2 below the goal): Khatib's law traps the robot at
    (8, 9.0000) (paper (8.04, 9.00); exact here, 1e-9); the goal-aware law leaves only the goal, whose Hessian is
    [ξ + η(1/r − 1/ρ0)²]·I = 2.40625·I; k₂(0.2, 0.8) = 0.343523 < ξ/η = 10."""
    khatib = find_stationary_points(Scene.load(SCENES / "gc2000_sec6b_khatib.yaml"))
    [trap] = khatib.traps
    assert (trap.x, trap.y) == pytest.approx((8.0, 9.0), abs=1e-9)
    assert not khatib.goal_is_global_minimum and not any(p.goal for p in khatib.stationary_points)
    assert khatib.gnron_bounds[0].k_exact is None and "no finite bound" in khatib.gnron_bounds[0].reason
    gnron = find_stationary_points(Scene.load(SCENES / "gc2000_sec6b_gnron.yaml"))
    [goal] = gnron.stationary_points
    assert goal.goal and goal.hessian_eigenvalues == pytest.approx((2.40625, 2.40625), rel=1e-12)
    assert gnron.gnron_bounds[0].k_exact == pytest.approx(0.343523, abs=5e-7) and gnron.gnron_bounds[0].satisfied


def test_fig6_in_two_dimensions_matches_the_ray():
    """GC2000 Fig 6's law (n = 0.5) about the circle of Fig 3: the 2-D search finds the 1-D ray's minimum
    (−0.356648) and a saddle at the ray's maximum (−0.122035); the goal is not C² (no Hessian) but the global minimum."""
    law = {"name": "gnron", "xi": 1.0, "eta": 1.0, "rho0": 2.0, "attraction_exponent": 2, "goal_exponent": 0.5}
    a = find_stationary_points(scene(law))
    [trap] = a.traps
    assert trap.x == pytest.approx(-0.356648, abs=1e-6)
    assert any(p.kind == "saddle" and p.x == pytest.approx(-0.122035, abs=1e-6) for p in a.stationary_points)
    goal = next(p for p in a.stationary_points if p.goal)
    assert goal.hessian_eigenvalues is None and not goal.smooth and a.goal_is_global_minimum


def test_goal_out_of_reach_of_every_obstacle_is_a_plain_minimum():
    """Khatib's law with the obstacle farther than ρ0 from the goal: the goal is a minimum with Hessian ξ·I."""
    law = {"name": "khatib", "xi": 2.0, "eta": 1.0, "rho0": 0.4, "attraction_exponent": 2}
    a = find_stationary_points(scene(law))
    goal = next(p for p in a.stationary_points if p.goal)
    assert goal.kind == "minimum" and goal.hessian_eigenvalues == pytest.approx((2.0, 2.0)) and a.gnron_bounds == ()
    assert a.goal_is_global_minimum and a.traps == ()


def test_crease_minimum_of_a_non_convex_polygon():
    """A chevron whose pocket faces away from the goal: the trap lies on the crease (bisector) of the polygon's
    distance, where ∇U jumps; found by Nelder–Mead, reported without a Hessian. Poincaré–Hopf still holds."""
    v = [[0, 1], [2.5, 0], [0, -1], [0, -0.7], [2, 0], [0, 0.7]]
    law = {"name": "khatib", "xi": 1.0, "eta": 1.0, "rho0": 1.0, "attraction_exponent": 2}
    a = find_stationary_points(scene(law, goal=(4.0, 0.0), obstacles=[{"polygon": v}], region=((-1.5, -2.5), (5.0, 2.5))), 61)
    [trap] = a.traps
    assert not trap.smooth and trap.hessian_eigenvalues is None and abs(trap.y) < 1e-7 and 0.0 < trap.x < 2.0
    ring = trap.potential <= field(a.scene, [[trap.x + 1e-4 * math.cos(t), trap.y + 1e-4 * math.sin(t)] for t in np.linspace(0, 6, 12)],
                                   hessian=False)[0]
    assert ring.all() and poincare_hopf(a) == 0


# ------------------------------------------------------------------ independent routes
def _fd_gradient_hessian(s, points, h):
    """Central differences of U itself (one call of `field` for every stencil point): gradients (N, 2), Hessians (N, 2, 2)."""
    p = np.atleast_2d(np.asarray(points, dtype=float))
    offsets = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]]) * h
    u = field(s, (p[:, None, :] + offsets[None]).reshape(-1, 2), hessian=False)[0].reshape(len(p), 9)
    g = np.column_stack([u[:, 1] - u[:, 2], u[:, 3] - u[:, 4]]) / (2 * h)
    hxx, hyy = (u[:, 1] - 2 * u[:, 0] + u[:, 2]) / h**2, (u[:, 3] - 2 * u[:, 0] + u[:, 4]) / h**2
    hxy = (u[:, 5] - u[:, 6] - u[:, 7] + u[:, 8]) / (4 * h * h)
    return g, np.stack([np.column_stack([hxx, hxy]), np.column_stack([hxy, hyy])], axis=1)


def test_gradient_and_hessian_against_finite_differences_of_the_potential():
    """The analytic ∇U and ∇²U (chain rule through ∇ρ, ∇²ρ = κ(I − ∇ρ∇ρᵀ)) against central differences of U:
    circles, segments (edge and end regions), polygons (edge and vertex regions), both laws, m = 1, 2, δ > 0.
    Step 1e-5: gradient error ~1e-10·U''', Hessian ~1e-10·U'''' + rounding 1e-16·U/h² → tolerances 1e-6 / 1e-4."""
    rng = np.random.default_rng(RNG_SEED)
    obstacles = [{"circle": {"center": [1.0, 0.3], "radius": 0.4}}, {"segment": {"from": [-1.0, 1.0], "to": [0.5, 1.6]}},
                 {"polygon": [[-2.0, -1.5], [-0.5, -1.8], [-1.0, -0.6]]}]
    for law in ({"name": "gnron", "xi": 1.3, "eta": 0.7, "rho0": 1.2, "attraction_exponent": 2, "goal_exponent": 1.5, "delta": 0.02},
                {"name": "khatib", "xi": 0.8, "eta": 0.3, "rho0": 1.5, "attraction_exponent": 1},
                {"name": "gnron", "xi": 1.0, "eta": 2.0, "rho0": 1.0, "attraction_exponent": 1, "goal_exponent": 3}):
        s = scene(law, goal=(0.2, -0.2), obstacles=obstacles)
        q = rng.uniform([-3, -3], [4, 3], (400, 2))
        rho = np.min([o.geometry(q)[0] for o in s.obstacles], axis=0)
        q = q[(rho > 0.05) & (np.hypot(*(q - s.goal).T) > 0.05)][:200]  # free, off the goal; some beyond ρ0
        _, g, hess, scale, free = field(s, q)
        fd_g, fd_h = _fd_gradient_hessian(s, q, 1e-5)
        for p, gi, hi, si, fg, fh in zip(q, g, hess, scale, fd_g, fd_h):
            assert np.abs(fg - gi).max() <= 1e-6 * (si + np.abs(gi).max()), (law, p)
            assert np.abs(fh - hi).max() <= 1e-4 * (np.abs(hi).max() + si + 1e-9), (law, p, fh, hi)


def _random_scene(rng):
    """Separate obstacles (circles, segments, triangles) with the goal outside each, the region covering every
    influence zone (so every stationary point lies inside it), δ = 0 (U → ∞ at every obstacle)."""
    rho0 = rng.uniform(0.5, 1.5)
    shapes, centers = [], []
    while len(shapes) < rng.integers(1, 4):
        c = rng.uniform(-2.5, 2.5, 2)
        size = rng.uniform(0.15, 0.6)
        if any(np.hypot(*(c - d)) < 2.5 * size + 1.0 for d in centers):
            continue
        kind = rng.choice(["circle", "segment", "polygon"])
        angle = rng.uniform(0, 2 * np.pi)
        if kind == "circle":
            shapes.append({"circle": {"center": c.tolist(), "radius": size}})
        elif kind == "segment":
            d = size * np.array([np.cos(angle), np.sin(angle)])
            shapes.append({"segment": {"from": (c - d).tolist(), "to": (c + d).tolist()}})
        else:
            shapes.append({"polygon": [(c + size * np.array([np.cos(angle + k * 2.1), np.sin(angle + k * 2.1)])).tolist() for k in range(3)]})
        centers.append(c)
    law = {"name": "khatib", "xi": 10 ** rng.uniform(-0.5, 0.5), "eta": 10 ** rng.uniform(-1.5, 0.5), "rho0": rho0,
           "attraction_exponent": int(rng.choice([1, 2]))}
    if rng.uniform() < 0.6:
        law.update(name="gnron", goal_exponent=float(rng.choice([0.5, 1.0, 1.5, 2.0, 3.0])))
    while True:
        goal = rng.uniform(-2.5, 2.5, 2)
        try:
            return scene(law, goal=tuple(goal), obstacles=shapes, region=((-5.0, -5.0), (5.0, 5.0)))
        except ValueError:  # the goal inside an obstacle: draw again
            continue


@pytest.fixture(scope="module")
def random_analyses():
    rng = np.random.default_rng(RNG_SEED + 1)
    return [find_stationary_points(_random_scene(rng), 61) for _ in range(10)]


@pytest.mark.xdist_group("traps_random_scenes")  # the ten scenes once per suite (tests/conftest.py)
def test_random_scenes_points_are_stationary_and_classified_like_finite_differences(random_analyses):
    """Every smooth point found: |∇U| <= 1e-9 of the cancelling forces (analytic), the central-difference gradient
    of U is ~0 on that scale, and the signs of the finite-difference Hessian's eigenvalues give the same kind."""
    checked = 0
    for a in random_analyses:
        for p in a.stationary_points:
            if p.goal or not p.smooth:
                continue
            _, g, _, scale, _ = field(a.scene, [[p.x, p.y]])
            assert np.hypot(*g[0]) <= 1e-9 * scale[0]
            fd_g, fd_h = _fd_gradient_hessian(a.scene, (p.x, p.y), 1e-5)
            assert np.abs(fd_g[0]).max() <= 1e-5 * scale[0]
            lam = np.linalg.eigvalsh(fd_h[0])
            if min(abs(lam)) > 1e-3 * max(abs(lam)):
                assert p.kind == ("minimum" if lam[0] > 0 else "maximum" if lam[1] < 0 else "saddle")
            checked += 1
    assert checked >= 10


@pytest.mark.xdist_group("traps_random_scenes")
def test_random_scenes_are_complete_by_poincare_hopf(random_analyses):
    """#minima − #saddles + #maxima = χ(plane minus k obstacles) = 1 − k: a missed point would break the count
    (the goal counts as a minimum when it is one, as at a cone or a non-C² point)."""
    for a in random_analyses:
        assert poincare_hopf(a) == 1 - len(a.scene.obstacles), [(p.x, p.y, p.kind) for p in a.stationary_points]


@pytest.mark.xdist_group("traps_random_scenes")
def test_random_scenes_goal_verdict_against_a_brute_force_grid(random_analyses):
    """goal_is_global_minimum ⇔ U(goal) <= min of U on a 401 × 401 grid of the free region and a small ring about the
    goal (which sees the descent from a goal that is not stationary)."""
    x = np.linspace(-5, 5, 401)
    X, Y = np.meshgrid(x, x)
    grid = np.column_stack([X.ravel(), Y.ravel()])
    for a in random_analyses:
        ring = np.array(a.scene.goal) + 1e-4 * np.column_stack([np.cos(np.linspace(0, 6.2, 32)), np.sin(np.linspace(0, 6.2, 32))])
        u, _, _, _, free = field(a.scene, np.concatenate([grid, ring]), hessian=False)
        goal_u = float(field(a.scene, [a.scene.goal], hessian=False)[0][0])
        brute = bool(np.min(u[free]) >= goal_u - 1e-12 * max(1.0, abs(goal_u)))
        assert a.goal_is_global_minimum == brute, (a.scene.law, goal_u, np.min(u[free]))


@pytest.mark.xdist_group("traps_random_scenes")
def test_random_scene_at_another_resolution_gives_the_same_points(random_analyses):
    """The search does not depend on its grid: resolution 41 finds the same points as 61 (to 1e-6 m)."""
    for a in random_analyses[:3]:
        b = find_stationary_points(a.scene, 41)
        key = lambda s: sorted((p.kind, round(p.x, 6), round(p.y, 6)) for p in s.stationary_points)
        assert key(a) == key(b)


# ------------------------------------------------------------------ scene files
GOOD = {"law": {"name": "gnron", "xi": 1, "eta": 1, "rho0": 2, "attraction_exponent": 2, "goal_exponent": 2}, "goal": [0, 0],
        "obstacles": [{"circle": {"center": [1, 0], "radius": 0.5}}, {"segment": {"from": [-1, 1], "to": [1, 1]}},
                      {"polygon": [[-2, -1], [-1, -1], [-1.5, -2]]}],
        "region": [[-3, -3], [3, 3]]}


def _bad(path, value):
    data = json.loads(json.dumps(GOOD))
    *parents, last = path
    target = data
    for key in parents:
        target = target[key]
    if value is KeyError:
        del target[last]
    else:
        target[last] = value
    return data


BAD_SCENES = {
    "negative radius": (_bad(["obstacles", 0, "circle", "radius"], -1), "obstacles[0].circle.radius must be a finite number in (0, 1000000] m; got -1"),
    "obstacle covers the goal": (_bad(["obstacles", 0, "circle", "center"], [0.2, 0]), "obstacles[0].circle covers the goal"),
    "inverted region": (_bad(["region"], [[3, -3], [-3, 3]]), "region must have xmin < xmax"),
    "empty region": (_bad(["region"], [[0, 0], [0, 0]]), "region must have xmin < xmax"),
    "tiny region": (_bad(["region"], [[-1e-4, -1], [1e-4, 1]]), "region must have xmin < xmax and ymin < ymax, sides of at least 1e-3 m"),
    "far coordinate": (_bad(["obstacles", 1, "segment", "to"], [2e6, 1]), "obstacles[1].segment.to[0] must be a finite number in [-1000000, 1000000] m"),
    "tiny rho0": (_bad(["law", "rho0"], 1e-9), "law.rho0 must be a finite number in [1e-06, 1000000] m"),
    "goal touching an obstacle": (_bad(["obstacles", 0, "circle", "radius"], 1 - 1e-12), "obstacles[0].circle covers the goal"),
    "goal outside region": (_bad(["goal"], [5, 0]), "goal must lie inside region"),
    "unknown law": (_bad(["law", "name"], "vff"), "law.name must be one of khatib, gnron; got 'vff'"),
    "unknown law option": (_bad(["law", "gamma"], 1), "law.gamma is not an option"),
    "unknown scene key": (_bad(["robot"], 1), "scene.robot is not an option"),
    "missing law key": (_bad(["law", "rho0"], KeyError), "law.rho0 is missing"),
    "missing goal exponent": (_bad(["law", "goal_exponent"], KeyError), "law.goal_exponent is missing"),
    "missing region": (_bad(["region"], KeyError), "scene.region is missing"),
    "non-numeric": (_bad(["law", "xi"], "fast"), "law.xi must be a finite number in (0, 1e+12]; got 'fast'"),
    "NaN": (_bad(["law", "eta"], float("nan")), "law.eta must be a finite number"),
    "inf": (_bad(["goal"], [float("inf"), 0]), "goal[0] must be a finite number"),
    "bool": (_bad(["law", "rho0"], True), "law.rho0 must be a finite number"),
    "attraction exponent": (_bad(["law", "attraction_exponent"], 3), "law.attraction_exponent must be 1 or 2; got 3"),
    "khatib with n": (_bad(["law", "name"], "khatib"), "law.goal_exponent must be 0 (or left out) for khatib; got 2"),
    "gnron with n = 0": (_bad(["law", "goal_exponent"], 0), "law.goal_exponent must be a finite number in (0, 10]"),
    "polygon with 2 vertices": (_bad(["obstacles", 2, "polygon"], [[0, 2], [1, 2]]), "obstacles[2].polygon must be a list of at least 3 vertices"),
    "self-intersecting polygon": (_bad(["obstacles", 2, "polygon"], [[-2, -2], [-1, -1], [-1, -2], [-2, -1]]), "obstacles[2].polygon intersects itself"),
    "repeated vertex": (_bad(["obstacles", 2, "polygon"], [[-2, -2], [-2, -2], [-1, -2]]), "obstacles[2].polygon is degenerate"),
    "collinear polygon": (_bad(["obstacles", 2, "polygon"], [[-2, -2], [-1.5, -2], [-1, -2]]), "obstacles[2].polygon is degenerate: zero area"),
    "degenerate segment": (_bad(["obstacles", 1, "segment", "to"], [-1, 1]), "obstacles[1].segment is degenerate"),
    "unknown obstacle": (_bad(["obstacles", 1], {"box": [1, 2]}), "obstacles[1] must be one of"),
    "point of 3": (_bad(["obstacles", 0, "circle", "center"], [1, 0, 0]), "obstacles[0].circle.center must be a point [x, y]"),
    "obstacles not a list": (_bad(["obstacles"], {"circle": 1}), "obstacles must be a list"),
    "not a mapping": ([1, 2, 3], "scene must be a mapping"),
}


@pytest.mark.parametrize("data, message", list(BAD_SCENES.values()), ids=list(BAD_SCENES))
def test_bad_scene_is_a_value_error_naming_the_field(data, message):
    with pytest.raises(ValueError) as info:
        Scene.from_dict(data)
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_scene_round_trips_and_library_checks_its_arguments():
    s = Scene.from_dict(GOOD)
    assert Scene.from_dict(s.to_dict()) == s
    with pytest.raises(ValueError, match="^resolution must be an integer in"):
        find_stationary_points(s, 5)
    with pytest.raises(ValueError, match="^scene must be a Scene"):
        find_stationary_points(GOOD)


def test_shipped_scenes_are_package_data():
    """`pip install .` takes the scenes along: pyproject lists data/scenes/*.yaml as package data of pfm_stability."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    patterns = config["tool"]["setuptools"]["package-data"].get("pfm_stability", [])
    assert any(Path("data/scenes/gc2000_fig3.yaml").match(p) for p in patterns)
    from pfm_stability.cli.traps import SHIPPED_SCENES

    assert sorted(SHIPPED_SCENES) == sorted(p.stem for p in SCENES.glob("*.yaml"))


# ------------------------------------------------------------------ the command
def run_cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def test_cli_text_output():
    code, out, err = run_cli(["traps", str(SCENES / "gc2000_fig4.yaml")])
    assert code == 0 and err == ""
    assert "stationary points:" in out and "<- goal" in out and "0.0549637" in out
    assert out.rstrip().splitlines()[-1] == "conclusion: trap at (-1.07809, 0)"


def test_cli_json_validates_and_plot_is_written(tmp_path):
    png = tmp_path / "fig3.png"
    code, out, err = run_cli(["traps", "gc2000_fig3", "--format", "json", "--plot", str(png), "--resolution", "41"])
    assert code == 0, err
    data = json.loads(out, parse_constant=lambda t: (_ for _ in ()).throw(ValueError(t)))
    assert [e.message for e in VALIDATOR.iter_errors(data)] == []
    assert data["command"] == "traps" and data["plot"] == str(png) and data["inputs"]["resolution"] == 41
    assert data["goal_is_global_minimum"] is True and len(data["stationary_points"]) == 2
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_json_with_undefined_values_validates(tmp_path):
    """Null bounds (Khatib's law), a non-C² goal (no Hessian), infinite conservative bounds ("inf", m = 1, n = 0)."""
    for law in ({"name": "khatib", "xi": 1, "eta": 0.1, "rho0": 0.8, "attraction_exponent": 2},
                {"name": "khatib", "xi": 1, "eta": 0.01, "rho0": 0.8, "attraction_exponent": 1},
                {"name": "gnron", "xi": 1, "eta": 1, "rho0": 2, "attraction_exponent": 2, "goal_exponent": 0.5}):
        path = tmp_path / "s.yaml"
        path.write_text(json.dumps({**GOOD, "law": law}))  # JSON is YAML
        code, out, err = run_cli(["traps", str(path), "--format", "json", "--resolution", "31"])
        assert code == 0, err
        data = json.loads(out)
        assert [e.message for e in VALIDATOR.iter_errors(data)] == []
    for mutate in (lambda d: d.update(command="report"), lambda d: d["stationary_points"][0].update(kind="trap"),
                   lambda d: d.update(extra=1), lambda d: d["gnron_bounds"][0].update(k_exact="Infinity")):
        broken = json.loads(out)
        mutate(broken)
        assert list(VALIDATOR.iter_errors(broken))


@pytest.mark.parametrize("name", ["negative radius", "obstacle covers the goal", "unknown law", "missing law key", "degenerate segment"])
def test_cli_bad_scene_exits_2_naming_the_field(tmp_path, name):
    data, message = BAD_SCENES[name]
    path = tmp_path / "bad.yaml"
    path.write_text(json.dumps(data))
    code, out, err = run_cli(["traps", str(path)])
    assert code == 2 and out == ""
    assert err.splitlines() == [f"pfm-stability: error: {err.splitlines()[0].split('error: ', 1)[1]}"]
    assert message in err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["traps", "/nonexistent/scene.yaml"], "scene /nonexistent/scene.yaml: cannot read the file (No such file or directory)"),
        (["traps", "gc2000_fig3", "--resolution", "5"], "resolution must be an integer in [10, 1000]; got '5'"),
        (["traps", "gc2000_fig3", "--resolution", "x"], "resolution must be an integer"),
        (["traps", "gc2000_fig3", "--plot", "/nonexistent/dir/x.png"], "plot must be a writable file path ending in .png"),
        (["traps", "gc2000_fig3", "--plot", "x.pdf"], "plot must be a writable file path ending in .png"),
        (["traps", "gc2000_fig3", "--format", "xml"], "invalid choice"),
    ],
)
def test_cli_bad_arguments_exit_2(argv, message):
    code, out, err = run_cli(argv)
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and message in err


def test_cli_not_yaml_and_not_a_mapping(tmp_path):
    path = tmp_path / "x.yaml"
    path.write_text("law: [unclosed\n")
    assert f"scene {path}, line 2: not valid YAML" in run_cli(["traps", str(path)])[2]
    path.write_text("just text\n")
    assert "scene must be a mapping" in run_cli(["traps", str(path)])[2]
    path.write_bytes(b"\xff\xfe\x00bad")
    code, _, err = run_cli(["traps", str(path)])
    assert code == 2 and f"scene {path}: cannot read the file" in err
