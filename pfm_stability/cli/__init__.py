"""The ``pfm-stability`` command line.

Subcommands live in their own modules (``report``, ``derive``, ``simulate``,
``validate``, ``plot``, ``traps``); each exposes ``add_parser(subparsers)`` and
``run(args) -> int``; their text, Markdown and LaTeX renderings are in
`render`, their JSON is written by `pfm_stability.io.serialize.dumps`. Module
imports here are light (no numpy, scipy, sympy or matplotlib) so that
start-up stays fast; the heavy libraries are imported by the subcommand that
needs them.

Every user error — a bad value, an unknown option, an impossible scenario, a
file that cannot be written (a full disk: `files.OutputError`) — ends with exit
status 2 and one line on stderr::

    pfm-stability: error: V must be a finite number in (0, 100] m/s; got -1.0
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import os
import re
import sys

from ..extras import MissingExtra

__all__ = ["main", "build_parser", "UsageError", "unknown_options"]

SUBCOMMANDS = ("report", "derive", "simulate", "validate", "plot", "traps", "map", "sweep", "identify", "diagnose")


class UsageError(Exception):
    """A user error found while parsing; printed as one line, exit status 2."""


_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
"""A negative number, also in scientific notation (``--offset -1e-3``): a value, not an option."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are a single line and an exception, not an exit.

    Negative numbers in scientific notation (``-1e-3``) are read as values;
    argparse's own pattern (Python < 3.13) takes them for unknown options.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)  # --t is not --tau, --l not --law: options are the paper's case-sensitive symbols
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message):
        raise UsageError(message)


def build_parser() -> argparse.ArgumentParser:
    """The full parser with every available subcommand."""
    parser = _Parser(
        prog="pfm-stability",
        description="Will a potential-field (VFF) controller oscillate near walls and in corridors? "
        "Koren & Borenstein 1991 analysis with exact-delay and sampled-data models, and a simulator that checks it.",
    )
    from ..version import __version__

    parser.add_argument("--version", action="version", version=f"pfm-stability {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    parser.subcommands = sub.choices  # name → its parser: `unknown_options` names the options of the one used
    for name in SUBCOMMANDS:
        try:
            module = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:  # a subcommand not built in this version
            if exc.name != f"{__name__}.{name}":
                raise
            continue
        module.add_parser(sub)
    return parser


def unknown_options(extras, parser) -> str:
    """The message for arguments no option of `parser` takes, with a suggestion per unknown option.

    Options are case-sensitive (``--V`` speed, ``--v`` nothing); an option that differs from a real one
    only in case, or is close to one, is named (``--v`` → ``--V``, ``--tua`` → ``--tau``).

    Parameters
    ----------
    extras : list of str
        The arguments no option took.
    parser : argparse.ArgumentParser
        The (sub)command's parser.
    """
    options = [o for o in parser._option_string_actions if o.startswith("--")]
    hints, case = [], False
    for token in extras:
        name = token.split("=", 1)[0]
        if not name.startswith("--"):
            continue
        same_letters = [o for o in options if o.lower() == name.lower()]
        close = same_letters or difflib.get_close_matches(name, options, n=1, cutoff=0.75)
        if close:
            hints.append((name, close[0]))
            case = case or bool(same_letters)
    message = f"unrecognized arguments: {' '.join(t if t.isprintable() else repr(t) for t in extras)}"  # a control character quoted: one line
    if len(hints) == 1:
        message += f"; did you mean {hints[0][1]}?"
    elif hints:
        message += "; did you mean " + ", ".join(f"{real} (for {given})" for given, real in hints) + "?"
    return message + (" (options are case-sensitive)" if case else "")


def _fail(message: str) -> int:
    print(f"pfm-stability: error: {message}", file=sys.stderr)
    return 2


BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""The commands solve many small eigenvalue problems: BLAS threads would only spin, and on a busy
machine (other processes on every core) make a report 3–5× slower. `main` pins them to one before
numpy is imported, unless the user set them."""


def main(argv=None) -> int:
    """Run the CLI; returns the exit status (0 ok, 2 user error).

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).
    """
    for variable in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(variable, "1")
    parser = build_parser()
    try:
        args, extras = parser.parse_known_args(argv)
        if extras:
            raise UsageError(unknown_options(extras, parser.subcommands.get(args.command, parser)))
        return int(args.run(args) or 0)
    except UsageError as exc:
        return _fail(str(exc))
    except ValueError as exc:
        return _fail(str(exc))
    except MissingExtra as exc:
        return _fail(str(exc))
    except BrokenPipeError:
        return 0
    except OSError as exc:  # the environment, not the code: a full disk, a vanished file, a device error
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        return _fail(f"{exc.strerror or exc}{where}")
