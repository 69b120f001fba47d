"""The laws' choice-valued parameters in ``report`` and in configuration files (docs/velocity_and_fuzzy.md, docs/config.md).

``--variant {gradient,squared,paper-eq23}`` (velocity-gated) and ``--symmetrize {none,negative,positive}``
(fuzzy), beside the fuzzy law's ``--side``, go through one mechanism (`parameters.FAMILY_LAW_CHOICES`,
`family_report.FamilyLaw.choices`). Checked: the variant's rest band against a root of the at-rest force
solved here by brentq, and its corridor friction against the closed form; the variant reaches the
simulated cycle; the mirrored fuzzy tables make the left and right walls' equilibria equal (and equal to
the printed tables' side they copy); the defaults equal the explicit default values; bad values and
choices of another law exit 2 naming the option; ``law.variant``/``law.symmetrize`` in a file, their
precedence and provenance. Every JSON output is checked against the shipped schema (`report_json`).
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
import yaml
import cli_helpers
from cli_helpers import file_error, run
from scipy.optimize import brentq

from pfm_stability.report.families import make_family_law
from pfm_stability.laws.fuzzy import load_dfapf
from pfm_stability.laws.fuzzy_law import FuzzyScheduledLaw
from pfm_stability.laws.velocity_laws import VelocityGatedRepulsion

FUZZY_WALL = ["--law", "fuzzy", "--alpha-p", "50", "--rho0", "0.5", "--alpha", "60"]  # F_a = 100 N, as tests/test_report_velocity_fuzzy.py
MAGNITUDE = {  # the at-rest force of each variant at clearance d < ρ0 (Ge & Cui 2002 eq 12/19 gradient; eq 23 as printed), written here
    "squared": lambda eta, rho0, d: eta * (1.0 / d - 1.0 / rho0) ** 2,
    "paper-eq23": lambda eta, rho0, d: eta**2 * eta * (1.0 / d - 1.0 / rho0) ** 2,
}


def report_json(argv) -> dict:
    """`cli_helpers.report_json` (exit 0, schema-valid) of arguments given as numbers, paths or text."""
    return cli_helpers.report_json([str(a) for a in argv])


def _gated_cases():
    """CARMEL-like defaults, extremes, and random values far from them (seeded)."""
    rng = random.Random(19)
    cases = [(0.1, 0.8, 0.5, 60.0), (5.0, 0.8, 0.5, 60.0), (1e-3, 0.05, 0.01, 1.0), (200.0, 30.0, 400.0, 89.0)]
    cases += [(10 ** rng.uniform(-3, 2), 10 ** rng.uniform(-1.5, 1.5), 10 ** rng.uniform(-2, 2), rng.uniform(1, 89)) for _ in range(4)]
    return cases


@pytest.mark.parametrize("variant", ["squared", "paper-eq23"])
@pytest.mark.parametrize("eta,rho0,alpha_p,alpha", _gated_cases())
def test_variant_rest_band_is_the_root_of_its_at_rest_force(variant, eta, rho0, alpha_p, alpha):
    """``--variant`` moves the wall's rest band to where the variant's at-rest force equals the pull F_a cos α
    (F_a = 2α_p with m = 2, ρ_g = 1): exactly `VelocityGatedRepulsion(variant=...).non_smooth_wall` (same code, ==), and
    within rel 1e-9 of the edge solved here by brentq on the magnitude written out (both solvers reach ~1e-14; 1e-9
    leaves room for the conditioning near ρ0 where the force is flat). The corridor's friction levels are the magnitude
    at L ± x (rel 1e-12: one formula, rounding only)."""
    L = 0.6 * rho0
    d = report_json(["--law", "velocity-gated", "--variant", variant, "--eta", eta, "--rho0", rho0, "--alpha-p", alpha_p,
                     "--alpha", alpha, "--L", L, "--no-simulate"])
    wall = d["environment"]["wall"]
    pull = 2.0 * alpha_p * math.cos(math.radians(alpha))
    library = VelocityGatedRepulsion(eta, rho0, 1.0, variant=variant.replace("-", "_")).non_smooth_wall(2.0 * alpha_p, math.radians(alpha))
    assert wall["d_s"] == library.d_s and wall["rest_band"] == [0.0, library.d_s]
    force = MAGNITUDE[variant]  # vanishes at ρ0 and grows without bound as d → 0: one crossing of the pull inside (0, ρ0)
    edge = brentq(lambda x: force(eta, rho0, x) - pull, rho0 * 1e-12, rho0 * (1 - 1e-12), xtol=1e-300, rtol=4 * np.finfo(float).eps)
    assert wall["d_s"] == pytest.approx(edge, rel=1e-9)
    assert wall["d_s"] != pytest.approx(min(math.sqrt(eta / pull), rho0), rel=1e-6)  # not the gradient variant's edge
    corridor = d["environment"]["corridor"]
    x = np.array(corridor["offsets"])
    left = np.where(L + x < rho0, force(eta, rho0, L + x), 0.0)
    assert np.allclose(corridor["friction_left"], left, rtol=1e-12, atol=0)
    assert d["inputs"]["variant"] == {"value": variant, "unit": "", "source": "user"}
    assert variant in d["law"]["description"]


def test_variant_reaches_the_simulated_cycle():
    """The wall's simulated cycle uses the variant: with ``--variant squared`` (α 60°, defaults) its mean and closest
    distance lie in the squared variant's rest band (0, d_s], while the gradient variant's cycle lies beyond that d_s
    (it rests on its own, wider band): the two bands differ by 36 %, far beyond the cycle's measured spread."""
    squared = report_json(["--law", "velocity-gated", "--alpha", "60", "--variant", "squared"])["environment"]["wall"]
    gradient = report_json(["--law", "velocity-gated", "--alpha", "60"])["environment"]["wall"]
    d_s = squared["d_s"]
    assert 0 < squared["cycle"]["min_distance"] <= squared["cycle"]["mean_distance"] <= d_s
    assert gradient["cycle"]["mean_distance"] > d_s and gradient["d_s"] > 1.3 * d_s


