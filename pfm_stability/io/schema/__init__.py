"""The JSON Schema of the command line's JSON output.

``output.schema.json`` (JSON Schema draft 2020-12) describes what
``pfm-stability report|simulate|validate --format json`` print: every
output carries ``schema_version`` (`pfm_stability.io.serialize.SCHEMA_VERSION`)
and ``command``; a number that may be infinite is written as the string
``"inf"`` or ``"-inf"`` and an undefined one as ``null``
(`pfm_stability.io.serialize.json_number`); wall-clock times live under
``timing`` only, so the rest of an output is the same from run to run.
"""

from __future__ import annotations

import json
from importlib import resources

__all__ = ["SCHEMA_FILE", "load_schema"]

SCHEMA_FILE = "output.schema.json"
"""File name of the schema inside this package."""


def load_schema() -> dict:
    """The output schema as a dict (read from the installed package data).

    Returns
    -------
    dict
        JSON Schema (draft 2020-12) of every command's ``--format json`` output.
    """
    return json.loads(resources.files(__name__).joinpath(SCHEMA_FILE).read_text(encoding="utf-8"))
