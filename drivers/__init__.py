"""Hardware layer of tsmd: the CANopen CiA 402 master, drive interface, units and clocks.

This package knows nothing of :mod:`tsmd` or of simulation (:mod:`simrig`); the daemon composes it.
"""
