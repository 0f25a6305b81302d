"""The command line of ``./run.sh executor serve``: its options, the
:class:`bridge.cell_settings.ServeSettings` they build (or the
``--settings`` document), then :func:`executor.serve.node.serve`."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from bridge import BridgeError
from bridge.cell_settings import (
    ServeSettings,
    add_assembly_uncertainty_argument,
    add_cell_arguments,
    cell_settings_of,
    decode_settings,
)
from bridge.cli_types import (
    ArgumentParser,
    add_assembly_argument,
    backend_option,
    finite_float,
    nonempty_path,
    path_setting,
)
from bridge.inputs import read_bytes
from bridge.recording.sinks import add_viewer_arguments
from bridge.session import DEFAULT_ENDPOINT, add_endpoint_arguments
from executor.serve.node import serve

SETTINGS_HELP = ("the cell's settings as one document: a JSON object (ServeSettings, docs/cell.md), or a file "
                 "holding one; instead of the other options (a session starts its cells so)")


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(
        prog="executor serve", description="Serve insertion experiments over Zenoh "
        f"(default: listen on {DEFAULT_ENDPOINT}).")
    parser.add_argument("--settings", metavar="JSON|FILE", help=SETTINGS_HELP)
    parser.add_argument("--cell", default="c1", help="cell id (default c1)")
    parser.add_argument("--backend", default="sim", metavar="{sim,truth,franka,MODULE:CLASS}",
                        help="sim: PyBullet cell; truth: answer from the geometry, no simulation; franka: a Franka "
                             "arm through franky (docs/franka.md); MODULE:CLASS: your class driving a real cell "
                             "(docs/backends.md) (default sim)")
    parser.add_argument("--backend-option", type=backend_option, action="append", default=[], metavar="KEY=VALUE",
                        help="an option for the franka or a MODULE:CLASS backend, e.g. host=172.16.0.2 "
                             "(repeatable)")
    add_assembly_argument(parser)
    parser.add_argument("--delay", type=finite_float(0, 3600), default=0.0, metavar="S",
                        help="truth backend: seconds each experiment takes (default 0)")
    parser.add_argument("--rrd", type=nonempty_path, help="save this cell's Rerun recording to FILE")
    parser.add_argument("--recording-id", help="Rerun recording id shared with the planner")
    add_viewer_arguments(parser, serve=False)  # a cell serves for as long as it runs: stream to a viewer
    parser.add_argument("--block-hole", action="append", default=[], metavar="H",
                        help="put an obstacle in hole H for plan steps (a fault injection; repeatable)")
    parser.add_argument("--lifeline", action="store_true",
                        help="exit when standard input closes (set by a supervising session)")
    parser.add_argument("--ilc-state", type=nonempty_path, metavar="FILE",
                        help="sim backend: load the cell's ILC corrections from FILE (if it exists) and "
                        "save them there after every update (a session passes <run>/<cell>-ilc.json)")
    add_cell_arguments(parser)
    add_assembly_uncertainty_argument(parser)
    add_endpoint_arguments(parser)
    return parser


def serve_settings_of(args: argparse.Namespace) -> ServeSettings:
    """The settings the options give: the ``--settings`` document, or the other options
    (the same struct); BridgeError when both are given or the document is not one."""
    settings = ServeSettings(
        cell_id=args.cell, backend=args.backend, backend_options=dict(args.backend_option), assembly=args.assembly,
        delay_s=args.delay, rrd=path_setting(args.rrd), recording_id=args.recording_id, viewer_url=args.rerun_connect,
        ilc_state=path_setting(args.ilc_state), block_holes=tuple(args.block_hole), lifeline=args.lifeline,
        listen=tuple(args.listen), connect=tuple(args.connect), zenoh_config=path_setting(args.zenoh_config),
        cell=cell_settings_of(args))
    if args.settings is None:
        return settings
    if settings != ServeSettings():
        raise BridgeError("--settings: expected the cell's settings either as one document or as options, not both")
    document = args.settings
    if document.lstrip().startswith("{"):
        return decode_settings(document, ServeSettings, "--settings")
    return decode_settings(read_bytes(document, "cell settings file (JSON)"), ServeSettings, document)



def main(argv: Sequence[str]) -> int:
    """``executor serve``: the settings of the options, then :func:`serve`."""
    return serve(serve_settings_of(build_parser().parse_args(list(argv))))

