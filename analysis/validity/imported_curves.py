"""What imported curves' validity says instead of the checks: a result's `imported` (analysis.validity.result).

Apart from the result's validity so that the analysis of a recording, which never has one, does not make
its dataclass at every start.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Mapping

from analysis.validity.frozen_json import frozen, rebuilt, thawed


@dataclass(frozen=True, kw_only=True, slots=True)
class ImportedCurves:
    """What imported curves' validity says instead of checks (analysis.curves.fitting): no per-line noise of their
    own, and how far to trust the numbers."""

    note: str
    uncertainties: str
    rms_relative_residual: Mapping[str, float | None]
    magnitude_only: tuple[str, ...]                     # the curves without phase
    ranges_hz: Mapping[str, tuple[float, float]]        # the band each curve was fitted over
    notes: tuple[str, ...]

    def __post_init__(self) -> None:
        for name in ("rms_relative_residual", "magnitude_only", "ranges_hz", "notes"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def __reduce__(self):
        return rebuilt, (type(self), {f.name: thawed(getattr(self, f.name)) for f in dataclasses.fields(self)})
