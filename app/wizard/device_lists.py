"""The Hardware page's two lists: sound cards with their host API and what suits a measurement, serial ports."""
from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTreeWidget, QTreeWidgetItem

from instruments.audio.config import AudioDeviceChoice
from instruments.audio.host_apis import BEST, GOOD, POOR, UNUSABLE, suitability

RANK_COLOURS = {BEST: "#1b5e20", POOR: "#8e1b1b", UNUSABLE: "#8c8c8c"}
RANK_WORDS = {BEST: "suits it", GOOD: "usable", POOR: "avoid", UNUSABLE: "cannot"}
VISIBLE_ROWS = 4


class _List(QTreeWidget):
    def __init__(self, headers: tuple[str, ...], stretch: int, parent=None):
        super().__init__(parent)
        self.setHeaderLabels(list(headers))
        self.setRootIsDecorated(False)
        self.setUniformRowHeights(True)
        self.setSelectionMode(QAbstractItemView.SingleSelection)
        self.setWordWrap(False)
        # One column takes what is left, so that every column stays in view (a long name is elided, its tooltip
        # says it whole).
        self.header().setStretchLastSection(False)
        for column in range(len(headers)):
            self.header().setSectionResizeMode(column, QHeaderView.Stretch if column == stretch else
                                               QHeaderView.ResizeToContents)
        row = self.fontMetrics().height() + 6
        self.setMinimumHeight(row * (VISIBLE_ROWS + 1) + 4)
        self.setMaximumHeight(row * (VISIBLE_ROWS + 2) + 4)


class SoundCardList(_List):
    """Sound devices: name, host API, channels, and whether the device suits a measurement (in a word;
    ``advice()`` says why, for the chosen one). One that only plays or records is listed, greyed, not chosen."""

    chosen = Signal()

    def __init__(self, parent=None):
        super().__init__(("Device", "Host API", "In / out", "For measurement"), 0, parent)
        self.currentItemChanged.connect(lambda *_: self.chosen.emit())

    def set_devices(self, devices, wanted: AudioDeviceChoice | None) -> None:
        """Fill the list (AudioDeviceInfo, in PortAudio's order) and select ``wanted`` when it is there."""
        self.blockSignals(True)
        self.clear()
        for device, judged in zip(devices, suitability(list(devices))):
            item = QTreeWidgetItem([device.name, device.hostapi,
                                    f"{device.max_input_channels} / {device.max_output_channels}",
                                    RANK_WORDS[judged.rank]])
            item.setData(0, Qt.UserRole, device.choice)
            if not device.full_duplex:
                for column in range(4):
                    item.setForeground(column, QColor(RANK_COLOURS[UNUSABLE]))
            item.setData(3, Qt.UserRole, judged.text)
            item.setToolTip(0, device.name)
            for column in range(1, 4):
                item.setToolTip(column, judged.text)
            if judged.rank in RANK_COLOURS:
                item.setForeground(3, QColor(RANK_COLOURS[judged.rank]))
            self.addTopLevelItem(item)
            if wanted is not None and device.choice == wanted and device.full_duplex:
                self.setCurrentItem(item)
        self.blockSignals(False)

    def choice(self) -> AudioDeviceChoice | None:
        """The chosen device, if it can both play and record."""
        item = self.currentItem()
        return None if item is None or item.text(3) == RANK_WORDS[UNUSABLE] else item.data(0, Qt.UserRole)

    def advice(self) -> str:
        """Whether the chosen device's host API suits a measurement, and why ("" when none is chosen)."""
        item = self.currentItem()
        return "" if item is None else f"{item.text(0)} under {item.text(1)}: {item.data(3, Qt.UserRole)}."


class SerialPortList(_List):
    """The serial ports this computer has; picking one gives its name (``picked``)."""

    picked = Signal(str)

    def __init__(self, parent=None):
        super().__init__(("Port", "Description", "USB id (VID:PID)", "Serial number"), 1, parent)
        self.itemClicked.connect(lambda item, _column: self.picked.emit(item.text(0)))

    def set_ports(self, ports) -> None:
        """Fill the list (instruments.serial_ports.SerialPort)."""
        self.clear()
        for port in ports:
            item = QTreeWidgetItem([port.device, port.description or "—", port.usb_id or "not USB",
                                    port.serial_number or "—"])
            item.setToolTip(1, " ".join(filter(None, (port.description, port.manufacturer))))
            self.addTopLevelItem(item)
