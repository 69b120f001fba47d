"""The one YAML reader: configuration files, sweep specs, scenes, presets, map metadata and the fuzzy tables.

Every YAML file the package reads goes through `read_yaml`, so all of them read values
and word their errors the same way.

Numbers
    A plain (unquoted) scalar written as a decimal number is a number, with or without a
    dot and with or without an exponent: ``0.1``, ``1e-3``, ``1E-3``, ``-2e+1``, ``.5e1``
    (YAML 1.2's rule). Plain YAML 1.1, PyYAML's default, reads ``1e-3`` as the text
    '1e-3' because it has no dot, and a range check then refuses a valid value as a wrong
    type. The rule is applied once, here, when the file is parsed: every reader and every
    library function that takes a mapping sees the same types. A quoted scalar
    (``'1e-3'``) is text, as YAML says, and is refused where a number is expected
    (``got '1e-3'``): the user wrote text on purpose.
Keys
    A key given twice in one mapping is an error (plain YAML keeps the last silently).
Errors
    One line, the `InputError`: the file as the reader calls it (``config robot.yaml``,
    ``spec study.yaml``, ``scene hall.yaml``, ``map depot.yaml``, ``preset carmel.yaml``,
    ``fuzzy tables dfapf.yaml``), the line of the key concerned (`YamlFile.line_of`: the
    key's own line, else that of the nearest enclosing key the file has), then the key and
    the problem::

        spec study.yaml, line 7: grid.V.from: V must be a finite number in (0, 100] m/s; got -1.0
        config robot.yaml, line 2: robot.V must be a finite number in (0, 100] m/s; got -1
        config robot.yaml: cannot read the file (No such file or directory)

    A mapping given in code has no lines: ``spec: grid.V.from: …``.

PyYAML is imported on first use, not with this module, so the command line starts
without it. No numpy.
"""

from __future__ import annotations

import functools
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["InputError", "YamlFile", "read_yaml", "parse_yaml", "mapping_source", "leading_key"]

_NUMBER = re.compile(r"^[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)[eE][-+]?[0-9]+$")
"""A decimal number with an exponent, with or without a dot: the floats YAML 1.1 leaves as text."""

_KEY_PART = re.compile(r"\[(\d+)\]|([^.\[\]]+)")
_LEADING_KEY = re.compile(r"^[A-Za-z_][\w-]*(?:\[\d+\]|\.[A-Za-z_][\w-]*)*")


class InputError(ValueError):
    """A value of an input file (or of a mapping given in code) that is refused, with where it is.

    ``str()`` is the one-line message the command line prints: ``<origin>, line <line>: <detail>``,
    ``<origin>: <detail>`` without a line, `detail` alone without an origin.

    Parameters
    ----------
    detail : str
        The problem, naming the key (``robot.V must be …``).
    origin : str, optional
        The file as the reader calls it (``config robot.yaml``), or a mapping's name (``spec``).
    key : str, optional
        The key concerned (``grid.V.from``, ``obstacles[0].circle.radius``), for its line.
    line : int, optional
        Its line in the file (1-based).
    """

    def __init__(self, detail: str, *, origin: str | None = None, key: str | None = None, line: int | None = None):
        self.detail, self.origin, self.key, self.line = detail, origin, key, line
        super().__init__(self._text())

    def _text(self) -> str:
        if self.origin is None:
            return self.detail
        return f"{self.origin}{f', line {self.line}' if self.line is not None else ''}: {self.detail}"

    def __str__(self) -> str:
        return self._text()

    def __reduce__(self):
        return (_rebuild, (self.detail, self.origin, self.key, self.line))


def _rebuild(detail, origin, key, line):
    return InputError(detail, origin=origin, key=key, line=line)


def leading_key(message: str) -> str | None:
    """The key a message starts with (``law.rho0`` of ``law.rho0 must be …``), or None.

    For readers whose checks word their messages key first (scenes, map metadata) and raise a plain ValueError.

    Parameters
    ----------
    message : str
        An error message.
    """
    match = _LEADING_KEY.match(message)
    return match.group(0) if match else None


def _parts(key) -> tuple:
    """``"grid.V.from"`` → ``("grid", "V", "from")``; ``"obstacles[0].circle"`` → ``("obstacles", 0, "circle")``; a tuple as it is."""
    if isinstance(key, tuple):
        return key
    return tuple(int(index) if index else name for index, name in _KEY_PART.findall(str(key)))


