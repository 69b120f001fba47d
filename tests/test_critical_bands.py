"""Critical values of a law that is not monotone: the nearest change of verdict, bands included, and its side.

docs/fields.md ("Critical values of a law's parameters"): L*, ρ0*, η* (and ξ*) of
Khatib's and the goal-aware law are the values nearest the operating point (in
log p) at which the verdict of the middle of the corridor changes. The goal-aware
law's N rises steeply towards ρ0 and drops to 0 at L = ρ0 (the repulsion's support
ends), so an unstable band can end at ρ0 — narrower than the search's 8 steps per
decade. The oracle is a dense brute-force scan written here: 2,000 values of the
parameter geometric on both sides of the operating point, N from
`force_law.corridor_gain` at each, the verdict from the model's own `is_stable`
(where N = 0 the report's own answer for a corridor without force), and the first
change of verdict from the operating point. The reported critical value must lie
in that cell (or, if the grid steps over a still narrower band, the verdict must
change at the reported value itself), and its `stable_side` must be the side on
which the verdict is stable just past it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cli_helpers import report_json, run
from pfm_stability.analysis.criteria import analyze_corridor, loop_of
from pfm_stability.laws.fields import GnronLaw
from pfm_stability.laws.force_law import PowerLaw, corridor_gain
from pfm_stability.models import Continuous
from pfm_stability.parameters import CARMEL, RANGES, Corridor

MODEL = Continuous()
POINTS = 1000
"""Grid points on each side of the operating point (2,000 in all)."""
GAP = 1e-7
"""Relative distance from a critical value at which its two sides are probed: above the search's 1e-9
(Newton's bracket) and the breakpoint gap (1e-9), far below the grid's spacing."""

BRIEF = dict(law=GnronLaw(0.024262860706326623, 3.079417469386693, 0.8148293100062761, 3, 1.4012249366010598, 0.20883113886193813),
             V=0.10507908166853012, tau=0.11863968682455824, W=0.2, L=0.9377)
"""The reported case: L* was 0.1173 m while the verdict changes at L = ρ0 = 0.81483 m."""


def _case(seed: int) -> dict:
    """A random goal-aware law, robot and corridor with an unstable band just inside ρ0.

    The goal part dominates (small ξ, η of order 1, n > 0): 1 + 2Q falls to 1 as L
    nears ρ0, so N rises steeply there and the band is mostly narrower than a search
    step (a factor 1.33 in L).

    V makes N·V exceed the continuous loop's NV* = 1/τ just inside ρ0 (by 5 % to a
    factor 2), so the verdict changes at ρ0 and at the band's other end; the operating
    point lies beyond ρ0 (N = 0) for even seeds and inside the support for odd ones.
    """
    rng = np.random.default_rng(seed)
    W = rng.uniform(0.1, 0.5)
    rho0 = 10 ** rng.uniform(-0.2, 0.4)
    law = GnronLaw(10 ** rng.uniform(-3, -1), 10 ** rng.uniform(0, 1), rho0, float(rng.choice([2.0, 3.0])), rng.uniform(0.5, 2),
                   10 ** rng.uniform(-0.7, 0.3))
    tau = 10 ** rng.uniform(-1.2, -0.4)
    N1 = corridor_gain(law, rho0 * (1 - 1e-6))
    V = min(rng.uniform(1.05, 2.0) / (tau * N1), RANGES["V"].high)
    L = rho0 * (rng.uniform(1.01, 1.1) if seed % 2 == 0 else rng.uniform(max(0.3, 0.6 * W / rho0), 0.98))
    return dict(law=law, V=V, tau=tau, W=W, L=L)


def _setup(case):
    robot = CARMEL.robot.replace(W=case["W"], V=case["V"], tau=case["tau"])
    return robot, CARMEL.controller


def _verdicts(case, gains):
    """The verdict at each N (array): the model's `is_stable` at N·V, the report's own verdict where N = 0."""
    robot, controller = _setup(case)
    loop = loop_of(robot, controller)
    beyond = analyze_corridor(robot, controller, Corridor(case["law"].rho0 * 2), models=["continuous"], law=case["law"])
    assert beyond.N == 0.0
    at_zero = beyond.models["continuous"].stable
    return np.array([at_zero if N == 0 else MODEL.is_stable(N * robot.V, loop) for N in gains])


def _first_change(grid, stable, p0):
    """(lo, hi) of the grid cell holding the change of verdict nearest p0 in log p, or None."""
    changes = np.flatnonzero(stable[1:] != stable[:-1])
    if changes.size == 0:
        return None
    i = min(changes, key=lambda c: min(abs(math.log(grid[c] / p0)), abs(math.log(grid[c + 1] / p0))))
    return float(grid[i]), float(grid[i + 1])


def _check(name, value, side, p0, lo, hi, gain_at, case):
    """The reported (value, side) against the dense scan of `gain_at` over [lo, hi] (module docstring)."""
    grid = np.unique(np.concatenate([np.geomspace(p0, lo, POINTS), np.geomspace(p0, hi, POINTS)]))
    stable = _verdicts(case, [gain_at(p) for p in grid])
    cell = _first_change(grid, stable, p0)
    if cell is None:  # one verdict over the whole scan: no critical value inside it
        assert not lo < value < hi or math.isnan(value), (name, value)
        return
    below, above = _verdicts(case, [gain_at(value * (1 - GAP)), gain_at(value * (1 + GAP))])
    in_cell = cell[0] * (1 - 1e-8) <= value <= cell[1] * (1 + 1e-8)
    nearer = abs(math.log(value / p0)) < min(abs(math.log(c / p0)) for c in cell)  # a band the grid stepped over
    assert in_cell or (nearer and below != above), (name, value, "first change of verdict in", cell)
    assert below != above, (name, value, "the verdict does not change there")
    assert side == ("below" if below else "above"), (name, value, side)


def _report(case, models=("continuous",)):
    robot, controller = _setup(case)
    return analyze_corridor(robot, controller, Corridor(case["L"]), models=list(models), law=case["law"]).models["continuous"]


def test_the_reported_case_changes_at_the_support_end():
    """The reported corridor (L = 0.9377 m > ρ0): the middle has no force (N = 0) and the verdict changes where the
    repulsion's support starts, L = ρ0 (N jumps to ~980 1/m, NV ≈ 103 > NV* = 8.43 1/s): L* = ρ0 to 1e-9 (the break
    is stepped onto 1e-9 either side, then narrowed by Newton), stable above; ρ0* = L (ρ0 reaching the corridor's
    wall), stable below. The text names the sides."""
    case = BRIEF
    v = _report(case)
    assert v.critical["L_critical"] == pytest.approx(case["law"].rho0, rel=1e-9)
    assert v.critical.stable_side("L_critical") == "above"
    assert v.critical["rho0_critical"] == pytest.approx(case["L"], rel=1e-9)
    assert v.critical.stable_side("rho0_critical") == "below"
    argv = ["--model", "continuous", "--law", "gnron", "--xi", repr(case["law"].xi), "--eta", repr(case["law"].eta), "--rho0", repr(case["law"].rho0),
            "--attraction-exponent", "3", "--goal-distance", repr(case["law"].rho_g), "--goal-exponent", repr(case["law"].n),
            "--V", repr(case["V"]), "--tau", repr(case["tau"]), "--W", "0.2", "--L", "0.9377"]
    d = report_json(argv)["corridor"]["continuous"]
    assert d["stable_side"]["L_critical"] == "above" and d["stable_side"]["rho0_critical"] == "below"
    code, text, _ = run(["report", *argv])
    row = next(line for line in text.splitlines() if line.lstrip().startswith("continuous ") and "stable" in line)
    assert code == 0 and " 0.8148 " in row and "<= 0.9377" in row  # L*: the footnote's side (above); rho0*: its own


@pytest.mark.parametrize("seed", range(6))
def test_L_critical_is_the_first_change_of_verdict(seed):
    """L* of random goal-aware corridors (an unstable band just inside ρ0) against the dense scan in L
    over [W/2, 50 L] (module docstring), the reported case included in seed 0's place by `BRIEF`."""
    case = BRIEF if seed == 0 else _case(seed)
    v = _report(case)
    L0 = case["L"]
    _check("L", v.critical["L_critical"], v.critical.stable_side("L_critical"), L0, case["W"] / 2 * (1 + 1e-9), min(50 * L0, RANGES["L"].high),
           lambda L: corridor_gain(case["law"], L), case)


