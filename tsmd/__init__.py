"""tsmd: driver daemon for tendon-sheath-driven robotic catheters."""

__version__ = "0.1.0"
