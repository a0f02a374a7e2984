"""The server enforces the audit trail (issue 31, class 6): each forgery tried as each role, directly against a
test server, is refused or overwritten by the server's own word; setup migrates an existing line."""
import json
import time
from datetime import datetime, timedelta, timezone

import psycopg
import pytest

from analysis.archive import open_archive
from analysis.archive.pg import setup
from analysis.archive.pg.schema import CURRENT_VERSION, MIGRATIONS
from tests.pg_server import ADMIN
from tests.production_helpers import LIMITS, small_measurement

FORGED_WHEN = datetime(2001, 1, 1, tzinfo=timezone.utc)


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))


def _as(db, user):
    return psycopg.connect(db.url(user), autocommit=True)


def _row_of(db, mid):
    with db.admin() as conn:
        return conn.execute("SELECT id, folder, measured_at, stored_at, driver, serial, operator, station, validity, "
                            "record, record_sha256 FROM linpar.measurements WHERE id = %s", (mid,)).fetchone()


def _insert_measurement(conn, row, new_id, **forged):
    columns = ["id", "folder", "measured_at", "stored_at", "driver", "serial", "operator", "station", "validity",
               "record", "record_sha256", *forged]
    values = [new_id, row[1] + "-copy" + new_id[-2:], *row[2:9], json.dumps(row[9]), row[10], *forged.values()]
    conn.execute(f"INSERT INTO linpar.measurements ({', '.join(columns)}) VALUES "
                 f"({', '.join(['%s'] * len(values))})", values)


@pytest.mark.parametrize("user", ["station_a", "eva"])          # an operator, an engineer (an operator too)
def test_a_measurement_stored_under_another_name_and_date_gets_the_sessions(pg_database, measured, user):
    path, doc = measured
    mid = open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "SN1"})
    new_id = mid[:-2] + ("00" if not mid.endswith("00") else "01")
    with _as(pg_database, user) as conn:
        _insert_measurement(conn, _row_of(pg_database, mid), new_id, stored_by="audrey", received_at=FORGED_WHEN)
    with pg_database.admin() as conn:
        by, at = conn.execute("SELECT stored_by, received_at FROM linpar.measurements WHERE id = %s",
                              (new_id,)).fetchone()
    assert by == user and abs(at - datetime.now(timezone.utc)) < timedelta(minutes=5)


def test_a_station_adds_to_its_own_measurements_only(pg_database, measured):
    path, doc = measured
    mid = open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "SN1"})
    for user in ("station_b", "eva"):
        with _as(pg_database, user) as conn, pytest.raises(psycopg.errors.InsufficientPrivilege, match="not stored"):
            conn.execute("INSERT INTO linpar.parameters (measurement_id, name, value, std, unit) "
                         "VALUES (%s, 'forged', 1, 0, 'ohm')", (mid,))
    with _as(pg_database, "audrey") as conn, pytest.raises(psycopg.errors.InsufficientPrivilege):
        conn.execute("INSERT INTO linpar.parameters (measurement_id, name, value, std, unit) "
                     "VALUES (%s, 'forged', 1, 0, 'ohm')", (mid,))


def test_a_limits_version_is_stamped_and_checked_by_the_server(pg_database):
    with _as(pg_database, "eva") as conn:
        conn.execute("INSERT INTO linpar.limits_versions (name, document, note, created_by, created_at) "
                     "VALUES (%s, %s, '', 'audrey', %s)", ("W6", json.dumps(LIMITS), FORGED_WHEN))
        for name, document in (("W6", {"format": "linpar-limits/1"}),
                               ("W6", {"format": "linpar-limits/1", "parameters": {"fs": {"min": "x", "unit": "Hz"}}}),
                               ("W6", {"format": "linpar-limits/1", "parameters": {"fs": {"min": 9, "max": 1,
                                                                                          "unit": "Hz"}}}),
                               ("W6", ["not", "an", "object"]),
                               ("W6\x1b]0;owned\x07", LIMITS),
                               ("W6\u202eSSAP", LIMITS)):
            with pytest.raises(psycopg.errors.CheckViolation):
                conn.execute("INSERT INTO linpar.limits_versions (name, document) VALUES (%s, %s)",
                             (name, json.dumps(document)))
    with pg_database.admin() as conn:
        rows = conn.execute("SELECT created_by, created_at FROM linpar.limits_versions").fetchall()
    assert len(rows) == 1 and rows[0][0] == "eva" and rows[0][1] > FORGED_WHEN + timedelta(days=365)
    for user in ("station_a", "audrey"):
        with _as(pg_database, user) as conn, pytest.raises(psycopg.errors.InsufficientPrivilege):
            conn.execute("INSERT INTO linpar.limits_versions (name, document) VALUES ('x', %s)", (json.dumps(LIMITS),))
    assert open_archive(pg_database.url("audrey")).limits().created_by == "eva"


