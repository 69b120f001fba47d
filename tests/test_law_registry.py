"""The law registry (`pfm_stability.laws.registry`) is the one table every reader of a law follows.

Checked, for every law and every parameter and choice of the registry:

* the command line: each parameter and choice is an option of exactly the commands whose laws take it
  (``report``, ``map``, ``simulate``; no other command has a law option), with the parameter's range from
  `parameters.RANGES` in its help and its type checking that range; ``--law`` offers exactly the command's laws;
* a configuration file's ``law:`` accepts exactly the keys the law takes (every other key of the registry is
  refused with the one refusal, naming the laws that take it), and ``law: NAME`` is ``law: {name: NAME}``;
* a sweep spec's ``law:`` accepts exactly the sweep's laws and the keys they take (and the same shorthand);
* ``map --law``: the options a map law takes are accepted, the others refused, as `registry.refusal` words it;
* the defaults a report states are the registry's (`make_law` builds with them);
* the views the report's modules read (``FAMILY_DEFAULTS`` …) agree with the table (one default per key).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from pfm_stability.cli import SUBCOMMANDS, build_parser
from pfm_stability.cli.options import describe, resolve_law, resolve_parameters
from pfm_stability.io.config import LAW_KEYS, config_from_mapping
from pfm_stability.laws import registry
from pfm_stability.laws.fields import make_law
from pfm_stability.laws.registry import LAW_NAMES, LAWS, PARAMETERS, choice_keys, get_law, laws_for, option_name, parameter_keys
from pfm_stability.parameters import CARMEL, DERIVATION_LAWS, RANGES
from pfm_stability.sweeps.spec import LAW_SWEPT, SWEEP_LAWS, spec_from_mapping

PARSER = build_parser()
SUBPARSERS = next(a for a in PARSER._actions if isinstance(a, argparse._SubParsersAction)).choices
OPTION_COMMANDS = ("report", "map", "simulate")
"""The registry's commands that take their laws as options (``sweep`` takes them in its spec)."""


def _options(command) -> dict:
    """Option string → action of a subcommand."""
    return {s: a for a in SUBPARSERS[command]._actions for s in a.option_strings}


def _valid(key):
    """A value of parameter or choice `key` inside its range (the law's default where there is one)."""
    for law in LAWS:
        if key in law.parameters and law.setting(key).default is not None:
            return law.setting(key).default
        if any(c.key == key for c in law.choices):
            return law.choice(key).default
    r = RANGES[key]
    return (r.low + r.high) / 2 if r.high < 1e300 else r.low + 1


def test_every_law_option_is_an_option_of_exactly_the_commands_that_take_it():
    """For every parameter and choice: the commands with an option ``--key`` are exactly those of `OPTION_COMMANDS`
    that offer a law taking it; no other command (validate, plot, derive, traps, sweep) has a law option. Why: the
    registry says which laws each command takes, and a law's parameters must follow it everywhere."""
    for key in (*PARAMETERS, *choice_keys()):
        expected = {command for command in OPTION_COMMANDS if registry.takers(key, laws_for(command))}
        having = {command for command in SUBCOMMANDS if option_name(key) in _options(command)}
        assert having == expected, (key, having, expected)


@pytest.mark.parametrize("command", OPTION_COMMANDS)
def test_law_choices_are_the_registry_s(command):
    """``--law`` offers exactly the command's laws (its default first); a command outside the registry has no ``--law``
    (``derive --law`` is the symbolic derivation's, `parameters.DERIVATION_LAWS`)."""
    assert tuple(_options(command)["--law"].choices) == laws_for(command)
    for other in set(SUBCOMMANDS) - set(OPTION_COMMANDS) - {"derive"}:
        assert "--law" not in _options(other), other
    assert tuple(_options("derive")["--law"].choices) == DERIVATION_LAWS


@pytest.mark.parametrize("command", OPTION_COMMANDS)
def test_law_options_state_and_check_the_registry_ranges(command):
    """Each law parameter's option states `parameters.RANGES[key]` in its help (as `options.describe` words it) and its
    type checks that range (the fuzzer draws inside and outside it); a choice lists exactly the law's values."""
    options = _options(command)
    for key in parameter_keys(laws_for(command)):
        action = options[option_name(key)]
        assert describe(key) in " ".join(action.help.split()), (command, key, action.help)
        assert action.type.range_key == key and action.type.kind == ("integer" if PARAMETERS[key].odd else "number")
    for key in choice_keys(laws_for(command)):
        law = get_law(registry.takers(key)[0])
        assert tuple(options[option_name(key)].choices) == law.choice(key).values


