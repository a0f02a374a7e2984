"""Data exchange: parameters (CSV, JSON), curves (.zma, .frd), the driver as a WinISD .wdr file.

Everything is built from a StoredResult (analysis.archive.results), so an
archived measurement and a freshly analysed recording export the same way;
`write_exports` writes every file atomically.
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

from analysis.archive.atomic import write_atomic
from analysis.archive.results import StoredResult
from analysis.export.curves import ExportError, frd_text, zma_text
from analysis.export.parameters import parameters_csv, parameters_json
from analysis.export.winisd import wdr_bytes
from analysis.session import HEADER_KEYS

KINDS = ("csv", "json", "zma", "zma_model", "frd", "frd_model", "driver")


# Exports of a result with nothing fitted (a broken measurement): its parameters, each "not measured" and why.
JUDGED_WITHOUT_FIT = ("csv", "json")


def trace_line(header: Mapping) -> str:
    """The header (analysis.session) on one line, for the comment lines of curve files."""
    return ", ".join(f"{k.replace('_', ' ')} {header[k]}" for k in HEADER_KEYS if header.get(k))


def export_bytes(kind: str, result: StoredResult, header: Mapping | None = None) -> bytes:
    # The recording's session is the base, as in reports: the same header from a recording or the archive.
    header = {**result.session, **{k: v for k, v in dict(header or {}).items() if v}}
    if result.not_fitted and kind not in JUDGED_WITHOUT_FIT:
        where = header.get("source") or header.get("id")
        raise ExportError(f"{where + ': ' if where else ''}a {kind.replace('_', ' ')} export needs a fit, and "
                          f"nothing was fitted: {result.not_fitted}")
    title = trace_line(header)
    if kind == "csv":
        return parameters_csv(result).encode("utf-8")
    if kind == "json":
        return parameters_json(result, header).encode("utf-8")
    if kind in ("zma", "zma_model"):
        return zma_text(result, "model" if kind.endswith("model") else "measured", title).encode("utf-8")
    if kind in ("frd", "frd_model"):
        return frd_text(result, "model" if kind.endswith("model") else "measured", title).encode("utf-8")
    if kind == "driver":
        return wdr_bytes(result, header)
    raise ValueError(f"unknown export {kind!r}; known: {', '.join(KINDS)}")


def write_exports(result: StoredResult, targets: Mapping[str, str | Path], header: Mapping | None = None) -> list[Path]:
    """targets: kind -> file. Every file is made in memory first, so an error writes none of them."""
    payloads = {kind: export_bytes(kind, result, header) for kind in targets}
    return [write_atomic(targets[kind], data) for kind, data in payloads.items()]


__all__ = ["ExportError", "KINDS", "export_bytes", "write_exports"]
