"""The product's backlash rule, chosen on the data sheet's own unit.

Three fraction rules end the backlash from the current (:mod:`tsmd.calibration.release`): the
share of the gap to the release line ("line", session 10), of the swing to the release level
("swing", before) and of the gap to the branch just beyond ("local", session 11). On the
sheet's own +-90 deg sweeps they tie, while the calibration grid's other amplitudes and
other-knob angles separate them per product (coilpipe unit 0: 64 against 103 of 112 values
within 2 deg; docs/calibration.md, session 10 lead), and no one of them holds on every plant.
So the manufacturer, who tracks the tip of this unit anyway, calibrates it with the fast
protocol under each rule (current only, as every unit is calibrated) and writes the rule whose
B comes closest to the tip into the sheet (the rule ends B and moves no edge; session 24): a
per-product constant measured where the other ones are. The knee
(:mod:`tsmd.calibration.knee`) is chosen the same way, after the rule: the chosen rules
calibrated once more with it on, kept per knob unless that placed fewer of the unit's B values
(lumped unit 0 loses with it).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.load_ramp import fit_sweep_sides
from tsmd.calibration.protocol import fast_protocol
from tsmd.calibration.sweep_result import PARAMETERS
from tsmd.calibration.tension_play_fit import sweeps_from_points
from tsmd.config import TsmdConfig
from tsmd.datasheet_rule_halves import points_half_cycle_reads
from tsmd.datasheet_rule_settled import (
    CANDIDATES,
    SWING_KNEE,
    as_candidate,
    offered,
    with_swing_knee,
)
from tsmd.profile import DeviceKnob, DeviceModel
from tsmd.profile.device import RELEASE_RULES
from tsmd.tip_truth import tip_truth
from tsmd.tracked_calibration import TARGET_DEG, play_protocol, score, truth_sweeps

RULE_NOISE_SEEDS = (0, 1)
"""Noise seeds of the sheet unit's calibrations per rule: one run per seed and rule."""


@dataclass(frozen=True)
class RuleScore:
    """One rule on one knob of the sheet's unit, over the noise seeds."""

    rule: str
    knob: int
    within: int
    values: int
    mean_abs_deg: float
    max_deg: float
    accepted: int
    runs: int
    backlash_gain: float | None = None
    """The unit's backlash gain at the other knob's 0 with B by this candidate (mean over the
    runs): the sheet's ``reference_rule_backlash_gain`` where this candidate is chosen."""
    half_placed: int = 0
    """Half-cycles after a reversal whose B lies within the target of the tip's in the same
    sweep (:mod:`tsmd.datasheet_rule_halves`), over the runs."""
    half_misread: int = 0
    """Half-cycles whose B is off by more than the tip's own (:attr:`HalfRead.misread`)."""
    half_cycles: int = 0
    backlash_within: int | None = None
    """The knob's B values (both sides, every grid point and run) within the target: what the
    knee can change (:func:`knee_choice`); None where not counted apart."""

    def key(self) -> tuple[int, int]:
        """Better first: more values within the target, then more runs accepted (a refused
        healthy unit is the worse failure: coilpipe unit 0's phi2 placed 56/56 under both
        "swing" and "local", "swing" with one of two runs refused). The mean error is reported,
        not compared: on lumped unit 0 two rules placed 56/56 with means 0.06 deg apart."""
        return (-self.within, -self.accepted)

    def backlash_key(self) -> tuple[int, int]:
        """As :meth:`key` on the B values alone (all values where B was not counted apart)."""
        within = self.within if self.backlash_within is None else self.backlash_within
        return (-within, -self.accepted)

    def text(self) -> str:
        return (f"{self.rule} {self.within}/{self.values} within {TARGET_DEG:g} deg (mean "
                f"{self.mean_abs_deg:.2f}, max {self.max_deg:.2f} deg, accepted "
                f"{self.accepted}/{self.runs}; B {self._backlash_text()}; B per half-cycle "
                f"{self.half_placed}/"
                f"{self.half_cycles} within {TARGET_DEG:g} deg, {self.half_misread} misread)")

    def _backlash_text(self) -> str:
        return "-" if self.backlash_within is None else f"{self.backlash_within}/{self.values // 2}"


def with_rule(device: DeviceModel, rule: str) -> DeviceModel:
    """The sheet with ``rule`` on every knob that can use it (line, local: where the knob has
    that share)."""
    if rule not in RELEASE_RULES:
        raise ValueError(f"unknown backlash rule {rule!r}")
    knobs = tuple(dataclasses.replace(k, backlash_release_rule=rule if usable(k, rule) else None,
                                      backlash_settled_share=None)
                  for k in device.knobs)
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def usable(knob: DeviceKnob, rule: str) -> bool:
    """Whether the knob's sheet has the share ``rule`` needs (the lag for "recovery", which
    ``tsmd datasheet --recovery-rule`` measures first, :mod:`tsmd.datasheet_recovery`; a
    knob a rule reads by the settle rule for :data:`~tsmd.datasheet_rule_settled.SWING_KNEE`)."""
    if rule == SWING_KNEE:
        return offered(knob)
    share = {"line": knob.backlash_release_line_share,
             "local": knob.backlash_release_local_share,
             "recovery": knob.backlash_recovery_lag_deg}.get(rule, 1.0)
    return share is not None


