"""Helpers shared by the report tests: run the CLI in-process, and the report's JSON checked against the schema."""

from __future__ import annotations

import contextlib
import io
import json

from jsonschema import Draft202012Validator

from pfm_stability.cli import main
from pfm_stability.io.schema import load_schema

VALIDATOR = Draft202012Validator(load_schema())


def run(argv) -> tuple[int, str, str]:
    """(exit status, stdout, stderr) of ``pfm-stability ARGV`` run in this process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def report_json(argv) -> dict:
    """The report's JSON, after checking exit 0 and the shipped schema."""
    code, out, err = run(["report", *argv, "--format", "json"])
    assert code == 0, err
    data = json.loads(out)
    errors = [f"{list(e.absolute_path)}: {e.message[:200]}" for e in VALIDATOR.iter_errors(data)]
    assert not errors, errors[:3]
    return data


class DiskFull(io.FileIO):
    """A new file on a disk with `room` bytes left: writes beyond it write what fits, then fail with ENOSPC."""

    def __init__(self, path, room: int):
        super().__init__(path, "wb")
        self.room = room

    def write(self, data):
        view = memoryview(data).cast("B")
        if len(view) > self.room:
            if self.room:
                super().write(view[: self.room])
                self.room = 0
            import errno
            import os

            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.room -= len(view)
        return super().write(view)


@contextlib.contextmanager
def disk_full(room: int):
    """Every file the package writes (`pfm_stability.io.files.open_new`, the one place it opens one) lands on a full disk."""
    import pfm_stability.io.files as files

    def open_new(path, mode):
        raw = DiskFull(path, room)
        return raw if "b" in mode else io.TextIOWrapper(raw, encoding="utf-8")

    saved = files.open_new
    files.open_new = open_new
    try:
        yield
    finally:
        files.open_new = saved
