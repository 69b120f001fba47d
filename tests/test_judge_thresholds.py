"""The oscillation judge's thresholds table (`maps.judging.judge_thresholds`, docs/judge.md): its defaults are what the judge
uses, every field is documented, and a re-judging with another table equals a fresh judge with it.

Each threshold of the episodes' judge is checked on a closed-form lateral signal that is an episode under the
default table and is none once that one threshold moves past the signal (the other fields at their defaults): a
sinusoid held at 1.6 cm (just above `amplitude_threshold`), and one growing by 1.2 e-folds over its six turning points
from 7 mm (below the threshold throughout, above `noise_floor`). The scoring's thresholds are checked on a few drives
of the straight test corridor (tests/test_map_paths.py) simulated once and judged again.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from pfm_stability.maps.judging import episodes as episodes_module
from pfm_stability.maps.judging.episodes import episodes, lateral_episodes, swing
from pfm_stability.maps.judging.judge_thresholds import JUDGE, JudgeThresholds

P = 1.0
"""The synthetic signals' period, s."""
DT = 0.005
"""Their step, s (200 samples a period)."""


def held(amplitude: float = 0.016, periods: float = 4.0):
    """(t, lateral): a sinusoid of `amplitude` (m) at period `P` over `periods` periods: with the first and last half
    period not judged, its six turning points at 0.75 P .. 3.25 P are one episode of three periods."""
    t = np.arange(0.0, periods * P, DT)
    return t, amplitude * np.sin(2 * math.pi * t / P)


def growing(efolds: float = 1.2, first: float = 0.007):
    """(t, lateral): a sinusoid over four periods whose amplitude grows by `efolds` e-folds from its first turning
    point (at 0.75 P, `first` m) to its sixth (at 3.25 P): below 1.5 cm on every turning point but the last two."""
    t = np.arange(0.0, 4 * P, DT)
    rate = efolds / (2.5 * P)
    return t, first * np.exp(rate * (t - 0.75 * P)) * np.sin(2 * math.pi * t / P)


def found(signal, **changes) -> tuple:
    """The episodes of `signal` judged with `JUDGE` changed by `changes`."""
    t, lateral = signal
    return lateral_episodes(t, lateral, P, JUDGE.replace(**changes))[0]


def test_the_aliases_are_the_tables_fields():
    """The constants other code imports are the table's fields (one source of truth)."""
    from pfm_stability.maps.deciding.decide import AMPLITUDE_THRESHOLD as decided
    from pfm_stability.validation import map_drives

    assert episodes_module.EPISODE_PERIODS == JUDGE.episode_periods == 3
    assert episodes_module.GROWTH_EFOLDS == JUDGE.growth_efolds == 1.0
    assert episodes_module.AMPLITUDE_THRESHOLD == decided == JUDGE.amplitude_threshold == 0.015
    assert episodes_module.NOISE_FLOOR == JUDGE.noise_floor == 0.005
    assert map_drives.MATCH_DISTANCE == JUDGE.match_distance == 0.5
    assert map_drives.WOBBLE_FACTOR == JUDGE.wobble_factor == 2.0
    assert JUDGE.end_exclusion == 3.0 and JUDGE.replace(end_periods=2).end_exclusion == 2.0


def test_every_field_is_documented_with_its_justification():
    """Every field is in the class docstring's Attributes, with its type, a unit (m, periods, e-folds, or
    dimensionless) and where its value comes from (a definition, a measurement, a chosen or physical scale); and it
    has a row of docs/judge.md's table."""
    from numpydoc.docscrape import NumpyDocString

    table = (Path(__file__).resolve().parents[1] / "docs" / "judge.md").read_text()

    documented = {p.name: (p.type, " ".join(p.desc)) for p in NumpyDocString(inspect.getdoc(JudgeThresholds))["Attributes"]}
    units = ("m,", "m.", "m)", ", m", "periods", "dimensionless", "e-folds", "Turning points")
    kinds = ("*Definition*", "*Measured*", "*A chosen scale*", "*Physical scale*")
    for f in dataclasses.fields(JudgeThresholds):
        assert f.name in documented and documented[f.name][0], f.name
        text = documented[f.name][1]
        assert any(unit in text for unit in units), f"{f.name}: no unit"
        assert any(kind in text for kind in kinds), f"{f.name}: no justification"
        assert f"\n| `{f.name}` |" in table, f"docs/judge.md's table has no row for {f.name}"


