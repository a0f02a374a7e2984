"""The export formats, found rather than listed: every module of
analysis.export that defines ``EXPORTERS`` (a tuple of Exporter) adds its
formats, so a new format is one module (and its test) and nothing else: the
CLI's options (`linpar export --KIND FILE`) and the GUI's Export data dialog
are built from this registry.
"""
from __future__ import annotations

import pkgutil
from dataclasses import dataclass
from importlib import import_module
from typing import Callable


@dataclass(frozen=True)
class Exporter:
    """One export format of a measurement's result (analysis.archive.results.StoredResult).

    kind: the name in `write_exports` targets and the CLI option (--zma-model);
    title: what the file holds, for people ("Measured impedance");
    write(result, header) -> bytes: the file, header being the traceability
    header (analysis.session.HEADER_KEYS) merged with the result's session;
    needs_fit: refused for a result with nothing fitted (a broken measurement);
    in_menu: offered by the GUI's Export data dialog; rank: where it is listed.
    """

    kind: str
    title: str
    suffix: str
    write: Callable[..., bytes]
    needs_fit: bool = True
    in_menu: bool = True
    rank: int = 100


_found: dict[str, Exporter] = {}


def exporters() -> dict[str, Exporter]:
    """Every export format by kind, in listing order (rank, then kind)."""
    if not _found:
        package = import_module("analysis.export")
        found: list[Exporter] = []
        for info in pkgutil.iter_modules(package.__path__):
            module = import_module(f"analysis.export.{info.name}")
            found.extend(getattr(module, "EXPORTERS", ()))
        kinds = [e.kind for e in found]
        twice = sorted({k for k in kinds if kinds.count(k) > 1})
        if twice:
            raise RuntimeError(f"export kinds defined twice: {', '.join(twice)}")
        _found.update((e.kind, e) for e in sorted(found, key=lambda e: (e.rank, e.kind)))
    return dict(_found)
