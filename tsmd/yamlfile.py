"""Reading a YAML file that a person wrote: every way it can be wrong is one line of text.

Configurations and catheter profiles both come from hand-edited or copied files; an invalid
byte, a truncated document (the parser's multi-line excerpt) or a document nested hundreds of
levels deep (RecursionError) must never reach the operator as a traceback or echo the file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml


def read_yaml(path: str | Path, error: type[Exception]) -> Any:
    """The parsed document of ``path``, or ``error`` naming the file and the problem."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(f"{p}: cannot read: no such file") from None
    except IsADirectoryError:
        raise error(f"{p}: is a directory, not a file") from None
    except OSError as exc:
        raise error(f"{p}: cannot read: {exc.strerror or type(exc).__name__}") from None
    except UnicodeDecodeError as exc:
        raise error(f"{p}: not UTF-8 text (invalid byte at offset {exc.start})") from None
    return parse_yaml(text, str(p), error)


def parse_yaml(text: str, source: str, error: type[Exception]) -> Any:
    """YAML text -> data, or ``error`` with one line: the source, the line and the problem."""
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark is not None else ""
        problem = str(getattr(exc, "problem", None) or type(exc).__name__).splitlines()[0]
        raise error(f"{source}: not valid YAML{where}: {problem}") from None
    except RecursionError:
        raise error(f"{source}: not valid YAML: nested too deeply") from None
