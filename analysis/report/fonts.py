"""The PDF report's font as its layout needs it: how wide each character is drawn.

matplotlib draws the report in DejaVu Sans. The layout (analysis.report.text_fit) measures a line by the
font's own advance widths, read here once per character, rather than by counting characters.
"""
from __future__ import annotations

from functools import lru_cache

from matplotlib import font_manager
from matplotlib.ft2font import FT2Font, LoadFlags

FAMILY = "DejaVu Sans"
_PIXELS_PER_EM = 100        # the size the advances are read at; they are returned per em


@lru_cache(maxsize=2)
def _font(bold: bool) -> FT2Font:
    # A font object of our own: matplotlib's cached ones (font_manager.get_font) are resized by every draw.
    path = font_manager.findfont(font_manager.FontProperties(family=FAMILY, weight="bold" if bold else "normal"))
    font = FT2Font(path)
    font.set_size(_PIXELS_PER_EM, 72)
    return font


@lru_cache(maxsize=None)
def advance(char: str, bold: bool = False) -> float:
    """How far `char` moves the pen, in ems: its width in points at a size of 1 pt."""
    glyph = _font(bold).load_char(ord(char), flags=LoadFlags.NO_HINTING)
    return glyph.linearHoriAdvance / 65536 / _PIXELS_PER_EM      # FreeType's 16.16 fixed point, in pixels
