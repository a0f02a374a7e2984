"""Lexical reading of numeric text tables: comments, a header, a delimiter, rows of numbers.

Handles what frequency-response tools write: .zma/.frd and REW exports ('*'
comments, the column names often in the last comment line), '#' comments,
tab, comma, semicolon or blank separated columns, decimal commas (with ';' or
blank separators), CRLF or CR line ends, a UTF-8 BOM, Latin-1 text.

Strict on purpose: after the first data row, every non-comment line must be a
row of the same number of finite numbers, or the file is refused with the line
number. A silently skipped line would be a silently wrong curve.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.errors import LinparError
from analysis.files import read_bytes
from analysis.importers.errors import ImportFormatError

COMMENT_MARKERS = ("*", "#", "%", "'", "//", "!")
# [0-9]+(?:\.[0-9]*)? rather than [0-9]+\.?[0-9]*: the same numbers, but a long run of digits cannot be split
# between two quantifiers in n ways, so refusing a field costs linear, not quadratic, time.
_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NOT_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)
_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_BLANKS = re.compile(r"[ \t]+")


@dataclass(frozen=True)
class Dialect:
    name: str                 # "tab", "semicolon", "comma", "blank"
    decimal_comma: bool

    def split(self, text: str) -> list[str]:
        text = text.strip()
        if self.name == "blank":
            return _BLANKS.split(text)
        sep = {"tab": "\t", "semicolon": ";", "comma": ","}[self.name]
        fields = [f.strip() for f in text.split(sep)]
        if len(fields) > 1 and fields[-1] == "":    # a trailing separator ends many exports
            fields.pop()
        return fields


@dataclass(frozen=True)
class Table:
    path: Path
    values: np.ndarray                  # rows x columns, finite floats
    lines: np.ndarray                   # 1-based line number of each row
    header: tuple[str, ...] | None      # column names, when a line before the data names them
    header_line: int | None
    preamble: tuple[str, ...]           # comment and text lines before the data (markers removed)
    dialect: Dialect

    @property
    def n_columns(self) -> int:
        return self.values.shape[1]

    def error(self, line: int | None, message: str) -> ImportFormatError:
        return ImportFormatError(self.path, line, message)


class _Refused(LinparError):
    pass


def read_text(path: str | Path) -> str:
    path = Path(path)
    try:    # a FIFO or a device would block the read forever; a huge file is no curve export
        raw = read_bytes(path, "curve", "a text file (a curve export)", _Refused)
    except _Refused as exc:
        raise ImportFormatError(path, None, str(exc).removeprefix(f"{path}: ")) from None
    return decode(path, raw)


def decode(path: Path, raw: bytes) -> str:
    nul = raw.find(b"\x00")
    if nul >= 0:
        line = raw.count(b"\n", 0, nul) + 1
        raise ImportFormatError(path, line, "binary data (a NUL byte): expected a text file")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("latin-1")    # the 8-bit exports of Windows tools; every byte decodes


def _is_comment(stripped: str) -> bool:
    return stripped.startswith(COMMENT_MARKERS)


def _strip_comment(stripped: str) -> str:
    for marker in sorted(COMMENT_MARKERS, key=len, reverse=True):
        if stripped.startswith(marker):
            return stripped[len(marker):].lstrip(marker[0]).strip()
    return stripped


def _looks_numeric(field: str, decimal_comma: bool) -> bool:
    if decimal_comma:
        field = field.replace(",", ".")
    return bool(_NUMBER.fullmatch(field))


def detect_dialect(stripped: str) -> Dialect:
    """The separator and decimal mark of a data line."""
    if "\t" in stripped:
        return Dialect("tab", "," in stripped)
    if ";" in stripped:
        return Dialect("semicolon", "," in stripped)
    if "," in stripped:
        blank_fields = _BLANKS.split(stripped)
        if len(blank_fields) > 1 and "." not in stripped and all(_looks_numeric(f, True) for f in blank_fields):
            return Dialect("blank", True)       # '10,5 7,1 25,3': decimal commas between blanks
        return Dialect("comma", False)
    return Dialect("blank", False)


def parse_number(path: Path, line: int, column: int, field: str, decimal_comma: bool) -> float:
    text = field.replace(",", ".") if decimal_comma else field
    if _NUMBER.fullmatch(text):
        value = float(text)
        if np.isfinite(value):
            return value
    if _NOT_FINITE.fullmatch(text) or _NUMBER.fullmatch(text):
        raise ImportFormatError(path, line, f"column {column}: {field!r} is not a finite number (NaN or infinite)")
    shown = field if len(field) <= 40 else field[:37] + "..."
    if field == "":
        raise ImportFormatError(path, line, f"column {column} is empty: expected a number")
    raise ImportFormatError(path, line, f"column {column}: non-numeric field {shown!r}: expected a number")


def parse_table(path: str | Path, text: str) -> Table:
    """Split `text` into preamble, optional header and numeric rows. Raises ImportFormatError."""
    path = Path(path)
    preamble: list[tuple[int, str, bool]] = []      # (line, text, is_comment)
    rows: list[list[float]] = []
    line_numbers: list[int] = []
    dialect: Dialect | None = None
    n_columns = 0
    first_data_line = 0
    for number, raw in enumerate(_LINE_BREAK.split(text), start=1):
        stripped = raw.strip()
        if not stripped:
            continue
        if _is_comment(stripped):
            if dialect is None:
                preamble.append((number, _strip_comment(stripped), True))
            continue
        if dialect is None:
            candidate = detect_dialect(stripped)
            fields = candidate.split(stripped)
            if not _looks_numeric(fields[0], candidate.decimal_comma):
                preamble.append((number, stripped, False))    # a title or column names
                continue
            dialect, n_columns, first_data_line = candidate, len(fields), number
            if n_columns < 2:
                raise ImportFormatError(path, number, "one column only: expected frequency and at least one value "
                                        "per line, separated by tabs, commas, semicolons or blanks")
        fields = dialect.split(stripped)
        if len(fields) != n_columns:
            raise ImportFormatError(path, number, f"{len(fields)} columns where line {first_data_line} has "
                                    f"{n_columns} ({dialect.name}-separated)")
        rows.append([parse_number(path, number, c + 1, f, dialect.decimal_comma) for c, f in enumerate(fields)])
        line_numbers.append(number)
    if not rows:
        what = "empty file" if not preamble else "no data rows (only comments or text)"
        raise ImportFormatError(path, None, f"{what}: expected lines of numbers")
    header, header_line = _header(preamble, dialect, n_columns)
    return Table(path, np.array(rows, dtype=float), np.array(line_numbers), header, header_line,
                 tuple(t for _, t, _ in preamble), dialect)


def _header(preamble, dialect: Dialect, n_columns: int) -> tuple[tuple[str, ...] | None, int | None]:
    """Column names: the line just before the data, when it splits into one name per column.

    Only that line: REW and most tools put the names there, and an earlier
    comment that happens to have as many words would name the columns wrongly.
    """
    if not preamble:
        return None, None
    number, text, _ = preamble[-1]
    for candidate in (dialect, Dialect("tab", False), Dialect("comma", False), Dialect("blank", False)):
        names = [n for n in candidate.split(text) if n]
        if len(names) == n_columns and any(re.search(r"[A-Za-z]", n) for n in names):
            return tuple(names), number
    return None, None


def read_table(path: str | Path) -> Table:
    return parse_table(path, read_text(path))
