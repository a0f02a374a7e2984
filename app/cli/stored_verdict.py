"""The QA verdict the archive gave a measurement as it stored it, against its newest limits: said by the commands
that store one (`linpar measure`, `linpar archive store`). The verdict was written into the record and counted
in the line's statistics, but neither command printed it: an operator read "stored ... (validity green)" for a
unit the archive recorded as FAIL."""
from __future__ import annotations

import sys

from analysis.validity.fit import VERDICT_HEADLINES


def stored_verdict(archive, mid: str, result) -> tuple[dict | None, str]:
    """({"verdict", "limits_version"}, the words: the headline and each parameter's line as `linpar analyze
    --limits` prints them) of the stored measurement `mid`, whose analysis is `result`; (None, "") when no limits
    judged it (none stored yet, or the measurement waits in a station's queue), or when it cannot be read back:
    the measurement is stored by then, and the verdict's words must not turn that into a failure."""
    try:
        return _stored_verdict(archive, mid, result)
    except Exception as exc:  # noqa: BLE001 - whatever the read-back met (a server gone meanwhile): said, not raised
        print(f"linpar: note: {mid} is stored; its QA verdict could not be read back: {exc}", file=sys.stderr)
        return None, ""


def _stored_verdict(archive, mid: str, result) -> tuple[dict | None, str]:
    entry = archive.get(mid).entry
    if entry.verdict is None:
        return None, ""
    qa = {"verdict": entry.verdict, "limits_version": entry.limits_version}
    version = next((v for v in archive.limits_versions() if v.version == entry.limits_version), None)
    headline = VERDICT_HEADLINES.get(entry.verdict, str(entry.verdict).upper())
    words = f"QA: {headline} (the archive's limits, version {entry.limits_version}" + \
        (f": {version.name})" if version is not None else ")")
    if version is not None:
        from analysis.limits import format_verdicts
        words += "\n" + format_verdicts(version.limits(), result.parameters, result.validity)
    return qa, words
