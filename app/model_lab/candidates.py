"""The diagnosis in the model lab: ranked candidates, the explanation of the selected one, and the
buttons that start a diagnosis, apply a candidate and follow the greedy path."""
from __future__ import annotations

import html
import math
from collections.abc import Iterator

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QFont
from PySide6.QtWidgets import (QAbstractItemView, QHBoxLayout, QHeaderView, QLabel, QPushButton, QTableWidget,
                               QTableWidgetItem, QTextBrowser, QVBoxLayout, QWidget)

from analysis.diagnosis import acceptance
from analysis.diagnosis.words import VERDICT_TITLES
from app.jobs.lab_outcome import CandidateRow, DiagnosisOutcome
from app.model_lab.catalogue import category_title
from app.widgets.column_widths import fit_to_contents, sized_when_filled

# The reduced chi^2 per channel is in the Fit cell's tooltip, the category in the Effect cell's: the columns must
# fit a 1280 px screen, where a Category column took the width and cut the effects' titles to a word ("Vented …"
# twice, for two different boxes).
COLUMNS = ("#", "Action", "Effect", "Fit", "Acceptable")
RANK, ACTION, EFFECT, DELTA_BIC, JUDGED = range(len(COLUMNS))
SIZED_COLUMNS = (RANK, ACTION, DELTA_BIC, JUDGED)      # as wide as their contents
# The word scale of a BIC change (Kass and Raftery's grades of evidence), the best grade first.
FIT_WORDS = ((-10.0, "fits far better"), (-6.0, "fits better"), (-2.0, "slightly better"), (2.0, "no better"))
WORSE = "fits worse"
BAR_CELLS = 8
CHANNEL_SHORT = {"impedance": "Z", "displacement": "Hx"}
NO_DIAGNOSIS = ("Diagnose tries every effect one move away from the current model (add one of a new category, "
                "or swap one for an alternative), refits each and ranks them by how much they lower BIC. An effect "
                "is taken only when it also explains the misfit it removes; when none does, the diagnosis says "
                "where the physics is missing.")
JUDGEMENT_WORDS = {acceptance.ACCEPTED: "yes", acceptance.FLAGGED: "no: flagged", acceptance.NO_GAIN: "no: no gain",
                   acceptance.MISFIT_LEFT: "no: misfit left", acceptance.FAILED: "refit failed"}
JUDGEMENT_TIPS = {
    acceptance.ACCEPTED: "it pays for its parameters and explains the misfit it removes; the greedy path takes "
                         "the best of these",
    acceptance.FLAGGED: "a parameter ended on a bound, outside its typical range or undetermined, or a channel "
                        "got worse",
    acceptance.NO_GAIN: "it does not lower the misfit enough to pay for its parameters",
    acceptance.MISFIT_LEFT: "it removes only part of what a smooth correction at its site removes: it absorbs a "
                            "misfit it does not explain",
}
APPLY_TIP = "Adopt the selected candidate: its fit is already computed"
APPLY_REFUSED_TIP = ("The diagnosis would not take the selected candidate ({why}). To try it anyway, check its "
                     "effect in the catalogue: that refits the model with it.")
VERDICT_COLOURS = {acceptance.NOTHING_MISSING: "#2e7d32", acceptance.EXPLAINED: "#2e7d32",
                   acceptance.PARTLY_EXPLAINED: "#b26a00", acceptance.UNEXPLAINED: "#8e1b1b"}


def bic_text(delta_bic: float) -> str:
    return f"{delta_bic:+.4g}" if math.isfinite(delta_bic) else "failed"


def fit_words(delta_bic: float) -> str:
    """How much better a candidate fits, in words: 'fits far better' … 'fits worse'."""
    if not math.isfinite(delta_bic):
        return "refit failed"
    return next((words for limit, words in FIT_WORDS if delta_bic <= limit), WORSE)


def fit_bar(delta_bic: float, best_gain: float) -> str:
    """A bar of BAR_CELLS cells, as long as the candidate's gain on a log scale relative to the best one's."""
    gain = -delta_bic if math.isfinite(delta_bic) else 0.0
    if gain <= 2.0 or best_gain <= 2.0:
        return "▱" * BAR_CELLS
    filled = max(1, round(BAR_CELLS * math.log10(gain) / math.log10(best_gain)))
    return "▰" * filled + "▱" * (BAR_CELLS - filled)


def effect_text(row: CandidateRow) -> str:
    """The Effect cell: the move's ids first, which tell any two candidates apart and are short enough to be read
    whole at 1280 px, then the titles, which the cell cuts where its width ends."""
    if row.replaces is not None:
        return f"{row.effect.id} for {row.replaces.id} · {row.effect.title} for {row.replaces.title}"
    if row.partner is not None:
        return f"{row.effect.id} + {row.partner.id} · {row.effect.title} with {row.partner.title}"
    return f"{row.effect.id} · {row.effect.title}"


