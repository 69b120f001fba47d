"""``pfm-stability map`` (docs/maps.md): outputs on the shipped maps, the JSON schema, and bad maps.

The shipped maps are analysed with robots that fit them (the TurtleBot3 sandbox with
a 0.2 m robot); the outputs are checked by reading them back the way their users do:
the PNG and the PGM with Pillow, the mask's YAML with PyYAML and its values with
Nav2's scale-mode formula (`pfm_stability.maps.deciding.outputs.pixel_to_percent`). A bad map
must give exit status 2, one line naming the problem, and nothing in the output
directory.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import shutil
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
import yaml
from jsonschema import Draft202012Validator
from PIL import Image

from pfm_stability.cli import main
from pfm_stability.maps.deciding.outputs import pixel_to_percent
from pfm_stability.io.schema import load_schema
from cli_helpers import file_error
from map_helpers import shared_map_analyses

MAPS = Path(str(resources.files("pfm_stability").joinpath("data", "maps")))
VALIDATOR = Draft202012Validator(load_schema())


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


ROBOTS = {"depot": ["--W", "0.4", "--tau", "0.2", "--k", "10", "--T", "0.05", "--f", "2", "--V", "0.3"], "tb3_sandbox": ["--W", "0.2", "--tau", "0.1", "--k", "20", "--T", "0.025", "--f", "2", "--V", "0.6", "--min-length", "0.5"]}


SHARED = {name: pytest.mark.xdist_group(f"map_cli_{name}") for name in ROBOTS}
"""The tests that read a shipped map with its robot run on one worker: its analysis once (tests/map_helpers.py)."""


@pytest.mark.parametrize("name", [pytest.param(name, marks=SHARED[name]) for name in ROBOTS])
def test_shipped_map_outputs(tmp_path, name):
    """Every output of the one result set is written and readable: the routes' PNG; their CSV (one row per stretch,
    as in the JSON); the mask PGM with the map's size, its YAML with the map's resolution and origin; and the mask's
    values decode to 100 % off the unstable route stretches and to floor(100 V*/V) (>= 1) within W/2 of each of them
    (a route stretch's piece of its route cut at its arc positions, here with numpy's interpolation): a zone wherever
    the verdict is unstable, none where it is stable. Every decided stretch's V* and margin agree with its verdict."""
    out = tmp_path / "out"
    with shared_map_analyses():
        code, stdout, err = run(["map", name, *ROBOTS[name], "--out-dir", str(out), "--format", "json", "--quiet"])
    assert code == 0, err
    data = json.loads(stdout)
    assert data["segments"] is None and data["summary"] == data["paths"]["summary"]
    assert sorted(p.name for p in out.iterdir()) == ["routes.csv", "routes.png", "speed_mask.pgm", "speed_mask.yaml"]
    with Image.open(out / "routes.png") as im:
        assert im.format == "PNG" and im.width > 500
    stretches = data["paths"]["stretches"]
    rows = list(csv.DictReader((out / "routes.csv").open()))
    assert len(rows) == len(stretches) and [float(r["length"]) for r in rows] == pytest.approx([s["length"] for s in stretches], rel=1e-5)
    source = yaml.safe_load((MAPS / f"{name}.yaml").read_text())
    mask_yaml = yaml.safe_load((out / "speed_mask.yaml").read_text())
    assert mask_yaml["resolution"] == pytest.approx(source["resolution"]) and mask_yaml["origin"] == pytest.approx(source["origin"])
    assert mask_yaml["mode"] == "scale" and (mask_yaml["free_thresh"], mask_yaml["occupied_thresh"], mask_yaml["negate"]) == (0.0, 1.0, 0)
    with Image.open(out / "speed_mask.pgm") as im:
        assert im.format == "PPM" and im.mode == "L" and im.size == (data["map"]["width"], data["map"]["height"])
        percent = pixel_to_percent(np.array(im))[::-1]  # row 0 at y = origin
    V, W = data["inputs"]["V"], data["inputs"]["W"]
    value = lambda x: math.inf if x == "inf" else x  # noqa: E731
    for s in stretches:  # one answer: V* >= V and margin >= 0 exactly when stable
        if s["verdict"] in ("stable", "unstable"):
            assert (s["verdict"] == "stable") == (value(s["V_critical"]) >= V) == (value(s["margin"]) >= 0), s
            assert (s["cause"] is None) == (s["verdict"] == "stable"), s
    r, (ox, oy) = data["map"]["resolution"], data["map"]["origin"][:2]
    expected = np.full(percent.shape, 100)
    jj, ii = np.mgrid[0:percent.shape[0], 0:percent.shape[1]]
    px, py = ox + (ii + 0.5) * r, oy + (jj + 0.5) * r
    unstable = [s for s in stretches if s["verdict"] == "unstable"]
    for s in unstable:  # within W/2 of each unstable route stretch (its piece of the route)
        route = np.array(data["paths"]["routes"][s["route"]]["points"])
        edges = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(route, axis=0).T))])
        arcs = np.concatenate([[s["start"]], edges[(edges > s["start"]) & (edges < s["stop"])], [s["stop"]]])
        piece = np.column_stack([np.interp(arcs, edges, route[:, 0]), np.interp(arcs, edges, route[:, 1])])
        for (x0, y0), (x1, y1) in zip(piece[:-1], piece[1:]):
            dx, dy = x1 - x0, y1 - y0
            t = np.clip(((px - x0) * dx + (py - y0) * dy) / max(dx * dx + dy * dy, 1e-300), 0, 1)
            near = np.hypot(px - x0 - t * dx, py - y0 - t * dy) <= W / 2
            expected[near] = np.minimum(expected[near], max(1, math.floor(100 * s["V_critical"] / V)))
    assert np.array_equal(percent, expected)
    assert (percent < 100).any() == bool(unstable)
    assert VALIDATOR.is_valid(data), [e.message for e in VALIDATOR.iter_errors(data)][:3]