@dataclass(frozen=True)
class YamlFile:
    """A YAML document read by `read_yaml`: its data and the line of every key.

    Attributes
    ----------
    data : object
        The document (mappings are dicts, sequences lists; None for an empty file).
    origin : str or None
        How messages name it: ``"<kind> <path>"``, or a mapping's name (`mapping_source`).
    path : str or None
        The file.
    lines : dict
        Key path (a tuple of keys and list indices) → 1-based line; ``()`` is the document.
    """

    data: object
    origin: str | None
    path: str | None = None
    lines: dict = field(default_factory=dict, repr=False)

    def line_of(self, key) -> int | None:
        """The line of `key` (``"grid.V.from"`` or a tuple), else of the nearest enclosing key the file has.

        A key that starts with the file's kind (``scene.region`` in a scene) is looked up without it.
        None for a mapping given in code.

        Parameters
        ----------
        key : str or tuple
            A dotted key (``"grid.V.from"``) or a tuple of keys.
        """
        if not self.lines:
            return None
        parts = _parts(key) if key is not None else ()
        kind = (self.origin or "").split(" ", 1)[0]
        if parts and parts[0] == kind and parts not in self.lines:
            parts = parts[1:]
        while parts and parts not in self.lines:
            parts = parts[:-1]
        return self.lines.get(parts)

    def error(self, detail: str, key=None) -> InputError:
        """An `InputError` about `key` (a dotted key, a tuple, or None for the whole file), at its line.

        Parameters
        ----------
        detail : str
            What is wrong.
        key : str or tuple, optional
            A dotted key or a tuple of keys; None: the whole file.
        """
        return InputError(detail, origin=self.origin, key=None if key is None else str(key), line=self.line_of(key))

    def refuse(self, exc: ValueError, key=None) -> InputError:
        """`exc` (a check's plain ValueError) as an `InputError` of this file, at the line of `key`
        (default: the key its message starts with, `leading_key`). An `InputError` of this file is kept.

        Parameters
        ----------
        exc : ValueError
            A check's error.
        key : str or tuple, optional
            The key it is about; None: the key its message starts with.
        """
        if isinstance(exc, InputError) and exc.origin == self.origin:
            return exc
        message = str(exc)
        return self.error(message, key if key is not None else leading_key(message))


def mapping_source(data, origin: str | None) -> YamlFile:
    """A mapping given in code as a `YamlFile` without lines, so that readers word its errors as a file's.

    Parameters
    ----------
    data : dict
        The mapping.
    origin : str or None
        What to call it in messages.
    """
    return YamlFile(data, origin)


def read_yaml(path, kind: str) -> YamlFile:
    """Read the YAML file `path`; its errors are named ``"<kind> <path>"`` (module docstring).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    kind : str
        What it is, for messages: ``"config"``, ``"spec"``, ``"scene"``, ``"map"``, ``"preset"``, ``"fuzzy tables"``.

    Returns
    -------
    YamlFile

    Raises
    ------
    InputError
        ``<kind> <path>: cannot read the file (<why>)`` (missing, a directory, not UTF-8);
        ``<kind> <path>, line <n>: not valid YAML: <problem> (column <c>)``;
        ``<kind> <path>, line <n>: <key> is given twice``.
    """
    origin = f"{kind} {os.fspath(path)}"
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, ValueError) as exc:  # missing, a directory, not UTF-8, a NUL in the path
        reason = getattr(exc, "strerror", None) or str(exc)
        raise InputError(f"cannot read the file ({reason})", origin=origin) from None
    data, lines = _parse(text, origin)
    return YamlFile(data, origin, os.fspath(path), lines)


def parse_yaml(text: str, origin: str | None = None):
    """The YAML document in `text` (a value embedded in a file, e.g. Nav2's footprint string), by the file rule.

    Parameters
    ----------
    text : str
        The YAML text.
    origin : str, optional
        What to call it in messages (the file and key it came from).

    Raises
    ------
    InputError
        Invalid YAML or a key given twice (named `origin`, lines counted in `text`).
    """
    return _parse(text, origin)[0]


def _parse(text: str, origin: str | None):
    """(data, lines) of a YAML text."""
    import yaml

    loader = _loader()(text)
    try:
        node = loader.get_single_node()
        lines = {}
        if node is not None:
            _walk(node, (), lines, origin)
        data = loader.construct_document(node) if node is not None else None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        column = f" (column {mark.column + 1})" if mark is not None else ""
        raise InputError(f"not valid YAML: {problem}{column}", origin=origin, line=mark.line + 1 if mark is not None else None) from None
    finally:
        loader.dispose()
    return data, lines


def _walk(node, path: tuple, lines: dict, origin) -> None:
    """Record the line of every key and list item under `node`; refuse a key given twice."""
    from yaml.nodes import MappingNode, ScalarNode, SequenceNode

    lines.setdefault(path, node.start_mark.line + 1)
    if isinstance(node, MappingNode):
        seen = set()
        for key_node, value_node in node.value:
            key = key_node.value if isinstance(key_node, ScalarNode) else str(key_node.start_mark)
            identity = (key_node.tag, key)
            if identity in seen:
                shown = ".".join(str(p) for p in (*path, key))
                raise InputError(f"{shown} is given twice", origin=origin, key=shown, line=key_node.start_mark.line + 1)
            seen.add(identity)
            lines[(*path, key)] = key_node.start_mark.line + 1
            _walk(value_node, (*path, key), lines, origin)
    elif isinstance(node, SequenceNode):
        for index, item in enumerate(node.value):
            lines[(*path, index)] = item.start_mark.line + 1
            _walk(item, (*path, index), lines, origin)


@functools.cache
def _loader():
    """yaml.SafeLoader reading exponent numbers without a dot as floats (built once, on first use)."""
    import yaml

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver("tag:yaml.org,2002:float", _NUMBER, list("-+0123456789."))
    return Loader
