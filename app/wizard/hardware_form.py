"""The Hardware page's editors for a channel map and a calibration (plain form widgets, no jobs)."""
from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QDoubleSpinBox, QFormLayout, QSpinBox, QWidget

from instruments.audio.config import Calibration, ChannelMap

# (field, label, unit suffix, display scale, decimals, maximum): display = SI x scale
CALIBRATION_FIELDS = (
    ("volts_per_fs_out", "Output (DAC × amplifier)", " V/FS", 1.0, 4, 1000.0),
    ("volts_per_fs_voltage_sense", "Voltage sense", " V/FS", 1.0, 4, 1000.0),
    ("volts_per_fs_current_sense", "Current-sense ADC", " V/FS", 1.0, 4, 100.0),
    ("shunt_ohm", "Shunt", " Ω", 1.0, 5, 100.0),
    ("current_amp_gain", "Current amplifier gain", " ×", 1.0, 3, 10000.0),
    ("volts_per_fs_laser", "Laser input", " V/FS", 1.0, 4, 100.0),
    ("laser_m_per_volt", "Laser scale", " mm/V", 1e3, 5, 1000.0),
)


class ChannelMapForm(QWidget):
    edited = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        form = QFormLayout(self)
        form.setContentsMargins(0, 0, 0, 0)
        self.spins: dict[str, QSpinBox] = {}
        for name, label in (("output", "Output to the amplifier"), ("voltage", "Voltage input"),
                            ("current", "Current input"), ("laser_analog", "Laser analog input")):
            spin = QSpinBox()
            spin.setRange(-1 if name == "laser_analog" else 0, 63)
            spin.setPrefix("channel ")
            if name == "laser_analog":
                spin.setSpecialValueText("none")
            spin.valueChanged.connect(self.edited)
            self.spins[name] = spin
            form.addRow(label, spin)

    def set_map(self, cm: ChannelMap) -> None:
        for name, spin in self.spins.items():
            value = getattr(cm, name)
            spin.blockSignals(True)
            spin.setValue(-1 if value is None else value)
            spin.blockSignals(False)

    def channel_map(self) -> ChannelMap:
        """AudioConfigError (with the reason) for a map that wires two signals to one input."""
        values = {name: spin.value() for name, spin in self.spins.items()}
        if values["laser_analog"] < 0:
            values["laser_analog"] = None
        return ChannelMap(**values)

    def set_editable(self, editable: bool) -> None:
        for spin in self.spins.values():
            spin.setReadOnly(not editable)


class CalibrationForm(QWidget):
    edited = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        form = QFormLayout(self)
        form.setContentsMargins(0, 0, 0, 0)
        self.spins: dict[str, QDoubleSpinBox] = {}
        for name, label, suffix, _scale, decimals, maximum in CALIBRATION_FIELDS:
            spin = QDoubleSpinBox()
            spin.setDecimals(decimals)
            spin.setRange(10.0 ** -decimals, maximum)
            spin.setSuffix(suffix)
            spin.valueChanged.connect(self.edited)
            self.spins[name] = spin
            form.addRow(label, spin)

    def set_calibration(self, calibration: Calibration) -> None:
        for name, _label, _suffix, scale, _d, _m in CALIBRATION_FIELDS:
            spin = self.spins[name]
            spin.blockSignals(True)
            spin.setValue(getattr(calibration, name) * scale)
            spin.blockSignals(False)

    def calibration(self) -> Calibration:
        return Calibration(**{name: self.spins[name].value() / scale
                              for name, _label, _suffix, scale, _d, _m in CALIBRATION_FIELDS})

    def set_editable(self, editable: bool) -> None:
        for spin in self.spins.values():
            spin.setReadOnly(not editable)
