"""The compliance figure's pair of loads chosen on the data sheet's units alone (opt-in): the
usual 40/60 or the heavy cycles' 40/75, whichever would show a doubled stretch more clearly."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence

import pytest

from tsmd.gap import compliance, compliance_pairs, session
from tsmd.gap.compliance import ComplianceSheet
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.presets import PRESETS
from tsmd.gap.protocol import ProtocolDesign, protocol

RATE_HZ = 50.0
HEAVY = ProtocolDesign(heavy_amp_deg=75.0)
HEAVY_PAIR = (40.0, 75.0)


def _sheet(spread_sd: float, noise_sd: float, loads: tuple[float, float] | None = None,
           figure: compliance.Figure = "load contrast") -> ComplianceSheet:
    return ComplianceSheet((50.0, 50.0), (noise_sd**2,) * 2, (spread_sd**2,) * 2, 5, figure,
                           loads)


def _offer(monkeypatch: pytest.MonkeyPatch, usual: ComplianceSheet,
           heavier: ComplianceSheet) -> ComplianceSheet | None:
    """The choice when the sheet's units read ``usual`` at 40/60 and ``heavier`` at 40/75."""
    def read(_units: Sequence[Sequence[GapSeries]], _alpha: float = 0.05,
             loads_deg: tuple[float, float] | None = None) -> ComplianceSheet:
        return heavier if loads_deg == HEAVY_PAIR else usual

    monkeypatch.setattr(compliance_pairs, "HEAVY_LOADS_DEG", HEAVY_PAIR)
    monkeypatch.setattr(compliance_pairs, "sheet_from_units", read)
    return compliance_pairs.sheet_at_chosen_loads([])


def test_a_doubled_stretch_is_seen_less_clearly_through_a_wider_spread_or_more_noise() -> None:
    z = compliance_pairs.doubled_stretch_z
    assert z(_sheet(0.3, 0.03)) < z(_sheet(0.1, 0.03))
    assert z(_sheet(0.1, 0.10)) < z(_sheet(0.1, 0.03))


def test_the_pair_whose_units_scatter_less_is_chosen(monkeypatch: pytest.MonkeyPatch) -> None:
    # planetwist's units: the heavier pair scatters more at about the same noise
    usual, heavier = _sheet(0.36, 0.04, (40.0, 60.0)), _sheet(0.55, 0.03, HEAVY_PAIR)
    assert _offer(monkeypatch, usual, heavier) is usual


def test_the_pair_read_with_less_noise_is_chosen(monkeypatch: pytest.MonkeyPatch) -> None:
    # notchclutch's units: the stretch grows little from 40 to 60 deg against the repeats
    usual, heavier = _sheet(0.0, 0.11, (40.0, 60.0)), _sheet(0.23, 0.018, HEAVY_PAIR)
    assert _offer(monkeypatch, usual, heavier) is heavier


def test_a_sheet_read_on_the_release_keeps_the_usual_pair(
        monkeypatch: pytest.MonkeyPatch) -> None:
    usual = _sheet(0.3, 0.03, (40.0, 60.0), "release")
    heavier = _sheet(0.0, 0.001, HEAVY_PAIR, "release")
    assert _offer(monkeypatch, usual, heavier) is usual


def test_off_by_default_the_sheet_is_read_at_the_usual_loads() -> None:
    assert compliance_pairs.HEAVY_LOADS_DEG is None
    sheet = compliance_pairs.sheet_at_chosen_loads(_units())
    assert sheet is not None and sheet.loads_deg is None
    assert sheet == compliance.sheet_from_units(_units())


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
    return [list(_series("none", u)) for u in (0, 5, 6)]


def test_a_unit_is_read_at_its_sheets_loads(monkeypatch: pytest.MonkeyPatch) -> None:
    unit = list(_series("compliance", 1))
    at_heavy = compliance.sheet_from_units(_units(), loads_deg=HEAVY_PAIR)
    assert at_heavy is not None and at_heavy.loads_deg == HEAVY_PAIR
    read = compliance.compliance_score(unit, at_heavy, 7)
    usual = compliance.compliance_score(unit, compliance.sheet_from_units(_units()), 7)
    monkeypatch.setattr(compliance, "CONTRAST_LEVELS_DEG", HEAVY_PAIR)
    unset = dataclasses.replace(at_heavy, loads_deg=None)
    expected = compliance.compliance_score(unit, unset, 7)
    assert read is not None and expected is not None
    assert read.share == expected.share and "loads 40/75 deg" in read.condition
    assert read.condition.replace(", loads 40/75 deg", "") == expected.condition
    assert usual is not None and usual.share != read.share


def test_at_the_chosen_loads_a_halved_tendon_is_named_and_an_unaltered_unit_is_not(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(compliance_pairs, "HEAVY_LOADS_DEG", HEAVY_PAIR)
    sheet = compliance_pairs.sheet_at_chosen_loads(_units())
    assert sheet is not None and sheet.loads_deg in (compliance.LEVELS_DEG, HEAVY_PAIR)
    softer = compliance.compliance_score(list(_series("compliance", 1)), sheet, 7)
    unaltered = compliance.compliance_score(list(_series("none", 1)), sheet, 7)
    assert softer is not None and softer.significant
    assert unaltered is not None and not unaltered.significant
