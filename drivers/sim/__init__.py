"""Simulated rig: CiA 402 drive nodes, motor model and catheter plant on a python-can bus."""
