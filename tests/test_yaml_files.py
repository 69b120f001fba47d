"""The one YAML reader (`pfm_stability.io.yaml_files`): every file the package reads reads numbers and words errors alike.

Checked on each kind of file — configuration file, sweep spec, scene, map metadata (and presets, the fuzzy
tables and a Nav2 file where they differ):

* the number rule: a plain ``1e-3``, ``1E-3`` and ``-2e+1`` (where the key's range holds it) are the numbers
  10⁻³ and −20 in every kind (plain YAML 1.1 reads them as text); a quoted ``'1e-3'`` is text and is refused
  where a number is expected, with the same words in every kind;
* the error format: a bad value is one line ``<kind> <file>, line <n>: <key> …`` whose line is the key's own
  line in the file (the exact line is asserted, for values on their own line and in flow mappings);
* a key given twice and invalid YAML are errors of that format in every kind; a missing file is
  ``<kind> <file>: cannot read the file (…)``;
* the error survives pickling (sweep workers pass errors between processes) and prints the same.

Float equality is exact here: the parser turns the same text into the same double.
"""

from __future__ import annotations

import pickle
import textwrap
from pathlib import Path

import pytest

from pfm_stability.io.config import load_config
from pfm_stability.io.yaml_files import InputError, parse_yaml, read_yaml
from pfm_stability.laws.fuzzy import DFAPF_FILE, load_dfapf
from pfm_stability.laws.scene import Scene
from pfm_stability.maps.reading.occupancy import load_map
from pfm_stability.sweeps.spec import load_spec
from cli_helpers import file_error

MAPS = Path(__file__).resolve().parent.parent / "pfm_stability" / "data" / "maps"


def _write(tmp_path, name, text) -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return path


def _config(tmp_path, T="0.05", k="2.0"):
    return _write(tmp_path, "robot.yaml", f"""
        # a robot
        robot:
          k: {k}
        controller:
          T: {T}
        """)


def _spec(tmp_path, T_from="0.01"):
    return _write(tmp_path, "study.yaml", f"""
        preset: carmel
        scenario: {{corridor: {{L: 0.9}}}}
        models: [sampled]
        grid:
          V: {{from: 0.2, to: 1.0, num: 2}}
          T:
            from: {T_from}
            to: 0.1
            num: 2
        """)


def _scene(tmp_path, delta="0.0", goal_x="0.0"):
    return _write(tmp_path, "hall.yaml", f"""
        law:
          name: gnron
          xi: 1.0
          eta: 1.0
          rho0: 2.0
          attraction_exponent: 2
          goal_exponent: 2
          delta: {delta}
        goal: [{goal_x}, 0.0]
        obstacles:
          - circle: {{center: [1.0, 0.0], radius: 0.5}}
        region: [[-30.0, -3.0], [4.0, 3.0]]
        """)


def _map(tmp_path, resolution="0.05", origin_x="0.0"):
    (tmp_path / "depot.pgm").write_bytes((MAPS / "depot.pgm").read_bytes())
    return _write(tmp_path, "depot.yaml", f"""
        image: depot.pgm
        mode: trinary
        resolution: {resolution}
        origin: [{origin_x}, 0.0, 0]
        negate: 0
        occupied_thresh: 0.65
        free_thresh: 0.25
        """)


# ------------------------------------------------------------------ numbers
@pytest.mark.parametrize("text, value", [("1e-3", 1e-3), ("1E-3", 1e-3), ("1.0e-3", 1e-3), (".1e-2", 1e-3)])
def test_exponent_numbers_are_numbers_in_every_kind_of_file(tmp_path, text, value):
    """``T: 1e-3`` is 10⁻³ in a configuration file, a sweep spec (``grid.T.from``), a scene (``law.delta``) and a map
    (``resolution``): the same text, the same number, whichever file it is in."""
    assert load_config(_config(tmp_path, T=text)).controller.T == value
    assert load_spec(_spec(tmp_path, T_from=text)).axes[1].start == value
    assert Scene.load(_scene(tmp_path, delta=text)).law.delta == value
    assert load_map(_map(tmp_path, resolution=text)).resolution == value


def test_negative_exponent_numbers_where_the_range_holds_them(tmp_path):
    """``-2e+1`` is −20 where a key takes negative values: a scene's goal, a map's origin, any number of a Nav2
    footprint string (read by the same rule)."""
    assert Scene.load(_scene(tmp_path, goal_x="-2e+1")).goal == (-20.0, 0.0)
    assert load_map(_map(tmp_path, origin_x="-2e+1")).origin[0] == -20.0
    assert parse_yaml("[[-2e+1, 1E-3], [0.1, -1e-1]]") == [[-20.0, 1e-3], [0.1, -0.1]]


def test_words_and_quoted_numbers_stay_text(tmp_path):
    """A quoted ``'1e-3'`` is text in every kind of file (YAML's rule: the user wrote text), refused where a number is
    expected with the same words; a word such as ``e3`` or ``1e`` is text too."""
    cases = [
        (load_config, _config(tmp_path, T="'1e-3'"), "config", "controller.T must be a finite number in [0, 100] s; got '1e-3'"),
        (load_spec, _spec(tmp_path, T_from="'1e-3'"), "spec", "grid.T.from must be a finite number; got '1e-3'"),
        (Scene.load, _scene(tmp_path, delta="'1e-3'"), "scene", "law.delta must be a finite number in [0, 1000000] m; got '1e-3'"),
        (load_map, _map(tmp_path, resolution="'1e-3'"), "map", "resolution must be a finite number in (0, 1000) m; got '1e-3'"),
    ]
    for read, path, kind, message in cases:
        with pytest.raises(ValueError) as caught:
            read(path)
        assert file_error(str(caught.value), f"{kind} {path}", path) == message
    assert parse_yaml("[e3, 1e, '1e-3', 1_0]") == ["e3", "1e", "1e-3", 10]


