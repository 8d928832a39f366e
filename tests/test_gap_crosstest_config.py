"""The cross-plant self-test's diagnosis settings, whoever calls it (docs/gap.md "Session 27,
round 2": a script that diagnosed a session with the simulator's parameters fitted read
warmgear 101's rate case as sensor where `tsmd gap selftest` reads nothing)."""

from __future__ import annotations

from typing import Any

import pytest

import tsmd.gap.crosstest as crosstest
from tsmd.gap.presets import PRESETS
from tsmd.gap.result import GapConfig


class _StoppedError(Exception):
    """Raised by the stand-in diagnosis once it has seen its settings."""


def _settings(monkeypatch: pytest.MonkeyPatch, config: GapConfig | None) -> GapConfig:
    """The settings diagnose_session hands to the diagnosis (references stubbed out)."""
    seen: dict[str, Any] = {}

    def stand_in(_series: object, _factory: object, _params: object, cfg: GapConfig) -> None:
        seen["cfg"] = cfg
        raise _StoppedError

    monkeypatch.setattr(crosstest, "diagnose", stand_in)
    monkeypatch.setattr(crosstest, "datasheet_reference", lambda *_a: (100.0, 100.0))
    monkeypatch.setattr(crosstest, "model_reference", lambda *_a: None)
    with pytest.raises(_StoppedError):
        crosstest.diagnose_session([], PRESETS["warmgear"], PRESETS["capstan"], "rate", 240.0,
                                   101, config=config)
    cfg: GapConfig = seen["cfg"]
    return cfg


def test_a_session_diagnosed_without_settings_fits_no_simulator_parameter(
        monkeypatch: pytest.MonkeyPatch) -> None:
    assert PRESETS["capstan"].fit  # the capstan simulator has parameters one could fit
    cfg = _settings(monkeypatch, None)
    assert cfg.fit_specs == () and cfg.method == "signature"


def test_a_session_diagnosed_without_settings_draws_as_the_selftest_command(
        monkeypatch: pytest.MonkeyPatch) -> None:
    cfg = _settings(monkeypatch, None)
    assert cfg.seed == crosstest.cross_config(PRESETS["capstan"].fit).seed


def test_given_settings_are_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    cfg = _settings(monkeypatch, GapConfig(fit_specs=PRESETS["capstan"].fit, seed=101))
    assert cfg.fit_specs == PRESETS["capstan"].fit and cfg.seed == 101
