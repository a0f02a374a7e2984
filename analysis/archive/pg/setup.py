"""`linpar archive setup`: the database's owner creates (or migrates) the archive, its roles and its users.

    setup("postgresql://owner@qa-db/linpar", {"station1": "operator", "eva": "engineer", "audit": "auditor"})

Run as the owner of the database, with the right to create roles (CREATEROLE,
or a superuser). Idempotent: run again after updating linpar, it migrates
the schema to this program's version and renews the grants.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from analysis.archive.pg.audit import SERVER_SETTINGS
from analysis.archive.pg.schema import add_user, ensure_roles, grant, migrate, roles_of
from analysis.archive.pg.server import parse_url, server_errors


@dataclass
class SetupReport:
    location: str
    schema_from: int
    schema_to: int
    roles_created: list[str] = field(default_factory=list)
    users: dict[str, str] = field(default_factory=dict)        # user -> "created" / "updated", with the role

    def describe(self) -> str:
        schema = (f"schema created at version {self.schema_to}" if self.schema_from == 0 else
                  f"schema migrated from version {self.schema_from} to {self.schema_to}"
                  if self.schema_from != self.schema_to else f"schema at version {self.schema_to}")
        users = "; ".join(f"{u}: {what}" for u, what in self.users.items())
        return f"{self.location}: {schema}" + (f"; roles created: {', '.join(self.roles_created)}"
                                               if self.roles_created else "") + (f"; users: {users}" if users else "")


def setup(url: str, users: Mapping[str, str] | None = None) -> SetupReport:
    import psycopg
    server = parse_url(url)
    doing = "setting up the archive (as the database's owner, with CREATEROLE)"
    with server_errors(server, doing):
        conn = psycopg.connect(**server.params, autocommit=True)
    try:
        with server_errors(server, doing):
            made = ensure_roles(conn)
            start, end = migrate(conn)
            grant(conn)
            bound_sessions(conn, server.dbname)
            report = SetupReport(server.display, start, end, made)
            for name, role in (users or {}).items():
                created = add_user(conn, name, role)
                report.users[name] = f"{'created' if created else 'updated'}, {', '.join(roles_of(conn, name))}"
        return report
    finally:
        conn.close()


def bound_sessions(conn, dbname: str) -> None:
    """The server-side bounds of every session on the archive's database (audit.SERVER_SETTINGS)."""
    from psycopg import sql
    for name, value in SERVER_SETTINGS.items():
        conn.execute(sql.SQL("ALTER DATABASE {} SET {} = {}").format(sql.Identifier(dbname), sql.Identifier(name),
                                                                      sql.Literal(value)))
