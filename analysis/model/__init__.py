"""The lumped loudspeaker model (electrical + mechanical) composed with effects, its small formulas and its default effects.

The public names of analysis.model.composed (Model, ModelError, BASE_PARAMS, ...) are importable
from the package itself; each is loaded on first use.
"""
from __future__ import annotations

import importlib

# Where each public name lives; a name is imported on first use only, so that
# importing one submodule of the package does not load the rest.
_HOME = {
    "BASE_PARAMS": "composed",
    "BL_PARAM": "composed",
    "ELECTRICAL_BASE": "composed",
    "Model": "composed",
    "ModelError": "composed",
}

__all__ = sorted(_HOME)


def __getattr__(name: str):
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{home}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOME))
