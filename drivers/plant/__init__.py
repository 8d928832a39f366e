"""Catheter plants: the physics the simulated drives move (see :mod:`drivers.plant.base`)."""

from drivers.plant.base import Plant, PlantStep, load_plant

__all__ = ["Plant", "PlantStep", "load_plant"]