def test_symmetrized_tables_make_both_walls_equal():
    """``--symmetrize negative|positive``: the mirrored tables are identical for the two walls, so the left and right
    walls' equilibria (d0, N, N_frozen, c) agree to 1e-9 relative (the bearings ±θ are mirrored exactly; only the
    centroid's rounding differs); they equal the printed tables' right (negative) or left (positive) wall, whose rows
    they copy (same tolerance). ``none`` (the default) keeps the two walls different (N 13.499 vs 13.256,
    tests/test_report_velocity_fuzzy.py)."""
    def first(*extra):
        e = report_json([*FUZZY_WALL, "--model", "exact_delay", *extra])["environment"]["wall"]["equilibria"][0]
        return np.array([e["d0"], e["N"], e["N_frozen"], e["c"]])

    printed = {side: first("--side", side) for side in ("left", "right")}
    assert abs(printed["left"][1] - printed["right"][1]) > 0.1
    for mirrored, copied in (("negative", "right"), ("positive", "left")):
        left, right = first("--symmetrize", mirrored), first("--symmetrize", mirrored, "--side", "right")
        assert np.allclose(left, right, rtol=1e-9, atol=0), mirrored
        assert np.allclose(left, printed[copied], rtol=1e-9, atol=0), mirrored
    none = first("--symmetrize", "none", "--side", "right")
    assert np.allclose(none, printed["right"], rtol=1e-15, atol=0)  # the default spelled out: the same computation


def test_symmetrized_law_matches_the_library_and_loads_the_tables_once():
    """`FamilyLaw.fuzzy()` is `FuzzyScheduledLaw` with `load_dfapf(symmetrize=...)` (equilibria equal exactly, same code),
    and the tables are read once per value (the same controllers object from two laws)."""
    law = make_family_law("fuzzy", {"symmetrize": "positive", "side": "right"}, alpha_p=3.0, rho0=1.5)
    mine = law.fuzzy().wall_equilibria(math.radians(40), "right")
    theirs = FuzzyScheduledLaw(1.5, 6.0, controllers=load_dfapf(symmetrize="positive")).wall_equilibria(math.radians(40), "right")
    assert [(e.x0, e.N, e.c) for e in mine] == [(e.x0, e.N, e.c) for e in theirs]
    assert law.fuzzy().controllers is make_family_law("fuzzy", symmetrize="positive").fuzzy().controllers
    assert law.fuzzy().controllers.symmetrize == "positive" and make_family_law("fuzzy").fuzzy().controllers.symmetrize is None
    assert make_family_law("velocity-gated", {"variant": "paper-eq23"}).gated().variant == "paper_eq23"
    assert make_family_law("velocity-gated").gated().variant == "gradient" and make_family_law("velocity").choices == {}