@pytest.mark.parametrize("seed", range(6, 10))
@pytest.mark.parametrize("name", ["rho0", "eta"])
def test_rho0_and_eta_critical_are_the_first_change_of_verdict(seed, name):
    """ρ0* and η* of random goal-aware corridors against the dense scan of the parameter over two decades either
    side (module docstring); ξ* = ξη/η* with the opposite side (only η/ξ enters)."""
    case = _case(seed)
    v = _report(case)
    law, p0 = case["law"], getattr(case["law"], name)
    r = RANGES[name]
    _check(name, v.critical[f"{name}_critical"], v.critical.stable_side(f"{name}_critical"), p0, max(r.low, p0 / 100), min(r.high, p0 * 100),
           lambda p: corridor_gain(dataclasses.replace(law, **{name: p}), case["L"]), case)
    if name == "eta" and math.isfinite(v.critical["eta_critical"]):
        assert v.critical["xi_critical"] == pytest.approx(law.xi * law.eta / v.critical["eta_critical"], rel=1e-12)
        assert {v.critical.stable_side("eta_critical"), v.critical.stable_side("xi_critical")} == {"below", "above"}


def test_L_critical_below_half_the_robot_width_is_no_critical_value():
    """KB's power law, a slow robot: eq (25) generalized, L* = (2nWⁿVf/NV*)^(1/(n+1)) computed here, lies below W/2,
    so every corridor the robot fits in is stable: L* = 0 (docs/models.md, "Critical values"), stable above; the model's
    own verdict at L just above W/2 and at 10 m agrees."""
    robot = CARMEL.robot.replace(V=0.05)
    controller = CARMEL.controller
    law = PowerLaw(controller.f, controller.n, robot.W)
    a = analyze_corridor(robot, controller, Corridor(0.5), models=["continuous"], law=law)
    v = a.models["continuous"]
    closed = (2 * controller.n * robot.W**controller.n * robot.V * controller.f / v.NV_critical) ** (1 / (controller.n + 1))
    assert closed < robot.W / 2
    assert v.critical["L_critical"] == 0.0 and v.critical.stable_side("L_critical") == "above"
    loop = loop_of(robot, controller)
    for L in (robot.W / 2 * (1 + 1e-6), 10.0):
        assert MODEL.is_stable(corridor_gain(law, L) * robot.V, loop)