def rule_backlash_gain(points: Sequence[Any], knob: int) -> float | None:
    """``knob``'s backlash gain with the other knob at 0 (mean of both sides) with B as the
    points were identified, by the estimator every unit's tension play uses; None without such
    a point or a load ramp to fit."""
    mine = [p for p in points if p.knob == knob]
    zero = [s for s in (sweeps_from_points(mine, knob) if mine else []) if s.other_knob_deg == 0]
    if not zero:
        return None
    s = zero[0]
    try:
        sides = fit_sweep_sides(s.pos_deg, s.current_A, s.dead_zone_pos_deg, s.dead_zone_neg_deg,
                                s.backlash_pos_deg, s.backlash_neg_deg)
    except ValueError:
        return None
    return 0.5 * (sides[0].backlash_gain + sides[1].backlash_gain)


def knob_errors(errors: Sequence[float], knob: int) -> np.ndarray:
    """One knob's share of :func:`score`'s values (knob 0's parameters first)."""
    n = len(errors) // 2
    return np.asarray(errors[knob * n:(knob + 1) * n], dtype=float)


def backlash_errors(errors: Sequence[float], knob: int) -> np.ndarray:
    """One knob's B values of :func:`score`'s (its parameters in
    :data:`~tsmd.calibration.sweep_result.PARAMETERS` order, each over the grid)."""
    mine = knob_errors(errors, knob)
    per = mine.size // len(PARAMETERS)
    keep = [i for i, name in enumerate(PARAMETERS) if name.startswith("backlash")]
    return np.concatenate([mine[i * per:(i + 1) * per] for i in keep])


Truth = dict[tuple[int, float], dict[str, float]]


def sheet_truth(config: TsmdConfig, sweeps: Sequence[GridPoint] | None = None) -> Truth:
    """The sheet unit's tracked D and B on the paper's grid (the plant alone), from its
    ``sweeps`` when the caller has them (:func:`tsmd.tracked_calibration.truth_sweeps`)."""
    points = truth_sweeps(config) if sweeps is None else sweeps
    return {(p.knob, p.other_deg): tip_truth(p) for p in points}


def scored(config: TsmdConfig, candidate: DeviceModel, label: str, truth: Truth,
           noise_seeds: Sequence[int]) -> list[RuleScore]:
    """The fast protocol on the sheet's unit with ``candidate``, scored per knob against the
    tip on the paper's grid as the family bench scores."""
    runs = [play_protocol(config, candidate, fast_protocol(), seed) for seed in noise_seeds]
    for run in runs:
        score(run, truth)
    out = []
    for knob in (0, 1):
        e = np.concatenate([knob_errors(r.errors, knob) for r in runs])
        finite = e[np.isfinite(e)]
        b = np.concatenate([backlash_errors(r.errors, knob) for r in runs])
        gains = [g for g in (rule_backlash_gain(r.points, knob) for r in runs) if g is not None]
        halves = [h for r in runs for h in points_half_cycle_reads(r.points, knob)]
        out.append(RuleScore(
            label, knob, int(np.sum(finite <= TARGET_DEG)), e.size,
            float(np.mean(finite)) if finite.size else math.nan,
            float(np.max(finite)) if finite.size else math.nan,
            sum(r.accepted for r in runs), len(runs),
            float(np.mean(gains)) if gains else None, sum(h.placed for h in halves),
            sum(h.misread for h in halves), len(halves),
            int(np.sum(np.abs(b[np.isfinite(b)]) <= TARGET_DEG))))
    return out


def rule_scores(config: TsmdConfig, device: DeviceModel,
                noise_seeds: Sequence[int] = RULE_NOISE_SEEDS,
                truth: Truth | None = None) -> list[RuleScore]:
    """Each rule on the sheet's unit (``config.sim``), scored per knob; where a rule reads a
    knob by the settle rule, "swing" read at its share with the knee too
    (:mod:`tsmd.datasheet_rule_settled`), scored on those knobs only."""
    truth = sheet_truth(config) if truth is None else truth
    out = [one for rule in RELEASE_RULES if any(usable(k, rule) for k in device.knobs)
           for one in scored(config, with_rule(device, rule), rule, truth, noise_seeds)]
    if any(offered(k) for k in device.knobs):
        out += [s for s in scored(config, with_swing_knee(device), SWING_KNEE, truth,
                                  noise_seeds) if offered(device.knobs[s.knob])]
    return out


