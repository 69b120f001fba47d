"""The README's quick start stays true: CI runs its test command verbatim, and the
report command it shows is the one the benchmark times."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _quick_start_commands():
    text = (ROOT / "README.md").read_text()
    section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```bash\n(.+?)\n```", section)


def test_ci_runs_the_readme_test_command_verbatim():
    report, tests = _quick_start_commands()
    assert "pytest" in tests
    ci_lines = [line for line in (ROOT / ".ci" / "run").read_text().splitlines() if line and not line.startswith(("#", "set ", "cd "))]
    assert ci_lines == [tests]


def test_readme_report_command_is_the_benchmarked_one():
    report, _ = _quick_start_commands()
    assert report.endswith("pfm-stability report --preset carmel --alpha 20 --L 0.9")
    bench = (ROOT / "benchmarks" / "bench_cold_start.py").read_text()
    assert '"report", "--preset", "carmel", "--alpha", "20", "--L", "0.9"' in bench
