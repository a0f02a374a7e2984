"""The one error an importer raises: which file, which line, what was expected."""
from __future__ import annotations

from pathlib import Path

from analysis.errors import LinparError


class ImportFormatError(LinparError, ValueError):
    """A file that cannot be imported. The message is one line: FILE: line N: what was expected."""

    def __init__(self, path: str | Path, line: int | None, message: str):
        self.path = Path(path)
        self.line = line
        self.reason = message
        where = f"{self.path}: line {line}: " if line is not None else f"{self.path}: "
        # One line whatever the data: a field copied into the message may hold a line break.
        super().__init__((where + message).replace("\r", " ").replace("\n", " "))
