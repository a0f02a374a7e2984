"""Three stations, one PostgreSQL archive: 300 measurements stored at once, none lost, none twice; one station
cut off from the server for 30 of its units catches up afterwards, each of them exactly once.

The one slow test of the production archive (~30 s on a busy 2-core machine): three separate processes are
what makes the stores concurrent the way a line's stations are (their own connections, their own queues, no
shared interpreter), and 300 is the count the issue asks for. The stations are simulators
(tests/production_station.py): each unit is stored through the archive's store(), as `linpar measure`
stores one, without playing a multitone in real time.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from analysis.archive.backends import open_archive
from analysis.archive.pg import ServerRefused
from tests.production_helpers import LIMITS, small_measurement
from tests.tcp_proxy import TcpProxy

REPO = Path(__file__).resolve().parents[2]
UNITS = 100


def start_station(name: str, url: str, recording: Path, results: Path, queues: Path, *extra: str):
    env = {**os.environ, "LINPAR_QUEUE": str(queues / name), "PYTHONPATH": str(REPO)}
    return subprocess.Popen([sys.executable, "-m", "tests.production_station", "--archive", url, "--station", name,
                             "--count", str(UNITS), "--recording", str(recording), "--results", str(results),
                             "--seed", str(sum(map(ord, name))), *extra],
                            cwd=REPO, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def read_lines(station, until: str, seen: list[str]) -> None:
    """Read the station's lines into `seen` up to one starting with `until`."""
    for line in station.stdout:
        seen.append(line.strip())
        if line.startswith(until):
            return
    raise AssertionError(f"the station ended before '{until}': {station.stderr.read()[-2000:]}")


@pytest.mark.slow
def test_three_stations_store_300_units_and_a_cut_off_one_catches_up_exactly_once(pg_database, tmp_path):
    recording, doc = small_measurement(tmp_path)
    results = tmp_path / "results.json"
    results.write_text(json.dumps(doc))
    open_archive(pg_database.url("eva")).store_limits(LIMITS)
    proxy = TcpProxy(pg_database.server.port)
    cut_url = pg_database.url("station_c").replace(f":{pg_database.server.port}/", f":{proxy.port}/")
    try:
        stations = {
            "QA-A": start_station("QA-A", pg_database.url("station_a"), recording, results, tmp_path),
            "QA-B": start_station("QA-B", pg_database.url("station_b"), recording, results, tmp_path),
            "QA-C": start_station("QA-C", cut_url + "?connect_timeout=3", recording, results, tmp_path,
                                  "--pause-at", "30,60"),
        }
        c, c_lines = stations["QA-C"], []
        read_lines(c, "paused 30", c_lines)
        proxy.cut()                                   # units 31 ... 60 of QA-C: the network is down
        c.stdin.write("\n")
        c.stdin.flush()
        read_lines(c, "paused 60", c_lines)
        proxy.restore()                               # unit 61 on: back, and the queue goes first
        c.stdin.write("\n")
        c.stdin.flush()
        read_lines(c, "done", c_lines)
        printed = {"QA-C": json.loads(c_lines[-1][len("done "):])}
        for name in ("QA-A", "QA-B"):
            out, err = stations[name].communicate(timeout=600)
            assert stations[name].returncode == 0, err[-2000:]
            printed[name] = json.loads(out.strip().splitlines()[-1][len("done "):])
        assert c.wait(timeout=60) == 0, c.stderr.read()[-2000:]
    finally:
        proxy.close()
        for station in locals().get("stations", {}).values():
            if station.poll() is None:
                station.kill()

    pending = {int(line.split()[1]): int(line.split()[3]) for line in c_lines if line.startswith("unit ")}
    assert [pending[i] for i in range(31, 61)] == list(range(1, 31))     # each unit of the cut queued, in turn
    assert pending[61] == 0 and max(pending[i] for i in range(61, UNITS + 1)) == 0    # sent with unit 61
    with pg_database.admin() as conn:
        rows = conn.execute("SELECT id, station, serial, record_sha256 FROM linpar.measurements").fetchall()
        files = conn.execute("SELECT count(*), count(DISTINCT measurement_id) FROM linpar.files").fetchone()
        judged = conn.execute("SELECT count(*) FROM linpar.measurements WHERE limits_version = 1").fetchone()[0]
    ids = [r[0] for r in rows]
    assert len(rows) == 300 and len(set(ids)) == 300                                     # all there, no id twice
    assert len({(r[1], r[2]) for r in rows}) == 300                                      # no unit twice
    for name, printed_ids in printed.items():
        assert sorted(printed_ids) == sorted(r[0] for r in rows if r[1] == name)       # none lost
        assert sorted(r[2] for r in rows if r[1] == name) == [f"{name}-{i:03d}" for i in range(1, UNITS + 1)]
    assert files == (300 * 5, 300) and judged == 300    # every unit with its files, judged by the limits it saw
    assert open_archive(cut_url).pending == 0
    with pytest.raises(ServerRefused, match="permission denied for table limits_versions"):
        open_archive(pg_database.url("station_c")).store_limits(LIMITS)
    summary = {"stored": len(rows), "distinct ids": len(set(ids)), "queued during the cut": 30,
               "sent when back": 30}
    print(f"\nthree stations: {summary}")
