"""Diagnosis: which physical effect a fitted model lacks, and where the physics is missing.

The candidates' refits and their ranking (candidates), the acceptance of a move (acceptance),
the residuals' structure (residuals), the sites of a misfit (sites, site_correction) and the
words that explain a verdict (words). The public names of analysis.diagnosis.candidates
(diagnose, explain, Candidate, ...) are importable from the package itself; each is loaded on first use.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

# Where each public name lives; a name is imported on first use only, so that
# importing one submodule of the package does not load the rest.
_HOME = {
    "MIN_BIC_GAIN": "candidates",
    "MAX_STEPS": "candidates",
    "Action": "candidates",
    "Candidate": "candidates",
    "Step": "candidates",
    "Diagnosis": "candidates",
    "candidate_models": "candidates",
    "rank_candidates": "candidates",
    "diagnose": "candidates",
    "explain": "candidates",
}

__all__ = sorted(_HOME)

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
