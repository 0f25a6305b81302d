"""What the planner and a cell share about precedence: :mod:`bridge.precedence.experiment`,
the experiment (a short sequence testing whether one part can go before another) and its outcome."""
