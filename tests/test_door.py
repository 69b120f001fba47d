"""Passage between two closely spaced obstacles (`pfm_stability.analysis.door`; KB 1991 §5.2, Fig 4; docs/door.md).

Independent routes to every number:

* KB's power law between point posts: the closed form of the peak (s* = a/√n),
  of the narrowest width and, for n = 2, of the stop (a cubic in c²), and the
  trigonometric root of the cubic for posts with a radius;
* Khatib's law (a test-local `ForceLaw` built from `potentials.khatib_force`)
  and Ge & Cui's goal-aware law (with a goal-directed part, from
  `potentials.gnron_forces`): a brute-force dense scan of F_long written here
  from the potentials, not through the module;
* the 2-D field `door_field` (nearest points computed for each obstacle kind)
  against the axis formulas, and its finite-difference lateral derivative
  against the reported stiffness;
* the meaning of the answers: passage is monotone in the width, the smallest
  passable width is a boundary, bad input → ValueError naming the argument,
  JSON round-trips.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace

import numpy as np
import pytest

from pfm_stability.analysis.door import (
    OBSTACLES,
    DoorPassage,
    approach_force,
    door_field,
    door_passage,
    power_law_door_peak,
    power_law_door_width,
    smallest_passable_width,
)
from pfm_stability.laws.force_law import ForceLaw, PowerLaw
from pfm_stability.parameters import CARMEL
from pfm_stability.laws.potentials import (
    attraction_force,
    gnron_forces,
    khatib_force,
    repulsion_derivatives,
)
from pfm_stability.io.serialize import dumps

CARMEL_LAW = PowerLaw(CARMEL.controller.f, CARMEL.controller.n, CARMEL.robot.W)  # f = 0.8, n = 2, W = 0.8 m


@dataclass(frozen=True)
class KhatibLaw(ForceLaw):
    """Khatib's repulsion η(1/d − 1/ρ0)/d² (GC2000 eq 4) in units of a constant attraction A."""

    eta: float
    rho0: float
    A: float = 1.0
    name = "Khatib (test)"

    def force(self, d):
        """P(d)/A."""
        return khatib_force(np.asarray(d, dtype=float), self.eta, self.rho0) / self.A

    def slope(self, d):
        """dP/dd / A = −U_ρρ/A."""
        return -repulsion_derivatives(np.asarray(d, dtype=float), 1.0, self.eta, self.rho0)[3] / self.A

    def with_scale(self, scale):
        """Another η."""
        return replace(self, eta=scale)


@dataclass(frozen=True)
class GoalAwareLaw(ForceLaw):
    """Ge & Cui's goal-aware repulsion at a frozen goal distance ρ_g: F_rep1/A and F_rep2/A (GC2000 eq 10, 11)."""

    eta: float
    rho0: float
    n: float
    rho_g: float
    xi: float = 1.0
    m: float = 1.0
    name = "goal-aware (test)"

    def __post_init__(self):
        object.__setattr__(self, "A", float(attraction_force(self.rho_g, self.xi, self.m)))  # the attraction at ρ_g (eq 1)

    def force(self, d):
        """F_rep1(d)/A."""
        return gnron_forces(np.asarray(d, dtype=float), self.rho_g, self.eta, self.rho0, self.n)[0] / self.A

    def goal_force(self, d):
        """F_rep2(d)/A, towards the goal."""
        return gnron_forces(np.asarray(d, dtype=float), self.rho_g, self.eta, self.rho0, self.n)[1] / self.A

    def slope(self, d):
        """dF_rep1/dd / A = −U_ρρ/A."""
        return -repulsion_derivatives(np.asarray(d, dtype=float), self.rho_g, self.eta, self.rho0, self.n)[3] / self.A

    def with_scale(self, scale):
        """Another η."""
        return replace(self, eta=scale)


# Khatib matched to CARMEL: ρ0 = 1.65 m (the active window's half side), F_r(W) = f = 0.8.
KHATIB = KhatibLaw(eta=0.8 * 0.64 / (1 / 0.8 - 1 / 1.65), rho0=1.65)
GOAL_AWARE = GoalAwareLaw(eta=0.3, rho0=1.65, n=2.0, rho_g=2.0)


