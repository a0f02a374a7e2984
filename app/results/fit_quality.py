"""Fit quality in words, with the numbers behind a Details toggle (Results page, wizard's Results step).

The headline names the model by its effects' titles and says how well it explains each channel
(analysis.fit.words). The statistics a developer reads (reduced chi^2 per channel, AIC, BIC, the
counts, the effect ids) sit in a details section that is folded away until asked for.
"""
from __future__ import annotations

import html

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QToolButton, QVBoxLayout, QWidget

from analysis.fit.model_uncertainty import model_part_words, pending
from analysis.fit.words import fit_headline, fit_is_at_noise
from analysis.pipeline import AnalysisResult

# Widgets whose object name is this hold the numbers behind a plain-language text (see the UI-text test).
DETAILS = "details"
OK_COLOUR, MISS_COLOUR, ERROR_COLOUR = "#2e7d32", "#b26a00", "#8e1b1b"


def model_words(result: AnalysisResult) -> str:
    fit = result.fit
    titles = [e.title for e in fit.model.effects]
    return "the lumped model" + (" with " + ", ".join(titles) if titles else " alone")


def fit_error_words(result: AnalysisResult) -> str:
    """"impedance 2.1 %, displacement 3.4 % (rms misfit)": each curve's fit error, what QA judges the model by."""
    errors = result.validity.fit_error_percent or {}
    if not errors:
        return ""
    return ", ".join(f"{name} {value:.2g} %" for name, value in errors.items()) + " (rms misfit of each curve)"


ESTIMATING_TEXT = ("Model part: estimating… (refits with the other forms of the inductance and creep, and with "
                   "effects a real driver has added; until they end each ± is the noise's alone)")


def model_part_html(result: AnalysisResult) -> str:
    """The model part of the uncertainties: being estimated (refits in the background), or what it came to."""
    if pending(result):
        return f"<span style='color:{MISS_COLOUR}'><b>{html.escape(ESTIMATING_TEXT)}</b></span>"
    words = model_part_words(result.validity)
    return f"<b>Model part</b>: {html.escape(words.removeprefix('model part: '))}" if words else ""


def headline_html(result: AnalysisResult) -> str:
    fit = result.fit
    if fit is None:
        return (f"<span style='color:{ERROR_COLOUR}'><b>Nothing could be fitted</b>: "
                f"{html.escape(str(result.not_fitted))}</span>")
    colour = OK_COLOUR if fit_is_at_noise(fit) else MISS_COLOUR
    text = (f"<b>Model</b>: {html.escape(model_words(result))}.<br>"
            f"<span style='color:{colour}'><b>{html.escape(fit_headline(fit))}</b></span>")
    errors = fit_error_words(result)
    if errors:
        text += f"<br><b>Fit error</b>: {html.escape(errors)}"
    text += f"<br>{model_part_html(result)}"
    if not fit.success:
        text += (f"<br><span style='color:{ERROR_COLOUR}'><b>The fit did not converge</b>: "
                 f"{html.escape(fit.message)}</span>")
    return text


def details_html(result: AnalysisResult) -> str:
    fit = result.fit
    if fit is None:
        return ""
    effects = ", ".join(f"{e.title} ({e.id})" for e in fit.model.effects) or "none"
    names = {"impedance": "Z", "displacement": "Hx"}
    chi = ", ".join(f"{names.get(k, k)} {v:.2f}" for k, v in fit.chi2_red_by_channel().items())
    return (f"<b>Effects</b>: {html.escape(effects)} &nbsp;·&nbsp; <b>reduced χ²</b>: {chi}"
            f" &nbsp;·&nbsp; AIC {fit.aic:.1f} &nbsp;·&nbsp; BIC {fit.bic:.1f}"
            f" &nbsp;·&nbsp; {fit.n_data} data, {fit.n_varying} parameters<br>"
            "<span style='color:#555'>A reduced χ² of 1 means the model meets the data within their noise; "
            "AIC and BIC weigh the misfit against the number of parameters (lower is better).</span>")


class FitQualityBox(QWidget):
    """The headline in words and a Details toggle over the numbers."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.headline = QLabel()
        self.headline.setTextFormat(Qt.RichText)
        self.headline.setWordWrap(True)
        self.headline.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.headline.setToolTip("How well the fitted model explains the measurement. Near its noise: the "
                                 "parameters can be trusted. A band it misses: an effect is missing there; "
                                 "the Model lab finds which.")
        self.toggle = QToolButton()
        self.toggle.setText("Details")
        self.toggle.setCheckable(True)
        self.toggle.setArrowType(Qt.RightArrow)
        self.toggle.setToolButtonStyle(Qt.ToolButtonTextBesideIcon)
        self.toggle.setAutoRaise(True)
        self.toggle.setToolTip("Show the statistics behind the sentence: reduced χ², AIC, BIC, counts")
        self.details = QLabel()
        self.details.setObjectName(DETAILS)
        self.details.setTextFormat(Qt.RichText)
        self.details.setWordWrap(True)
        self.details.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.details.hide()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setSpacing(2)
        layout.addWidget(self.headline)
        layout.addWidget(self.toggle)
        layout.addWidget(self.details)
        self.toggle.toggled.connect(self._on_toggled)

    def set_result(self, result: AnalysisResult) -> None:
        self.headline.setText(headline_html(result))
        details = details_html(result)
        self.details.setText(details)
        self.toggle.setVisible(bool(details))

    def text(self) -> str:
        """Everything the box says, the details included (for tests and copying)."""
        return self.headline.text() + "<br>" + self.details.text()

    def _on_toggled(self, shown: bool) -> None:
        self.details.setVisible(shown)
        self.toggle.setArrowType(Qt.DownArrow if shown else Qt.RightArrow)
