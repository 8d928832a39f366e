"""Capstan-chain plant: tendons in discretised sheaths with Coulomb capstan friction per element."""

from simrig.plants.capstan.tendon_sheath import (
    DEFAULT_KNOBS,
    Effects,
    KnobParams,
    TendonSheathPlant,
    make_tendon_sheath_plant,
)

__all__ = [
    "DEFAULT_KNOBS",
    "Effects",
    "KnobParams",
    "TendonSheathPlant",
    "make_tendon_sheath_plant",
]
