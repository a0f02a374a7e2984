"""The joint weighted least-squares fit of Z and Hx, its start values, its report and its stalls.

The public names of analysis.fit.least_squares (fit_model, fit_recording, FitData, FitResult, ...)
are importable from the package itself; each is loaded on first use.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

# Where each public name lives; a name is imported on first use only, so that
# importing one submodule of the package does not load the rest.
_HOME = {
    "ASSUMED_RELATIVE_STD": "least_squares",
    "CHANNELS": "least_squares",
    "ChannelFit": "least_squares",
    "EVALUATIONS_PER_PARAMETER": "least_squares",
    "FitCancelled": "least_squares",
    "FitData": "least_squares",
    "FitError": "least_squares",
    "FitResult": "least_squares",
    "RELATIVE_STD_FLOOR": "least_squares",
    "StallWatch": "least_squares",
    "channel_sigmas": "least_squares",
    "component_sigma": "least_squares",
    "fit_model": "least_squares",
    "linear_gain": "least_squares",
    "screen_fit": "least_squares",
    "start_context": "least_squares",
    "start_values": "least_squares",
}

__all__ = sorted(_HOME)

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
