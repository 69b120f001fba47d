"""Inputs are checked once, at the public entry: the searches inside a report probe already-checked loops unchecked.

A report's T* and k* searches build hundreds of loops (one per probe of T or k) and its α*
bisection evaluates the wall gain at hundreds of angles; each used to re-run every input check
(`pfm_stability.checks`). The probes now use private unchecked copies (`Loop._with_delay`,
`Loop._with_steering_gain`, `HolonomicLoop._with_delay`, `force_law._wall_gain`,
`Characteristic._state_space`, `LoopModel._growth_rates`). What must hold:

* an unchecked copy is the loop the checked constructor makes from the same values (same fields,
  the resolutions `T_RESOLUTION` and `TAU_RESOLUTION` applied the same way), for random and
  extreme values — compared field by field, exactly: both are the same float assignments;
* every public entry still refuses bad input with a ValueError;
* the carmel report makes fewer than 400 check calls (it made ≈4,800), counted by
  ``benchmarks/count_checks.py`` in a fresh process.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pfm_stability.laws.force_law import PowerLaw, _wall_gain, wall_gain
from pfm_stability.models import Loop, make_model
from pfm_stability.models.holonomic import HolonomicLoop
from pfm_stability.models.sampled import Sampled, continuous_plant
from pfm_stability.parameters import T_RESOLUTION, TAU_RESOLUTION

ROOT = Path(__file__).resolve().parents[1]


def _fields(loop):
    return {name: getattr(loop, name) for name in loop.__dataclass_fields__}


def _random_loops(seed=7, n=40):
    """Random steering loops over the whole ranges (log-uniform), some c ≠ 0."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        tau = float(10 ** rng.uniform(-12, 2)) if rng.random() < 0.9 else 0.0
        T = float(10 ** rng.uniform(-14, 2)) if rng.random() < 0.9 else 0.0
        k = float(10 ** rng.uniform(-6, 4))
        c = float(rng.uniform(-0.99, 100)) if rng.random() < 0.3 else 0.0
        yield Loop(tau, T, k, c=c)


EXTREME_T = [0.0, 5e-324, 1e-13, T_RESOLUTION * (1 - 1e-15), T_RESOLUTION, 1e-3, 0.065, 100.0]
EXTREME_K = [1e-6, 1.0, 2.0, 1e4]


@pytest.mark.parametrize("T", EXTREME_T)
def test_unchecked_delay_probe_is_the_checked_loop(T):
    """`Loop._with_delay(T)` has the fields of `Loop(τ, T, k, c=c)` (T below 1e-12 s stored as 0), for random loops."""
    for loop in _random_loops():
        assert _fields(loop._with_delay(T)) == _fields(Loop(loop.tau, T, loop.k, c=loop.c))
        assert loop._with_delay(T) == loop.with_delay(T)
        assert hash(loop._with_delay(T)) == hash(loop.with_delay(T))


@pytest.mark.parametrize("k", EXTREME_K)
def test_unchecked_gain_probe_is_the_checked_loop(k):
    """`Loop._with_steering_gain(k)` has the fields of `Loop(τ, T, k, c=c)`, τ with τk < 1e-9 stored as 0."""
    for loop in [*_random_loops(seed=11), Loop(TAU_RESOLUTION / 2.0, 0.1, 1.0), Loop(0.3, 0.065, 2.0)]:
        assert _fields(loop._with_steering_gain(k)) == _fields(Loop(loop.tau, loop.T, k, c=loop.c))
    # the resolution on both sides of τk = 1e-9 (τ = 1e-6 s kept at k = 1, dropped just below k = 1e-3)
    loop = Loop(1e-6, 0.1, 1.0)
    for k_edge in (1e-3 * (1 - 1e-9), 1e-3, 1e-3 * (1 + 1e-9)):
        assert _fields(loop._with_steering_gain(k_edge)) == _fields(Loop(1e-6, 0.1, k_edge))


@pytest.mark.parametrize("T", EXTREME_T)
def test_unchecked_holonomic_delay_probe_is_the_checked_loop(T):
    """`HolonomicLoop._with_delay(T)` has the fields of `HolonomicLoop(T, c_h)`."""
    for c_h in (-3.0, 1e-9, 0.7, 1e15):
        loop = HolonomicLoop(0.05, c_h)
        assert _fields(loop._with_delay(T)) == _fields(HolonomicLoop(T, c_h))


def test_unchecked_wall_gain_is_the_checked_one():
    """`_wall_gain` returns what `wall_gain` returns at angles across the range (same code after the checks)."""
    law = PowerLaw(2.0, 1.0, 0.6)
    for alpha in np.linspace(1e-3, math.pi / 2 - 1e-3, 25):
        assert _wall_gain(law, float(alpha)) == wall_gain(law, float(alpha))


@pytest.mark.parametrize("call", [
    lambda: Loop(0.3, 0.065, 2.0).with_delay(-1.0),
    lambda: Loop(0.3, 0.065, 2.0).with_delay(math.nan),
    lambda: Loop(0.3, 0.065, 2.0).state_space("held"),
    lambda: continuous_plant(Loop(0.3, 0.065, 2.0), "held"),
    lambda: HolonomicLoop(0.05, 1.0).with_delay(1e3),
    lambda: HolonomicLoop(0.05, 1.0).state_space("reference"),
    lambda: Sampled("command", 1).growth_rates(math.inf, [Loop(0.3, 0.065, 2.0)]),
    lambda: make_model("pade").growth_rates("2", [Loop(0.3, 0.065, 2.0)]),
    lambda: make_model("sampled").critical_delay(math.nan, Loop(0.3, 0.065, 2.0)),
    lambda: make_model("continuous").critical_gain_k(2.0, HolonomicLoop(0.05, 1.0)),
    lambda: wall_gain(PowerLaw(2.0, 1.0, 0.6), 2.0),
    lambda: wall_gain("power", 0.3),
], ids=["with_delay<0", "with_delay nan", "state_space", "continuous_plant", "holonomic T", "holonomic hold",
        "growth_rates inf", "growth_rates str", "critical_delay nan", "k* holonomic", "wall alpha", "wall law"])
def test_public_entries_still_check(call):
    """Each public entry the probes bypass still refuses bad input with a one-line ValueError."""
    with pytest.raises(ValueError) as info:
        call()
    assert "\n" not in str(info.value)


@pytest.mark.slow
def test_carmel_report_checks_its_inputs_a_few_hundred_times():
    """The carmel report's check calls (every public function of `checks`, counted in a fresh process so that no
    cache is warm) stay below 400 (≈4,800 before the probes went unchecked; 324 after)."""
    out = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "count_checks.py"), "--top", "0"],
                         capture_output=True, text=True, check=True, cwd=ROOT).stdout
    first = out.splitlines()[0]
    assert "exit 0" in first, out
    calls = int(first.split(", ")[-1].split()[0])
    assert 50 < calls < 400, out
