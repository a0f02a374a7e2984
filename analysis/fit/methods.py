"""The identification methods a user can choose by name (`--method`, the GUI's analysis options).

- joint: Z and Hx fitted together, every line weighted by its own noise (analysis.fit.least_squares). The default: on
  recordings the model describes it is the most efficient, and on the realistic recordings of the tests
  (several physics at once, none in the model's form) it comes closer than the two steps.
- paper: the seed paper's two steps, Z for the electrical parameters, then Hx for Bl and the creep with
  those held (analysis.fit.paper): neither channel's misfit bends what the other determines. The one to
  use on curves exported by other tools, magnitude only, whose Z misfit at low frequency would pull the
  creep in a joint fit.
- alternating: the paper's two steps repeated until they agree, the creep left to Hx (analysis.fit.alternating).
  The default for imported magnitude-only curves (analysis.curves.fitting.default_method): within 3 % on
  LPM-like exports of realistic drivers, where the joint fit lands 5-21 % off.
"""
from __future__ import annotations

import threading
from typing import Callable, Mapping

from analysis.errors import LinparError

DEFAULT_METHOD = "joint"
METHODS = {
    "joint": "Z and Hx fitted together, each line weighted by its noise",
    "paper": "the paper's two steps: Z for the electrical parameters, then Hx for Bl and the creep",
    "alternating": "the paper's two steps repeated until they agree, the creep fitted on Hx alone",
}


class UnknownMethodError(LinparError, ValueError):
    pass


def check_method(name: str) -> str:
    """`name` when it is a method; UnknownMethodError naming the known ones otherwise."""
    if name not in METHODS:
        raise UnknownMethodError(f"unknown identification method {name!r}: choose one of {', '.join(METHODS)}")
    return name


def fitter(name: str) -> Callable:
    """The fit function of method `name`: (data, model, start=None, cancel=None) -> FitResult."""
    check_method(name)
    if name == "paper":
        from analysis.fit.paper import fit_paper
        return fit_paper
    if name == "alternating":
        from analysis.fit.alternating import fit_alternating
        return fit_alternating
    from analysis.fit.least_squares import fit_model
    return fit_model


def fit_with(name: str, data, model, start: Mapping[str, float] | None = None,
             cancel: threading.Event | None = None):
    return fitter(name)(data, model, start=start, cancel=cancel)
