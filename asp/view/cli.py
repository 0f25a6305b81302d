"""``./run.sh view RUN [--print] [--json] [--web] [--screenshot DIR]``: open a run's Rerun recording.

RUN is a run folder (``runs/<id>``, its ``*.rrd`` files are opened together: planner
and cells log into one recording id) or a single ``.rrd`` file. With a display, the
Rerun viewer shipped in the venv (``rerun`` next to the Python executable) is started
on the files plus ``RUN/view.rbl``, the blueprint of what the recording holds
(``bridge.recording.layout.Contents.of``): the planner's tab when it has ``planner/...``
entities, one tab per cell that logged more than an assembly (its Fig. 17 view on its first
fitting attempt), one assembly tab per cell that assembled. Without a display (no ``DISPLAY`` /
``WAYLAND_DISPLAY``) or with ``--print`` it prints what the recording holds: ids and
one line per entity path with its row count, timelines and components (``--json``: the
same as JSON). ``--web`` serves the files to a web browser instead (Rerun's web viewer on
free loopback ports; the address is logged; Ctrl-C stops). ``--screenshot DIR`` writes a
picture of every tab, rendered by the web viewer in a headless Chromium
(:mod:`asp.view.screenshot`), as the viewer opens the recording and, for each ``--at
TIMELINE=VALUE`` (``experiment=1``), paused at that time. A RUN without ``.rrd`` files is
an error (exit code 2).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from asp import PlannerError
from bridge.cli_types import ArgumentParser, nonempty_path

if TYPE_CHECKING:
    from bridge.recording.layout import TimePoint


def recording_files(run: Path) -> list[Path]:
    """The ``.rrd`` files of RUN (a folder or one file); PlannerError if there are none."""
    if run.suffix == ".rrd" and run.exists() and not run.is_dir():
        return [run]  # the reader refuses a FIFO or device, naming what it is
    if not run.exists():
        raise PlannerError(f"{run}: no such run folder or .rrd file")
    files = sorted(run.glob("*.rrd")) if run.is_dir() else []
    if not files:
        raise PlannerError(f"{run}: holds no Rerun recording; expected RUN/*.rrd or an .rrd file")
    return files


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def rerun_executable() -> str:
    """The ``rerun`` CLI of this environment (the wheel installs it beside python)."""
    beside = Path(sys.executable).parent / "rerun"
    found = str(beside) if beside.is_file() else shutil.which("rerun")
    if found is None:
        raise PlannerError("no 'rerun' executable beside python or on PATH; install rerun-sdk")
    return found


def _time_point(text: str) -> TimePoint:
    """``--at``'s value as a :class:`bridge.recording.layout.TimePoint`."""
    from bridge.recording.layout import TimePoint

    try:
        return TimePoint.parse(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def main(argv: Sequence[str]) -> int:
    parser = ArgumentParser(prog="view", description=__doc__.split("\n\n")[0])
    parser.add_argument("run", metavar="RUN", help="run folder (RUN/*.rrd) or an .rrd file")
    parser.add_argument("--print", action="store_true", help="print the contents, no viewer")
    parser.add_argument("--json", action="store_true", help="print the contents as JSON")
    parser.add_argument("--screenshot", type=nonempty_path, metavar="DIR",
                        help="render every tab in a headless Chromium (Rerun's web viewer), write DIR/<k>-<tab>.png; "
                             "needs chromium on PATH, takes a few minutes")
    parser.add_argument("--at", type=_time_point, action="append", default=[], metavar="TIMELINE=VALUE",
                        help="with --screenshot: also picture every tab paused at this time (experiment=1, "
                             "sim_time=2.5 [s]); repeatable")
    parser.add_argument("--web", action="store_true",
                        help="serve the recording to a web browser (for headless machines); the address to open "
                             "is printed, Ctrl-C stops")
    args = parser.parse_args(list(argv))

    from bridge.recording.layout import Contents, write_blueprint
    from bridge.recording.reader import format_summary, read_recording

    run = Path(args.run)
    files = recording_files(run)
    summary = read_recording(files)
    contents = Contents.of(summary.entities)
    if args.at and not args.screenshot:
        parser.error("--at: only with --screenshot DIR")
    timelines = set().union(*(entity.timelines for entity in summary.entities.values()))
    for point in args.at:
        if point.timeline not in timelines:
            raise PlannerError(f"--at {point}: {run} has no timeline {point.timeline!r}; "
                               f"it has {', '.join(sorted(timelines)) or 'none'}")
    if args.screenshot:
        from asp.view.screenshot import take_screenshots

        recording_id = min(summary.recording_ids, default="view")
        for picture in take_screenshots(files, contents, recording_id, args.screenshot, args.at):
            print(picture)
        return 0
    if args.print or args.json or not (has_display() or args.web):
        if not (args.print or args.json):
            print("view: no display (DISPLAY/WAYLAND_DISPLAY unset); printing the recording",
                  file=sys.stderr)
        print(json.dumps(summary.to_json(), indent=2) if args.json else format_summary(summary))
        return 0
    blueprint = write_blueprint(run if run.is_dir() else run.parent, contents)
    if args.web:
        from bridge.recording.sinks import Viewer, hosted_viewer, keep_serving

        served = Viewer(serve=True)
        try:  # Ctrl-C is how the user ends it: also while the server still loads the files
            with hosted_viewer(served, [*files, blueprint]):
                keep_serving(served)
        except KeyboardInterrupt:
            pass
        return 0
    subprocess.Popen(
        [rerun_executable(), *map(str, files), str(blueprint)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )
    print(f"view: opened {len(files)} recording file(s) in the Rerun viewer")
    return 0
