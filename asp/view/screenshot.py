"""``./run.sh view RUN --screenshot DIR [--at TIMELINE=VALUE]``: every tab of a recording pictured in a browser.

The recording is served to Rerun's web viewer (:func:`bridge.recording.sinks.hosted_viewer`)
and opened in a headless Chromium (:mod:`asp.view.browser`). The viewer needs tens of
seconds to load and render on a software rasteriser; the first picture is taken once two
in a row, :data:`POLL_S` apart, are the same and the viewer's state has not changed
between them (all data has arrived), later ones once two in a row are the same. Then,
for each tab, a blueprint that shows that tab (``rrb.Tabs(active_tab=k)``) is streamed to
the viewer and the tab is pictured once it has settled (or, after :data:`TAB_TIMEOUT_S`, as it is then, with a warning).

First every tab is pictured as the viewer opens the recording: paused where it placed the
cursor when the data arrived, the blueprint of ``view.rbl``
(:func:`bridge.recording.layout.blueprint`): ``DIR/<k>-<tab>.png``, k from 1.
Then, for each ``--at`` time, the viewer is paused with its cursor there and every tab is
pictured again: ``DIR/<k>-<tab>-<timeline>-<value>.png``. A blueprint cannot place the
cursor; the page's viewer handle (``window._handle``, set by the page ``rerun
--serve-web`` serves) takes the viewer-control request Rerun's ``ViewerClient.set_time``
sends to a native viewer (:func:`set_time_request`); the server of ``--serve-web`` does not
relay that request to the web viewer (it answers ``Unimplemented``), so it goes in through
the page.
"""

from __future__ import annotations

import json
import logging
import re
import time
from collections.abc import Sequence
from pathlib import Path

import rerun as rr

from asp import PlannerError
from asp.view.browser import Browser, find_chromium
from bridge.recording.layout import APPLICATION_ID, Contents, TimePoint, blueprint, tab_names
from bridge.recording.sinks import Viewer, hosted_viewer

POLL_S = 5.0
"""Time between two pictures while waiting for the page to settle [s]."""
LOAD_TIMEOUT_S = 600.0
"""Longest the web viewer may take to load the recording and settle [s] (measured on two
cores: 85 s for a Cranfield session's planner file alone; several minutes for the whole
session when other work loads the cores, one run beyond 300 s)."""
TAB_TIMEOUT_S = 180.0
"""Longest a tab may take to settle once its blueprint is sent [s]."""
PLAY_STATE_PAUSED = 1
"""``PLAY_STATE_PAUSED`` of Rerun's viewer-control protocol (rerun-sdk 0.41)."""
_LOG = logging.getLogger(__name__)


def take_screenshots(files: Sequence[Path], contents: Contents, recording_id: str, folder: Path,
                     at: Sequence[TimePoint] = ()) -> list[Path]:
    """Write one PNG per tab of ``contents``' blueprint into ``folder`` (created), as the
    viewer opens the recording and paused at each of ``at``; PlannerError when there is no Chromium
    (:data:`asp.view.browser.NAMES`), the page never settles or does not take the time."""
    chromium = find_chromium()
    if chromium is None:
        raise PlannerError("--screenshot needs a Chromium on PATH (chromium, chromium-browser or google-chrome; "
                           "Debian: apt-get install chromium)")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PlannerError(f"{folder}: cannot write ({exc.strerror})") from None
    written: list[Path] = []
    with hosted_viewer(Viewer(serve=True), files) as served, Browser(chromium) as browser:
        assert served.page is not None and served.connect is not None
        stream = rr.RecordingStream(APPLICATION_ID, recording_id=recording_id)
        stream.set_sinks(rr.GrpcSink(served.connect))
        try:  # disconnected before the server stops, else the SDK logs the broken connection
            stream.send_blueprint(blueprint(contents))
            browser.open(served.page)
            picture = _settled(browser, LOAD_TIMEOUT_S, b"", loading=True)
            if picture is None:
                raise PlannerError(f"the web viewer did not load and settle within {LOAD_TIMEOUT_S:g} s")
            picture = _picture_tabs(browser, stream, contents, folder, picture, None, written)
            for point in at:
                picture = _picture_tabs(browser, stream, contents, folder, picture, point, written)
        finally:
            stream.disconnect()
    return written


