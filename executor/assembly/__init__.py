"""The assembling cell: the whole product in one PyBullet world, picked, carried and
placed along a plan step by step (``product``, ``world``, ``grasp``, ``transfer``, ``step``)."""
