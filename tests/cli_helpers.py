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


WHOLE_FILE = ("the file", "not valid YAML", "none of", "must be", "key ")
"""How the details about a whole file start (no key of its own)."""


def file_error(message: str, origin: str, path=None) -> str:
    """The detail of a file's one-line error ``<origin>, line <n>: <detail>``, after checking its form.

    With `path` (the file), the line is checked to be the one that holds the key the detail starts with
    (``robot.V must be …``: a line with ``V:``); a detail about the whole file (its shape, its YAML, keys not
    found: `WHOLE_FILE`) only needs a line of the file (or the one after it, where YAML found the end too soon).
    This is what `pfm_stability.io.yaml_files` promises for every file it reads.
    """
    import re

    from pfm_stability.io.yaml_files import leading_key

    match = re.fullmatch(rf"{re.escape(origin)}, line (\d+): (.*)", message)
    assert match, f"not '<{origin}>, line N: …': {message!r}"
    line, detail = int(match[1]), match[2]
    if path is not None:
        lines = open(path, encoding="utf-8").read().splitlines()
        assert 1 <= line <= len(lines) + 1, (line, message)
        key = leading_key(detail)
        if detail.startswith(WHOLE_FILE) or key is None:
            return detail
        name = re.split(r"[.\[]", key.rstrip("]"))[-1]
        assert re.search(rf"(^|[\s{{,-])'?{re.escape(name)}'?\s*:", lines[line - 1]), f"line {line} {lines[line - 1]!r} does not hold {key}: {message}"
    return detail
