"""Settings and results of a gap diagnosis: what the report shows, as plain data."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from tsmd.gap.fit import ParamSpec
from tsmd.gap.reference import ProductReference
from tsmd.gap.where import BinRow


@dataclass(frozen=True)
class GapConfig:
    """Settings of one diagnosis (defaults are what `tsmd gap` uses)."""

    fit_specs: tuple[ParamSpec, ...] = ()
    holdout: float | tuple[str, ...] = 0.3
    block_s: float | None = None
    fit_max_rows: int = 2000
    rank_max_rows: int = 6000
    base_evals: int = 120
    polish_evals: int = 20
    refine_evals: int = 10
    joint_top: int = 2
    candidate_evals: int = 8
    seed: int = 0
    n_boot: int = 2000
    ci_level: float = 0.9
    family_alpha: float = 0.05
    min_share: float = 0.05
    explained_share: float = 0.5
    gap_floor: float = 0.1
    max_combined: int = 3
    candidates: tuple[str, ...] | None = None
    method: str = "signature"
    """'signature': effects by their condition signature on top of a structural layer (robust
    to wrong base physics); 'candidates': the earlier candidate transforms around the plant."""
    sig_max_rows: int = 12000
    compliance_reference: tuple[float, float] | None = None
    """The catheter model's data sheet figure of lost motion per ampere (deg/A, knob 1, 2;
    :func:`tsmd.gap.compliance.reference_deg_per_A` on the protocol recorded with another
    unit). With it and the protocol, compliance is named from the reversals; without, it is
    scored but not named."""
    product_reference: ProductReference | None = None
    """What the catheter model has always (its own rate, coupling and creep contrasts), from
    the protocol recorded on the data sheet's unit (:func:`tsmd.gap.contrast.product_reference`):
    with it those tests name only what a unit has beyond its model."""
    final_max_rows: int = 20000
    """Held-out rows replayed for the how-far figures (all of them up to this many)."""
    n_surrogates: int = 30
    fit_window_s: float = 60.0
    fit_windows: int = 6
    """The physics base fit sees ``fit_windows`` stretches of ``fit_window_s`` spread over the
    training data (recordings shorter than 1.5x that in all are fitted whole): a few plant
    constants are set by minutes of varied knob motion, and replaying half an hour for every
    evaluation of the fit is what made a long recording slow."""
    signature_fit_evals: tuple[int, int] = (36, 8)
    signature_fit_rows: int = 800
    """Coordinate-search and simplex evaluations and grid rows of the base fit in the signature
    method when it runs on windows (long recordings): the structural layer takes what a longer
    fit would remove; the fit sets its carriers and the 'physics' figures."""


@dataclass
class CandidateScore:
    name: str
    title: str
    physics: str
    params: dict[str, float]
    share: float
    ci: tuple[float, float]
    significant: bool
    train_cost_drop: float
    ljung_box_q: dict[str, float]
    metrics: dict[str, float]
    stage: str = "screen"


@dataclass
class GapResult:
    """Everything the report shows; :meth:`to_json` gives the same figures as plain data."""

    verdict: str
    summary: str
    split: str
    base_params: dict[str, Any]
    fitted_params: dict[str, float]
    noise_std: dict[str, float]
    gap_ratio: tuple[float, float, float]
    before: dict[str, float]
    after_top: dict[str, float] | None
    after_combined: dict[str, float] | None
    top: list[str]
    combined: list[str]
    combined_share: tuple[float, float, float] | None
    candidates: list[CandidateScore]
    where_shares: dict[str, dict[str, float]]
    where_bins: dict[str, list[BinRow]]
    ljung_box_base: dict[str, float]
    timing_s: dict[str, float]
    rows: dict[str, int]
    structure: dict[str, Any] | None = None
    """Signature method: base mismatch and the effect on top (see tsmd.gap.signature)."""
    plot_data: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return {
            "verdict": self.verdict, "summary": self.summary, "split": self.split,
            "base_params": self.base_params, "fitted_params": self.fitted_params,
            "noise_std": self.noise_std,
            "gap_ratio": {"point": self.gap_ratio[0], "ci": list(self.gap_ratio[1:])},
            "before": self.before, "after_top": self.after_top,
            "after_combined": self.after_combined, "top": self.top, "combined": self.combined,
            "combined_share": (None if self.combined_share is None else
                               {"point": self.combined_share[0],
                                "ci": list(self.combined_share[1:])}),
            "candidates": [{
                "name": c.name, "title": c.title, "physics": c.physics, "params": c.params,
                "share": c.share, "ci": list(c.ci), "significant": c.significant,
                "train_cost_drop": c.train_cost_drop, "ljung_box_q": c.ljung_box_q,
                "stage": c.stage,
                "metrics": c.metrics} for c in self.candidates],
            "where": {
                group: {"shares": self.where_shares[group],
                        "bins": [vars(b) for b in self.where_bins[group]]}
                for group in self.where_shares},
            "ljung_box_base": self.ljung_box_base, "timing_s": self.timing_s, "rows": self.rows,
            "structure": self.structure,
        }
