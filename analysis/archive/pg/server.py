"""The server a postgresql:// URL names: checked where it enters, connected to with bounded waits, and every
error of the server or the network turned into one line that says what to do.

Two kinds of failure are told apart, because a station treats them apart:

- ServerUnreachable: the network or the server is down (refused, timed out,
  the connection dropped). A station keeps measuring and queues locally
  (analysis.archive.pg.outbox); the next store or `linpar archive sync` sends.
- ServerRefused: the server answered no (a role without the right, a failed
  login, no such database, a schema it must migrate first). Waiting does not
  help: the message says who must do what.

Connections are opened per operation and closed after it; libpq's keepalives
notice a server that vanishes in the middle of one within ~15 s, and
connect_timeout (default 5 s, or the URL's) bounds the wait for one that is off.
"""
from __future__ import annotations

import contextlib
import hashlib
import re
from dataclasses import dataclass
from typing import Iterator

from analysis.archive.names import ArchiveError
from analysis.archive.names import shown as masked
from analysis.errors import one_line

CONNECT_TIMEOUT_S = 5
SCHEMA = "linpar"
# What libpq says when the name or the network failed (checked first: a host may be named "x.invalid")...
_NO_ANSWER = ("failed to resolve host", "could not translate host name", "Connection refused", "timeout expired",
              "No route to host", "Network is unreachable", "server closed the connection", "Connection reset")
# ... and when the server answered and said no, as opposed to not answering at all.
_REFUSALS = ("authentication failed", "does not exist", "pg_hba.conf", "permission denied", "password",
             "invalid", "too many connections", "not permitted", "SSL")
# What to do about a refusal the user can mend, by what libpq says.
_REMEDIES = (
    (("password authentication failed", "no password supplied"),
     "check the user and the password: in the URL (postgresql://USER:PASSWORD@HOST/DB), $PGPASSWORD or ~/.pgpass"),
    (("does not exist",), "check the URL's user and database: the line's administrator creates them with "
                          "'linpar archive setup'"),
    (("pg_hba.conf",), "the server's administrator allows this station in the server's pg_hba.conf"),
)


class ServerUnreachable(ArchiveError):
    """The server cannot be reached now (network, server down): measurements wait in the local queue."""


class ServerRefused(ArchiveError):
    """The server answered, and refused: a right, a login, a database, a schema version."""

    queued_id: str | None = None      # a measurement that waits in the local queue because of it


@dataclass(frozen=True)
class ServerURL:
    """A postgresql:// URL, checked: the keywords libpq takes, and the place to show in messages."""

    url: str
    params: dict
    user: str
    host: str
    port: int
    dbname: str

    @property
    def display(self) -> str:
        """The URL without a password, for messages and labels."""
        return f"postgresql://{self.user}@{self.host}:{self.port}/{self.dbname}"

    @property
    def slug(self) -> str:
        """A folder name for this server and user (its local queue, its cache)."""
        raw = f"{self.user}@{self.host}:{self.port}/{self.dbname}"
        tail = hashlib.sha256(raw.encode()).hexdigest()[:8]
        return re.sub(r"[^A-Za-z0-9@._-]+", "-", f"{self.user}@{self.host}-{self.port}-{self.dbname}")[:80] + "-" + tail


def parse_url(url: str) -> ServerURL:
    """The checked URL; ArchiveError (one line, the password never shown) when it cannot be one."""
    from psycopg import conninfo
    text = str(url).strip()
    shown = masked(text)[:120]
    if not re.match(r"^postgres(ql)?://", text, re.IGNORECASE):
        raise ArchiveError(f"{shown}: expected postgresql://USER@HOST[:PORT]/DATABASE")
    try:
        params = conninfo.conninfo_to_dict(text)
    except Exception as exc:  # noqa: BLE001 - psycopg's parser raises ProgrammingError and others: all one line
        raise ArchiveError(f"{shown}: not a PostgreSQL URL ({one_line(exc)}): expected "
                           "postgresql://USER@HOST[:PORT]/DATABASE") from None
    import getpass
    user = str(params.get("user") or getpass.getuser())
    host = str(params.get("host") or "localhost")
    port_text = str(params.get("port") or "5432")
    if not port_text.isdigit() or not 1 <= int(port_text) <= 65535:
        raise ArchiveError(f"{shown}: port {port_text!r}: expected a whole number from 1 to 65535")
    dbname = str(params.get("dbname") or user)
    if "connect_timeout" not in params:
        params["connect_timeout"] = str(CONNECT_TIMEOUT_S)
    else:
        timeout = str(params["connect_timeout"])
        if not timeout.isdigit() or not 1 <= int(timeout) <= 600:
            raise ArchiveError(f"{shown}: connect_timeout {timeout!r}: expected seconds from 1 to 600")
    params.setdefault("application_name", "linpar")
    from analysis.archive.pg.audit import STATION_OPTIONS
    params["options"] = f"{params.get('options', '')} {STATION_OPTIONS}".strip()
    for key, value in (("keepalives", "1"), ("keepalives_idle", "5"), ("keepalives_interval", "3"),
                       ("keepalives_count", "3")):
        params.setdefault(key, value)
    return ServerURL(text, params, user, host, int(port_text), dbname)


