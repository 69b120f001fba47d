"""``pfm-stability validate``: JSON keys, text report, overlay PNG, sweep, exit status 2 on bad input."""

import json

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
        (["--scenario", "corridor", "--T", "0"], "T must be a finite number in (0, 100] s"),
        (["--scenario", "corridor", "--sweep", "3"], "sweep must be an integer in [8, 100000]"),
        (["--scenario", "corridor", "--sweep-plot", "x.png"], "sweep-plot needs --sweep N"),
        (["--scenario", "corridor", "--no-map"], "no-map applies to --plot only"),
        (["--scenario", "corridor", "--alpha", "95"], "alpha must be a finite number in [1e-06, 89.999999] deg; got 95.0"),
        (["--scenario", "corridor", "--members", "2"], "members must be an integer in [3, 1000]"),
        (["--scenario", "corridor", "--V", "-1"], "V must be"),
        (["--scenario", "hall"], "invalid choice"),
        (["--scenario", "corridor", "--V", "0.5", "--tau", "0.6", "--k", "1", "--f", "0.5", "--T", "0.03", "--compute-delay", "0"],
         "lies outside the values this scenario can be simulated with"),
        (["--scenario", "corridor", "--env", "analytic", "--rtol", "0.05", "--plot", "/nonexistent/dir/x.png", "--no-map"],
         "plot must be a writable file path ending in .png; got '/nonexistent/dir/x.png' (directory /nonexistent/dir does not exist)"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, message, capsys):
    assert main(["validate", "--quiet", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err