# ------------------------------------------------------------------ the error format
@pytest.mark.parametrize("kind", ["config", "spec", "scene", "map"])
def test_a_bad_value_names_the_file_the_line_and_the_key(tmp_path, kind):
    """A value out of range: ``<kind> <file>, line <n>: <key> …`` with n the key's own line (comments and the keys
    above counted), the key as the file nests it, and the command line's range words."""
    path, read, line, detail = {
        "config": (_config(tmp_path, T="-1e-3"), load_config, 5, "controller.T must be a finite number in [0, 100] s; got -0.001"),
        "spec": (_spec(tmp_path, T_from="-1e-3"), load_spec, 7, "grid.T.from: T must be a finite number in [0, 100] s; got -0.001"),
        "scene": (_scene(tmp_path, delta="-1e-3"), Scene.load, 8, "law.delta must be a finite number in [0, 1000000] m; got -0.001"),
        "map": (_map(tmp_path, resolution="-5e-2"), load_map, 3, "resolution must be a finite number in (0, 1000) m; got -0.05"),
    }[kind]
    with pytest.raises(ValueError) as caught:
        read(path)
    assert str(caught.value) == f"{kind} {path}, line {line}: {detail}"
    assert file_error(str(caught.value), f"{kind} {path}", path) == detail


def test_a_key_inside_a_flow_mapping_has_its_line(tmp_path):
    """A key written inline (``V: {from: -1, …}`` on line 5 of a spec) has the line it is written on; a missing key
    the line of the mapping that lacks it."""
    path = _write(tmp_path, "study.yaml", """
        preset: carmel
        scenario: {corridor: {L: 0.9}}
        models: [sampled]
        grid:
          V: {from: -1, to: 1.0, num: 2}
        """)
    with pytest.raises(ValueError) as caught:
        load_spec(path)
    assert str(caught.value) == f"spec {path}, line 5: grid.V.from: V must be a finite number in (0, 100] m/s; got -1.0"
    path.write_text(path.read_text().replace("to: 1.0, ", ""))
    with pytest.raises(ValueError, match=rf"^spec {path}, line 5: grid.V.to is missing$"):
        load_spec(path)


@pytest.mark.parametrize("kind", ["config", "spec", "scene", "map", "preset", "fuzzy tables"])
def test_duplicate_keys_and_bad_yaml_are_errors_of_the_same_form(tmp_path, kind):
    """A key given twice (plain YAML keeps the last silently) and invalid YAML: ``<kind> <file>, line <n>: …`` with the
    line of the second key, of the syntax error; a missing file: ``<kind> <file>: cannot read the file (…)``."""
    twice = _write(tmp_path, "twice.yaml", """
        outer:
          a: 1
          a: 2
        """)
    with pytest.raises(InputError) as caught:
        read_yaml(twice, kind)
    assert str(caught.value) == f"{kind} {twice}, line 3: outer.a is given twice"
    broken = _write(tmp_path, "broken.yaml", "a: [1, 2\nb: 3\n")
    with pytest.raises(InputError, match=rf"^{kind} {broken}, line 2: not valid YAML: .* \(column \d+\)$"):
        read_yaml(broken, kind)
    with pytest.raises(InputError, match=rf"^{kind} {tmp_path / 'none.yaml'}: cannot read the file \(No such file or directory\)$"):
        read_yaml(tmp_path / "none.yaml", kind)


def test_every_reader_goes_through_the_one_reader(tmp_path):
    """Each kind of file refuses a key given twice with the one reader's message (so each reads through it): a
    configuration file, a spec, a scene, a map, the fuzzy tables."""
    duplicated = {
        "config": ("robot.yaml", "robot:\n  V: 1\n  V: 2\n", load_config, "robot.V"),
        "spec": ("study.yaml", "preset: carmel\npreset: carmel\n", load_spec, "preset"),
        "scene": ("hall.yaml", "goal: [0, 0]\ngoal: [1, 0]\n", Scene.load, "goal"),
        "map": ("depot.yaml", "image: depot.pgm\nimage: depot.pgm\n", load_map, "image"),
        "fuzzy tables": ("dfapf.yaml", DFAPF_FILE.read_text() + "variables: {}\n", lambda p: load_dfapf(path=p), "variables"),
    }
    for kind, (name, text, read, key) in duplicated.items():
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(ValueError) as caught:
            read(path)
        line = len(text.splitlines())
        assert str(caught.value) == f"{kind} {path}, line {line}: {key} is given twice", kind


def test_nav2_values_have_their_lines(tmp_path):
    """A Nav2 file's bad value names the key as Nav2 users know it and the line it is on."""
    path = _write(tmp_path, "nav2_params.yaml", """
        controller_server:
          ros__parameters:
            controller_frequency: -2e+1
        """)
    with pytest.raises(ValueError) as caught:
        load_config(path)
    assert str(caught.value) == (f"Nav2 {path}, line 3: controller_server.controller_frequency must be a finite number "
                                 "in [0.01, 1000000] Hz; got -20.0")


def test_errors_survive_pickling():
    """An `InputError` crosses process boundaries (sweep workers) unchanged: same text, same fields."""
    error = InputError("grid.V.from: V must be …", origin="spec s.yaml", key="grid.V.from", line=7)
    again = pickle.loads(pickle.dumps(error))
    assert str(again) == str(error) == "spec s.yaml, line 7: grid.V.from: V must be …"
    assert (again.origin, again.key, again.line, again.detail) == (error.origin, error.key, error.line, error.detail)
