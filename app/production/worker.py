"""The Production page's statistics off the GUI thread: read the population (a server may be slow or gone),
compute the statistics, hand back one frozen result or one line of error.

A ProductionWorker is a JobRunner (app.jobs.book) with one thread: the
newest request is the one shown; an older one still running is cancelled
and its result dropped.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject

from app.jobs.book import Job, JobRunner


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


def store_limits(source: str, path: str, note: str = "") -> str:
    """Store a limits file as the archive's next limits version (every check of `linpar qa limits --store`);
    the line that says what was stored. A server refuses a user whose role may not (ServerRefused)."""
    import json

    from analysis.archive import open_archive
    from analysis.files import read_text
    from analysis.limits import LimitsError, load_limits
    load_limits(path)                                       # every check of a limits file, with its lines
    document = json.loads(read_text(path, "config", "a JSON limits file", LimitsError))
    archive = open_archive(source)
    version = archive.store_limits(document, note)
    return f"Stored {path} as limits version {version.version} ({version.name}) in {archive.location}."


class ProductionWorker(JobRunner):
    def __init__(self, parent: QObject | None = None):
        super().__init__(parent, max_threads=1)

    def start(self, request: ProductionRequest) -> Job:
        self.cancel_all()               # only the newest request's result is shown
        return self.run("statistics", lambda job: compute(request), "computing the production statistics")

    def store(self, source: str, path: str, note: str = "") -> Job:
        return self.run("limits", lambda job: store_limits(source, path, note), f"storing the limits {path}")
