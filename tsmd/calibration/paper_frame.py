"""The D/B the paper's compensator is fed: the sweeps read in our fit's frame (session 27).

Session 26 (round 2) made the reported D/B take every sure reading offset of the sheet's unit,
however small, because they then match the tip's 1 deg threshold better; our compensator's fit
kept the offsets of 1 deg and more only (``MODEL_MIN_OFFSET_DEG``), because the sub-degree ones
cost its tracking. The paper's compensator went on reading the reported values and so changed
frame with them: on warmgear development 1-2 its rows got worse in 19 of 22 (the sub-degree
offsets moved phi1's D_pos(0) 0.9 deg outward, lifting H_pos 1.15 deg further above the tip's
rest, and B_neg 0.6-1.0 deg wider, carrying its straight release line further outside the tip's
gradual one). The paper's model has straight lines with sharp corners; its D and B are where
those corners lie, which on a rounded knee is inside the tip's 1 deg departure. So both
compensators read the sweeps in the same frame, the one the sheet's constants were read
against, and the reported values stay what the report scores.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from tsmd.profile import CatheterProfile, KnobProfile

PAPER_GRIDS = ("dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_pos_deg", "backlash_neg_deg")


def same_grids(a: KnobProfile, b: KnobProfile) -> bool:
    return all(getattr(a, name) == getattr(b, name) for name in PAPER_GRIDS)


def with_paper_frame(reported: CatheterProfile, model_frame: CatheterProfile) -> CatheterProfile:
    """``reported`` with each knob's :attr:`KnobProfile.paper` set to ``model_frame``'s knob (the
    profile built from the same points in our fit's frame) where its D/B differ; unchanged where
    they are the same (no sub-degree offset applied on that knob)."""
    knobs: Sequence[KnobProfile] = [
        k if same_grids(k, m) else dataclasses.replace(
            k, paper=dataclasses.replace(m, tension_play=None, paper=None))
        for k, m in zip(reported.knobs, model_frame.knobs, strict=True)]
    return dataclasses.replace(reported, knobs=(knobs[0], knobs[1]))


__all__ = ["PAPER_GRIDS", "same_grids", "with_paper_frame"]
