"""A family's package gives its hub's public names, and importing it loads nothing until a name is used.

analysis.fit, analysis.validity, analysis.diagnosis, analysis.recording, analysis.model and
app.model_lab each map their public names to the submodule that defines them (_HOME) and import
it on first use (module-level __getattr__), so `from analysis.fit import FitResult` works and
`import analysis.fit.words` does not drag in scipy.optimize through the package.
"""
from __future__ import annotations

import importlib

import pytest

from tests.fresh_import import loaded_by_import

LAZY = ("analysis.fit", "analysis.validity", "analysis.diagnosis", "analysis.recording", "analysis.model",
        "app.model_lab")


@pytest.mark.parametrize("package", LAZY)
def test_importing_the_package_loads_none_of_its_submodules(package):
    assert loaded_by_import(package, f"{package}.") == []


@pytest.mark.parametrize("package", LAZY)
def test_every_public_name_is_the_defining_modules_own(package):
    module = importlib.import_module(package)
    assert module.__all__, f"{package} gives no name"
    for name in module.__all__:
        home = importlib.import_module(f"{package}.{module._HOME[name]}")
        assert getattr(module, name) is getattr(home, name)
        assert name in dir(module)


def test_an_unknown_name_is_an_attribute_error():
    import analysis.fit
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        analysis.fit.no_such_name      # noqa: B018
    with pytest.raises(ImportError):
        exec("from analysis.fit import no_such_name", {})