def with_knee(device: DeviceModel, on: tuple[bool, bool]) -> DeviceModel:
    """The sheet with the knee on where ``on`` says (per knob)."""
    return device.with_knob_flag("backlash_knee", on)


def choose_knee(config: TsmdConfig, chosen: DeviceModel, rule_scores_: Sequence[RuleScore],
                truth: Truth, noise_seeds: Sequence[int] = RULE_NOISE_SEEDS
                ) -> tuple[DeviceModel, list[RuleScore]]:
    """The chosen rules once more with the knee on, kept where it helps (:func:`knee_choice`).
    (sheet, the knee's scores)"""
    knee = scored(config, with_knee(chosen, (True, True)), "knee", truth, noise_seeds)
    return knee_choice(chosen, rule_scores_, knee), knee


def knee_choice(chosen: DeviceModel, rule_scores_: Sequence[RuleScore],
                knee_scores: Sequence[RuleScore]) -> DeviceModel:
    """Each knob keeps the knee unless it placed fewer B values (then: fewer runs accepted)
    than the knob's rule without it. A tie keeps it: the knee only stops a rule from reading B
    where the current no longer says anything, and a unit that the rule alone already places
    fully cannot show that (stickslip unit 0: 56/56 either way, while held-out units of that
    product were refused without it); the products it harms show it on their own unit (lumped
    unit 0: 31 and 45 of 56 with it, 56/56 without). B alone (session 23): the knee moves no
    edge, and the edges these runs read carry no reading offset yet, so their count moved
    with the re-sweeps' order and decided warmgear's phi2 (34 against 30 of 56 values, while
    B per half-cycle was 21/24 without the knee and 24/24 with it)."""
    on = []
    for knob, k in enumerate(chosen.knobs):
        plain = [s for s in rule_scores_ if s.knob == knob and s.rule == k.backlash_release_rule]
        knee = [s for s in knee_scores if s.knob == knob]
        # a candidate chosen with its knee (SWING_KNEE) was scored with it: it has no other
        on.append(bool(k.backlash_knee)
                  or (bool(plain and knee)
                      and knee[0].backlash_key() <= plain[0].backlash_key()))
    return with_rule_gains(with_knee(chosen, (on[0], on[1])), rule_scores_, knee_scores)


def with_rule_gains(chosen: DeviceModel, rule_scores_: Sequence[RuleScore],
                    knee_scores: Sequence[RuleScore]) -> DeviceModel:
    """Each knob's ``reference_rule_backlash_gain``: the gain its chosen rule (with the knee
    where chosen) read on the sheet's unit; none where that candidate gave none."""
    knobs = []
    for knob, k in enumerate(chosen.knobs):
        pool = knee_scores if k.backlash_knee else [
            s for s in rule_scores_ if s.rule == k.backlash_release_rule]
        gains = [s.backlash_gain for s in pool if s.knob == knob and s.backlash_gain is not None]
        gain = round(gains[0], 3) if gains else None
        knobs.append(dataclasses.replace(k, reference_rule_backlash_gain=gain))
    return dataclasses.replace(chosen, knobs=(knobs[0], knobs[1]))


def choose_rules(device: DeviceModel, scores: Sequence[RuleScore]) -> DeviceModel:
    """Each knob gets, among the rules that misread the fewest of the unit's half-cycles
    (:attr:`tsmd.datasheet_rule_halves.HalfRead.misread`; session 21: warmgear unit 0's phi1
    "swing" placed 49/56 grid values against "local" 43/56 while ending 2 of 24 half-cycles at
    a loaded gear step 36-38 deg off, and on development unit 1 it did so at two of three grid
    points), the rule that placed the most B values within the target (then: the most runs
    accepted; :meth:`RuleScore.backlash_key`); a tie keeps the earlier of
    :data:`RELEASE_RULES` ("line": the rule of a sheet with a line share and no choice, chosen
    on the development units of lumped and segments;
    :data:`~tsmd.datasheet_rule_settled.SWING_KNEE` last, so a tie keeps the rule of before);
    a rule needs its share. B alone (session 24), as for the knee (:func:`knee_choice`): a
    half-cycle's edge is fitted from its constant stretch on, whatever ends its backlash
    (:func:`tsmd.calibration.identify.identify_sweep`), so a rule moves an edge only through
    the re-sweeps its B's half-width asks for (docs/calibration.md, session 24)."""
    knobs = []
    for knob, k in enumerate(device.knobs):
        mine = [s for s in scores if s.knob == knob and usable(k, s.rule)]
        if not mine:
            knobs.append(k)
            continue
        fewest = min(s.half_misread for s in mine)
        mine = [s for s in mine if s.half_misread == fewest]
        best = min(mine, key=lambda s: (s.backlash_key(), CANDIDATES.index(s.rule)))
        knobs.append(as_candidate(k, best.rule))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
