"""A package's public names, each imported from its submodule on first use (PEP 562).

A family's package (analysis.fit, analysis.validity, ...) lists where each public name lives; importing
the package, or one of its submodules, then loads none of the others, so start-up pays only for what a
command uses. The submodule's name comes from the package's own table, never from data.
"""
from __future__ import annotations

import importlib
import sys
from typing import Callable, Mapping


def lazy_exports(package: str, homes: Mapping[str, str]) -> tuple[Callable[[str], object], Callable[[], list]]:
    """The package's module-level ``__getattr__`` and ``__dir__`` for ``homes`` (public name -> submodule)."""

    def __getattr__(name: str):
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{home}", package), name)
        setattr(sys.modules[package], name, value)      # found once; later lookups never reach __getattr__
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(homes))

    return __getattr__, __dir__