def _unreachable(exc) -> bool:
    """True when the server did not answer (the network, a server down or restarting), not a refusal."""
    state = getattr(exc, "sqlstate", None)
    if state is not None:
        # 55P03 lock_not_available, 57014 query_canceled (the station's lock and statement timeouts): the
        # server is busy with a row a cut connection left, not refusing; the store waits in the queue.
        return state.startswith("08") or state in ("57P01", "57P02", "57P03", "55P03", "57014")
    message = str(exc)
    if any(words in message for words in _NO_ANSWER):
        return True
    reason = message.rsplit("failed: ", 1)[-1]       # what follows "connection to server at HOST, port N failed: "
    return not any(word in reason for word in _REFUSALS)


def _remedy(message: str) -> str:
    return next(("; " + what for words, what in _REMEDIES if any(w in message for w in words)), "")


@contextlib.contextmanager
def server_errors(server: ServerURL, doing: str, needs: str = "") -> Iterator[None]:
    """Errors of the server as one-line ArchiveErrors: ServerUnreachable, ServerRefused, or ArchiveError.

    `needs`: the role the action takes ("an engineer"), said when the server refuses it for want of a right.
    """
    import psycopg
    from psycopg import errors
    try:
        yield
    except errors.InsufficientPrivilege as exc:
        who = f"the database user {server.user!r}"
        hint = f" ({needs} may; the line's administrator grants it with 'linpar archive setup')" if needs else ""
        raise ServerRefused(f"{server.display}: the server refused {doing}: {_first_line(exc)}: {who} may not"
                            f"{hint}") from None
    except (psycopg.OperationalError, psycopg.InterfaceError) as exc:
        if _unreachable(exc):
            raise ServerUnreachable(f"{server.display}: cannot reach the server while {doing} "
                                    f"({_first_line(exc)})") from None
        reason = _first_line(exc)
        raise ServerRefused(f"{server.display}: the server refused {doing}: {reason}{_remedy(reason)}") from None
    except psycopg.Error as exc:
        raise ArchiveError(f"{server.display}: {doing}: {_first_line(exc)}") from None


def _first_line(exc) -> str:
    text = str(exc).strip()
    text = re.sub(r"^connection failed: ", "", text)
    return one_line(text.splitlines()[0] if text else type(exc).__name__)[:300]


def connect(server: ServerURL, doing: str):
    """An autocommit connection with search_path linpar, its schema version checked (analysis.archive.pg.schema).

    Transactions are explicit (`with conn.transaction():`), so that a failed statement never leaves a
    session half in one.
    """
    import psycopg
    with server_errors(server, doing):
        conn = psycopg.connect(**server.params, autocommit=True)
    try:
        with server_errors(server, doing):
            conn.execute(f"SET search_path TO {SCHEMA}, pg_catalog")
            _check_version(conn, server)
    except BaseException:
        conn.close()
        raise
    return conn


def _check_version(conn, server: ServerURL) -> None:
    """ServerRefused unless the server's schema is the version this program speaks."""
    from analysis.archive.pg.schema import CURRENT_VERSION, version_of
    version = version_of(conn)
    if version == CURRENT_VERSION:
        return
    if version == 0:
        raise ServerRefused(f"{server.display}: this database holds no linpar archive: its owner creates it with "
                            f"'linpar archive setup --archive postgresql://OWNER@{server.host}:{server.port}/"
                            f"{server.dbname}'")
    if version < CURRENT_VERSION:
        raise ServerRefused(f"{server.display}: the archive's schema is version {version}, this program needs "
                            f"{CURRENT_VERSION}: the database's owner migrates it with 'linpar archive setup'")
    raise ServerRefused(f"{server.display}: the archive's schema is version {version}, newer than this program's "
                        f"{CURRENT_VERSION}: update linpar on this station")
