"""The GUI while it works: live-panel repaints and event-loop stalls, measuring and diagnosing.

A MainWindow (1400 x 900, offscreen) measures with its wizard on the JACK
virtual rig (the in-process simulator in real time when jackd is missing),
the Measure step's live panels in view. A QTimer at 5 ms notes the gaps
between its ticks: the longest, less the 5 ms, is how long the event loop
stalled. A period of the woofer template lasts 1.37 s, so the measurement
itself offers under one frame a second; to see whether the panels keep up
with a fast frame source while the measurement loads the machine, frames of
the same excitation are also offered at OFFERED_HZ (60 a second), and the
repaints per second are counted. Rows also say how many frames the
measurement delivered, whether the audio stream dropped out while the GUI
painted (xruns, restarts of the averaging: every repaint holds the GIL, which
the audio callback needs), and the longest time a 1 ms Python thread waited
to run (the GIL held by the GUI or the measurement). That thread is the bench's,
not the workstation's, and it takes the GIL a thousand times a second: beside
the stall it lengthens the GUI thread's gaps (three pairs of runs with 60 frames
offered: 26.2, 27.6, 29.2 ms without it, 34.9, 33.3, 62.5 ms with it, the GUI
thread's CPU in the gap 22-26 ms in both). So it runs in the measurement alone
only; the run with frames offered measures its stall without it.

Then a diagnosis in the Model lab of a recording whose laser lags by 100 us
(every candidate refitted in worker processes, the table filled at the end):
the longest stall from the click until the candidates are shown, then the same for a second diagnosis,
whose table replaces the first's. Then four refits that the lab's
catalogue asks for (a checkbox: lr3 in place of lr2 and back). Last, how
long a click from the Measure page to the Results page or the Model lab
holds the GUI thread until the page is painted: the third longest of nine
clicks against the target, the median and the longest beside it, and a
fixed computation timed after each click, which shows how much this machine
itself spreads (MachineControl).
"""
from __future__ import annotations

import os
import shutil
import statistics
import tempfile
import threading
import time
from pathlib import Path

from bench.common import Row, at_most

TICK_MS = 5
OFFERED_HZ = int(os.environ.get("GUI_BENCH_OFFERED_HZ", "60"))
STALL_LIMIT_MS = 50.0
SWITCHES = 9                # page switches measured to each page
SWITCH_PAUSE_S = 0.2        # before each switch (and before each control computation)
REFITS = 4                  # refits of the Model lab asked for by its catalogue's checkboxes
REPAINT_TARGET = 25.0
TIMEOUT_S = 180.0
# Beside each stall: the GUI thread's CPU time in it, what an idle machine would show (time.thread_time).
CPU_ROW = "  the GUI thread's most CPU time between two ticks"


def run(workdir: Path) -> list[Row]:
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication(["gui-bench"])
    from app.jobs.gui_gc import collect_in_gui_thread
    collect_in_gui_thread()               # as the workstation runs (app/jobs/gui_gc.py)
    from app.window.main_window import MainWindow
    from app.window.settings import Settings

    folder = Path(tempfile.mkdtemp(prefix="gui-bench-", dir=workdir))
    settings = Settings(QSettings(str(folder / "settings.ini"), QSettings.IniFormat))
    settings.qsettings.setValue("measure/out_dir", str(folder / "measurements"))
    settings.qsettings.setValue("archive/root", str(folder / "archive"))     # never the user's archive
    rig = _start_rig(folder) if shutil.which("jackd") else None
    try:
        window = MainWindow(settings)
        if rig is not None:
            # The wizard looks for the bench's own rig, not the user's.
            window.wizard.hardware_page.rig_name = rig.name
            window.wizard.hardware_page.rig_runtime_dir = str(rig.paths.directory.parent)
        window.resize(1400, 900)
        window.show()
        rows = _measuring(app, window, rig)
        rows += _diagnosing(app, window, folder)
        rows += _refitting(app, window)
        rows += _switching(app, window)
        window.close()
    finally:
        if rig is not None:
            from instruments.audio import portaudio
            from instruments.rig.manager import stop_rig
            portaudio.release()
            stop_rig(rig.name, runtime_dir=rig.paths.directory.parent)
    return rows


def _start_rig(folder: Path):
    from instruments.rig.manager import start_rig
    return start_rig(f"linpar-gui-bench-{os.getpid()}", runtime_dir=folder / "rig", seed=3)


