"""The PDF report's fonts (analysis.report.fonts): a fallback font where one is installed, a visible stand-in for
what no font has."""
from analysis.report.fonts import FALLBACK_FAMILIES, STAND_IN, advance, draws, drawable, families

HIEROGLYPH = "\N{EGYPTIAN HIEROGLYPH A001}"        # in no font of the report's, installed or not


def test_a_character_no_font_has_is_written_as_the_stand_in_and_measured_as_it():
    assert drawable(f"Acme Ü — W6 {HIEROGLYPH}") == f"Acme Ü — W6 {STAND_IN}"
    assert draws(STAND_IN) and advance(HIEROGLYPH) == advance(STAND_IN) > 0


def test_cjk_is_drawn_by_an_installed_fallback_font_else_stood_in_for():
    fallback = set(families()) & set(FALLBACK_FAMILIES)
    assert drawable("日本語") == ("日本語" if fallback else STAND_IN * 3)
    assert families()[0] == "DejaVu Sans"          # the report's own font comes first: Latin text looks the same
