"""``./run.sh executor serve``: a cell node serving insertion experiments over Zenoh.

The node declares the queryable ``cell/<id>/insert`` and the liveliness token
``cell/<id>/alive/<instance>`` (and ``cell/<id>/ping``, which echoes its payload unread), then
serves until SIGTERM/SIGINT (or, with ``--lifeline``, until its stdin closes: the
supervising session died), then closes the Zenoh session cleanly. Before it declares
anything else it claims its cell id (:mod:`assembly_constraints.executor.claim`): when another process already
serves that id it exits with code 2 instead, and it stops the same way if it meets such a
process later.

- Every request is size-capped and validated (:mod:`assembly_constraints.bridge.messages`) in the Zenoh
  thread; a malformed, oversized or wrong-version request gets an ErrorReply at once and
  the cell keeps serving.
- Valid requests run one at a time in the main thread. Results are idempotent by
  request id: a repeated id gets the cached reply and never re-runs the experiment.
- Backends: ``sim`` runs the PyBullet :class:`assembly_constraints.executor.trial.Cell` (imported lazily)
  with the execution layer and uncertainty of its cell settings (``--layer``,
  ``--cell-seed``, ``--grasp-tilt-bias`` ...) and its ILC state in ``--ilc-state``;
  ``truth`` answers from the cell's geometry (cross-sections), or where the product has no
  ``geometry.toml`` from its ``sizes.lp``, without simulation, optionally
  after ``--delay`` seconds, to measure the bridge and test the protocol quickly;
  ``MODULE:CLASS`` loads a user's backend (:mod:`assembly_constraints.executor.backend_plugin`), e.g. a real robot.
- Plan steps (``cell/<id>/step``, :class:`assembly_constraints.bridge.messages.StepRequest`) run in the same
  queue: ``sim`` in the assembling world of :mod:`assembly_constraints.executor.assembly` (kept between the
  steps of one plan run), ``truth`` from the geometry; ``--block-hole H`` puts an obstacle
  in hole H (a fault to show the planner's recovery); ``--uncertainty cell`` gives the
  plan steps the cell's uncertainty, layer and ILC (default ``random``: their own errors).

Its settings are one :class:`assembly_constraints.bridge.cell_settings.ServeSettings`: ``--settings JSON|FILE``
(how a session starts its cells) or the options, which build the same struct; the
node takes only the struct (:func:`serve`).

The modules: :mod:`.cli` the command line (options to settings), :mod:`.node` the node
(requests, queue, idempotency, claim, signals), :mod:`.backends` the backend the settings
name and the checks made before the session opens, :mod:`.sim` and :mod:`.truth` the two
built-in backends.

One line per event is printed to stdout (``ready``, ``start <id> <part> <hole>``,
``done <id> <result>``), flushed, so a supervisor can follow the node.
"""

from assembly_constraints.executor.backend_plugin import Backend, UnknownPair
from assembly_constraints.executor.serve.cli import build_parser, main, serve_settings_of
from assembly_constraints.executor.serve.node import serve

__all__ = ["Backend", "UnknownPair", "build_parser", "main", "serve", "serve_settings_of"]