class StallMeter:
    """Gaps between the ticks of a TICK_MS QTimer, and (`probe_gil`) between the wake-ups of a 1 ms Python thread."""

    def __init__(self, probe_gil: bool = True):
        from PySide6.QtCore import QTimer
        self.timer = QTimer()
        self.timer.setTimerType(self.timer.timerType().PreciseTimer)
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(self._tick)
        self.gaps: list[float] = []
        self.cpu_gaps: list[float] = []       # the GUI thread's CPU time in each gap (time.thread_time)
        self.thread_gaps: list[float] = []
        self._last = self._last_cpu = 0.0
        self._stop = threading.Event()
        self.probe_gil = probe_gil

    def _tick(self) -> None:
        now, cpu = time.perf_counter(), time.thread_time()
        self.gaps.append(now - self._last)
        self.cpu_gaps.append(cpu - self._last_cpu)
        self._last, self._last_cpu = now, cpu

    def _spin(self) -> None:
        last = time.perf_counter()
        while not self._stop.is_set():
            time.sleep(0.001)
            now = time.perf_counter()
            self.thread_gaps.append(now - last)
            last = now

    def __enter__(self) -> "StallMeter":
        self._last, self._last_cpu = time.perf_counter(), time.thread_time()
        self.timer.start()
        self._thread = threading.Thread(target=self._spin, daemon=True) if self.probe_gil else None
        if self._thread is not None:
            self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.timer.stop()
        self._stop.set()
        if self._thread is not None:
            self._thread.join()

    @property
    def stall_ms(self) -> float:
        return self.stall_between(0, len(self.gaps))

    def stall_between(self, first: int, last: int) -> float:
        """The longest stall among the ticks first..last-1 (indices into gaps)."""
        return max(0.0, 1e3 * max(self.gaps[first:last], default=0.0) - TICK_MS)

    @property
    def stall_cpu_ms(self) -> float:
        return self.stall_cpu_between(0, len(self.cpu_gaps))

    def stall_cpu_between(self, first: int, last: int) -> float:
        """The GUI thread's most CPU time between two ticks first..last-1: the stall an idle machine would see
        (the wall-time stall on a shared machine also counts the other processes' turns)."""
        return 1e3 * max(self.cpu_gaps[first:last], default=0.0)

    @property
    def thread_wait_ms(self) -> float:
        return 1e3 * max(self.thread_gaps, default=0.0)


def _wait(app, condition, timeout_s: float = TIMEOUT_S) -> bool:
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        app.processEvents()
        time.sleep(0.002)
    return True


def _offered_frames(template, level: float):
    """Frames of the measurement's own excitation, to offer the panels faster than periods come."""
    from analysis.drivers import load_driver
    from analysis.live import LiveAccumulator
    from analysis.synthesis import ChannelNoise, synthesize_recording
    from app.wizard.plans import multitone_for

    driver = load_driver("paper")
    mt = multitone_for(template).scaled(rms=level)
    rec = synthesize_recording(driver.model(), driver.parameters, mt.waveform, mt.excited_bins, mt.sample_rate, 6, 0,
                               ChannelNoise(1e-4, 1e-5, 1e-8), seed=2)
    acc = LiveAccumulator(rec.sample_rate, rec.period_samples, mt.excited_bins)
    signals = ("voltage", "current", "displacement")
    return [acc.add_period({s: rec.periods(s)[k] for s in signals}) for k in range(6)][1:]


