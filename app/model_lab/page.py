"""The Model lab page: add, remove or swap effects, refit in the background, diagnose, and watch
reduced chi^2 fall towards the noise floor version after version.

The lab starts from the model the Results page fitted and keeps its own
history of versions. Every refit starts from the current version's values and
from the model's own start values, as `linpar analyze --model` does
(analysis.diagnosis.refit); a diagnosis ranks every model one move away (analysis.diagnosis.candidates) and
its candidates can be adopted without a refit, their fits being computed
already. The current version is handed back to the Results page
(model_adopted), so that both pages show the same model.
"""
from __future__ import annotations

import html
from collections.abc import Iterator
from pathlib import Path

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import QHBoxLayout, QLabel, QSplitter, QStackedWidget, QTabWidget, QVBoxLayout, QWidget

from analysis.diagnosis import acceptance
from analysis.errors import LinparError
from analysis.fit.least_squares import FitData
from analysis.fit.words import fit_headline
from analysis.pipeline import AnalysisResult
from analysis.diagnosis.refit_words import refit_text
from app.jobs.controls import JobControls
from app.jobs.lab_outcome import DiagnosisOutcome, LabFit, first_version
from app.jobs.lab_worker import LabWorker
from app.jobs.next_turn import in_turns
from app.model_lab.candidates import APPLY_TIP, CandidatesPanel, fit_words
from app.model_lab.catalogue import EffectCatalogue
from app.model_lab.plots import ChartPoint, ChiSquareChart, ResidualPanel
from app.model_lab.sites import SitePanel
from app.model_lab.session import LabSession
from app.model_lab.versions import LabVersion, changed_model, move_text
from app.results.parameter_table import titled_parameter_table
from app.widgets.layout_room import LinesLabel
from app.jobs.workers import AnalysisOutcome

HEADER_LINES = 4        # the version and how it came (one or two lines), its fit's headline (one or two)
EMPTY_TEXT = ("No model yet.\n\nOpen a recording (File ▸ Open recording…): the lab starts from the model the "
              "Results page fits, and from there you add, remove or swap effects.")


