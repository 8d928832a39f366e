"""The rule choice's candidate for a knob whose release share is settled (session 22).

At a share at or above :data:`~tsmd.calibration.options.SETTLED_FRACTION` a sheet reads the
knob's backlash by the paper's settle rule, whichever fraction rule it names ("swing" at a
settled share of the swing, "line" at a settled share of the gap to the release line), and the
knee (which bounds only the fraction rules) does nothing there. The rule choice
(:mod:`tsmd.datasheet_rule`) scores the rules without the knee and chooses the knee after, so a
fraction rule that needs the knee lost to the settle rule before its knee was tried: on
jawcrimp phi1 (swing share 0.990, line 1.055) every candidate was the settle rule, whose settle
point comes late on some half-cycles, mostly a sweep's first (development unit 1: 17.8-22.2 deg
against the tip's 11.5), while the swing share with the knee reads every half-cycle within 1 deg
of the tip (docs/calibration.md, session 21). So a knob where a rule reads by the settle rule
is also offered "swing" read at its share with the knee (``backlash_knee``; at a settled share
``backlash_settled_share`` too), scored on the sheet's unit like every rule and chosen only
where it does better (a tie keeps the earlier rules). Always with the knee: so near the level
the share's crossing without it lies where the current creeps, placed by its scatter (jawcrimp
unit 1: 28.5-43.2 deg). A swing share of 1 (the current had made up its whole swing before the
tip moved: screwrod) leaves no crossing to read and is not offered.
"""

from __future__ import annotations

import dataclasses

from tsmd.calibration.options import SETTLED_FRACTION
from tsmd.profile import DeviceKnob, DeviceModel
from tsmd.profile.device import RELEASE_RULES

SWING_KNEE = "swing-knee"
"""The candidate's label in the rule choice: "swing" read at its share, with the knee."""
CANDIDATES = (*RELEASE_RULES, SWING_KNEE)
"""Every candidate in the order a tie is broken (this one last)."""


def _settled(share: float | None) -> bool:
    return share is not None and share >= SETTLED_FRACTION


def offered(knob: DeviceKnob) -> bool:
    """Whether a rule reads this knob by the settle rule (its swing or line share settled)
    while its swing share still leaves a crossing to read (below 1)."""
    share = knob.backlash_settle_fraction
    return (share is not None and share < 1.0
            and (_settled(share) or _settled(knob.backlash_release_line_share)))


def with_swing_knee(device: DeviceModel) -> DeviceModel:
    """The sheet with :data:`SWING_KNEE` on every knob it is offered to; the other knob reads
    "swing" as usual (its scores are not this candidate's)."""
    knobs = tuple(as_candidate(k, SWING_KNEE) if offered(k)
                  else dataclasses.replace(k, backlash_release_rule="swing",
                                           backlash_settled_share=None, backlash_knee=None)
                  for k in device.knobs)
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def as_candidate(knob: DeviceKnob, label: str) -> DeviceKnob:
    """The knob reading by the candidate ``label`` (a plain rule: without the knee, which is
    chosen after)."""
    if label == SWING_KNEE:
        return dataclasses.replace(
            knob, backlash_release_rule="swing", backlash_knee=True,
            backlash_settled_share=True if _settled(knob.backlash_settle_fraction) else None)
    return dataclasses.replace(knob, backlash_release_rule=label, backlash_settled_share=None,
                               backlash_knee=None)


def rule_text(knob: DeviceKnob) -> str:
    """The knob's rule as the datasheet prints it."""
    settled = " at its settled share" if knob.backlash_settled_share else ""
    return f"{knob.backlash_release_rule}{settled}"
