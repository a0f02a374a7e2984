"""The report as a PDF (A4 portrait), drawn with matplotlib: text pages, then pages of plots.

Text is laid out top-down in inches; a line that would run past the bottom
margin starts a new page, and long messages are wrapped, so nothing is
clipped however many findings or parameters there are.
"""
from __future__ import annotations

import io
import textwrap

import matplotlib
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from analysis.report.content import CHANNEL_TITLES, ReportContent
from analysis.report.html import LIGHT_COLOURS
from analysis.report.plots import STYLE, draw_hx, draw_impedance, draw_residuals, draw_spl

A4 = (8.27, 11.69)
MARGIN = 0.7             # inches
BODY_PT, HEAD_PT, TITLE_PT = 8.5, 11.5, 15
GAP = 1.3            # line height / font size
# Characters per line of body text across the page: DejaVu Sans averages ~0.55 em.
WRAP = int((A4[0] - 2 * MARGIN) * 72 / (BODY_PT * 0.56))


class _TextPages:
    """Places lines of text down A4 pages, opening a new page when one is full."""

    def __init__(self, pdf: PdfPages, footer: str):
        self.pdf, self.footer, self.page_no = pdf, footer, 0
        self.fig: Figure | None = None
        self.y = 0.0

    def _new_page(self) -> None:
        self.close()
        self.fig = Figure(figsize=A4)
        self.page_no += 1
        self.y = MARGIN
        self.fig.text(MARGIN / A4[0], 0.4 / A4[1], f"{self.footer}   page {self.page_no}", fontsize=7,
                      color="#666666")

    def close(self) -> None:
        if self.fig is not None:
            self.pdf.savefig(self.fig)
            self.fig = None

    def _room(self, height: float) -> None:
        if self.fig is None or self.y + height > A4[1] - MARGIN:
            self._new_page()

    def text(self, x: float, s: str, size: float = BODY_PT, **kw) -> None:
        """Draw at the current line, x inches from the left margin (the line does not advance)."""
        self.fig.text((MARGIN + x) / A4[0], 1 - self.y / A4[1], s, fontsize=size, va="top", **kw)

    def line(self, s: str = "", size: float = BODY_PT, gap: float = GAP, x: float = 0.0, **kw) -> None:
        height = size * gap / 72
        self._room(height)
        if s:
            self.text(x, s, size, **kw)
        self.y += height

    def heading(self, s: str) -> None:
        self._room(0.7)       # never leave a heading alone at the bottom of a page
        self.y += 0.12
        self.line(s, HEAD_PT, weight="bold")
        self.y += 0.04

    def light(self, x: float, status: str) -> None:
        r = BODY_PT / 72 * 0.42
        centre = ((MARGIN + x + r), A4[1] - self.y - r * 1.15)
        self.fig.add_artist(Circle(centre, r, transform=self.fig.dpi_scale_trans,
                                   facecolor=LIGHT_COLOURS.get(status, "#b8b8b8"), edgecolor="#444444",
                                   linewidth=0.5))

    def wrapped(self, s: str, x: float = 0.0, **kw) -> None:
        width = max(20, WRAP - int(x * 72 / (BODY_PT * 0.56)))
        for part in textwrap.wrap(s, width) or [""]:
            self.line(part, x=x, **kw)

    def pairs(self, rows, key_width: float = 2.0) -> None:
        for key, value in rows:
            lines = textwrap.wrap(value, max(20, WRAP - int(key_width * 72 / (BODY_PT * 0.56)))) or [""]
            self._room(BODY_PT * GAP / 72 * len(lines))
            self.text(0, key, weight="bold")
            for part in lines:
                self.line(part, x=key_width)


