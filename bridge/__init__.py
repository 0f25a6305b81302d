"""Zenoh messaging shared by the planner and the cells (DESIGN.md, Bridge).

- :mod:`bridge.keys`: every key expression (``cell/<id>/insert``, ``cell/<id>/alive``);
- :mod:`bridge.messages`: typed, versioned JSON messages, validated on receipt;
- :mod:`bridge.session`: opening Zenoh sessions (peer mode on loopback by default);
- :mod:`bridge.client`: requests with id, timeout and failover; cell discovery.
"""


class BridgeError(Exception):
    """Base error of the bridge: a bad message, a bad endpoint or config, a lost cell.

    The message names the bad value and what was expected.
    """
