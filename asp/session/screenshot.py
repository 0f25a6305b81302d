"""``./run.sh view RUN --screenshot DIR``: a picture of every tab of a recording, taken in a real browser.

The recording is served to Rerun's web viewer (:func:`assembly_constraints.bridge.recording.sinks.hosted_viewer`)
and opened in a headless Chromium (:mod:`assembly_constraints.asp.session.browser`). The viewer needs tens of
seconds to load and render on a software rasteriser; a picture is taken once two in a row,
:data:`POLL_S` apart, are the same. Then, for each tab, a blueprint that shows that tab
(``rrb.Tabs(active_tab=k)``) is streamed to the viewer and the tab is pictured once it has
settled (or, after :data:`TAB_TIMEOUT_S`, as it is then, with a warning). The blueprints
follow the newest data (:func:`assembly_constraints.bridge.recording.layout.blueprint`), so every tab is
pictured at the end of the recording: the last experiment's knowledge, the whole plots. ``DIR/<k>-<tab>.png``, k from 1.
"""

from __future__ import annotations

import logging
import re
import time
from collections.abc import Sequence
from pathlib import Path

import rerun as rr

from assembly_constraints.asp import PlannerError
from assembly_constraints.asp.session.browser import Browser, find_chromium
from assembly_constraints.bridge.recording.layout import APPLICATION_ID, Contents, blueprint, tab_names
from assembly_constraints.bridge.recording.sinks import Viewer, hosted_viewer

POLL_S = 5.0
"""Time between two pictures while waiting for the page to settle [s]."""
LOAD_TIMEOUT_S = 300.0
"""Longest the web viewer may take to load the recording and settle [s]."""
TAB_TIMEOUT_S = 180.0
"""Longest a tab may take to settle once its blueprint is sent [s]."""
_LOG = logging.getLogger(__name__)


def take_screenshots(files: Sequence[Path], contents: Contents, recording_id: str, folder: Path) -> list[Path]:
    """Write one PNG per tab of ``contents``' blueprint into ``folder`` (created); PlannerError
    when there is no Chromium (:data:`assembly_constraints.asp.session.browser.NAMES`) or the page never settles."""
    chromium = find_chromium()
    if chromium is None:
        raise PlannerError("--screenshot needs a Chromium on PATH (chromium, chromium-browser or google-chrome; "
                           "Debian: apt-get install chromium)")
    folder.mkdir(parents=True, exist_ok=True)
    names = tab_names(contents)
    written: list[Path] = []
    with hosted_viewer(Viewer(serve=True), files) as served, Browser(chromium) as browser:
        assert served.page is not None and served.connect is not None
        stream = rr.RecordingStream(APPLICATION_ID, recording_id=recording_id)
        stream.set_sinks(rr.GrpcSink(served.connect))
        stream.send_blueprint(blueprint(contents))
        browser.open(served.page)
        picture = _settled(browser, LOAD_TIMEOUT_S, b"")
        if picture is None:
            raise PlannerError(f"the web viewer did not load and settle within {LOAD_TIMEOUT_S:g} s")
        for number, name in enumerate(names):
            if number:
                stream.send_blueprint(blueprint(contents, active_tab=number))
                picture = _settled(browser, TAB_TIMEOUT_S, picture)
                if picture is None:
                    _LOG.warning("tab %s did not settle within %g s; pictured as it was", name, TAB_TIMEOUT_S)
                    picture = browser.screenshot()
            path = folder / f"{number + 1}-{re.sub(r'[^A-Za-z0-9]+', '-', name).strip('-')}.png"
            path.write_bytes(picture)
            written.append(path)
        stream.disconnect()
    return written


def _settled(browser: Browser, timeout_s: float, previous: bytes) -> bytes | None:
    """A picture of the page once it differs from ``previous`` and two in a row agree;
    None if that does not happen within ``timeout_s`` [s]."""
    deadline = time.monotonic() + timeout_s
    last = b""
    while time.monotonic() < deadline:
        time.sleep(POLL_S)
        picture = browser.screenshot()
        if picture == last and picture != previous:
            return picture
        last = picture
    return None
