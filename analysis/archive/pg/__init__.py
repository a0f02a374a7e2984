"""The PostgreSQL back end of the archive (psycopg 3): the line's server, its roles, a station's local queue.

    PostgresArchive(url)          the archive (analysis.archive.backends.ArchiveBackend)
    setup(url, users)             the database owner creates or migrates the schema, the roles, the users
"""
from analysis.archive.pg.archive import PostgresArchive
from analysis.archive.pg.server import ServerRefused, ServerUnreachable
from analysis.archive.pg.setup import setup

__all__ = ["PostgresArchive", "ServerRefused", "ServerUnreachable", "setup"]
