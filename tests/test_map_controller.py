"""``map --controller rpp``: Nav2's Regulated Pure Pursuit along a map's routes (`maps.deciding.tracking`, docs/maps.md, "Nav2's
controllers along a map").

The independent route is ``report --controller rpp``: a stretch's verdict, margin, V* and L* at its half-width and speed
equal the report's; a straight corridor gets one verdict; where a short lookahead is unstable, the zone mask's state
sets a lookahead the report finds stable; the outputs are written all or none; the VFF-only options are refused.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from cli_helpers import VALIDATOR, disk_full, report_json, run
from pfm_stability.io.yaml_files import read_yaml
from pfm_stability.maps.deciding.outputs import pixel_to_percent

pytest.importorskip("skimage")

LENGTH, HALF = 12.0, 0.45
"""The synthetic corridor: 12 m long, 0.45 m from its centre line to each wall's face (dead ends)."""
COST_FACTOR = ["--param", "inflation_cost_scaling_factor=10"]
"""RPP's cost factor equal to the inflation layer's (Nav2's defaults differ): the cost heuristic slows the robot in the corridor."""
FAST = ["--V", "3.0", *COST_FACTOR]
"""Unstable at the default lookahead 0.6 m: V/L above (V/L)* in the corridor's middle."""


def corridor_map(directory: Path) -> Path:
    """A straight corridor along x at 0.05 m a pixel: walls of 3 pixels, free band 2·HALF wide, open ends inside a frame."""
    r = 0.05
    free = round(2 * HALF / r)
    rows, cols = free + 6, round(LENGTH / r) + 6
    img = np.zeros((rows, cols), dtype=np.uint8)
    img[3:3 + free, 3:cols - 3] = 254
    Image.fromarray(img).save(directory / "corridor.pgm")
    path = directory / "corridor.yaml"
    path.write_text(f"image: corridor.pgm\nresolution: {r}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path


def map_json(argv) -> dict:
    code, out, err = run(["map", *argv, "--format", "json", "--quiet"])
    assert code == 0, err
    data = json.loads(out)
    errors = [f"{list(e.absolute_path)}: {e.message[:200]}" for e in VALIDATOR.iter_errors(data)]
    assert not errors, errors[:3]
    return data


@pytest.fixture(scope="module")
def corridor(tmp_path_factory) -> Path:
    return corridor_map(tmp_path_factory.mktemp("rpp_corridor"))


def _middle(data: dict) -> dict:
    """The stretch covering the corridor's middle."""
    stretches = data["paths"]["stretches"]
    return max(stretches, key=lambda s: s["length"])


def _close(a, b, rtol=1e-6):
    if a == "inf" or b == "inf":
        return a == b
    return abs(a - b) <= rtol * max(abs(a), abs(b))


@pytest.mark.parametrize("argv", [FAST, ["--V", "0.5", *COST_FACTOR], ["--V", "1.2", "--param", "use_velocity_scaled_lookahead_dist=true",
                                                                        *COST_FACTOR]])
def test_a_stretch_is_the_report_at_its_half_width_and_speed(corridor, argv):
    data = map_json([str(corridor), "--controller", "rpp", *argv])
    s = _middle(data)
    report = report_json(["--controller", "rpp", "--model", "sampled", "--L", repr(s["half_width"]), *argv])
    verdict, law = report["path"]["sampled"], report["environment"]["path"]["law"]
    assert s["verdict"] == verdict["verdict"]
    assert s["cause"] == ("growth" if verdict["verdict"] == "unstable" else None)
    assert report["environment"]["path"]["pose_cost"] == s["pose_cost"] and s["curvature"] == 0.0
    for mine, theirs in (("margin", "margin"), ("V_critical", "V_critical"), ("lookahead_critical", "lookahead_critical")):
        assert _close(s[mine], verdict[theirs]), (mine, s[mine], verdict[theirs])
    assert _close(s["V"], law["V"]) and _close(s["L"], law["L"])


def test_the_straight_corridor_gets_one_verdict(corridor):
    data = map_json([str(corridor), "--controller", "rpp", *FAST])
    s = _middle(data)
    route = data["paths"]["routes"][s["route"]]
    end = 1.5  # near the dead ends the skeleton bends towards a corner and the end wall raises the cost (a slower, other speed)
    assert s["verdict"] == "unstable" and s["start"] <= end and s["stop"] >= route["length"] - end
    assert [x["route"] for x in data["paths"]["stretches"]] == [s["route"]] * len(data["paths"]["stretches"])  # one route
    assert abs(s["half_width"] - HALF) < 0.05 + 1e-9  # the clearance on the skeleton: within half a grid cell of the face
    assert data["controller"] == "rpp" and data["segments"] is None and data["validation"] is None


def test_the_zone_mask_sets_a_lookahead_the_report_finds_stable(corridor, tmp_path):
    out = tmp_path / "out"
    data = map_json([str(corridor), "--controller", "rpp", *FAST, "--out-dir", str(out)])
    assert sorted(p.name for p in out.iterdir()) == ["routes.csv", "routes.png", "speed_mask.pgm", "speed_mask.yaml", "zone_mask.pgm", "zone_mask.yaml",
                                                     "zone_params.yaml"]
    assert (out / "routes.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # the stretches drawn by verdict and remedy
    s = _middle(data)
    zone = s["zone_lookahead"]
    assert zone is not None and s["lookahead_critical"] <= zone <= 0.9 and zone - s["lookahead_critical"] < 0.01 + 1e-9
    params = read_yaml(str(out / "zone_params.yaml"), "zone_params").data
    zp = params["local_costmap"]["local_costmap"]["ros__parameters"]["zone_params"]
    assert zp["plugin"] == "nav2_costmap_2d::ZoneParameterFilter"
    states = {zp[name]["id"]: zp[name]["lookahead"] for name in zp["states"]}
    assert zp["nominal_defaults"] == ["lookahead"] and zp["nominal_defaults.lookahead"]["value"] == 0.6
    assert "PR #6104" in (out / "zone_params.yaml").read_text().splitlines()[1]
    # the mask's cell at the corridor's middle reads back (scale mode) as the state of that lookahead
    with Image.open(out / "zone_mask.pgm") as im:
        pixels = np.array(im)
    row = pixels.shape[0] - 1 - int((s["y0"] + s["y1"]) / 2 / 0.05)
    state = int(pixel_to_percent(pixels[row, int(LENGTH / 2 / 0.05)]))
    assert states[state]["value"] == zone and states[state]["parameter"] == "FollowPath.lookahead_dist"
    assert int(pixel_to_percent(pixels[0, 0])) == 0  # elsewhere: the nominal lookahead
    with Image.open(out / "speed_mask.pgm") as im:
        speed = pixel_to_percent(np.array(im)[row, int(LENGTH / 2 / 0.05)])
    assert speed == int(np.floor(100 * s["V_critical"] / 3.0))
    # the zone's lookahead is stable by the report, at the stretch's half-width and speed
    fixed = report_json(["--controller", "rpp", "--model", "sampled", "--L", repr(s["half_width"]), *FAST, "--param", f"lookahead_dist={zone}"])
    assert fixed["path"]["sampled"]["verdict"] == "stable"


def test_the_outputs_are_written_all_or_none(corridor, tmp_path):
    out = tmp_path / "out"
    with disk_full(1000):
        code, _, err = run(["map", str(corridor), "--controller", "rpp", *FAST, "--out-dir", str(out), "--quiet"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "could not write map outputs" in err
    assert not out.exists()


@pytest.mark.parametrize("extra, option", [(["--validate", "5"], "--validate"), (["--wobble", "0.1"], "--wobble"),
                                           (["--goals", "goals.csv"], "--goals"), (["--law", "power"], "--law"),
                                           (["--min-length", "2"], "--min-length"), (["--f", "2"], "--f")])
def test_the_vff_options_are_refused_in_one_line(corridor, extra, option):
    code, out, err = run(["map", str(corridor), "--controller", "rpp", *extra])
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and option in lines[0] and "--controller rpp" in lines[0]


def test_another_controller_is_refused_in_one_line(corridor):
    code, _, err = run(["map", str(corridor), "--controller", "graceful"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--controller graceful" in err and "rpp" in err


def test_vff_map_has_no_controller(corridor):
    code, out, err = run(["map", str(corridor), "--W", "0.4", "--format", "json", "--quiet"])
    assert code == 0, err
    data = json.loads(out)
    assert "controller" not in data and "tracking" not in data and "amplitude" in data["paths"]["stretches"][0]
