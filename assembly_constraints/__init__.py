"""Learning assembly constraints by demonstration and active exploration, as installed.

- :mod:`assembly_constraints.cli`: the one command line, ``assembly-constraints``;
- :mod:`assembly_constraints.api`: the Python API (learn precedence, learn sizes with an
  oracle, plan, run a session, read a run folder), documented in ``docs/api.md``.

The work itself is done by the planner (:mod:`assembly_constraints.asp`), the cell
(:mod:`assembly_constraints.executor`) and what they share (:mod:`assembly_constraints.bridge`),
the repository's folders ``asp/``, ``executor/`` and ``bridge/``; this package is the front
that puts them together, and the one name the installed package adds.
"""

__version__ = "0.1.0"
