"""The measurement archive: folders of measurements and an SQLite index (no Qt, no numpy on import).

    Archive(root).store(recording, result, meta) -> id
    Archive(root).list(driver=..., validity=..., limit=...) -> [Entry]
    Archive(root).get(id) -> Measurement (.record, .path(role), .result())
    Archive(root).rebuild() -> RebuildReport
    compare(archive, ids) -> Comparison      (up to 8 measurements side by side)
"""
from analysis.archive.archive import Archive, Measurement, MeasurementId, MeasurementMeta, default_root
from analysis.archive.compare import MAX_COMPARED, Comparison, compare
from analysis.archive.index import Filter, RebuildReport
from analysis.archive.names import ArchiveError
from analysis.archive.record import Entry

__all__ = ["Archive", "ArchiveError", "Comparison", "Entry", "Filter", "MAX_COMPARED", "Measurement",
           "MeasurementId", "MeasurementMeta", "RebuildReport", "compare", "default_root"]
