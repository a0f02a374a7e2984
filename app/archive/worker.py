"""The archive's slow work off the GUI thread: storing a measurement, loading a comparison, rebuilding the index;
and for an archive on a PostgreSQL server, listing and sending the station's queue (a server may be slow or gone).

An ArchiveWorker is a JobRunner (app.jobs.book) with one thread, so a store
and the rebuild that follows it run in the order asked. Each job opens its
own archive (analysis.archive.open_archive of the page's source: its own
connection, its own repair notes). What crosses to the GUI thread is frozen,
or one line of text: every archive error (ArchiveError, SQLite, the file
system, a results file that does not read) becomes that line.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

from PySide6.QtCore import QObject, Signal

from app.jobs.book import Job, JobRunner
from instruments.measurement.raw_stream import raw_capture_path


@dataclass(frozen=True, slots=True)
class StoredMeasurement:
    id: str
    recording: Path             # the recording that was stored (it stays where it was)
    notes: tuple[str, ...]      # what opening the index had to repair
    queued: bool = False        # the server could not be reached: it waits in the station's queue


@dataclass(frozen=True, slots=True)
class ComparisonData:
    comparison: Any                         # analysis.archive.Comparison
    dates: tuple[str, ...]                  # measured_at of each, as the index has it
    curves: tuple[Mapping[str, Any], ...]   # per measurement: channel -> analysis.archive.results.Curve
    notes: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class RebuildDone:
    text: str                   # RebuildReport.describe() (or SyncReport.describe() for a server's queue)
    skipped: int


@dataclass(frozen=True, slots=True)
class Listed:
    entries: tuple              # analysis.archive.Entry, newest first
    notes: tuple[str, ...]


def laser_stream_of(recording: Path) -> Path | None:
    """NAME.laser.npz next to NAME.wav, written by the runner when a serial laser was read."""
    path = raw_capture_path(recording.with_suffix(""))
    return path if path.is_file() else None


class ArchiveWorker(JobRunner):
    """A JobRunner with one result signal per kind of job; one thread, so a store and its rebuild keep order."""

    stored = Signal(int, object)        # job id, StoredMeasurement
    compared = Signal(int, object)      # job id, ComparisonData
    rebuilt = Signal(int, object)       # job id, RebuildDone
    listed = Signal(int, object)        # job id, Listed
    result_signals = ("stored", "compared", "rebuilt", "listed")

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent, max_threads=1)

    def result_signal(self, job: Job) -> str:
        return job.kind

    def _run(self, kind: str, root, work: Callable[[Job], object]) -> Job:
        from analysis.archive.backends import shown
        return self.run(kind, work, f"the archive's {kind} ({shown(str(root))})")

    def store(self, root: str | Path, recording: Path, result, meta: Mapping[str, Any]) -> Job:
        """Store a recording file and its analysis.pipeline.AnalysisResult with `meta` (MeasurementMeta's keys)."""
        def work(job):
            from analysis.archive import open_archive
            archive = open_archive(str(root))
            mid = archive.store(recording, result, dict(meta), laser_stream=laser_stream_of(recording))
            return StoredMeasurement(mid, recording, tuple(archive.notes), archive.pending > 0)
        return self._run("stored", root, work)

    def compare(self, root: str | Path, ids: list[str]) -> Job:
        """analysis.archive.compare of `ids`, with each one's stored curves for the overlay."""
        ids = list(ids)

        def work(job):
            from analysis.archive import compare, open_archive
            archive = open_archive(str(root))
            comparison = compare(archive, ids)
            dates, curves = [], []
            for mid in comparison.ids:
                job.check()
                m = archive.get(mid)
                dates.append(m.entry.measured_at)
                curves.append(dict(m.result().curves))
            return ComparisonData(comparison, tuple(dates), tuple(curves), tuple(archive.notes))
        return self._run("compared", root, work)

    def rebuild(self, root: str | Path) -> Job:
        """Rebuild a folder archive's index; for a server, send this station's queue (it has no index)."""
        def work(job):
            from analysis.archive import is_url, open_archive
            archive = open_archive(str(root))
            if is_url(str(root)):
                report = archive.sync()
                return RebuildDone(f"queue sent: {report.describe()}", report.waiting)
            report = archive.rebuild()
            return RebuildDone(report.describe(), len(report.skipped))
        return self._run("rebuilt", root, work)

    def list(self, root: str | Path, flt) -> Job:
        """List an archive (on a server: the GUI thread must not wait for the network)."""
        def work(job):
            from analysis.archive import open_archive
            archive = open_archive(str(root))
            return Listed(tuple(archive.list(flt)), tuple(archive.notes))
        return self._run("listed", root, work)
