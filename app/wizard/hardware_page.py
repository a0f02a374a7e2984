"""Step 2: the sound card (or the virtual rig), its wiring and calibration, and the laser; a Test for each."""
from __future__ import annotations

import json

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (QButtonGroup, QCheckBox, QComboBox, QGridLayout, QGroupBox, QHBoxLayout, QLabel,
                               QLineEdit, QPushButton, QRadioButton, QVBoxLayout)

from app.jobs.controls import JobControls
from app.wizard.base import ERROR_COLOUR, OK_COLOUR, WizardPage, coloured, rich_label
from app.wizard.device_lists import SerialPortList, SoundCardList
from app.wizard.hardware import (
    ANALOG_LASER, NO_LASER, RIG, SERIAL_LASER, SIMULATOR, SOUNDCARD, HardwareConfig,
    find_virtual_rig, virtual_rig_unavailable)
from app.wizard.hardware_form import CalibrationForm, ChannelMapForm
from instruments.audio.config import AudioConfigError, AudioDeviceChoice, Calibration, ChannelMap
from instruments.rig.engine import RIG_CALIBRATION, RIG_CHANNEL_MAP
from instruments.rig.state import DEFAULT_NAME
from instruments.serial_ports import list_serial_ports, port_example

SETTINGS_KEY = "measure/hardware"
LASER_RATES = (4000.0, 2000.0, 1000.0, 500.0, 250.0)
SAMPLE_RATES = (48000, 44100, 96000)
FORGOTTEN_INDEX = ("The sound card chosen last time was remembered by its number in PortAudio's list, which changes "
                   "when a device is plugged in: choose it again (from now on it is remembered by name and host API).")


def remembered_device(saved) -> tuple[AudioDeviceChoice | None, str]:
    """The device the settings remember, and a note for the user when it was stored the old way (by index)."""
    if not saved:
        return None, ""
    if isinstance(saved, dict) and isinstance(saved.get("name"), str) and isinstance(saved.get("hostapi"), str):
        return AudioDeviceChoice(saved["name"], saved["hostapi"]), ""      # other keys (an old index) dropped
    return None, FORGOTTEN_INDEX


