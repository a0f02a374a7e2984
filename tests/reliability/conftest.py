"""The fuzz suites' outcome counts, at the end of the run (the issue asks for them in its closing note)."""
from __future__ import annotations


def pytest_terminal_summary(terminalreporter):
    from tests.reliability.cli_outcome import OUTCOMES
    if OUTCOMES:
        counts = ", ".join(f"{n} x {kind}" for kind, n in sorted(OUTCOMES.items()))
        terminalreporter.write_line(f"linpar runs on hostile input: {sum(OUTCOMES.values())} ({counts})")