@SHARED["depot"]
def test_text_output_lists_the_slowest_unstable_stretches():
    """The text output names the map, the robot, the unstable route stretches (slowest V* first, with their cause) and
    the routes' summary (the analysis of test_shipped_map_outputs[depot], tests/map_helpers.py)."""
    with shared_map_analyses():
        code, stdout, err = run(["map", "depot", *ROBOTS["depot"], "--quiet"])
    assert code == 0, err
    assert stdout.startswith("map depot: 604 x 307 cells of 0.05 m") and "unstable route stretches" in stdout and "routes:" in stdout
    rows = [line.split() for line in stdout.splitlines() if line.strip().startswith("(") and "%" in line]
    speeds = [float(row[-3]) for row in rows]
    assert speeds == sorted(speeds) and len(speeds) >= 3


@SHARED["tb3_sandbox"]
def test_json_is_deterministic():
    """Two runs print the same JSON once the wall-clock timing is dropped (seeded thinning and selection): the second
    analyses the map afresh; the first is the analysis test_shipped_map_outputs[tb3_sandbox] made earlier in this
    process when it ran first (tests/map_helpers.py), a fresh one otherwise."""
    outs = []
    for shared in (shared_map_analyses(), contextlib.nullcontext()):
        with shared:
            code, stdout, _ = run(["map", "tb3_sandbox", *ROBOTS["tb3_sandbox"], "--format", "json", "--quiet"])
        assert code == 0
        data = json.loads(stdout)
        data.pop("timing")
        outs.append(json.dumps(data))
    assert outs[0] == outs[1]


def _copy_map(tmp_path: Path, name="depot") -> Path:
    for suffix in ("yaml", "pgm"):
        shutil.copy(MAPS / f"{name}.{suffix}", tmp_path / f"{name}.{suffix}")
    return tmp_path / f"{name}.yaml"