def brute_force_long(P, Q, a, r, s):
    """F_long on the axis written out from the geometry: two repulsions P along (post → robot), Q forward."""
    total = np.ones_like(s)
    for side in (1.0, -1.0):
        dx, dy = 0.0 - side * a, -s  # robot at (0, −s), post centre at (±a, 0)
        dist = np.hypot(dx, dy)
        total += P(dist - r) * dy / dist + Q(dist - r)
    return total


# ------------------------------------------------------------------ KB's power law: closed forms
@pytest.mark.parametrize("n", [0.5, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("width", [0.9, 1.2, 2.5])
def test_power_law_peak_matches_closed_form(n, width):
    """Point posts: peak 2f(W/a)ⁿnⁿᐟ²/(n+1)^((n+1)/2) at s* = a/√n (docs/door.md). The scan's maximum is
    refined on the root of the analytic slope, so the peak agrees to rounding (1e-12) and its place to
    ~√ε relative of a flat maximum (1e-7)."""
    law = PowerLaw(0.8, n, 0.8)
    p = door_passage(law, width)
    a = width / 2
    closed = 2 * 0.8 * (0.8 / a) ** n * n ** (n / 2) / (n + 1) ** ((n + 1) / 2)
    assert power_law_door_peak(0.8, n, 0.8, width)[0] == pytest.approx(closed, rel=1e-13)
    assert p.peak_repulsion == pytest.approx(closed, rel=1e-12)
    assert p.peak_distance == pytest.approx(a / math.sqrt(n), rel=1e-7)
    assert p.margin == pytest.approx(1 - closed, abs=1e-12)
    assert p.passes == (closed < 1)


@pytest.mark.parametrize("r", [0.05, 0.2, 0.39])
def test_power_law_peak_with_post_radius_matches_the_cubic(r):
    """Posts of radius r: the peak sits at the root c* > a of n c³ − (n+1)a²c + a²r = 0. The closed form's
    root is checked to be a root (1e-12 relative residual), then the numeric peak against it (1e-12)."""
    width = 1.6
    a = width / 2
    peak, s_star = power_law_door_peak(0.8, 2.0, 0.8, width, r)
    c = math.hypot(a, s_star)
    assert abs(2 * c**3 - 3 * a * a * c + a * a * r) <= 1e-12 * c**3
    p = door_passage(CARMEL_LAW, width, post_radius=r)
    assert p.peak_repulsion == pytest.approx(peak, rel=1e-12)
    assert p.peak_distance == pytest.approx(s_star, rel=1e-7)


def test_carmel_smallest_width_closed_form():
    """CARMEL (f = 0.8, n = 2, W = 0.8 m), point posts: w* = 2W√(4f/(3√3)) = 1.25561 m. The numeric
    boundary is bisected to rtol 1e-12 on a peak exact to rounding, so 1e-11."""
    closed = 2 * 0.8 * math.sqrt(4 * 0.8 / (3 * math.sqrt(3)))
    assert power_law_door_width(0.8, 2.0, 0.8) == pytest.approx(closed, rel=1e-14)
    assert closed == pytest.approx(1.25561, abs=5e-6)
    for obstacle in OBSTACLES:  # a wall end seen from the axis is a post at its end
        assert smallest_passable_width(CARMEL_LAW, obstacle=obstacle) == pytest.approx(closed, rel=1e-11)


@pytest.mark.parametrize("width", [0.9, 1.0, 1.1, 1.2, 1.25])
def test_power_law_stop_and_lateral_verdict(width):
    """n = 2, points: the stop solves 2fW²s = c³, i.e. u³ = 4f²W⁴(u − a²) with u = c² (largest root;
    numpy's cubic roots polished by one Newton step: 1e-10). At the stop −∂F_x/∂x = −2F_r(s² − na²)/c³:
    trapped iff s < √n·a (exact sign)."""
    f, W, a = 0.8, 0.8, width / 2
    roots = np.roots([1.0, 0.0, -4 * f * f * W**4, 4 * f * f * W**4 * a * a])
    u = max(z.real for z in roots if abs(z.imag) < 1e-9 and z.real > a * a)
    u -= (u**3 - 4 * f * f * W**4 * (u - a * a)) / (3 * u * u - 4 * f * f * W**4)
    s_stop = math.sqrt(u - a * a)
    p = door_passage(CARMEL_LAW, width)
    assert not p.passes
    assert p.stop_distance == pytest.approx(s_stop, rel=1e-10)
    c = math.hypot(a, s_stop)
    k = -2 * f * (W / c) ** 2 * (s_stop**2 - 2 * a * a) / c**3
    assert p.lateral_stiffness == pytest.approx(k, rel=1e-9)
    assert p.at_stop == ("trapped" if s_stop < math.sqrt(2) * a else "turns away")


# ------------------------------------------------------------------ Khatib and goal-aware: brute force
@pytest.mark.parametrize("law, width, r", [(KHATIB, 1.0, 0.0), (KHATIB, 1.25, 0.0), (KHATIB, 1.5, 0.1), (GOAL_AWARE, 1.0, 0.0), (GOAL_AWARE, 1.3, 0.05)])
def test_numeric_against_dense_scan(law, width, r):
    """F_long on 10⁶ points of s ∈ (0, 2 m] (beyond, every post is farther than ρ0 = 1.65 m: no force), written
    out from the potentials here. Its minimum misses the true one by at most ½|g''|Δs² < 2e-10 (Δs = 2 µm,
    |g''| < 1e2 1/m²): 1e-9. The stop is the last grid point with F_long <= 0, within Δs: 3e-6."""
    a = width / 2
    s = np.linspace(1e-7, 2.0, 1_000_001)
    P = lambda d: law.force(d)
    Q = (lambda d: law.goal_force(d)) if hasattr(law, "goal_force") else (lambda d: 0.0 * d)
    F = brute_force_long(P, Q, a, r, s)
    p = door_passage(law, width, post_radius=r, robot_width=0.4)
    assert p.margin == pytest.approx(F.min(), abs=1e-9)
    assert p.peak_distance == pytest.approx(s[np.argmin(F)], abs=2e-3)  # a flat minimum: located to ~√(1e-9)
    assert p.passes == bool(F.min() > 0)
    if not p.passes:
        assert p.stop_distance == pytest.approx(s[np.flatnonzero(F <= 0)[-1]], abs=3e-6)
    assert p.goal_force == isinstance(law, GoalAwareLaw)


@dataclass(frozen=True)
class GoalAwareLawWithSlope(GoalAwareLaw):
    """The same law with Q′ given (dF_rep2/dρ / A = U_ρg/A), as a `ForceLaw` with ``goal_slope`` provides it."""

    def goal_slope(self, d):
        """Q′(d)."""
        return repulsion_derivatives(np.asarray(d, dtype=float), self.rho_g, self.eta, self.rho0, self.n)[4] / self.A


def test_goal_slope_used_when_given():
    """A law's own Q′ and the module's central difference of Q (relative step 1e-6, error ~1e-11) locate the same
    peak: results agree to 1e-9 (the peak's value is insensitive to its place to first order)."""
    for width in (1.0, 1.3):
        a = door_passage(GOAL_AWARE, width, robot_width=0.4)
        b = door_passage(GoalAwareLawWithSlope(**{k: getattr(GOAL_AWARE, k) for k in ("eta", "rho0", "n", "rho_g")}), width, robot_width=0.4)
        assert b.peak_repulsion == pytest.approx(a.peak_repulsion, rel=1e-9)
        assert b.peak_distance == pytest.approx(a.peak_distance, rel=1e-6)
        if a.stop_distance is not None:
            assert b.stop_distance == pytest.approx(a.stop_distance, rel=1e-9)


def test_goal_force_lets_a_narrower_door_pass():
    """F_rep2 points through the door (forward): with it the narrowest passable width is smaller than with
    the same F_rep1 alone (two bisections at rtol 1e-8, far apart: 2 %)."""
    with_goal = smallest_passable_width(GOAL_AWARE, robot_width=0.4, rtol=1e-8)
    alone = smallest_passable_width(KhatibLaw(GOAL_AWARE.eta * GOAL_AWARE.rho_g**2, GOAL_AWARE.rho0, GOAL_AWARE.A), robot_width=0.4, rtol=1e-8)
    assert with_goal < 0.98 * alone


# ------------------------------------------------------------------ the 2-D field
@pytest.mark.parametrize("obstacle", OBSTACLES)
def test_field_on_the_axis(obstacle):
    """`door_field` (nearest points of posts or half-lines, in 2-D) on the axis: F_x = 0 by symmetry (1e-12),
    F_y = `approach_force` (rounding: 1e-12); −∂F_x/∂x by a central difference (h = 1e-5 m, error ~h² < 1e-8)
    equals the reported lateral stiffness (1e-6 relative)."""
    for law, width in ((CARMEL_LAW, 1.1), (KHATIB, 1.1)):
        s = np.linspace(0.01, 2.0, 50)
        fx, fy = door_field(law, width, 0.0, -s, obstacle=obstacle, post_radius=0.05)
        assert np.max(np.abs(fx)) <= 1e-12
        np.testing.assert_allclose(fy, approach_force(law, width, s, post_radius=0.05), rtol=0, atol=1e-12)
        p = door_passage(law, width, obstacle=obstacle, post_radius=0.05)
        h = 1e-5
        dfx = (door_field(law, width, h, -p.stop_distance, obstacle=obstacle, post_radius=0.05)[0]
               - door_field(law, width, -h, -p.stop_distance, obstacle=obstacle, post_radius=0.05)[0]) / (2 * h)
        assert p.lateral_stiffness == pytest.approx(-float(dfx), rel=1e-6)


def test_wall_ends_differ_from_posts_only_beside_the_opening():
    """For |x| < w/2 a wall end's nearest point is its end, so the fields agree (to 4 ULP: the two obstacles
    take different code paths to the same distances); in front of the wall (|x| > w/2) the wall's nearest
    point is straight ahead and the fields differ."""
    law, w = CARMEL_LAW, 1.2
    x, y = np.meshgrid(np.linspace(-0.59, 0.59, 13), np.linspace(-2.0, 2.0, 17))
    for a, b in zip(door_field(law, w, x, y, obstacle="posts"), door_field(law, w, x, y, obstacle="wall-ends")):
        np.testing.assert_allclose(a, b, rtol=4 * np.finfo(float).eps, atol=0)
    posts = door_field(law, w, 1.0, -0.5, obstacle="posts")
    wall = door_field(law, w, 1.0, -0.5, obstacle="wall-ends")
    d = math.hypot(0.4, 0.5)  # robot at (1, −0.5): right post at distance d; the right wall's nearest point (1, 0) is 0.5 ahead
    assert posts[0] - wall[0] == pytest.approx(float(law.force(d)) * 0.4 / d, rel=1e-12)
    assert wall[1] - posts[1] == pytest.approx(float(-law.force(0.5) + law.force(d) * 0.5 / d), rel=1e-12)
    assert np.isnan(door_field(law, w, 1.0, 0.0, obstacle="wall-ends")[0])  # inside the wall


# ------------------------------------------------------------------ what the answers mean
@pytest.mark.parametrize("law, r", [(CARMEL_LAW, 0.0), (CARMEL_LAW, 0.1), (KHATIB, 0.0)])
def test_passage_is_monotone_in_width(law, r):
    """A wider door never blocks a robot a narrower one lets through (each repulsion falls with distance):
    on 40 widths the verdicts are False…False True…True and the peak falls strictly."""
    widths = np.linspace(0.8 + 2 * r + 0.01, 3.0, 40)
    results = [door_passage(law, float(w), post_radius=r) for w in widths]
    verdicts = [p.passes for p in results]
    assert verdicts == sorted(verdicts) and verdicts[0] is False and verdicts[-1] is True
    assert np.all(np.diff([p.peak_repulsion for p in results]) < 0)


@pytest.mark.parametrize("law, r", [(CARMEL_LAW, 0.0), (CARMEL_LAW, 0.1), (KHATIB, 0.05), (GOAL_AWARE, 0.0)])
def test_smallest_width_is_a_boundary(law, r):
    """w* is bisected to rtol 1e-12; the peak changes by O(1) per unit of w/a, so at w*(1 ± 1e-9) the
    verdicts must be clean: passes just above, stops just below."""
    w = smallest_passable_width(law, post_radius=r, robot_width=0.4)
    assert door_passage(law, w * (1 + 1e-9), post_radius=r, robot_width=0.4).passes
    assert not door_passage(law, w * (1 - 1e-9), post_radius=r, robot_width=0.4).passes


def test_fit_limit():
    """A weak law lets the robot through any opening it fits: the answer is the fit limit W + 2r (exact),
    and a strong one blocks up to a finite width."""
    weak = PowerLaw(1e-4, 2.0, 0.8)
    assert smallest_passable_width(weak, post_radius=0.1) == 0.8 + 0.2
    assert door_passage(weak, 1.0 + 1e-6, post_radius=0.1).passes
    assert math.isfinite(smallest_passable_width(PowerLaw(100.0, 2.0, 0.8)))


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"width": 0.0}, "width"),
        ({"width": -1.0}, "width"),
        ({"width": math.nan}, "width"),
        ({"width": 0.7}, "width"),  # W = 0.8 m does not fit
        ({"width": 1.0, "post_radius": 0.15}, "width"),  # 0.8 + 0.3 > 1
        ({"width": 1.0, "obstacle": "door"}, "obstacle"),
        ({"width": 1.0, "post_radius": -0.1}, "post_radius"),
        ({"width": 1.0, "post_radius": math.nan}, "post_radius"),
        ({"width": 1.0, "robot_width": -1.0}, "robot_width"),
        ({"width": 1.0, "robot_width": math.inf}, "robot_width"),
        ({"width": "1"}, "width"),
    ],
)
def test_bad_input_names_the_argument(kwargs, name):
    """Every bad argument → one-line ValueError starting with the argument's name (the CLI prints it verbatim)."""
    width = kwargs.pop("width")
    with pytest.raises(ValueError) as err:
        door_passage(CARMEL_LAW, width, **kwargs)
    assert str(err.value).startswith(name + " ") and "\n" not in str(err.value)


