"""The PostgreSQL archive's schema: versioned migrations, the three roles and what each may do.

MIGRATIONS[i] takes the schema `linpar` from version i to i + 1. They are
run by the database's owner (`linpar archive setup`), each in one transaction
with its version number (PostgreSQL's DDL is transactional: a failure leaves
the schema at one version or the next), under an advisory lock so that two
administrators cannot migrate at once. Add a migration at the end; never edit
one that has shipped. A station only checks the version: older than this
program -> "run setup"; newer -> "update linpar". Nothing here is a cache:
unlike the folder archive's index, the server's tables are the archive.

Roles (group roles, NOLOGIN; login users are made members of one):

    linpar_auditor    reads everything
    linpar_operator   + stores measurements (INSERT, never UPDATE or DELETE: a stored
                        measurement and its verdict stay as they were stored)
    linpar_engineer   + stores limits versions and marks golden units

The server enforces them (GRANT), whatever program connects. Files are large
objects written only through the SECURITY DEFINER functions file_create,
file_write and file_seal: the objects belong to the schema's owner, so no
login user can rewrite or unlink one; every chunk's SHA-256 is checked by the
server as it arrives, the whole file's is kept and checked by every reader.
"""
from __future__ import annotations

ROLES = {"auditor": "linpar_auditor", "operator": "linpar_operator", "engineer": "linpar_engineer"}

_V1 = r"""
CREATE SCHEMA IF NOT EXISTS linpar;
CREATE TABLE linpar.measurements (
    id text COLLATE "C" PRIMARY KEY CHECK (id ~ '^[0-9]{8}-[0-9]{6}-[0-9a-f]{6}$'),
    folder text COLLATE "C" NOT NULL UNIQUE,
    measured_at text COLLATE "C" NOT NULL,
    stored_at text COLLATE "C" NOT NULL,
    driver text NOT NULL,
    serial text NOT NULL,
    operator text NOT NULL,
    station text NOT NULL,
    validity text NOT NULL,
    effects text NOT NULL DEFAULT '',
    verdict text CHECK (verdict IN ('pass', 'fail', 'invalid', 'not judged')),
    limits_version integer,
    record jsonb NOT NULL,
    record_sha256 text NOT NULL,
    stored_by text NOT NULL DEFAULT session_user,
    received_at timestamptz NOT NULL DEFAULT now(),
    CHECK ((verdict IS NULL) = (limits_version IS NULL)));
CREATE INDEX measurements_by_date ON linpar.measurements (measured_at, id);
CREATE INDEX measurements_by_station ON linpar.measurements (station, measured_at);
CREATE INDEX measurements_by_driver ON linpar.measurements (driver, serial);
CREATE TABLE linpar.parameters (
    measurement_id text COLLATE "C" NOT NULL REFERENCES linpar.measurements (id),
    name text NOT NULL,
    value double precision,
    std double precision,
    unit text NOT NULL,
    PRIMARY KEY (measurement_id, name));
CREATE TABLE linpar.files (
    measurement_id text COLLATE "C" NOT NULL REFERENCES linpar.measurements (id),
    role text NOT NULL,
    name text NOT NULL,
    lo oid NOT NULL UNIQUE,
    size bigint NOT NULL CHECK (size >= 0),
    sha256 text NOT NULL CHECK (sha256 ~ '^[0-9a-f]{64}$'),
    PRIMARY KEY (measurement_id, role));
CREATE TABLE linpar.uploads (
    lo oid PRIMARY KEY,
    created_by text NOT NULL DEFAULT session_user);
CREATE TABLE linpar.limits_versions (
    version integer GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    name text NOT NULL,
    document jsonb NOT NULL,
    note text NOT NULL DEFAULT '',
    created_at timestamptz NOT NULL DEFAULT now(),
    created_by text NOT NULL DEFAULT session_user);
ALTER TABLE linpar.measurements ADD FOREIGN KEY (limits_version) REFERENCES linpar.limits_versions (version);
CREATE TABLE linpar.golden_units (
    measurement_id text COLLATE "C" PRIMARY KEY REFERENCES linpar.measurements (id),
    marked bigint GENERATED ALWAYS AS IDENTITY UNIQUE,   -- the order they were marked in (now() ties in a transaction)
    added_at timestamptz NOT NULL DEFAULT now(),
    added_by text NOT NULL DEFAULT session_user);

CREATE FUNCTION linpar.file_create() RETURNS oid
LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
DECLARE
    o oid;
BEGIN
    o := lo_create(0);
    INSERT INTO linpar.uploads (lo) VALUES (o);
    RETURN o;
END $$;

CREATE FUNCTION linpar.file_write(o oid, at bigint, chunk bytea, chunk_sha256 text) RETURNS void
LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
BEGIN
    IF NOT EXISTS (SELECT 1 FROM linpar.uploads WHERE lo = o AND created_by = session_user) THEN
        RAISE EXCEPTION 'large object % is not an upload of %', o, session_user
            USING ERRCODE = 'insufficient_privilege';
    END IF;
    IF encode(sha256(chunk), 'hex') <> chunk_sha256 THEN
        RAISE EXCEPTION 'a chunk of a file arrived damaged (SHA-256 differs)' USING ERRCODE = 'data_corrupted';
    END IF;
    PERFORM lo_put(o, at, chunk);
END $$;

CREATE FUNCTION linpar.file_seal(mid text, file_role text, file_name text, o oid, file_size bigint,
                                 file_sha256 text) RETURNS void
LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
DECLARE
    fd integer;
    stored_size bigint;
BEGIN
    IF NOT EXISTS (SELECT 1 FROM linpar.measurements WHERE id = mid AND stored_by = session_user) THEN
        RAISE EXCEPTION 'measurement % was not stored by %', mid, session_user
            USING ERRCODE = 'insufficient_privilege';
    END IF;
    DELETE FROM linpar.uploads WHERE lo = o AND created_by = session_user;
    IF NOT FOUND THEN
        RAISE EXCEPTION 'large object % is not an upload of %', o, session_user
            USING ERRCODE = 'insufficient_privilege';
    END IF;
    fd := lo_open(o, 262144);            -- INV_READ
    stored_size := lo_lseek64(fd, 0, 2); -- SEEK_END
    PERFORM lo_close(fd);
    IF stored_size <> file_size THEN
        RAISE EXCEPTION 'file % of % arrived with % bytes of %', file_role, mid, stored_size, file_size
            USING ERRCODE = 'data_corrupted';
    END IF;
    INSERT INTO linpar.files (measurement_id, role, name, lo, size, sha256)
        VALUES (mid, file_role, file_name, o, file_size, file_sha256);
    EXECUTE format('GRANT SELECT ON LARGE OBJECT %s TO linpar_auditor', o);
END $$;

REVOKE ALL ON FUNCTION linpar.file_create(), linpar.file_write(oid, bigint, bytea, text),
    linpar.file_seal(text, text, text, oid, bigint, text) FROM PUBLIC;
"""

