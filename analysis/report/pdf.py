"""The report as a PDF (A4 portrait), drawn with matplotlib, in the order of the HTML page.

Everything flows top-down in inches: text lines, the QA verdict banner and
the plots. A line that would run past the bottom margin starts a new page,
long messages are wrapped, and a plot that does not fit what is left of a
page starts the next one (it may shrink to PLOT_SHRINK of its height to stay),
so nothing is clipped. A dry run of the layout counts the pages first: when
slightly smaller plots (PLOT_SCALES) save a page, they are used, so that no
last page holds only the few lines that ran over.

Each plot sits in fixed margins inside the band of the page it occupies (room\nfor its title, axis labels and tick labels); the text around it is placed by\nhand and lies outside that band.
"""
from __future__ import annotations

import io
import logging
import textwrap

import matplotlib
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.patches import Circle, Rectangle
from matplotlib.textpath import TextPath

from analysis.report.content import CHANNEL_TITLES, ReportContent
from analysis.report.fonts import STAND_IN, drawable, families
from analysis.report.html import LIGHT_COLOURS
from analysis.report.plots import STYLE, draw_hx, draw_impedance, draw_residuals, draw_spl
from analysis.limits import INTERVAL_K
from analysis.report.numbers import NOT_DETERMINED_NOTE
from analysis.report.qa import VERDICT_COLOURS, QASection
from analysis.report.text_fit import shorten, width_in, wrap

# fontTools says every font it subsets at INFO, some 250 lines an export: noise on the user's terminal
# (`linpar gui` logs at INFO). Their warnings still show.
for _chatty in ("fontTools", "matplotlib"):
    logging.getLogger(_chatty).setLevel(logging.WARNING)
# The fallback font has no bold: matplotlib warns "Failed to find font weight bold" for each bold line it looks
# at, and draws its regular weight, which is what the report wants.
logging.getLogger("matplotlib.font_manager").setLevel(logging.ERROR)

A4 = (8.27, 11.69)
MARGIN = 0.7             # inches
BODY_PT, HEAD_PT, TITLE_PT, VERDICT_PT, FOOTER_PT = 8.5, 11.5, 15, 16, 7
GAP = 1.3            # line height / font size
EM = 0.56            # DejaVu Sans averages ~0.55 em per character
# Characters per line of body text across the page.
WRAP = int((A4[0] - 2 * MARGIN) * 72 / (BODY_PT * EM))
LINE = BODY_PT * GAP / 72
# Said once, under the header, when a name holds a character no font of the report's draws (analysis.report.fonts).
STAND_IN_NOTE = (f"{STAND_IN} stands for a character the fonts of this PDF cannot draw: the HTML report and the "
                 "data export write the names in full.")
KEEP_TOGETHER = 2.5      # inches: a shorter section is not split across pages
PLOT_LEFT = 0.6 * MARGIN        # axis labels sit in the left margin's outer part: plots use the width
PLOT_SHRINK = 0.8
# A plot band's fixed margins, inches: its title above, the frequency axis' ticks and label below, the y axis'
# label and tick labels on the left (of the plots' left edge, PLOT_LEFT), the gap between stacked axes.
PLOT_TITLE, PLOT_X_LABELS, PLOT_Y_LABELS, PLOT_GAP = 0.3, 0.5, 0.75, 0.1
PLOT_SCALES = (0.95, 0.9, 0.85, 0.8, 0.75, 0.7)    # tried in turn: the first that saves a page is used
PLOT_HEIGHTS = {"impedance": 4.6, "hx": 4.6, "spl": 3.0, "residuals": 2.4}     # inches; residuals per channel


def _chars(width_in: float) -> int:
    return max(12, int(width_in * 72 / (BODY_PT * EM)))


BOLD_EM = 0.64           # DejaVu Sans Bold's characters are wider: a key's width is estimated with this


def _key_inches(key: str) -> float:
    return len(key) * BODY_PT * BOLD_EM / 72


def _key_width(rows, least: float = 2.0, most: float = 3.8) -> float:
    """A key column as wide as the longest key needs, between least and most inches."""
    return min(most, max(least, max((_key_inches(k) for k, _ in rows), default=0.0) + 0.15))