def effect_tooltip(row: CandidateRow) -> str:
    """The Effect cell's text whole, one effect a line, with its category."""
    effects = [row.effect] + [e for e in (row.partner,) if e is not None]
    lines = [f"{e.title} (id {e.id}): {category_title(e.category)}" for e in effects]
    if row.replaces is not None:
        lines.append(f"in place of {row.replaces.title} (id {row.replaces.id})")
    return "\n".join(lines)


def fit_tooltip(row: CandidateRow) -> str:
    if not math.isfinite(row.delta_bic) or row.fitted is None:
        return "The refit of this candidate failed" + (f": {row.error}" if row.error else ".")
    chi2 = ", ".join(f"{CHANNEL_SHORT.get(k, k)} {v:.3g}" for k, v in row.chi2_red.items())
    return (f"{fit_words(row.delta_bic).capitalize()} than the current model, once its extra parameters are "
            "paid for.\n"
            f"Details: the Bayesian information criterion changes by {bic_text(row.delta_bic)} "
            "(below -10: far better; -6 to -10: better; -2 to -6: slightly; above -2: no better); "
            f"reduced χ² with it: {chi2} (1 is the noise floor).")

class CandidatesPanel(QWidget):
    selected_changed = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.rows: tuple[CandidateRow, ...] = ()
        self.stale = False
        self._heading = "<b>Diagnosis</b>"

        self.diagnose_button = QPushButton("Diagnose")
        self.diagnose_button.setToolTip("Refit every candidate one move away from the current model and rank them "
                                        "by how much better they fit (in the background, on every core)")
        self.apply_button = QPushButton("Apply")
        self.apply_button.setToolTip(APPLY_TIP)
        self.follow_button = QPushButton("Follow the greedy path")
        self.follow_button.setToolTip("Take the best candidate that explains the misfit it removes, again and "
                                      "again, then stop; every step becomes a version")
        buttons = QHBoxLayout()
        buttons.setContentsMargins(0, 0, 0, 0)
        for button in (self.diagnose_button, self.apply_button, self.follow_button):
            buttons.addWidget(button)
        buttons.addStretch(1)
        self.title = QLabel("<b>Diagnosis</b>")
        self.title.setTextFormat(Qt.RichText)
        self.title.setWordWrap(True)
        self.verdict = QLabel()
        self.verdict.setTextFormat(Qt.RichText)
        self.verdict.setWordWrap(True)
        self.verdict.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.verdict.hide()

        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.table.setAlternatingRowColors(True)
        self.table.verticalHeader().setVisible(False)
        self.table.verticalHeader().setDefaultSectionSize(self.fontMetrics().height() + 6)
        # The move's ids and titles take what is left, the titles cut at its end (whole in the tooltip).
        self.table.horizontalHeader().setSectionResizeMode(EFFECT, QHeaderView.Stretch)
        sized_when_filled(self.table, SIZED_COLUMNS)       # measured when filled, not at each show of the lab
        fit_to_contents(self.table, SIZED_COLUMNS)
        self.table.setTextElideMode(Qt.ElideRight)
        self.table.setWordWrap(False)
        self.table.itemSelectionChanged.connect(self.on_selection_changed)

        self.explanation = QTextBrowser()
        self.explanation.setMinimumHeight(60)
        self.explanation.setHtml(f"<p>{html.escape(NO_DIAGNOSIS)}</p>")

        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(buttons)
        layout.addWidget(self.verdict)
        layout.addWidget(self.title)
        layout.addWidget(self.table, 3)
        layout.addWidget(self.explanation, 2)

    def set_outcome(self, outcome: DiagnosisOutcome | None, version: int = 0, effects: str = "") -> None:
        """Show the candidates of a diagnosis of version `version` (None: no diagnosis yet)."""
        for _ in self.setting_outcome(outcome, version, effects):
            pass

    def setting_outcome(self, outcome: DiagnosisOutcome | None, version: int = 0,
                        effects: str = "") -> Iterator[None]:
        """set_outcome in two steps, for a caller that runs them in turns of their own: the table and the words,
        then the candidate the diagnosis would take selected (its explanation, and the lab's catalogue entry)."""
        self.stale = False
        self.table.clearSelection()
        self.rows = outcome.candidates if outcome is not None else ()
        chosen = outcome.chosen if outcome is not None else None
        # Emptied first, then filled: every row is new. The columns are measured once, when filled (a column
        # sized to its contents by Qt measured every row again at each item put in: 135 ms of the GUI thread for
        # a second diagnosis's 24 rows).
        self.table.setRowCount(0)
        self.table.setRowCount(len(self.rows))
        gains = [-row.delta_bic for row in self.rows if math.isfinite(row.delta_bic)]
        best_gain = max(gains, default=0.0)
        for r, row in enumerate(self.rows):
            # Read across: "replace" + "<new id> for <old id> · <titles>" is the move.
            action = "replace" if row.replaces is not None else "add"
            cells = {RANK: str(r + 1), ACTION: action, EFFECT: effect_text(row),
                     DELTA_BIC: f"{fit_bar(row.delta_bic, best_gain)} {fit_words(row.delta_bic)}"}
            cells[JUDGED] = JUDGEMENT_WORDS.get(row.judgement, row.judgement)
            if row is chosen:
                cells[JUDGED] = "yes: the best"
            for column, text in cells.items():
                item = QTableWidgetItem(text)
                if column == RANK:
                    item.setTextAlignment(Qt.AlignRight | Qt.AlignVCenter)
                if column == EFFECT:
                    item.setToolTip(effect_tooltip(row))
                if column == ACTION and row.replaces is not None:
                    item.setToolTip(f"replaces {row.replaces.title} (id {row.replaces.id})")
                if column == DELTA_BIC:
                    item.setToolTip(fit_tooltip(row))
                if column == JUDGED:
                    item.setToolTip(JUDGEMENT_TIPS.get(row.judgement, ""))
                if row.accepted and column in (DELTA_BIC, JUDGED):
                    font = QFont()
                    font.setBold(True)     # the acceptance rule would take it
                    item.setFont(font)
                self.table.setItem(r, column, item)
        fit_to_contents(self.table, SIZED_COLUMNS)
        if outcome is None:
            self._heading = "<b>Diagnosis</b>"
            self.title.setText(self._heading)
            self.verdict.hide()
            self.explanation.setHtml(f"<p>{html.escape(NO_DIAGNOSIS)}</p>")
        else:
            self._heading = f"<b>Diagnosis</b> of version {version} ({html.escape(effects)})"
            self.title.setText(f"{self._heading}: {len(self.rows)} candidates, best first")
            self.show_verdict(outcome)
            chosen = next((i for i, row in enumerate(self.rows) if row.accepted), None)
            # None would be taken, or a greedy path took them and these are what it refused: the verdict
            # instead of a candidate offered first.
            if chosen is None or outcome.path:
                self.explanation.setHtml(f"<p>{html.escape(outcome.verdict_text)}</p>" if outcome.verdict_text
                                         else "<p>No candidate was ranked from this model: Diagnose to rank "
                                              "from it.</p>")
        self.table.setCurrentItem(None)       # no current cell either: a key press must not select one
        if outcome is not None and not outcome.path and chosen is not None:
            yield
            self.table.selectRow(chosen)      # tells selected_changed
        else:
            self.selected_changed.emit()

    def show_verdict(self, outcome: DiagnosisOutcome) -> None:
        if not outcome.verdict:
            self.verdict.hide()
            return
        colour = VERDICT_COLOURS.get(outcome.verdict, "#333")
        # One short sentence here; the whole verdict (where, the site, what next) below and in the tooltip.
        self.verdict.setText(f"<span style='color:{colour}'><b>{html.escape(VERDICT_TITLES[outcome.verdict])}"
                             f"</b></span> · {html.escape(outcome.verdict_headline)}")
        self.verdict.setToolTip(outcome.verdict_text)
        self.verdict.show()

    def mark_stale(self, version: int) -> None:
        """The model changed since the diagnosis: its candidates are one move from an older version."""
        if not self.rows:
            return
        self.title.setText(f"{self._heading}: the model is now version {version}; Diagnose again to rank "
                           f"from it")        # the newest version, at each one added
        if not self.stale:
            self.stale = True
            self.selected_changed.emit()

    def selected(self) -> CandidateRow | None:
        rows = self.table.selectionModel().selectedRows()
        if not rows or rows[0].row() >= len(self.rows):
            return None
        return self.rows[rows[0].row()]

    def apply_refusal(self) -> str:
        """Why Apply is off for the selected candidate ('' when it is on offer)."""
        row = self.selected()
        if row is None or row.accepted:
            return ""
        return APPLY_REFUSED_TIP.format(why=JUDGEMENT_WORDS.get(row.judgement, row.judgement))

    def select(self, index: int) -> None:
        self.table.selectRow(index)

    def on_selection_changed(self) -> None:
        row = self.selected()
        if row is not None:
            flags = "".join(f"<li>{html.escape(f.message)}</li>" for f in row.flags)
            self.explanation.setHtml(f"<p><b>{html.escape(row.move)}</b> ({html.escape(row.effect.title)}): "
                                     f"{html.escape(fit_words(row.delta_bic))}. {html.escape(row.explanation)}</p>"
                                     + (f"<p>Flags:</p><ul>{flags}</ul>" if flags else ""))
        self.selected_changed.emit()