def _v2() -> str:
    # The key parameters beside the measurement's row (analysis.archive.schema.value_column), written with it
    # (analysis.archive.pg.upload); the existing rows' are filled from the parameters table here.
    from analysis.archive.schema import KEY_PARAMETERS, std_column, value_column
    columns = [c for n in KEY_PARAMETERS for c in (value_column(n), std_column(n))]
    fill = ", ".join(f"{value_column(n)} = p.{value_column(n)}, {std_column(n)} = p.{std_column(n)}"
                     for n in KEY_PARAMETERS)
    pivot = ", ".join(f"max(value) FILTER (WHERE name = '{n}') AS {value_column(n)}, "
                      f"max(std) FILTER (WHERE name = '{n}') AS {std_column(n)}" for n in KEY_PARAMETERS)
    return (f"ALTER TABLE linpar.measurements {', '.join(f'ADD COLUMN {c} double precision' for c in columns)};\n"
            f"UPDATE linpar.measurements m SET {fill} FROM (SELECT measurement_id, {pivot} FROM linpar.parameters "
            f"GROUP BY measurement_id) p WHERE p.measurement_id = m.id;\n")


def _v3() -> str:
    from analysis.archive.pg.audit import V3_AUDIT
    return V3_AUDIT


def _v4() -> str:
    from analysis.archive.pg.audit import V4_BIDI
    return V4_BIDI


MIGRATIONS: tuple[str, ...] = (_V1, _v2(), _v3(), _v4())
CURRENT_VERSION = len(MIGRATIONS)
_LOCK_KEY = 0x6C696E706172      # "linpar": the advisory lock that serialises migrations

