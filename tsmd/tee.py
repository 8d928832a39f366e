"""Convert one real TEE probe acquisition (CSV) into the tsmd recording format.

The TEE data (``../shared/data/tee``, see its README) were logged by a stepper-driven robot on a
transesophageal echo probe: a sample index, motor steps, raw motor current and two EM sensor poses
(tip and base). It carries no timestamps and no step-to-knob ratio, so both are documented
assumptions here, exposed as parameters:

* ``DEFAULT_SAMPLE_PERIOD_S`` = 0.02 s (50 Hz): one triangle cycle is 1160-1440 samples; the
  paper's rig sweeps one cycle in 25 s (0.04 Hz), i.e. 17-22 ms per sample, and 50 Hz is the round
  rate in that range. It keeps the paper's 20 Hz Butterworth cutoff below Nyquist.
* ``DEFAULT_STEPS_PER_KNOB_DEG`` = 16: outside the dead zone and backlash the tracked tip turns
  0.082-0.087 deg per motor step on knob 1 (both directions, three acquisitions). The paper's
  data-sheet slope tip/knob is omega = 1.32 (mean of four catheters), so one knob degree is
  1.32 / 0.084 = 15.7 steps; 16 is that figure rounded. With it knob 1 sweeps about +-37 knob deg.
  Knob 2's positive side is steeper (0.106 deg/step, slope 1.66 with this ratio): reported as is.

Current: raw driver units x 2.69 mA (the source's identification script), stored in amperes.
Tip angle: the tip's rotation relative to the base, ``R_base^-1 R_tip``, taken relative to the
first sample (``R_rel(0)^-1 R_rel(t)``) as a rotation vector, projected on the bending axis (the
principal axis of the rotation vectors), signed so that it increases with the knob angle.
"""

from __future__ import annotations

import csv
import io
import os
import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tsmd.recording import Recording, RecordingError

DEFAULT_SAMPLE_PERIOD_S = 0.02
"""Assumed sample period (no timestamps were logged); see the module docstring."""

DEFAULT_STEPS_PER_KNOB_DEG = 16.0
"""Assumed motor steps per knob degree (the source gives none); see the module docstring."""

CURRENT_A_PER_RAW = 2.69e-3
"""Raw driver current unit in amperes (the source's script: raw x 2.69 = mA)."""

TEE_DATA_ENV = "TSMD_TEE_DATA"
"""Environment variable naming the TEE data directory (tests and benches)."""

_STEPS_COL = "Motor position"
_CURRENT_COL = "Current"
_TIP_Q_COLS = ("Tip orientation x", "Tip orientation y", "Tip orientation z",
               "Tip orientation w")
_BASE_Q_COLS = ("Base orientation x", "Base orientation y", "Base orientation z",
                "Base orientation w")

_MIN_ROWS = 10


def default_tee_dir() -> Path:
    """``$TSMD_TEE_DATA`` or the shared data directory beside the repository (``../shared``)."""
    env = os.environ.get(TEE_DATA_ENV)
    if env:
        return Path(env)
    repo = Path(__file__).resolve().parent.parent
    return repo.parent / "shared" / "data" / "tee"


def knob_from_filename(path: str | os.PathLike[str]) -> int:
    """The knob a TEE file moves, from its name (``motor1_...`` -> 1, ``motor2_...`` -> 2)."""
    match = re.match(r"motor([12])_", Path(path).name)
    if match is None:
        raise RecordingError(
            f"{path}: cannot tell the knob from the file name; pass knob=1 or knob=2")
    return int(match.group(1))


