"""A station's queue is its server's, whatever the URL's spelling (issue 31): queued via 127.0.0.1, it is sent
via localhost or a URL without a port, each measurement once; a queue a linpar kept per URL is moved, not
orphaned. On the session's throw-away server, reached through a TCP proxy that a test can cut."""
from pathlib import Path

import pytest

from analysis.archive.archive import Archive
from analysis.archive.backends import open_archive
from analysis.archive.pg.outbox import Outbox, queue_folder
from analysis.archive.pg.queue_identity import POINTER_FILE, remembered
from analysis.archive.pg.server import parse_url
from tests.production_helpers import small_measurement
from tests.tcp_proxy import TcpProxy


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


@pytest.fixture
def proxy(pg_database):
    proxy = TcpProxy(pg_database.server.port)
    yield proxy
    proxy.close()


def _serials(db) -> list[str]:
    with db.admin() as conn:
        return sorted(r[0] for r in conn.execute("SELECT serial FROM linpar.measurements").fetchall())


def _spelling(db, host: str, port: int | None) -> str:
    where = f"{host}:{port}" if port else host
    return f"postgresql://station_a@{where}/{db.name}?connect_timeout=2"


@pytest.mark.parametrize("other_host, with_port", [("localhost", True), ("127.0.0.1", False),
                                                   ("localhost", False)])
def test_two_spellings_of_one_server_share_one_queue(pg_database, measured, proxy, monkeypatch, other_host,
                                                     with_port):
    path, doc = measured
    monkeypatch.setenv("PGPORT", str(proxy.port))        # where libpq goes when the URL names no port
    first = _spelling(pg_database, "127.0.0.1", proxy.port)
    other = _spelling(pg_database, other_host, proxy.port if with_port else None)
    assert parse_url(first).slug != parse_url(other).slug           # two spellings, two URL folders
    sent_before = open_archive(first).store(path, doc, {"serial": "before"})
    proxy.cut()
    station = open_archive(first)
    queued = station.store(path, doc, {"serial": "queued"})
    assert station.pending == 1 and _serials(pg_database) == ["before"]
    proxy.restore()
    report = open_archive(other).sync()             # the case: 'nothing waits' here, it did
    assert report.sent == [queued] and report.waiting == 0, report
    assert _serials(pg_database) == ["before", "queued"]                   # each once
    assert open_archive(first).pending == 0 and open_archive(other).pending == 0
    assert open_archive(first).sync().sent == [] and _serials(pg_database) == ["before", "queued"]
    assert remembered(queue_folder(parse_url(first).slug)) == remembered(queue_folder(parse_url(other).slug))
    assert sent_before


def test_a_queue_kept_per_url_by_an_older_linpar_is_moved_not_orphaned(pg_database, measured, proxy):
    path, doc = measured
    url = _spelling(pg_database, "127.0.0.1", proxy.port)
    old_folder = queue_folder(parse_url(url).slug)
    old_ids = [Outbox(old_folder).put(path, doc, {"serial": f"old{i}"}, None, None, None) for i in range(2)]
    assert not (old_folder / POINTER_FILE).exists() and len(Archive(old_folder).list()) == 2

    proxy.cut()                       # cut off: what waits in the URL's folder is still this station's queue
    assert open_archive(url).pending == 2
    proxy.restore()
    station = open_archive(url)
    mid = station.store(path, doc, {"serial": "new"})       # the first connection finds the server's identity
    assert _serials(pg_database) == ["new", "old0", "old1"] and station.pending == 0
    identity = remembered(old_folder)
    assert identity is not None and identity != old_folder and Archive(old_folder).list() == []
    assert mid and len(old_ids) == 2

    # An older linpar, still running at the station, queues under the URL again: the next opening moves it.
    late = Outbox(old_folder).put(path, doc, {"serial": "late"}, None, None, None)
    proxy.cut()
    station = open_archive(url)
    assert station.pending == 1 and Path(station.outbox.root) == identity
    assert [e.id for e in Archive(identity).list()] == [late] and Archive(old_folder).list() == []
    proxy.restore()
    assert open_archive(url).sync().sent == [late]
    assert _serials(pg_database) == ["late", "new", "old0", "old1"]