# Idempotent: run by setup after every migration (a new table gets its rights here too).
_GRANTS = r"""
GRANT linpar_auditor TO linpar_operator;
GRANT linpar_operator TO linpar_engineer;
GRANT USAGE ON SCHEMA linpar TO linpar_auditor;
GRANT SELECT ON ALL TABLES IN SCHEMA linpar TO linpar_auditor;
REVOKE SELECT ON linpar.uploads FROM linpar_auditor;
GRANT INSERT ON linpar.measurements, linpar.parameters TO linpar_operator;
GRANT EXECUTE ON FUNCTION linpar.file_create(), linpar.file_write(oid, bigint, bytea, text),
    linpar.file_seal(text, text, text, oid, bigint, text) TO linpar_operator;
GRANT INSERT ON linpar.limits_versions TO linpar_engineer;
GRANT INSERT, DELETE ON linpar.golden_units TO linpar_engineer;
"""


def version_of(conn) -> int:
    """The schema's version; 0 when the database has no linpar schema yet."""
    row = conn.execute("SELECT to_regclass('linpar.schema_version')").fetchone()
    if row[0] is None:
        return 0
    rows = conn.execute("SELECT version FROM linpar.schema_version").fetchall()
    if len(rows) != 1:
        from analysis.archive.names import ArchiveError
        raise ArchiveError("linpar.schema_version must hold exactly one row: the database is not a linpar archive")
    return int(rows[0][0])


def migrate(conn) -> tuple[int, int]:
    """Bring the schema to CURRENT_VERSION (as the database's owner); (version before, version after)."""
    from analysis.archive.names import ArchiveError
    with conn.transaction():
        conn.execute("SELECT pg_advisory_xact_lock(%s)", (_LOCK_KEY,))
        start = version_of(conn)
        if start > CURRENT_VERSION:
            raise ArchiveError(f"the archive's schema is version {start}, newer than this program's "
                               f"{CURRENT_VERSION}: update linpar")
        for version in range(start, CURRENT_VERSION):
            with conn.transaction():       # a savepoint: the migration and its number, or neither
                if version == 0:
                    conn.execute("CREATE SCHEMA IF NOT EXISTS linpar")
                    conn.execute("CREATE TABLE linpar.schema_version (version integer NOT NULL)")
                    conn.execute("INSERT INTO linpar.schema_version VALUES (0)")
                conn.execute(MIGRATIONS[version])
                conn.execute("UPDATE linpar.schema_version SET version = %s", (version + 1,))
    return start, CURRENT_VERSION


def ensure_roles(conn) -> list[str]:
    """Create the three group roles where missing (needs CREATEROLE); the ones created."""
    made = []
    for role in ROLES.values():
        exists = conn.execute("SELECT 1 FROM pg_roles WHERE rolname = %s", (role,)).fetchone()
        if not exists:
            conn.execute(f'CREATE ROLE "{role}" NOLOGIN')
            made.append(role)
    return made


def grant(conn) -> None:
    """Give the three roles their rights on this database's archive (idempotent)."""
    with conn.transaction():
        conn.execute(_GRANTS)


def add_user(conn, name: str, role: str) -> bool:
    """Make `name` a login user of `role` ("operator", "engineer", "auditor"); True when the user was created.

    A user keeps only the role given: its other linpar roles are revoked. Passwords are the
    administrator's business (ALTER ROLE ... PASSWORD, or the server's pg_hba.conf).
    """
    from psycopg import sql
    from analysis.archive.names import ArchiveError
    if role not in ROLES:
        raise ArchiveError(f"{name}={role}: unknown role: expected one of {', '.join(ROLES)}")
    created = conn.execute("SELECT 1 FROM pg_roles WHERE rolname = %s", (name,)).fetchone() is None
    with conn.transaction():
        if created:
            conn.execute(sql.SQL("CREATE ROLE {} LOGIN").format(sql.Identifier(name)))
        for other in ROLES.values():
            if other != ROLES[role]:
                conn.execute(sql.SQL("REVOKE {} FROM {}").format(sql.Identifier(other), sql.Identifier(name)))
        conn.execute(sql.SQL("GRANT {} TO {}").format(sql.Identifier(ROLES[role]), sql.Identifier(name)))
    return created


def roles_of(conn, user: str) -> list[str]:
    """The linpar roles `user` has (directly or through another role), for messages."""
    rows = conn.execute("SELECT r.rolname FROM pg_roles r WHERE r.rolname = ANY(%s) "
                        "AND pg_has_role(%s, r.oid, 'MEMBER') ORDER BY r.rolname",
                        (list(ROLES.values()), user)).fetchall()
    names = {v: k for k, v in ROLES.items()}
    return [names[r[0]] for r in rows]
