"""``pfm-stability validate``: JSON keys, text report, overlay PNG, sweep, exit status 2 on bad input."""

import json

import numpy as np
import pytest

from pfm_stability.cli import main

MODELS = {"continuous", "kb_first_order", "pade", "exact_delay", "sampled"}
PNG = b"\x89PNG\r\n\x1a\n"


def test_json_has_the_issue_keys_and_applies_the_overrides(capsys):
    """parameter, simulated_boundary (a number), predicted_boundary / relative_error keyed by model, inputs with sources."""
    argv = ["validate", "--scenario", "corridor", "--env", "analytic", "--format", "json", "--quiet", "--rtol", "0.01",
            "--hold", "reference", "--compute-delay", "0", "--k", "3", "--V", "0.6"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["parameter"] == "L" and isinstance(out["simulated_boundary"], float)
    assert set(out["predicted_boundary"]) == set(out["relative_error"]) == MODELS
    assert abs(out["relative_error"]["sampled"]) < 1e-3
    i = out["inputs"]
    assert (i["hold"], i["compute_delay"], i["k"], i["V"]) == ("reference", 0, 3.0, 0.6)
    assert i["sources"]["k"] == "user" and i["sources"]["tau"] == "preset carmel"
    assert out["sweep"] is None and out["plot"] is None and len(out["oscillation"]) == 3


def test_text_plot_and_sweep(tmp_path, capsys):
    """Text report with the model table, the overlay PNG, and a sweep that lists agreement and wrong-verdict rates."""
    png, sweep_png = tmp_path / "wall.png", tmp_path / "sweep.png"
    argv = ["validate", "--scenario", "wall", "--env", "analytic", "--rtol", "0.01", "--plot", str(png), "--no-map",
            "--sweep", "16", "--sweep-plot", str(sweep_png)]
    assert main(argv) == 0
    captured = capsys.readouterr()
    text = captured.out
    assert "simulated boundary: alpha* =" in text and "exact_delay" in text and "rel. error" in text
    assert "random sweep: 16 Latin-hypercube sets" in text and "kb_first_order" in text
    assert "oscillation near the boundary" in text
    assert png.read_bytes()[:8] == PNG and sweep_png.read_bytes()[:8] == PNG
    assert "validate: round 1" in captured.err  # progress on stderr


@pytest.mark.slow  # seconds: scheduled first (tests/conftest.py)
def test_grid_overlay_with_stability_map(tmp_path, capsys):
    """--plot in the grid draws the 7 x 9 map over every model's boundary curve; the text shows KB's lumped law beside."""
    png = tmp_path / "v.png"
    assert main(["validate", "--scenario", "corridor", "--parameter", "V", "--L", "0.8", "--rtol", "0.01",
                 "--plot", str(png), "--quiet", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["env"] == "grid" and out["inputs"]["L"] == 0.8
    assert len(out["stability_map"]["points"]) == 63 and set(out["stability_map"]["curves"]) == MODELS
    assert set(out["lumped_predicted_boundary"]) == MODELS
    assert abs(out["relative_error"]["sampled"]) < 0.05
    assert png.read_bytes()[:8] == PNG


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--scenario", "corridor", "--parameter", "alpha"], "parameter must be one of L, V, f for scenario corridor"),
        (["--scenario", "corridor", "--L", "1.0"], "L is the bisected parameter"),
        (["--scenario", "wall", "--L", "1.0"], "L does not apply to scenario wall"),
        (["--scenario", "corridor", "--sweep-plot", "x.png"], "sweep-plot needs --sweep N"),
        (["--scenario", "corridor", "--no-map"], "no-map applies to --plot only"),
        (["--scenario", "hall"], "invalid choice"),
        (["--scenario", "corridor", "--V", "0.5", "--tau", "0.6", "--k", "1", "--f", "0.5", "--T", "0.03", "--compute-delay", "0"],
         "lies outside the values this scenario can be simulated with"),
        (["--scenario", "corridor", "--env", "analytic", "--rtol", "0.05", "--plot", "/nonexistent/dir/x.png", "--no-map"],
         "plot must be a writable file path ending in .png; got '/nonexistent/dir/x.png' (directory /nonexistent/dir does not exist)"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, message, capsys):
    """Exit 2, one line (every option's own range: tests/test_cli_fuzz.py::test_every_range_end_is_accepted_or_rejected_as_stated)."""
    assert main(["validate", "--quiet", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


# ------------------------------------------------ a configuration file's law
def _grid_wall_force(d, ratio, n=2.0, W=0.8, c=0.1, h=16, cv=15, samples=4000):
    """KB eq (1) summed over the 2h + 1 wall cells of the active window, averaged over the robot's position along the
    wall within its cell, by brute force (midpoint rule over `samples` positions): F_r(d)/F_ct of a straight grid wall."""
    y = (np.arange(samples) + 0.5) / samples * c - c / 2
    cells = np.arange(-h, h + 1) * c
    r2 = d * d + (y[:, None] - cells[None, :]) ** 2
    return float(np.mean(np.sum(ratio * cv * W**n * d / r2 ** ((n + 1) / 2), axis=1)))


def _grid_corridor_gain(L, ratio, step=1e-4):
    """N = −2P′(L) (KB §5.4) of the brute-force grid wall, by a central difference."""
    return -2.0 * (_grid_wall_force(L + step, ratio) - _grid_wall_force(L - step, ratio)) / (2 * step)


@pytest.mark.parametrize("env,tolerance", [("analytic", 1e-3), ("grid", 0.02)])
def test_validate_follows_the_config_files_grid_law(env, tolerance, tmp_path, capsys):
    """A --config file's ``law: grid`` (with its cell_ratio) is the law validate simulates and predicts with, as in
    report and simulate (docs/config.md, precedence; `sim.scenario_law`).

    Oracle: V* = NV*/N with N = −2P′(L) of the grid wall summed cell by cell in this test (KB eq 1 over the window's
    33 cells, averaged along the wall; the midpoint rule and the difference step are accurate to ~1e-8) and NV* of the
    `sampled` model (command hold, one-sample delay); and `report --config`'s V* for the same file, and the law
    `simulate --config --env analytic` reports. Before the fix, --env analytic used KB's power law (V* 0.224 against
    0.474) and --env grid the calibrated ratio 0.00311 instead of the file's 0.004. Tolerances: predictions 1e-6
    (two routes to one root); the simulated boundary 1e-3 with continuous walls (the bisection's bracket, rtol 1e-4)
    and 2 % in the grid (the force's ripple with the robot's position in its cell: docs/validation.md, 5 % bar).
    """
    from pfm_stability.models import Loop, Sampled
    from pfm_stability.parameters import CARMEL

    config = tmp_path / "robot.yaml"
    config.write_text("preset: carmel\nlaw: {name: grid, cell_ratio: 0.004}\nscenario: {corridor: {L: 0.6}}\n")
    robot, controller = CARMEL.robot, CARMEL.controller
    NV_star = Sampled(controller.hold, controller.compute_delay).boundary(Loop(robot.tau, controller.T, robot.k)).NV_critical
    expected = NV_star / _grid_corridor_gain(0.6, 0.004)

    assert main(["validate", "--scenario", "corridor", "--parameter", "V", "--env", env, "--config", str(config),
                 "--rtol", "1e-3" if env == "analytic" else "0.01", "--quiet", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["law"].startswith("grid wall") and out["inputs"]["cell_ratio"] == 0.004 and out["inputs"]["L"] == pytest.approx(0.6)
    assert out["predicted_boundary"]["sampled"] == pytest.approx(expected, rel=1e-6)
    assert out["simulated_boundary"] == pytest.approx(expected, rel=tolerance)

    assert main(["report", "--config", str(config), "--format", "json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["corridor"]["sampled"]["V_critical"] == pytest.approx(expected, rel=1e-6)
    assert main(["simulate", "--scenario", "corridor", "--env", env, "--config", str(config), "--duration", "2",
                 "--quiet", "--format", "json"]) == 0
    simulated = json.loads(capsys.readouterr().out)["inputs"]
    assert (simulated.get("law") or "grid wall").startswith("grid wall")
    if env == "grid":
        assert simulated["cell_ratio"] == 0.004


def test_validate_sweep_follows_the_config_files_grid_law():
    """verdict_sweep(law="grid") in the analytic environment: every member's NV is the grid wall's, N = −2P′(L) (corridor)
    of the brute-force window sum at the member's calibrated cell ratio (f_av = f, KB §4) — not KB's power law.

    Tolerance 1e-6: the oracle's midpoint rule and central difference are accurate to ~1e-8.
    """
    from pfm_stability.laws.effective_force import calibrate_cell_ratio
    from pfm_stability.validation import verdict_sweep

    sweep = verdict_sweep(8, seed=1, env="analytic", law="grid")
    corridors = [p for p in sweep.points if p.scenario == "corridor"]
    assert corridors
    for p in corridors:
        ratio = calibrate_cell_ratio(p.f, 2.0, 0.8, 0.1, 33)
        assert p.NV == pytest.approx(_grid_corridor_gain(p.geometry, ratio) * p.V, rel=1e-6)
    with pytest.raises(ValueError, match="law applies to env=analytic only"):
        verdict_sweep(8, env="grid", law="grid")


def test_bisecting_f_with_a_config_files_cell_ratio_exits_2(tmp_path, capsys):
    """With the cell ratio given, f only calibrates a ratio that is no longer used: bisecting f is refused in one line."""
    config = tmp_path / "robot.yaml"
    config.write_text("law: {name: grid, cell_ratio: 0.004}\n")
    assert main(["validate", "--scenario", "corridor", "--parameter", "f", "--config", str(config), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "f cannot be bisected with a given cell_ratio (0.004)" in err and err.count("\n") == 1 and "Traceback" not in err
