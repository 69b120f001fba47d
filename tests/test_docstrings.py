"""House style (docs/architecture.md): every module has a docstring and every public
function, class and method of the package documents itself (numpydoc)."""

import importlib
import inspect
import pkgutil

import pytest

import pfm_stability

MODULES = sorted(
    m.name for m in pkgutil.walk_packages(pfm_stability.__path__, "pfm_stability.") if not m.name.endswith("__main__")
)


@pytest.mark.parametrize("name", MODULES)
def test_module_and_public_objects_have_docstrings(name):
    module = importlib.import_module(name)
    assert module.__doc__ and module.__doc__.strip(), f"{name} has no module docstring"
    missing = []
    for attr in getattr(module, "__all__", []):
        obj = getattr(module, attr)
        if not (inspect.isfunction(obj) or inspect.isclass(obj)) or getattr(obj, "__module__", name) != name:
            continue
        if not inspect.getdoc(obj):
            missing.append(attr)
        if inspect.isclass(obj):
            for meth_name, meth in vars(obj).items():
                if meth_name.startswith("_") or not inspect.isfunction(meth):
                    continue
                if not inspect.getdoc(getattr(obj, meth_name)):
                    missing.append(f"{attr}.{meth_name}")
    assert not missing, f"{name}: undocumented public objects {missing}"


@pytest.mark.parametrize("name", [m for m in MODULES if not m.endswith(("__init__",)) and m.count(".") >= 1])
def test_modules_declare_all(name):
    module = importlib.import_module(name)
    if name.startswith("pfm_stability.cli"):
        return  # subcommand modules expose add_parser/run by convention
    assert hasattr(module, "__all__"), f"{name} has no __all__"
