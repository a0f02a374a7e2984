"""`linpar qa stats` over 100,000 stored measurements, on the folder archive (SQLite index) and on PostgreSQL.

The population: one small measurement stored through the archive's store()
(its record is the template), then 100,000 units of it with their own
parameters (3 stations, station QA3 reading 0.3 sigma high, fs drifting 1
sigma up from unit 60,000), written in bulk: for the folder archive, a
folder with its measurement.json per unit plus the index rows in one
transaction (as a rebuild writes them); for PostgreSQL, COPY into the tables
(the files, which `qa stats` never reads, are left out). What is timed is the
command, as a user runs it: a whole `linpar qa stats` process (Python's
start-up and imports included; as this machine runs it, and with linpar's
modules compiled as an installed copy has them) and, for comparison, the
statistics in process.
PostgreSQL is a throw-away server (tests/pg_server.py, as the tests start it);
without PostgreSQL installed its rows say so.
"""
from __future__ import annotations

import copy
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from bench.common import Row, at_most, compiled_env, median_time

N_UNITS = 100_000
STATIONS = ("QA1", "QA2", "QA3")
LIMITS = {"format": "linpar-limits/1", "name": "bench",
          "parameters": {"fs": {"nominal": 70.5, "tolerance": 5.0, "unit": "Hz"},
                         "RE": {"nominal": 3.0, "tolerance": "5%", "unit": "ohm"}}}


def _template(workdir: Path) -> tuple[dict, Path, dict]:
    """(a stored record, its recording, its results document): one real store of the small measurement."""
    from analysis.archive import Archive
    from analysis.archive.results import results_document
    from analysis.pipeline import analyze_recording
    from analysis.recording.format import write_recording
    from bench.archive_bench import small_recording
    rec = small_recording()
    path = workdir / "production-unit"
    write_recording(path, rec)
    doc = results_document(analyze_recording(rec), rec)
    archive = Archive(workdir / "template-archive")
    archive.store_limits(LIMITS)
    mid = archive.store(path, doc, {"driver": "W6", "station": "QA1"})
    return archive.get(mid).record, path, doc


def _units(template: dict):
    """Records of N_UNITS units, oldest first (their key parameters drawn; a drift and a station offset).

    Each record is the template with its own identity, parameters and verdict; the rest (files, effects ...)
    is shared, not copied: the records are only ever serialised."""
    rng = np.random.default_rng(19)
    base = {k: p["value"] for k, p in template["key_parameters"].items() if p["value"] is not None}
    values = np.array(list(base.values())) * (1 + rng.standard_normal((N_UNITS, len(base))) * 0.01)
    noise = rng.standard_normal(N_UNITS)
    fs_column = list(base).index("fs")
    for i in range(N_UNITS):
        mid = f"2024{1 + i // 20000:02d}{1 + i // 1000 % 20:02d}-{i // 3600 % 24:02d}{i // 60 % 60:02d}{i % 60:02d}-" \
              f"{i:06x}"
        station = STATIONS[i % 3]
        fs = 70.5 + 0.8 * noise[i] + (0.8 if i >= 60_000 else 0.0) + (0.24 if station == "QA3" else 0.0)
        values[i, fs_column] = fs
        drawn = dict(zip(base, values[i].tolist()))
        record = {**template, "id": mid, "folder": f"{mid}-w6-{i}", "serial": f"SN{i:06d}", "station": station,
                  "measured_at": f"{mid[:4]}-{mid[4:6]}-{mid[6:8]}T{mid[9:11]}:{mid[11:13]}:{mid[13:15]}Z",
                  "key_parameters": {k: {**p, "value": drawn.get(k, p["value"])}
                                     for k, p in template["key_parameters"].items()},
                  "qa": {"verdict": "pass" if 65.5 <= fs <= 75.5 else "fail", "limits_version": 1,
                         "limits_name": "bench"}}
        yield record


def fill_folder(root: Path, template: dict) -> None:
    """The folders (what `qa stats` checks the index against) and the index rows, all in one transaction:
    the rows as analysis.archive.index.insert writes them, without its per-record savepoint and checks
    (the records are made here, not read), so that 100,000 units take a minute, not ten."""
    import sqlite3

    from analysis.archive import Archive
    from analysis.archive.archive import FOLDERS
    from analysis.archive.index import INDEX_FILE, _real
    from analysis.archive.schema import KEY_PARAMETERS, migrate, std_column, value_column
    Archive(root).store_limits(LIMITS)
    folders = root / FOLDERS
    folders.mkdir(parents=True)
    conn = sqlite3.connect(root / INDEX_FILE)
    migrate(conn)
    measurements, parameters = [], []
    for r in _units(template):
        folder = folders / r["folder"]
        folder.mkdir()
        (folder / "measurement.json").write_text(json.dumps(r))
        kept = [r["key_parameters"].get(n, {}) for n in KEY_PARAMETERS]
        measurements.append((r["id"], r["folder"], r["measured_at"], r["stored_at"], r["driver"], r["serial"],
                             r["operator"], r["station"], r["validity"], ",".join(r["effects"]),
                             r["qa"]["verdict"], r["qa"]["limits_version"],
                             *(_real(x) for p in kept for x in (p.get("value"), p.get("std")))))
        parameters += [(r["id"], n, _real(p["value"]), _real(p["std"]), p["unit"])
                       for n, p in r["key_parameters"].items() if n in KEY_PARAMETERS]
    columns = ["id", "folder", "measured_at", "stored_at", "driver", "serial", "operator", "station", "validity",
               "effects", "verdict", "limits_version",
               *(c(n) for n in KEY_PARAMETERS for c in (value_column, std_column))]
    with conn:
        conn.executemany(f"INSERT INTO measurements ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))})",
                         measurements)
        conn.executemany("INSERT INTO parameters VALUES (?, ?, ?, ?, ?)", parameters)
    conn.close()


