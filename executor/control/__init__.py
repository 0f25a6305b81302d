"""Control of the arm: the torque-mode Cartesian impedance controller (:mod:`.controller`),
the admittance law adapting toward the reference wrench (:mod:`.admittance`), the failure
detector of eqs. (6)/(7) and the goal check (:mod:`.detector`) and the 1 ms motion
stepper every skill moves through (:mod:`.motion`).  Builds on :mod:`executor.world`."""
