"""Built-in catheter plants: independent physics models behind :class:`simrig.plant.Plant`."""
