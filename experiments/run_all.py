"""Regenerate every experiment's PNG and JSON and the results table of experiments/README.md.

    python experiments/run_all.py [--out experiments/results] [--quick] [--no-readme]

Runs, in order, ``fig3_calibration``, ``fig5_wall``, ``fig6_corridor`` (KB
1991 Figs 3, 5, 6), ``validation_summary`` (docs/validation.md), the Ge & Cui
2000 experiments, KB's Fig 4 door, the Ge & Cui 2002 experiments
(``gc2002_*``) and the DFAPF paper's (``dfapf_fuzzy``), each
writing into `--out`, then replaces the table between the markers
``<!-- results-table:begin -->`` and ``<!-- results-table:end -->`` of
``experiments/README.md`` (unless ``--no-readme``; ``--quick`` never touches
the README). About five minutes on a 2-core machine.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

EXPERIMENTS = ("fig3_calibration", "fig5_wall", "fig6_corridor", "validation_summary", "gc2000_traps", "gc2000_corridor", "kb_fig4_door",
               "gc2002_tracking", "gc2002_exponents", "gc2002_eq23", "gc2002_holonomic_corridor", "gc2002_steering",
               "gc2002_relay_wall", "dfapf_fuzzy")
BEGIN, END = "<!-- results-table:begin -->", "<!-- results-table:end -->"
README = HERE / "README.md"


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def results_table(rows) -> str:
    """Markdown table of the experiments' rows."""
    lines = [
        "| Experiment | Quantity | Paper | Predicted | Simulated | Note |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        lines.append("| " + " | ".join(_cell(r[k]) for k in ("experiment", "quantity", "kb", "predicted", "simulated", "note")) + " |")
    return "\n".join(lines)


def rewrite_readme(table: str, readme: Path = README) -> None:
    """Put `table` between the README's markers."""
    text = readme.read_text()
    if BEGIN not in text or END not in text:
        raise ValueError(f"{readme} must contain the markers {BEGIN} and {END}")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    readme.write_text(f"{head}{BEGIN}\n{table}\n{END}{tail}")


def run_all(out, quick: bool = False, only=EXPERIMENTS) -> list:
    """Run the experiments; returns every result table row."""
    rows = []
    for name in only:
        started = time.perf_counter()
        module = importlib.import_module(name)
        result = module.run(out, quick=quick)
        rows += result["rows"]
        print(f"{name}: {time.perf_counter() - started:.1f} s — {result.get('finding', '')}", flush=True)
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(HERE / "results"), help="output folder (default: experiments/results)")
    parser.add_argument("--quick", action="store_true", help="reduced runs (CI smoke test); the README is left alone")
    parser.add_argument("--no-readme", action="store_true", help="do not rewrite the README table")
    args = parser.parse_args(argv)
    rows = run_all(args.out, quick=args.quick)
    if not (args.quick or args.no_readme):
        rewrite_readme(results_table(rows))
        print(f"rewrote the results table of {README}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
