"""The simulated rig: catheter plants, simulated CiA 402 drive nodes, motor model, EM tracker.

Simulation depends on the hardware layer (:mod:`drivers`, for the object dictionary and the
CiA 402 state machine it must speak), never the other way round, and knows nothing of
:mod:`tsmd`. :mod:`simrig.plant` (the ``Plant`` protocol) imports nothing but numpy, so a user's
catheter model can implement it without pulling in CANopen.
"""