def test_names_with_control_or_bidirectional_characters_are_refused_by_the_server(pg_database, measured):
    path, doc = measured
    mid = open_archive(pg_database.url("station_a")).store(path, doc, {"serial": "SN1"})
    row = list(_row_of(pg_database, mid))
    for column, name in ((4, "W6\x1b[2J"), (7, "st2\u202eSSAP"), (5, "SN\u20661"), (6, "\u200fanna")):
        forged = list(row)
        forged[column] = name
        with _as(pg_database, "station_a") as conn, pytest.raises(psycopg.errors.CheckViolation):
            _insert_measurement(conn, forged, mid[:-2] + ("00" if not mid.endswith("00") else "01"))


def test_every_station_session_is_bounded_and_setup_bounds_the_server_side(pg_database):
    from analysis.archive.pg.server import connect, parse_url
    conn = connect(parse_url(pg_database.url("station_a")), "checking")
    try:
        assert conn.execute("SHOW lock_timeout").fetchone()[0] == "5s"
        assert conn.execute("SHOW statement_timeout").fetchone()[0] == "2min"
    finally:
        conn.close()
    with _as(pg_database, "audrey") as plain:         # any client, not only linpar's: the database's own settings
        assert plain.execute("SHOW idle_in_transaction_session_timeout").fetchone()[0] == "1min"
        assert plain.execute("SHOW tcp_keepalives_idle").fetchone()[0] in ("10", "10s")


def test_setup_migrates_an_existing_line_to_the_audited_schema(pg_server, measured, tmp_path):
    name = f"linpar_old_{id(tmp_path) % 100000}"
    pg_server.create_database(name)
    with pg_server.admin(name) as conn:      # a line set up by the previous linpar: schema version 2
        from analysis.archive.pg.schema import ensure_roles, grant
        ensure_roles(conn)
        conn.execute("CREATE SCHEMA linpar")
        conn.execute("CREATE TABLE linpar.schema_version (version integer NOT NULL)")
        conn.execute("INSERT INTO linpar.schema_version VALUES (2)")
        for migration in MIGRATIONS[:2]:
            conn.execute(migration)
        conn.execute("INSERT INTO linpar.limits_versions (name, document, created_by, created_at) VALUES "
                     "('old\tname', %s, 'someone', '2001-01-01')", (json.dumps({**LIMITS, "name": "old\tname"}),))
    report = setup(pg_server.url(ADMIN, name), {"station_a": "operator", "audrey": "auditor"})
    assert (report.schema_from, report.schema_to) == (2, CURRENT_VERSION) == (2, 4)
    old = open_archive(pg_server.url("audrey", name)).limits()
    assert old.created_by == "someone" and old.name == "old\\tname"        # kept as stored, shown escaped
    path, doc = measured
    mid = open_archive(pg_server.url("station_a", name)).store(path, doc, {"serial": "SN1"})
    with pg_server.admin(name) as conn:
        assert conn.execute("SELECT stored_by FROM linpar.measurements WHERE id = %s", (mid,)).fetchone()[0] \
            == "station_a"
        conn.execute("SELECT 1")
    with pg_server.admin() as conn:
        conn.execute(f'DROP DATABASE "{name}" WITH (FORCE)')


def _orphans(db) -> list[int]:
    """The server's sessions of station_a left in an open transaction (the cut upload's)."""
    with db.admin() as conn:
        return [r[0] for r in conn.execute("SELECT pid FROM pg_stat_activity WHERE usename = 'station_a' AND "
                                           "state = 'idle in transaction'").fetchall()]


def _wait_for(predicate, seconds: float, what: str):
    from tests.pace import paced
    deadline = time.monotonic() + paced(seconds)
    while not (value := predicate()):
        assert time.monotonic() < deadline, f"{what}: not within {seconds:g} s (paced)"
        time.sleep(0.1)
    return value


