"""`tsmd datasheet` (tsmd.datasheet): a tracked unit's sweeps give its data sheet; bad input is
one line. The simulator path is the same analysis on a recording of the full stack."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.calibration import LockstepPlantRunner
from support.profiles import DEVICE

from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
from tsmd.cli import main
from tsmd.compensation.release_ratio import RELEASE_RATIO_RANGE
from tsmd.datasheet import (
    CONDITIONING_CYCLES,
    RELEASE_READ_CYCLES,
    DatasheetError,
    analysed_from,
    knob_constants,
    readable,
    settle,
    tip_sweep,
)
from tsmd.profile import DEFAULT_HANDLE_SLIP_DEG, DeviceModel, load_device_model, save_device_model
from tsmd.recording import Recording, read_recording, write_recording

PERIOD_S = 0.01


def tracked_sweep(knob: int) -> Recording:
    """A conditioned +-90 deg sweep of ``knob`` on the built-in plant, tip tracked."""
    runner = LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S, seed=knob)
    t, q, skip = settle(*tip_sweep(knob, 0.0, PERIOD_S), PERIOD_S)
    rec = runner.run(t, q)
    first = analysed_from(skip, PERIOD_S)
    return Recording({k: v[first:] for k, v in rec.columns.items()}, rec.metadata)


@pytest.fixture(scope="module")
def sweep_files(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    out = []
    for knob in (0, 1):
        path = tmp_path_factory.mktemp("sweeps") / f"sweep-phi{knob + 1}.csv"
        write_recording(path, tracked_sweep(knob))
        out.append(path)
    return out


def test_tracked_sweeps_give_the_plants_data_sheet(sweep_files: list[Path], tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "device.yaml"
    code = main(["datasheet", "--from-recording", *map(str, reversed(sweep_files)),
                 "--device-model", "unit-7", "--out", str(out),
                 "--config", str(Path(__file__).parents[1] / "tsmd" / "data" / "sim.yaml")])
    assert code == 0, capsys.readouterr().err
    measured = load_device_model(out)
    shipped = load_device_model(DEVICE)  # measured on the full simulated stack
    assert measured.device_model == "unit-7"
    for got, ref in zip(measured.knobs, shipped.knobs, strict=True):
        assert got.omega == pytest.approx(ref.omega, abs=0.1)
        assert got.reference_pos.tip_deg == pytest.approx(ref.reference_pos.tip_deg, abs=3.0)
        assert got.reference_neg.tip_deg == pytest.approx(ref.reference_neg.tip_deg, abs=3.0)
        assert got.reference_backlash_pos_deg == pytest.approx(ref.reference_backlash_pos_deg,
                                                               abs=3.0)
        assert got.limits == ref.limits
        assert got.handle_slip_deg == DEFAULT_HANDLE_SLIP_DEG  # the handle's design value
    assert out.read_text().count("handle_slip_deg") == 2  # the sheet carries it, per knob


def test_a_recording_without_tip_angles_is_refused_in_one_line(
        sweep_files: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = tracked_sweep(0)
    rec.columns["tip1"] = np.full(len(rec), np.nan)
    rec.columns["tip2"] = np.full(len(rec), np.nan)
    bare = tmp_path / "no-tip.csv"
    write_recording(bare, rec)
    code = main(["datasheet", "--from-recording", str(bare), str(sweep_files[1]),
                 "--device-model", "x", "--out", str(tmp_path / "d.yaml")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert "no-tip.csv" in err and "tip" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "d.yaml").exists()


def test_two_sweeps_of_the_same_knob_are_refused(
        sweep_files: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["datasheet", "--from-recording", str(sweep_files[0]), str(sweep_files[0]),
                 "--device-model", "x", "--out", str(tmp_path / "d.yaml")])
    assert code == 2
    assert "second sweep of knob 1" in capsys.readouterr().err


def test_plant_parameters_must_be_a_json_object(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["datasheet", "--plant", "simrig.plants.capstan:make_tendon_sheath_plant",
                 "--params", "[1, 2]", "--device-model", "x", "--out", str(tmp_path / "d.yaml")])
    assert code == 2
    assert "--params" in capsys.readouterr().err


def test_tip_measurements_skip_the_conditioning_cycle() -> None:
    """A data-sheet sweep's whole-pass part is 2.25 cycles of +-90 deg after the plant has been
    through every state once (its tension-free start is not the product's behaviour)."""
    assert CONDITIONING_CYCLES >= 1.0
    t, q = tip_sweep(1, 30.0, PERIOD_S)
    _, qq, skip = settle(t, q, PERIOD_S)
    first = analysed_from(skip, PERIOD_S)
    before, after = qq[skip:first, 1], qq[first:, 1]
    assert before.min() == pytest.approx(-90.0, abs=0.01)
    assert before.max() == pytest.approx(90.0, abs=0.01)
    assert after.size * PERIOD_S == pytest.approx(2.25 / 0.04, abs=2 * PERIOD_S)
    assert abs(after[0]) < 0.1 and after[1] > after[0]  # the same start as without conditioning
    assert np.all(qq[skip:, 0] == 30.0)  # the other knob held (reached during the settle move)


def test_a_tracked_sweep_gives_the_current_edges_and_backlash_gain(sweep_files: list[Path]
                                                                   ) -> None:
    """What method ours needs of the data-sheet unit, by calibration's own current analysis:
    its edges (product-constant plateaus) and its backlash gain (per-unit omega)."""
    shipped = load_device_model(DEVICE)
    for knob, path in enumerate(sweep_files):
        c = knob_constants(read_recording(path), knob)
        ref = shipped.knobs[knob]
        assert c.dead_zone_pos_deg == pytest.approx(ref.reference_dead_zone_pos_deg, abs=2.0)
        assert c.dead_zone_neg_deg == pytest.approx(ref.reference_dead_zone_neg_deg, abs=2.0)
        assert c.backlash_gain is not None and 0.05 < c.backlash_gain < 0.5
        sheet = c.device_knob(ref.limits)
        assert sheet.reference_backlash_gain == pytest.approx(c.backlash_gain, abs=1e-3)
        assert sheet.reference_dead_zone_pos_deg == pytest.approx(c.dead_zone_pos_deg, abs=0.01)


def test_a_tracked_sweep_gives_a_settle_lag_and_release_swing_the_sheet_carries(
        sweep_files: list[Path]) -> None:
    """The tip lets go after the current has settled (0.6-1.0 deg of knob on the full stack's
    capstan nominal, 2.9 deg on phi1 of this plant-only runner's 4 reversals: the lag belongs
    to the rig it is measured on), and the current swings after each reversal: both read on
    every reversal and carried by the sheet (docs/calibration.md, session 9)."""
    limits = load_device_model(DEVICE).knobs[0].limits
    for knob, path in enumerate(sweep_files):
        c = knob_constants(read_recording(path), knob)
        assert c.settle_lag_deg is not None and 0.0 < c.settle_lag_deg < 5.0
        assert c.release_swing_A is not None and c.release_swing_A > 0.0
        sheet = c.device_knob(limits)
        assert sheet.backlash_settle_lag_deg == pytest.approx(c.settle_lag_deg, abs=0.01)
        assert sheet.reference_release_swing_A == pytest.approx(c.release_swing_A, abs=1e-4)


def test_a_tracked_sweep_gives_the_line_share_the_sheet_carries(sweep_files: list[Path]) -> None:
    """The share of the gap to the release line at the tip's release (session 10): the capstan
    nominal's branch is flat and settled, so close to its settle fraction and to 1."""
    limits = load_device_model(DEVICE).knobs[0].limits
    for knob, path in enumerate(sweep_files):
        c = knob_constants(read_recording(path), knob)
        assert c.release_line_share is not None and 0.9 < c.release_line_share <= 1.05
        assert c.release_line_share == pytest.approx(c.backlash_settle_fraction, abs=0.03)
        sheet = c.device_knob(limits)
        assert sheet.backlash_release_line_share == pytest.approx(c.release_line_share,
                                                                  abs=1e-4)


def test_the_backlash_gain_uses_the_settle_rule_whatever_the_products_rule() -> None:
    """On a product whose current has not settled when the tip starts back (lumped: settle
    fraction < 0.99), calibration ends the paper's B at that fraction; the tension play's
    backlash gain of every unit comes from the settle rule (the straight release line starts
    where the release has settled), so the sheet's gain must too: one estimator."""
    from simrig.plants.lumped import make_lumped_plant
    from tsmd.calibration.identify import identify_sweep, settle_rule_backlash
    from tsmd.calibration.load_ramp import fit_sweep_sides
    from tsmd.calibration.options import IdentifyOptions, for_product

    runner = LockstepPlantRunner(make_lumped_plant(), PERIOD_S, seed=0)
    t, q, skip = settle(*tip_sweep(0, 0.0, PERIOD_S), PERIOD_S)
    rec = runner.run(t, q)
    first = analysed_from(skip, PERIOD_S)
    c = knob_constants(rec, 0, first)
    assert c.backlash_settle_fraction is not None and c.backlash_settle_fraction < 0.99
    keys = ("dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_pos_deg", "backlash_neg_deg")
    gains, backlash = {}, {}
    for name, options in (("settle", IdentifyOptions()),
                          # the knee off: with it the fraction's end on this sweep comes
                          # close to the settle rule's and the two gains no longer differ
                          ("product", replace(for_product(IdentifyOptions(),
                                                          c.backlash_settle_fraction),
                                              backlash_knee=False))):
        cur = identify_sweep(rec["t"][first:], rec["cmd1"][first:], rec["pos1"][first:],
                             rec["cur1"][first:], options)
        backlash[name] = (cur.estimate("backlash_pos_deg"), cur.estimate("backlash_neg_deg"))
        if name == "product":  # whatever rule the result used, the settle rule's B from its data
            assert settle_rule_backlash(cur.data) == pytest.approx(backlash["settle"], abs=0.3)
        sides = fit_sweep_sides(cur.data.pos_deg, cur.data.current_filtered_A,
                                *(cur.estimate(k) for k in keys))
        gains[name] = 0.5 * (sides[0].backlash_gain + sides[1].backlash_gain)
    assert abs(gains["product"] - gains["settle"]) > 0.01  # the two rules differ here
    assert c.backlash_gain == pytest.approx(gains["settle"], abs=0.005)


def test_the_sheets_sweep_has_enough_reversals_for_its_release_reads() -> None:
    """One reversal's release anchor scatters as much as the units' shares differ; the sheet
    reads it over at least 40 reversals at +-90 deg per knob (docs/calibration.md, s8-acc2)."""
    t, q = tip_sweep(0, 0.0, PERIOD_S, RELEASE_READ_CYCLES)
    _, qq, skip = settle(t, q, PERIOD_S)
    knob = qq[analysed_from(skip, PERIOD_S):, 0]
    turns = np.flatnonzero(np.diff(np.sign(np.diff(knob))) != 0)
    assert np.count_nonzero(np.abs(knob[turns + 1]) > 89.0) >= 40


def test_release_reads_take_every_reversal_and_whole_pass_constants_the_first_cycles() -> None:
    """``stop`` ends only the whole-pass constants (slopes, edges, gain: unchanged by a longer
    sweep); the share and slope ratio are read at every reversal of the recording."""
    from simrig.plants.lumped import make_lumped_plant

    runner = LockstepPlantRunner(make_lumped_plant(), PERIOD_S, seed=0)
    t, q, skip = settle(*tip_sweep(0, 0.0, PERIOD_S, 4.25), PERIOD_S)
    rec = runner.run(t, q)
    first = analysed_from(skip, PERIOD_S)
    stop = first + round(2.25 / 0.04 / PERIOD_S)
    long = knob_constants(rec, 0, first, stop)
    short = knob_constants(Recording({k: v[:stop] for k, v in rec.columns.items()},
                                     rec.metadata), 0, first)
    assert short.release_reversals == 4 and long.release_reversals == 8
    assert long.backlash_settle_fraction != short.backlash_settle_fraction
    for name in ("omega", "release_omega", "dead_zone_pos_deg", "dead_zone_neg_deg",
                 "backlash_gain", "dead_zone_offset_deg"):
        assert getattr(long, name) == getattr(short, name)


def test_the_loaded_shape_template_is_written_only_when_asked(sweep_files: list[Path],
                                                             tmp_path: Path) -> None:
    """On the family's held-out units the template did not improve ours' worst row, so a
    data sheet carries it only with ``--loaded-shape`` (docs/model.md, Session 10)."""
    sim_yaml = str(Path(__file__).parents[1] / "tsmd" / "data" / "sim.yaml")
    plain, shaped = tmp_path / "plain.yaml", tmp_path / "shaped.yaml"
    for out, extra in ((plain, []), (shaped, ["--loaded-shape"])):
        assert main(["datasheet", "--from-recording", *map(str, sweep_files), "--device-model",
                     "unit-7", "--out", str(out), "--config", sim_yaml, *extra]) == 0
    assert all(k.loaded_shape_pos is None and k.loaded_shape_neg is None
               for k in load_device_model(plain).knobs)
    assert any(k.loaded_shape_pos is not None or k.loaded_shape_neg is not None
               for k in load_device_model(shaped).knobs)


def _with_phi2(device: DeviceModel, **values: Any) -> DeviceModel:
    return replace(device, knobs=(device.knobs[0], replace(device.knobs[1], **values)))


def test_a_measured_read_the_schema_refuses_is_left_out_and_named() -> None:
    measured = _with_phi2(load_device_model(DEVICE), backlash_release_line_share=7.0,
                          backlash_release_local_share=0.98)
    sheet, dropped = readable(measured)
    assert sheet.knobs[1].backlash_release_line_share is None
    assert sheet.knobs[1].backlash_release_local_share == 0.98
    assert sheet.knobs[0] == measured.knobs[0]
    assert len(dropped) == 1 and "knobs.phi2.backlash_release_line_share" in dropped[0]


def test_a_tracked_release_the_calibration_could_not_use_is_left_out_and_named() -> None:
    device = load_device_model(DEVICE)
    knob = device.knobs[1]
    assert knob.reference_backlash_gain is not None
    release = (RELEASE_RATIO_RANGE[0] - 0.05) * knob.omega / (1.0 - knob.reference_backlash_gain)
    sheet, dropped = readable(_with_phi2(device, release_omega=release))
    assert sheet.knobs[1].release_omega is None
    assert sheet.knobs[1].reference_backlash_pos_deg == knob.reference_backlash_pos_deg
    assert sheet.knobs[0] == device.knobs[0]
    assert len(dropped) == 1 and "knobs.phi2.release_omega" in dropped[0]


def test_a_sheet_without_the_tracked_release_writes_its_reference_backlash(tmp_path: Path) -> None:
    device = load_device_model(DEVICE)
    save_device_model(_with_phi2(device, release_omega=None), tmp_path / "sheet.yaml")
    knob = load_device_model(tmp_path / "sheet.yaml").knobs[1]
    assert knob.release_omega is None
    assert knob.reference_backlash_pos_deg == device.knobs[1].reference_backlash_pos_deg


def test_a_measured_sheet_invalid_beyond_its_optional_reads_is_one_error() -> None:
    with pytest.raises(DatasheetError, match="knobs.phi2.omega"):
        readable(_with_phi2(load_device_model(DEVICE), omega=-1.0))


def test_a_line_share_past_the_release_line_is_written_and_read_back(tmp_path: Path) -> None:
    """A handle that is harder to back-drive than to drive (a self-locking screw) moves the
    current past the release line before the tip lets go: a share above 1 is a measurement."""
    sheet, dropped = readable(_with_phi2(load_device_model(DEVICE),
                                         backlash_release_line_share=1.06))
    save_device_model(sheet, tmp_path / "sheet.yaml")
    assert dropped == []
    assert load_device_model(tmp_path / "sheet.yaml").knobs[1].backlash_release_line_share == 1.06
