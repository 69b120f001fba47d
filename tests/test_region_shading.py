"""Which model the region maps shade, and that each map says what its model says point by point.

The dense maps of `pfm_stability.analysis.regions` shade, by default, the model the
stability report's verdict uses (``sampled`` with the controller's hold and
compute delay). Checked here:

* at KB's Fig 6a point (CARMEL, L = 0.9 m, V = 0.8 m/s) and Fig 5 point
  (α = 20°) the shaded verdict is the report's ``sampled`` verdict, in the
  map and in the drawn figure;
* every map verdict equals the model's own `is_stable(NV, loop)` (eigenvalues,
  Routh or crossing count — not the boundary the map used) on a sample of grid
  points and on points just inside and outside every edge of the stable set,
  for CARMEL and for two loops far from it whose stable sets are unusual:
  command hold without compute delay at kT = 3 (τ = 0.03 s, T = 0.2 s,
  k = 15 1/s: stable only for NV in (1.62, 3.82) 1/s, not near NV = 0) and
  reference hold at kT ≈ 6.2 (two stable intervals);
* asked for ``exact_delay``, the maps keep the vectorized crossing count,
  which agrees with the stable-set route away from the boundary.

Tolerances. Verdicts are booleans and compared exactly; the only tolerance is
how close to an edge of the stable set a point may be. Grid points closer
than 1e-6 (relative, in NV) to an edge are skipped: there the boundary (found
to ~1e-12) and `is_stable` (a pole modulus within round-off of 1) may
legitimately differ — the report calls such points "undecided" (1e-9). The
edge probes sit 1e-3 (relative) inside and outside each edge: far beyond
the boundary's error, close enough that a misplaced edge (a wrong interval,
NV* used instead of the stable set) fails.
"""

import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from pfm_stability.laws.force_law import ForceLaw, PowerLaw, corridor_gain, wall_gain  # noqa: E402
from pfm_stability.models import ExactDelay, Loop, Sampled, models_for  # noqa: E402
from pfm_stability.models.verdicts import in_stable_set  # noqa: E402
from pfm_stability.parameters import CARMEL, Controller, Robot  # noqa: E402
from pfm_stability.analysis.region_panels import corridor_V_panel, wall_alpha_panel  # noqa: E402
from pfm_stability.plots.regions import plot_corridor_region, plot_wall_alpha_critical  # noqa: E402
from pfm_stability.analysis.regions import (  # noqa: E402
    corridor_region,
    region_model,
    verdict_model,
    wall_alpha_region,
    wall_f_region,
)
from pfm_stability.report.stability import build_report  # noqa: E402

ROBOT, CONTROLLER = CARMEL.robot, CARMEL.controller

# far from CARMEL: (robot, controller) whose sampled stable set is not (0, NV*)
HOLD_GAP = (Robot(V=0.8, tau=0.03, k=15.0, W=0.8), Controller(f=0.8, n=2.0, T=0.2, hold="command", compute_delay=0))
TWO_BANDS = (Robot(V=0.8, tau=0.1, k=6.1923 / 0.2, W=0.8), Controller(f=0.8, n=2.0, T=0.2, hold="reference", compute_delay=0))
CASES = {"carmel": (ROBOT, CONTROLLER), "hold-gap": HOLD_GAP, "two-bands": TWO_BANDS}
EDGE_SKIP = 1e-6
EDGE_PROBE = 1e-3


def _loop(robot, controller):
    return Loop(robot.tau, controller.T, robot.k)


def _edges(stable_set):
    return [x for pair in stable_set for x in pair if 0 < x < math.inf]


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


# ------------------------------------------------------------------ the shaded model
def test_the_unusual_loops_are_unusual():
    """The two loops far from CARMEL have the stable sets the map tests rely on."""
    (gap,) = Sampled("command", 0).boundary(_loop(*HOLD_GAP)).stable_set
    assert Sampled("command", 0).boundary(_loop(*HOLD_GAP)).NV_critical == 0 and 1.0 < gap[0] < gap[1] < 5.0
    assert len(Sampled("reference", 0).boundary(_loop(*TWO_BANDS)).stable_set) == 2


