"""House style (docs/architecture.md): a public docstring's numpydoc ``Parameters`` section
matches the signature it documents.

`tests/test_docstrings.py` checks that every public object has a docstring; this module checks
that the docstring is *right* about the arguments: every documented name is a parameter, every
parameter is documented, and they come in the signature's order. A renamed, added or removed
argument whose docstring was not updated fails here.

What is checked (public = named in some module's ``__all__``; each object once, at the module
that defines it):

* functions, and the methods, static and class methods a public class defines itself: the
  ``Parameters`` section against ``inspect.signature`` (``self``/``cls`` excluded; ``*args`` and
  ``**kwargs`` only if the docstring documents them, as ``*args`` or ``args``). A method without
  a docstring of its own shows the one it overrides (``help``, `inspect.getdoc`): that docstring is
  checked where it is written, and the override must take the same parameters;
* classes: the constructor's parameters (``inspect.signature(cls)``). A class documents them in
  ``Parameters`` (checked as above) or, a dataclass, in ``Attributes``: there every constructor
  parameter must appear, in order, and every listed name must be an attribute of the class
  (fields, properties and class attributes may be listed besides the constructor's);
* names are identifiers: a prose line inside ``Parameters`` is parsed by numpydoc as a
  parameter named by the line and is reported (prose belongs above the section).

Exceptions whose constructor is the builtin one have no signature to check.
``KNOWN_MISMATCHES`` lists the mismatches of modules whose docstrings another piece of work
owns; remove an entry when its docstring is fixed (an entry that no longer mismatches is
harmless; a new mismatch anywhere fails).
"""

import dataclasses
import importlib
import inspect
import pkgutil
import warnings

import pytest
from numpydoc.docscrape import NumpyDocString

import pfm_stability

MODULES = sorted(
    m.name for m in pkgutil.walk_packages(pfm_stability.__path__, "pfm_stability.") if not m.name.endswith("__main__")
)

# module:qualname of mismatches a piece of work has yet to fix (empty: every public docstring matches); a new
# entry needs a reason, and is deleted with its fix.
KNOWN_MISMATCHES = frozenset()


def public_objects():
    """Every public function and class of the package, once each: {(module, qualname): object}."""
    found = {}
    for name in MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", []):
            obj = getattr(module, attr, None)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            home = getattr(obj, "__module__", "") or ""
            if home.startswith("pfm_stability"):
                found.setdefault((home, obj.__qualname__), obj)
    return found


def parse(doc):
    """The numpydoc sections of ``doc``; numpydoc's own complaints (unknown sections) are not ours."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return NumpyDocString(doc)


def documented_names(section):
    """Names of a numpydoc ``Parameters``/``Attributes`` section, ``x, y : float`` counted as two."""
    return [n.strip() for p in section for n in p.name.split(",") if n.strip()]


def signature_names(function, documented):
    """Parameters a docstring must document: all but self/cls, and ``*args``/``**kwargs`` only if documented."""
    names = []
    for i, (name, p) in enumerate(inspect.signature(function).parameters.items()):
        if i == 0 and name in ("self", "cls"):
            continue
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            star = "*" if p.kind == p.VAR_POSITIONAL else "**"
            if star + name in documented:
                names.append(star + name)
            elif name in documented:
                names.append(name)
            continue
        names.append(name)
    return names


def bad_names(documented):
    """Documented 'names' that are not identifiers (prose parsed as a parameter)."""
    return [n for n in documented if not n.lstrip("*").isidentifier()]


def function_problem(function, doc):
    """What is wrong with ``doc``'s Parameters section for ``function`` (None: nothing)."""
    if not doc:
        return None  # tests/test_docstrings.py reports a missing docstring
    try:
        documented = documented_names(parse(doc)["Parameters"])
    except ValueError as error:  # numpydoc cannot parse it
        return f"unparsable docstring: {error}"
    try:
        expected = signature_names(function, documented)
    except (TypeError, ValueError):
        return None  # no introspectable signature
    if bad := bad_names(documented):
        return f"Parameters lists non-names {bad} (prose belongs above the section)"
    if documented != expected:
        return f"Parameters documents {documented}, the signature has {expected}"
    return None


