"""Part-in-hole size constraints (paper 2.2): knowledge, the learner, oracles, selection
policies (the paper's heuristic, baselines, ``best``), biorders, evaluation."""
