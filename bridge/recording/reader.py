"""Reading Rerun recordings (``.rrd``) back: which entities they hold, and values.

Rerun 0.41 dropped ``rr.dataframe``; this module uses the SDK's own chunk reader
(``rerun.chunk.RrdReader``, in process, no extra dependency) instead of parsing the
output of ``rerun rrd print``. Used by the tests and by ``./run.sh view RUN --print``.
A file with a torn tail (its writer died mid-message) is read up to its last whole
message, with a warning (:mod:`bridge.recording.torn`).

Entity paths are reported as Rerun prints them, with a leading ``/``
(``/executor/c1/outcome``); Rerun's own ``/__properties`` entities are left out.
"""

from __future__ import annotations

import stat
import warnings
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyarrow as pa
from rerun.chunk import Chunk, RrdReader

from bridge import BridgeError
from bridge.inputs import file_kind, shorten
from bridge.recording.torn import readable


@dataclass
class EntitySummary:
    """One entity: logged rows (``static_rows`` of them static), components, timelines."""

    path: str
    rows: int = 0
    static_rows: int = 0
    components: set[str] = field(default_factory=set)
    timelines: set[str] = field(default_factory=set)


@dataclass
class RecordingSummary:
    """What one or more ``.rrd`` files hold."""

    files: list[Path]
    application_ids: set[str] = field(default_factory=set)
    recording_ids: set[str] = field(default_factory=set)
    blueprints: int = 0
    entities: dict[str, EntitySummary] = field(default_factory=dict)

    def under(self, prefix: str) -> dict[str, EntitySummary]:
        """Entities at or below ``prefix`` (e.g. ``/executor/c1``)."""
        prefix = "/" + prefix.strip("/")
        return {
            path: entity for path, entity in self.entities.items()
            if path == prefix or path.startswith(prefix + "/")
        }

    def to_json(self) -> dict[str, Any]:
        """``{"files", "application_ids", "recording_ids", "blueprints", "entities":
        {path: {"rows", "static_rows", "components", "timelines"}}}``."""
        return {
            "files": [str(f) for f in self.files],
            "application_ids": sorted(self.application_ids),
            "recording_ids": sorted(self.recording_ids),
            "blueprints": self.blueprints,
            "entities": {
                path: {
                    "rows": e.rows, "static_rows": e.static_rows,
                    "components": sorted(e.components), "timelines": sorted(e.timelines),
                }
                for path, e in sorted(self.entities.items())
            },
        }


_CONTROL_COLUMN_PREFIX = "rerun.controls."
_VIEW_ORIGIN = "ViewBlueprint:space_origin"
_TABS_KIND = 1  # ContainerBlueprint:container_kind of rrb.Tabs
_VISUALIZER_TYPE = "VisualizerInstruction:visualizer_type"  # its overrides name their archetype anyway


@contextmanager
def _open(path: Path) -> Iterator[RrdReader]:
    """A reader of one ``.rrd`` file (of its whole messages when its tail is torn, with a
    warning: :mod:`bridge.recording.torn`); BridgeError naming the file when it is
    missing, unreadable or not a Rerun recording (empty, garbage, another format)."""
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise BridgeError(f"{path}: no such recording file (expected an .rrd file)") from None
    except OSError as exc:
        raise BridgeError(f"{path}: cannot read the recording: {exc.strerror or exc}") from None
    if not stat.S_ISREG(mode):
        raise BridgeError(f"{path}: not a regular file ({file_kind(mode)}); expected an .rrd file")
    try:
        with path.open("rb") as file:
            file.read(1)
    except OSError as exc:
        raise BridgeError(f"{path}: cannot read the recording: {exc.strerror or exc}") from None
    with readable(path) as source:
        try:
            with _tolerating_unfinished_files():
                reader = RrdReader(source)
        except (RuntimeError, ValueError) as exc:
            raise BridgeError(f"{path}: not a Rerun recording ({shorten(exc, 120)}); expected an .rrd file") from None
        yield reader


