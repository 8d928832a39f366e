"""The product's bend relation, measured on the data sheet's unit (`tsmd datasheet
--bend-relation`).

Online re-estimation sees a tendon's dead-zone edge in the current under compensated motion, not
its release line (docs/online.md, session 10). How far a sheath bend moves the release line per
degree of edge move, and how much beta grows with it, is a property of the product's
construction (one number per product over units and bend angles, session 11), so the
manufacturer measures it where the other constants are measured: the sheet's unit calibrated
from current (fast protocol, the sheet's own rule) straight and with its sheath bent 30, 60 and
90 deg (:func:`tsmd.online.bend.measure_bend_relation`). Four calibrations: optional, since it
adds minutes to the sheet.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from simrig.plant import Plant, PlantLoadError
from simrig.scenario import ShapeChange, ShapeChangePlant
from tsmd.calibration import fast_protocol
from tsmd.calibration.errors import CalibrationRefusedError
from tsmd.calibration.run import calibrate
from tsmd.config import TsmdConfig
from tsmd.errors import TsmdError
from tsmd.online.apply import OnlineError
from tsmd.online.bend import BendRelation, measure_bend_relation, with_bend_relation
from tsmd.profile import CatheterProfile, DeviceModel
from tsmd.replay import LockstepRunner

BENDS_DEG = (30.0, 60.0, 90.0)
"""Sheath bends the sheet's unit is calibrated at besides straight (session 11's set)."""
BEND_SEED = 3000
"""Noise seed of the sheet unit's calibrations (the bench's seed for unit 0)."""

CalibrateBent = Callable[[float], CatheterProfile]
"""A unit's calibration with its sheath bent by the given angle (0: straight)."""


ReadSlopes = Callable[[CatheterProfile, float], tuple[float, float]]
"""Each knob's loaded-slope rise a bend of the given angle shows online under the straight
profile (:func:`tsmd.datasheet_bend_slope.rig_slope_reader`)."""


def bend_relation(calibrate_bent: CalibrateBent,
                  bends_deg: Sequence[float] = BENDS_DEG,
                  read_slopes: ReadSlopes | None = None) -> BendRelation:
    """The relation from one unit calibrated straight and at ``bends_deg``; a bend whose
    calibration is refused is left out (an OnlineError in one line when none is left). With
    ``read_slopes``, each bend's slope rise too (the release move per slope rise of a bend
    that moves no edge)."""
    straight = calibrate_bent(0.0)
    bent, rises = [], []
    for deg in bends_deg:
        try:
            bent.append(calibrate_bent(deg))
        except CalibrationRefusedError:
            continue
        if read_slopes is not None:
            rises.append(read_slopes(straight, deg))
    return measure_bend_relation(straight, bent, rises if read_slopes is not None else None)


def sheet_with_bend(device: DeviceModel, calibrate_bent: CalibrateBent,
                    bends_deg: Sequence[float] = BENDS_DEG,
                    read_slopes: ReadSlopes | None = None) -> tuple[DeviceModel, str]:
    """The sheet with the product's relation and a line saying what it is; a product whose
    bends move no edge (stickslip unit 0, session 13: 0.5 deg nowhere) has none, and the sheet
    measured before it is kept without one rather than lost (the daemon then moves x0 with
    the edge, as for any sheet without a relation)."""
    try:
        bend = bend_relation(calibrate_bent, bends_deg, read_slopes)
    except OnlineError as exc:
        return device, f"no bend relation on the sheet: {exc}"
    return with_bend_relation(device, bend), (
        f"bend relation on the sheet's unit (straight and "
        f"{'/'.join(f'{b:g}' for b in bends_deg)} deg): release line "
        f"{bend.release_per_edge:.3f} deg per edge deg, beta x (1 + "
        f"{bend.gain_per_release_deg:.4f} per release deg)"
        + ("" if not bend.gain_per_slope else
           f"; without an edge move beta x (1 + {bend.gain_per_slope:.3f} per slope rise)")
        + ("" if bend.omega_per_gain is None else
           f", omega x (1 + {bend.omega_per_gain:.3f} per relative beta change)"))


def rig_calibration(factory: Callable[[], Plant], device: DeviceModel, config: TsmdConfig,
                    seed: int = BEND_SEED) -> CalibrateBent:
    """Calibrations of the simulated rig's plant under ``device``'s sheet, bent on demand."""

    def run(bend_deg: float) -> CatheterProfile:
        changes = [ShapeChange(0.0, {"sheath_curvature_deg": bend_deg})] if bend_deg else []
        try:
            plant = ShapeChangePlant(factory(), changes)
        except PlantLoadError as exc:
            raise TsmdError(f"--bend-relation: {exc}") from None
        with LockstepRunner(config, None, "none", seed, plant) as runner:
            return calibrate(runner, f"{device.device_model}-bend-{bend_deg:g}", device,
                             protocol=fast_protocol())

    return run


__all__ = ["BENDS_DEG", "BEND_SEED", "CalibrateBent", "ReadSlopes", "bend_relation",
           "rig_calibration", "sheet_with_bend"]
