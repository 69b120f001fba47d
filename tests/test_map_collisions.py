"""Where the validation's drives collided, beside the map's prediction (`validation.map_collisions`, docs/maps.md,
"Where the drives collided")."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from pfm_stability.maps.deciding.decide import CAUSES, PATH_VERDICTS
from pfm_stability.validation.map_collisions import locate_collisions


def _verdicts():
    """Two straight routes along y = 0 (x 0–10 m, samples every 0.1 m) and y = 5: route 0 stable but for a collision
    course on x in [2, 3] and a forced weave on [6, 7]; route 1 stable."""
    x = np.tile((np.arange(100) + 0.5) * 0.1, 2)
    y = np.repeat([0.0, 5.0], 100)
    route = np.repeat([0, 1], 100)
    code = np.full(200, PATH_VERDICTS.index("stable"))
    cause = np.full(200, -1)
    course = (route == 0) & (x >= 2) & (x <= 3)
    weave = (route == 0) & (x >= 6) & (x <= 7)
    code[course | weave] = PATH_VERDICTS.index("unstable")
    cause[course], cause[weave] = CAUSES.index("collision course"), CAUSES.index("forced weave")
    return SimpleNamespace(samples=SimpleNamespace(x=x, y=y, segment=route), code=code, cause=cause)


def test_each_collision_is_set_beside_the_nearest_prediction():
    """Collisions by hand: 0.3 m off a collision course (foreseen), 0.45 m past its end (foreseen: within 0.5 m of
    its last sample), beside the weave (near a weave), on a stable stretch, on route 1, and 2 m from every route (off
    the routes); each with its nearest route, distance, verdict and cause; the counts are those."""
    contacts = [(0, 2.55, 0.3), (1, 3.45, 0.0), (2, 6.5, -0.2), (3, 8.5, 0.1), (4, 4.05, 5.2), (5, 4.0, 2.5)]  # samples at x = 0.05 + 0.1 k
    summary = locate_collisions(_verdicts(), contacts, 0.5)
    by_drive = {c.drive: c for c in summary.collisions}
    assert by_drive[0].foreseen and by_drive[0].cause == "collision course" and by_drive[0].distance == pytest.approx(0.3, abs=1e-9)
    assert by_drive[1].foreseen and by_drive[1].verdict == "stable"  # nearest sample past the course, the course within reach
    assert by_drive[2].near_weave and not by_drive[2].foreseen and by_drive[2].cause == "forced weave"
    assert by_drive[3].verdict == "stable" and not (by_drive[3].foreseen or by_drive[3].near_weave)
    assert by_drive[4].route == 1 and by_drive[4].distance == pytest.approx(0.2, abs=1e-9)
    assert by_drive[5].route is None and by_drive[5].verdict is None
    assert (summary.foreseen, summary.near_weave, summary.elsewhere, summary.off_routes) == (2, 1, 2, 1)
    data = summary.to_dict()
    assert data["count"] == 6 and len(data["collisions"]) == 6 and data["match_distance"] == 0.5


def test_no_collision_is_an_empty_summary():
    summary = locate_collisions(_verdicts(), [], 0.5)
    assert summary.collisions == () and summary.to_dict()["count"] == 0


def test_the_validation_locates_every_drive_that_collided(tmp_path):
    """The validation by driving (`drive_map`, tb3_sandbox with the small robot: most drives collide): every drive
    whose event is a collision has its contact point and no other drive has one, the collisions located are exactly
    those drives, and each contact is where the disc touched: its centre within W/2 plus a cell's diagonal of an
    occupied cell of the map's histogram grid (the simulator's grid is the same cells, `validation.maps.simulator_grid`;
    the diagonal allows for its own cell geometry)."""
    import math

    from pfm_stability.cli.map import map_path
    from pfm_stability.laws.fields import make_law
    from pfm_stability.maps.analysis import analyze_map
    from pfm_stability.maps.reading.contact import obstacle_distance
    from pfm_stability.maps.reading.occupancy import load_map
    from pfm_stability.parameters import CARMEL
    from pfm_stability.validation.map_drives import drive_map

    robot, controller = CARMEL.robot.replace(W=0.3, V=0.5), CARMEL.controller
    analysis = analyze_map(load_map(map_path("tb3_sandbox")), robot, controller, make_law("grid", robot, controller), corridors=False)
    validation = drive_map(analysis, 6, seed=0)
    collided = [d for d in validation.drives if d.event == "collision"]
    assert collided and all(d.contact is not None for d in collided)
    assert all(d.contact is None for d in validation.drives if d.event != "collision")
    assert sorted(c.drive for c in validation.collisions.collisions) == sorted(d.index for d in collided)
    px, py = np.array([d.contact for d in collided]).T
    gap = obstacle_distance(analysis.grid, px, py, robot.W)
    assert (gap <= robot.W / 2 + analysis.grid.cell_size * math.sqrt(2)).all()