@contextmanager
def _tolerating_unfinished_files() -> Iterator[None]:
    """A file still being written (or from a killed process) has no footer yet; the
    reader warns and falls back to a whole-file scan, which is what we want."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*no footer.*")
        yield


def _chunks(reader: RrdReader) -> Iterator[Chunk]:
    """Every chunk of every recording store of the file (blueprints excluded)."""
    with _tolerating_unfinished_files():
        for store in reader.recordings():
            yield from reader.stream(store=store)


def chunk_count(path: Path | str) -> int:
    """How many chunks the recording stores of ``path`` hold (blueprints excluded): what
    compaction (:mod:`bridge.recording.compaction`) brings down."""
    with _open(Path(path)) as reader:
        return sum(1 for _ in _chunks(reader))


def read_recording(paths: Path | str | Sequence[Path | str]) -> RecordingSummary:
    """Summarise ``.rrd`` files: entity paths with row counts, components, timelines."""
    files = [Path(paths)] if isinstance(paths, (str, Path)) else [Path(p) for p in paths]
    summary = RecordingSummary(files=files)
    for path in files:
        try:
            with _open(path) as reader:
                _summarise(reader, summary)
        except RuntimeError as exc:  # damaged inside (a torn tail is read up to its last whole message)
            raise BridgeError(f"{path}: not a readable Rerun recording ({shorten(exc, 120)})") from None
    return summary


def _summarise(reader: RrdReader, summary: RecordingSummary) -> None:
    """Add what one ``.rrd`` file holds to ``summary``."""
    with _tolerating_unfinished_files():
        for store in reader.recordings():
            summary.application_ids.add(store.application_id)
            summary.recording_ids.add(store.recording_id)
        summary.blueprints += len(reader.blueprints())
    for chunk in _chunks(reader):
        if chunk.entity_path.startswith("/__"):
            continue
        entity = summary.entities.setdefault(chunk.entity_path, EntitySummary(chunk.entity_path))
        entity.rows += chunk.num_rows
        entity.static_rows += chunk.num_rows if chunk.is_static else 0
        entity.timelines.update(chunk.timeline_names)
        names = chunk.to_record_batch().schema.names
        entity.components.update(
            n for n in names
            if ":" in n and not n.startswith(_CONTROL_COLUMN_PREFIX)
        )


def column_values(
    paths: Path | str | Iterable[Path | str], entity: str, column: str
) -> list[Any]:
    """Every row's value of ``column`` of ``entity`` (e.g. ``/executor/c1/outcome``), in
    file order. ``column`` is a component (``"TextLog:text"``, ``"Scalars:scalars"``) or
    a timeline (``"sim_time"`` → float [s], ``"experiment"`` → int, ``"log_time"`` →
    int [ns since the epoch]).

    A component row holds its batch: ``["fit ..."]`` for a text log line, ``[1.0]`` for
    one scalar, ``[fx, fy, fz]`` for three plotted series. Rows of chunks lacking the
    column (e.g. static style rows) are skipped.
    """
    files = [paths] if isinstance(paths, (str, Path)) else list(paths)
    wanted = "/" + entity.strip("/")
    values: list[Any] = []
    for path in files:
        with _open(Path(path)) as reader:
            for chunk in _chunks(reader):
                if chunk.entity_path != wanted:
                    continue
                batch = chunk.to_record_batch()
                if column in batch.schema.names:
                    values.extend(_python_values(batch.column(column)))
    return values


@dataclass
class ViewSummary:
    """One view of a blueprint: its class (``Spatial3DView``, ``TimeSeriesView``, ...),
    display name, origin (without the leading ``/``), contents queries, the view's
    properties by archetype (``{"EyeControls3D": {"position": [...], ...}}``) and its
    per-entity overrides by entity path (``{"executor/c1/tool/tip": {"VisibleTimeRanges:ranges": [...]}}``;
    a visualizer's component overrides under their archetype's name, ``"Cylinders3D:colors"``)."""

    kind: str = ""
    name: str = ""
    origin: str = ""
    contents: list[str] = field(default_factory=list)
    properties: dict[str, dict[str, Any]] = field(default_factory=dict)
    overrides: dict[str, dict[str, Any]] = field(default_factory=dict)


@dataclass
class BlueprintSummary:
    """The views of a blueprint, the names of its tabs in order and the time panel's fields
    (``{"timeline": "sim_time", "play_state": 3}``; play state 1 paused, 2 playing, 3 following)."""

    views: list[ViewSummary] = field(default_factory=list)
    tabs: list[str] = field(default_factory=list)
    time_panel: dict[str, Any] = field(default_factory=dict)


def read_blueprint(path: Path | str) -> BlueprintSummary:
    """The last blueprint of an ``.rrd`` / ``.rbl`` file (the one the viewer shows)."""
    summary = BlueprintSummary()
    with _open(Path(path)) as reader, _tolerating_unfinished_files():
        stores = reader.blueprints()
        chunks = list(reader.stream(store=stores[-1])) if stores else []
    views: dict[str, ViewSummary] = {}
    containers: dict[str, dict[str, Any]] = {}
    for chunk in chunks:
        batch = chunk.to_record_batch()
        row = {name: column.to_pylist()[-1] for name, column in zip(batch.schema.names, batch.columns) if ":" in name}
        parts = chunk.entity_path.strip("/").split("/")
        if parts[0] == "time_panel":
            summary.time_panel.update({n.split(":")[1]: _single(v) for n, v in row.items()})
        elif parts[0] == "container":
            containers["/".join(parts)] = {n.split(":")[1]: v if n.endswith(":contents") else _single(v)
                                           for n, v in row.items()}
        elif parts[0] == "view" and len(parts) >= 2:
            view = views.setdefault(parts[1], ViewSummary())
            if len(parts) == 2:
                view.kind = _single(row.get("ViewBlueprint:class_identifier"))
                view.name = _single(row.get("ViewBlueprint:display_name"))
                view.origin = str(_single(row.get(_VIEW_ORIGIN)) or "").strip("/")
            elif parts[2:4] == ["ViewContents", "overrides"]:
                # .../overrides/<entity>/visualizers[/<instruction id>]: one entity's overrides
                end = parts.index("visualizers", 4) if "visualizers" in parts[4:] else len(parts)
                view.overrides.setdefault("/".join(parts[4:end]), {}).update(
                    {n: _single(v) for n, v in row.items() if n != _VISUALIZER_TYPE})
            elif parts[2] == "ViewContents":
                view.contents = list(row.get("ViewContents:query") or [])
            else:
                view.properties[parts[2]] = {n.split(":")[1]: _single(v) for n, v in row.items()}
    summary.views = list(views.values())
    tabs = next((c for c in containers.values() if c.get("container_kind") == _TABS_KIND), {})
    summary.tabs = [containers.get(child, {}).get("display_name", child) for child in tabs.get("contents") or []]
    return summary


def _single(value: Any) -> Any:
    """A component row's one value (rows hold batches)."""
    return value[0] if isinstance(value, list) and len(value) == 1 else value


