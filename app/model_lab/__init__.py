"""The Model lab page and its parts: the candidates' table, the effects' catalogue, a new effect's editor, the plots, the sites and the versions.

ModelLab (app.model_lab.page) is importable from the package itself; it is loaded on first use.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

# Where each public name lives; a name is imported on first use only, so that
# importing one submodule of the package does not load the rest.
_HOME = {
    "APPLY_TIP": "page",
    "CandidatesPanel": "page",
    "ChartPoint": "page",
    "ChiSquareChart": "page",
    "EMPTY_TEXT": "page",
    "EffectCatalogue": "page",
    "LabSession": "session",
    "LabVersion": "page",
    "ModelLab": "page",
    "ResidualPanel": "page",
    "SitePanel": "page",
    "changed_model": "page",
    "chi2_text": "plots",
    "fit_words": "page",
    "move_text": "page",
}

__all__ = sorted(_HOME)

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
