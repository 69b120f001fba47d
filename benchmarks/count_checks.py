"""How many input checks (`pfm_stability.checks`) one command makes, and who makes them.

Every public function of `pfm_stability.checks` is wrapped with a counter, in the
module itself and wherever a module of the package imported it by name, before the
command runs in this process (the CLI's own `main`). The total and the count per
caller (the calling function, ``module:qualname``) are printed, most first; with
``--chain N`` the callers are the last N frames of the package instead (who called
the caller). A check happens at a public entry once: a report that re-checks the same
loop at every probe of a bisection shows up here as thousands of calls. Run:

    python benchmarks/count_checks.py [--chain 2] [--top 20] [-- report --preset carmel --alpha 20 --L 0.9]
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import functools
import io
import sys

DEFAULT_COMMAND = ["report", "--preset", "carmel", "--alpha", "20", "--L", "0.9"]


def _caller(frame, depth: int) -> str:
    """The last `depth` frames of the package above `frame`, innermost last (``module:qualname``)."""
    names = []
    while frame is not None and len(names) < depth:
        module = frame.f_globals.get("__name__", "")
        if module.startswith("pfm_stability") and module != "pfm_stability.checks":
            names.append(f"{module}:{frame.f_code.co_qualname}")
        frame = frame.f_back
    return " <- ".join(names) or "(outside the package)"


@contextlib.contextmanager
def counting(depth: int = 1):
    """Within the block every public check is counted (in `checks` and every module that imported it by name);
    yields the counts {(check, caller): calls}. The original functions are restored on exit."""
    import pfm_stability.checks as checks

    _import_package()
    counts: collections.Counter = collections.Counter()
    originals = {name: getattr(checks, name) for name in checks.__all__}

    def counted(name, function):
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            counts[(name, _caller(sys._getframe(1), depth))] += 1
            return function(*args, **kwargs)

        return wrapper

    wrapped = {id(f): counted(name, f) for name, f in originals.items()}
    patched = []  # (module, attribute, original)
    for module in [checks] + [m for n, m in list(sys.modules.items()) if n.startswith("pfm_stability.") and m is not checks]:
        for attr, value in list(vars(module).items()):
            if id(value) in wrapped and any(value is f for f in originals.values()):
                patched.append((module, attr, value))
                setattr(module, attr, wrapped[id(value)])
    try:
        yield counts
    finally:
        for module, attr, value in patched:
            setattr(module, attr, value)


def report_check_calls(command=DEFAULT_COMMAND, depth: int = 1) -> tuple[int, collections.Counter]:
    """(exit status, counts) of one CLI command run in this process (`counting`)."""
    from pfm_stability.cli import main as cli_main

    with counting(depth) as counts, contextlib.redirect_stdout(io.StringIO()):
        status = cli_main(list(command))
    return status, counts


def _import_package() -> None:
    """Import every module of the package that imports here (optional extras may be missing)."""
    import pkgutil

    import pfm_stability

    for info in pkgutil.walk_packages(pfm_stability.__path__, "pfm_stability."):
        if info.name.endswith("__main__"):
            continue
        with contextlib.suppress(Exception):
            __import__(info.name)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chain", type=int, default=1, help="frames of the package per caller (default 1)")
    parser.add_argument("--top", type=int, default=25, help="callers listed (default 25)")
    parser.add_argument("command", nargs="*", help="the pfm-stability command (default: the carmel report)")
    args = parser.parse_args(argv)
    status, counts = report_check_calls(args.command or DEFAULT_COMMAND, args.chain)
    total = sum(counts.values())
    print(f"{' '.join(args.command or DEFAULT_COMMAND)}: exit {status}, {total} check calls")
    by_check = collections.Counter()
    for (name, _), n in counts.items():
        by_check[name] += n
    print("per check: " + ", ".join(f"{name} {n}" for name, n in by_check.most_common()))
    for (name, caller), n in counts.most_common(args.top):
        print(f"{n:7d}  {name:<20} {caller}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
