"""A throw-away PostgreSQL server for the tests: initdb in a temporary folder, a free port, stopped at the end.

The Debian package `postgresql` (tools/system-packages.sh installs it for
`make test`) puts initdb and pg_ctl in /usr/lib/postgresql/<version>/bin.
PostgreSQL refuses to run as root, so as root (CI) the server runs as the
`postgres` system user the package creates (runuser), in a folder given to
it. Durability is switched off (fsync, synchronous_commit): the server and
its data are thrown away with the session.

    server = PostgresServer.start()
    server.url("station_a", "linpar_t1")       postgresql://station_a@127.0.0.1:PORT/linpar_t1
    server.stop()
"""
from __future__ import annotations

import os
import pwd
import shutil
import socket
import subprocess
import tempfile
import time
from pathlib import Path

ADMIN = "linpar_admin"
INSTALL_HINT = ("PostgreSQL is not installed: install the Debian package postgresql (apt-get install postgresql; "
                "'make test' does it when run as root) to run the PostgreSQL archive tests")


def binaries() -> Path | None:
    """The folder with initdb, pg_ctl and postgres, or None."""
    found = shutil.which("initdb")
    if found and shutil.which("pg_ctl"):
        return Path(found).resolve().parent
    versions = sorted(Path("/usr/lib/postgresql").glob("*/bin/initdb"),
                      key=lambda p: int(p.parent.parent.name) if p.parent.parent.name.isdigit() else 0)
    return versions[-1].parent if versions else None


def missing_reason() -> str | None:
    """Why the PostgreSQL tests cannot run here (to skip them with it), or None."""
    if binaries() is None:
        return INSTALL_HINT
    if os.geteuid() == 0:
        try:
            pwd.getpwnam("postgres")
        except KeyError:
            return ("PostgreSQL refuses to run as root and there is no 'postgres' system user to run it as: "
                    "install the Debian package postgresql, which creates it")
    return None


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class PostgresServer:
    def __init__(self, folder: Path, port: int, bin_dir: Path):
        self.folder = folder
        self.data = folder / "data"
        self.port = port
        self.bin = bin_dir

    # --- running commands as the server's user -------------------------------------------

    def _as_owner(self, argv: list[str]) -> list[str]:
        if os.geteuid() != 0:
            return argv
        return ["runuser", "-u", "postgres", "--", *argv]

    def _run(self, argv: list[str], timeout: float = 120) -> subprocess.CompletedProcess:
        done = subprocess.run(self._as_owner(argv), capture_output=True, text=True, timeout=timeout)
        if done.returncode != 0:
            raise RuntimeError(f"{' '.join(argv[:2])} failed ({done.returncode}): {done.stderr.strip()[-2000:]}"
                               f"{self._log_tail()}")
        return done

    def _log_tail(self) -> str:
        log = self.folder / "server.log"
        try:
            return "\nserver log:\n" + log.read_text()[-2000:]
        except OSError:
            return ""

    # --- life -----------------------------------------------------------------------------------

    @classmethod
    def start(cls) -> "PostgresServer":
        bin_dir = binaries()
        if bin_dir is None:
            raise RuntimeError(INSTALL_HINT)
        folder = Path(tempfile.mkdtemp(prefix="linpar-pg-"))
        if os.geteuid() == 0:
            owner = pwd.getpwnam("postgres")
            os.chown(folder, owner.pw_uid, owner.pw_gid)
        os.chmod(folder, 0o700)
        last = None
        for _attempt in range(3):       # the free port may be taken between asking and binding
            server = cls(folder, _free_port(), bin_dir)
            try:
                server._init_and_start()
                return server
            except RuntimeError as exc:
                last = exc
                if "could not bind" not in str(exc) and "already in use" not in str(exc):
                    break
        shutil.rmtree(folder, ignore_errors=True)
        raise RuntimeError(f"the test PostgreSQL server did not start: {last}")

    def _init_and_start(self) -> None:
        if not (self.data / "PG_VERSION").exists():
            self._run([str(self.bin / "initdb"), "-D", str(self.data), "-U", ADMIN, "-A", "trust", "-E", "UTF8",
                       "--locale=C", "--no-sync"])
        options = (f"-p {self.port} -k {self.folder} -c listen_addresses=127.0.0.1 -c fsync=off "
                   f"-c synchronous_commit=off -c full_page_writes=off -c max_connections=60 "
                   f"-c shared_buffers=64MB")
        self._run([str(self.bin / "pg_ctl"), "-D", str(self.data), "-o", options, "-l",
                   str(self.folder / "server.log"), "-w", "-t", "60", "start"])

    def stop(self) -> None:
        try:
            self._run([str(self.bin / "pg_ctl"), "-D", str(self.data), "-m", "immediate", "-w", "stop"], timeout=60)
        except (RuntimeError, subprocess.TimeoutExpired):
            pass
        shutil.rmtree(self.folder, ignore_errors=True)

    # --- using it -----------------------------------------------------------------------------

    def url(self, user: str = ADMIN, dbname: str = "postgres") -> str:
        return f"postgresql://{user}@127.0.0.1:{self.port}/{dbname}"

    def admin(self, dbname: str = "postgres"):
        import psycopg
        return psycopg.connect(self.url(ADMIN, dbname), autocommit=True)

    def create_database(self, name: str) -> None:
        from psycopg import sql
        with self.admin() as conn:
            conn.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(name)))

    def require_password(self, user: str, password: str) -> None:
        """From now on `user` logs in over TCP with `password` only (scram-sha-256); everyone else as before."""
        from psycopg import sql
        with self.admin() as conn:
            conn.execute(sql.SQL("ALTER ROLE {} PASSWORD {}").format(sql.Identifier(user), sql.Literal(password)))
            hba = self.data / "pg_hba.conf"        # rewritten in place: it keeps the server's user as its owner
            rules = hba.read_text()
            hba.write_text(f"host all {user} 127.0.0.1/32 scram-sha-256\n" + rules)
            conn.execute("SELECT pg_reload_conf()")

    def wait_ready(self, timeout_s: float = 30) -> None:
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                with self.admin():
                    return
            except Exception:  # noqa: BLE001 - retried until the deadline
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.2)