def _edit(path: Path, **changes) -> None:
    data = yaml.safe_load(path.read_text())
    for key, value in changes.items():
        if value is None:
            data.pop(key)
        else:
            data[key] = value
    path.write_text(yaml.safe_dump(data))


BAD_MAPS = {
    "missing image": (lambda p: _edit(p, image="nothing.pgm"), "does not exist"),
    "image not an image": (lambda p: (p.parent / "depot.pgm").write_text("P5 not really"), "not a readable image"),
    "unreadable YAML": (lambda p: p.write_text("image: [unclosed\n"), "not valid YAML"),
    "missing key": (lambda p: _edit(p, resolution=None), "key 'resolution' is missing"),
    "resolution <= 0": (lambda p: _edit(p, resolution=0), "resolution must be"),
    "threshold above 1": (lambda p: _edit(p, occupied_thresh=1.5), "occupied_thresh must be"),
    "free >= occupied": (lambda p: _edit(p, free_thresh=0.7), "free_thresh must be below occupied_thresh"),
    "unknown mode": (lambda p: _edit(p, mode="fancy"), "mode must be one of"),
    "no free space": (lambda p: Image.new("L", (40, 30), 0).save(p.parent / "depot.pgm", format="PPM"), "no free space"),
    "no route long enough": (lambda p: Image.new("L", (30, 30), 254).save(p.parent / "depot.pgm", format="PPM"), "no route long enough"),
    "image of the wrong format": (lambda p: Image.new("CMYK", (40, 30)).save(p.parent / "depot.pgm", format="TIFF"), "pixel mode CMYK"),
}


ANALYSIS_ERRORS = ("no free space", "no route long enough")
"""Cases of `BAD_MAPS` that the analysis refuses (a good file of a map without corridors), not the map reader."""


@pytest.mark.parametrize("case", list(BAD_MAPS))
def test_bad_map_exits_2_and_writes_nothing(tmp_path, case):
    """Each bad map: exit 2, one line "pfm-stability: error: map FILE, line N: <problem>" with the line of the key it names
    (`cli_helpers.file_error`; or the analysis' message), no traceback, and the output directory (created on success only)
    does not exist afterwards."""
    spoil, message = BAD_MAPS[case]
    path = _copy_map(tmp_path)
    spoil(path)
    out = tmp_path / "out"
    code, stdout, err = run(["map", str(path), "--out-dir", str(out), "--quiet"])
    assert code == 2 and stdout == ""
    assert err.startswith("pfm-stability: error: ") and message in err and len(err.strip().splitlines()) == 1
    if case not in ANALYSIS_ERRORS:
        assert message in file_error(err.removeprefix("pfm-stability: error: ").rstrip("\n"), f"map {path}", path)
    assert not out.exists()


def test_existing_output_directory_is_untouched_on_failure(tmp_path):
    """An existing --out-dir keeps exactly what it had when the analysis fails (no temporary files left)."""
    path = _copy_map(tmp_path)
    _edit(path, resolution=-1)
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("x")
    assert run(["map", str(path), "--out-dir", str(out), "--quiet"])[0] == 2
    assert [p.name for p in out.iterdir()] == ["keep.txt"]


@pytest.mark.parametrize("argv, message", [
    (["map", "depot", "--law", "khatib", "--goal-distance", "3"], "argument --law: invalid choice: 'khatib'"),
    (["map", "depot", "--out-dir", "/nonexistent-dir/x"], "out-dir must be a writable directory"),
])
def test_bad_options(argv, message):
    """Options are checked before any work: exit 2 with the option named (every option's range:
    tests/test_cli_fuzz.py::test_every_range_end_is_accepted_or_rejected_as_stated)."""
    code, _, err = run([*argv, "--quiet"])
    assert code == 2 and message in err


