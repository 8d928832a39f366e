"""Per-catheter profiles and device models (YAML, versioned schema).

A *device model* holds the data-sheet constants of a catheter type (slope omega, the reference
points of design assumption 1, knob limits). A *profile* holds what calibration identified for one
catheter: per knob the dead zone and backlash grids over the other knob's angle, H, the
interpolation method, the tension play's parameters (method ``ours``) and the quality figures.
A knob's ``ours`` block written by tsmd before the tension play is read past with a warning:
its constants came from a data sheet measured on the scored unit; method ``ours`` then asks
for a recalibration.

Loading validates everything and raises :class:`ProfileError` naming the file, the key and the
reason. Saving is atomic and keeps the previous profile as ``<file>.bak``.
"""

from tsmd.profile.device import (
    DEFAULT_HANDLE_SLIP_DEG,
    DEVICE_SCHEMA_VERSION,
    DeviceKnob,
    DeviceModel,
    ReferencePoint,
)
from tsmd.profile.files import (
    ProfileStore,
    dump_profile,
    load_device_model,
    load_profile,
    save_device_fields,
    save_device_model,
    save_profile,
)
from tsmd.profile.schema import profile_from_mapping, profile_to_mapping
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping
from tsmd.profile.types import (
    ANGLE_RANGE_DEG,
    KNOB_NAMES,
    OMEGA_RANGE,
    PROFILE_SCHEMA_VERSION,
    CatheterProfile,
    KnobProfile,
    ProfileError,
    make_knob_profile,
    standard_grid,
)

__all__ = [
    "ANGLE_RANGE_DEG", "DEFAULT_HANDLE_SLIP_DEG", "DEVICE_SCHEMA_VERSION", "KNOB_NAMES",
    "OMEGA_RANGE", "PROFILE_SCHEMA_VERSION", "CatheterProfile", "DeviceKnob", "DeviceModel",
    "KnobProfile", "ProfileError", "ProfileStore", "ReferencePoint", "device_model_from_mapping",
    "device_model_to_mapping", "dump_profile", "load_device_model", "load_profile",
    "make_knob_profile", "profile_from_mapping", "profile_to_mapping", "save_device_fields",
    "save_device_model", "save_profile", "standard_grid",
]
