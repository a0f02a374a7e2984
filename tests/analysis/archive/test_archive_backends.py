"""One suite, both back ends: what every archive must do (analysis.archive.backends.ArchiveBackend).

Each test runs against the folder archive (folders + SQLite index) and the
PostgreSQL archive on the session's throw-away server (tests/pg_server.py);
without PostgreSQL installed the second half is skipped, saying what to install.
"""
import threading

import pytest

from analysis.archive import ArchiveError
from analysis.archive.backends import open_archive
from analysis.archive.population import Selection
from analysis.limits import LimitsError
from tests.production_helpers import LIMITS, small_measurement, unit


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


@pytest.fixture(params=["folder", "postgresql"])
def opener(request, tmp_path):
    """open(user) -> a new archive object on one archive: a folder, or one test database (users: conftest)."""
    if request.param == "folder":
        root = tmp_path / "archive"
        return lambda user="station_a": open_archive(str(root))
    db = request.getfixturevalue("pg_database")
    return lambda user="station_a": open_archive(db.url(user))


def test_store_list_get_and_the_files_byte_for_byte(opener, measured, tmp_path):
    path, doc = measured
    archive = opener()
    mid = archive.store(path, doc, {"driver": "woofer 6", "serial": "SN1", "operator": "ana", "station": "QA1",
                                    "measured_at": "2024-05-01T12:00:00+02:00"})
    (entry,) = opener().list()
    assert (entry.id, entry.driver, entry.serial, entry.station, entry.measured_at) == \
           (mid, "woofer 6", "SN1", "QA1", "2024-05-01T10:00:00Z")
    assert entry.parameters["fs"]["value"] == doc["parameters"]["fs"]["value"]
    assert entry.verdict is None and entry.limits_version is None      # no limits in the archive yet
    m = opener().get(mid[:-1])
    assert m.id == mid
    assert m.path("recording").read_bytes() == path.with_suffix(".wav").read_bytes()
    assert m.path("sidecar").read_bytes() == path.with_suffix(".json").read_bytes()
    assert m.result().parameters["Bl"].value == doc["parameters"]["Bl"]["value"]
    copy = opener().export(mid, tmp_path / "out")
    assert sorted(p.name for p in copy.iterdir()) == ["calibration.json", "measurement.json", "recording.json",
                                                      "recording.wav", "results.json", "settings.json"]
    assert archive.pending == 0


def test_list_filters_and_lookups(opener, measured):
    path, doc = measured
    archive = opener()
    ids = [archive.store(path, doc, {"driver": d, "serial": f"S{i}", "operator": "ana", "station": "QA1",
                                     "measured_at": f"2024-05-0{i + 1}T08:00:00Z"})
           for i, d in enumerate(("woofer", "woofer", "tweeter_x%"))]
    assert [e.id for e in archive.list()] == ids[::-1]                 # newest first
    assert [e.serial for e in archive.list(driver="TWEETER_X%")] == ["S2"]
    assert archive.list(driver="%") == archive.list(driver="tweeter_x%")   # '%' is a character, not a wildcard
    assert len(archive.list(limit=2)) == 2
    assert [e.serial for e in archive.list(since="2024-05-02", until="2024-05-02")] == ["S1"]
    assert archive.list(validity="red") == []
    with pytest.raises(ArchiveError, match="no measurement"):
        archive.get("19990101")
    with pytest.raises(ArchiveError, match="not a measurement id"):
        archive.get("../etc")
    with pytest.raises(ArchiveError, match="matches"):
        archive.get(ids[0][:4])


def test_limits_are_versioned_and_each_verdict_names_its_version(opener, measured):
    path, doc = measured
    archive = opener("eva")
    assert archive.limits() is None and archive.limits_versions() == []
    v1 = archive.store_limits(LIMITS, note="first article")
    assert (v1.version, v1.name, v1.note) == (1, "6-inch woofer", "first article")
    station = opener("station_a")
    good = station.store(path, unit(doc, fs=70.0, RE=3.0), {"serial": "good"})
    bad = station.store(path, unit(doc, fs=80.0, RE=3.0), {"serial": "bad"})
    stricter = {**LIMITS, "name": "tighter", "parameters": {"fs": {"min": 69.0, "max": 69.5, "unit": "Hz"}}}
    v2 = opener("eva").store_limits(stricter)
    later = station.store(path, unit(doc, fs=70.0), {"serial": "later"})
    verdicts = {e.serial: (e.verdict, e.limits_version) for e in opener().list()}
    assert verdicts == {"good": ("pass", 1), "bad": ("fail", 1), "later": ("fail", 2)}
    assert {good, bad, later} == {e.id for e in opener().list()}
    assert [v.version for v in opener().limits_versions()] == [1, 2]
    assert opener().limits().version == v2.version == 2
    assert opener().limits(1).document == v1.document                 # an old version stays as it was
    with pytest.raises(ArchiveError, match="no limits version 7"):
        opener().limits(7)
    with pytest.raises(LimitsError, match="parameters.fs.unit"):
        opener("eva").store_limits({**LIMITS, "parameters": {"fs": {"min": 1, "unit": "furlong"}}})
    assert [v.version for v in opener().limits_versions()] == [1, 2]


def test_golden_units(opener, measured):
    path, doc = measured
    station = opener("station_a")
    ids = [station.store(path, doc, {"serial": f"G{i}"}) for i in range(3)]
    engineer = opener("eva")
    assert engineer.golden() == []
    assert engineer.set_golden(ids[:2]) == ids[:2]
    assert engineer.set_golden([ids[0][:-1]], golden=False) == [ids[1]]
    assert opener().golden() == [ids[1]]
    with pytest.raises(ArchiveError, match="no measurement"):
        engineer.set_golden(["19990101-000000-abcdef"])


def test_population_selects_exactly_and_keeps_time_order(opener, measured):
    path, doc = measured
    station = opener()
    plan = [("QA1", "W6", 70.1), ("QA10", "W6", 70.2), ("QA1", "W8", 70.3), ("QA1", "W6", 70.4)]
    ids = [station.store(path, unit(doc, fs=fs), {"station": s, "driver": d,
                                                  "measured_at": f"2024-06-0{i + 1}T00:00Z"})
           for i, (s, d, fs) in enumerate(plan)]
    everything = opener().population()
    assert list(everything.ids) == ids and everything.values["fs"].tolist() == [70.1, 70.2, 70.3, 70.4]
    qa1 = opener().population(Selection(stations=("QA1",)).checked())        # not QA10
    assert qa1.values["fs"].tolist() == [70.1, 70.3, 70.4]
    w6 = opener().population(Selection(stations=("QA1",), drivers=("W6",), since="2024-06-02").checked(), ["fs"])
    assert w6.ids == (ids[3],) and set(w6.values) == {"fs"}
    assert w6.stds["fs"].tolist() == [doc["parameters"]["fs"]["std"]]
    assert len(opener().population(Selection(until="2024-05-31").checked())) == 0


def test_concurrent_stores_lose_and_duplicate_nothing(opener, measured):
    path, doc = measured
    ids, errors = [], []

    def station(name):
        archive = opener(name)
        try:
            for i in range(8):
                ids.append(archive.store(path, doc, {"station": name, "serial": f"{name}-{i}"}))
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)
    threads = [threading.Thread(target=station, args=(n,)) for n in ("station_a", "station_b", "station_c")]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    assert errors == []
    listed = opener().list()
    assert len(listed) == len(ids) == 24 and {e.id for e in listed} == set(ids)
    assert len({e.serial for e in listed}) == 24
