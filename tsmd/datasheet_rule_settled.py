"""The rule choice's candidate for a knob whose release share is settled (session 22).

At a share of the swing at or above :data:`~tsmd.calibration.options.SETTLED_FRACTION` a sheet
reads the knob's backlash by the paper's settle rule, whichever fraction rule it names, and the
knee (which bounds only the fraction rules) does nothing: every candidate of the rule choice
(:mod:`tsmd.datasheet_rule`) was the settle rule. On jawcrimp phi1 (share 0.990) the settle
point comes late on some half-cycles, mostly a sweep's first (development unit 1: 17.8-22.2 deg
against the tip's 11.5), while the swing share with the knee reads every half-cycle within 1 deg
of the tip (docs/calibration.md, session 21). So such a knob is also offered "swing" read at
its share with the knee (the sheet's ``backlash_settled_share`` and ``backlash_knee``), scored
on the sheet's unit like every rule and chosen only where it does better; a tie keeps the
settle rule. Always with the knee: so near the level the share's crossing without it lies
where the current creeps, placed by its scatter (jawcrimp unit 1: 28.5-43.2 deg). A share of 1
(the current had made up its whole swing before the tip moved: screwrod) leaves no crossing to
read and is not offered.
"""

from __future__ import annotations

import dataclasses

from tsmd.calibration.options import SETTLED_FRACTION
from tsmd.profile import DeviceKnob, DeviceModel
from tsmd.profile.types import RELEASE_RULES

SETTLED_SHARE = "swing-share"
"""The candidate's label in the rule choice: "swing" read at a settled share, with the knee."""
CANDIDATES = (*RELEASE_RULES, SETTLED_SHARE)
"""Every candidate in the order a tie is broken (the settled share's last)."""


def settled_swing(knob: DeviceKnob) -> bool:
    """Whether the knob's swing share is settled and still leaves a crossing to read."""
    share = knob.backlash_settle_fraction
    return share is not None and SETTLED_FRACTION <= share < 1.0


def with_settled_share(device: DeviceModel) -> DeviceModel:
    """The sheet with "swing" read at its share with the knee on every knob whose share is
    settled; the other knob reads "swing" as usual (its scores are not this candidate's)."""
    knobs = tuple(as_candidate(k, SETTLED_SHARE) if settled_swing(k)
                  else dataclasses.replace(k, backlash_release_rule="swing",
                                           backlash_settled_share=None)
                  for k in device.knobs)
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def candidate_of(knob: DeviceKnob) -> str | None:
    """The rule-choice label a knob's sheet reads by."""
    return SETTLED_SHARE if knob.backlash_settled_share else knob.backlash_release_rule


def as_candidate(knob: DeviceKnob, label: str) -> DeviceKnob:
    """The knob reading by the candidate ``label``."""
    if label == SETTLED_SHARE:
        return dataclasses.replace(knob, backlash_release_rule="swing",
                                   backlash_settled_share=True, backlash_knee=True)
    return dataclasses.replace(knob, backlash_release_rule=label, backlash_settled_share=None)
