"""What the planner and the cells share: Zenoh messaging, the assembly folder, the Rerun layout.

- :mod:`bridge.keys`: every key expression (``cell/<id>/insert``, ``cell/<id>/alive/<instance>``);
- :mod:`bridge.messages`: typed, versioned JSON messages, validated on receipt;
- :mod:`bridge.session`: opening Zenoh sessions (peer mode on loopback by default);
- :mod:`bridge.client`: requests with id, timeout and failover; cell discovery;
- :mod:`bridge.assembly`: the assembly folder (``assembly.toml``) and its loader;
- :mod:`bridge.recording.layout`: the Rerun application id, entity roots and blueprint;
- :mod:`bridge.recording.reader`: reading ``.rrd`` recordings back;
- :mod:`bridge.cli_types`: argument types both command lines use;
- :mod:`bridge.files`: writing output files atomically, checking output paths;
- :mod:`bridge.precedence.experiment`: the precedence experiment a cell runs and its outcome;
- :mod:`bridge.protocol_schema`: the JSON Schemas of the messages, as published in
  ``docs/protocol/``.

Nothing here imports the planner (``asp``) or the cell (``executor``).
"""


from bridge.errors import ToolError


class BridgeError(ToolError):
    """Base error of the bridge: a bad message, a bad endpoint or config, a lost cell.

    The message names the bad value and what was expected.
    """
