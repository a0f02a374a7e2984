"""Lines of the PDF report fitted to a width measured in the font's advance widths (analysis.report.fonts).

Counting characters at an average width let a name of wide letters (capitals, a run of "X") run past the
page's edge and pushed the footer's page number off the page. Kerning only narrows a line, so the sum of its
characters' advances is an upper bound of its drawn width: a line measured so stays inside the margins.
"""
from __future__ import annotations

from analysis.report.fonts import advance

ELLIPSIS = "…"


def width_in(text: str, size_pt: float, bold: bool = False) -> float:
    """The width `text` is drawn at, in inches."""
    return size_pt * sum(advance(c, bold) for c in text) / 72


def _longest_prefix(text: str, width: float, size_pt: float, bold: bool) -> int:
    """How many of `text`'s first characters fit in `width` inches (at least one: a line always advances)."""
    used = 0.0
    for n, c in enumerate(text):
        used += size_pt * advance(c, bold) / 72
        if used > width:
            return max(1, n)
    return len(text)


def wrap(text: str, width: float, size_pt: float, bold: bool = False) -> list[str]:
    """`text`'s words in lines no wider than `width` inches, runs of white space read as one space (as
    textwrap.wrap: [] for blank text). A word wider than a line is cut where the line is full."""
    lines: list[str] = []
    line, used = "", 0.0
    space = width_in(" ", size_pt, bold)
    for word in text.split():
        wide = width_in(word, size_pt, bold)
        if line and used + space + wide <= width:
            line, used = f"{line} {word}", used + space + wide
            continue
        if line:
            lines.append(line)
        while wide > width:
            cut = _longest_prefix(word, width, size_pt, bold)
            lines.append(word[:cut])
            word = word[cut:]
            wide = width_in(word, size_pt, bold)
        line, used = word, wide
    if line:
        lines.append(line)
    return lines


def shorten(text: str, width: float, size_pt: float, bold: bool = False) -> str:
    """`text` on one line no wider than `width` inches: cut, with an ellipsis, when it is wider."""
    text = " ".join(text.split())
    if width_in(text, size_pt, bold) <= width:
        return text
    room = width - width_in(ELLIPSIS, size_pt, bold)
    return text[:_longest_prefix(text, room, size_pt, bold)].rstrip() + ELLIPSIS