def blueprint_origins(path: Path | str) -> set[str]:
    """Origins of the views in the last blueprint of an ``.rrd`` / ``.rbl`` file
    (e.g. ``{"executor/c1", "executor/c1/wrench/force", ...}``)."""
    return {view.origin for view in read_blueprint(path).views}


def _python_values(array: pa.Array) -> list[Any]:
    """Arrow values as Python; durations as float seconds, timestamps as int ns
    (Python's datetime types cannot hold nanoseconds)."""
    if pa.types.is_duration(array.type):
        return [None if v is None else v / 1e9 for v in array.cast(pa.int64()).to_pylist()]
    if pa.types.is_timestamp(array.type):
        return array.cast(pa.int64()).to_pylist()
    return array.to_pylist()


def format_summary(summary: RecordingSummary) -> str:
    """Human-readable listing: ids, then one line per entity (rows, components)."""
    lines = [
        f"files: {', '.join(str(f) for f in summary.files)}",
        f"application ids: {', '.join(sorted(summary.application_ids)) or '-'}; "
        f"recording ids: {', '.join(sorted(summary.recording_ids)) or '-'}; "
        f"blueprints: {summary.blueprints}",
        f"{len(summary.entities)} entity paths:",
    ]
    width = max((len(p) for p in summary.entities), default=0)
    for path, entity in sorted(summary.entities.items()):
        kind = ", ".join([*sorted(entity.timelines), *(["static"] if entity.static_rows else [])])
        lines.append(
            f"  {path:<{width}}  {entity.rows:>7} rows  [{kind}]  {', '.join(sorted(entity.components))}"
        )
    return "\n".join(lines)
