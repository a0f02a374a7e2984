"""The PDF report's fonts: which one draws each character, how wide it is, and what stands in where none can.

matplotlib draws the report in DejaVu Sans, which has no Chinese, Japanese or Korean. A fallback font draws what
it lacks when matplotlib finds one installed: FALLBACK_FAMILIES, Debian's fonts-droid-fallback (1.8 MB, in
tools/system-packages.sh) among them. A character no font has would be drawn as an empty box, with one of
matplotlib's warnings on the user's terminal for each; it is written as STAND_IN instead, and the report says so
(analysis.report.pdf). The layout (analysis.report.text_fit) measures a line by the advance widths read here.
"""
from __future__ import annotations

from functools import lru_cache

from matplotlib import font_manager
from matplotlib.ft2font import FT2Font, LoadFlags

FAMILY = "DejaVu Sans"
# Only fonts checked to draw into the report's PDF (single TrueType files): Droid Sans Fallback has the CJK
# ideographs and kana, not Hangul.
FALLBACK_FAMILIES = ("Droid Sans Fallback",)
STAND_IN = "\N{REPLACEMENT CHARACTER}"          # "�": DejaVu Sans has it, and readers know it for "lost"
_PIXELS_PER_EM = 100        # the size the advances are read at; they are returned per em


@lru_cache(maxsize=1)
def families() -> tuple[str, ...]:
    """DejaVu Sans, then each fallback font matplotlib finds installed: matplotlib's font.family for the PDF."""
    installed = {entry.name for entry in font_manager.fontManager.ttflist}
    return (FAMILY,) + tuple(name for name in FALLBACK_FAMILIES if name in installed)


@lru_cache(maxsize=2)
def _fonts(bold: bool) -> tuple[FT2Font, ...]:
    """The fonts of families() in turn, bold where the font has it (the fallbacks have no bold)."""
    fonts = []
    for i, family in enumerate(families()):
        weight = "bold" if bold and i == 0 else "normal"
        # Font objects of our own: matplotlib's cached ones (font_manager.get_font) are resized by every draw.
        font = FT2Font(font_manager.findfont(font_manager.FontProperties(family=family, weight=weight)))
        font.set_size(_PIXELS_PER_EM, 72)
        fonts.append(font)
    return tuple(fonts)


@lru_cache(maxsize=None)
def _font_for(char: str, bold: bool) -> FT2Font | None:
    return next((font for font in _fonts(bold) if font.get_char_index(ord(char))), None)


def draws(char: str) -> bool:
    """True when a font of the report's draws `char` (white space is laid out, not drawn)."""
    return char.isspace() or _font_for(char, False) is not None


def drawable(text: str) -> str:
    """`text` with each character no font of the report's has written as STAND_IN."""
    return "".join(c if draws(c) else STAND_IN for c in text)


@lru_cache(maxsize=None)
def advance(char: str, bold: bool = False) -> float:
    """How far `char` moves the pen, in ems (its width in points at a size of 1 pt); STAND_IN's where no
    font has it, since that is what is drawn."""
    font = _font_for(char, bold) or _font_for(STAND_IN, bold)
    glyph = font.load_char(ord(char) if font.get_char_index(ord(char)) else ord(STAND_IN),
                           flags=LoadFlags.NO_HINTING)
    return glyph.linearHoriAdvance / 65536 / _PIXELS_PER_EM      # FreeType's 16.16 fixed point, in pixels