def _measuring(app, window, rig) -> list[Row]:
    """Two measurements: the panels fed by the measurement alone, then with frames offered at OFFERED_HZ too."""
    from app.wizard.calibration import Corrections
    from app.wizard.hardware import RIG, SIMULATOR, HardwareConfig
    from app.wizard.plans import TEMPLATES, DriverInfo

    wizard = window.wizard
    template = TEMPLATES["woofer"]
    level = 1.0
    where = "the JACK virtual rig" if rig is not None else "the in-process simulator (real time; no jackd)"
    if rig is not None:
        hardware = HardwareConfig(kind=RIG, rig_name=rig.name, rig_runtime_dir=str(rig.paths.directory.parent),
                                  sample_rate=rig.state.sample_rate, channel_map=rig.state.workstation_channel_map,
                                  calibration=rig.state.workstation_calibration)
    else:
        hardware = HardwareConfig(kind=SIMULATOR, realtime=True)
    state = wizard.state
    state.driver = DriverInfo("bench", "1", 0.0133, 4.0, template.key)
    state.hardware = hardware
    state.corrections = Corrections(source="exact" if rig is not None else "none")
    state.level_v, state.level_reason, state.level_words = level, "the bench's level", "bench"
    window.pages.setCurrentWidget(wizard)
    wizard.go_to(4)
    _wait(app, lambda: False, 0.5)          # the window's first paint is its showing's, not the measurement's
    page = wizard.measure_page
    alone = _measure_once(app, wizard, page, template, [], 0, probe_gil=True)
    offered = _measure_once(app, wizard, page, template, _offered_frames(template, level), OFFERED_HZ,
                            probe_gil=False)        # the module doc: the probe lengthens the stalls beside it
    for run_ in (alone, offered):
        if "failed" in run_:
            return [Row(f"gui: the measurement on {where} failed: {run_['failed']}", 0.0, "", "", False)]
    return [
        Row(f"gui: measuring on {where}, {template.n_periods} periods of {template.period_samples}",
            alone["averaging"], "s", "", None),
        Row("gui: frames the measurement delivered per second", alone["frames"], "/s", "", None),
        at_most("gui: longest event-loop stall while averaging", alone["stall"], "ms", STALL_LIMIT_MS),
        Row(CPU_ROW, alone["stall_cpu"], "ms", "", None),
        at_most("gui: longest stall from the last period to the result shown", alone["handoff"], "ms",
                STALL_LIMIT_MS),
        Row(CPU_ROW, alone["handoff_cpu"], "ms", "", None),
        Row("gui: longest wait of a 1 ms Python thread while measuring (GIL)", alone["thread"], "ms", "", None),
        at_most("gui: xruns and restarts of the averaging", alone["xruns"], "", 0),
        Row(f"gui: live-panel repaints per second, frames also offered at {OFFERED_HZ}/s", offered["paints"], "/s",
            f">= {REPAINT_TARGET:g}", offered["paints"] >= REPAINT_TARGET),
        at_most(f"gui: longest event-loop stall while averaging, {OFFERED_HZ}/s offered", offered["stall"], "ms",
                STALL_LIMIT_MS),
        Row(CPU_ROW, offered["stall_cpu"], "ms", "", None),
        at_most(f"gui: xruns and restarts of the averaging, {OFFERED_HZ}/s offered", offered["xruns"], "", 0),
    ]


def _measure_once(app, wizard, page, template, offered: list, offered_hz: int, probe_gil: bool) -> dict:
    from PySide6.QtCore import QTimer

    sent = [0]
    feeder = QTimer()
    feeder.setInterval(round(1000 / max(offered_hz, 1)))
    feeder.timeout.connect(lambda: (page.panels.set_frame(offered[sent[0] % len(offered)]),
                                    sent.__setitem__(0, sent[0] + 1)))
    finished, failed = [], []
    on_finished = finished.append
    on_failed = lambda job, message: failed.append(message)      # noqa: E731
    wizard.measurement_finished.connect(on_finished)
    window, shown = wizard.window(), []
    on_shown = shown.append
    window.measurement_shown.connect(on_shown)
    page.jobs.runner.failed.connect(on_failed)
    paints_before, frames_before = len(page.panels.paint_times), page.panels.frames_received
    with StallMeter(probe_gil) as meter:
        page.start_button.click()
        started = time.monotonic()
        if offered:
            feeder.start()
        _wait(app, lambda: page.panels.frames_received - frames_before - sent[0] >= template.n_periods
              or finished or failed)
        feeder.stop()
        averaging = time.monotonic() - started
        averaged_ticks = len(meter.gaps)
        ok = _wait(app, lambda: finished or failed)
        # The hand-off to the Results page, the Model lab and QA, in turns of its own: all of it, however long the
        # machine's load makes it, then what it left to lay out.
        _wait(app, lambda: shown or failed)
        _wait(app, lambda: False, 0.3)
    wizard.measurement_finished.disconnect(on_finished)
    window.measurement_shown.disconnect(on_shown)
    page.jobs.runner.failed.disconnect(on_failed)
    if not ok or failed:
        return {"failed": failed[0] if failed else "timed out"}
    frames = page.panels.frames_received - frames_before - sent[0]
    return {"averaging": averaging, "frames": frames / averaging,
            "paints": (len(page.panels.paint_times) - paints_before) / averaging,
            "stall": meter.stall_between(0, averaged_ticks),
            "stall_cpu": meter.stall_cpu_between(0, averaged_ticks),
            "handoff": meter.stall_between(averaged_ticks, len(meter.gaps)),
            "handoff_cpu": meter.stall_cpu_between(averaged_ticks, len(meter.cpu_gaps)),
            "thread": meter.thread_wait_ms, "xruns": _audio_stats(finished[0].path)}