def test_a_link_cut_at_the_station_mid_upload_never_hangs_the_next_store(pg_database, measured, monkeypatch):
    """A cable pulled at the station in the middle of an upload: the server keeps the cut session and its open
    transaction, which holds the measurement's uncommitted row. The station's next store sends its queue oldest
    first, so it meets that row's lock, and MUST: the orphan is held for the whole test (the proxy keeps the
    server's side open and answers its keepalives, as a far router does; the cut session has no idle timeout of
    its own here; the server's timeouts that end it in production are tested above). The next store returns
    within 10 s (the station's lock_timeout, 5 s) with both measurements in the queue and says so; once the
    orphan is gone (ended here as the server's idle-in-transaction timeout ends it), the queue sends each
    measurement exactly once. Without the station's lock_timeout the next store waits until its statement
    timeout, 120 s."""
    from analysis.archive.pg import audit
    from analysis.archive.pg import upload as upload_module
    from tests.pace import paced
    from tests.tcp_proxy import TcpProxy
    monkeypatch.setattr(audit, "STATION_OPTIONS", audit.STATION_OPTIONS.replace(
        "idle_in_transaction_session_timeout=60s", "idle_in_transaction_session_timeout=0"))
    assert "lock_timeout=5s" in audit.STATION_OPTIONS       # the station's own bound, as shipped
    path, doc = measured
    proxy = TcpProxy(pg_database.server.port)
    real, cut = upload_module.send_file, []

    def cut_after_the_first_file(conn, mid, role, name, file_path):
        real(conn, mid, role, name, file_path)
        if not cut:             # the row and one file are on the server, in the open transaction
            cut.append(mid)
            proxy.cut_station_side()
    try:
        url = pg_database.url("station_a").replace(f":{pg_database.server.port}/", f":{proxy.port}/")
        monkeypatch.setattr(upload_module, "send_file", cut_after_the_first_file)
        station = open_archive(url + "?connect_timeout=2")
        # Dated a minute back: the queue sends oldest first, and the next store comes within the same second.
        first = station.store(path, doc, {"serial": "cut"}, now=datetime.now(timezone.utc) - timedelta(minutes=1))
        assert cut == [first] and station.pending == 1
        monkeypatch.setattr(upload_module, "send_file", real)
        orphan = _wait_for(lambda: _orphans(pg_database), 10.0, "the cut session idle in its transaction")
        assert len(orphan) == 1
        proxy.restore()

        started = time.monotonic()
        station = open_archive(url + "?connect_timeout=2")
        second = station.store(path, doc, {"serial": "next"})
        took = time.monotonic() - started
        assert took < paced(10.0), took
        assert station.pending == 2, station.notes
        note = " ".join(station.notes)
        assert "lock timeout" in note and f"{second} waits in the local queue" in note and "1 other" in note, note
        assert _orphans(pg_database) == orphan          # the lock was held all along: the store met it

        with pg_database.admin() as conn:
            conn.execute("SELECT pg_terminate_backend(%s)", (orphan[0],))
        _wait_for(lambda: not _orphans(pg_database), 30.0, "the orphan ended")
        report = open_archive(url).sync()
        assert sorted(report.sent) == sorted([first, second]) and report.waiting == 0, report
        with pg_database.admin() as conn:
            rows = conn.execute("SELECT id, serial FROM linpar.measurements ORDER BY serial").fetchall()
            files = conn.execute("SELECT measurement_id, count(*) FROM linpar.files GROUP BY 1").fetchall()
            params = conn.execute("SELECT measurement_id, count(*), count(DISTINCT name) FROM linpar.parameters "
                                  "GROUP BY 1").fetchall()
        assert rows == [(first, "cut"), (second, "next")]          # each once
        assert {mid: n for mid, n in files} == {first: len(doc_files(pg_database, first)),
                                                 second: len(doc_files(pg_database, second))}
        assert all(n == distinct > 0 for _, n, distinct in params) and len(params) == 2
        assert open_archive(url).pending == 0
    finally:
        proxy.close()


def doc_files(db, mid) -> dict:
    """The files the stored record names."""
    with db.admin() as conn:
        return conn.execute("SELECT record->'files' FROM linpar.measurements WHERE id = %s", (mid,)).fetchone()[0]