class _DryPage:
    """A page of a dry run: takes the text and shapes, draws nothing. Making real Figures only to count pages
    cost the export seconds (a Figure and its texts per page, for each of up to 7 layouts tried)."""
    dpi_scale_trans = None

    def text(self, *args, **kwargs) -> None:
        pass

    def add_artist(self, artist) -> None:
        pass


class _Pages:
    """Places text and plots down A4 pages, opening a new page when one is full."""

    def __init__(self, pdf: PdfPages | None, footer: str, content: ReportContent, plot_scale: float = 1.0,
                 total: int | None = None):
        """pdf None: a dry run that only counts pages (nothing is plotted or saved)."""
        self.pdf, self.footer, self.content, self.page_no = pdf, footer, content, 0
        self.plot_scale, self.total = plot_scale, total
        self.stood_in = False           # a character was written as STAND_IN
        self.fig: Figure | _DryPage | None = None
        self.y = 0.0
        self.plots: list[tuple[str, float, float]] = []      # (what, top, height) on the current page

    @property
    def bottom(self) -> float:
        return A4[1] - MARGIN

    def _new_page(self) -> None:
        self.close()
        self.fig = Figure(figsize=A4) if self.pdf is not None else _DryPage()
        self.page_no += 1
        self.y = MARGIN
        of = f" of {self.total}" if self.total else ""
        page = f"   page {self.page_no}{of}"
        # The page number is what a footer is for: a long title gives way to it.
        footer = shorten(self.footer, A4[0] - 2 * MARGIN - width_in(page, FOOTER_PT), FOOTER_PT)
        self.fig.text(MARGIN / A4[0], 0.4 / A4[1], drawable(footer + page), fontsize=FOOTER_PT, color="#666666",
                      parse_math=False)

    def close(self) -> None:
        if self.fig is not None:
            if self.pdf is not None:
                self._draw_plots()
                self.pdf.savefig(self.fig)
            self.plots = []
            self.fig = None

    def _room(self, height: float) -> None:
        if self.fig is None or self.y + height > self.bottom:
            self._new_page()

    # --- text ---------------------------------------------------------------------

    def text(self, x: float, s: str, size: float = BODY_PT, **kw) -> None:
        """Draw at the current line, x inches from the left margin (the line does not advance)."""
        shown = drawable(s)
        self.stood_in |= shown != s
        # parse_math=False: a name holding two "$" is text, not a formula for matplotlib to typeset.
        self.fig.text((MARGIN + x) / A4[0], 1 - self.y / A4[1], shown, fontsize=size, va="top", parse_math=False,
                      **kw)

    def line(self, s: str = "", size: float = BODY_PT, gap: float = GAP, x: float = 0.0, **kw) -> None:
        height = size * gap / 72
        self._room(height)
        if s:
            self.text(x, s, size, **kw)
        self.y += height

    def heading(self, s: str, keep: float = 0.7) -> None:
        self._room(keep)       # never leave a heading alone at the bottom of a page
        self.y += 0.12
        self.line(s, HEAD_PT, weight="bold")
        self.y += 0.04

    def light(self, x: float, status: str) -> None:
        """A validity light at the start of the line about to be written."""
        self._room(LINE)
        r = BODY_PT / 72 * 0.42
        centre = ((MARGIN + x + r), A4[1] - self.y - r * 1.15)
        self.fig.add_artist(Circle(centre, r, transform=self.fig.dpi_scale_trans,
                                   facecolor=LIGHT_COLOURS.get(status, "#b8b8b8"), edgecolor="#444444",
                                   linewidth=0.5))

    def wrapped(self, s: str, x: float = 0.0, **kw) -> None:
        for part in wrap(s, A4[0] - 2 * MARGIN - x, BODY_PT, kw.get("weight") == "bold") or [""]:
            self.line(part, x=x, **kw)

    def section(self, title: str, rows, key_width: float = 2.0) -> None:
        """A heading and its key-value rows, kept on one page when they are short (up to KEEP_TOGETHER)."""
        height = LINE * sum(len(self._wrap_value(value, key_width)) + self._own_line(key, key_width)
                            for key, value in rows)
        self.heading(title, keep=0.55 + height if height <= KEEP_TOGETHER else 0.7)
        self.pairs(rows, key_width)

    @staticmethod
    def _wrap_value(value: str, key_width: float) -> list[str]:
        return wrap(value, A4[0] - 2 * MARGIN - key_width, BODY_PT) or [""]

    @staticmethod
    def _own_line(key: str, key_width: float) -> int:
        """1 when the key would run into its value (it takes a line of its own), else 0."""
        return int(_key_inches(key) > key_width - 0.08)

    def pairs(self, rows, key_width: float = 2.0) -> None:
        for key, value in rows:
            lines = self._wrap_value(value, key_width)
            own_line = self._own_line(key, key_width)
            self._room(LINE * (len(lines) + own_line))
            if own_line:            # a key longer than its column was printed over its value
                self.line(key, weight="bold")
            else:
                self.text(0, key, weight="bold")
            for part in lines:
                self.line(part, x=key_width)

    def banner(self, qa: QASection) -> None:
        """The QA verdict in a coloured box across the page: the first thing a QA reader looks for."""
        background, colour = VERDICT_COLOURS[qa.verdict]
        headline = f"QA: {qa.headline}"
        width_pt = TextPath((0, 0), headline, size=VERDICT_PT, prop=FontProperties(weight="bold")).get_extents().width
        left = 0.12 + width_pt / 72 + 0.3
        width = A4[0] - 2 * MARGIN - left - 0.1
        lines = wrap(qa.why, width, BODY_PT) + wrap(f"limits: {qa.name} ({qa.file})", width, BODY_PT)
        height = max(0.5, LINE * len(lines) + 0.2)
        self._room(height + 0.15)
        self.y += 0.05
        self.fig.add_artist(Rectangle((MARGIN, A4[1] - self.y - height), A4[0] - 2 * MARGIN, height,
                                      transform=self.fig.dpi_scale_trans, facecolor=background, edgecolor=colour,
                                      linewidth=1.5))
        top = self.y
        self.y = top + (height - VERDICT_PT / 72 * 1.2) / 2
        self.text(0.12, headline, VERDICT_PT, weight="bold", color=colour)
        self.y = top + (height - LINE * len(lines)) / 2
        for part in lines:
            self.text(left, part, color=colour)
            self.y += LINE
        self.y = top + height + 0.1

    # --- plots ----------------------------------------------------------------------

    def plot(self, what: str, height: float) -> None:
        """Reserve a band for a plot; it is drawn when the page closes."""
        height *= self.plot_scale
        if self.fig is None or self.bottom - self.y < PLOT_SHRINK * height:
            self._new_page()
        band = min(height, self.bottom - self.y)
        self.plots.append((what, self.y, band))
        self.y += band

    def _axes(self, top: float, height: float, rows: int, ratios=None, share: bool = False) -> list:
        """`rows` axes stacked in a band `height` inches high from `top`, in fixed margins (inches): room for
        a title above, the frequency axis' labels below, the y label and tick labels on the left. Fixed
        margins, not constrained layout: that measured every text of the page twice and took a third of
        an export's time."""
        left, right = PLOT_LEFT + PLOT_Y_LABELS, A4[0] - MARGIN * 0.6
        first = last = None
        axes = []
        ratios = ratios or [1] * rows
        inner = height - PLOT_TITLE - PLOT_X_LABELS - PLOT_GAP * (rows - 1)
        y = top + PLOT_TITLE
        for ratio in ratios:
            h = inner * ratio / sum(ratios)
            ax = self.fig.add_axes(((left) / A4[0], 1 - (y + h) / A4[1], (right - left) / A4[0], h / A4[1]),
                                   sharex=first if share else None)
            first = first or ax
            last = ax
            axes.append(ax)
            y += h + PLOT_GAP
        if share:
            for ax in axes:
                if ax is not last:
                    ax.tick_params(labelbottom=False)
        return axes

    def _draw_plots(self) -> None:
        r = self.content.result
        for what, top, band in self.plots:
            if what == "impedance":
                draw_impedance(r, *self._axes(top, band, 2, [3, 2], share=True))
            elif what == "hx":
                draw_hx(r, *self._axes(top, band, 2, [3, 2], share=True))
            elif what == "spl":
                draw_spl(r, *self._axes(top, band, 1))
            else:               # one band per channel, each with its title and frequency axis
                n = len(r.curves)
                draw_residuals(r, [self._axes(top + i * band / n, band / n, 1)[0] for i in range(n)])


