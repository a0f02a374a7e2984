"""Job controls: what the job says never changes the height of its row (it would resize every plot below)."""
from __future__ import annotations

from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from app.jobs.book import JobRunner
from app.jobs.controls import JobControls

LONG = ("Trying every effect on lumped + lr2 + creep-log + delay-x, one move away, refitting each of them in "
        "the background; then looking for the site of the misfit left")


def test_a_text_that_wraps_differently_keeps_the_row_and_the_page_below_in_place(qapp, qtbot):
    page = QWidget()
    runner = JobRunner(page)
    controls = JobControls(runner, bar_width=120)
    below = QLabel("a plot")
    layout = QVBoxLayout(page)
    layout.addWidget(controls)
    layout.addWidget(below, 1)
    qtbot.addWidget(page)
    page.resize(420, 300)
    page.show()
    qtbot.waitExposed(page)

    heights, tops = [], []
    for text in ("", "Fitting", LONG, "Looking for the site of the misfit left", ""):
        controls.text.setText(text)
        page.layout().activate()
        heights.append(controls.height())
        tops.append(below.geometry().top())
    assert len(set(heights)) == 1 and len(set(tops)) == 1, (heights, tops)
    # The long text really needs more than the row shows: without the fixed height the row would have grown.
    free = QLabel(LONG)
    free.setWordWrap(True)
    assert free.heightForWidth(controls.text.width()) > controls.text.height()


def test_the_whole_text_is_the_tooltip(qapp, qtbot):
    runner = JobRunner()
    controls = JobControls(runner)
    qtbot.addWidget(controls)
    controls._say(LONG)
    assert controls.text.toolTip() == LONG