def _without_choice_sources(d: dict, keys) -> dict:
    for key in keys:
        d["inputs"][key].pop("source")
    return d


@pytest.mark.parametrize("argv,explicit", [
    (["--law", "velocity-gated", "--alpha", "45", "--L", "0.5"], ["--variant", "gradient"]),
    (["--law", "velocity-gated", "--robot", "holonomic", "--alpha", "45", "--no-simulate"], ["--variant", "gradient"]),
    ([*FUZZY_WALL, "--L", "0.4", "--model", "exact_delay"], ["--symmetrize", "none", "--side", "left"]),
])
def test_defaults_equal_the_explicit_default_values(argv, explicit):
    """No choice typed = the default choices typed: the same JSON but the choices' sources ("default (…)" vs "user"),
    and the same text but those input lines. Today's output of these commands is kept by the existing tests
    (tests/test_report_velocity_fuzzy.py, tests/test_report_families.py), which run unchanged."""
    keys = explicit[::2]
    default, typed = report_json(argv), report_json([*argv, *explicit])
    for key in keys:
        name = key[2:]
        assert default["inputs"][name]["source"].startswith("default (") and typed["inputs"][name]["source"] == "user"
    assert _without_choice_sources(default, [k[2:] for k in keys]) == _without_choice_sources(typed, [k[2:] for k in keys])
    text = [run(["report", *a])[1].splitlines() for a in (argv, [*argv, *explicit])]
    changed = [(a, b) for a, b in zip(*text) if a != b]
    assert len(text[0]) == len(text[1]) and len(changed) == len(keys)
    assert all(a.endswith("(default (gradient))") or a.endswith("(default (none))") or a.endswith("(default (left))") for a, _ in changed)


@pytest.mark.parametrize("argv,message", [
    (["--law", "velocity-gated", "--variant", "paper_eq23", "--alpha", "60"],
     "argument --variant: invalid choice: 'paper_eq23' (choose from 'gradient', 'squared', 'paper-eq23')"),
    (["--law", "fuzzy", "--symmetrize", "yes", "--alpha", "60"], "argument --symmetrize: invalid choice: 'yes'"),
    (["--law", "fuzzy", "--variant", "squared", "--alpha", "60"], "--variant applies to --law velocity-gated, not to --law fuzzy"),
    (["--law", "velocity", "--variant", "squared", "--alpha", "60"], "--variant applies to --law velocity-gated, not to --law velocity"),
    (["--variant", "squared", "--alpha", "60"], "--variant applies to --law velocity-gated, not to --law power"),
    (["--law", "velocity-gated", "--symmetrize", "negative", "--alpha", "60"], "--symmetrize applies to --law fuzzy, not to --law velocity-gated"),
    (["--law", "grid", "--symmetrize", "negative", "--alpha", "60"], "--symmetrize applies to --law fuzzy, not to --law grid"),
    (["--law", "velocity-gated", "--side", "right", "--alpha", "60"], "--side applies to --law fuzzy, not to --law velocity-gated"),
])
def test_bad_choices_exit_2_naming_the_option(argv, message):
    """Exit 2, nothing on stdout, one line naming the option and its values or the law it applies to."""
    code, out, err = run(["report", *argv])
    assert (code, out) == (2, ""), err
    assert err.startswith("pfm-stability: error: ") and message in err and len(err.strip().splitlines()) == 1, err