def _validity(pages: _Pages, c: ReportContent) -> None:
    pages.heading("Validity")
    pages.light(0, c.overall)
    pages.line(f"Overall: {c.overall}        peak excursion {c.peak_displacement}", x=0.25, weight="bold")
    for light in c.lights:
        pages.light(0.1, light.status)
        pages.line(f"{CHANNEL_TITLES.get(light.channel, light.channel)}: {light.status}", x=0.35)
        for f in light.findings:
            pages.light(0.45, f.severity)
            pages.wrapped(f"{f.code}: {f.message}", x=0.7)
            pages.wrapped(f"Remedy: {f.remedy}", x=0.7, color="#333333")


def _qa_table(pages: _Pages, qa: QASection) -> None:
    pages.heading("QA limits")
    pages.wrapped(f"Limits file {qa.file} ({qa.name}): {qa.headline}. Values in the file's units; "
                  "tolerance used: distance from the middle of a two-sided limit as a share of its half-width. "
                  f"Each parameter is judged by its value ± {INTERVAL_K:g} σ: pass inside, FAIL wholly outside, uncertain across.")
    if qa.fit_error:
        pages.wrapped(f"Fit error (rms misfit of each curve): {qa.fit_error}.")
    cols = (0.0, 0.95, 2.75, 3.4, 3.55, 5.05)   # name | result | measured (right) | used (right) | limit | margin
    widths = {4: _chars(cols[5] - cols[4] - 0.1), 5: _chars(A4[0] - 2 * MARGIN - cols[5])}
    pages.line("", gap=0.5)
    pages._room(LINE * 2)
    for x, title, kw in ((cols[0], "parameter", {}), (cols[1], "result", {}), (cols[2], "measured", {"ha": "right"}),
                         (cols[3], "tol. used", {"ha": "right"}), (cols[4], "limit", {}), (cols[5], "margin", {})):
        pages.text(x, title, weight="bold", **kw)
    pages.line("")
    colours = {"pass": "#1b5e20", "FAIL": "#8e1b1b", "uncertain": "#8a4300"}
    for row in qa.rows:
        limit = textwrap.wrap(row.limit, widths[4]) or [""]
        margin = textwrap.wrap(row.margin or row.note, widths[5]) or [""]
        pages._room(LINE * max(len(limit), len(margin)))
        pages.text(cols[0], row.name)
        pages.text(cols[1], row.outcome, weight="bold" if row.outcome in ("FAIL", "uncertain") else "normal",
                   color=colours.get(row.outcome, "#555555"))
        pages.text(cols[2], row.value, ha="right")
        pages.text(cols[3], row.used, ha="right")
        for i in range(max(len(limit), len(margin))):
            if i < len(limit):
                pages.text(cols[4], limit[i])
            grey = {"color": "#555555"} if row.note and not row.margin else {}
            pages.line(margin[i] if i < len(margin) else "", x=cols[5], **grey)


