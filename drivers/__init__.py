"""Motor-driver layer of tsmd: CANopen CiA 402 master, simulated drives and catheter physics.

This package knows nothing of :mod:`tsmd`; the daemon composes it.
"""
