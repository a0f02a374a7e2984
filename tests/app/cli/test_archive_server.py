"""The command line against the PostgreSQL archive: which archive a command uses ($LINPAR_ARCHIVE_URL over
$LINPAR_ARCHIVE, an option over both), `archive setup` and `archive sync`, the server's refusals as one
line, and `linpar measure --archive URL` with a server that comes and goes (on the simulated sound card)."""
import json

import pytest

from analysis.archive import Archive
from app.cli import main
from tests.production_helpers import LIMITS, small_measurement
from tests.tcp_proxy import TcpProxy


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return small_measurement(tmp_path_factory.mktemp("unit"))[0]


def server_serials(db) -> list[str]:
    with db.admin() as conn:
        return sorted(r[0] for r in conn.execute("SELECT serial FROM linpar.measurements").fetchall())


def test_the_url_in_the_environment_wins_over_the_folder_and_an_option_over_both(capsys, pg_database, recording,
                                                                                  tmp_path, monkeypatch):
    folder = tmp_path / "folder-archive"
    monkeypatch.setenv("LINPAR_ARCHIVE", str(folder))
    monkeypatch.setenv("LINPAR_ARCHIVE_URL", pg_database.url("station_a"))
    code, out, err = run(capsys, "archive", "store", recording, "--serial", "to-server", "--json")
    assert code == 0, err
    assert server_serials(pg_database) == ["to-server"] and not folder.exists()
    code, out, err = run(capsys, "archive", "list")
    assert "to-server" in out and f"1 measurement(s) in postgresql://station_a@127.0.0.1:" in out
    code, out, err = run(capsys, "archive", "store", recording, "--serial", "to-folder", "--root", folder)
    assert code == 0 and [e.serial for e in Archive(folder).list()] == ["to-folder"]
    assert server_serials(pg_database) == ["to-server"]
    mid = json.loads(run(capsys, "archive", "list", "--json")[1])[0]["id"]
    code, out, err = run(capsys, "report", mid, "--html", tmp_path / "r.html")       # report reads the server too
    assert code == 0, err
    assert "to-server" in (tmp_path / "r.html").read_text()


def test_setup_users_and_a_role_s_refusal_as_one_line(capsys, pg_database, tmp_path):
    code, out, err = run(capsys, "archive", "setup", "--archive", pg_database.url("linpar_admin"),
                         "--user", "line_b=operator", "--json")
    assert code == 0, err
    assert json.loads(out)["users"]["line_b"].startswith("created")
    limits = tmp_path / "limits.json"
    limits.write_text(json.dumps(LIMITS))
    code, out, err = run(capsys, "qa", "limits", "--store", limits, "--archive", pg_database.url("line_b"))
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "the server refused storing a limits version: permission denied for table limits_versions" in err
    assert "'line_b' may not (an engineer may" in err
    code, out, err = run(capsys, "qa", "limits", "--store", limits, "--archive", pg_database.url("eva"))
    assert code == 0 and "as limits version 1" in out
    code, out, err = run(capsys, "archive", "setup", "--archive", pg_database.url("linpar_admin"),
                         "--user", "x=admin")
    assert code == 2 and "unknown role: expected one of auditor, operator, engineer" in err


def test_measure_queues_while_the_server_is_away_and_sync_sends_once(capsys, pg_database, tmp_path, monkeypatch):
    import app.cli.devices as cli_devices
    from instruments.audio.simulated import SimulatedAudio
    monkeypatch.setattr(cli_devices, "open_devices", lambda args, stack: (
        SimulatedAudio(realtime=False, seed=1), None, {"name": "paper (simulated)", "sd_m2": 0.0133}))
    proxy = TcpProxy(pg_database.server.port)
    try:
        url = pg_database.url("station_c").replace(f":{pg_database.server.port}/", f":{proxy.port}/")
        measure = ["measure", "--out", tmp_path / "out", "--period", "16384", "--periods", "4", "--json",
                   "--archive", url + "?connect_timeout=2"]
        code, out, err = run(capsys, *measure, "--name", "m1", "--serial", "S1")
        assert code == 0 and json.loads(out)["archive"].keys() == {"id", "root"}
        proxy.cut()
        code, out, err = run(capsys, *measure, "--name", "m2", "--serial", "S2")
        assert code == 0, err
        archived = json.loads(out)["archive"]
        assert archived["queued"] is True and "cannot reach the server" in err and "waits in" in err
        code, out, err = run(capsys, "archive", "sync", "--archive", url + "?connect_timeout=2")
        assert code == 2 and "1 measurement(s) wait in the local queue" in err and len(err.strip().splitlines()) == 1
        assert server_serials(pg_database) == ["S1"]
        proxy.restore()
        code, out, err = run(capsys, "archive", "sync", "--archive", url, "--json")
        assert code == 0 and json.loads(out)["sent"] == [archived["id"]]
        code, out, err = run(capsys, "archive", "sync", "--archive", url)
        assert "nothing waits" in out
        assert server_serials(pg_database) == ["S1", "S2"]
    finally:
        proxy.close()


def test_a_wrong_password_an_unknown_database_and_an_unresolvable_host_are_one_line_each(capsys, pg_database,
                                                                                          monkeypatch):
    from analysis.archive.pg import setup
    monkeypatch.delenv("PGPASSWORD", raising=False)
    setup(pg_database.url("linpar_admin"), {"paula": "auditor"})     # her own: the server is the session's
    pg_database.server.require_password("paula", "right")
    with_password = pg_database.url("paula").replace("paula@", "paula:{}@")
    assert run(capsys, "qa", "stats", "--archive", with_password.format("right"))[0] == 0
    server = pg_database.url("paula").rsplit("/", 1)[0]
    for url, says in (
            (with_password.format("wrong"), "password authentication failed for user \"paula\"; check the user "
                                            "and the password"),
            (pg_database.url("paula"), "no password supplied; check the user and the password"),
            (f"{server}/no_such_db".replace("paula@", "eva@"), 'database "no_such_db" does not exist; check the '
                                                                "URL's user and database"),
            ("postgresql://eva:pw@no-such-host.invalid/line?connect_timeout=2", "cannot reach the server"),
            ("", "--archive: empty")):
        code, out, err = run(capsys, "qa", "stats", "--archive", url)
        assert code == 2 and out == "" and err.startswith("linpar: error: ") and says in err, err
        assert len(err.strip().splitlines()) == 1 and "wrong" not in err and ":pw@" not in err