def test_report_help_names_each_law_s_default():
    """``report --help`` states each parameter's default per law, as the registry has it (``--goal-exponent``: 2 for gnron,
    0 for fuzzy; ``--goal-distance`` required for Ge & Cui 2000's laws, 1 m for the others)."""
    options = _options("report")
    goal_exponent = " ".join(options["--goal-exponent"].help.split())
    assert "gnron/fuzzy:" in goal_exponent and "(default 2 for gnron; 0 for fuzzy)" in goal_exponent
    goal_distance = " ".join(options["--goal-distance"].help.split())
    assert "(required for khatib, gnron; default 1 for velocity, velocity-gated, fuzzy)" in goal_distance


@pytest.mark.parametrize("law", LAW_NAMES)
def test_config_accepts_exactly_the_keys_the_law_takes(law):
    """``law: {name: LAW, KEY: value}`` in a configuration file is accepted exactly when the registry says LAW takes KEY
    (every key of `config.LAW_KEYS`, which is the registry's parameters and choices); otherwise the one refusal,
    naming the laws that take it."""
    assert LAW_KEYS == ("name", *PARAMETERS, *choice_keys())
    for key in LAW_KEYS[1:]:
        data = {"law": {"name": law, key: _valid(key)}}
        if get_law(law).takes(key):
            assert config_from_mapping(data, "config c.yaml").law[key] == _valid(key)
        else:
            takers = registry.either(registry.takers(key))
            with pytest.raises(ValueError, match=rf"^config c.yaml: law.{key} applies to {takers}, not to law {law}$"):
                config_from_mapping(data, "config c.yaml")


@pytest.mark.parametrize("law", LAW_NAMES)
def test_a_law_s_name_alone_is_the_law(law):
    """``law: NAME`` (a bare name) is short for ``law: {name: NAME}`` in a configuration file and a sweep spec."""
    assert config_from_mapping({"law": law}, "config c.yaml").law == config_from_mapping({"law": {"name": law}}, "config c.yaml").law == {"name": law}
    base = {"scenario": {"corridor": {"L": 0.9}}, "grid": {"V": {"from": 0.2, "to": 1.0, "num": 2}}}
    if law not in SWEEP_LAWS:
        with pytest.raises(ValueError, match=rf"^spec s.yaml: law.name: law must be one of {', '.join(SWEEP_LAWS)}; got '{law}'$"):
            spec_from_mapping({**base, "law": law}, origin="s.yaml")
    elif _needed(law):
        with pytest.raises(ValueError, match=rf"law {law} needs goal_distance"):
            spec_from_mapping({**base, "law": law}, origin="s.yaml")
    else:
        assert spec_from_mapping({**base, "law": law}, origin="s.yaml").law == spec_from_mapping({**base, "law": {"name": law}}, origin="s.yaml").law == law


def _needed(law) -> dict:
    """The parameters `law` requires, at valid values (the goal distance of Ge & Cui 2000's laws)."""
    return {s.key: 2.0 for s in get_law(law).settings if s.required}


def test_sweep_accepts_exactly_the_sweep_laws_and_their_keys():
    """A spec's law is one of the registry's sweep laws; a fixed law parameter is accepted exactly when the law takes it
    (its key is one of `spec.LAW_SWEPT`: the sweep laws' parameters), else the one refusal at that key."""
    assert SWEEP_LAWS == laws_for("sweep") and LAW_SWEPT == parameter_keys(SWEEP_LAWS)
    base = {"scenario": {"corridor": {"L": 0.9}}, "grid": {"V": {"from": 0.2, "to": 1.0, "num": 2}}}
    for law in SWEEP_LAWS:
        for key in LAW_SWEPT:
            data = {**base, "law": {"name": law, **_needed(law), key: _valid(key)}}
            if get_law(law).takes(key):
                assert spec_from_mapping(data, origin="s.yaml").law_parameters[key] == _valid(key)
            else:
                takers = registry.either(registry.takers(key, SWEEP_LAWS))
                with pytest.raises(ValueError, match=rf"^spec s.yaml: law.{key} applies to {takers}, not to law {law}$"):
                    spec_from_mapping(data, origin="s.yaml")
    for key in set(PARAMETERS) - set(LAW_SWEPT):
        with pytest.raises(ValueError, match=rf"unknown key law.{key}; the laws take: {', '.join(LAW_SWEPT)}"):
            spec_from_mapping({**base, "law": {"name": "power", key: _valid(key)}}, origin="s.yaml")


