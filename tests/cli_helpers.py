"""Helpers shared by the report tests: run the CLI in-process, and the report's JSON checked against the schema."""

from __future__ import annotations

import contextlib
import io
import json

from jsonschema import Draft202012Validator

from pfm_stability.cli import main
from pfm_stability.schema import load_schema

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
