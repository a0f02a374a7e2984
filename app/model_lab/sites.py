"""The model lab's "Missing physics" view: where the misfit belongs, with the best site's smooth correction.

The correction is drawn as the site takes it (analysis.diagnosis.sites): at the
electrical and mechanical sites what it adds (resistance and reactance, in
ohm or kg/s), at the others the factor (its change of size in per cent and
its phase in degrees).
"""
from __future__ import annotations

import html

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from analysis.diagnosis.acceptance import MIN_BIC_GAIN
from analysis.diagnosis.sites import SiteResult
from analysis.diagnosis.words import SITE_WORDS, chi2_words, tied_sites
from app.widgets import style
from app.widgets.grid_axis import show_grid
from app.widgets.plots import LEFT_AXIS_WIDTH, LogFrequencyAxis
from app.widgets.still_scene import StillScene

SIZE_COLOUR = "#6a3d9a"
PHASE_COLOUR = "#e08a00"
NO_DIAGNOSIS = ("Diagnose to see where the misfit belongs: each site of the model (electrical, force factor, "
                "mechanical, compliance, current, displacement) gets a smooth correction in turn, and the one that "
                "removes the most misfit is drawn here.")
MIN_SPAN = 1.0          # % and degrees: a flat correction still gets a readable axis
RANKED_SHOWN = 4


class CorrectionPlot(StillScene, pg.PlotWidget):
    """A site's correction against frequency: real and imaginary part of what it adds, or a factor's size and phase."""

    def __init__(self, parent=None):
        super().__init__(parent=parent, axisItems={"bottom": LogFrequencyAxis("bottom")})
        plot = self.getPlotItem()
        plot.setLogMode(x=True, y=False)
        show_grid(plot)
        plot.setMenuEnabled(False)
        plot.getAxis("left").setWidth(LEFT_AXIS_WIDTH)
        plot.getAxis("left").enableAutoSIPrefix(False)     # "kg/s (x0.001)" over 200 reads as 200 kg/s
        plot.setLabel("bottom", "frequency (Hz)")
        plot.addItem(pg.InfiniteLine(pos=0.0, angle=0, movable=False, pen=pg.mkPen(style.GUIDE, width=1)))
        self.size_curve = pg.PlotDataItem(pen=pg.mkPen(SIZE_COLOUR, width=2))
        self.phase_curve = pg.PlotDataItem(pen=pg.mkPen(PHASE_COLOUR, width=2, style=Qt.DashLine))
        plot.addItem(self.size_curve)
        plot.addItem(self.phase_curve)

    def show_site(self, site: SiteResult) -> None:
        freqs = site.freqs
        if site.unit == "1":
            first, second = 100.0 * (np.abs(site.correction) - 1.0), np.degrees(np.angle(site.correction))
            names, unit = ("change of size (%)", "phase (°)"), "% · °"
        else:
            first, second = site.correction.real, site.correction.imag
            unit = {"ohm": "Ω", "Rms": "× Rms"}.get(site.unit, site.unit)
            names = (f"resistance added ({unit})", f"reactance added ({unit})")
        plot = self.getPlotItem()
        plot.setLabel("left", unit)
        plot.setTitle(f"<span style='color:{SIZE_COLOUR}'>━ {names[0]}</span> &nbsp; "
                      f"<span style='color:{PHASE_COLOUR}'>╍ {names[1]}</span>", size="9pt")
        # Drawn where the data determine it; elsewhere its shape means nothing, and it is left out.
        seen = site.determined
        size, phase = np.where(seen, first, np.nan), np.where(seen, second, np.nan)
        self.size_curve.setData(freqs, size, connect="finite")
        self.phase_curve.setData(freqs, phase, connect="finite")
        shown = np.concatenate([size[seen], phase[seen]])
        peak = float(np.max(np.abs(shown))) if shown.size else 0.0
        limit = max(MIN_SPAN if site.unit == "1" else 1e-3, 1.15 * peak)
        self.getPlotItem().setYRange(-limit, limit, padding=0)
        self.getPlotItem().enableAutoRange(axis="x")

    def clear_factor(self) -> None:
        self.size_curve.setData([], [])
        self.phase_curve.setData([], [])
        self.getPlotItem().setTitle(None)


class SitePanel(QWidget):
    """The best site's correction and the sites' ranking in words."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.sites: tuple[SiteResult, ...] = ()
        self.heading = QLabel()
        self.heading.setTextFormat(Qt.RichText)
        self._diagnosed_heading: str | None = None
        self.heading.setWordWrap(True)
        self.plot = CorrectionPlot()
        self.ranking = QLabel()
        self.ranking.setTextFormat(Qt.RichText)
        self.ranking.setWordWrap(True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(self.heading)
        layout.addWidget(self.plot, 1)
        layout.addWidget(self.ranking)
        self.set_sites(())

    @property
    def shown_site(self) -> str | None:
        """The key of the site whose correction is drawn (None: none)."""
        return self.sites[0].key if self._needed() else None

    def _needed(self) -> bool:
        return bool(self.sites) and self.sites[0].delta_bic < -MIN_BIC_GAIN

    def set_sites(self, sites: tuple[SiteResult, ...]) -> None:
        self._diagnosed_heading = None          # the heading of these sites, before mark_stale prefixes it
        self.sites = tuple(sites)
        self.ranking.setText("")
        if not self.sites:
            self.heading.setText(html.escape(NO_DIAGNOSIS))
            self.plot.clear_factor()
            return
        best = self.sites[0]
        if not self._needed():
            self.heading.setText("<b>No site needs a correction</b>: the model misses nothing a smooth correction "
                                 "anywhere would pay for.")
            self.plot.clear_factor()
            return
        name, what = SITE_WORDS[best.site]
        tied = [SITE_WORDS[s.site][0] for s in tied_sites(self.sites)]
        if "displacement" not in best.chi2_red:
            apart = " With Z alone the sites cannot be told apart."
        elif tied:
            apart = f" The data cannot tell it from the {html.escape(' or the '.join(tied))} site."
        else:
            apart = ""
        hidden = "" if best.determined.all() else " Drawn where the data determine it."
        self.heading.setText(f"<b>Look at the {html.escape(name)} site</b>: a smooth correction there takes the "
                             f"reduced χ² to {html.escape(chi2_words(best.chi2_red))}.{apart}{hidden}")
        self.heading.setToolTip(f"The {name} site: {what}. The plot shows the correction {best.acts_as}.")
        self.plot.show_site(best)
        rows = [f"{html.escape(s.key)} ({html.escape(chi2_words(s.chi2_red))})" for s in self.sites[1:RANKED_SHOWN]]
        self.ranking.setText("Then: " + " · ".join(rows))

    def mark_stale(self, version: int) -> None:
        """The model changed since the diagnosis: the sites are those of an older version (the newest named, at each
        version added: it said "Version 2 is newer" with the lab at version 3)."""
        if not self.sites:
            return
        if self._diagnosed_heading is None:
            self._diagnosed_heading = self.heading.text()
        self.heading.setText(f"<i>Version {version} is newer than this diagnosis: Diagnose again.</i> "
                             f"{self._diagnosed_heading}")