def fill_postgres(url_admin: str, template: dict) -> None:
    import psycopg
    from psycopg.types.json import Jsonb

    from analysis.archive.pg.upload import record_sha256
    from analysis.archive.schema import KEY_PARAMETERS, std_column, value_column
    numbers = [c(n) for n in KEY_PARAMETERS for c in (value_column, std_column)]
    with psycopg.connect(url_admin, autocommit=True) as conn:
        conn.execute("INSERT INTO linpar.limits_versions (name, document) VALUES ('bench', %s)", (Jsonb(LIMITS),))
        with conn.cursor() as cur:
            with conn.transaction():
                with cur.copy("COPY linpar.measurements (id, folder, measured_at, stored_at, driver, serial, "
                              "operator, station, validity, effects, verdict, limits_version, record, record_sha256, "
                              f"stored_by, {', '.join(numbers)}) FROM STDIN") as copy_m:
                    for r in _units(template):
                        kept = [r["key_parameters"].get(n, {}) for n in KEY_PARAMETERS]
                        copy_m.write_row((r["id"], r["folder"], r["measured_at"], r["stored_at"], r["driver"],
                                          r["serial"], r["operator"], r["station"], r["validity"],
                                          ",".join(r["effects"]), r["qa"]["verdict"], 1, json.dumps(r),
                                          record_sha256(r), "bench",
                                          *(x for p in kept for x in (p.get("value"), p.get("std")))))
                with cur.copy("COPY linpar.parameters (measurement_id, name, value, std, unit) FROM STDIN") as copy_p:
                    for r in _units(template):        # the same units again: 1.2 million rows are not kept
                        for n, p in r["key_parameters"].items():
                            copy_p.write_row((r["id"], n, p["value"], p["std"], p["unit"]))
        conn.execute("ANALYZE linpar.measurements")
        conn.execute("ANALYZE linpar.parameters")


def _command_time(archive: str, env: dict) -> tuple[float, str]:
    cmd = [sys.executable, "-m", "app.cli", "qa", "stats", "--archive", archive]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    return median_time(lambda: subprocess.run(cmd, check=True, capture_output=True, env=env), repeats=5), out


def _in_process(archive: str) -> float:
    from analysis.archive import open_archive
    from analysis.production import production_stats

    def once():
        a = open_archive(archive)
        return production_stats(a.population(with_stds=False), a.limits())
    return median_time(once, repeats=5)


def run(workdir: Path) -> list[Row]:
    template, _path, _doc = _template(workdir)
    env = {**os.environ, "LINPAR_QUEUE": str(workdir / "queues")}
    env.pop("LINPAR_ARCHIVE_URL", None)
    rows = []

    root = workdir / "production-archive"
    t0 = time.perf_counter()
    fill_folder(root, template)
    rows.append(Row(f"fill a folder archive with {N_UNITS:,} units (bulk, not timed below)",
                    time.perf_counter() - t0, "s", "", None))
    t_cmd, out = _command_time(str(root), env)
    assert f"{N_UNITS} measurement(s)" in out, out[:300]
    rows.append(at_most(f"'linpar qa stats', {N_UNITS:,} units, folder archive (whole process)", t_cmd, "s", 2.0))
    rows.append(Row("  the same with linpar's bytecode compiled (as installed)",
                    _command_time(str(root), compiled_env(env, workdir))[0], "s", "", None))
    rows.append(Row("  the same in process (population + statistics)", _in_process(str(root)), "s", "", None))

    from tests.pg_server import ADMIN, PostgresServer, missing_reason
    reason = missing_reason()
    if reason:
        rows.append(Row(f"'linpar qa stats' on PostgreSQL: not run: {reason[:60]}", float("nan"), "s", "<= 1", None))
        return rows
    server = PostgresServer.start()
    try:
        from analysis.archive.pg import setup
        server.create_database("bench")
        setup(server.url(ADMIN, "bench"), {"eva": "engineer"})
        t0 = time.perf_counter()
        fill_postgres(server.url(ADMIN, "bench"), template)
        rows.append(Row(f"fill PostgreSQL with {N_UNITS:,} units (COPY, not timed below)", time.perf_counter() - t0,
                        "s", "", None))
        url = server.url("eva", "bench")
        t_cmd, out = _command_time(url, env)
        assert f"{N_UNITS} measurement(s)" in out, out[:300]
        rows.append(at_most(f"'linpar qa stats', {N_UNITS:,} units, PostgreSQL (whole process)", t_cmd, "s", 1.0))
        rows.append(Row("  the same with linpar's bytecode compiled (as installed)",
                        _command_time(url, compiled_env(env, workdir))[0], "s", "", None))
        rows.append(Row("  the same in process (population + statistics)", _in_process(url), "s", "", None))
    finally:
        server.stop()
    return rows


if __name__ == "__main__":   # pragma: no cover
    import tempfile
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    with tempfile.TemporaryDirectory() as tmp:
        for r in run(Path(tmp)):
            print(f"{r.name:<80}{r.value:>9.3f} {r.unit} {r.target} {'' if r.ok is None else ('ok' if r.ok else 'NO')}")