def test_default_shading_is_the_report_verdict_model():
    """Default: sampled with the controller's hold and compute delay; other models by name or object."""
    assert verdict_model(CONTROLLER) == Sampled(CONTROLLER.hold, CONTROLLER.compute_delay) == region_model(CONTROLLER)
    assert region_model(CONTROLLER, "exact_delay") == ExactDelay()
    region = corridor_region(ROBOT, CONTROLLER, [0.9], [0.8])
    assert (region.model, region.options) == ("sampled", {"hold": "command", "compute_delay": 1})
    assert region.stable_set == Sampled("command", 1).boundary(_loop(ROBOT, CONTROLLER)).stable_set
    assert corridor_region(ROBOT, CONTROLLER, [0.9], [0.8], model="exact_delay").stable_set is None
    with pytest.raises(ValueError, match="contradicts the controller"):
        corridor_region(ROBOT, CONTROLLER, [0.9], [0.8], model=Sampled("reference", 0))


def test_fig6a_and_fig5_shading_is_the_report_verdict():
    """CARMEL at KB's Fig 6a (corridor L = 0.9 m) and Fig 5 (wall α = 20°), V = 0.8 m/s:
    the shaded verdict is the report's sampled verdict ("unstable": Fig 6a is 5.5 % past NV*,
    so no tolerance is needed), while exact_delay calls Fig 6a stable — the figure used to shade that."""
    corridor = build_report(ROBOT, CONTROLLER, L=0.9).corridor.models["sampled"].verdict
    wall = build_report(ROBOT, CONTROLLER, alpha_deg=20.0).wall.models["sampled"].verdict
    assert corridor == "unstable" and wall == "unstable"
    assert corridor_region(ROBOT, CONTROLLER, [0.9], [ROBOT.V]).stable[0, 0] == (corridor == "stable")
    assert wall_alpha_region(ROBOT, CONTROLLER, [ROBOT.V], [math.radians(20.0)]).stable[0, 0] == (wall == "stable")
    assert corridor_region(ROBOT, CONTROLLER, [0.9], [ROBOT.V], model="exact_delay").stable[0, 0]
    # the drawn figure: the shading cell at (L, V) = (0.9, 0.8) has the report's colour
    fig = plot_corridor_region(corridor_V_panel(ROBOT, CONTROLLER, L=[0.85, 0.9, 0.95], V=[0.7, 0.8, 0.9]), legend=False)
    from matplotlib.collections import QuadMesh

    (mesh,) = [c for c in fig.axes[0].collections if isinstance(c, QuadMesh)]
    assert np.asarray(mesh.get_array()).reshape(3, 3)[1, 1] == (1.0 if corridor == "stable" else 0.0)
    fig = plot_wall_alpha_critical(wall_alpha_panel(ROBOT, CONTROLLER, V=np.linspace(0.7, 0.9, 3), resolution=3), legend=False)
    assert "shaded: sampled (command hold, compute delay 1)" in fig.axes[0].get_title()


# ------------------------------------------------------------------ map = is_stable, point by point
def _check_points(model, loop, NV, stable):
    """Map verdicts equal model.is_stable at every point not within EDGE_SKIP of an edge; returns the count."""
    edges = np.array(_edges(model.boundary(loop).stable_set))
    checked = 0
    for nv, s in zip(np.ravel(NV), np.ravel(stable)):
        if edges.size and np.min(np.abs(nv / edges - 1.0)) < EDGE_SKIP:
            continue
        assert bool(s) == model.is_stable(float(nv), loop), (model, nv)
        checked += 1
    return checked


@pytest.mark.parametrize("case", list(CASES))
def test_corridor_map_equals_is_stable_on_a_sample(case):
    """(L, V) maps of every model: 40 random grid points each, verdict = model.is_stable(NV) (exact)."""
    robot, controller = CASES[case]
    loop = _loop(robot, controller)
    L, V = np.linspace(0.45, 2.0, 25), np.linspace(0.05, 2.0, 30)
    rng = np.random.default_rng(7)
    picks = rng.choice(L.size * V.size, 40, replace=False)
    for model in models_for(controller):
        region = corridor_region(robot, controller, L, V, model=model)
        assert region.model == model.name
        assert _check_points(model, loop, region.NV.ravel()[picks], region.stable.ravel()[picks]) >= 38


