"""The lumped loudspeaker model (electrical + mechanical) composed with effects, its small formulas and its default effects.

The public names of analysis.model.composed (Model, ModelError, BASE_PARAMS, ...) are importable
from the package itself; each is loaded on first use.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

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

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