def _parameters(pages: _Pages, rows, title: str = "Parameters") -> None:
    pages.heading(title)
    cols = (0.0, 2.1, 3.1, 3.8, 4.5)   # name | value (right-aligned at) | ±1σ | unit | rel | note
    pages._room(LINE * 2)
    pages.text(cols[0], "parameter", weight="bold")
    pages.text(cols[1] + 0.6, "value", weight="bold", ha="right")
    pages.text(cols[2] + 0.5, "± 1σ", weight="bold", ha="right")
    pages.text(cols[3], "unit", weight="bold")
    pages.text(cols[4], "rel.", weight="bold")
    pages.line("")
    previous = ""
    for p in rows:
        # A missing value has no relative uncertainty: its note starts in that column. The same reason for
        # the next parameter (all the mechanical ones without a laser) is not repeated in full.
        x_note = cols[4] + (0.6 if p.relative else 0.0)
        note = "as above" if p.note and p.note == previous else p.note
        previous = p.note
        note_lines = textwrap.wrap(note, _chars(A4[0] - 2 * MARGIN - x_note))
        pages._room(LINE * max(1, len(note_lines)))
        pages.text(cols[0], p.name)
        pages.text(cols[1] + 0.6, p.value, ha="right")
        pages.text(cols[2] + 0.5, p.std, ha="right")
        pages.text(cols[3], p.unit)
        pages.text(cols[4], p.relative)
        for part in note_lines or [""]:
            pages.line(part, x=x_note, color="#555555")
    if not all(p.determined for p in rows):
        pages.wrapped(NOT_DETERMINED_NOTE, color="#555555")