def _audio_stats(wav: Path) -> float:
    from analysis.recording.format import read_recording
    capture = read_recording(wav).extra.get("audio_capture", {})
    return float(sum(capture.get(k, 0) for k in ("input_overflows", "input_underflows", "output_underflows",
                                                 "output_overflows", "restarts")))


def _diagnosing(app, window, folder: Path) -> list[Row]:
    from analysis.drivers import load_driver
    from analysis.effects import get_effect
    from analysis.multitone import design_multitone
    from analysis.recording.format import write_recording
    from analysis.synthesis import ChannelNoise, synthesize_recording

    driver = load_driver("paper")
    model = driver.model()
    model = model.with_effects(model.effects + (get_effect("delay-x"),))
    mt = design_multitone(48000, 16384, 5.0, 10000.0, rms=1.0)
    rec = synthesize_recording(model, {**driver.parameters, "tau_x": 100e-6}, mt.waveform, mt.excited_bins, 48000,
                               8, 1, ChannelNoise(1e-4, 1e-4, 1e-8), seed=3,
                               driver={"name": "laser 100 us late", "sd_m2": driver.sd_m2})
    wav, _ = write_recording(folder / "laser-late", rec)
    shown = []
    window.analysis_shown.connect(shown.append)
    window.open_path(wav)
    if not _wait(app, lambda: shown):
        return [Row("gui: the recording for the diagnosis was not analysed in time", 0.0, "", "", False)]
    lab = window.model_lab
    window.pages.setCurrentWidget(lab)
    _wait(app, lambda: False, 0.5)          # the page's first paint is the tab switch's, not the diagnosis's
    done = []
    lab.diagnosis_shown.connect(done.append)
    runs = []
    for _ in range(2):          # the second fills a table that holds the first's candidates
        with StallMeter() as meter:
            started = time.monotonic()
            lab.candidates.diagnose_button.click()
            ok = _wait(app, lambda: len(done) > len(runs))
            took = time.monotonic() - started
            _wait(app, lambda: False, 0.3)          # what the GUI does right after showing the table counts too
        if not ok:
            return [Row("gui: the diagnosis did not finish in time", 0.0, "", "", False)]
        runs.append((took, meter))
    (took, meter), (_, again) = runs
    return [Row("gui: diagnosis in the Model lab, click to candidates shown", took, "s", "", None),
            at_most("gui: longest event-loop stall during the diagnosis", meter.stall_ms, "ms", STALL_LIMIT_MS),
            Row(CPU_ROW, meter.stall_cpu_ms, "ms", "", None),
            at_most("gui: longest event-loop stall during a second diagnosis", again.stall_ms, "ms", STALL_LIMIT_MS),
            Row(CPU_ROW, again.stall_cpu_ms, "ms", "", None)]