def load_tee_acquisition(path: str | os.PathLike[str], *,
                         steps_per_knob_deg: float = DEFAULT_STEPS_PER_KNOB_DEG,
                         knob: int | None = None,
                         sample_period_s: float = DEFAULT_SAMPLE_PERIOD_S) -> Recording:
    """Read one TEE CSV and return it as a :class:`Recording` (knob deg, A, tip deg).

    ``q``, ``cmd`` and ``pos`` of the moved knob all hold the logged motor position (the source
    logs one position), relative to the first sample; the other knob's columns are 0.
    """
    p = Path(path)
    if knob is None:
        knob = knob_from_filename(p)
    if knob not in (1, 2):
        raise RecordingError(f"knob must be 1 or 2, got {knob!r}")
    if not (np.isfinite(steps_per_knob_deg) and steps_per_knob_deg > 0):
        raise RecordingError(f"steps_per_knob_deg must be > 0, got {steps_per_knob_deg!r}")
    if not (np.isfinite(sample_period_s) and sample_period_s > 0):
        raise RecordingError(f"sample_period_s must be > 0, got {sample_period_s!r}")
    try:
        text = p.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise RecordingError(f"{p}: cannot read: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise RecordingError(f"{p}: not UTF-8 text ({exc.reason})") from exc
    table = _parse_table(text, str(p))

    steps = table[_STEPS_COL]
    raw_current = table[_CURRENT_COL]
    q_tip = np.column_stack([table[c] for c in _TIP_Q_COLS])
    q_base = np.column_stack([table[c] for c in _BASE_Q_COLS])
    for name, quat in (("tip", q_tip), ("base", q_base)):
        norms = np.linalg.norm(quat, axis=1)
        bad = np.flatnonzero(np.abs(norms - 1.0) > 0.05)
        if bad.size:
            raise RecordingError(
                f"{p}: row {int(bad[0]) + 1}: {name} orientation is not a unit quaternion "
                f"(norm {norms[bad[0]]:.3f})")

    knob_deg = (steps - steps[0]) / steps_per_knob_deg
    tip_deg = bending_angle_deg(q_base, q_tip, knob_deg)
    n = len(steps)
    zeros = np.zeros(n)
    moved, other = (1, 2) if knob == 1 else (2, 1)
    columns: dict[str, NDArray[np.float64]] = {
        "t": np.arange(n, dtype=float) * float(sample_period_s)}
    for prefix in ("q", "cmd", "pos"):
        columns[f"{prefix}{moved}"] = knob_deg.copy()
        columns[f"{prefix}{other}"] = zeros.copy()
    columns[f"cur{moved}"] = raw_current * CURRENT_A_PER_RAW
    columns[f"cur{other}"] = zeros.copy()
    columns[f"tip{moved}"] = tip_deg
    columns[f"tip{other}"] = zeros.copy()
    columns["steps"] = steps.copy()
    ordered = {k: columns[k] for k in ("t", "q1", "q2", "cmd1", "cmd2", "pos1", "pos2",
                                       "cur1", "cur2", "tip1", "tip2", "steps")}
    metadata = {
        "source": f"TEE acquisition {p.name}",
        "knob": str(knob),
        "steps_per_knob_deg": repr(float(steps_per_knob_deg)),
        "sample_period_s": repr(float(sample_period_s)),
        "start_steps": repr(float(steps[0])),
        "current_A_per_raw": repr(CURRENT_A_PER_RAW),
        "assumptions": "sample period and steps per knob degree assumed (not in the source)",
    }
    return Recording(ordered, metadata)


def bending_angle_deg(q_base_xyzw: NDArray[np.float64], q_tip_xyzw: NDArray[np.float64],
                      knob_deg: NDArray[np.float64]) -> NDArray[np.float64]:
    """Tip bending angle (deg) relative to the first sample, on the principal bending axis.

    The sign is chosen so that the angle increases with ``knob_deg`` (positive correlation).
    """
    rel = Rotation.from_quat(q_base_xyzw).inv() * Rotation.from_quat(q_tip_xyzw)
    rotvec = (rel[0].inv() * rel).as_rotvec()
    _, _, vt = np.linalg.svd(rotvec, full_matrices=False)
    angle = np.degrees(rotvec @ vt[0])
    if np.std(knob_deg) > 0 and np.std(angle) > 0 and np.corrcoef(angle, knob_deg)[0, 1] < 0:
        angle = -angle
    return np.asarray(angle, dtype=float)


def _parse_table(text: str, source: str) -> dict[str, NDArray[np.float64]]:
    reader = csv.reader(io.StringIO(text))
    try:
        header = [h.strip() for h in next(reader)]
    except StopIteration:
        raise RecordingError(f"{source}: empty file") from None
    wanted = [_STEPS_COL, _CURRENT_COL, *_TIP_Q_COLS, *_BASE_Q_COLS]
    missing = [c for c in wanted if c not in header]
    if missing:
        raise RecordingError(f"{source}:1: not a TEE acquisition: missing column(s) "
                             f"{', '.join(repr(m) for m in missing)}")
    index = {name: header.index(name) for name in wanted}
    rows: list[list[float]] = []
    for lineno, row in enumerate(reader, start=2):
        if not row or all(not cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise RecordingError(f"{source}:{lineno}: {len(row)} cells, header has {len(header)}")
        values = []
        for name in wanted:
            cell = row[index[name]].strip()
            try:
                value = float(cell)
            except ValueError:
                raise RecordingError(
                    f"{source}:{lineno}: column {name!r}: {cell!r} is not a number") from None
            if not np.isfinite(value):
                raise RecordingError(f"{source}:{lineno}: column {name!r} is {cell!r}")
            values.append(value)
        rows.append(values)
    if len(rows) < _MIN_ROWS:
        raise RecordingError(f"{source}: only {len(rows)} data rows (need >= {_MIN_ROWS})")
    data = np.asarray(rows, dtype=float)
    return {name: data[:, j].copy() for j, name in enumerate(wanted)}