@pytest.mark.parametrize("law", ["khatib", "gnron"])
def test_law_named_by_a_config_file_is_checked_too(tmp_path, law):
    """A law `map` does not support is refused when a --config file names it (not only when typed): the resolved
    law is checked, before the map is read (the map here does not exist, so a later check would name the map)."""
    config = tmp_path / "robot.yaml"
    config.write_text(f"law: {{name: {law}, goal_distance: 3.0}}\n")
    code, stdout, err = run(["map", str(tmp_path / "missing.yaml"), "--config", str(config), "--quiet"])
    assert code == 2 and stdout == ""
    assert err.startswith("pfm-stability: error: law must be one of grid, power") and law in err


def test_help_lists_only_the_laws_map_takes():
    """``map --help`` offers --law grid and power (`parameters.MAP_LAWS`), grid the default, and none of the options of
    the laws it refuses (Khatib's and the goal-aware law need a goal a map does not give)."""
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer), pytest.raises(SystemExit) as exit_:
        main(["map", "--help"])
    out = buffer.getvalue()
    assert exit_.value.code == 0
    assert "--law {grid,power}" in out and "khatib" not in out and "gnron" not in out
    for option in ("--xi", "--eta", "--rho0", "--goal-distance", "--goal-exponent", "--attraction-exponent", "--delta"):
        assert option not in out
    law_help = " ".join(out.split("--law {grid,power}")[-1].split("--cell-ratio")[0].split())
    assert law_help.endswith("the histogram grid's law (default, unless the configuration file names one)")


@pytest.mark.parametrize("command, name, folder", [("map", "nosuchmap", "maps"), ("traps", "nosuchscene", "scenes")])
def test_unknown_shipped_name_lists_the_shipped_ones(command, name, folder):
    """A bare name that is neither a file nor shipped: exit 2, one line listing the shipped names, each of which is a
    file of pfm_stability/data/<folder> (every scene file there; every map but depot_speed, Nav2's example speed mask,
    which is not an occupancy map)."""
    code, out, err = run([command, name])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert f"{name!r} is neither a file nor a shipped" in err
    listed = err.split("(shipped: ")[1].rstrip(")\n").split(", ")
    files = Path(str(resources.files("pfm_stability").joinpath("data", folder)))
    assert sorted(listed) == sorted(p.stem for p in files.glob("*.yaml") if p.stem != "depot_speed")


@pytest.mark.parametrize("origin", ["[0.0, 0.0]", "[0.0, 0.0, 0.0, 1.0]", "0.0", "[0.0, .nan, 0.0]", "[0.0, 0.0, true]"])
def test_origin_map_server_refuses_is_refused(tmp_path, origin):
    """Nav2's map_server takes origin as exactly three numbers [x, y, yaw] ("value of the 'origin' tag should have 3
    elements"; a bool is not a number to it): two (the yaw left out), four, a scalar or a bool are refused, and NaN too
    (map_server would read it; no coordinate follows from it): exit 2, one line naming origin."""
    path = _copy_map(tmp_path)
    path.write_text(path.read_text().replace("origin: [0.0, 0.0, 0]", f"origin: {origin}"))
    code, out, err = run(["map", str(path), "--quiet"])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "origin" in err