def test_the_table_refuses_nonsense():
    with pytest.raises(ValueError, match="episode_periods"):
        JudgeThresholds(episode_periods=0)
    with pytest.raises(ValueError, match="noise_floor"):
        JudgeThresholds(noise_floor=-1.0)
    with pytest.raises(ValueError, match="max_gap_periods"):
        JudgeThresholds(min_gap_periods=0.5, max_gap_periods=0.4)


def test_a_weave_held_above_the_amplitude_threshold_is_an_episode_and_below_it_none():
    assert len(found(held())) == 1  # 1.6 cm (1.56 cm smoothed) >= 1.5 cm
    assert found(held(), amplitude_threshold=0.017) == ()
    assert found(held(0.014)) == () and len(found(held(0.014), amplitude_threshold=0.013)) == 1


def test_growth_by_more_than_the_efolds_is_an_episode():
    assert len(found(growing(1.2))) == 1  # 1.2 e-folds >= 1.0, every turning point but the last two below 1.5 cm
    assert found(growing(1.2), growth_efolds=1.4) == ()
    assert found(growing(0.8)) == () and len(found(growing(0.8), growth_efolds=0.7)) == 1


def test_an_episode_lasts_the_episode_periods():
    assert len(found(held())) == 1  # six turning points: three periods
    assert found(held(), episode_periods=4) == ()
    assert len(found(held(periods=5.0), episode_periods=4)) == 1


def test_turning_points_under_the_noise_floor_are_none():
    assert len(found(growing(1.2))) == 1  # its first turning point 7 mm (6.8 mm smoothed) > 5 mm
    assert found(growing(1.2), noise_floor=0.0075) == ()  # five turning points left: no three periods


def test_turning_points_closer_than_the_least_gap_merge_and_farther_than_the_largest_break_the_weave():
    assert found(held(), min_gap_periods=0.55) == ()  # P/2 apart: merged, no alternation left
    assert found(held(), max_gap_periods=0.45) == ()  # P/2 apart: a bend, not an oscillation
    longer = np.arange(0.0, 5.5 * P, DT)
    # turning points 0.65 P apart; the one-period average keeps 29 % of it: 2.1 cm left about it
    slower = (longer, 0.03 * np.sin(2 * math.pi * longer / (1.3 * P)))
    assert len(found(slower)) == 1 and found(slower, max_gap_periods=0.6) == ()


def test_the_ends_are_not_judged():
    assert found(held(), edge_periods=0.8) == ()  # the first and last turning points fall inside the unjudged ends


def test_the_smoothing_and_the_average_length_set_the_measured_amplitude():
    assert found(held(), smoothing_periods=0.5) == ()  # a mean over P/2 passes 64 %: 1.0 cm
    assert found(held(), average_periods=0.5) == ()  # the half-period average keeps 64 % of the weave: 0.6 cm left
    assert len(found(held(), smoothing_periods=0.0625)) == 1 and len(found(held(), average_periods=1.0)) == 1


def test_an_episode_begins_its_lead_before_its_first_turning_point():
    (lo, hi), = found(held())
    (lo2, hi2), = found(held(), lead_periods=0.5)
    assert hi2 == hi and lo == pytest.approx(0.75 * P - 0.25 * P, abs=2 * DT) and lo2 == pytest.approx(lo - 0.25 * P, abs=1e-12)