def class_problem(cls):
    """What is wrong with a class docstring's account of its constructor (None: nothing)."""
    doc = cls.__doc__
    if not doc:
        return None
    try:
        sections = parse(inspect.cleandoc(doc))
    except ValueError as error:
        return f"unparsable docstring: {error}"
    try:
        parameters = inspect.signature(cls).parameters
    except (TypeError, ValueError):
        return None  # builtin constructor (exceptions)
    if sections["Parameters"]:
        documented = documented_names(sections["Parameters"])
        if bad := bad_names(documented):
            return f"Parameters lists non-names {bad} (prose belongs above the section)"
        expected = signature_names(cls, documented)
        if documented != expected:
            return f"Parameters documents {documented}, the constructor has {expected}"
        return None
    expected = signature_names(cls, [])
    if not expected:
        return None
    attributes = documented_names(sections["Attributes"])
    if not (dataclasses.is_dataclass(cls) and attributes):
        return f"the constructor's parameters {expected} are not documented (Parameters section)"
    if bad := bad_names(attributes):
        return f"Attributes lists non-names {bad} (prose belongs above the section)"
    fields = {f.name for f in dataclasses.fields(cls)}
    if unknown := [n for n in attributes if n not in fields and not hasattr(cls, n)]:
        return f"Attributes lists {unknown}, which are not attributes of the class"
    in_order = [n for n in attributes if n in expected]
    if in_order != expected:
        return f"Attributes documents the constructor's parameters as {in_order}, the constructor has {expected}"
    return None


def problems_of(obj):
    """Every mismatch of a public function or class (its own methods too): {qualname: problem}."""
    out = {}
    if inspect.isfunction(obj):
        if problem := function_problem(obj, inspect.getdoc(obj)):
            out[obj.__qualname__] = problem
        return out
    if problem := class_problem(obj):
        out[obj.__qualname__] = problem
    for name, member in vars(obj).items():
        if name.startswith("_"):
            continue
        function = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
        if not inspect.isfunction(function):
            continue
        if function.__doc__:
            problem = function_problem(function, inspect.getdoc(function))
        else:
            problem = override_problem(obj, name, function)
        if problem:
            out[f"{obj.__qualname__}.{name}"] = problem
    return out


def override_problem(cls, name, function):
    """An undocumented override shows the docstring of the method it overrides: it must take the same parameters."""
    for base in cls.__mro__[1:]:
        member = vars(base).get(name)
        inherited = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
        if inspect.isfunction(inherited) and inherited.__doc__:
            mine, theirs = signature_names(function, []), signature_names(inherited, [])
            if mine != theirs:
                return f"shows the docstring of {base.__qualname__}.{name}{theirs} but takes {mine}"
            return None
    return None


PUBLIC = public_objects()
HOMES = sorted({home for home, _ in PUBLIC})


def test_the_check_sees_the_package():
    """Guards against a check that passes because it looks at nothing: the package has hundreds of
    public functions and classes, and the check parses real Parameters sections."""
    assert len(PUBLIC) > 300
    documented = [obj for obj in PUBLIC.values() if inspect.isfunction(obj) and parse(inspect.getdoc(obj) or "")["Parameters"]]
    assert len(documented) > 200


def test_the_check_catches_each_kind_of_mismatch():
    """Each rule of the module docstring, on a small function that breaks it."""

    def documented(a, b, *args, c=1, **kwargs):
        """Add.

        Parameters
        ----------
        a : float
            First.
        b, c : float
            Second and third.
        """

    def reordered(a, b):
        """Add.

        Parameters
        ----------
        b : float
            Second.
        a : float
            First.
        """

    def prose(a):
        """Add.

        Parameters
        ----------
        a : float
            First.
        All arrays broadcast together.
        """

    def missing(a, b):
        """Add.

        Parameters
        ----------
        a : float
            First.
        """

    @dataclasses.dataclass(frozen=True)
    class Fields:
        """Record.

        Attributes
        ----------
        x : float
            First.
        total : float
            A property besides the fields.
        y : float
            Second.
        """

        x: float
        y: float

        @property
        def total(self):
            return self.x + self.y

    @dataclasses.dataclass(frozen=True)
    class Swapped:
        """Record.

        Attributes
        ----------
        y : float
            Second.
        x : float
            First.
        """

        x: float
        y: float

    assert function_problem(documented, inspect.getdoc(documented)) is None
    assert "documents ['b', 'a']" in function_problem(reordered, inspect.getdoc(reordered))
    assert "non-names" in function_problem(prose, inspect.getdoc(prose))
    assert "the signature has ['a', 'b']" in function_problem(missing, inspect.getdoc(missing))
    assert class_problem(Fields) is None
    assert "constructor has ['x', 'y']" in class_problem(Swapped)


@pytest.mark.parametrize("home", HOMES)
def test_parameters_sections_match_signatures(home):
    problems = {}
    for (module, _), obj in PUBLIC.items():
        if module == home:
            problems.update(problems_of(obj))
    unexpected = {q: p for q, p in problems.items() if f"{home}:{q}" not in KNOWN_MISMATCHES}
    assert not unexpected, "\n".join(f"{home}:{q}: {p}" for q, p in sorted(unexpected.items()))