def test_library_refuses_bad_choices():
    """`make_family_law`: ValueError naming the choice and its values, or the laws it applies to (the registry's one
    wording, `laws.registry.refusal`, as a file's ``law.<key>`` is refused)."""
    cases = [
        (("velocity-gated", {"variant": "paper_eq23"}), {}, "variant must be one of gradient, squared, paper-eq23; got 'paper_eq23'"),
        (("fuzzy", {"variant": "squared"}), {}, "variant applies to velocity-gated, not to law fuzzy"),
        (("fuzzy",), {"symmetrize": True}, "symmetrize must be one of none, negative, positive; got True"),
        (("velocity", {"colour": "red"}), {}, "colour is not a parameter of any law (see the laws in docs/fields.md and docs/velocity_and_fuzzy.md), given to law velocity"),
        (("velocity",), {"xi": 1.0}, "xi applies to khatib or gnron, not to law velocity"),
        (("fuzzy",), {"eta": 1.0}, "eta applies to velocity or velocity-gated, not to law fuzzy"),
        (("fuzzy", {"side": "up"}), {}, "side must be one of left, right; got 'up'"),
    ]
    for args, kwargs, message in cases:
        with pytest.raises(ValueError, match=None) as info:
            make_family_law(*args, **kwargs)
        assert str(info.value) == message


def _write(tmp_path, data, name="robot.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_config_keys_precedence_and_provenance(tmp_path):
    """``law.variant`` and ``law.symmetrize`` in a file (with its law typed as ``--law``): the report's JSON equals
    the options typed (but the sources, which name the file); an option typed beats the file; the file's choices
    apply only where its law is the one in force."""
    gated = _write(tmp_path, {"law": {"name": "velocity-gated", "variant": "paper-eq23", "eta": 2.0}})
    base = ["--law", "velocity-gated", "--alpha", "50", "--no-simulate"]
    filed = report_json(["--config", gated, *base])
    typed = report_json([*base, "--variant", "paper-eq23", "--eta", "2"])
    assert filed["inputs"]["variant"] == {"value": "paper-eq23", "unit": "", "source": f"config {gated}"}
    assert filed["environment"] == typed["environment"] and filed["law"] == typed["law"]
    assert filed["environment"] != report_json([*base, "--eta", "2"])["environment"]  # the file's variant did act
    beaten = report_json(["--config", gated, *base, "--variant", "squared"])
    assert beaten["inputs"]["variant"]["source"] == "user" and "squared variant" in beaten["law"]["description"]
    fuzzy = _write(tmp_path, {"law": {"name": "fuzzy", "symmetrize": "negative", "side": "right"}}, "fuzzy.yaml")
    d = report_json(["--config", fuzzy, "--law", "fuzzy", "--alpha", "60"])
    assert d["inputs"]["symmetrize"] == {"value": "negative", "unit": "", "source": f"config {fuzzy}"}
    assert d["inputs"]["side"]["source"] == f"config {fuzzy}" and "negative-bearing rows mirrored" in d["law"]["description"]
    switched = report_json(["--config", fuzzy, *base])
    assert "symmetrize" not in switched["inputs"] and switched["inputs"]["variant"]["source"] == "default (gradient)"


@pytest.mark.parametrize("law,message", [
    ({"name": "fuzzy", "variant": "squared"}, "law.variant applies to velocity-gated, not to law fuzzy"),
    ({"name": "velocity-gated", "symmetrize": "negative"}, "law.symmetrize applies to fuzzy, not to law velocity-gated"),
    ({"name": "power", "variant": "gradient"}, "law.variant applies to velocity-gated, not to law power"),
    ({"name": "velocity-gated", "variant": "paper_eq23"}, "law.variant must be one of gradient, squared, paper-eq23; got 'paper_eq23'"),
    ({"name": "fuzzy", "symmetrize": True}, "law.symmetrize must be one of none, negative, positive; got True"),
])
def test_config_refuses_bad_choices(tmp_path, law, message):
    """A choice of another law or a value not allowed: exit 2, one line naming the file and the key."""
    path = _write(tmp_path, {"law": law})
    code, out, err = run(["report", "--config", str(path), "--alpha", "60"])
    assert (code, out) == (2, ""), err
    assert err.startswith("pfm-stability: error: ") and err.endswith("\n") and err.count("\n") == 1
    assert file_error(err.removeprefix("pfm-stability: error: ").rstrip("\n"), f"config {path}", path) == message