def _picture_tabs(browser: Browser, stream: rr.RecordingStream, contents: Contents, folder: Path,
                  shown: bytes, point: TimePoint | None, written: list[Path]) -> bytes:
    """Picture every tab paused, the cursor where the viewer placed it on opening (``point``
    None; ``shown`` is what the page shows now) or at ``point``; append the files to
    ``written``; the last picture."""
    picture = shown
    for number, name in enumerate(tab_names(contents)):
        stream.send_blueprint(blueprint(contents, number, timeline=None if point is None else point.timeline))
        # the first tab as opened may look as it did under the recording's own blueprint
        before = b"" if number == 0 and point is None else picture
        picture = _settled(browser, TAB_TIMEOUT_S, before) or _unsettled(browser, name)
        if point is not None:  # once the blueprint is shown: it sets the time panel when it arrives
            _move_cursor(browser, point)
            picture = _settled(browser, TAB_TIMEOUT_S, b"") or _unsettled(browser, name)
        suffix = "" if point is None else f"-{point}"
        path = folder / f"{number + 1}-{re.sub(r'[^A-Za-z0-9.]+', '-', name + suffix).strip('-')}.png"
        path.write_bytes(picture)
        written.append(path)
    return picture


def _unsettled(browser: Browser, tab: str) -> bytes:
    """A picture of ``tab`` as it is, with a warning that it did not settle."""
    _LOG.warning("tab %s did not settle within %g s; pictured as it was", tab, TAB_TIMEOUT_S)
    return browser.screenshot()


def _move_cursor(browser: Browser, point: TimePoint) -> None:
    """Pause the web viewer with its cursor at ``point`` (:func:`set_time_request`)."""
    handle = "window._handle"
    if not browser.evaluate(f"typeof {handle}?.viewer_control === 'function'"):
        raise PlannerError(f"the web viewer page has no {handle}.viewer_control; cannot set the time {point}")
    request = json.dumps(list(set_time_request(point)))
    browser.evaluate(f"{handle}.viewer_control(Uint8Array.from({request})).then(() => true)", await_promise=True)


def set_time_request(point: TimePoint) -> bytes:
    """The viewer-control request (protobuf ``ViewerControlRequest``) that pauses the viewer
    with its cursor at ``point``: field 6 ``set_time_cursor`` {2 timeline {1 name}, 3 time
    {1 value}, 5 play state}, as ``rerun.experimental.ViewerClient.set_time`` encodes it."""
    timeline = _bytes_field(1, point.timeline.encode())
    cursor = _bytes_field(2, timeline) + _bytes_field(3, _int_field(1, point.viewer_time))
    return _bytes_field(6, cursor + _int_field(5, PLAY_STATE_PAUSED))


def _varint(value: int) -> bytes:
    """``value`` as a protobuf varint (negative numbers as 64-bit two's complement)."""
    value &= (1 << 64) - 1
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def _int_field(number: int, value: int) -> bytes:
    return _varint(number << 3) + _varint(value)


def _bytes_field(number: int, value: bytes) -> bytes:
    return _varint(number << 3 | 2) + _varint(len(value)) + value


def _settled(browser: Browser, timeout_s: float, previous: bytes, loading: bool = False) -> bytes | None:
    """A picture of the page once it differs from ``previous`` and two in a row agree
    (``previous`` empty: once two agree); ``loading``: and so do two reports of the
    viewer's state between them (``window._handle.viewer_state()``: its recordings, their
    timelines' ranges, the views; it changes while data still arrives, which a picture need
    not show when the data lands in another tab, and a recording's own blueprint arriving
    late would replace the one sent). None if that does not happen within ``timeout_s`` [s]."""
    deadline = time.monotonic() + timeout_s
    last: tuple[bytes, list[int]] = (b"", [])
    while time.monotonic() < deadline:
        time.sleep(POLL_S)
        state = browser.evaluate("Array.from(window._handle?.viewer_state?.() ?? [])") if loading else [0]
        now = (browser.screenshot(), state)
        if now == last and now[1] and now[0] != previous:
            return now[0]
        last = now
    return None
