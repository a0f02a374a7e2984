"""The PDF report's layout (analysis.report.pdf): names of any length stay inside the page, and every page keeps
its number."""
import re
import subprocess

import pytest

from analysis.report import build_report, write_report
from tests.builders import needs_pdftotext, pdf_text

A4_WIDTH_PT = 8.27 * 72
EDGE_PT = 0.3 * 72          # the margins are wider: a word reaching into this strip ran over the margin


def _word_boxes(pdf) -> list[tuple[str, float, float]]:
    """(word, xMin, xMax) in points of every word pdftotext finds."""
    text = subprocess.run(["pdftotext", "-bbox", str(pdf), "-"], check=True, capture_output=True, text=True).stdout
    return [(w, float(x0), float(x1))
            for x0, x1, w in re.findall(r'<word xMin="([\d.]+)" yMin="[\d.]+" xMax="([\d.]+)" yMax="[\d.]+">([^<]*)'
                                        r"</word>", text)]


# A maker's name with spaces (191 characters) and one of wide capitals without a space to break at (420): the
# first cut the footer and its page number off the page, the second ran the title and the Driver row past the
# A4 edge (a line's width was guessed from its number of characters).
SPACED = " ".join(["Loudspeaker-Fabrik Müller & Söhne GmbH Prototyp"] * 4)
LONG = "Very long driver name " + "X" * 398


@needs_pdftotext
@pytest.mark.parametrize("driver", [SPACED, LONG], ids=["spaced", "long"])
def test_a_long_name_stays_inside_the_page_and_every_page_keeps_its_number(stored, tmp_path, driver):
    pdf = tmp_path / "r.pdf"
    write_report(build_report(stored, {"driver": driver, "serial": "SN-1"}), pdf=pdf)
    pages = pdf_text(pdf).split("\f")[:-1]
    for n, page in enumerate(pages, 1):
        assert f"page {n} of {len(pages)}" in page
    outside = [(w, x0, x1) for w, x0, x1 in _word_boxes(pdf) if x0 < EDGE_PT or x1 > A4_WIDTH_PT - EDGE_PT]
    assert outside == []
    # The whole name is still there, wrapped, in the title and the Driver row: only the footer shortens it.
    head = "".join(pages[0].split("Serial number")[0].split()).replace("Driver", "", 1)
    assert head.count("".join(driver.split())) == 2


@needs_pdftotext
def test_a_name_the_fonts_cannot_draw_gives_no_warning_and_says_once_where_it_is_whole(stored, tmp_path):
    """A name ending in 日本語 printed matplotlib's "Glyph 26085 missing from font(s) DejaVu Sans" three times on
    the terminal and drew empty boxes."""
    import warnings
    from analysis.report import render_html
    driver = "Lautsprecher — 日本語 \N{EGYPTIAN HIEROGLYPH A001}"
    content = build_report(stored, {"driver": driver})
    pdf = tmp_path / "r.pdf"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_report(content, pdf=pdf)
    from analysis.report.fonts import FALLBACK_FAMILIES, STAND_IN, families
    text = pdf_text(pdf)
    cjk = "日本語" if set(families()) & set(FALLBACK_FAMILIES) else STAND_IN * 3
    assert f"Lautsprecher — {cjk} {STAND_IN}" in text
    assert text.count("stands for a character the fonts of this PDF cannot draw") == 1
    assert driver in render_html(content)           # where the note says the name is whole


@needs_pdftotext
def test_a_parameter_the_data_do_not_determine_reads_so_with_one_line_under_the_table(stored, undetermined_qms,
                                                                                     tmp_path):
    pdf = tmp_path / "r.pdf"
    write_report(build_report(undetermined_qms, {}), pdf=pdf)
    customer = pdf_text(pdf).split("Appendix")[0]
    assert re.search(r"^\s*Qms\s+not determined\s+[\d.]+\s+400 %", customer, re.M)
    from analysis.report.numbers import NOT_DETERMINED_NOTE
    table = customer.split("Parameters")[1].split("Model")[0]
    assert table.count("not determined") == 2 and " ".join(NOT_DETERMINED_NOTE.split()) in " ".join(table.split())
    assert re.search(r"^\s*Qts\s+\d", customer, re.M)          # the others are numbers, and no note for them
    plain = tmp_path / "plain.pdf"
    write_report(build_report(stored, {}), pdf=plain)
    assert "not determined" not in pdf_text(plain)


@needs_pdftotext
def test_a_name_with_dollar_signs_is_printed_as_typed_not_typeset_as_a_formula(stored, tmp_path):
    """matplotlib reads text between two "$" as mathtext: "W$x^2$" would be drawn as W and x squared."""
    pdf = tmp_path / "r.pdf"
    write_report(build_report(stored, {"driver": "W$x^2$ woofer", "serial": "SN$1$"}), pdf=pdf)
    rows = {line.split()[0]: " ".join(line.split()[1:]) for line in pdf_text(pdf).splitlines() if line.strip()}
    assert rows["Driver"] == "W$x^2$ woofer" and rows["Serial"] == "number SN$1$"