def _refitting(app, window) -> list[Row]:
    """A checkbox of the Model lab's catalogue changes the model (lr3 in place of the diagnosis' inductance, then
    back): the refit runs on the lab's worker process (app.jobs.refit_process), then the lab and the Results page
    show the new version. The longest stall of the REFITS refits, from the click until the version is shown and
    0.3 s after; and how long the user waited, click to version shown."""
    lab = window.model_lab
    window.pages.setCurrentWidget(lab)
    _wait(app, lambda: False, 0.5)
    base = lab.current.fitted.fit.model.effect_ids
    other = tuple("lr3" if effect_id == "lr2" else effect_id for effect_id in base)
    if other == base:
        other = base + ("lr3",)
    stalls, cpus, waits = [], [], []
    for checked in (other, base) * (REFITS // 2):
        added = []
        lab.version_added.connect(added.append)
        with StallMeter() as meter:
            clicked = time.perf_counter()
            lab.on_selection_changed(checked)
            ok = _wait(app, lambda: added)
            waits.append(time.perf_counter() - clicked)
            _wait(app, lambda: False, 0.3)
        lab.version_added.disconnect(added.append)
        if not ok:
            return [Row("gui: a refit in the Model lab was not shown in time", 0.0, "", "", False)]
        stalls.append(meter.stall_ms)
        cpus.append(meter.stall_cpu_ms)
    return [at_most(f"gui: longest event-loop stall during a refit in the Model lab (of {len(stalls)})",
                    max(stalls), "ms", STALL_LIMIT_MS),
            Row(CPU_ROW, max(cpus), "ms", "", None),
            Row(f"  a refit, click to version shown, median of {len(waits)}", statistics.median(waits), "s", "", None),
            Row("  the longest of them", max(waits), "s", "", None)]


def _switching(app, window) -> list[Row]:
    """Clicking from the Measure page to a page of plots, painted, SWITCHES times: the third longest against the
    target (the two longest set aside: the machine's own spread, MachineControl, reaches a switch or two of nine;
    a page slow in three of nine fails), the median and the longest beside it, and the fixed computation timed
    right after the longest switch."""
    rows = []
    control = MachineControl()
    for page, name in ((window.results, "Results"), (window.model_lab, "Model lab")):
        took, cpu, after = [], [], []
        for _ in range(SWITCHES):
            window.pages.setCurrentWidget(window.wizard)
            _wait(app, lambda: False, SWITCH_PAUSE_S)
            started, started_cpu = time.perf_counter(), time.thread_time()
            window.pages.setCurrentWidget(page)
            window.repaint()                    # painted now, not in a later turn
            app.processEvents()
            took.append(1e3 * (time.perf_counter() - started))
            cpu.append(1e3 * (time.thread_time() - started_cpu))
            _wait(app, lambda: False, SWITCH_PAUSE_S)
            after.append(control.measure())
        by_length = sorted(range(SWITCHES), key=took.__getitem__)
        third, longest = by_length[-3], by_length[-1]
        rows.append(at_most(f"gui: showing the {name} page (3rd longest of {SWITCHES} switches)", took[third], "ms",
                            STALL_LIMIT_MS))
        rows.append(Row("  the GUI thread's CPU time in it", cpu[third], "ms", "", None))
        rows.append(Row(f"  the median of the {SWITCHES}, wall", statistics.median(took), "ms", "", None))
        rows.append(Row("  the longest, wall", took[longest], "ms", "", None))
        rows.append(Row("  the longest, the GUI thread's CPU time", cpu[longest], "ms", "", None))
        rows.append(Row("  the fixed computation right after the longest, CPU time", after[longest], "ms", "", None))
    rows.append(Row(f"gui: the machine: the fixed computation after each switch, median of {len(control.cpu_ms)}",
                    statistics.median(control.cpu_ms), "ms", "", None))
    rows.append(Row("  its longest, CPU time: the machine's own spread", max(control.cpu_ms), "ms", "", None))
    return rows


class MachineControl:
    """The same fixed computation, pure Python, timed in CPU time after the same pause as a page switch.

    On the 2-core virtual machine this bench was tuned on, a computation of ~10 ms of CPU time took up to 40 ms
    after no pause and up to 72 ms after a 0.2 s pause (100 runs each, nothing else running): the host lends the
    virtual cores to others, and a thread's CPU time counts time the core was not its. The longest of a few
    switches measures that spread as much as the page; the third longest of nine, the page. These rows show the
    spread at the time of the run, and the computation right after the longest switch, so that a long switch can
    be told from a slow machine."""

    LOOP = 250_000          # ~10 ms of CPU time on that machine

    def __init__(self):
        self.cpu_ms: list[float] = []

    def measure(self) -> float:
        """Run the computation once; its CPU time in ms (also kept in cpu_ms)."""
        started = time.thread_time()
        total = 0
        for i in range(self.LOOP):
            total += i
        self.cpu_ms.append(1e3 * (time.thread_time() - started))
        return self.cpu_ms[-1]


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        for row in run(Path(tmp)):
            ok = "" if row.ok is None else ("yes" if row.ok else "NO")
            print(f"{row.name:<72}{row.value:>10.3f} {row.unit:<4}{row.target:>8}  {ok}")