class ModelLab(QWidget):
    version_added = Signal(object)      # LabVersion, after the page shows it
    diagnosis_shown = Signal(object)    # DiagnosisOutcome, after the table shows it
    job_failed = Signal(str)            # the message shown
    job_cancelled = Signal()
    model_adopted = Signal(object)      # AnalysisOutcome of a new current model, for the Results page

    def __init__(self, parent=None):
        super().__init__(parent)
        self.worker = LabWorker(self)
        self.session = LabSession()                 # the recording, the versions, the diagnosis (no Qt)
        self.new_effect_dialog = None               # the "New effect…" dialog while it is open
        self._in_turns = None                       # the steps left of a version shown in turns (a refit's)
        self._diagnosis_turns = None                # the steps left of a diagnosis shown in turns

        self.empty = QLabel(EMPTY_TEXT)
        self.empty.setAlignment(Qt.AlignCenter)
        self.empty.setWordWrap(True)

        # The header's texts keep HEADER_LINES lines whatever they say (LinesLabel): its height changing with a
        # refit's words resized the chart and the residual plots below it.
        self.model_label = LinesLabel(HEADER_LINES, whole_in_tooltip=False)     # its tooltip: the fit's report
        self.model_label.setTextFormat(Qt.RichText)
        self.model_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        # What the last job did, with what to try (a refit's words run to five sentences): its first line at the top,
        # a text too long cut at the bottom (whole in its tooltip).
        self.status_label = LinesLabel(HEADER_LINES)
        # The refit or diagnosis running: what it does, a busy indicator and Cancel.
        self.jobs = JobControls(self.worker, cancel_tip="Stop the refit or diagnosis; the current version stays",
                                bar_width=120)
        self.jobs.busy_changed.connect(self._on_busy_changed)
        # The two share one place: a job empties the status as it starts, and the job controls are empty between
        # jobs. Side by side, each had half the room, and at 1280 px a refit's advice was cut.
        self.status_stack = QStackedWidget()
        self.status_stack.addWidget(self.status_label)
        self.status_stack.addWidget(self.jobs)
        header = QHBoxLayout()
        header.addWidget(self.model_label, 3)
        header.addWidget(self.status_stack, 2)

        self.catalogue = EffectCatalogue()
        self.residual_panel = ResidualPanel()
        self.candidates = CandidatesPanel()
        self.chart = ChiSquareChart()
        self.site_panel = SitePanel()
        self.views = QTabWidget()          # reduced chi^2 by version, or where the physics is missing
        self.views.addTab(self.chart, "Reduced χ²")
        self.views.addTab(self.site_panel, "Missing physics")
        table_box, self.parameter_table = titled_parameter_table("<b>Parameters</b> of the current version (bold: fitted)")

        middle = QSplitter(Qt.Vertical)
        middle.addWidget(self.residual_panel)
        middle.addWidget(self.candidates)
        middle.setSizes([440, 360])
        right = QSplitter(Qt.Vertical)
        right.addWidget(self.views)
        right.addWidget(table_box)
        right.setSizes([420, 380])
        splitter = QSplitter(Qt.Horizontal)
        splitter.addWidget(self.catalogue)
        splitter.addWidget(middle)
        splitter.addWidget(right)
        # Every column gives and takes space in proportion: on a 1280 px screen the middle one, with the
        # residual plots and the candidates, would otherwise be squeezed to what the sides leave.
        for index, stretch in enumerate((2, 5, 3)):
            splitter.setStretchFactor(index, stretch)
        splitter.setSizes([280, 640, 380])
        self.splitter = splitter

        content = QWidget()
        content_layout = QVBoxLayout(content)
        content_layout.setContentsMargins(0, 0, 0, 0)
        content_layout.addLayout(header)
        content_layout.addWidget(splitter, 1)
        self.content = content
        self.stack = QStackedWidget()
        self.stack.addWidget(self.empty)
        self.stack.addWidget(content)
        layout = QVBoxLayout(self)
        layout.addWidget(self.stack)

        self.catalogue.selection_changed.connect(self.on_selection_changed)
        self.catalogue.new_effect_requested.connect(self.on_new_effect)
        self.candidates.diagnose_button.clicked.connect(self.on_diagnose)
        self.candidates.apply_button.clicked.connect(self.on_apply)
        self.candidates.follow_button.clicked.connect(self.on_follow)
        self.candidates.selected_changed.connect(self.on_candidate_selected)
        self._update_buttons()

    # -- state (the session's) ----------------------------------------------
    @property
    def base(self) -> AnalysisResult | None:
        return self.session.base

    @property
    def data(self) -> FitData | None:
        return self.session.data

    @property
    def versions(self) -> list[LabVersion]:
        return self.session.versions

    @property
    def diagnosis(self) -> DiagnosisOutcome | None:
        return self.session.diagnosis

    @property
    def current(self) -> LabVersion | None:
        return self.session.current

    @property
    def busy(self) -> bool:
        return self.jobs.busy

    @Slot(object)
    def set_result(self, result: AnalysisResult) -> None:
        """A result from the Results page: a new recording restarts the lab from its model."""
        for _ in self.setting_result(result):
            pass

    def setting_result(self, result: AnalysisResult) -> Iterator[None]:
        """set_result in steps, each up to a `yield` (the main window's StagedFanOut runs each in a turn of its own:
        the whole set-up held the GUI thread 30-40 ms of CPU). Done once the generator is exhausted."""
        if not hasattr(result, "spectra"):      # imported curves (File > Open curves…): no recording to model
            self.jobs.drop()
            self.empty.setText("The Model lab works on recordings; imported curves are analysed on the Results page "
                               "(and by `linpar diagnose --impedance`).")
            self.stack.setCurrentWidget(self.empty)
            return
        if self.session.is_same_recording(result):
            # The same recording: the Results page shows one of our versions, or Sd was edited.
            if self.session.set_sd(result.sd_m2):
                self._show_parameters()
            return
        self.jobs.drop()
        self._in_turns = self._diagnosis_turns = None       # the steps left of a version, a diagnosis of the old one
        self.session.restart(result)
        if result.fit is None:          # a broken measurement: nothing the lab could start from
            self.empty.setText(f"Nothing to model: {result.not_fitted}")
            self.stack.setCurrentWidget(self.empty)
            return
        self.candidates.set_outcome(None)
        self.site_panel.set_sites(())
        self.views.setCurrentWidget(self.chart)
        self.catalogue.set_displacement_available(result.fit.model.with_displacement)
        yield
        yield from self._showing_added(self.session.add(*first_version(result)), adopt=False, announce=True)
        self.status_label.setText("")
        self.stack.setCurrentWidget(self.content)

    def shutdown(self, wait_ms: int) -> bool:
        """Cancel the lab's work and wait for it; True when it stopped in time."""
        self.jobs.drop()
        return self.worker.shutdown(wait_ms)

    def _add_version(self, fitted: LabFit, how: str, adopt: bool = True, announce: bool = True) -> LabVersion:
        self._in_turns = None           # a version still being shown in turns is overtaken by this one
        version = self.session.add(fitted, how)
        for _ in self._showing_added(version, adopt, announce):
            pass
        return version

    def _add_version_in_turns(self, fitted: LabFit, how: str) -> None:
        """_add_version, each step of the page's update in a turn of its own (next_turn.in_turns): for a refit that a
        checkbox asked for. In one turn, the residual plots, the table and the chart, with the paints their scenes
        start at once (a QGraphicsView sends the window's pending paint when its scene has processed a change),
        held the GUI thread 50-80 ms of CPU. A newer version, shown in turns or at once, drops the steps left."""
        version = self.session.add(fitted, how)
        steps = self._in_turns = self._showing_added(version, adopt=True, announce=True)
        in_turns(self, steps, going_on=lambda: self._in_turns is steps)

    def _showing_added(self, version: LabVersion, adopt: bool, announce: bool) -> Iterator[None]:
        """The page's update for a new version, in steps (see _showing_current), then the diagnosis marked stale and
        the version announced (the Results page's first step runs in the announcing turn), each a step of its own."""
        yield from self._showing_current()
        if self.diagnosis is not None and not self.session.diagnosis_is_current:
            yield
            self.candidates.mark_stale(version.number)
            self.site_panel.mark_stale(version.number)
        yield
        if adopt and announce:
            result = version.fitted.result
            self.model_adopted.emit(AnalysisOutcome(version.number, result.source or Path(), result,
                                                    version.fitted.curves))
        if announce:
            self.version_added.emit(version)

    # -- showing -----------------------------------------------------------
    def _show_current(self) -> None:
        for _ in self._showing_current():
            pass

    def _showing_current(self) -> Iterator[None]:
        """_show_current in five steps (the header's words; each residual plot; the table; the chart), each with
        the paint it sets off 2-8 ms of the GUI thread's CPU (three steps held it 17-26 ms each)."""
        version = self.versions[-1]
        fit = version.fitted.fit
        # The effects by their ids, as the catalogue's checkboxes name them: by their titles, four effects took three
        # of the header's lines at 1280 px and cut the fit's headline below them.
        ids = ", ".join(fit.model.effect_ids) or "textbook"
        text = (f"<b>Version {version.number}</b>: {html.escape(ids)} "
                f"<span style='color:#555'>({html.escape(version.how)})</span><br>{html.escape(fit_headline(fit))}")
        self.model_label.setToolTip(f"<pre>{html.escape(fit.report())}</pre>")     # the numbers one look away
        if not fit.success:
            text += (f"<br><span style='color:#8e1b1b'><b>The fit did not converge</b>: "
                     f"{html.escape(fit.message)}</span>")
        self.model_label.setText(text)
        self.catalogue.set_checked(fit.model.effect_ids)
        yield
        yield from self.residual_panel.setting_fit(version.fitted.curves, version.fitted.residual)
        yield
        self._show_parameters()
        yield
        self.chart.set_points([ChartPoint(v.number, v.effects, v.how, v.fitted.fit.chi2_red_by_channel())
                               for v in self.versions])
        self._update_buttons()

    def _show_parameters(self) -> None:
        result = self.versions[-1].fitted.result
        descriptions = {spec.name: spec.description for spec in result.fit.model.param_specs}
        self.parameter_table.set_parameters(result.parameters, descriptions, result.sd_m2)

    def _on_busy_changed(self, busy: bool) -> None:
        self.status_stack.setCurrentWidget(self.jobs if busy else self.status_label)
        self._update_buttons()

    def _update_buttons(self) -> None:
        ready = self.current is not None and not self.busy
        self.candidates.diagnose_button.setEnabled(ready)
        self.candidates.follow_button.setEnabled(ready)
        row = self.candidates.selected()
        # Only a candidate the diagnosis would take is on offer; another one is the catalogue's checkbox away.
        refusal = self.candidates.apply_refusal()
        self.candidates.apply_button.setEnabled(ready and row is not None and row.fitted is not None
                                                and not self.candidates.stale and not refusal)
        self.candidates.apply_button.setToolTip(refusal or APPLY_TIP)

    # -- jobs --------------------------------------------------------------
    def showEvent(self, event) -> None:
        super().showEvent(event)
        if self.current is not None:
            self.worker.refits.start()      # the user came to refit: no process start in the first one's wait

    def _run(self, job, text: str, finished) -> None:
        self.status_label.setText("")           # the job controls say what is being done
        self.jobs.run(job, text, finished, self.on_failed, self.on_cancelled)

    @Slot(tuple)
    def on_selection_changed(self, checked: tuple) -> None:
        """A checkbox changed: refit the changed model from the current version (analysis.diagnosis.refit)."""
        if self.current is None:
            return
        current = self.current.fitted.fit.model
        try:
            model = changed_model(current, checked)
        except LinparError as exc:      # an effect this version does not know, two of one category
            self.catalogue.set_checked(current.effect_ids)
            self.status_label.setText(f"Cannot build that model: {exc}")
            return
        self.jobs.drop()         # a newer choice replaces a refit or diagnosis still running
        if model.effect_ids == current.effect_ids:
            return
        self._run(self.worker.refit(self.base, self.data, model, self.current.fitted.fit),
                  f"Refitting: {move_text(current, model)}…", self.on_refit_finished)

    @Slot()
    def on_new_effect(self) -> None:
        """The "New effect…" dialog, previewing on the current version; a saved effect joins the catalogue."""
        from app.model_lab.new_effect import NewEffectDialog
        dialog = NewEffectDialog(self.current.fitted.fit if self.current is not None else None, parent=self,
                                 site=self._diagnosed_site())
        dialog.saved.connect(self.on_effect_saved)
        self.new_effect_dialog = dialog
        dialog.open()

    def _diagnosed_site(self):
        """The site the diagnosis of the current version named first (None: no diagnosis, or no site needed)."""
        if not self.session.diagnosis_is_current:
            return None
        sites = self.diagnosis.sites
        return sites[0].site if sites and self.site_panel.shown_site else None

    @Slot(object)
    def on_effect_saved(self, effect) -> None:
        self.catalogue.refresh_user_effects()
        self.catalogue.show_effect(effect.id)
        self.status_label.setText(f"Saved {effect.id} to {effect.source}: check it under User effects to fit it; "
                                  "the diagnosis now tries it too")

    @Slot()
    def on_diagnose(self) -> None:
        if self.current is None or self.busy:
            return
        self._run(self.worker.diagnose(self.base, self.data, self.current.fitted.fit),
                  f"Diagnosing version {self.current.number}…", self.on_diagnosis_finished)

    @Slot()
    def on_follow(self) -> None:
        if self.current is None or self.busy:
            return
        taken = None
        if self.session.diagnosis_is_current:
            taken = self.diagnosis.chosen     # ranked already: the path goes on from the one it would take
        self._run(self.worker.diagnose(self.base, self.data, self.current.fitted.fit, follow=True, taken=taken),
                  f"Following the greedy path from version {self.current.number}…",
                  lambda outcome: self.on_diagnosis_finished(outcome, follow=True))

    @Slot()
    def on_apply(self) -> None:
        row = self.candidates.selected()
        if row is None or row.fitted is None or self.busy or self.candidates.stale or not row.accepted:
            return
        old = self.current
        self._add_version(row.fitted, f"{move_text(old.fitted.fit.model, row.fitted.fit.model)} "
                                      f"from the diagnosis of version {old.number}")
        self.status_label.setText(f"Applied: {move_text(old.fitted.fit.model, row.fitted.fit.model)} "
                                  f"({fit_words(row.delta_bic)})")

    @Slot()
    def on_candidate_selected(self) -> None:
        row = self.candidates.selected()
        if row is not None:
            self.catalogue.show_effect(row.effect.id)     # the whole catalogue entry of the candidate
        self._update_buttons()

    # -- the jobs' outcomes ------------------------------------------------
    def on_refit_finished(self, fitted: LabFit) -> None:
        old = self.current
        self.status_label.setText(refit_text(old.fitted.fit, fitted.fit))
        self._add_version_in_turns(fitted, move_text(old.fitted.fit.model, fitted.fit.model))

    def on_diagnosis_finished(self, outcome: DiagnosisOutcome, follow: bool = False) -> None:
        """The diagnosis shown in turns of the event loop (next_turn.in_turns): its versions and the table of
        candidates, the candidate it would take selected, then the sites and the words. In one turn they held the
        GUI thread 13-20 ms of CPU, and the paint they set off as much again. A new recording, or a newer
        diagnosis, drops the steps left."""
        steps = self._diagnosis_turns = self._showing_diagnosis(outcome, follow)
        in_turns(self, steps, going_on=lambda: self._diagnosis_turns is steps)

    def _showing_diagnosis(self, outcome: DiagnosisOutcome, follow: bool) -> Iterator[None]:
        start = self.current.number
        for step, fitted in enumerate(outcome.path, start=1):
            previous = self.current.fitted.fit.model
            last = step == len(outcome.path)
            self._add_version(fitted, f"greedy path from version {start}, step {step}: "
                                      f"{move_text(previous, fitted.fit.model)}", announce=last)
        self.session.diagnosed(outcome)
        diagnosed = self.current.number
        yield from self.candidates.setting_outcome(outcome, diagnosed, self.current.effects)
        yield
        self.site_panel.set_sites(outcome.sites)
        if self.current.number != diagnosed:      # a version came while the steps ran (a checkbox)
            self.site_panel.mark_stale(self.current.number)
        if outcome.verdict in (acceptance.PARTLY_EXPLAINED, acceptance.UNEXPLAINED) and self.site_panel.shown_site:
            self.views.setCurrentWidget(self.site_panel)     # the misfit left: where it belongs
        if outcome.path:
            self.status_label.setText(f"Greedy path: {len(outcome.path)} step(s), now version {diagnosed}")
        elif follow:
            self.status_label.setText("The greedy path stops at once: no candidate explains the misfit it removes")
        else:
            self.status_label.setText(f"Diagnosed version {diagnosed}: {len(outcome.candidates)} candidates")
        self._update_buttons()
        self.diagnosis_shown.emit(outcome)

    def on_failed(self, message: str) -> None:
        self.catalogue.set_checked(self.current.fitted.fit.model.effect_ids)
        self.status_label.setText(f"Failed: {message}; still version {self.current.number}")
        self.job_failed.emit(message)

    def on_cancelled(self) -> None:
        self.catalogue.set_checked(self.current.fitted.fit.model.effect_ids)
        self.status_label.setText(f"Cancelled: still version {self.current.number}")
        self.job_cancelled.emit()
