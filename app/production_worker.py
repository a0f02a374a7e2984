"""The Production page's statistics off the GUI thread: read the population (a server may be slow or gone),
compute the statistics, hand back one frozen result or one line of error.

Built like app.archive_worker: a one-thread pool (the newest request is the
one shown; an older one still running is cancelled and its result dropped).
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, Signal

from app.job_book import JobBook, failure_text


@dataclass(frozen=True, slots=True)
class ProductionRequest:
    source: str                     # the archive: a folder or a postgresql:// URL
    since: str | None = None
    until: str | None = None
    station: str | None = None
    driver: str | None = None
    baseline: int = 50


@dataclass(frozen=True, slots=True)
class ProductionData:
    request: ProductionRequest
    location: str
    population: Any                 # analysis.archive.population.Population
    stats: Any                      # analysis.production.ProductionStats
    excluded_ids: frozenset         # left out of the statistics (red, not judgeable), for the exports
    notes: tuple[str, ...]


class _Job:
    def __init__(self, job: int, request: ProductionRequest, worker: "ProductionWorker"):
        self.id = job
        self.request = request
        self._worker = worker
        self.cancel_event = threading.Event()     # NB: set by the GUI thread, read by the pool thread

    def cancel(self) -> None:
        self.cancel_event.set()

    def __call__(self) -> None:
        try:
            data = compute(self.request)
        except Exception as exc:  # noqa: BLE001 - the job runner is the GUI's error boundary (job_book)
            if not self.cancel_event.is_set():
                self._worker.failed.emit(self.id, failure_text(exc, "computing the production statistics"))
            else:
                self._worker.cancelled.emit(self.id)
            return
        if self.cancel_event.is_set():
            self._worker.cancelled.emit(self.id)
        else:
            self._worker.computed.emit(self.id, data)


def compute(request: ProductionRequest) -> ProductionData:
    from analysis.archive import open_archive
    from analysis.archive.population import Selection
    from analysis.production import production_stats
    from analysis.production.summary import NOT_JUDGEABLE
    archive = open_archive(request.source)
    selection = Selection(request.since, request.until, (request.station,) if request.station else (),
                          (request.driver,) if request.driver else ()).checked()
    population = archive.population(selection)
    stats = production_stats(population, archive.limits(), request.baseline, None, selection.describe())
    excluded = frozenset(i for i, v, d in zip(population.ids, population.validity, population.verdicts)
                         if v == "red" or d in NOT_JUDGEABLE)
    return ProductionData(request, archive.location, population, stats, excluded, tuple(archive.notes))


class ProductionWorker(QObject, JobBook):
    computed = Signal(int, object)      # job id, ProductionData
    failed = Signal(int, str)           # job id, one line for the user
    cancelled = Signal(int)

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self._init_jobs(self, (self.computed, self.failed, self.cancelled), max_threads=1)

    def start(self, request: ProductionRequest) -> int:
        self.cancel_all()               # only the newest request's result is shown
        return self._start(_Job(self._next_id(), request, self)).id
