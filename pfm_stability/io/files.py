"""Every file the commands write, written atomically, and every failure to write one as one line.

A file is written to a temporary name in its own directory and renamed over the
target only once it is complete (`os.replace`, atomic on one file system), so a
full disk, a killed process or an error half-way never leaves a truncated or
empty file under the name the user asked for, and an existing file there stays
as it was. A write that fails (``OSError``: a full disk, a read-only or
pseudo file system, a vanished directory) becomes `OutputError`, a
``ValueError`` whose one-line message names the file and the reason; the CLI
prints it and exits with status 2 (docs/architecture.md).

`check_writable` is the check the commands run on an output path before any
work: it creates (and removes) a temporary file where the output will go, the
only test that catches a directory that looks writable but is not (``/proc``,
``/sys``, a read-only mount seen by root).

`open_new` is the one place a file is opened for writing: the tests replace it to
simulate a full disk for every command. This module imports no numpy.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile

__all__ = ["OutputError", "open_new", "atomic_file", "write_text", "save_figure", "atomic_directory", "check_writable"]


class OutputError(ValueError):
    """A file could not be written: one line naming it and why (exit status 2 in the CLI)."""


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


def open_new(path: str, mode: str):
    """Open the new (temporary) file `path` for writing in `mode` ("w" text UTF-8, or "wb").

    Parameters
    ----------
    path : str
        The new file's path.
    mode : str
        ``"w"`` (text, UTF-8) or ``"wb"``.
    """
    return open(path, mode, encoding="utf-8") if "b" not in mode else open(path, mode)


@contextlib.contextmanager
def atomic_file(path, mode: str = "wb", *, what: str = "output"):
    """A file object for `path`, renamed into place only if the block completes.

    Parameters
    ----------
    path : str or os.PathLike
        The target file; its directory must exist.
    mode : str
        ``"wb"`` (default) or ``"w"`` (text, UTF-8).
    what : str
        What the file is, for the message (``"plot"``, ``"table"``).

    Raises
    ------
    OutputError
        ``"could not write plot /full/disk/p.png: No space left on device"``;
        nothing is left at `path` (an existing file there is untouched).
    """
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.", suffix=".tmp", dir=directory)
        os.close(fd)
        with open_new(tmp, mode) as handle:
            yield handle
        os.replace(tmp, path)
        tmp = None
    except OSError as exc:
        raise OutputError(f"could not write {what} {path}: {_reason(exc)}") from None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.remove(tmp)


def write_text(path, text: str, *, what: str = "output") -> None:
    """Write `text` (UTF-8) to `path` atomically (`atomic_file`).

    Parameters
    ----------
    path : str or path-like
        The file.
    text : str
        Its content.
    what : str, optional
        What the file is, for the error message.
    """
    with atomic_file(path, "w", what=what) as handle:
        handle.write(text)


def save_figure(fig, path, *, dpi: int = 110, what: str = "plot") -> None:
    """Save a matplotlib figure atomically, in the format of `path`'s suffix (``.png``); then close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or path-like
        The image file.
    dpi : int, optional
        Resolution, dots per inch.
    what : str, optional
        What the file is, for the error message.
    """
    import matplotlib.pyplot as plt

    fmt = os.path.splitext(os.fspath(path))[1].lstrip(".").lower() or "png"
    try:
        with atomic_file(path, "wb", what=what) as handle:
            fig.savefig(handle, format=fmt, dpi=dpi)
    finally:
        plt.close(fig)


@contextlib.contextmanager
def atomic_directory(out_dir, names, *, what: str = "outputs"):
    """Temporary paths for the files `names` of `out_dir`, renamed into it only if the block completes.

    Yields a dict name → temporary path in a staging directory inside `out_dir`
    (created if missing), so each rename is atomic. On any failure the staging
    directory, and `out_dir` if it was created here and is left empty, are
    removed: a failure leaves nothing behind. An ``OSError`` becomes `OutputError`.

    Parameters
    ----------
    out_dir : str or path-like
        The output directory.
    names : sequence of str
        The files' names in it.
    what : str, optional
        What the files are, for the error message.
    """
    out_dir = os.fspath(out_dir)
    created = not os.path.exists(out_dir)
    staging = None
    try:
        if created:
            os.makedirs(out_dir)
        staging = tempfile.mkdtemp(prefix=".outputs-", dir=out_dir)
        paths = {name: os.path.join(staging, name) for name in names}
        yield paths
        for name, tmp in paths.items():
            if os.path.exists(tmp):
                os.replace(tmp, os.path.join(out_dir, name))
    except OSError as exc:
        raise OutputError(f"could not write {what} in {out_dir}: {_reason(exc)}") from None
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
        if created and os.path.isdir(out_dir) and not os.listdir(out_dir):
            os.rmdir(out_dir)


def check_writable(directory: str) -> str | None:
    """None if a file can be created in the existing `directory`, else the reason (e.g. "Permission denied").

    Creates and removes one empty temporary file: `os.access` alone says yes to
    root in ``/proc`` and ``/sys``, where nothing can be created.

    Parameters
    ----------
    directory : str
        An existing directory.
    """
    try:
        fd, probe = tempfile.mkstemp(prefix=".pfm-stability-probe-", dir=directory)
    except OSError as exc:
        return _reason(exc)
    os.close(fd)
    with contextlib.suppress(OSError):
        os.remove(probe)
    return None
