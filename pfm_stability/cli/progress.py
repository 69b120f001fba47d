"""Progress on stderr for the long subcommands (``simulate``, ``validate``).

Two shapes of progress come from the library:

* the simulator's ``progress(step, total)`` (`pfm_stability.sim.simulate`:
  every 1024 samples and at the end) → `step_progress`, a tqdm bar of
  samples, shown only when stderr is a terminal (in a log file a bar is noise);
* the validation's ``progress(line)`` (`validate_boundary`, `verdict_sweep`:
  one line of text after each batch of runs) → `line_progress`. On a
  terminal each line is written above a tqdm status line with the elapsed
  time, redrawn every second so that a long batch (a sweep of 10⁵ runs
  simulates in two batches) still shows that work goes on.
  When stderr is not a terminal the lines are printed as plain text
  (``validate: round 3: L in [...]``): they are few (one per batch) and
  are what a log of a long validation should hold.

``--quiet`` silences both. tqdm is imported only when a bar is shown, so the
command line starts without it.
"""

from __future__ import annotations

import contextlib
import sys
import threading

__all__ = ["stderr_is_terminal", "step_progress", "line_progress"]

REFRESH_SECONDS = 1.0
"""How often a line-progress bar redraws its elapsed time, s."""


def stderr_is_terminal() -> bool:
    """True if stderr is an interactive terminal (where a progress bar belongs)."""
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):  # no stderr, or a closed one
        return False


def _bar(**options):
    from tqdm import tqdm

    return tqdm(file=sys.stderr, dynamic_ncols=True, **options)


@contextlib.contextmanager
def step_progress(desc: str, *, quiet: bool = False, unit: str = "sample"):
    """A ``progress(step, total)`` callable drawing a tqdm bar, or None (quiet, or not a terminal).

    Parameters
    ----------
    desc : str
        Bar label (the subcommand).
    quiet : bool
        No progress at all.
    unit : str
        What a step is.

    Yields
    ------
    callable or None
    """
    if quiet or not stderr_is_terminal():
        yield None
        return
    bar = None

    def update(step: int, total: int) -> None:
        nonlocal bar
        if bar is None:  # drawn at the first report, when the total is known
            bar = _bar(desc=desc, unit=unit, unit_scale=True, total=total)
        if bar.total != total:
            bar.total = total
        if step > bar.n:
            bar.update(step - bar.n)

    try:
        yield update
    finally:
        if bar is not None:
            bar.close()


@contextlib.contextmanager
def line_progress(prefix: str, *, quiet: bool = False):
    """A ``progress(line)`` callable: tqdm lines and a ticking bar on a terminal, plain lines otherwise.

    Parameters
    ----------
    prefix : str
        Put before every line (the subcommand).
    quiet : bool
        No progress at all: yields None.

    Yields
    ------
    callable or None
    """
    if quiet:
        yield None
        return
    if not stderr_is_terminal():

        def emit(line: str) -> None:
            print(f"{prefix}: {line}", file=sys.stderr, flush=True)

        yield emit
        return
    bar = _bar(desc=prefix, total=None, leave=False, bar_format="{desc}: working, {elapsed} elapsed")
    stop = threading.Event()

    def tick() -> None:
        while not stop.wait(REFRESH_SECONDS):
            bar.refresh()

    ticker = threading.Thread(target=tick, name=f"{prefix}-progress", daemon=True)
    ticker.start()

    def emit(line: str) -> None:
        bar.write(f"{prefix}: {line}", file=sys.stderr)

    try:
        yield emit
    finally:
        stop.set()
        ticker.join()
        bar.close()