def _text_pages(pages: _TextPages, c: ReportContent) -> None:
    for part in textwrap.wrap(c.title, int((A4[0] - 2 * MARGIN) * 72 / (TITLE_PT * 0.62))):
        pages.line(part, TITLE_PT, gap=1.6, weight="bold")
    pages.pairs(c.header, 1.5)

    pages.heading("Validity")
    pages.line("")
    pages.y -= BODY_PT * GAP / 72
    pages.light(0, c.overall)
    pages.line(f"Overall: {c.overall}        peak excursion {c.peak_displacement}", x=0.25, weight="bold")
    for light in c.lights:
        pages.line("")
        pages.y -= BODY_PT * GAP / 72
        pages.light(0.1, light.status)
        pages.line(f"{CHANNEL_TITLES.get(light.channel, light.channel)}: {light.status}", x=0.35)
        for f in light.findings:
            pages.line("")
            pages.y -= BODY_PT * GAP / 72
            pages.light(0.45, f.severity)
            pages.wrapped(f"{f.code}: {f.message}", x=0.7)
            pages.wrapped(f"Remedy: {f.remedy}", x=0.7, color="#333333", style="italic")

    pages.heading("Parameters")
    cols = (0.0, 1.6, 2.6, 3.3, 4.0)   # name | value (right-aligned at) | ±1σ | unit | rel | note
    pages.text(cols[0], "parameter", weight="bold")
    pages.text(cols[1] + 0.6, "value", weight="bold", ha="right")
    pages.text(cols[2] + 0.5, "± 1σ", weight="bold", ha="right")
    pages.text(cols[3], "unit", weight="bold")
    pages.text(cols[4], "rel.", weight="bold")
    pages.line("")
    for p in c.parameters:
        note_lines = textwrap.wrap(p.note, max(20, WRAP - int((cols[4] + 0.6) * 72 / (BODY_PT * 0.56))))
        pages._room(BODY_PT * GAP / 72 * max(1, len(note_lines)))
        pages.text(cols[0], p.name)
        pages.text(cols[1] + 0.6, p.value, ha="right", family="DejaVu Sans Mono")
        pages.text(cols[2] + 0.5, p.std, ha="right", family="DejaVu Sans Mono")
        pages.text(cols[3], p.unit)
        pages.text(cols[4], p.relative)
        if note_lines:
            for part in note_lines:
                pages.line(part, x=cols[4] + 0.6, color="#555555")
        else:
            pages.line("")

    pages.heading("Model and fit quality")
    pages.pairs(c.model)
    for note in c.notes:
        pages.wrapped(note, style="italic", color="#555555")
    pages.heading("Measurement settings")
    pages.pairs(c.settings)
    pages.heading("Calibration")
    pages.pairs(c.calibration)
    pages.close()


def _plot_pages(pdf: PdfPages, c: ReportContent, footer: str, first_page: int) -> None:
    r = c.result
    page = first_page
    groups = [["impedance", "hx"] if c.has_displacement else ["impedance"],
              (["spl"] if c.has_spl else []) + ["residuals"]]
    for group in groups:
        fig = Figure(figsize=A4, layout="constrained")
        fig.get_layout_engine().set(h_pad=0.12, rect=(MARGIN / A4[0] * 0.6, 0.6 / A4[1], 1 - 1.2 * MARGIN / A4[0],
                                                       1 - 1.1 / A4[1]))
        heights = {"impedance": 5, "hx": 5, "spl": 3, "residuals": 2.5 * len(r.curves)}
        sub = fig.subfigures(len(group), 1, height_ratios=[heights[g] for g in group], squeeze=False)[:, 0]
        for sf, what in zip(sub, group):
            if what == "impedance":
                draw_impedance(r, *sf.subplots(2, 1, sharex=True, height_ratios=[3, 2]))
            elif what == "hx":
                draw_hx(r, *sf.subplots(2, 1, sharex=True, height_ratios=[3, 2]))
            elif what == "spl":
                draw_spl(r, sf.subplots())
            else:
                draw_residuals(r, sf.subplots(len(r.curves), 1, squeeze=False)[:, 0])
        fig.text(MARGIN / A4[0], 0.4 / A4[1], f"{footer}   page {page}", fontsize=7, color="#666666")
        pdf.savefig(fig)
        page += 1


def render_pdf(content: ReportContent) -> bytes:
    footer = content.title
    buf = io.BytesIO()
    with matplotlib.rc_context(STYLE):
        # No creation date: the same measurement gives the same file.
        with PdfPages(buf, metadata={"Title": content.title, "Creator": "linpar", "CreationDate": None}) as pdf:
            pages = _TextPages(pdf, footer)
            _text_pages(pages, content)
            _plot_pages(pdf, content, footer, pages.page_no + 1)
    return buf.getvalue()
