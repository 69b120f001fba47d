"""The package's architecture, as `docs/architecture.md` states it, checked on the source.

The layering table of `docs/architecture.md` (columns ``level | modules | role``) is
the single statement of which module sits where; these tests parse it, read every
``pfm_stability/**/*.py`` with `ast` (nothing is imported, so the tests are fast
and see imports inside functions too) and check:

1. every module of the package is placed in the table (and every entry is a module);
2. no module imports a module at a higher level; and, from the document's second
   table (``module | never imports``), the simulator imports none of the prediction
   modules, a rule the levels alone cannot express;
3. no import circle between modules;
4. one concept per module, and a generous size alarm: no module longer than 900
   lines (except `analysis.derivation`, a transcript of the derivation step by step);
   at most six modules at the package root (the rest live in sub-packages by concept);
5. there is one batched bisection, in `solve`;
6. nothing in the repository points at documents outside it.

Which imports count
-------------------
Every ``import pfm_stability…`` and ``from pfm_stability… import …``, absolute or
relative, at module level or inside a function, class or ``try``. ``from . import x``
and ``from .pkg import x`` count as importing the submodule ``pkg.x`` when ``x`` is a
module file, otherwise as importing ``pkg`` (its ``__init__``).

Imports inside ``if TYPE_CHECKING:`` are collected but exempt from the level and
circle rules: they never run, so they create neither a dependency at run time nor an
import circle, and annotations may name a type from anywhere. Dynamic imports
(``importlib.import_module`` with a computed name: the lazy facade of the package root
and the subcommand dispatch of ``cli``) are not seen; both only go downwards or stay
inside ``cli``.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from functools import cache
from itertools import pairwise
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PACKAGE = "pfm_stability"
PACKAGE_DIR = REPO / PACKAGE
ARCHITECTURE = REPO / "docs" / "architecture.md"

MAX_LINES = 900
MAX_ROOT_MODULES = 6
LONG_MODULES_ALLOWED = {"analysis.derivation"}
BATCHED_BISECTION_MODULE = "numerics.solve"
BISECTION_ENTRY_POINTS = {"bisect_batched", "bisect_root"}

EXTERNAL_REFERENCES = [
    re.compile(r"DESIGN\s*(§|\.md)", re.IGNORECASE),
    re.compile(r"papers/[^\s]*\.txt", re.IGNORECASE),
    re.compile(r"\bissue\s*#?\d+\b", re.IGNORECASE),
]
SCANNED_FOR_REFERENCES = ["pfm_stability", "tests", "analyses", "experiments", "benchmarks", "docs", "README.md"]


# ----------------------------------------------------------------- the package
@dataclass(frozen=True)
class Module:
    name: str  # dotted, relative to the package: "sim.grid", "models", "" for the root
    path: Path
    is_package: bool  # an __init__.py

    @property
    def rel(self) -> str:
        return str(self.path.relative_to(REPO))


@cache
def modules() -> dict[str, Module]:
    """Every module of the package by relative dotted name ("" is the root ``__init__``)."""
    out = {}
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE_DIR).with_suffix("").parts)
        if "__pycache__" in parts:
            continue
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        name = ".".join(parts)
        out[name] = Module(name, path, is_package)
    return out


@cache
def source(path: Path) -> str:
    return path.read_text(encoding="utf-8")


@cache
def tree(path: Path) -> ast.Module:
    return ast.parse(source(path), filename=str(path))


# ---------------------------------------------------------------- the imports
@dataclass(frozen=True)
class Import:
    importer: str  # relative dotted name
    imported: str  # relative dotted name ("" = the package root)
    path: str  # file, relative to the repository
    line: int
    type_checking: bool

    def where(self) -> str:
        return f"{self.path}:{self.line}"


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _relative(absolute: str) -> str | None:
    """``pfm_stability.sim.grid`` → ``sim.grid``; ``pfm_stability`` → ``""``; None outside the package."""
    if absolute == PACKAGE:
        return ""
    if absolute.startswith(PACKAGE + "."):
        return absolute[len(PACKAGE) + 1:]
    return None


def _join(*parts: str) -> str:
    return ".".join(p for p in parts if p)


def _resolve_from(module: Module, node: ast.ImportFrom) -> str | None:
    """The relative dotted name of the module a ``from X import …`` reads from (None outside the package)."""
    if node.level == 0:
        return _relative(node.module or "")
    package = module.name if module.is_package else module.name.rpartition(".")[0]
    parts = package.split(".") if package else []
    if node.level - 1 > len(parts):
        raise AssertionError(f"{module.rel}:{node.lineno}: relative import beyond the package")
    base = ".".join(parts[: len(parts) - (node.level - 1)])
    return _join(base, node.module or "")


def _collect(module: Module, node: ast.AST, type_checking: bool, known: dict, out: list) -> None:
    """Append the package imports under `node` to `out`, marking those inside ``if TYPE_CHECKING:``."""
    if isinstance(node, ast.If) and _is_type_checking(node.test):
        for child in node.body:
            _collect(module, child, True, known, out)
        for child in node.orelse:
            _collect(module, child, type_checking, known, out)
        return
    if isinstance(node, ast.Import):
        for alias in node.names:
            target = _relative(alias.name)
            if target is not None:
                out.append(Import(module.name, target, module.rel, node.lineno, type_checking))
    elif isinstance(node, ast.ImportFrom):
        base = _resolve_from(module, node)
        if base is not None:
            for alias in node.names:
                sub = _join(base, alias.name)
                target = sub if sub in known else base
                out.append(Import(module.name, target, module.rel, node.lineno, type_checking))
    for child in ast.iter_child_nodes(node):
        _collect(module, child, type_checking, known, out)


@cache
def imports() -> tuple[Import, ...]:
    """Every import of a package module, from every module of the package."""
    known = modules()
    out: list[Import] = []
    for module in known.values():
        _collect(module, tree(module.path), False, known, out)
    return tuple(out)


# ------------------------------------------------------------------ the table
def _cells(line: str) -> list[str]:
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def _table(header: list[str]) -> list[list[str]]:
    """The rows of the first Markdown table of architecture.md whose header is `header`."""
    assert ARCHITECTURE.exists(), f"{ARCHITECTURE.relative_to(REPO)} is missing: it holds the layering table these tests check"
    lines = source(ARCHITECTURE).splitlines()
    for i, line in enumerate(lines):
        if line.lstrip().startswith("|") and [c.lower() for c in _cells(line)] == header:
            rows = []
            for row in lines[i + 2:]:
                if not row.lstrip().startswith("|"):
                    break
                rows.append(_cells(row))
            assert rows, f"the table '| {' | '.join(header)} |' in docs/architecture.md has no rows"
            return rows
    raise AssertionError(
        f"docs/architecture.md has no Markdown table with the header '| {' | '.join(header)} |'"
    )


def _names(cell: str) -> list[str]:
    return [name.strip().strip("`").strip() for name in cell.split(",") if name.strip().strip("`").strip()]


@cache
def layers() -> dict[str, int]:
    """Table entry (relative dotted name, ``""`` for the root ``__init__``) → level."""
    out = {}
    for row in _table(["level", "modules", "role"]):
        assert len(row) == 3, f"layering table row {row} does not have three cells"
        level_text = row[0].strip("`* ").upper().lstrip("L")
        assert level_text.isdigit(), f"layering table: level {row[0]!r} is not a number"
        for name in _names(row[1]):
            key = "" if name in ("__init__", PACKAGE) else name
            assert key not in out, f"layering table: {name!r} is listed twice"
            out[key] = int(level_text)
    return out


def level_of(name: str) -> int | None:
    """The level of a module: its own entry, else that of the nearest enclosing sub-package."""
    table = layers()
    if name in table:
        return table[name]
    parts = name.split(".")
    for i in range(len(parts) - 1, 0, -1):
        prefix = ".".join(parts[:i])
        if prefix in table:
            return table[prefix]
    return None


def _display(name: str) -> str:
    return name or f"{PACKAGE} (root __init__)"


# ---------------------------------------------------------------------- tests
def test_every_module_is_in_the_layering_table():
    """Every module of the package has a level in docs/architecture.md.

    A module inside a sub-package takes the sub-package's level unless the table lists
    it by itself. Why: a module that is in no layer can import anything and be imported
    by anything; the level rule below would silently not apply to it. The other way
    round, every name in the table must be a module: a misspelt entry places nothing.
    """
    missing = sorted(_display(name) for name in modules() if level_of(name) is None)
    assert not missing, (
        "modules with no level in docs/architecture.md (add them to the layering table): " + ", ".join(missing)
    )
    stale = sorted(_display(entry) for entry in layers() if entry not in modules())
    assert not stale, "the layering table of docs/architecture.md names modules that do not exist: " + ", ".join(stale)


def test_no_module_imports_a_higher_level():
    """No module imports a module at a higher level of the layering table.

    Imports within one level are allowed (test_no_import_circle keeps them acyclic);
    ``if TYPE_CHECKING:`` imports are exempt. Why: the levels are what lets a reader
    understand a module from the ones below it alone, lets the simulator, the models
    and the command line change independently, and keeps cheap modules cheap to import
    (the CLI validates input before numpy loads).
    """
    violations = []
    for imp in imports():
        if imp.type_checking:
            continue
        low, high = level_of(imp.importer), level_of(imp.imported)
        if low is not None and high is not None and high > low:
            violations.append(
                f"{imp.where()}: {_display(imp.importer)} (L{low}) imports {_display(imp.imported)} (L{high})"
            )
    assert not violations, f"{len(set(violations))} imports of a higher level (docs/architecture.md, layering table):\n" + "\n".join(
        sorted(set(violations))
    )


def test_never_imports_table():
    """The modules of the document's ``module | never imports`` table import none of the modules named there.

    A rule the levels cannot express: `sim` sits above the prediction modules (so that
    `validation` can use both) yet must not use them. Why: the simulator is the
    independent check of the predictions; if it computed anything with the models it
    would agree with them by construction. ``if TYPE_CHECKING:`` imports are exempt.
    """
    violations = []
    for row in _table(["module", "never imports"]):
        assert len(row) == 2, f"'never imports' table row {row} does not have two cells"
        banned = _names(row[1])
        for owner in _names(row[0]):
            for imp in imports():
                if imp.type_checking or not _within(imp.importer, owner):
                    continue
                hit = next((b for b in banned if _within(imp.imported, b)), None)
                if hit is not None:
                    violations.append(f"{imp.where()}: {imp.importer} imports {imp.imported} ({owner} never imports {hit})")
    assert not violations, f"{len(set(violations))} imports against the 'never imports' table of docs/architecture.md:\n" + "\n".join(
        sorted(set(violations))
    )


def _within(name: str, entry: str) -> bool:
    return name == entry or name.startswith(entry + ".")


def _is_reexport(importer: str, imported: str) -> bool:
    """A package ``__init__`` importing one of its own submodules (``sim`` → ``sim.grid``)."""
    module = modules().get(importer)
    return module is not None and module.is_package and imported.startswith(importer + "." if importer else "")


def test_no_import_circle():
    """No import circle between modules (module granularity).

    Edges are the run-time imports (``if TYPE_CHECKING:`` ones are left out), except a
    sub-package ``__init__`` importing its own submodules to re-export them. Why: the
    levels allow imports within a level, and a circle there (A imports B imports A)
    makes the import order decide what works, breaks as soon as one import moves to
    module level, and means the two modules are really one.
    """
    graph: dict[str, set[str]] = {name: set() for name in modules()}
    where: dict[tuple[str, str], str] = {}
    for imp in imports():
        if imp.type_checking or imp.importer == imp.imported or _is_reexport(imp.importer, imp.imported):
            continue
        graph[imp.importer].add(imp.imported)
        where.setdefault((imp.importer, imp.imported), imp.where())
    cycles, seen = [], set()
    for component in _strongly_connected(graph):
        if len(component) < 2:
            continue
        for member in component:  # the shortest circle through each member, each circle once
            cycle = _cycle_in(member, set(component), graph)
            key = frozenset(pairwise(cycle))
            if key not in seen:
                seen.add(key)
                cycles.append(cycle)
    report = [" -> ".join(_display(n) for n in cycle) + "   [" + ", ".join(where[(a, b)] for a, b in pairwise(cycle)) + "]" for cycle in cycles]
    assert not cycles, f"{len(cycles)} import circle(s):\n" + "\n".join(sorted(report))


def _strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components, iteratively."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                out.append(sorted(component))
    return out


def _cycle_in(start: str, members: set[str], graph: dict[str, set[str]]) -> list[str]:
    """The shortest circle from `start` back to it inside one strongly connected component (breadth first)."""
    parents = {start: None}
    queue = [start]
    while queue:
        node = queue.pop(0)
        for child in sorted(graph[node] & members):
            if child == start:
                path = [node]
                while parents[path[-1]] is not None:
                    path.append(parents[path[-1]])
                return path[::-1] + [start]
            if child not in parents:
                parents[child] = node
                queue.append(child)
    raise AssertionError(f"no circle through {start} in {sorted(members)}")  # pragma: no cover


def test_no_module_is_over_the_size_alarm():
    """No module of the package is longer than 900 lines, except `analysis.derivation`.

    Why: a module is one concept (docs/architecture.md), and 900 lines is a generous alarm that a
    module holds more than one; it is not a reason to split a concept by size (`analysis.derivation`
    is exempt: it is the derivation of the paper, one step after another).
    """
    offenders = []
    for name, module in modules().items():
        lines = len(source(module.path).splitlines())
        if lines > MAX_LINES and name not in LONG_MODULES_ALLOWED:
            offenders.append(f"{module.rel}: {lines} lines")
    assert not offenders, f"modules over {MAX_LINES} lines (one concept each?):\n" + "\n".join(sorted(offenders))


def test_at_most_six_modules_at_the_root():
    """The package root holds at most six modules (the facade, `__main__`, the version and the vocabulary every
    layer shares); everything else lives in a sub-package named by its concept (docs/architecture.md)."""
    root = sorted(p.name for p in PACKAGE_DIR.glob("*.py"))
    assert len(root) <= MAX_ROOT_MODULES, f"{len(root)} modules at the package root: {', '.join(root)}"


def test_one_batched_bisection():
    """The only bisection loop of the package is in `solve` (`bisect_batched`, `bisect_root`).

    Checked simply and robustly: every function or method whose name contains
    "bisect" (``bisect_…``, ``…_bisection``, ``_bisect``) outside `solve.py` must be a
    thin wrapper, i.e. its body calls `bisect_batched` or `bisect_root`. A function so
    named that calls neither runs its own bracket-narrowing loop. Why: one bisection,
    tested once, with one meaning of "rounds", "members" and "rtol"; a second copy
    drifts (different stopping rule, different handling of quantized values).
    """
    offenders = []
    for name, module in modules().items():
        if name == BATCHED_BISECTION_MODULE:
            continue
        for node in ast.walk(tree(module.path)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and "bisect" in node.name.lower():
                called = {
                    call.func.id if isinstance(call.func, ast.Name) else call.func.attr
                    for call in ast.walk(node)
                    if isinstance(call, ast.Call) and isinstance(call.func, (ast.Name, ast.Attribute))
                }
                if not called & BISECTION_ENTRY_POINTS:
                    offenders.append(f"{module.rel}:{node.lineno}: {node.name}() calls neither bisect_batched nor bisect_root")
    assert not offenders, "bisections outside pfm_stability/numerics/solve.py:\n" + "\n".join(sorted(offenders))


def _text_files():
    for entry in SCANNED_FOR_REFERENCES:
        path = REPO / entry
        if path.is_file():
            yield path
        elif path.is_dir():
            for file in sorted(path.rglob("*")):
                if file.is_file() and "__pycache__" not in file.parts and not any(p.startswith(".") for p in file.relative_to(REPO).parts):
                    yield file


def test_no_reference_to_documents_outside_the_repository():
    """No file of the package, tests, analyses, experiments, benchmarks, docs or README
    points at a document a reader of the repository does not have.

    Looked for (case-insensitive): ``DESIGN §…`` / ``DESIGN.md``, ``papers/….txt``,
    ``issue N`` / ``issue #N``. Binary files are skipped, and so is this file (it holds
    the patterns). Why: every reference must lead somewhere a user can follow —
    docs/theory.md, docs/models.md, docs/simulator.md, docs/validation.md,
    docs/architecture.md, or the paper's equation numbers ("KB eq N").
    """
    this = Path(__file__).resolve()
    hits = []
    for file in _text_files():
        if file.resolve() == this:
            continue
        data = file.read_bytes()
        if b"\0" in data:
            continue
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for pattern in EXTERNAL_REFERENCES:
                for match in pattern.finditer(line):
                    hits.append(f"{file.relative_to(REPO)}:{number}: {match.group(0)!r}")
    assert not hits, f"{len(hits)} references to documents outside the repository:\n" + "\n".join(hits)
