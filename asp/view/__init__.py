"""Opening a run's Rerun recordings: the ``view`` subcommand (:mod:`.cli`: the native or
web viewer, ``--print``), a headless browser's pictures of every tab (:mod:`.screenshot`,
driving Chromium through :mod:`.browser`)."""
