"""Data exchange: parameters (CSV, JSON), curves (.zma, .frd), the driver as a WinISD .wdr file.

Everything is built from a StoredResult (analysis.archive.results), so an
archived measurement and a freshly analysed recording export the same way;
`write_exports` writes every file atomically. The formats are the modules'
EXPORTERS, found by the registry (registry.py): a new format is one module.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Mapping

from analysis.export.curves import ExportError
from analysis.export.registry import Exporter, exporters
from analysis.files import write_atomic

if TYPE_CHECKING:      # a type only: listing the formats (the CLI's parser) loads no archive
    from analysis.archive.results import StoredResult


def export_bytes(kind: str, result: StoredResult, header: Mapping | None = None) -> bytes:
    known = exporters()
    if kind not in known:
        raise ValueError(f"unknown export {kind!r}; known: {', '.join(known)}")
    # The recording's session is the base, as in reports: the same header from a recording or the archive.
    header = {**result.session, **{k: v for k, v in dict(header or {}).items() if v}}
    if result.not_fitted and known[kind].needs_fit:
        where = header.get("source") or header.get("id")
        raise ExportError(f"{where + ': ' if where else ''}a {kind.replace('_', ' ')} export needs a fit, and "
                          f"nothing was fitted: {result.not_fitted}")
    return known[kind].write(result, header)


def write_exports(result: StoredResult, targets: Mapping[str, str | Path], header: Mapping | None = None) -> list[Path]:
    """targets: kind -> file. Every file is made in memory first, so an error writes none of them."""
    payloads = {kind: export_bytes(kind, result, header) for kind in targets}
    return [write_atomic(targets[kind], data) for kind, data in payloads.items()]


__all__ = ["ExportError", "Exporter", "export_bytes", "exporters", "write_exports"]
