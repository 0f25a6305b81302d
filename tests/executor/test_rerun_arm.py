"""The arm in the cell's recording: every link's geometry, and link poses over sim_time
that agree with the logged tool tip (the ``part`` link frame is the tool centre point)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bridge.recording.reader import column_values, read_recording
from executor.rerun_log import AttemptLogger
from executor.trial import Cell

KUKA_LINKS = [f"lbr_iiwa_link_{k}" for k in range(1, 8)]


@pytest.mark.slow
def test_a_trial_recording_shows_the_arm_moving_with_the_tool(tmp_path: Path) -> None:
    rrd = tmp_path / "c1.rrd"
    logger = AttemptLogger.to_file(rrd, "c1")
    cell = Cell(logger=logger)
    try:
        cell.run_trial("p1", "r1", seed=3, max_attempts=1)
    finally:
        cell.close()
        logger.close()
    entities = read_recording(rrd).entities
    for link in ["base", *KUKA_LINKS]:  # each mesh logged once, with the arm at rest
        path, visual = next((p, e) for p, e in entities.items() if p.startswith(f"/executor/c1/arm/{link}/visual_"))
        assert "Asset3D:blob" in visual.components and not visual.static_rows
        assert len(column_values(rrd, path, "Asset3D:media_type")) == 1
        assert set(column_values(rrd, path, "experiment")) == {0} and set(column_values(rrd, path, "sim_time")) == {0}
    assert "Asset3D:blob" in entities["/executor/c1/scene/plate_mesh"].components
    for link in [*KUKA_LINKS, "flange", "part"]:
        assert "sim_time" in entities[f"/executor/c1/arm/{link}"].timelines

    # The arm at rest is logged with the scene, before the first attempt (experiment 0,
    # sim_time 0), its hand empty: the held part's geometry comes with the attempt.
    for link in [*KUKA_LINKS, "flange", "part"]:
        assert column_values(rrd, f"executor/c1/arm/{link}", "experiment")[:2] == [0, 1], link
    # ... all of it at one instant on log_time too: a viewer opened there shows the whole arm
    at_rest = {column_values(rrd, f"executor/c1/arm/{link}", "log_time")[0] for link in [*KUKA_LINKS, "part"]}
    at_rest |= {column_values(rrd, p, "log_time")[0] for p in entities if p.startswith("/executor/c1/arm/lbr")
                and "/visual_" in p}
    assert len(at_rest) == 1
    assert column_values(rrd, "executor/c1/arm/part", "sim_time")[0] == 0
    assert column_values(rrd, "executor/c1/arm/part/held", "experiment") == [1]
    assert "TextDocument:text" in entities["/executor/c1/arm/part/held"].components  # names the part
    # A viewer draws each archetype's latest values: the round peg's row clears a square
    # part's box and a mesh part's mesh, which would otherwise stay drawn around it.
    held = "executor/c1/arm/part/held"
    assert column_values(rrd, held, "Cylinders3D:radii") == [[pytest.approx(cell.geometry.parts["p1"].size / 2)]]
    assert column_values(rrd, held, "Boxes3D:half_sizes") == [[]] and column_values(rrd, held, "Asset3D:blob") == [[]]
    tip = np.array(column_values(rrd, "executor/c1/tool/tip", "Points3D:positions")).reshape(-1, 3)
    rest, *moving = column_values(rrd, "executor/c1/arm/part", "Transform3D:translation")
    part = np.array(moving).reshape(-1, 3)
    link_7 = np.array(column_values(rrd, "executor/c1/arm/lbr_iiwa_link_7", "Transform3D:translation"))
    assert len(part) == len(tip) > 100
    assert np.linalg.norm(np.reshape(rest, 3) - part[0]) > 0.1  # upright as loaded, not yet over the hole
    assert np.max(np.linalg.norm(part - tip, axis=1)) < 1e-3
    assert np.ptp(link_7.reshape(-1, 3)[:, 2]) > 0.01  # the wrist moves during the attempt


def test_the_hole_rims_lie_on_the_plate_around_each_hole(tmp_path: Path) -> None:
    """The tool view shows the holes by their rims (the plate would hide the tip in them)."""
    rrd = tmp_path / "c1.rrd"
    logger = AttemptLogger.to_file(rrd, "c1")
    cell = Cell(logger=logger)
    cell.close()
    logger.close()
    holes = sorted(cell.geometry.holes.items())
    (rims,) = column_values(rrd, "executor/c1/scene/hole_rims", "LineStrips3D:strips")
    assert len(rims) == len(holes) == 5
    for rim, (hid, hole) in zip(rims, holes):
        points = np.array(rim)
        assert np.allclose(points[0], points[-1]), hid  # closed
        assert np.allclose(points[:, 2], cell.geometry.plate.top_z, atol=1e-6), hid
        reach = np.linalg.norm(points[:, :2] - hole.position, axis=1)  # [m] from the hole's axis
        a, b = hole.sides
        expected = a / 2 if hole.kind == "round" else np.hypot(a, b) / 2  # the circle, or the corners
        assert reach.max() == pytest.approx(expected, abs=1e-6), hid  # stored as float32
