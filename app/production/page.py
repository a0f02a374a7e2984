"""The Production page: is the line drifting, what is the Cpk this week, which station reads high?

Per parameter of the selected units (dates, station, driver): n, mean, sigma,
Cp/Cpk, Pp/Ppk and yield against the archive's newest limits version; for the
parameter chosen in the table, the individuals/moving-range chart with the
Western Electric alarms in red, and the histogram with the limits. The alarms
tab names each alarm's rule and its measurements; the stations tab says which
station reads high. The numbers are analysis.production's; they are computed
in app.production.worker (a server may be slow), and exported from here to
CSV, JSON or Q-DAS AQDEF.
"""
from __future__ import annotations

import html
import shlex
from pathlib import Path

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import (QAbstractItemView, QComboBox, QFileDialog, QHBoxLayout, QHeaderView,
                               QLabel, QPushButton, QSizePolicy, QSpinBox, QSplitter, QTableWidget, QTableWidgetItem,
                               QTabWidget, QVBoxLayout, QWidget)

from analysis.archive.backends import shown
from analysis.production.capability_interval import MIN_UNITS, centred_interval, spread_interval, too_few
from app.widgets import style
from app.archive.filter import NO_DATE, date_edit
from app.archive.page import archive_source
from app.jobs.controls import JobControls
from app.results.parameter_table import display_name
from app.production.charts import ALARM, ControlChartView, HistogramView, display_unit
from app.production.worker import ProductionRequest, ProductionWorker

FILTER_DELAY_MS = 300
STATS_COLUMNS = ("Parameter", "n", "Mean", "σ", "Limit", "Cp", "Cpk", "Pp", "Ppk", "Yield", "Alarms")
ALARM_COLUMNS = ("Rule", "Units", "What", "Measurements")
STATION_COLUMNS = ("Station", "n", "Mean", "Offset from the stations' mean", "Reads")
EXPORTS = {"CSV, one row per measurement and parameter (*.csv)": ".csv", "JSON (*.json)": ".json",
           "Q-DAS AQDEF for qs-STAT (*.dfq)": ".dfq"}
LOW_CPK = 1.33          # below it a capability index is shown in red: the customary minimum for a process
NAME_WIDTH = 104        # px of the Parameter column: a long name ("Sensitivity (1 W into Re, 1 m)") is elided


def _number(value, scale: float = 1.0, digits: int = 4) -> str:
    return "–" if value is None else f"{value * scale:.{digits}g}"


def _item(text: str, tooltip: str = "", colour: str | None = None) -> QTableWidgetItem:
    item = QTableWidgetItem(text)
    if tooltip:
        item.setToolTip(tooltip)
    if colour:
        item.setForeground({"red": Qt.GlobalColor.darkRed, "grey": Qt.GlobalColor.gray}.get(
            colour, Qt.GlobalColor.darkGreen))
    return item


def _index_item(value: float | None, interval: tuple[float, float] | None, n: int) -> QTableWidgetItem:
    """A capability index as an estimate: its value, its 95 % interval on the cell's second line and in the
    tooltip (on one line the four intervals widened the table past a 1280 px screen); green only when the
    whole interval clears LOW_CPK, red when the value is below it, grey (no verdict) below MIN_UNITS units."""
    if value is None:
        return _item("–")
    text = f"{value:.2f}"
    if interval is not None:
        text += f"\n{interval[0]:.2f}–{interval[1]:.2f}"
    why = too_few(n)
    tip = (f"95 % confidence interval {interval[0]:.2f} to {interval[1]:.2f} from {n} units"
           if interval is not None else "")
    if why:
        return _item(text, f"{why}. {tip}".strip(), "grey")
    colour = "red" if value < LOW_CPK else ("green" if interval is not None and interval[0] >= LOW_CPK else None)
    return _item(text, tip, colour)


def _table(columns) -> QTableWidget:
    table = QTableWidget(0, len(columns))
    table.setHorizontalHeaderLabels(columns)
    table.verticalHeader().setVisible(False)
    table.setEditTriggers(QAbstractItemView.NoEditTriggers)
    table.setSelectionBehavior(QAbstractItemView.SelectRows)
    table.setSelectionMode(QAbstractItemView.SingleSelection)
    table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
    table.horizontalHeader().setStretchLastSection(True)
    table.setWordWrap(False)
    return table


