"""Bench caches keyed by the code that fills them.

A bench that caches calibrated profiles must never reuse profiles made by older calibration
code: session 9 found a cache whose lumped profiles came from the calibration of two sessions
before, so its figures did not compare with a fresh run. The key is a hash of every source
file a profile depends on (calibration, data sheet, loop, drivers, the simulated plants); the
modules a cached profile never passes through (benches, online estimation, gap diagnosis,
compensators: calibration runs with none) are left out so that working on them keeps the cache.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("tsmd", "simrig", "drivers")
NOT_IN_PROFILES = ("tsmd/bench", "tsmd/online", "tsmd/gap", "tsmd/compensation")


def source_files(root: Path = ROOT, packages: Iterable[str] = PACKAGES,
                 excluded: Iterable[str] = NOT_IN_PROFILES) -> list[Path]:
    """The ``.py`` files of ``packages`` under ``root`` outside ``excluded``, in a fixed order."""
    skip = tuple(root / e for e in excluded)
    files = [p for pkg in packages for p in (root / pkg).rglob("*.py")
             if not any(p.is_relative_to(s) for s in skip)]
    return sorted(files)


def code_key(files: Iterable[Path], root: Path = ROOT) -> str:
    """12 hex digits of a hash over each file's path (relative to ``root``) and contents."""
    digest = hashlib.sha256()
    for path in files:
        digest.update(str(path.relative_to(root)).encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()[:12]


def keyed_cache(cache: Path) -> Path:
    """``cache``'s subdirectory for the code as it is now."""
    return cache / f"code-{code_key(source_files())}"


__all__ = ["code_key", "keyed_cache", "source_files"]