def _open_corridor(tmp_path: Path, resolution: float, gap_pixels: int, length_pixels: int) -> Path:
    """A map of one straight corridor of `gap_pixels` free pixels between one-pixel walls, `length_pixels` long."""
    img = np.full((length_pixels, gap_pixels + 2), 254, dtype=np.uint8)
    img[:, 0] = img[:, -1] = 0
    Image.fromarray(img).save(tmp_path / "c.pgm")
    path = tmp_path / "c.yaml"
    path.write_text(f"image: c.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path


def test_a_resolution_typo_is_warned_about(tmp_path):
    """A corridor of 8 pixels at 0.25 m/pixel (meant: 0.025): the map is analysed with one warning line on stderr
    (before the analysis' work) and the same line in the JSON's ``warnings``: a pixel (0.25 m) is wider than half the
    robot (W/2 = 0.2 m; `maps.analysis.MAX_RESOLUTION`). A corridor of 20 pixels at 0.05 m/pixel (1 m, 2.5 W): none."""
    code, out, err = run(["map", str(_open_corridor(tmp_path, 0.25, 8, 40)), "--W", "0.4", "--format", "json", "--quiet"])
    assert code == 0, err
    warnings = [line for line in err.splitlines() if line.startswith("pfm-stability: warning: ")]
    assert len(warnings) == 1 and "resolution 0.25 m/pixel is implausible" in warnings[0] and "0.2 m" in warnings[0]
    data = json.loads(out)
    assert data["warnings"] == [warnings[0].removeprefix("pfm-stability: warning: ")]
    assert VALIDATOR.is_valid(data)
    code, out, err = run(["map", str(_open_corridor(tmp_path, 0.05, 20, 200)), "--W", "0.4", "--format", "json", "--quiet"])
    assert code == 0 and err == "" and json.loads(out)["warnings"] == []


class _Stop(Exception):
    pass


def test_a_resolution_typo_making_a_500_m_map_is_warned_before_the_work(tmp_path):
    """The issue's case: resolution 5.0 typed for 0.05 turns a 100-pixel map into a 500 m one. `analyze_map` calls
    ``warn`` with one line naming the resolution before any work: a ``warn`` that raises stops it before the histogram
    grid (5000 x 5000 cells at 0.1 m) is built, so the call returns at once. The CLI's text and JSON say which reading of
    unknown cells was used (checked on a plausible map)."""
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.parameters import CARMEL

    lines = []

    def warn(line):
        lines.append(line)
        raise _Stop

    occupancy = load_map(_open_corridor(tmp_path, 5.0, 8, 100))
    with pytest.raises(_Stop):
        analyze_map(occupancy, CARMEL.robot, CARMEL.controller, make_law("grid", CARMEL.robot, CARMEL.controller), warn=warn)
    assert len(lines) == 1 and "\n" not in lines[0] and "resolution 5 m/pixel is implausible" in lines[0] and "5.0 for 0.05" in lines[0]
    path = _open_corridor(tmp_path, 0.05, 20, 200)
    code, out, err = run(["map", str(path), "--W", "0.4", "--format", "json", "--quiet", "--unknown", "free"])
    assert code == 0 and json.loads(out)["inputs"]["unknown"] == "free"
    code, out, err = run(["map", str(path), "--W", "0.4", "--quiet"])
    assert code == 0 and "(unknown = occupied)" in out


def test_corridors_many_robot_widths_wide_are_warned_about(tmp_path):
    """At a plausible resolution (0.1 m/pixel) a corridor 5 m wide (20 m long) is 12.5 robot widths (W = 0.4 m), more
    than `maps.analysis.MAX_CORRIDOR_WIDTHS` = 10 (a resolution 10 times too large looks like this): one warning line
    naming the width (4.9 m: twice the clearance of the skeleton's cells, half a cell beside the axis of an even gap).
    A 3.8 m corridor (9.5 W) is not warned about."""
    code, out, err = run(["map", str(_open_corridor(tmp_path, 0.1, 50, 200)), "--W", "0.4", "--format", "json", "--quiet"])
    assert code == 0, err
    (line,) = err.splitlines()
    assert line.startswith("pfm-stability: warning: ") and "narrowest corridor is 4.9 m wide, 12 robot widths" in line
    assert json.loads(out)["warnings"] == [line.removeprefix("pfm-stability: warning: ")]
    code, out, err = run(["map", str(_open_corridor(tmp_path, 0.1, 38, 200)), "--W", "0.4", "--format", "json", "--quiet"])
    assert code == 0 and err == "" and json.loads(out)["warnings"] == []
