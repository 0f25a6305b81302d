"""What the planner and the cells share: Zenoh messaging, the assembly folder, the Rerun layout.

- :mod:`assembly_constraints.bridge.keys`: every key expression (``cell/<id>/insert``, ``cell/<id>/alive/<instance>``);
- :mod:`assembly_constraints.bridge.messages`: typed, versioned JSON messages, validated on receipt;
- :mod:`assembly_constraints.bridge.session`: opening Zenoh sessions (peer mode on loopback by default);
- :mod:`assembly_constraints.bridge.client`: requests with id, timeout and failover; cell discovery;
- :mod:`assembly_constraints.bridge.assembly`: the assembly folder (``assembly.toml``) and its loader;
- :mod:`assembly_constraints.bridge.recording.layout`: the Rerun application id, entity roots and blueprint;
- :mod:`assembly_constraints.bridge.recording.reader`: reading ``.rrd`` recordings back;
- :mod:`assembly_constraints.bridge.cli_types`: argument types both command lines use;
- :mod:`assembly_constraints.bridge.files`: writing output files atomically, checking output paths;
- :mod:`assembly_constraints.bridge.protocol_schema`: the JSON Schemas of the messages, as published in ``docs/protocol/``.

Nothing here imports the planner (``asp``) or the cell (``executor``).
"""


from assembly_constraints.bridge.errors import ToolError


class BridgeError(ToolError):
    """Base error of the bridge: a bad message, a bad endpoint or config, a lost cell.

    The message names the bad value and what was expected.
    """
