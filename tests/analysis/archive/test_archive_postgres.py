"""What only the PostgreSQL archive does: roles the server enforces, a station's queue sent exactly once
whatever breaks when, files checked against their SHA-256, versioned schema. On the session's throw-away
server (tests/pg_server.py); skipped, saying what to install, without PostgreSQL."""
import psycopg
import pytest

from analysis.archive import ArchiveError
from analysis.archive.archive import Archive
from analysis.archive.backends import open_archive
from analysis.archive.pg import ServerRefused, setup
from analysis.archive.pg import upload as upload_module
from analysis.archive.pg.schema import CURRENT_VERSION
from tests.production_helpers import LIMITS, small_measurement, unit
from tests.tcp_proxy import TcpProxy


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


def server_ids(db) -> list[str]:
    with db.admin() as conn:
        return [r[0] for r in conn.execute("SELECT id FROM linpar.measurements ORDER BY id").fetchall()]


def test_the_server_refuses_what_a_role_may_not_do(pg_database, measured):
    path, doc = measured
    station = open_archive(pg_database.url("station_a"))
    with pytest.raises(ServerRefused, match=r"refused storing a limits version: permission denied for table "
                                            r"limits_versions: the database user 'station_a' may not \(an engineer"):
        station.store_limits(LIMITS)
    mid = station.store(path, doc, {"serial": "SN1"})
    with pytest.raises(ServerRefused, match="golden_units"):
        station.set_golden([mid])
    auditor = open_archive(pg_database.url("audrey"))
    assert [e.id for e in auditor.list()] == [mid]                    # an auditor reads
    with pytest.raises(ServerRefused, match="waits in the local queue") as refused:
        auditor.store(path, doc, {"serial": "SN2"})                 # ... and stores nothing
    assert refused.value.queued_id and auditor.pending == 1           # kept at the station, not lost
    with pytest.raises(ServerRefused, match="limits_versions"):
        auditor.store_limits(LIMITS)
    engineer = open_archive(pg_database.url("eva"))
    assert engineer.store_limits(LIMITS).version == 1
    assert engineer.set_golden([mid]) == [mid]
    assert server_ids(pg_database) == [mid]


def test_no_login_user_can_change_or_remove_what_is_stored(pg_database, measured):
    path, doc = measured
    mid = open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "SN1"})
    with pg_database.admin() as conn:
        (lo,) = conn.execute("SELECT lo FROM linpar.files WHERE measurement_id = %s AND role = 'recording'",
                             (mid,)).fetchone()
    for user in ("station_a", "eva"):
        with psycopg.connect(pg_database.url(user), autocommit=True) as conn:
            for statement, args in (("UPDATE linpar.measurements SET verdict = 'pass'", ()),
                                    ("DELETE FROM linpar.measurements", ()),
                                    ("UPDATE linpar.parameters SET value = 1", ()),
                                    ("SELECT lo_put(%s, 0, '\\x00'::bytea)", (lo,)),
                                    ("SELECT lo_unlink(%s)", (lo,)),
                                    ("SELECT linpar.file_write(%s, 0, '\\x00'::bytea, "
                                     "encode(sha256('\\x00'::bytea), 'hex'))", (lo,))):
                with pytest.raises(psycopg.errors.InsufficientPrivilege):
                    conn.execute(statement, args)
    m = open_archive(pg_database.url("audrey")).get(mid)
    assert m.path("recording").read_bytes() == path.with_suffix(".wav").read_bytes()


def test_a_station_cut_off_from_the_server_queues_and_sends_each_once_when_it_is_back(pg_database, measured):
    path, doc = measured
    proxy = TcpProxy(pg_database.server.port)
    try:
        url = pg_database.url("station_b").replace(f":{pg_database.server.port}/", f":{proxy.port}/")
        station = open_archive(url + "?connect_timeout=2")
        before = [station.store(path, doc, {"serial": f"A{i}"}) for i in range(2)]
        proxy.cut()
        station = open_archive(url + "?connect_timeout=2")
        during = [station.store(path, doc, {"serial": f"B{i}"}) for i in range(3)]
        assert station.pending == 3
        assert any("cannot reach the server" in n and "waits in the local queue" in n for n in station.notes)
        with pytest.raises(ArchiveError, match="cannot reach the server"):
            station.list()
        assert server_ids(pg_database) == sorted(before)
        proxy.restore()
        after = open_archive(url).store(path, doc, {"serial": "C0"})
        assert server_ids(pg_database) == sorted([*before, *during, after])
        assert open_archive(url).pending == 0
        serials = sorted(e.serial for e in open_archive(pg_database.url("audrey")).list())
        assert serials == ["A0", "A1", "B0", "B1", "B2", "C0"]
    finally:
        proxy.close()


def test_a_send_the_station_never_heard_back_from_is_not_stored_twice(pg_database, measured, monkeypatch):
    path, doc = measured
    station = open_archive(pg_database.url("station_a"))

    class Killed(BaseException):
        """The station dies after the server committed, before it removed its copy."""
    real = Archive.discard
    monkeypatch.setattr(Archive, "discard", lambda self, mid: (_ for _ in ()).throw(Killed()))
    with pytest.raises(Killed):
        station.store(path, doc, {"serial": "once"})
    monkeypatch.setattr(Archive, "discard", real)
    station = open_archive(pg_database.url("station_a"))
    assert station.pending == 1
    report = station.sync()
    assert report.already and not report.sent and station.pending == 0
    assert len(server_ids(pg_database)) == 1


