"""The Model lab's catalogue, reduced-chi^2 chart, candidates and header at the sizes they have on a 1280x720
screen: the effects' titles take the room left without a horizontal scroll bar (cut with "…", whole in the
tooltip), the channels' names never lie over the noise floor's label, the candidates' ids are read whole, and the
header's words are not cut."""
from __future__ import annotations

import dataclasses

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication, QStyle

from analysis.diagnosis.candidates import candidate_models
from analysis.diagnosis.refit_words import refit_text
from analysis.effects import get_effect, parse_effects
from analysis.fit.least_squares import fit_model
from analysis.model import Model
from app.jobs.lab_outcome import CandidateRow, DiagnosisOutcome, lab_fit
from app.model_lab.candidates import EFFECT, CandidatesPanel
from app.model_lab.catalogue import EffectCatalogue
from app.model_lab.plots import CHANNEL_SHORT, ChartPoint, ChiSquareChart
from app.model_lab.versions import move_text
from tests.app.conftest import open_and_wait

# What the lab gives them in a 1280x720 window (docs/screenshots/model-lab-*-1280x720.png).
CATALOGUE_SIZE, CHART_SIZE, CANDIDATES_SIZE = (270, 560), (365, 230), (617, 250)


def test_the_catalogues_titles_fit_beside_the_ids_without_a_scroll_bar(qtbot):
    catalogue = EffectCatalogue()
    qtbot.addWidget(catalogue)
    catalogue.resize(*CATALOGUE_SIZE)
    catalogue.show()
    QApplication.processEvents()
    tree = catalogue.tree
    assert not tree.horizontalScrollBar().isVisible()
    assert tree.columnWidth(0) + tree.columnWidth(1) <= tree.viewport().width()
    item = catalogue.item("lr2")
    title = item.text(1)
    # Too long for its column, so cut on screen; whole where the user points.
    assert tree.fontMetrics().horizontalAdvance(title) > tree.columnWidth(1)
    assert title in item.toolTip(1)


@pytest.mark.parametrize("last", [1.0, 3.0, 0.8, 40.0])
def test_the_chi2_charts_channel_names_never_cover_the_noise_floors_label(qtbot, last):
    chart = ChiSquareChart()
    qtbot.addWidget(chart)
    chart.resize(*CHART_SIZE)
    chart.show()
    chart.set_points([ChartPoint(1, "lr2, creep-log", "as fitted", {"impedance": 200.0, "displacement": 900.0}),
                      ChartPoint(2, "lr2, creep-log, rms", "added", {"impedance": last, "displacement": last})])
    QApplication.processEvents()
    floor = chart.floor.label.sceneBoundingRect()
    legend = chart.plot.legend
    assert legend is None or not legend.sceneBoundingRect().intersects(floor)
    title = chart.plot.titleLabel.text
    assert all(name in title for name in CHANNEL_SHORT.values())       # the colours are said in the title


def _every_move_from(effect_ids: str) -> tuple[CandidateRow, ...]:
    """A row for every move one step from `effect_ids` (as a diagnosis ranks them), and a pair of two effects."""
    rows = [CandidateRow(str(action), effect, replaced, -100.0 - i, "", None)
            for i, (action, effect, replaced, _) in enumerate(candidate_models(Model(parse_effects(effect_ids))))]
    return (*rows, CandidateRow("add", get_effect("breakup"), None, -1.0, "", None, partner=get_effect("breakup-spot")))


def test_the_candidates_ids_are_read_whole_and_no_two_rows_look_alike(qtbot):
    """The effect's title alone, beside a Category column, was cut to a word: "Vented …" for two different boxes."""
    panel = CandidatesPanel()
    qtbot.addWidget(panel)
    panel.resize(*CANDIDATES_SIZE)
    panel.show()
    rows = _every_move_from("lr2,creep-log")
    panel.set_outcome(DiagnosisOutcome(None, rows, (), ""), 1, "lr2, creep-log")
    QApplication.processEvents()
    table = panel.table
    room = table.columnWidth(EFFECT) - 2 * (table.style().pixelMetric(QStyle.PM_FocusFrameHMargin) + 1)   # as the cell draws
    shown = [table.fontMetrics().elidedText(table.item(r, EFFECT).text(), Qt.ElideRight, room)
             for r in range(table.rowCount())]
    for row, text in zip(rows, shown):
        ids = row.effect.id + (f" + {row.partner.id}" if row.partner else "") + \
            (f" for {row.replaces.id}" if row.replaces else "")
        assert text.startswith(ids), (text, ids)
    assert len(set(shown)) == len(shown)
    assert not table.horizontalScrollBar().isVisible()


def test_in_a_1280x720_window_the_labs_header_says_its_words_whole(qtbot, window, recordings):
    """Its labels keep HEADER_LINES lines (so that refits do not move the plots); the status beside the job controls
    lost the first and the last line of a refit's words (the last its advice), the model's its fit's headline."""
    window.resize(1280, 720)
    open_and_wait(qtbot, window, recordings["paper"])
    lab = window.model_lab
    window.pages.setCurrentWidget(lab)
    qtbot.waitUntil(lambda: lab.current is not None and not window.result_pages.pending)
    # The longest a version's words run to: four effects, one of them swapped in from a diagnosis, and a misfit
    # far from the noise on both channels.
    before = fit_model(lab.data, Model(parse_effects("lr3,creep-log,bl-eddy,lowpass2-x")))
    after = fit_model(lab.data, Model(parse_effects("lr3,creep-rs,bl-eddy,lowpass2-x")), start=before.values)
    how = f"{move_text(before.model, after.model)} from the diagnosis of version 4"
    lab._add_version(lab_fit(lab.base, after), how)
    # A refit's words with a parameter on its bound: the chi^2 change, the bound, what to try.
    fitted = lab.versions[0].fitted.fit
    spec = next(s for s in fitted.model.param_specs if s.name == "lambda")
    on_bound = dataclasses.replace(fitted, values={**fitted.values, "lambda": spec.max})
    lab.status_label.setText(refit_text(fitted, on_bound))
    assert "Try widening that bound" in lab.status_label.text()
    QApplication.processEvents()
    for label in (lab.model_label, lab.status_label):
        assert label.heightForWidth(label.width()) <= label.height(), label.text()
    # Both problems at once: the misfit rose, and a parameter on its bound (they ran past four lines).
    both = dataclasses.replace(on_bound, chi2=fitted.chi2 * 10)
    lab.status_label.setText(refit_text(fitted, both))
    assert "The misfit rose" in lab.status_label.text() and "Try widening that bound" in lab.status_label.text()
    QApplication.processEvents()
    assert lab.status_label.heightForWidth(lab.status_label.width()) <= lab.status_label.height()
