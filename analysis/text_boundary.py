"""Text that crosses a boundary: the one check where a name enters, and the escapes where it leaves.

A name a user typed or a file said (a limits name, a serial, an operator, a
station, a driver, an effect's title) is copied into records, reports,
exports, terminals and the GUI. One class of characters is refused where it
enters, and the same class is what every reader of the archive checks, so
that nothing stored can be refused when read back:

- control characters (C0, DEL, C1: tabs, line breaks, NUL, ESC that starts
  terminal sequences), the Unicode line and paragraph separators;
- the bidirectional controls (U+200E, U+200F, U+061C, U+202A-U+202E,
  U+2066-U+2069): a station typed as "st2" + U+202E + "SSAP" read "st2PASS"
  in a report, beside its verdict;
- lone UTF-16 surrogates: Python's stand-ins for bytes that were not UTF-8
  (a Latin-1 `--operator $'M\\xfcller'`), which no file or terminal can encode.

Where text leaves, each way out has its own escape:

- `shown`: what cannot be printed becomes visible (`\\t`, `\\x1b`, `\\xfc`):
  a value read back that breaks the rule is shown flagged, never dropped;
- `terminal`: ANSI/OSC escape sequences removed, other control characters shown;
- `spreadsheet_cell`: OWASP's CSV-injection rule: a cell that begins with
  = + - @, a tab or a carriage return is prefixed with ' so that no
  spreadsheet runs it as a formula;
- Qt labels are set to plain text (app/, not here: no Qt in analysis).
"""
from __future__ import annotations

import re
from functools import cache

from analysis.errors import LinparError

# The bidirectional controls (LRM, RLM, ALM, the embeddings and overrides, the isolates), as a character class's
# inside: the patterns below, _what's words and the server's CHECK (analysis.archive.pg.audit) share it.
BIDI_CLASS = r"\u200e\u200f\u061c\u202a-\u202e\u2066-\u2069"
# The patterns, compiled on first use (PEP 562 below): a class holding the surrogates' 2048 characters takes
# 0.2-0.6 ms to compile, and most starts of the command line use SURROGATES alone (its arguments' check).
_PATTERNS = {
    # The class refused where a name enters and checked wherever a stored one is read.
    "CONTROL": rf"[\x00-\x1f\x7f-\x9f\u2028\u2029{BIDI_CLASS}\ud800-\udfff]",
    # The same, but a line break allowed: a multi-line description (an effect's physics).
    "CONTROL_BUT_NEWLINE": rf"[\x00-\x09\x0b-\x1f\x7f-\x9f\u2028\u2029{BIDI_CLASS}\ud800-\udfff]",
    "_BIDI": f"[{BIDI_CLASS}]",
    # ESC [ ... final byte (CSI), ESC ] ... BEL or ESC \ (OSC), ESC and one byte: what a terminal acts on.
    "_ESCAPE_SEQUENCE": r"\x1b\[[0-?]*[ -/]*[@-~]|\x1b\][^\x07\x1b]*(?:\x07|\x1b\\)?|\x9b[0-?]*[ -/]*[@-~]"
                        r"|\x9d[^\x07\x1b\x9c]*(?:\x07|\x1b\\|\x9c)?|\x1b[@-_]?",
}
# Python's stand-ins for bytes that were not UTF-8 (surrogateescape).
SURROGATES = re.compile(r"[\ud800-\udfff]")
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r")
_NAMED = {"\t": "\\t", "\n": "\\n", "\r": "\\r", "\x00": "\\0"}


@cache
def _pattern(name: str) -> re.Pattern:
    return re.compile(_PATTERNS[name])


def __getattr__(name: str) -> re.Pattern:
    """CONTROL and CONTROL_BUT_NEWLINE, compiled when first asked for (`from analysis.text_boundary import
    CONTROL` too)."""
    if name in _PATTERNS and not name.startswith("_"):
        return _pattern(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class TextError(LinparError, ValueError):
    """A name that may not cross into the archive, a report or a terminal as given; one line."""


def _what(char: str) -> str:
    if "\ud800" <= char <= "\udfff":
        return f"the byte {_visible(char)} that is not UTF-8 (set the terminal or file to UTF-8)"
    if _pattern("_BIDI").match(char):
        return f"the bidirectional control {_visible(char)} (it reorders the text shown after it)"
    return f"the control character {_visible(char)}"


def _visible(char: str) -> str:
    code = ord(char)
    if char in _NAMED:
        return _NAMED[char]
    if 0xDC80 <= code <= 0xDCFF:          # surrogateescape's stand-in for the byte code - 0xDC00
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def control_found(text: str, pattern: re.Pattern | None = None) -> str | None:
    """What the first refused character is, in words ("the control character \\t"), or None; `pattern`: the
    class refused (default CONTROL)."""
    bad = (pattern or _pattern("CONTROL")).search(text)
    return None if bad is None else _what(bad.group())


def one_line(value, where: str, error: type[LinparError] = TextError, pattern: re.Pattern | None = None) -> str:
    """`value` when it is a string without refused characters; `error` naming `where` otherwise."""
    if not isinstance(value, str):
        raise error(f"{where}: found {type(value).__name__}, expected a string")
    what = control_found(value, pattern)
    if what:
        raise error(f"{where}: holds {what}; expected one line of text")
    return value


def cleaned(value: str, max_len: int = 200) -> str:
    """A string as it may be stored when it cannot be refused (a form's field): refused characters -> spaces."""
    return _pattern("CONTROL").sub(" ", value).strip()[:max_len]


def shown(text: str, pattern: re.Pattern | None = None) -> str:
    """Every refused character written visibly (\\t, \\x1b, \\xfc): safe to print, and still telling; `pattern`:
    the class refused (default CONTROL)."""
    return (pattern or _pattern("CONTROL")).sub(lambda m: _visible(m.group()), text)


def terminal(text: str) -> str:
    """Text for a terminal: escape sequences (colours, titles, hyperlinks) removed, other controls shown;
    line breaks kept."""
    return shown(_pattern("_ESCAPE_SEQUENCE").sub("", str(text)), _pattern("CONTROL_BUT_NEWLINE"))


def spreadsheet_cell(text: str) -> str:
    """A text cell no spreadsheet runs as a formula (OWASP: prefix = + - @ tab CR with a quote)."""
    text = str(text)
    return "'" + text if text.startswith(_FORMULA_START) else text


def spreadsheet_comment(line: str, delimiter: str = ",") -> str:
    """A comment line of a CSV file ('# driver ...') that no spreadsheet runs as a formula.

    A spreadsheet knows no comments: it splits the line at the delimiter as any row, so a name holding a comma
    puts what follows in a cell of its own ('# driver ACME,=1+2' has the cell '=1+2'). Each part after the
    first that would start a formula is quoted as spreadsheet_cell does, also behind spaces or an opening quote
    ('"=1+2"' is the cell =1+2).
    The line still starts with '#' for the readers that skip such lines (pandas' comment='#', csv readers).
    """
    first, *rest = str(line).split(delimiter)
    return delimiter.join([first, *("'" + part if part.lstrip(' "').startswith(_FORMULA_START) else part
                                    for part in rest)])
