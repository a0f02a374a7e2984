"""The QA page on imported curves (File > Open curves…): it says what applies to a file, not to a recording (no
signal, noise or distortion checks ran: the curves are judged by their fit), and its NOT JUDGED advice looks at
the file, not at the wiring (app/qa/imported_words.py, analysis.validity.fit.CURVES_MISFIT_REMEDY)."""
from __future__ import annotations

import dataclasses
import html

import pytest

from app.jobs.curves import CurvesRequest, analyse_curves
from app.qa import imported_words
from app.qa.view import QAView
from tests.app.conftest import analysis_wait_ms
from tests.builders import REAL_DATA, QuietJob
from tests.uiv_files import write_uiv_and_zma

SEAS = REAL_DATA / "seas_l16rnx" / "L16RNX_0g_242_27mV.zma"
RECORDING_WORDS = ("not checked yet", "have not run on this measurement", "wiring", "channels' findings",
                   "Model lab")


@pytest.fixture(scope="module")
def curves(tmp_path_factory):
    """The paper driver's .zma, fitted as File > Open curves… fits it."""
    _, zma = write_uiv_and_zma(tmp_path_factory.mktemp("zma"))
    return analyse_curves(QuietJob(), CurvesRequest(zma))


def _page_text(page: QAView) -> str:
    return html.unescape(page.overall_text.text() + " " + page.verdict_label.text())


def _says_nothing_of_recordings(text: str) -> None:
    for words in RECORDING_WORDS:
        assert words not in text


def test_imported_curves_are_said_to_be_judged_by_their_fit(qtbot, settings, curves):
    page = QAView(settings.qsettings)
    qtbot.addWidget(page)
    page.set_result(curves)
    text = _page_text(page)
    assert imported_words.HEADLINE in text and "judged by their fit" in text
    assert imported_words.NO_LIMITS in text and page.verdict == "none"
    _says_nothing_of_recordings(text)
    # No voltage, current or displacement lights "not measured": one line saying why there are none.
    assert not any(light.isVisibleTo(page) for light in page.channels.values())
    assert page.no_channels.isVisibleTo(page)


def test_imported_curves_the_model_misses_are_not_judged_with_advice_on_the_file(qtbot, settings, curves):
    missed = dataclasses.replace(curves, validity=curves.validity.replace(fit_error_percent={"impedance": 12.0}))
    page = QAView(settings.qsettings)
    qtbot.addWidget(page)
    page.set_result(missed)
    text = _page_text(page)
    assert page.verdict == "not judged"
    assert "does not describe these curves: it misses the impedance by 12 % rms" in text
    assert "'linpar diagnose' on the same files" in text and "check what the file holds" in text
    _says_nothing_of_recordings(text)


@pytest.mark.skipif(not SEAS.exists(), reason=f"the SEAS L16RNX curves are kept outside the repository and "
                                                f"missing here: {SEAS}")
def test_a_real_zma_on_the_qa_page_of_the_window(qtbot, window):
    with qtbot.waitSignal(window.model_part_shown, timeout=analysis_wait_ms(4)):
        window.open_curves(CurvesRequest(SEAS))
    text = _page_text(window.qa)
    assert imported_words.HEADLINE in text
    _says_nothing_of_recordings(text)
