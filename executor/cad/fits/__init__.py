"""The fits between two parts that the sweeps (:mod:`executor.cad.sweep`) let slide along
their axis, found on the parts' meshes: ``faces``, the cylinders and prisms fitted on a
mesh, the nominal zero-clearance fits they make and a part taken thinner at them for its
sweeps (it imports none of the import's other modules); ``threads``, modelled threads
measured on the meshes and cosmetic ones taken from a standard thread's major and tap-drill
diameters, each pair a screwed fit (it names an axis as the sweeps do). Units: metres.
"""
