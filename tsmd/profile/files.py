"""Profiles and data sheets on disk: read and validated, written atomically with the previous
file kept as ``<file>.bak``; the profile store of one directory."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml

from tsmd.profile.device import DeviceModel
from tsmd.profile.schema import plain_values, profile_from_mapping, profile_to_mapping
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping
from tsmd.profile.types import ID_PATTERN, KNOB_NAMES, CatheterProfile, ProfileError
from tsmd.yamlfile import parse_yaml, read_yaml


def _read_yaml(path: Path) -> Any:
    return read_yaml(path, ProfileError)


def load_device_model(path: str | os.PathLike[str]) -> DeviceModel:
    """Read and validate a device model (data-sheet constants) from YAML."""
    return device_model_from_mapping(_read_yaml(Path(path)), str(path))


def load_profile(path: str | os.PathLike[str]) -> CatheterProfile:
    """Read and validate a catheter profile; any defect of the file is one ProfileError line."""
    data = _read_yaml(Path(path))
    try:
        return profile_from_mapping(data, str(path))
    except RecursionError:
        raise ProfileError(f"{path}: nested too deeply to be a profile") from None


def dump_profile(profile: CatheterProfile) -> str:
    header = (f"# tsmd catheter profile, schema version {profile.schema_version}\n"
              f"# source: {profile.source}\n")
    return header + yaml.safe_dump(plain_values(profile_to_mapping(profile)), sort_keys=False,
                                   default_flow_style=None, width=100)


def save_profile(profile: CatheterProfile, path: str | os.PathLike[str]) -> None:
    """Write atomically: temp file in the same directory, fsync, keep the old file as .bak,
    rename over, fsync the directory. A crash at any point leaves a complete profile on disk."""
    target = Path(path)
    text = dump_profile(profile)
    profile_from_mapping(yaml.safe_load(text), str(target))  # never write what we cannot read
    _write_atomically(target, text)


def save_device_model(device: DeviceModel, path: str | os.PathLike[str],
                      comment: str = "") -> None:
    """Write a data sheet atomically (as :func:`save_profile`), ``comment`` as its YAML header."""
    target = Path(path)
    header = "".join(f"# {line}\n".replace("# \n", "#\n") for line in comment.splitlines())
    text = header + yaml.safe_dump(plain_values(device_model_to_mapping(device)), sort_keys=False,
                                   allow_unicode=True)
    device_model_from_mapping(yaml.safe_load(text), str(target))  # never write what we cannot read
    _write_atomically(target, text)


def save_device_fields(source: str | os.PathLike[str], device: DeviceModel,
                       keys: Sequence[str], path: str | os.PathLike[str], comment: str) -> None:
    """Write the data sheet ``source`` to ``path`` (atomically, as :func:`save_device_model`)
    with each knob's scalar fields ``keys`` as in ``device`` and every other line as it was:
    its header, then ``comment``, then its body with only those fields' lines changed. Refused
    in one line when the result would read other than ``device``."""
    text = Path(source).read_text(encoding="utf-8")
    lines = text.splitlines(keepends=True)
    head = next((i for i, line in enumerate(lines) if not line.startswith("#")), len(lines))
    body = lines[head:]
    for name, knob in zip(KNOB_NAMES, device.knobs, strict=True):
        start, end = _knob_block(body, name, str(source))
        kept = [line for line in body[start:end] if line.split(":")[0].strip() not in keys]
        added = [f"    {key}: {float(v)!r}\n" for key in keys
                 if (v := getattr(knob, key)) is not None]
        body[start:end] = kept + added
    new = ("".join(lines[:head])
           + "".join(f"# {line}\n".replace("# \n", "#\n") for line in comment.splitlines())
           + "".join(body))
    if device_model_from_mapping(parse_yaml(new, str(path), ProfileError), str(path)) != device:
        raise ProfileError(f"{source}: its fields other than {', '.join(keys)} would change; "
                           "not written")
    _write_atomically(Path(path), new)


def _knob_block(body: list[str], name: str, source: str) -> tuple[int, int]:
    """The lines of knob ``name``'s mapping under ``knobs:`` (after its own line, up to the next
    line indented less than its fields)."""
    try:
        top = body.index("knobs:\n")
        start = body.index(f"  {name}:\n", top) + 1
    except ValueError:
        raise ProfileError(f"{source}: no knobs.{name} block as tsmd writes it (two-space "
                           "indents)") from None
    end = next((i for i in range(start, len(body))
                if body[i].strip() and not body[i].startswith("    ")), len(body))
    while end > start and not body[end - 1].strip():
        end -= 1
    return start, end


def _write_atomically(target: Path, text: str) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        if target.exists():
            backup = target.with_name(target.name + ".bak")
            # A hard link keeps the old file under the backup name while the target name
            # still points at it; replace() then swaps the target in one step.
            with contextlib.suppress(FileNotFoundError):
                backup.unlink()
            try:
                os.link(target, backup)
            except OSError:  # no hard links on this file system: copy instead
                shutil.copy2(target, backup)
        os.replace(tmp_name, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp_name)
        raise
    _fsync_dir(target.parent)


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


class ProfileStore:
    """Profiles kept as ``<dir>/<catheter_id>.yaml``."""

    def __init__(self, directory: str | os.PathLike[str]) -> None:
        self.directory = Path(directory)

    def path(self, catheter_id: str) -> Path:
        if not ID_PATTERN.match(catheter_id):
            raise ProfileError(
                f"catheter id {catheter_id!r} must be letters, digits, '.', '_' or '-'")
        return self.directory / f"{catheter_id}.yaml"

    def load(self, catheter_id: str) -> CatheterProfile:
        path = self.path(catheter_id)
        if not path.exists():
            raise ProfileError(f"no profile for catheter {catheter_id!r} in {self.directory}")
        profile = load_profile(path)
        # <id>.<version>.yaml (e.g. an online re-estimate) is a version of catheter <id>
        if profile.catheter_id != catheter_id \
                and not catheter_id.startswith(profile.catheter_id + "."):
            raise ProfileError(f"{path}: catheter_id is {profile.catheter_id!r}, "
                               f"expected {catheter_id!r}")
        return profile

    def save(self, profile: CatheterProfile) -> Path:
        path = self.path(profile.catheter_id)
        try:
            save_profile(profile, path)
        except OSError as exc:
            raise ProfileError(f"{path}: cannot save ({exc.strerror or exc}); the previous "
                               "profile, if any, is unchanged") from None
        return path

    def list(self) -> list[str]:
        if not self.directory.is_dir():
            return []
        return sorted(p.stem for p in self.directory.glob("*.yaml")
                      if ID_PATTERN.match(p.stem) and p.is_file())