def test_bad_law_and_other_entry_points():
    """The law must be a ForceLaw; `smallest_passable_width`, `approach_force` and `door_field` check too."""
    with pytest.raises(ValueError, match="^law "):
        door_passage(lambda d: d, 1.0)
    with pytest.raises(ValueError, match="^obstacle "):
        smallest_passable_width(CARMEL_LAW, obstacle="gap")
    with pytest.raises(ValueError, match="^distance "):
        approach_force(CARMEL_LAW, 1.0, [-1.0])
    with pytest.raises(ValueError, match="^width "):
        door_field(CARMEL_LAW, 0.2, 0.0, -1.0, post_radius=0.1)


@pytest.mark.parametrize("width", [1.0, 2.0])
def test_json_round_trip(width):
    """`to_dict` is strict JSON (`serialize.dumps`, allow_nan=False) and `from_dict` gives the same result back
    (floats survive JSON exactly); inf is written "inf", a missing stop null."""
    p = door_passage(CARMEL_LAW, width, obstacle="wall-ends", post_radius=0.05, find_smallest=True)
    data = json.loads(dumps(p.to_dict()))
    assert DoorPassage.from_dict(data) == p
    assert data["passes"] == p.passes and (data["stop_distance"] is None) == p.passes
    assert data["at_stop"] == p.at_stop and data["geometry"]["opening"] == pytest.approx(width - 0.1)
    far = door_passage(KhatibLaw(eta=1.0, rho0=0.4), 1.0, robot_width=0.4)  # posts beyond ρ0: no force at all
    assert far.to_dict()["peak_distance"] == "inf" and far.margin == 1.0 and DoorPassage.from_dict(far.to_dict()) == far


def test_report_door_option_gives_the_library_answer():
    """`pfm-stability report --door W` prints `door_passage` of the preset's law (JSON under "door"), and a
    door the robot cannot fit through exits 2 naming --door's parameter."""
    import contextlib
    import io
    import json

    from pfm_stability.cli import main
    from pfm_stability.analysis.door import door_passage
    from pfm_stability.laws.force_law import PowerLaw
    from pfm_stability.parameters import CARMEL

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["report", "--door", "1.2", "--format", "json"]) == 0
    data = json.loads(out.getvalue())["door"]
    c, r = CARMEL.controller, CARMEL.robot
    expected = door_passage(PowerLaw(c.f, c.n, r.W), 1.2, robot_width=r.W, find_smallest=True).to_dict()
    assert data == json.loads(json.dumps(expected))
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(["report", "--door", "0.5"])
        except SystemExit as e:
            code = e.code
    assert code == 2 and "door must be" in err.getvalue()
