"""The measurement archive: folders of measurements and an SQLite index (no Qt, no numpy on import).

    Archive(root).store(recording, result, meta) -> id
    Archive(root).list(driver=..., validity=..., limit=...) -> [Entry]
    Archive(root).get(id) -> Measurement (.record, .path(role), .result())
    Archive(root).rebuild() -> RebuildReport
    compare(archive, ids) -> Comparison      (up to 8 measurements side by side)
    open_archive(spec) -> a folder archive, or the PostgreSQL archive a postgresql:// URL names
                                             (analysis.archive.backends: $LINPAR_ARCHIVE_URL, $LINPAR_ARCHIVE)
"""
from analysis.archive.archive import Archive, Measurement, MeasurementId, MeasurementMeta, default_root
from analysis.archive.backends import ArchiveBackend, SyncReport, archive_spec, is_url, open_archive
from analysis.archive.compare import MAX_COMPARED, Comparison, compare
from analysis.archive.index import Filter, RebuildReport
from analysis.archive.names import ArchiveError
from analysis.archive.record import Entry

__all__ = ["Archive", "ArchiveBackend", "ArchiveError", "Comparison", "Entry", "Filter", "MAX_COMPARED", "Measurement",
           "MeasurementId", "MeasurementMeta", "RebuildReport", "SyncReport", "archive_spec", "compare",
           "default_root", "is_url", "open_archive"]
