"""``view --screenshot``: a real headless Chromium renders every tab of a real recording.

Needs a Chromium on PATH (Debian: ``apt-get install chromium``); skipped elsewhere. One
browser run of a few minutes on a software rasteriser, so it is marked slow.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from asp.view.browser import find_chromium
from asp.view.screenshot import take_screenshots
from bridge.recording.layout import Contents, TimePoint
from bridge.recording.reader import read_recording
from executor.rerun_log import AttemptLogger, LogTarget

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(find_chromium() is None, reason="no chromium on PATH (Debian: apt-get install chromium)"),
]


@pytest.mark.timeout(900)
def test_every_tab_is_rendered_and_not_blank(tmp_path: Path) -> None:
    rrd = tmp_path / "c1.rrd"
    logger = AttemptLogger("c1", LogTarget(recording_id="shots", rrd_path=rrd))
    logger.log_scene([("plate", "box", (0.1, 0.12, 0.0375), (0.59, 0.0, 0.0375), (0, 0, 0, 1), (150, 160, 175))])
    for experiment, force in ((1, 10.0), (2, 40.0)):
        logger.begin_attempt("p1", "r1", experiment, 1, experiment=experiment)
        for k in range(300):
            phase = k / 299
            logger.log_step(0.002 * k, phase, np.array([0.55, -0.06, 0.2 - 0.1 * phase]),
                            np.array([0.0, 0.0, -force * phase]), np.array([0.0, 0.0, -9.0 * phase]),
                            np.zeros(3), np.zeros(3))
        logger.end_attempt(_Fit())
    logger.close()

    contents = Contents.of(read_recording(rrd).entities)
    pictures = take_screenshots([rrd], contents, "shots", tmp_path / "shots", at=[TimePoint("experiment", 1)])
    assert [p.name for p in pictures] == ["1-c1.png", "1-c1-experiment-1.png"]
    opened, first = (np.asarray(Image.open(p).convert("RGB"), dtype=np.float64) for p in pictures)
    assert opened.shape[:2] == first.shape[:2] == (1000, 1600)
    assert opened.std() > 10 and first.std() > 10, "a blank picture"
    assert np.abs(opened - first).mean() > 1.0, "the picture at experiment 1 is the one as opened"


class _Fit:
    outcome = "fit"
    max_force_dev = 1.0
    max_torque_dev = 0.0
    end_error = 0.0
    duration_s = 0.6
    sim_time_s = 0.6
    jammed = False
    wiggles = 0
    phase_reached = 1.0