class ProductionPage(QWidget):
    computed = Signal(object)           # app.production.worker.ProductionData, once shown
    failed = Signal(str)
    limits_stored = Signal(str)         # the line that says which version was stored

    def __init__(self, settings, parent=None):
        super().__init__(parent)
        self.settings = settings
        self.worker = ProductionWorker(self)
        self.jobs = JobControls(self.worker, cancel_tip="Stop computing; the statistics shown stay", bar_width=120)
        self.data = None
        self.parameter: str | None = None
        self.stored_line = ""                   # what Store limits… stored, until the statistics show it

        self.source_label = QLabel()
        self.source_label.setTextFormat(Qt.PlainText)       # an archive's path or URL is never markup
        self.source_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.since_edit = date_edit("Measured on or after this day")
        self.until_edit = date_edit("Measured on or before this day")
        self.station_combo, self.driver_combo = QComboBox(), QComboBox()
        self.station_combo.addItem("every station", None)
        self.driver_combo.addItem("every driver", None)
        self.baseline_spin = QSpinBox()
        self.baseline_spin.setRange(10, 100000)
        self.baseline_spin.setValue(50)
        self.baseline_spin.setSuffix(" units")
        self.baseline_spin.setToolTip("The control chart's centre and σ come from the first N units of the selection")
        self.refresh_button = QPushButton("Refresh")
        self.export_button = QPushButton("Export…")
        self.export_button.setToolTip("The selected units as CSV, JSON or Q-DAS AQDEF (.dfq)")
        self.store_limits_button = QPushButton("Store limits…")
        self.store_limits_button.setToolTip("Store a reviewed limits file (linpar-limits/1) as the archive's next "
                                            "limits version, which the statistics then use. On a server only an "
                                            "engineer's login may.")
        self.message = QLabel()
        self.message.setWordWrap(True)
        self.message.setTextFormat(Qt.RichText)
        self.summary = QLabel()
        self.summary.setTextFormat(Qt.PlainText)            # it quotes the limits' name and the filters typed
        self.summary.setWordWrap(True)
        self.stats_table = _table(STATS_COLUMNS)
        self.stats_table.horizontalHeader().setSectionResizeMode(0, QHeaderView.Fixed)
        self.stats_table.setColumnWidth(0, NAME_WIDTH)
        # No stretched last column: it kept at least Qt's default 100 px, which cost the table its fit at 1280.
        self.stats_table.horizontalHeader().setStretchLastSection(False)
        self.alarms_table = _table(ALARM_COLUMNS)
        self.stations_table = _table(STATION_COLUMNS)
        self.chart = ControlChartView()
        self.histogram = HistogramView()
        self.details = QTabWidget()
        self._build_layout()

        self.filter_timer = QTimer(self)
        self.filter_timer.setSingleShot(True)
        self.filter_timer.setInterval(FILTER_DELAY_MS)
        self.filter_timer.timeout.connect(self.refresh)
        for signal in (self.since_edit.dateChanged, self.until_edit.dateChanged, self.baseline_spin.valueChanged,
                       self.station_combo.currentIndexChanged, self.driver_combo.currentIndexChanged):
            signal.connect(lambda *_: self.filter_timer.start())
        self.refresh_button.clicked.connect(self.refresh)
        self.export_button.clicked.connect(self.on_export)
        self.store_limits_button.clicked.connect(self.on_store_limits)
        self.stats_table.itemSelectionChanged.connect(self.on_parameter_chosen)
        self.export_button.setEnabled(False)

    def _build_layout(self) -> None:
        # Two rows, and nothing that cannot shrink: the page must not set the window's minimum width.
        self.source_label.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Preferred)
        for combo in (self.station_combo, self.driver_combo):
            combo.setSizeAdjustPolicy(QComboBox.AdjustToMinimumContentsLengthWithIcon)
            combo.setMinimumContentsLength(11)
        top = QHBoxLayout()
        top.addWidget(QLabel("<b>Production</b>"))
        top.addWidget(self.source_label, 1)
        top.addWidget(self.jobs)
        top.addWidget(QLabel("Baseline"))
        top.addWidget(self.baseline_spin)
        top.addWidget(self.refresh_button)
        top.addWidget(self.store_limits_button)
        top.addWidget(self.export_button)
        filters = QHBoxLayout()
        for label, widget in (("Measured from", self.since_edit), ("to", self.until_edit), ("", self.station_combo),
                              ("", self.driver_combo)):
            if label:
                filters.addWidget(QLabel(label))
            filters.addWidget(widget)
        filters.addStretch(1)
        self.details.addTab(self.alarms_table, "Alarms")
        self.details.addTab(self.stations_table, "Stations")
        left = QSplitter(Qt.Vertical)
        left.addWidget(self.stats_table)
        left.addWidget(self.details)
        left.setSizes([300, 200])
        right = QSplitter(Qt.Vertical)
        right.addWidget(self.chart)
        right.addWidget(self.histogram)
        right.setSizes([380, 180])
        body = QSplitter(Qt.Horizontal)
        body.addWidget(left)
        body.addWidget(right)
        body.setStretchFactor(0, 3)             # the table's eleven columns first: no sideways scrolling at 1280 px
        body.setStretchFactor(1, 2)
        body.setSizes([780, 500])
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addLayout(filters)
        layout.addWidget(self.message)
        layout.addWidget(self.summary)
        layout.addWidget(body, 1)
        self.message.hide()

    # -- asking ------------------------------------------------------------------------------
    def request(self) -> ProductionRequest:
        def day(edit):
            return None if edit.date() == NO_DATE else edit.date().toString("yyyy-MM-dd")
        return ProductionRequest(archive_source(self.settings.qsettings), day(self.since_edit), day(self.until_edit),
                                 self.station_combo.currentData(), self.driver_combo.currentData(),
                                 self.baseline_spin.value())

    def refresh(self) -> int:
        self.filter_timer.stop()
        request = self.request()
        self.source_label.setText(shown(request.source))
        job = self.worker.start(request)
        self.jobs.run(job, "Reading the archive and computing…", self.on_computed, self.on_failed,
                      lambda: self.summary.setText("Cancelled: the statistics shown are the previous ones."))
        return job.id

    def showEvent(self, event) -> None:
        super().showEvent(event)
        self.refresh()              # stations store while the page is away

    def _say(self, text: str, kind: str = "error") -> None:
        colour = style.VALIDITY_COLOURS["red" if kind == "error" else "yellow"][1]
        self.message.setText(f"<span style='color:{colour}'>{html.escape(text)}</span>")
        self.message.setVisible(bool(text))

    # -- showing -----------------------------------------------------------------------------
    def on_failed(self, message: str) -> None:
        self.summary.setText("")
        self._say(f"Cannot compute the production statistics of {shown(self.request().source)}: {message}")
        self.failed.emit(message)

    def on_computed(self, data) -> None:
        self.data = data
        notes = [*data.notes, *([self.stored_line] if self.stored_line else [])]
        self.stored_line = ""                   # said once, above the statistics of the new version
        self._say("; ".join(notes), "note") if notes else self.message.hide()
        self._offer(self.station_combo, data.population.stations)
        self._offer(self.driver_combo, data.population.drivers)
        self.summary.setText(self._summary_text(data.stats, self._loaded_limits_file()))
        self._fill_stats(data.stats)
        self.export_button.setEnabled(len(data.population) > 0)
        self.computed.emit(data)

    @staticmethod
    def _offer(combo: QComboBox, names) -> None:
        known = {combo.itemData(i) for i in range(combo.count())}
        for name in sorted(set(names) - known):
            combo.addItem(name, name)

    def _loaded_limits_file(self) -> str:
        """The limits file the QA page has loaded (it remembers it), for the command that stores it."""
        from app.qa.view import LIMITS_KEY
        q = getattr(self.settings, "qsettings", None)
        return str(q.value(LIMITS_KEY, "") or "") if q is not None else ""

    @staticmethod
    def _summary_text(stats, loaded_limits: str = "") -> str:
        parts = [f"{stats.n_measurements} measurement(s): {stats.selection}"]
        if stats.excluded:
            parts.append("left out: " + ", ".join(f"{n} {why}" for why, n in stats.excluded.items()))
        # The statistics use the archive's stored limits, not a file loaded on the QA page: say how to store it.
        store = f"linpar qa limits --store {shlex.quote(loaded_limits or 'FILE')}"
        parts.append(f"limits version {stats.limits.version} ({stats.limits.name})" if stats.limits is not None
                     else f"no limits stored: Cp, Cpk, Pp, Ppk and yield need the archive's limits; an engineer "
                          f"stores them with Store limits… or: {store}")
        few = [p.capability.n for p in stats.parameters.values() if p.capability.n < MIN_UNITS]
        if stats.limits is not None and few:
            parts.append(f"capability indices greyed: {max(few)} unit(s) or fewer, at least {MIN_UNITS} needed; "
                         "below each index its 95 % confidence interval")
        if stats.first_pass_yield is not None:
            parts.append(f"first-pass yield {100 * stats.first_pass_yield:.1f} % as the stations judged")
        return "; ".join(parts) + "."

    def _fill_stats(self, stats) -> None:
        table = self.stats_table
        table.blockSignals(True)
        table.setRowCount(len(stats.parameters))
        chosen_row = 0
        for row, p in enumerate(stats.parameters.values()):
            c, s = p.capability, p.display_scale
            unit = f" {display_unit(p.display_unit)}".rstrip()
            alarms = 0 if p.chart is None else len(p.chart.alarms)
            name = _item(display_name(p.name), display_name(p.name))
            name.setData(Qt.ItemDataRole.UserRole, p.name)         # the statistics' key, for on_parameter_chosen
            cells = [name, _item(str(c.n)), _item(_number(c.mean, s) + unit,
                                                           f"min {_number(c.minimum, s)}, max {_number(c.maximum, s)}"),
                     _item(_number(c.sigma_overall, s, 3), f"within (moving range): {_number(c.sigma_within, s)}"),
                     _item(p.limit_text or "–")]
            for value, interval in ((c.cp, spread_interval), (c.cpk, centred_interval), (c.pp, spread_interval),
                                    (c.ppk, centred_interval)):
                cells.append(_index_item(value, interval(value, c.n), c.n))
            cells.append(_item("–" if c.yield_fraction is None else f"{100 * c.yield_fraction:.1f} %"))
            cells.append(_item(str(alarms), colour="red" if alarms else None))
            for col, item in enumerate(cells):
                table.setItem(row, col, item)
            if p.name == self.parameter:
                chosen_row = row
        table.resizeRowsToContents()            # the indices' intervals are their cells' second line
        table.blockSignals(False)
        if stats.parameters:
            table.selectRow(chosen_row)
            self.on_parameter_chosen()
        else:
            self.chart.clear_chart("No unit in this selection")
            self.histogram.getPlotItem().clear()
            self.alarms_table.setRowCount(0)
            self.stations_table.setRowCount(0)

    def on_parameter_chosen(self) -> None:
        rows = self.stats_table.selectionModel().selectedRows() if self.stats_table.selectionModel() else []
        if self.data is None or not rows:
            return
        name = self.stats_table.item(rows[0].row(), 0).data(Qt.ItemDataRole.UserRole)
        self.parameter = name
        p = self.data.stats.parameters[name]
        self.chart.show_parameter(p)
        self.histogram.show_parameter(p)
        self._fill_alarms(p)
        self._fill_stations(p)

    def _fill_alarms(self, p) -> None:
        alarms = () if p.chart is None else p.chart.alarms
        self.alarms_table.setRowCount(len(alarms))
        for row, a in enumerate(alarms):
            units = [i + 1 for i in a.points]
            ids = [p.ids[i] for i in a.points]
            span = str(units[0]) if len(units) == 1 else f"{units[0]}–{units[-1]}"
            what = a.title + (f" ({a.side})" if a.side else "")
            for col, item in enumerate((_item(a.rule, colour="red"), _item(span), _item(what, what),
                                        _item(ids[0] + (f" and {len(ids) - 1} more" if len(ids) > 1 else ""),
                                              "\n".join(ids)))):
                self.alarms_table.setItem(row, col, item)
        self.details.setTabText(0, f"{display_name(p.name)}: alarms ({len(alarms)})")

    def _fill_stations(self, p) -> None:
        rows = p.stations.stations
        self.stations_table.setRowCount(len(rows))
        unit = f" {display_unit(p.display_unit)}".rstrip()
        for row, st in enumerate(rows):
            pairs = [q for q in p.stations.pairs if st.station in (q.a, q.b)]
            tip = "\n".join(f"against {q.b if q.a == st.station else q.a}: p = {q.p:.2g}"
                            + (" (differs)" if q.significant else "") for q in pairs if q.p is not None)
            offset = f"{st.offset * p.display_scale:+.3g}{unit}" + \
                     ("" if st.offset_sigmas is None else f" ({st.offset_sigmas:+.2f} σ)")
            cells = (_item(st.station), _item(str(st.n)), _item(_number(st.mean, p.display_scale) + unit),
                     _item(offset, tip), _item(st.reads or "as the others", tip, "red" if st.reads else None))
            for col, item in enumerate(cells):
                self.stations_table.setItem(row, col, item)
        self.details.setTabText(1, f"{display_name(p.name)}: stations" + (f" ({sum(1 for s in rows if s.reads)} differ)"
                                                            if any(s.reads for s in rows) else ""))

    # -- limits ------------------------------------------------------------------------------
    def on_store_limits(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Store a limits file as the next limits version",
                                              self._loaded_limits_file(), "Limits (*.json);;All files (*)")
        if path:
            self.store_limits(path)

    def store_limits(self, path: str | Path, note: str = "") -> int:
        """Store the limits file at `path` in the archive (off the GUI thread); the page says what came of it
        and shows the statistics against the new version. The job's id."""
        job = self.worker.store(self.request().source, str(path), note)
        self.jobs.run(job, "Storing the limits…", self.on_limits_stored, self.on_store_failed)
        return job.id

    def on_limits_stored(self, line: str) -> None:
        self.stored_line = line
        self._say(line, "note")
        self.limits_stored.emit(line)
        self.refresh()

    def on_store_failed(self, message: str) -> None:
        self._say(f"The limits were not stored: {message}")
        self.failed.emit(message)

    # -- export ------------------------------------------------------------------------------
    def on_export(self) -> None:
        path, chosen = QFileDialog.getSaveFileName(self, "Export the selected units", "production.csv",
                                                   ";;".join(EXPORTS))
        if path:
            self.export_to(Path(path), EXPORTS.get(chosen))

    def export_to(self, path: Path, suffix: str | None = None) -> Path | None:
        """Write the shown population to `path` (CSV, JSON or .dfq by suffix); the path, or None (the page says)."""
        if self.data is None:
            return None
        import json

        from analysis.archive.atomic import write_atomic
        from analysis.production.aqdef import encode, write_dfq
        from analysis.production.exchange import population_csv, population_json
        kind = (suffix or path.suffix).lower()
        data = self.data
        try:
            if kind == ".dfq":
                payload = encode(write_dfq(data.population, data.stats.parameters, data.excluded_ids))
            elif kind == ".json":
                payload = json.dumps(population_json(data.population, data.stats.selection, data.location,
                                                     data.stats.limits), indent=1, ensure_ascii=False) + "\n"
            else:
                payload = population_csv(data.population)
            written = write_atomic(path, payload)
        except Exception as exc:  # noqa: BLE001 - the GUI's error boundary (job_book.failure_text)
            from app.jobs.book import failure_text
            self._say(f"Could not export to {path}: {failure_text(exc, f'exporting to {path}')}")
            return None
        self._say(f"Written: {written} ({len(data.population)} measurement(s)).", "note")
        return written

    def shutdown(self, wait_ms: int) -> bool:
        return self.worker.shutdown(wait_ms)


__all__ = ["ALARM", "ProductionPage"]