def _flow(pages: _Pages, c: ReportContent) -> None:
    """The customer's pages (parameters, model, validity, plots, calibration), then the appendix on a page
    of its own (fit statistics, correlations, the model's internal quantities, residuals, raw settings)."""
    for part in wrap(c.title, A4[0] - 2 * MARGIN, TITLE_PT, bold=True):
        pages.line(part, TITLE_PT, gap=1.6, weight="bold")
    if c.qa is not None:
        pages.banner(c.qa)
    pages.pairs(c.header, 1.5)
    if pages.stood_in:
        pages.wrapped(STAND_IN_NOTE, color="#555555")
    if c.qa is not None:
        _qa_table(pages, c.qa)
    _parameters(pages, c.parameters)
    pages.section("Model", c.model)
    for note in c.notes:
        pages.wrapped(note, color="#555555")
    _validity(pages, c)

    plots = ["impedance"] + (["hx"] if c.has_displacement else []) + (["spl"] if c.has_spl else [])
    if not c.result.curves:        # nothing was fitted (a broken measurement): the notes say why
        plots = []
    for i, what in enumerate(plots):
        if i == 0:      # the heading goes with the first plot, never alone at the foot of a page
            pages.heading("Plots", keep=0.5 + PLOT_SHRINK * PLOT_HEIGHTS[what] * pages.plot_scale)
        pages.plot(what, PLOT_HEIGHTS[what])
    pages.section("Calibration", c.calibration)

    pages.close()               # the appendix starts a page of its own
    pages.line("Appendix: engineering detail", HEAD_PT + 2, gap=1.6, weight="bold")
    if c.fit:
        pages.section("Fit", c.fit)
    if c.internal:
        _parameters(pages, c.internal, "Model's internal quantities")
    pages.section("Measurement settings", c.settings, _key_width(c.settings))
    if c.calibration_detail:           # nothing recorded: the first page says so already
        pages.section("Calibration as recorded", c.calibration_detail, _key_width(c.calibration_detail))
    if plots:          # last: a plot may shrink to stay on the page, where text would run over onto a new one
        residuals = PLOT_HEIGHTS["residuals"] * len(c.result.curves)
        pages.heading("Residuals", keep=0.5 + PLOT_SHRINK * residuals * pages.plot_scale)
        pages.plot("residuals", residuals)
    pages.close()


def _layout(content: ReportContent) -> tuple[float, int]:
    """(scale of the plots, pages): 1, or the largest smaller scale that saves a page (text that ran a few
    lines over onto a page of its own)."""
    def pages_at(scale: float) -> int:
        pages = _Pages(None, content.title, content, scale)
        _flow(pages, content)
        return pages.page_no

    full = pages_at(1.0)
    for scale in PLOT_SCALES:
        fewer = pages_at(scale)
        if fewer < full:
            return scale, fewer
    return 1.0, full


def render_pdf(content: ReportContent) -> bytes:
    buf = io.BytesIO()
    with matplotlib.rc_context({**STYLE, "font.family": list(families())}):
        scale, total = _layout(content)
        # No creation date: the same measurement gives the same file.
        with PdfPages(buf, metadata={"Title": content.title, "Creator": "linpar", "CreationDate": None}) as pdf:
            _flow(_Pages(pdf, content.title, content, scale, total), content)
    return buf.getvalue()