@pytest.mark.parametrize("law", laws_for("map"))
def test_map_takes_exactly_its_laws_options(law):
    """``map --law LAW --KEY v``: accepted (the law built) exactly when the registry says LAW takes KEY, else the one
    refusal naming the map's laws that take it; the map's parser has no option of a law it does not offer."""
    for key in parameter_keys(laws_for("map")):
        args = PARSER.parse_args(["map", "depot", "--law", law, option_name(key), str(_valid(key))])
        params = resolve_parameters(args)
        if get_law(law).takes(key):
            built, sources = resolve_law(args, params)
            assert sources[key] == "user" and built.parameters()[key] == _valid(key)
        else:
            with pytest.raises(ValueError, match=rf"^{option_name(key)} applies to --law grid, not to --law {law}$"):
                resolve_law(args, params)


@pytest.mark.parametrize("law", ("grid", "khatib", "gnron"))
def test_make_law_defaults_are_the_registry_s(law):
    """`fields.make_law` builds a static law with the registry's defaults (what the report calls ``default (…)``)."""
    built = make_law(law, CARMEL.robot, CARMEL.controller, **({"goal_distance": 3.0} if law != "grid" else {}))
    for setting in get_law(law).settings:
        if setting.default is not None:
            assert built.parameters()[setting.key] == setting.default, (law, setting.key)


def test_views_agree_with_the_table():
    """The views the report's modules read are the table's: the static and family laws partition `LAWS`; a parameter
    shared by the family laws has one default (`FAMILY_DEFAULTS` holds one per key); a choice belongs to one law."""
    assert set(registry.FORCE_LAWS) | set(registry.FAMILY_LAWS) == set(LAW_NAMES)
    assert not set(registry.FORCE_LAWS) & set(registry.FAMILY_LAWS)
    for law in LAWS:
        if law.kind == "family":
            for setting in law.settings:
                assert registry.FAMILY_DEFAULTS[setting.key] == setting.default, (law.name, setting.key)
            assert registry.FAMILY_LAW_PARAMETERS[law.name] == law.parameters
        else:
            assert registry.LAW_PARAMETERS[law.name] == (*law.controller, *law.parameters)
    owners = [c.key for law in LAWS for c in law.choices]
    assert len(owners) == len(set(owners))
    assert registry.MAP_LAWS == laws_for("map") and registry.HOLONOMIC_LAWS == ("velocity", "velocity-gated")


def test_lists_kept_elsewhere_agree_with_the_registry():
    """Two lists outside the registry's readers must name what it does until they read it: the report's law inputs (in
    the order the report lists them) are the static laws' parameters, and the simulator's analytic laws are those
    ``simulate`` offers."""
    from pfm_stability.report.stability import LAW_INPUTS
    from pfm_stability.sim.scenario import LAW_NAMES as SIMULATED

    assert LAW_INPUTS == parameter_keys(registry.FORCE_LAWS)
    assert SIMULATED == laws_for("simulate")


def test_the_documented_table_is_the_registry():
    """docs/fields.md, "The law registry": one row per law, in order, with its kind, parameters (f and n first), choices,
    robot families and commands exactly as declared (a reader of the documentation sees the table the code reads)."""
    lines = (Path(__file__).resolve().parent.parent / "docs" / "fields.md").read_text(encoding="utf-8").splitlines()
    header = lines.index("| law | kind | parameters (besides W) | choices | robot families | commands |")
    rows = []
    for line in lines[header + 2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split("|")])

    def names(cell):
        return tuple(name.strip() for name in cell.split(",")) if cell != "—" else ()

    documented = [(law.strip("`"), kind, names(params), names(choices), names(families), names(commands))
                  for law, kind, params, choices, families, commands in rows]
    declared = [(law.name, law.kind, (*law.controller, *law.parameters), tuple(c.key for c in law.choices), law.families, law.commands)
                for law in LAWS]
    assert documented == declared
