"""What one edge tracker reports (the API's ``status.online.edges``, docs/api.md).

Apart from :class:`tsmd.online.estimator.EdgeTracker` so that the tracker's module keeps to its
estimation; the fields are the tracker's counters and values, read only.
"""

from __future__ import annotations

from typing import Any


def edge_status(edge: Any) -> dict[str, Any]:
    """The status fields of ``edge`` (an :class:`~tsmd.online.estimator.EdgeTracker`)."""
    share = edge.share.share
    state = ("learning" if edge.learning else "frozen" if edge.frozen_for > 0
             else "tracking" if edge.reference.settled else "settling")
    return {"state": state, "offset_deg": round(edge.applied_deg, 3),
            "zero_load_offset_deg": round(edge.zero_load_deg, 3),
            "estimate_deg": round(edge.estimate_deg, 3),
            "confidence": round(edge.confidence, 2), "ramps": edge.n_ramps,
            "odd_slope_ramps": edge.n_odd_slope, "odd_knee_ramps": edge.n_odd_knee,
            "odd_crossing_ramps": edge.n_odd_crossing, "refused_ramps": edge.n_refused,
            "odd_speed_ramps": edge.n_odd_speed,
            "feature": edge.last_feature or None,
            "backlash_gain_ratio": round(edge.gain_ratio, 3),
            "other_knob_bins_deg": edge.bins.biases_deg(),
            "frozen_reason": edge.frozen_reason if edge.frozen_for > 0 else None,
            "reference_relearned": edge.reference.relearned,
            "reread_ramps": edge.n_reread, "partner_held": edge.n_partner_held,
            "between_ramps": edge.n_between, "widened_ramps": edge.n_widened,
            "steeper_ramps": edge.n_steeper, "own_slope_ramps": edge.n_own_between,
            "own_slope_held_ramps": edge.n_own_held, "flatter_own_ramps": edge.n_flatter_own,
            "leaning_steeper_ramps": edge.n_leaning_steeper,
            "bin_lean_held_ramps": edge.n_bin_lean,
            "followed_own_slope_ramps": edge.n_followed_own,
            "cut_window_ramps": edge.n_cut, "share_read_ramps": edge.n_share_read,
            "learned_share": None if share is None else round(share, 3)}


__all__ = ["edge_status"]
