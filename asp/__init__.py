"""The planner: ASP encodings (``asp/encodings/*.lp``) and the Python that drives clingo.

Learns precedence constraints from demonstrations (paper 2.1), which part fits which
hole by active exploration (paper 2.2), assigns holes and builds complete plans.
"""

from bridge.errors import ToolError

MAX_IDS = 64
"""At most this many parts, and this many holes, in the planner's input (demonstrations,
precedence and sizes facts, learned facts): the learners' matrices and searches are
sized by them."""


class PlannerError(ToolError):
    """Base error of the planner: bad input or an unsolvable request.

    The message names the bad value (file:line or field) and what was expected; the
    command line prints it and exits with code 2.
    """
