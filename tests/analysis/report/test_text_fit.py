"""Lines fitted to a width by the font's advance widths (analysis.report.text_fit)."""
import pytest
from matplotlib.font_manager import FontProperties
from matplotlib.textpath import TextToPath

from analysis.report.fonts import FAMILY
from analysis.report.text_fit import ELLIPSIS, shorten, width_in, wrap


@pytest.mark.parametrize("text", ["XXXXXXXXXXXXXXXXXXXX", "Loudspeaker-Fabrik Müller & Söhne", "iiiiiiiiii WWWW"])
@pytest.mark.parametrize("bold", [False, True])
def test_a_width_is_the_drawn_width_or_a_little_more(text, bold):
    drawn = TextToPath().get_text_width_height_descent(
        text, FontProperties(family=FAMILY, size=10, weight="bold" if bold else "normal"), ismath=False)[0] / 72
    # Kerning only narrows a line (matplotlib's width also ends at the last glyph's outline: a hair either way).
    assert 0.999 * drawn <= width_in(text, 10, bold) <= 1.03 * drawn


def test_wide_letters_wrap_inside_the_width_and_no_character_is_lost():
    # 40 "X" are 3.8 inches at 10 pt; counted as average letters (0.56 em), 50 of them were thought to fit.
    text = "Very long driver name " + "X" * 120
    lines = wrap(text, 3.0, 10, bold=True)
    assert len(lines) >= 4 and all(width_in(line, 10, True) <= 3.0 for line in lines)
    assert "".join("".join(lines).split()) == "".join(text.split())      # the long word is cut, never shortened
    assert lines[0] == "Very long driver name"           # words are not cut where they fit on a line of their own


def test_a_line_too_wide_is_shortened_with_an_ellipsis():
    text = "Loudspeaker-Fabrik Müller & Söhne GmbH " * 5
    short = shorten(text, 2.0, 7)
    assert short.endswith(ELLIPSIS) and width_in(short, 7) <= 2.0 and text.startswith(short[:-1])
    assert shorten("Acme W6", 2.0, 7) == "Acme W6"
