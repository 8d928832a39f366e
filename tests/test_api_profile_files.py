"""The ``profile`` command on broken files: a ``profile`` error, one line, no file bytes."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.api import start_stack, stop_stack
from support.profiles import make_profile

from tsmd.profile import ProfileStore

SECRET = b"\xff\xfeSECRET-BYTES"


def broken_files(store: Path) -> dict[str, bytes]:
    ProfileStore(store).save(make_profile("whole"))
    whole = (store / "whole.yaml").read_bytes()
    return {"not-utf8": b"catheter_id: not-utf8\n# " + SECRET + b"\n",
            "deep": b"knobs: " + b"[" * 500 + b"]" * 500 + b"\n",
            "truncated": whole[: len(whole) // 2],
            "garbage": b"{{{{: ::: ]]\n" + SECRET[2:]}


@pytest.mark.parametrize("catheter", ["not-utf8", "deep", "truncated", "garbage"])
def test_a_broken_profile_file_answers_code_profile_in_one_line(
        tmp_path: Path, catheter: str, capsys: pytest.CaptureFixture[str]) -> None:
    store = tmp_path / "store"
    store.mkdir()
    for name, data in broken_files(store).items():
        (store / f"{name}.yaml").write_bytes(data)
    stack = start_stack(tmp_path, profiles_dir=store)
    try:
        with stack.client() as client:
            response = client.request("profile", catheter=catheter)
            assert response["ok"] is False
            assert response["error"]["code"] == "profile", response
            message = response["error"]["message"]
            assert "\n" not in message and f"{catheter}.yaml" in message
            assert "SECRET" not in message
            assert client.call("status")["profile"] is None  # nothing half-loaded
    finally:
        stop_stack(stack)
    captured = capsys.readouterr()
    assert "SECRET" not in captured.out + captured.err
    assert "Traceback" not in captured.out + captured.err
