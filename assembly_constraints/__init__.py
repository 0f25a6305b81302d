"""Learning assembly constraints by demonstration and active exploration, as installed.

- :mod:`assembly_constraints.cli`: the one command line, ``assembly-constraints``;
- :mod:`assembly_constraints.api`: the Python API (learn precedence, learn sizes with an
  oracle, plan, run a session, read a run folder), documented in ``docs/api.md``.

The work itself is done by the planner (:mod:`asp`), the cell (:mod:`executor`) and what
they share (:mod:`bridge`), the repository's folders ``asp/``, ``executor/`` and ``bridge/``,
installed beside this package under those names; this package is the front that puts them
together.
"""

__version__ = "0.1.0"
