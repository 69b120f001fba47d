"""experiments/ (docs/validation.md) still run: every script in quick mode, the README results table.

The full runs (``python experiments/run_all.py``) regenerate the committed
PNG/JSON under experiments/results; here each script runs reduced into a
temporary folder and the KB findings it reports are checked: Fig 3's f_av
with KB's procedure (2.15, not 0.8) and the collision with f_av = 0.8; Fig 5's
collision below α* and settling above; Fig 6's wide run settling and narrow
run colliding, with the grid boundaries of the sampled model.
"""

import importlib
import json
import math
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.xdist_group("experiments")  # one worker runs the experiments once (tests/conftest.py)

EXPERIMENTS = Path(__file__).resolve().parents[1] / "experiments"
CHECKED_HERE = ("fig3_calibration", "fig5_wall", "fig6_corridor", "validation_summary", "gc2000_traps", "gc2000_corridor", "kb_fig4_door")
"""The scripts this file runs and checks; Ge & Cui 2002's and the DFAPF paper's run in tests/test_experiments_gc2002.py."""


@pytest.fixture(scope="module")
def run_all():
    sys.path.insert(0, str(EXPERIMENTS))
    try:
        yield importlib.import_module("run_all")
    finally:
        sys.path.remove(str(EXPERIMENTS))


@pytest.fixture(scope="module")
def quick_results(run_all, tmp_path_factory):
    out = tmp_path_factory.mktemp("experiments")
    rows = run_all.run_all(out, quick=True, only=CHECKED_HERE)
    return out, rows


def _json(out, name):
    return json.loads((out / name).read_text())


def test_every_experiment_writes_png_and_json(quick_results):
    out, rows = quick_results
    for name in ("fig3", "fig5", "fig5_boundary", "fig6", "fig6_boundary", "validation_errors", "sweep"):
        assert (out / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    for name in ("fig3", "fig5", "fig6", "validation_summary"):
        data = _json(out, f"{name}.json")
        assert data["rows"] and data["inputs"]["quick"] is True
    assert {r["experiment"] for r in rows} >= {"Fig 3", "Fig 5", "Fig 6", "Fig 6a", "Fig 6b", "Validation"}


def test_fig3_reports_kbs_calibration_finding(quick_results):
    """KB Fig 3: the smallest ratio avoiding the obstacle gives f_av ≈ 2.15, not KB's 0.8; with f_av = 0.8 it collides."""
    d = _json(quick_results[0], "fig3.json")
    assert d["kb_procedure"]["f_av"] == pytest.approx(2.15, rel=0.03)  # quick bisection: 12 x 2 instead of 24 x 3
    assert d["kb_procedure"]["collided"] is False
    assert d["f_av_0.8"]["f_av"] == pytest.approx(0.8) and d["f_av_0.8"]["collided"] is True


def test_fig5_unstable_below_and_stable_above_alpha_star(quick_results):
    """KB Fig 5: α = 20° < α* collides; the same wall at 40° settles; α* simulated = sampled (grid law) within 5 %."""
    d = _json(quick_results[0], "fig5.json")
    assert d["runs"]["kb"]["collided"] and d["runs"]["kb"]["predicted"]["sampled"]["verdict"] == "unstable"
    above = d["runs"]["above"]
    assert not above["collided"] and above["measured"]["stable"] and above["predicted"]["sampled"]["verdict"] == "stable"
    a = d["alpha_critical_deg"]
    assert 20.0 < a["simulated"] < 40.0
    assert abs(a["relative_error_grid_law"]["sampled"]) < 0.05


def test_fig6_wide_settles_narrow_collides(quick_results):
    """KB Fig 6: L = 0.9 m settles, L = 0.6 m oscillates into a collision; L* ≈ 0.69 m (sampled, grid law)."""
    d = _json(quick_results[0], "fig6.json")
    assert d["runs"]["wide"]["measured"]["stable"] and not d["runs"]["wide"]["collided"]
    assert d["runs"]["narrow"]["collided"] and d["runs"]["narrow"]["measured"]["growth_rate"] > 0
    L = d["L_critical_m"]
    assert 0.6 < L["simulated"] < 0.9 and abs(L["relative_error_grid_law"]["sampled"]) < 0.05


def test_every_script_is_run_by_one_test_file(run_all):
    """Every script of `run_all.EXPERIMENTS` runs in the suite: here, or in tests/test_experiments_gc2002.py."""
    from test_experiments_gc2002 import SCRIPTS

    assert set(run_all.EXPERIMENTS) == set(CHECKED_HERE) | set(SCRIPTS)


def test_results_table_and_readme(run_all, tmp_path, quick_results):
    """The runner renders the rows as a Markdown table between the README's markers; the committed README has one."""
    table = run_all.results_table(quick_results[1])
    assert table.startswith("| Experiment | Quantity |") and table.count("\n") == len(quick_results[1]) + 1
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n{run_all.BEGIN}\nold\n{run_all.END}\noutro\n")
    run_all.rewrite_readme(table, readme)
    text = readme.read_text()
    assert "old" not in text and table in text and text.startswith("intro") and text.endswith("outro\n")
    committed = (EXPERIMENTS / "README.md").read_text()
    inside = committed.split(run_all.BEGIN)[1].split(run_all.END)[0]
    assert "| Fig 3 |" in inside and "| Validation |" in inside
    for name in ("fig3.png", "fig5.png", "fig6.png", "fig3.json", "validation_summary.json"):
        assert (EXPERIMENTS / "results" / name).is_file(), name


def test_general_field_experiments_write_png_and_json(quick_results):
    """Ge & Cui 2000's traps (Figs 2–4, 6, Sec VI.B), the goal-aware corridor (crossover ρ_g* = √(1 + 2ηc(L)²/ξ)
    = 1.1456 m for ξ = 1, η = 0.1, ρ0 = 0.8, L = 0.4) and KB's Fig 4 door are part of `run_all`: each writes
    its PNG and JSON, and the door's numeric w* equals its closed form (to 1e-9: both are exact to round-off)."""
    out, rows = quick_results
    for name in ("gc2000_fig4", "gc2000_corridor", "kb_fig4_door"):
        assert (out / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    corridor = _json(out, "gc2000_corridor.json")
    assert abs(corridor["crossover"]["rho_g"] / math.sqrt(1 + 2 * 0.1 * (1 / 0.4 - 1 / 0.8) ** 2 / 1.0) - 1) < 1e-9
    door = _json(out, "kb_fig4_door.json")
    assert abs(door["relative_error_numeric_vs_closed_form"]) < 1e-9
    traps = _json(out, "gc2000_traps.json")
    assert traps["rows"]
