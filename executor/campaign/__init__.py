"""Experiments over many trials of the cell: the paper's Fig. 18 robustness campaign on
worker processes (:mod:`.run`, ``executor campaign``) and its Fig. 17/18 figures
(:mod:`.plots`), the wrench and end-error margins the detector thresholds come from
(:mod:`.margins`, ``executor margins``), the cell's speed benchmark (:mod:`.bench`,
``./run.sh bench executor``) and the import's (:mod:`.import_bench`, ``./run.sh bench import``)."""