def test_a_swing_holds_its_turning_points():
    t, lateral = held()
    x, y = lateral, t * 1.0  # driving along +y at 1 m/s, weaving in x
    assert swing(t, x, y, P).max() == pytest.approx(0.016 * 0.974, rel=0.02)
    assert swing(t, x, y, P, JUDGE.replace(swing_points=7)).max() == 0.0  # six turning points judged
    assert len(episodes(t, x, y, P)[0]) == 1 and episodes(t, x, y, P, JUDGE.replace(amplitude_threshold=0.017))[0] == ()


# --- the scoring's thresholds, and the experiment's re-judging, on a few corridor drives ---------------------------

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "experiments"))


@pytest.fixture(scope="module")
def corridor_runs(tmp_path_factory):
    """Three drives of the 1.2 m test corridor at 1.4 V* (they weave), simulated once."""
    from test_map_paths import _report, corridor_analysis, corridors_root

    from pfm_stability.validation.map_drives import simulate_drives

    V_star = _report(0.6).models["sampled"].critical["V_critical"]
    analysis = corridor_analysis(0.6, 1.4 * V_star, corridors_root(tmp_path_factory))
    return simulate_drives(analysis, 3, seed=1)


@pytest.mark.xdist_group("map_corridor_0.6")
def test_rejudging_equals_a_fresh_judge_with_the_same_thresholds(corridor_runs):
    """The experiment's re-judging of drives simulated once (experiments/judge_thresholds.py, `judged`) gives what
    `drive_map` gives with the same thresholds from scratch: the same drives (seeded), judged afresh."""
    from judge_thresholds import judged

    from pfm_stability.validation.map_drives import drive_map

    runs = corridor_runs
    for thresholds in (JUDGE, JUDGE.replace(amplitude_threshold=0.01, match_window=0.25, end_periods=2)):
        fresh = drive_map(runs.analysis, runs.count, seed=runs.seed, thresholds=thresholds)
        mine = judged(runs, thresholds)
        assert (mine.recall, mine.precision, mine.specificity) == (fresh.recall, fresh.precision, fresh.specificity)
        assert (mine.recall_interval, mine.precision_interval, mine.specificity_interval) == (
            fresh.recall_interval, fresh.precision_interval, fresh.specificity_interval)
        assert mine.episodes == fresh.counts["episodes"] and mine.lengths == fresh.lengths


@pytest.mark.xdist_group("map_corridor_0.6")
def test_the_scorings_thresholds_move_what_is_measured(corridor_runs):
    """On the same drives: a longer start exclusion measures less of each drive, a longer end exclusion leaves more
    unmeasured, a zero match window matches no less strictly than Λ/2 (never more), and a larger match distance
    (beyond the robot's width) is the one recorded."""
    from pfm_stability.validation.map_drives import judge_drives

    runs = corridor_runs
    base = judge_drives(runs)
    assert base.counts["episodes"] > 0
    later = judge_drives(runs, JUDGE.replace(start_periods=3.0, start_share=0.5))
    assert later.lengths["drive_paths_driven"] < base.lengths["drive_paths_driven"]
    shorter = judge_drives(runs, JUDGE.replace(end_periods=6.0))
    assert shorter.lengths["drive_paths_unmeasured"] > base.lengths["drive_paths_unmeasured"]
    exact = judge_drives(runs, JUDGE.replace(match_window=0.0))
    assert exact.lengths["predicted_unstable_matched"] <= base.lengths["predicted_unstable_matched"]
    assert exact.lengths["episode_recalled"] <= base.lengths["episode_recalled"]
    assert judge_drives(runs, JUDGE.replace(match_distance=2.0)).inputs["match_distance"] == 2.0
    assert base.inputs["match_distance"] == max(0.5, runs.analysis.robot.W)
    loose = judge_drives(runs, JUDGE.replace(wobble_factor=1e6))
    assert loose.wobble.factor == 1e6 and loose.wobble.within >= base.wobble.within
