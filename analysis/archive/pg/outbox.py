"""A station's local queue: every measurement is stored here first, then sent to the server, exactly once.

The queue is a folder archive of its own (analysis.archive.Archive: a
complete folder renamed into place, or nothing), kept per server and user in
$LINPAR_QUEUE or queue/ in the platform's data folder (analysis.config_folder). Sending one measurement is one
transaction on the server (its row, parameters and files), keyed by the
measurement's id, which the station chose when it queued it:

- the server had no such id: the transaction stores it;
- it had it with the same record (SHA-256 of the canonical JSON): it was
  sent before and the acknowledgement was lost (the network dropped after
  the commit, or the station stopped before it removed its copy): nothing
  is stored again;
- it had it with another record (two stations drew the same 24 random bits
  in the same second): the measurement gets a new id, drawn from its own
  record's SHA-256 (so that a resend draws the same one), and is sent under it.

Only then is the local copy removed. So a measurement is on the server once
whatever breaks when: the queue never deletes before the server has it, and
the server never takes an id twice. One sender per queue at a time (an
exclusive lock on .send.lock): two programs at one station do not send the
same folder at once. The queue also keeps the last limits version the
station saw (limits.json), so that a station cut off from the server judges
with it, and the verdict names that version.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from analysis import file_lock
from analysis.archive.archive import Archive
from analysis.archive.atomic import FILE_MODE, write_atomic
from analysis.archive.limits_store import LimitsVersion, version_json, version_of_json
from analysis.archive.names import ArchiveError, folder_name
from analysis.archive.pg.server import ServerRefused, ServerUnreachable, server_errors
from analysis.archive.pg.upload import IdTaken, record_sha256, send_measurement
from analysis.archive.sync_report import SyncReport
from analysis.config_folder import data_folder, overridden

LIMITS_CACHE = "limits.json"
LOCK_FILE = ".send.lock"


def queue_folder(slug: str) -> Path:
    return (overridden("LINPAR_QUEUE") or data_folder() / "queue") / slug


class Outbox:
    def __init__(self, root: Path):
        self.root = Path(root)
        self.archive = Archive(self.root)

    def put(self, recording, result, meta, laser_stream, now, judge_with: LimitsVersion | None) -> str:
        return self.archive.store(recording, result, meta, laser_stream=laser_stream, now=now, judge_with=judge_with)

    def waiting(self) -> list:
        """The queued measurements, oldest first (in the order they were measured and stored)."""
        return sorted(self.archive.list(), key=lambda e: (e.stored_at, e.id))

    # --- the limits a station cut off from the server judges with ------------------------------

    def remember_limits(self, version: LimitsVersion | None) -> None:
        if version is None or self.last_limits() == version:
            return
        self.root.mkdir(parents=True, exist_ok=True)
        write_atomic(self.root / LIMITS_CACHE, json.dumps(version_json(version), indent=1) + "\n")

    def last_limits(self) -> LimitsVersion | None:
        path = self.root / LIMITS_CACHE
        if not path.is_file():
            return None
        try:
            return version_of_json(json.loads(path.read_text()), str(path))
        except (ArchiveError, ValueError, OSError):
            return None         # a damaged copy: judged with no limits rather than wrong ones

    # --- sending ------------------------------------------------------------------------------------

    def _sending(self):
        """The station's sending lock: yields False when another program at this station is sending."""
        self.root.mkdir(parents=True, exist_ok=True)
        return file_lock.exclusive(self.root / LOCK_FILE, wait=False)

    def send(self, conn, server) -> SyncReport:
        """Send every queued measurement, oldest first; stop at the first that the server cannot take."""
        report = SyncReport()
        with self._sending() as mine:
            queued = self.waiting()
            if not mine:
                report.waiting, report.problem = len(queued), "another program at this station is sending them"
                return report
            for n, entry in enumerate(queued):
                try:
                    mid, outcome = self._send_one(conn, server, entry.id)
                except (ServerUnreachable, ServerRefused) as exc:
                    report.waiting = len(queued) - n
                    report.problem, report.refused = str(exc), isinstance(exc, ServerRefused)
                    break
                except ArchiveError as exc:     # this one cannot be sent as it is: it stays, the others go
                    report.stuck.append(f"{entry.id}: {exc}")
                    continue
                (report.sent if outcome == "sent" else report.already).append(mid)
                self.archive.discard(entry.id)
            report.waiting += len(report.stuck)
        return report

    def _send_one(self, conn, server, mid: str) -> tuple[str, str]:
        m = self.archive.get(mid)
        record = m.record
        digest = record_sha256(m.record)
        for attempt in range(5):
            try:
                with server_errors(server, f"sending the measurement {record['id']}", needs="an operator"):
                    return record["id"], send_measurement(conn, record, m.folder)
            except IdTaken:
                # The new id follows from the record, not from chance: sent again after a lost acknowledgement,
                # the measurement draws the same ids in the same order and finds itself there (ALREADY).
                tail = hashlib.sha256(f"{digest}/{attempt}".encode()).hexdigest()[:6]
                new = f"{mid[:15]}-{tail}"
                record = {**record, "id": new, "folder": folder_name(new, record["driver"], record["serial"])}
        raise ArchiveError(f"{mid}: the server has other measurements under five ids drawn for it")
