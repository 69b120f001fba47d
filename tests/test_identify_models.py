"""Which plant `identify` fits (`pfm_stability.analysis.plant_fit`, docs/diagnose.md "Which plant"): a second lag and a
slew limit on the commanded yaw rate, with intervals, chosen by BIC on the same samples, and written by ``--out``.

The truths are `log_helpers`' plants, integrated independently of the package (an event loop with exact steps): two lags
in cascade (`Plant.tau2`), and Nav2's velocity smoother (`log_helpers.smooth`: a 20-Hz timer moving its held output
towards the newest command by at most A/20, as nav2_velocity_smoother's OPEN_LOOP mode does) before the first-order
plant. Tolerances are the brief's: g within 5 %, τ within 10 %, D within 20 ms, τ_a within 10 % and its interval holding
the truth, the slew limit's interval holding the truth. The exact responses are checked against a third route (a
1e-4-s Euler slew limiter and scipy's ``lsim`` with a first-order hold, exact for piecewise-linear inputs) to A·1e-4
rad/s, the Euler limiter's own error.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml
from jsonschema import Draft202012Validator

from log_helpers import Plant, Recording, simulate, smooth, write_log
from pfm_stability.analysis.identification import identify
from pfm_stability.analysis.plant_response import lag_response, plant_response, slew_limited
from pfm_stability.io.config import load_config
from pfm_stability.io.logs import read_log
from pfm_stability.io.schema import load_schema

from cli_helpers import run

VALIDATOR = Draft202012Validator(load_schema())


def identified(tmp_path, plant, recording, kind="csv"):
    path = write_log(simulate(plant, recording), tmp_path, kind)
    return identify(read_log(path, need=("command", "odometry")), "odometry"), path


# ------------------------------------------------------------------------------ the responses
@pytest.mark.parametrize("lags", [(0.2, 0.0), (0.2, 0.05), (0.08, 0.07)])
def test_the_slew_limited_response_is_an_independent_integration(lags):
    """`plant_response` behind a slew limit of 2 rad/s² against an Euler slew limiter on a 1e-4-s grid followed by
    scipy.signal.lsim (first-order hold: exact for the Euler limiter's piecewise-linear output)."""
    from scipy import signal

    tau, tau_a = lags
    rng = np.random.default_rng(1)
    cmd_t = np.cumsum(rng.uniform(0.04, 0.06, 120))
    u = np.repeat(rng.uniform(-1, 1, 12), 10)
    dt = 1e-4
    grid = np.arange(0.0, cmd_t[-1] + 1.0, dt)
    held = u[np.clip(np.searchsorted(cmd_t, grid, side="right") - 1, 0, None)]
    r = np.empty_like(grid)
    r[0] = u[0]
    for k in range(1, grid.size):
        r[k] = r[k - 1] + min(max(held[k - 1] - r[k - 1], -2.0 * dt), 2.0 * dt)
    den = np.polymul([tau, 1.0], [tau_a, 1.0]) if tau_a else [tau, 1.0]
    _, y, _ = signal.lsim(signal.lti([1.0], den), r - u[0], grid, interp=True)
    t = np.arange(cmd_t[0] + 0.5, cmd_t[-1], 0.02)
    mine = plant_response(cmd_t, u, t, tau, 0.03, tau_a, 2.0)
    np.testing.assert_allclose(mine, np.interp(t - 0.03, grid, y + u[0]), atol=3 * 2.0 * dt)


def test_an_unreached_slew_limit_is_no_limit_and_its_knots_ramp():
    """A limit no command step reaches gives the held commands' response (to round-off); the knots ramp at ±A exactly and
    end on the command."""
    rng = np.random.default_rng(2)
    cmd_t = np.cumsum(rng.uniform(0.04, 0.06, 200))
    u = np.repeat(rng.uniform(-1, 1, 20), 10)
    t = np.arange(cmd_t[0], cmd_t[-1], 0.013)
    np.testing.assert_allclose(plant_response(cmd_t, u, t, 0.2, 0.05, 0.0, 1e9), lag_response(cmd_t, u, t, 0.2, 0.05), atol=1e-6)
    kt, kv = slew_limited(cmd_t, u, 1.5)
    slopes = np.diff(kv) / np.where(np.diff(kt) > 0, np.diff(kt), 1.0)
    assert np.all(np.abs(slopes) <= 1.5 + 1e-9) and np.all(np.diff(kt) >= 0)
    assert kv[-1] == pytest.approx(u[-1])


def test_the_smoother_of_the_helpers_is_nav2s_rule():
    """`log_helpers.smooth` moves by at most A/f per tick towards the newest command and holds it (the OPEN_LOOP rule of
    nav2_velocity_smoother's applyConstraints with equal max_accel and −max_decel)."""
    cmd_t = np.arange(0.0, 3.0, 0.1)
    u = np.where(cmd_t < 1.0, 0.0, 1.0)
    ticks, out = smooth(cmd_t, u, 2.0, 20.0, 0.01)
    assert np.all(np.abs(np.diff(out)) <= 0.1 + 1e-12)
    assert out[np.searchsorted(ticks, 1.0)] == pytest.approx(0.1) and out[-1] == pytest.approx(1.0)


# ------------------------------------------------------------------------------ which plant
@pytest.fixture(scope="module")
def fits(tmp_path_factory):
    """Three robots, 60 s of step turns each: two lags, Nav2's smoother before one lag, and both."""
    out = {}
    for name, plant in {"two_lags": Plant(g=0.85, tau=0.3, dead_time=0.06, tau2=0.05),
                        "slew_limited": Plant(g=0.9, tau=0.2, dead_time=0.08, slew=2.0),
                        "two_lags_slew_limited": Plant(g=0.8, tau=0.25, dead_time=0.05, tau2=0.04, slew=2.0)}.items():
        out[name] = (plant, *identified(tmp_path_factory.mktemp(name), plant, Recording(profile="steps", seed=4)))
    return out


@pytest.mark.parametrize("name", ["two_lags", "slew_limited", "two_lags_slew_limited"])
def test_the_plant_the_data_support_is_fitted_within_the_tolerances(fits, name):
    plant, r, _ = fits[name]
    p = r.plant
    assert r.identified and p.model == name, [(m.model, m.bic) for m in p.models]
    assert p.g.value == pytest.approx(plant.g, rel=0.05) and p.tau.value == pytest.approx(plant.tau, rel=0.10)
    assert abs(p.dead_time.value - plant.dead_time) < 0.02
    if plant.tau2:
        assert p.actuator_lag.value == pytest.approx(plant.tau2, rel=0.10)
        assert p.actuator_lag.low <= plant.tau2 <= p.actuator_lag.high
    else:
        assert p.actuator_lag is None
    if math.isfinite(plant.slew):
        assert p.yaw_accel_limit.low <= plant.slew <= p.yaw_accel_limit.high and p.yaw_accel_limit.low > 0
    else:
        assert p.yaw_accel_limit is None
    selected = [m for m in p.models if m.selected]
    assert len(selected) == 1 and selected[0].model == name and selected[0].bic == min(m.bic for m in p.models)
    first = next(m for m in p.models if m.model == "first_order")
    assert first.ljung_box_p < 1e-3 and first.samples == selected[0].samples  # same samples; first order leaves structure


def test_a_torque_limit_is_fitted_by_the_nearest_plant_and_its_residuals_say_so(tmp_path):
    """A limit on the delivered yaw acceleration (a motor's torque, `Plant.rate_limit`), not on the command: the nearest
    candidate is a slew limit, which explains the saturation (far better than one lag) but not its shape, and the
    residuals' Ljung–Box test says so (p < 0.01)."""
    r, _ = identified(tmp_path, Plant(rate_limit=2.0), Recording(profile="steps", seed=3))
    p = r.plant
    assert p.yaw_accel_limit is not None
    selected = next(m for m in p.models if m.selected)
    assert selected.ljung_box_p < 0.01
    first = next(m for m in p.models if m.model == "first_order")
    assert selected.ssr < 0.5 * first.ssr


# ------------------------------------------------------------------------------ the command
def test_json_text_and_out_carry_the_selected_plant(fits, tmp_path):
    """The JSON (valid) names the model and every candidate; the text shows τ_a and A with their intervals and the
    candidates' ΔBIC; ``--out`` writes actuator_lag and yaw_accel_limit, which the configuration reads into the Robot."""
    _, r, path = fits["two_lags_slew_limited"]
    code, out, err = run(["identify", str(path), "--format", "json"])
    assert code == 0, err
    data = json.loads(out)
    assert [f"{list(e.absolute_path)}: {e.message}" for e in VALIDATOR.iter_errors(data)] == []
    assert data["plant"]["model"] == "two_lags_slew_limited" and data["plant"]["actuator_lag"]["value"] > 0
    assert [m["model"] for m in data["fit"]["models"]] == ["first_order", "two_lags", "slew_limited", "two_lags_slew_limited"]
    assert sum(m["selected"] for m in data["fit"]["models"]) == 1
    code, text, _ = run(["identify", str(path), "--out", str(tmp_path / "robot.yaml")])
    assert code == 0 and "τ_a (second lag)" in text and "A (slew limit)" in text and "ΔBIC" in text
    written = yaml.safe_load((tmp_path / "robot.yaml").read_text())["robot"]
    assert written["actuator_lag"] == pytest.approx(r.plant.actuator_lag.value, rel=1e-5)
    assert written["yaw_accel_limit"] == pytest.approx(r.plant.yaw_accel_limit.value, rel=1e-5)
    (tmp_path / "full.yaml").write_text((tmp_path / "robot.yaml").read_text().replace("robot:\n", "robot:\n  k: 2.0\n  W: 0.5\n  V: 0.5\n"))
    robot = load_config(tmp_path / "full.yaml").robot
    assert robot.actuator_lag == pytest.approx(written["actuator_lag"]) and robot.yaw_accel_limit == pytest.approx(written["yaw_accel_limit"])
    code, md, _ = run(["identify", str(path), "--format", "markdown"])
    assert code == 0 and "| candidate | ΔBIC |" in md
