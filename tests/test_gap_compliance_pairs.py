"""Compliance read at two pairs of loads (opt-in): the usual 40/60 and the heavy cycles' 40/75,
each against the same units' sheet at those loads, named when either clears its spread."""

from __future__ import annotations

import dataclasses
import functools

import pytest

from tsmd.gap import compliance, compliance_pairs, session
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.presets import PRESETS
from tsmd.gap.protocol import ProtocolDesign, protocol

RATE_HZ = 50.0
HEAVY = ProtocolDesign(heavy_amp_deg=75.0)
SHEET_UNITS = (0, 5, 6)
WIDE = (4.0, 4.0)
"""A units' spread no unit clears (log variance: x7.4 at one standard deviation)."""


@functools.cache
def _series(case: str, unit: int) -> tuple[GapSeries, ...]:
    """A capstan unit's protocol with the heavy cycles appended (unit 0 without scatter)."""
    original = session.protocol
    session.protocol = lambda rate_hz, design=None: protocol(rate_hz, HEAVY)  # type: ignore[assignment]
    try:
        made = session.make_session(PRESETS["capstan"], case, 4.0, RATE_HZ, unit,
                                    unit_variation=0.0 if unit == 0 else 0.1)
    finally:
        session.protocol = original  # type: ignore[assignment]
    return tuple(series_from_recording(r, f"pairs-{case}-{unit}-{i}")
                 for i, r in enumerate(made) if "segments" in r.metadata)


def _units() -> list[list[GapSeries]]:
    return [list(_series("none", u)) for u in SHEET_UNITS]


def _both_sheets(monkeypatch: pytest.MonkeyPatch) -> compliance.ComplianceSheet:
    monkeypatch.setattr(compliance_pairs, "HEAVY_LOADS_DEG", (40.0, 75.0))
    sheet = compliance_pairs.sheet_at_both_loads(_units())
    assert sheet is not None and sheet.heavier is not None
    return sheet


def test_off_by_default_the_sheet_has_one_pair_and_the_score_is_the_usual_one() -> None:
    assert compliance_pairs.HEAVY_LOADS_DEG is None
    sheet = compliance_pairs.sheet_at_both_loads(_units())
    assert sheet is not None and sheet.heavier is None and sheet.loads_deg is None
    unit = list(_series("compliance", 1))
    assert (compliance_pairs.either_pair_score(unit, sheet, 7)
            == compliance.compliance_score(unit, sheet, 7))


def test_the_heavier_sheet_is_read_at_the_heavier_loads(
        monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = _both_sheets(monkeypatch)
    assert sheet.loads_deg == compliance.LEVELS_DEG
    assert sheet.heavier is not None and sheet.heavier.loads_deg == (40.0, 75.0)
    # the tendon's stretch grows further from 40 to 75 deg than the constant part does
    assert sheet.heavier.figure_deg_per_A != pytest.approx(sheet.figure_deg_per_A, rel=0.01)


def test_a_halved_tendon_is_named_when_only_the_usual_pair_clears_its_spread(
        monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = _both_sheets(monkeypatch)
    assert sheet.heavier is not None
    blind_heavy = dataclasses.replace(
        sheet, heavier=dataclasses.replace(sheet.heavier, allowance_log_var=WIDE))
    score = compliance_pairs.either_pair_score(list(_series("compliance", 1)), blind_heavy, 7)
    assert score is not None and score.significant
    assert "40/60" in score.condition


def test_a_halved_tendon_is_named_when_only_the_heavier_pair_clears_its_spread(
        monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = _both_sheets(monkeypatch)
    blind_usual = dataclasses.replace(sheet, allowance_log_var=WIDE)
    score = compliance_pairs.either_pair_score(list(_series("compliance", 1)), blind_usual, 7)
    assert score is not None and score.significant
    assert "40/75" in score.condition


def test_nothing_is_named_when_neither_pair_clears_its_spread(
        monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = _both_sheets(monkeypatch)
    assert sheet.heavier is not None
    blind = dataclasses.replace(sheet, allowance_log_var=WIDE,
                                heavier=dataclasses.replace(sheet.heavier,
                                                            allowance_log_var=WIDE))
    score = compliance_pairs.either_pair_score(list(_series("compliance", 1)), blind, 7)
    assert score is not None and not score.significant


def test_each_pair_is_read_at_half_the_level(monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = _both_sheets(monkeypatch)
    seen: list[tuple[tuple[float, float] | None, int]] = []
    score_at = compliance.compliance_score

    def spy(series: list[GapSeries], sh: compliance.ComplianceSheet, n_tried: int,
            *args: float) -> object:
        seen.append((sh.loads_deg, n_tried))
        return score_at(series, sh, n_tried, *args)

    monkeypatch.setattr(compliance_pairs, "compliance_score", spy)
    compliance_pairs.either_pair_score(list(_series("compliance", 1)), sheet, 7)
    assert seen == [(compliance.LEVELS_DEG, 14), ((40.0, 75.0), 14)]


def test_an_unaltered_unit_is_named_by_neither_pair(monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = _both_sheets(monkeypatch)
    score = compliance_pairs.either_pair_score(list(_series("none", 1)), sheet, 7)
    assert score is not None and not score.significant
