"""``pfm-stability simulate``: JSON keys, text, plot, exit status 2 on bad input."""

import json

import pytest

from pfm_stability.cli import main


def test_json_has_the_issue_keys(capsys):
    assert main(["simulate", "--scenario", "kb-fig6-narrow", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"events", "metrics", "inputs", "prediction"} <= set(out)
    assert out["events"][0]["type"] == "collision" and out["events"][0]["t"] > 0
    assert {"growth_rate", "angular_frequency", "oscillating", "stable"} <= set(out["metrics"])
    assert out["metrics"]["oscillating"] is True and out["metrics"]["stable"] is False
    assert out["inputs"]["sources"]["k"].startswith("ASSUMED")
    assert out["prediction"]["sampled"]["verdict"] == "unstable"


def test_overrides_and_analytic_corridor(capsys):
    assert main(["simulate", "--scenario", "corridor", "--env", "analytic", "--L", "1.2", "--V", "0.5",
                 "--hold", "reference", "--compute-delay", "0", "--format", "json", "--duration", "10"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["inputs"]["V"] == 0.5 and out["inputs"]["hold"] == "reference" and out["inputs"]["env"] == "analytic"
    assert out["metrics"]["stable"] is True and out["events"] == []


def test_text_report_and_plot(tmp_path, capsys):
    png = tmp_path / "fig6.png"
    assert main(["simulate", "--scenario", "kb-fig6-wide", "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    assert "prediction (corridor, L = 0.9 m)" in text and "stable: yes" in text
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--scenario", "corridor", "--L", "0.3"], "L must be"),
        (["--scenario", "kb-fig3", "--env", "analytic"], "env must be grid"),
        (["--scenario", "nowhere"], "invalid choice"),
        (["--scenario", "corridor", "--plot", "/nonexistent/dir/x.png"],
         "plot must be a writable file path ending in .png; got '/nonexistent/dir/x.png' (directory /nonexistent/dir does not exist)"),
        (["--scenario", "corridor", "--W", "2.0"], "L must be"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, message, capsys):
    """Exit 2, one line (every option's own range: tests/test_cli_fuzz.py::test_every_range_end_is_accepted_or_rejected_as_stated)."""
    assert main(["simulate", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err
