"""Which archive a command uses (--archive URL|DIR, --root DIR, the environment) and the server's own verbs.

    linpar archive setup --archive postgresql://OWNER@HOST/DB [--user NAME=ROLE ...]   create or migrate it
    linpar archive sync [--archive URL]                                                 send this station's queue

Every command that reads or writes the archive takes --archive (a
postgresql:// URL or a folder) or --root (a folder); without them
$LINPAR_ARCHIVE_URL, then $LINPAR_ARCHIVE, then the default folder
(analysis.archive.backends.archive_spec).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from analysis.config_folder import data_folder
from app.cli.options import CliError, add_json_option
from app.cli.output import print_json

SERVER_VERBS = ("setup", "sync")


def add_archive_options(parser: argparse.ArgumentParser) -> None:
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--archive", metavar="URL|DIR",
                       help="the archive: postgresql://USER@HOST[:PORT]/DB (the line's server) or a folder "
                            f"(default: $LINPAR_ARCHIVE_URL, else $LINPAR_ARCHIVE, else {data_folder() / 'archive'})")
    where.add_argument("--root", metavar="DIR", help="a folder archive (as --archive DIR)")


def spec_of(args) -> str:
    """The archive the options name; the environment's when they name none."""
    from analysis.archive.backends import archive_spec
    for option in ("archive", "root"):
        if getattr(args, option, None) is not None and not getattr(args, option).strip():
            raise CliError(f"--{option}: empty: give a folder" + (" or postgresql://USER@HOST[:PORT]/DATABASE"
                                                                 if option == "archive" else ""))
    explicit = getattr(args, "archive", None) or (str(Path(args.root).expanduser()) if getattr(args, "root", None)
                                                  else None)
    return archive_spec(explicit)


def open_from_args(args, creates: bool = False):
    """The archive the options name. A folder named on the command line that does not exist is refused unless
    the command `creates` (stores the first measurement or limits): a mistyped path answered "0 measurement(s)",
    exit 0, as if the line had measured nothing (a store says where it stored)."""
    from analysis.archive.backends import open_archive
    spec = spec_of(args)
    named = getattr(args, "archive", None) or getattr(args, "root", None)
    if named and not creates and "://" not in spec and not Path(spec).exists():
        raise CliError(f"{spec}: no archive there: check the path (a first 'linpar archive store' or 'linpar qa "
                       "limits --store' makes one)")
    return open_archive(spec)


def say_notes(archive) -> None:
    for note in archive.notes:
        print(f"linpar: note: {note}", file=sys.stderr)


def register_verbs(verbs) -> None:
    setup = verbs.add_parser("setup", help="create or migrate the archive on a PostgreSQL server, its roles and "
                                           "users (as the database's owner)")
    setup.add_argument("--user", action="append", default=[], metavar="NAME=ROLE",
                       help="make NAME a login user with ROLE operator, engineer or auditor (repeatable)")
    sync = verbs.add_parser("sync", help="send this station's queued measurements to the archive's server")
    for parser in (setup, sync):
        add_archive_options(parser)
        add_json_option(parser, "print JSON")


def run_verb(args) -> int:
    from analysis.archive.backends import is_url
    spec = spec_of(args)
    if args.archive_command == "setup":
        if not is_url(spec):
            raise CliError("archive setup: a folder archive needs no setup; give --archive postgresql://OWNER@HOST/DB")
        users = {}
        for item in args.user:
            name, sep, role = item.partition("=")
            if not sep or not name.strip() or not role.strip():
                raise CliError(f"--user {item!r}: expected NAME=ROLE, ROLE one of operator, engineer, auditor")
            users[name.strip()] = role.strip()
        from analysis.archive.pg import setup
        report = setup(spec, users)
        if args.json:
            print_json({"archive": report.location, "schema_from": report.schema_from,
                        "schema_to": report.schema_to, "roles_created": report.roles_created, "users": report.users})
        else:
            print(report.describe())
        return 0
    from analysis.archive.backends import open_archive
    archive = open_archive(spec)
    report = archive.sync()
    say_notes(archive)
    if report.waiting:
        from analysis.archive import ArchiveError
        sent = f"{len(report.sent)} sent, " if report.sent else ""
        why = "; ".join(x for x in (report.problem, *report.stuck[:3]) if x)
        raise ArchiveError(f"{why}: {sent}{report.waiting} measurement(s) wait in the local queue "
                           f"{getattr(getattr(archive, 'outbox', None), 'root', '')}; nothing is lost")
    if args.json:
        print_json({"archive": archive.location, "sent": report.sent, "already": report.already})
    else:
        print(f"{archive.location}: {report.describe()}" if report.sent or report.already
              else f"{archive.location}: nothing waits in this station's queue")
    return 0