@pytest.mark.parametrize("case", list(CASES))
def test_maps_flip_at_every_edge_of_the_stable_set(case):
    """Probes 1e-3 inside and outside every finite edge of the shaded model's stable set, in all three maps:
    the map and is_stable agree, and the verdict changes across each edge."""
    robot, controller = CASES[case]
    loop = _loop(robot, controller)
    model = verdict_model(controller)
    edges = _edges(model.boundary(loop).stable_set)
    assert edges
    NV = np.array([e * (1 + s * EDGE_PROBE) for e in edges for s in (-1, 1)])
    law = PowerLaw(controller.f, controller.n, robot.W)
    L, alpha = 0.9, math.radians(40.0)
    maps = [
        corridor_region(robot, controller, [L], NV / corridor_gain(law, L)).stable[:, 0],
        wall_alpha_region(robot, controller, NV / wall_gain(law, alpha)[1], [alpha]).stable[0],
        wall_f_region(robot, controller, alpha, NV / wall_gain(law, alpha)[1], [controller.f]).stable[0],
    ]
    expected = [model.is_stable(float(nv), loop) for nv in NV]
    assert all(expected[2 * i] != expected[2 * i + 1] for i in range(len(edges)))  # each probe pair straddles an edge
    for stable in maps:
        assert stable.tolist() == expected
    assert in_stable_set(model.boundary(loop).stable_set, NV).tolist() == expected


def test_hold_gap_map_is_unstable_at_low_speed():
    """The command-hold loop at kT = 3 is unstable for small NV: slow is not safe there, and the map shows it
    (NV* alone, 0, would call the whole plane unstable; the stable set gives a band)."""
    robot, controller = HOLD_GAP
    region = corridor_region(robot, controller, [0.9], np.linspace(0.05, 2.0, 60))
    (lo, hi), = region.stable_set
    assert not region.stable[0, 0] and region.stable.any() and not region.stable[-1, 0]
    inside = (region.NV[:, 0] > lo) & (region.NV[:, 0] < hi)
    assert np.array_equal(region.stable[:, 0], inside)


def test_exact_delay_map_keeps_the_crossing_count():
    """model="exact_delay": vectorized crossing counts (stable_set None), equal to the stable-set route and to
    is_stable away from the boundary (points within 1e-6 of NV* skipped), for KB's law and a general law."""
    loop = _loop(ROBOT, CONTROLLER)
    L, V = np.linspace(0.45, 2.0, 40), np.linspace(0.05, 2.0, 50)
    region = corridor_region(ROBOT, CONTROLLER, L, V, model="exact_delay")
    assert region.stable_set is None
    b = ExactDelay().boundary(loop)
    far = np.abs(region.NV / b.NV_critical - 1) > EDGE_SKIP
    assert np.array_equal(region.stable[far], in_stable_set(b.stable_set, region.NV)[far])
    assert _check_points(ExactDelay(), loop, region.NV.ravel()[::97], region.stable.ravel()[::97]) >= 20
    alpha = np.radians([15.0, 35.0, 60.0])
    general = wall_alpha_region(ROBOT, CONTROLLER, V, alpha, law=_Opaque(PowerLaw(CONTROLLER.f, CONTROLLER.n, ROBOT.W)), model="exact_delay")
    power = wall_alpha_region(ROBOT, CONTROLLER, V, alpha, model="exact_delay")
    assert np.array_equal(general.stable, power.stable)


def test_general_law_route_uses_the_stable_set_too():
    """A law behind the generic interface (general-law N) gives the same sampled map as KB's closed form."""
    robot, controller = HOLD_GAP
    law = PowerLaw(controller.f, controller.n, robot.W)
    L, V = np.linspace(0.45, 2.0, 30), np.linspace(0.05, 2.0, 30)
    a = corridor_region(robot, controller, L, V)
    b = corridor_region(robot, controller, L, V, law=_Opaque(law))
    np.testing.assert_allclose(b.NV, a.NV, rtol=1e-12)
    assert np.array_equal(a.stable, b.stable) and a.stable.any() and not a.stable.all()


class _Opaque(ForceLaw):
    """KB's power law behind the generic ForceLaw interface (forces the general-law code path)."""

    def __init__(self, law):
        self.law, self.name = law, "opaque power law"

    @property
    def scale(self):
        return self.law.scale

    def force(self, d):
        return self.law.force(d)

    def slope(self, d):
        return self.law.slope(d)

    def with_scale(self, scale):
        return _Opaque(self.law.with_scale(scale))
