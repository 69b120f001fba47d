"""Fuzz the command line as a new user would: random options and values for every subcommand.

Each run calls ``pfm_stability.cli.main`` in-process with a seeded random argument
list: valid values drawn from each parameter's range (and far outside it), edge
values (0, the bounds, 1e-300, 1e300), NaN, inf, empty strings and text. A run is
classified as ``exit 0``, ``exit 2``, ``traceback`` (any exception escaping
``main``, with its type), ``timeout``, ``bad json`` (``--format json`` whose
stdout does not parse with NaN/Infinity rejected, or does not validate against
``pfm_stability/schema/output.schema.json``), ``wrong success`` (exit 0 without
the PNG an output option named), or ``exit 2, not one error line`` (stderr holds
more than the one error line besides progress lines and Python warnings). Runs
whose stderr holds a Python warning (e.g. a numpy RuntimeWarning) are counted
separately. Output files go to a temporary directory. Run:

    python benchmarks/fuzz_cli.py [--runs 536] [--seed 0] [--timeout 60]
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import os
import random
import signal
import sys
import tempfile
import traceback

NUMERIC = {
    "--V": (0.05, 3.0), "--tau": (0.0, 2.0), "--T": (0.0, 1.5), "--k": (0.1, 20.0), "--f": (0.05, 5.0),
    "--n": (0.5, 4.0), "--W": (0.2, 1.2), "--alpha": (0.5, 89.5), "--L": (0.3, 3.0), "--offset": (1e-6, 0.2),
    "--duration": (1.0, 40.0), "--cell-ratio": (0.01, 2.0), "--cell-size": (0.02, 0.3), "--jitter": (0.0, 0.05),
    "--rtol": (1e-3, 0.2), "--mass": (0.5, 50.0), "--xi": (0.1, 10.0), "--eta": (0.01, 5.0), "--rho0": (0.3, 3.0),
}
INTEGER = {"--compute-delay": (0, 1), "--pade-order": (1, 12), "--window-cells": (3, 61), "--seed": (0, 99),
           "--members": (3, 9), "--sweep": (8, 12)}
WEIRD = ["nan", "inf", "-inf", "", "fast", "1e300", "-1e300", "1e-300", "-0", "0", "-1", "89.999999", "90", "1e4",
         "0x10", " 1", "1,5", "None", "true"]


def _options(subparser):
    out = {}
    for action in subparser._actions:
        if not action.option_strings or action.dest in ("help", "version"):
            continue
        name = max(action.option_strings, key=len)
        out[name] = action
    return out


def _value(rng, name, action, tmp):
    if action.nargs == 0:
        return None
    if action.choices is not None and rng.random() < 0.85:
        return str(rng.choice(list(action.choices)))
    if name in ("--out", "--plot", "--sweep-plot", "--out-dir"):
        return rng.choice([os.path.join(tmp, "f.png"), tmp, "", os.path.join(tmp, "no", "such", "dir.png"), os.path.join(tmp, "f")])
    r = rng.random()
    if r < 0.12:
        return rng.choice(WEIRD)
    if name in INTEGER:
        lo, hi = INTEGER[name]
        return str(rng.randint(lo - (1 if r < 0.22 else 0), hi + (1 if r < 0.22 else 0)))
    lo, hi = NUMERIC.get(name, (0.01, 10.0))
    x = rng.uniform(lo, hi)
    if r < 0.22:
        x *= rng.choice([-1, 1e-6, 1e3])
    return repr(x)


def _argv(rng, parser, tmp):
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    command = rng.choice(sorted(sub.choices))
    p = sub.choices[command]
    argv = [command]
    for action in p._actions:  # positionals
        if not action.option_strings and action.dest != "help":
            argv.append(str(rng.choice(list(action.choices))) if action.choices else "x")
    options = _options(p)
    required = [n for n, a in options.items() if a.required]
    chosen = set(required) | set(rng.sample(sorted(options), k=min(len(options), rng.randint(0, 6))))
    for name in sorted(chosen):
        action = options[name]
        value = _value(rng, name, action, tmp)
        argv.append(name)
        if value is not None:
            argv.append(value)
    # keep the expensive subcommands short unless the fuzz chose otherwise
    if command in ("simulate", "validate") and "--duration" not in chosen:
        argv += ["--duration", "8"]
    if command == "validate" and "--rtol" not in chosen:
        argv += ["--rtol", "0.05"]
    return command, argv


class _Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise _Timeout()


def _schema_validator():
    try:
        from jsonschema import Draft202012Validator
    except ImportError:  # the test extra is not installed: parse only
        return None
    from pfm_stability.io.schema import load_schema

    return Draft202012Validator(load_schema())


def _is_warning(line: str) -> bool:
    return "Warning: " in line or line.startswith("  ")  # "file:line: RuntimeWarning: ..." and its source line


def run_one(main, argv, timeout, validator=None):
    out, err = io.StringIO(), io.StringIO()
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(timeout)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:
                code = exc.code
        kind = f"exit {code}"
        if code == 0:
            for flag in ("--out", "--plot", "--sweep-plot"):
                if flag in argv:
                    path = (argv[argv.index(flag) + 1:] or [""])[0]
                    if not path.endswith(".png") or not os.path.isfile(path):
                        kind = f"wrong success ({flag} {os.path.basename(path) or repr(path)})"
        if code == 0 and "--format" in argv and argv[argv.index("--format") + 1:][:1] == ["json"]:
            try:
                data = json.loads(out.getvalue(), parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
            except ValueError as exc:
                kind = f"bad json ({str(exc)[:40]})"
            else:
                error = next(iter(validator.iter_errors(data)), None) if validator is not None else None
                if error is not None:
                    kind = f"bad json (schema: {'/'.join(map(str, error.absolute_path))})"
        if code == 2:
            lines = [line for line in err.getvalue().splitlines() if not line.startswith(f"{argv[0]}: ") and not _is_warning(line)]
            if len(lines) != 1 or not lines[0].startswith("pfm-stability: error: "):
                kind = "exit 2, not one error line"
    except _Timeout:
        kind = "timeout"
    except Exception as exc:  # noqa: BLE001 - this is what the fuzz counts
        kind = f"traceback {type(exc).__name__}"
        err.write(traceback.format_exc())
    finally:
        signal.alarm(0)
    return kind, err.getvalue()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=536)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=int, default=60, help="seconds per run")
    parser.add_argument("--show", type=int, default=3, help="tracebacks shown per kind")
    args = parser.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    from pfm_stability.cli import build_parser
    from pfm_stability.cli import main as cli_main

    rng = random.Random(args.seed)
    validator = _schema_validator()
    warned = collections.Counter()
    warning_examples = {}
    counts = collections.Counter()
    per_command = collections.defaultdict(collections.Counter)
    examples = collections.defaultdict(list)
    with tempfile.TemporaryDirectory() as tmp:
        cli = build_parser()
        for i in range(args.runs):
            command, argv = _argv(rng, cli, tmp)
            kind, err = run_one(cli_main, argv, args.timeout, validator)
            counts[kind] += 1
            for line in err.splitlines():
                if "Warning: " in line:
                    where = line.split(": ")[0].rsplit("/", 1)[-1] + ": " + line.split(": ", 2)[1]
                    warned[where] += 1
                    warning_examples.setdefault(where, argv)
            per_command[command][kind] += 1
            if not kind.startswith("exit") and len(examples[kind]) < args.show:
                examples[kind].append((argv, err.strip().splitlines()[-1:] if err else []))
            print(f"\r{i + 1}/{args.runs}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    print(f"{args.runs} runs (seed {args.seed}):")
    for kind, n in counts.most_common():
        print(f"  {kind:40s} {n}")
    print("per command:")
    for command, c in sorted(per_command.items()):
        print(f"  {command:10s} " + ", ".join(f"{k}: {n}" for k, n in c.most_common()))
    for kind, items in examples.items():
        print(f"examples of {kind}:")
        for argv, last in items:
            print("  pfm-stability " + " ".join(repr(a) if (" " in a or a == "") else a for a in argv))
            for line in last:
                print("    " + line)
    if warned:
        print("Python warnings on stderr (each location is shown once per process):")
        for where, n in warned.most_common():
            argv = warning_examples[where]
            print(f"  {where}: first in pfm-stability " + " ".join(repr(a) if (" " in a or a == "") else a for a in argv))
    bad = sum(n for k, n in counts.items() if not k.startswith("exit") or k == "exit 2, not one error line")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
