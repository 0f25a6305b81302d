"""The skills of the cell (paper 3.1/3.2): the taught Cartesian DMP with its reference
wrench and phase stopping (:mod:`.dmp`), the stochastic hole search (:mod:`.search`), the
insertion proper (:mod:`.insertion`), the wiggle exception strategy (:mod:`.wiggle`) and
the scripted kinesthetic teaching that records the DMPs (:mod:`.teach`).  Skills move the
arm through :class:`executor.control.motion.Motion`."""