class HardwarePage(WizardPage):
    title = "Hardware"
    subtitle = ("The sound card that drives the amplifier and reads voltage and current, and the laser. The "
                "in-process simulator stands in for all of it when nothing else is there: choose it to try "
                "linpar without hardware.")

    def __init__(self, state, session, parent=None, rig_name: str = DEFAULT_NAME, rig_runtime_dir: str | None = None):
        super().__init__(state, session, parent)
        self.rig_name, self.rig_runtime_dir = rig_name, rig_runtime_dir
        self.rig = None
        self.devices: list = []
        self.device_message = ""
        self._saved_device: AudioDeviceChoice | None = None

        self.simulator_radio = QRadioButton("In-process simulator: no hardware needed (the paper's driver and a laser)")
        self.realtime_check = QCheckBox("in real time (off: as fast as the computer goes)")
        self.realtime_check.setChecked(True)
        self.rig_radio = QRadioButton(f"JACK virtual rig '{rig_name}': optional, tries the sound-card path through JACK")
        self.rig_status = rich_label()
        self.rig_refresh = QPushButton("Look again")
        self.soundcard_radio = QRadioButton("Sound card")
        self.device_list = SoundCardList()
        self.device_refresh = QPushButton("Refresh list")
        self.device_advice = plain_label()
        self.rate_combo = QComboBox()
        for rate in SAMPLE_RATES:
            self.rate_combo.addItem(f"{rate / 1000:g} kHz", rate)
        self.kind_group = QButtonGroup(self)
        for button in (self.simulator_radio, self.rig_radio, self.soundcard_radio):
            self.kind_group.addButton(button)
        self.channel_form = ChannelMapForm()
        self.calibration_form = CalibrationForm()
        self.audio_jobs = JobControls(session)
        self.test_audio_button = QPushButton("Test sound card")
        self.audio_result = rich_label(selectable=True)

        self.laser_none = QRadioButton("No laser (impedance only)")
        self.laser_analog = QRadioButton("Laser's analog output on a sound-card input (channel map)")
        self.laser_serial = QRadioButton("ILD1420 on a serial port")
        self.laser_group = QButtonGroup(self)
        for button in (self.laser_analog, self.laser_none, self.laser_serial):
            self.laser_group.addButton(button)
        self.laser_port = QLineEdit()
        self.laser_port.setPlaceholderText(port_example())
        self.port_list = SerialPortList()
        self.port_refresh = QPushButton("Look for ports")
        self.port_note = plain_label()
        self.laser_rate = QComboBox()
        for rate in LASER_RATES:
            self.laser_rate.addItem(f"{rate:g} Hz", rate)
        self.laser_jobs = JobControls(session)
        self.test_laser_button = QPushButton("Test laser")
        self.laser_result = rich_label(selectable=True)
        self._build_layout()

        for button in (self.simulator_radio, self.rig_radio, self.soundcard_radio, self.laser_none,
                       self.laser_analog, self.laser_serial):
            button.toggled.connect(self.on_edited)
        for signal in (self.realtime_check.toggled, self.device_list.chosen,
                       self.rate_combo.currentIndexChanged, self.channel_form.edited, self.calibration_form.edited,
                       self.laser_port.textChanged, self.laser_rate.currentIndexChanged):
            signal.connect(self.on_edited)
        self.rig_refresh.clicked.connect(self.on_look_for_rig)
        self.device_refresh.clicked.connect(self.on_refresh_devices)
        self.port_refresh.clicked.connect(self.on_refresh_ports)
        self.port_list.picked.connect(self.laser_port.setText)
        self.test_audio_button.clicked.connect(self.on_test_audio)
        self.test_laser_button.clicked.connect(self.on_test_laser)
        for jobs in (self.audio_jobs, self.laser_jobs):
            jobs.busy_changed.connect(self.on_busy_changed)
        self._restore()

    def _build_layout(self) -> None:
        audio_box = QGroupBox("Sound card")
        grid = QGridLayout(audio_box)
        grid.addWidget(self.simulator_radio, 0, 0, 1, 3)
        grid.addWidget(self.realtime_check, 1, 1, 1, 2)
        grid.addWidget(self.rig_radio, 2, 0, 1, 2)
        grid.addWidget(self.rig_refresh, 2, 2)
        grid.addWidget(self.rig_status, 3, 1, 1, 2)
        grid.addWidget(self.soundcard_radio, 4, 0, 1, 2)
        grid.addWidget(self.device_refresh, 4, 2)
        grid.addWidget(self.device_list, 5, 0, 1, 3)
        grid.addWidget(self.device_advice, 6, 0, 1, 3)
        grid.addWidget(QLabel("Sample rate"), 7, 0)
        grid.addWidget(self.rate_combo, 7, 1)
        grid.setColumnStretch(1, 1)
        grid.setColumnMinimumWidth(0, 24)
        test_row = QHBoxLayout()
        test_row.addWidget(self.test_audio_button)
        test_row.addWidget(self.audio_jobs, 1)
        grid.addLayout(test_row, 8, 0, 1, 3)
        grid.addWidget(self.audio_result, 9, 0, 1, 3)

        wiring = QGroupBox("Wiring and calibration constants")
        wiring_layout = QHBoxLayout(wiring)
        wiring_layout.addWidget(self.channel_form)
        wiring_layout.addWidget(self.calibration_form)
        self.wiring_note = rich_label()

        laser_box = QGroupBox("Laser")
        laser = QGridLayout(laser_box)
        laser.addWidget(self.laser_analog, 0, 0, 1, 3)
        laser.addWidget(self.laser_none, 1, 0, 1, 3)
        laser.addWidget(self.laser_serial, 2, 0, 1, 3)
        laser.addWidget(QLabel("Port"), 3, 0)
        laser.addWidget(self.laser_port, 3, 1)
        laser.addWidget(self.laser_rate, 3, 2)
        laser.addWidget(self.port_list, 4, 0, 1, 3)
        laser.addWidget(self.port_note, 5, 0, 1, 2)
        laser.addWidget(self.port_refresh, 5, 2)
        laser_test = QHBoxLayout()
        laser_test.addWidget(self.test_laser_button)
        laser_test.addWidget(self.laser_jobs, 1)
        laser.addLayout(laser_test, 6, 0, 1, 3)
        laser.addWidget(self.laser_result, 7, 0, 1, 3)
        laser.setColumnStretch(1, 1)

        left = QVBoxLayout()
        left.addWidget(audio_box)
        left.addWidget(wiring)
        left.addWidget(self.wiring_note)
        left.addStretch(1)
        right = QVBoxLayout()
        right.addWidget(laser_box)
        right.addStretch(1)
        layout = QHBoxLayout(self)
        layout.addLayout(left, 3)
        layout.addLayout(right, 2)

    # -- state ------------------------------------------------------------------
    def kind(self) -> str:
        if self.rig_radio.isChecked():
            return RIG
        return SOUNDCARD if self.soundcard_radio.isChecked() else SIMULATOR

    def laser_kind(self) -> str:
        if self.laser_serial.isChecked():
            return SERIAL_LASER
        return NO_LASER if self.laser_none.isChecked() else ANALOG_LASER

    def config(self) -> HardwareConfig:
        """The chosen hardware; AudioConfigError (with the reason) when the channel map is not possible."""
        kind = self.kind()
        common = dict(kind=kind, realtime=self.realtime_check.isChecked(), rig_name=self.rig_name,
                      rig_runtime_dir=self.rig_runtime_dir, laser=self.laser_kind(),
                      laser_port=self.laser_port.text().strip(), laser_rate_hz=self.laser_rate.currentData())
        if kind == SIMULATOR:
            return HardwareConfig(**common)
        if kind == RIG:
            state = self.rig.state if self.rig is not None else None
            return HardwareConfig(**common, sample_rate=state.sample_rate if state else 48000,
                                  channel_map=state.workstation_channel_map if state else RIG_CHANNEL_MAP,
                                  calibration=state.workstation_calibration if state else RIG_CALIBRATION)
        return HardwareConfig(**common, device=self.device_list.choice(), sample_rate=self.rate_combo.currentData(),
                              channel_map=self.channel_form.channel_map(), calibration=self.calibration_form.calibration())

    def missing(self) -> str | None:
        if self.audio_jobs.busy or self.laser_jobs.busy:
            return "Wait for the test to finish, or cancel it."
        kind = self.kind()
        if kind == RIG and self.rig is None:
            return (f"The JACK virtual rig '{self.rig_name}' is not running: start it with 'linpar rig start' and "
                    f"press Look again, or choose the in-process simulator.")
        if kind == SOUNDCARD and self.device_list.choice() is None:
            if self.device_list.currentItem() is not None:      # one that only plays or only records
                return "Choose a sound card that both plays and records: " + self.device_list.advice()
            return "Choose a sound card: " + (self.device_message or "press Refresh list.")
        try:
            config = self.config()
        except AudioConfigError as exc:
            return f"The channel map is not possible: {exc}"
        if config.laser == ANALOG_LASER and config.channel_map.laser_analog is None:
            return "Give the laser's analog input in the channel map, or choose 'No laser'."
        if config.laser == SERIAL_LASER and not config.laser_port:
            return f"Give the laser's serial port (a device such as {port_example()}), or choose another laser."
        return None

    @property
    def busy(self) -> bool:
        return self.audio_jobs.busy or self.laser_jobs.busy

    def commit(self) -> None:
        config = self.config()
        self.state.hardware = config
        saved = {"kind": config.kind, "realtime": config.realtime, "laser": config.laser,
                 "laser_port": config.laser_port, "laser_rate_hz": config.laser_rate_hz,
                 "sample_rate": config.sample_rate}
        if config.kind == SOUNDCARD:
            saved.update(device=config.device.to_dict() if config.device else None,
                         channel_map=config.channel_map.to_dict(), calibration=config.calibration.to_dict())
        self.state.settings.setValue(SETTINGS_KEY, json.dumps(saved))

    def _restore(self) -> None:
        try:
            saved = json.loads(self.state.settings.value(SETTINGS_KEY, "") or "{}")
        except (TypeError, json.JSONDecodeError):      # not text, or not JSON: settings of another program
            saved = {}
        if not isinstance(saved, dict):
            saved = {}
        self.realtime_check.setChecked(bool(saved.get("realtime", True)))
        self.laser_port.setText(str(saved.get("laser_port", "")))
        self.laser_rate.setCurrentIndex(max(0, self.laser_rate.findData(saved.get("laser_rate_hz", 4000.0))))
        self.rate_combo.setCurrentIndex(max(0, self.rate_combo.findData(saved.get("sample_rate", 48000))))
        try:
            self.channel_form.set_map(ChannelMap.from_dict(saved["channel_map"]) if "channel_map" in saved
                                      else ChannelMap(output=0, voltage=0, current=1, laser_analog=2))
            self.calibration_form.set_calibration(Calibration.from_dict(saved["calibration"])
                                                  if "calibration" in saved else RIG_CALIBRATION)
        except AudioConfigError:
            pass        # settings of an older version: start from the defaults
        self._saved_device, note = remembered_device(saved.get("device"))
        self.audio_result.setText(note)
        self.on_refresh_ports()
        {NO_LASER: self.laser_none, SERIAL_LASER: self.laser_serial}.get(saved.get("laser"),
                                                                          self.laser_analog).setChecked(True)
        self.on_look_for_rig()
        # A sound card only when it was the last choice; else the virtual rig (JACK when it runs).
        if saved.get("kind") == SOUNDCARD:
            self.soundcard_radio.setChecked(True)
        elif self.rig is not None:
            self.rig_radio.setChecked(True)
        else:
            self.simulator_radio.setChecked(True)
        self.on_edited()

    # -- slots --------------------------------------------------------------------
    def on_edited(self, *_args) -> None:
        kind = self.kind()
        self.realtime_check.setEnabled(kind == SIMULATOR)
        self.device_list.setEnabled(kind == SOUNDCARD)
        self.device_advice.setText((self.device_list.advice() or self.device_message) if kind == SOUNDCARD else "")
        self.device_refresh.setEnabled(kind == SOUNDCARD and not self.busy)
        self.rate_combo.setEnabled(kind == SOUNDCARD)
        self.channel_form.set_editable(kind == SOUNDCARD)
        self.calibration_form.set_editable(kind == SOUNDCARD)
        if kind != SOUNDCARD:
            rig_state = self.rig.state if (kind == RIG and self.rig is not None) else None
            self.channel_form.set_map(rig_state.workstation_channel_map if rig_state else RIG_CHANNEL_MAP)
            self.calibration_form.set_calibration(rig_state.workstation_calibration if rig_state else RIG_CALIBRATION)
            self.wiring_note.setText("The virtual rig's own wiring and constants (fixed): its amplifier, shunt and "
                                     "laser follow them exactly.")
        else:
            self.wiring_note.setText("Calibrate the chain as a whole (a known voltage, a reference resistor, a "
                                     "gauge block), not from data sheets. The next step corrects the current "
                                     "channel against a reference resistor.")
        if kind == SOUNDCARD and not self.devices and not self.busy and not self.device_message:
            self.on_refresh_devices()
        serial = self.laser_kind() == SERIAL_LASER
        self.laser_port.setEnabled(serial)
        self.laser_rate.setEnabled(serial)
        self.port_list.setEnabled(serial)
        self.test_laser_button.setEnabled(serial and not self.busy)
        self.test_audio_button.setEnabled(not self.busy and not (kind == RIG and self.rig is None))
        self.changed.emit()

    def on_busy_changed(self, _busy: bool) -> None:
        self.on_edited()

    def on_look_for_rig(self) -> None:
        self.rig = find_virtual_rig(self.rig_name, self.rig_runtime_dir)
        if (why_not := virtual_rig_unavailable()) is not None:
            self.rig_radio.setEnabled(False)
            self.rig_refresh.setEnabled(False)
            self.rig_status.setText("Not on this system: " + why_not + ".")
        elif self.rig is None:
            # Not an error: nobody needs the JACK rig to measure. Said plainly, in the page's own colour.
            self.rig_status.setText("not started (to use it: 'linpar rig start' in a terminal, then Look again)")
        else:
            s = self.rig.state
            self.rig_status.setText(coloured(f"running (pid {s.pid}), JACK server '{s.jack_server}', "
                                             f"{s.sample_rate / 1000:g} kHz, driver {s.driver}", OK_COLOUR))
        self.on_edited()

    def on_refresh_devices(self) -> None:
        self.device_message = "looking for sound cards…"
        self.audio_jobs.run(self.session.list_sound_cards(), "Asking PortAudio for its sound cards…",
                            self.on_devices, self.on_devices_failed)

    def on_devices(self, devices) -> None:
        self.devices = list(devices)
        self.device_list.set_devices(self.devices, self.device_list.choice() or self._saved_device)
        self.device_message = ("" if any(d.full_duplex for d in self.devices) else
                               "PortAudio lists no sound card that both plays and records.")
        self.on_edited()

    def on_refresh_ports(self, ports=None) -> None:
        """List the serial ports (a fraction of a second on any system: asked on the GUI thread)."""
        try:
            ports = list_serial_ports() if ports is None else ports
        except OSError as exc:      # the system would not give its list (permissions, a driver): type the name
            ports, why = [], f"The serial ports could not be listed ({exc}); type the port's name."
        else:
            why = "" if ports else (f"No serial port found: plug in the laser's USB adapter and look again, or type "
                                    f"the port's name (such as {port_example()}).")
        self.port_list.set_ports(ports)
        self.port_note.setText(why or f"{len(ports)} port{'s' if len(ports) != 1 else ''} found: click one to use "
                                      f"it.")

    def on_devices_failed(self, message: str) -> None:
        self.device_message = message
        self.audio_result.setText(coloured(message, ERROR_COLOUR))
        self.on_edited()

    def on_test_audio(self) -> None:
        try:
            config = self.config()
        except AudioConfigError as exc:
            self.audio_result.setText(coloured(f"Not tested: {exc}", ERROR_COLOUR))
            return
        self.audio_result.setText("")
        self.audio_jobs.run(self.session.test_audio(config), "Testing the sound card…",
                            lambda text: self.audio_result.setText(coloured("Found: " + text, OK_COLOUR)),
                            lambda message: self.audio_result.setText(coloured("Failed: " + message, ERROR_COLOUR)),
                            lambda: self.audio_result.setText("Test cancelled."))

    def on_test_laser(self) -> None:
        self.laser_result.setText("")
        self.laser_jobs.run(self.session.test_laser(self.config()), "Opening the laser…",
                            lambda text: self.laser_result.setText(coloured("Found: " + text, OK_COLOUR)),
                            lambda message: self.laser_result.setText(coloured("Failed: " + message, ERROR_COLOUR)),
                            lambda: self.laser_result.setText("Test cancelled."))


def plain_label() -> QLabel:
    """A wrapped label for text that names devices (their names may hold '<' or '&', which rich text would eat)."""
    label = QLabel()
    label.setTextFormat(Qt.PlainText)
    label.setWordWrap(True)
    return label
