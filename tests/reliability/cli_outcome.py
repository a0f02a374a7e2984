"""What a `linpar` run on hostile input may end in, checked in-process: exit 0 with strict JSON, or exit 2 with
one line, and never a traceback or a crash report.

`outcome(capsys, argv)` runs app.cli.main, checks the rule and counts the outcome in OUTCOMES (printed at
the end of the session by tests/conftest.py, summed over the workers, for the issue's closing note). The one
other exit a command gives on purpose is `analyze --limits`'s verdict: 1 for a driver that fails its limits, 2 with
the JSON (or the table) when the measurement cannot be judged.
"""
from __future__ import annotations

import json
import os
from collections import Counter
from pathlib import Path

from app.cli import main

OUTCOMES: Counter = Counter()


def strict_json(text: str):
    """JSON as every reader takes it: NaN and Infinity are refused."""
    def refuse(name):
        raise AssertionError(f"{name} in the JSON output")
    return json.loads(text, parse_constant=refuse)


def _crash_reports() -> set[Path]:
    folder = Path(os.environ["LINPAR_CACHE"])
    return set(folder.glob("crash-*")) if folder.is_dir() else set()


def outcome(capsys, argv) -> str:
    """Run `linpar argv` and check the rule; 'ok' (exit 0), 'refused' (exit 2, one line) or 'verdict'."""
    argv = [str(a) for a in argv]
    before = _crash_reports()
    code = main(argv)
    out, err = capsys.readouterr()
    assert not _crash_reports() - before, f"{argv}: an internal error: {err}"
    assert "Traceback" not in out + err, (argv, err)
    errors = [line for line in err.splitlines() if line.startswith("linpar: error: ")]
    if code == 2 and errors:
        assert len(errors) == 1 and out == "", (argv, out, err)
        OUTCOMES["exit 2, one line"] += 1
        return "refused"
    assert not errors, (argv, err)
    wants_json = "--json" in argv
    if code in (1, 2) and "--limits" in argv:     # the QA verdict: fail, or not judged
        verdict = strict_json(out)["limits"]["verdict"] if wants_json else out
        OUTCOMES[f"exit {code}, QA verdict"] += 1
        assert code == 1 and "fail" in verdict or code == 2 and ("invalid" in verdict or "not judged" in verdict
                                                                  or "INVALID" in verdict or "NOT JUDGED" in verdict)
        return "verdict"
    assert code == 0, (argv, code, err)
    if wants_json:
        strict_json(out)
    OUTCOMES["exit 0" + (", strict JSON" if wants_json else "")] += 1
    return "ok"
