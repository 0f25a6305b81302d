"""Precedence constraints (paper 2.1): demonstrations, the must-precede relation,
counting, sampling, evaluation, guidance, drawing."""
