"""The product's release-path slope ratio, read from its data sheet (session 7; its home since
session 21, where the sheet loader refuses a ratio the calibration could not use).

The ends of all backlashes of one side lie on a line of slope ``omega / (1 - beta)``; the data
sheet's tracked ``release_omega`` gives how much shallower or steeper the product's tip runs
once released (:mod:`tsmd.calibration.release_path` moves each unit's release line by it).
"""

from __future__ import annotations

from typing import Any

RELEASE_RATIO_RANGE: tuple[float, float] = (0.7, 1.3)
"""Plausible release-path over backlash-end-locus slope ratios; outside, the sheet is refused."""


def ratio_gain(device_knob: Any) -> float | None:
    """The sheet unit's backlash gain the ratio is taken against: the settle rule's
    (``reference_backlash_gain``, sessions 7-15) or the product rule's
    (``reference_rule_backlash_gain``, the reading every unit's ``beta`` is fitted with), the one
    whose moved gain on the sheet's own unit, ``1 - omega (1 - rule) / (release_omega (1 -
    gain))``, is nearer the backlash growth its tracker showed between reversals at 60 and 90
    deg (``reference_tip_backlash_gain``, session 16); the settle rule's without that key.
    Where the sheet also has the growth read at the corners of the paper's lines
    (``reference_tip_line_backlash_gain``, session 17), the choice is made against it: the
    model's backlash is the knob travel to its release line, which a tip with rounded
    corners reaches after the 1 deg threshold has fired. A sheet's ``release_ratio_gain``
    ("settle" or "rule") overrides the choice."""
    settle = getattr(device_knob, "reference_backlash_gain", None)
    rule = getattr(device_knob, "reference_rule_backlash_gain", None)
    chosen = getattr(device_knob, "release_ratio_gain", None)
    if chosen is not None:  # the product's choice on its sheet unit's tracking (session 21)
        picked = settle if chosen == "settle" else rule
        return None if picked is None else float(picked)
    tip = getattr(device_knob, "reference_tip_line_backlash_gain", None)
    if tip is None:
        tip = getattr(device_knob, "reference_tip_backlash_gain", None)
    release = getattr(device_knob, "release_omega", None)
    if settle is None or rule is None or tip is None or release is None:
        return None if settle is None else float(settle)
    omega = float(device_knob.omega)

    def miss(gain: float) -> float:
        return abs(1.0 - omega * (1.0 - float(rule)) / (float(release) * (1.0 - gain)) - tip)

    return float(min((float(settle), float(rule)), key=miss))


def release_slope_ratio(device_knob: Any) -> float:
    """The product's release-path slope over its backlash-end locus slope, from the data sheet:
    ``release_omega (1 - gain) / omega`` (tracked release slope against the locus the current's
    backlash gain gives on the same unit; the gain by :func:`ratio_gain`); 1 without them."""
    release = getattr(device_knob, "release_omega", None)
    gain = ratio_gain(device_knob)
    if release is None or gain is None:
        return 1.0
    ratio = float(release) * (1.0 - float(gain)) / float(device_knob.omega)
    lo, hi = RELEASE_RATIO_RANGE
    if not lo <= ratio <= hi:
        raise ValueError(f"data sheet: release_omega {release} gives a release/locus slope ratio "
                         f"{ratio:.2f} outside [{lo}, {hi}]")
    return ratio


def release_ratio_problem(device_knob: Any) -> str | None:
    """Why the sheet knob's tracked release cannot be used (its ratio outside
    :data:`RELEASE_RATIO_RANGE`), None where it can or the sheet has none."""
    try:
        release_slope_ratio(device_knob)
    except ValueError as exc:
        return str(exc).removeprefix("data sheet: ")
    return None