def test_a_connection_dropped_in_the_middle_of_a_send_stores_nothing_until_it_is_sent_again(
        pg_database, measured, monkeypatch):
    path, doc = measured
    real = upload_module.send_file
    calls = []

    def dropped(conn, mid, role, name, file_path):
        real(conn, mid, role, name, file_path)
        calls.append(role)
        if len(calls) == 2:        # after two of the files: the server drops this session
            with pg_database.admin() as admin:
                admin.execute("SELECT pg_terminate_backend(%s)", (conn.info.backend_pid,))
    monkeypatch.setattr(upload_module, "send_file", dropped)
    station = open_archive(pg_database.url("station_a"))
    mid = station.store(path, doc, {"serial": "dropped"})
    assert station.pending == 1 and server_ids(pg_database) == []
    with pg_database.admin() as conn:
        assert conn.execute("SELECT count(*) FROM linpar.files").fetchone()[0] == 0
        assert conn.execute("SELECT count(*) FROM pg_largeobject_metadata").fetchone()[0] == 0   # nothing half
    monkeypatch.setattr(upload_module, "send_file", real)
    assert open_archive(pg_database.url("station_a")).sync().sent == [mid]
    m = open_archive(pg_database.url("audrey")).get(mid)
    assert m.path("recording").read_bytes() == path.with_suffix(".wav").read_bytes()


def test_two_stations_that_draw_the_same_id_both_keep_their_measurement(pg_database, measured, monkeypatch):
    path, doc = measured
    import analysis.archive.archive as archive_module
    monkeypatch.setattr(archive_module, "new_measurement_id", lambda now=None: "20240501-120000-abcdef")
    first = open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "A"})
    second = open_archive(pg_database.url("station_b")).store(path, unit(doc, fs=71.0), {"serial": "B"})
    assert first == "20240501-120000-abcdef" and second != first and second.startswith("20240501-120000-")
    entries = {e.serial: e for e in open_archive(pg_database.url("audrey")).list()}
    assert (entries["A"].id, entries["B"].id) == (first, second)
    assert entries["B"].parameters["fs"]["value"] == 71.0


def test_a_measurement_sent_under_a_new_id_and_never_acknowledged_is_not_stored_twice(pg_database, measured,
                                                                                       monkeypatch):
    path, doc = measured
    import analysis.archive.archive as archive_module
    monkeypatch.setattr(archive_module, "new_measurement_id", lambda now=None: "20240501-120000-abcdef")
    open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "A"})

    class Killed(BaseException):
        """Station B dies after the server committed its measurement under a new id, before it heard back."""
    real = Archive.discard
    monkeypatch.setattr(Archive, "discard", lambda self, mid: (_ for _ in ()).throw(Killed()))
    with pytest.raises(Killed):
        open_archive(pg_database.url("station_b")).store(path, unit(doc, fs=71.0), {"serial": "B"})
    monkeypatch.setattr(Archive, "discard", real)
    report = open_archive(pg_database.url("station_b")).sync()
    assert report.already and not report.sent
    assert len(server_ids(pg_database)) == 2


def test_a_file_damaged_on_the_server_is_refused_by_its_checksum(pg_database, measured):
    path, doc = measured
    mid = open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "SN1"})
    with pg_database.admin() as conn:
        conn.execute("SELECT lo_put(lo, 100, '\\xdeadbeef'::bytea) FROM linpar.files "
                     "WHERE measurement_id = %s AND role = 'recording'", (mid,))
    with pytest.raises(ArchiveError, match="does not match its checksum"):
        open_archive(pg_database.url("audrey")).get(mid).path("recording")


def test_the_schema_is_versioned_and_setup_is_idempotent(pg_database):
    report = setup(pg_database.url("linpar_admin"), {"station_a": "operator"})
    assert (report.schema_from, report.schema_to) == (CURRENT_VERSION, CURRENT_VERSION)
    assert "station_a: updated, auditor, operator" in report.describe()
    with pg_database.admin() as conn:
        conn.execute("UPDATE linpar.schema_version SET version = 99")
    with pytest.raises(ServerRefused, match="version 99, newer than this program's .*update linpar"):
        open_archive(pg_database.url("audrey")).list()
    pg_database.server.create_database(pg_database.name + "_empty")
    with pytest.raises(ServerRefused, match="holds no linpar archive: its owner creates it with 'linpar archive "
                                            "setup"):
        open_archive(pg_database.server.url("audrey", pg_database.name + "_empty")).list()


@pytest.mark.parametrize("url, message", [
    ("postgresql://u@h:notaport/db", "port 'notaport'"),
    ("postgresql://u@h/db?bogus=1", "not a PostgreSQL URL"),
    ("postgresql://u@h/db?connect_timeout=0", "connect_timeout"),
    ("mysql://u@h/db", "unknown kind of archive"),
    ("postgresql://u:secret@h/db?bogus=1", r"u:\*\*\*@h"),
])
def test_a_bad_url_is_one_line_without_the_password(url, message):
    with pytest.raises(ArchiveError, match=message) as error:
        open_archive(url)
    assert "secret" not in str(error.value) and "\n" not in str(error.value)
