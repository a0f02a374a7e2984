"""Analysis core and model lab: speed and memory on the standard recording."""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tracemalloc
from pathlib import Path

from bench.common import Row, at_most, child_time, compiled_env, median_time, standard_recording


def run(workdir: Path) -> list[Row]:
    from analysis.diagnosis.candidates import diagnose
    from analysis.diagnosis.sites import localise
    from analysis.fit.least_squares import FitData
    from analysis.model.composed import Model
    from analysis.parallel import fit_executor
    from analysis.pipeline import analyze_path
    from analysis.recording.format import read_recording
    from analysis.spectra import estimate_spectra

    path = standard_recording(workdir)
    rows = []
    t_analysis = median_time(lambda: analyze_path(path), repeats=7)
    rows.append(at_most("analysis in process (read, spectra, fit, derived)", t_analysis, "s", 0.3))

    rows += model_part_rows(path)

    cmd = [sys.executable, "-m", "app.cli", "analyze", str(path), "--json"]
    t_process = median_time(lambda: subprocess.run(cmd, check=True, capture_output=True), repeats=5)
    rows.append(at_most("whole 'linpar analyze' process", t_process, "s", 1.5))
    rows += startup_rows(path)

    rec = read_recording(path)
    samples = rec.data.size
    del rec
    tracemalloc.start()
    analyze_path(path)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    ratio = peak / (samples * 8)
    rows.append(at_most("peak memory / samples in float64", ratio, "x", 4.0))

    data = FitData.from_spectra(estimate_spectra(read_recording(path)))
    textbook = Model((), with_displacement=True)
    with fit_executor() as pool:
        t_diag = median_time(lambda: diagnose(data, textbook, executor=pool), repeats=5)
        result = diagnose(data, textbook, executor=pool, locate=False)
        t_sites = median_time(lambda: localise(data, result.final, pool), repeats=5)
    rows.append(at_most("diagnosis, whole catalogue from the textbook model, and sites", t_diag, "s", 3.0))
    rows.append(Row("  of which the six sites' corrections of the final model", t_sites, "s", "", None))
    t_serial = median_time(lambda: diagnose(data, textbook), repeats=1, warmup=0)
    rows.append(Row("  the same diagnosis on one core", t_serial, "s", "", None))
    rows += diagnosis_rows(data)
    return rows


def model_part_rows(standard: Path) -> list[Row]:
    """The model part of the uncertainties (analysis.fit.model_uncertainty). On the standard recording the
    model describes the data: nothing is refitted, the full result is the statistical one. On a realistic
    woofer (tests/realistic_drivers.py) it refits the other forms of the inductance and creep, and the model with
    each effect of analysis.fit.added_physics added: the GUI shows
    the statistical result at once and the parts after these refits (in its background); the CLI waits."""
    from analysis.fit.model_uncertainty import model_uncertainty
    from analysis.pipeline import analyze_path, analyze_recording
    from tests.realistic_drivers import realistic_recording

    clean = analyze_path(standard)
    rows = [at_most("model part of the standard recording (nothing to refit)",
                    median_time(lambda: model_uncertainty(clean), repeats=7), "s", 0.01)]
    woofer = realistic_recording("woofer", 0)
    statistical = analyze_recording(woofer)
    rows.append(Row("realistic woofer: statistical result (what the GUI shows first)",
                    median_time(lambda: analyze_recording(woofer), repeats=3), "s", "", None))
    rows.append(Row("realistic woofer: its model part's refits (in the GUI's background)",
                    median_time(lambda: model_uncertainty(statistical), repeats=3, warmup=0), "s", "", None))
    rows.append(Row("realistic woofer: the full result (statistical and model part)",
                    median_time(lambda: model_uncertainty(analyze_recording(woofer)), repeats=3, warmup=0), "s",
                    "", None))
    return rows


# The floor of `linpar analyze`: a process that reads the recording and takes its FFTs, and nothing else; with the
# one BLAS thread linpar's command sets itself (app/blas_threads.py), so that both are timed alike.
FLOOR = ("import sys\n"
         "from app.blas_threads import one_blas_thread\n"
         "one_blas_thread()\n"
         "from analysis.recording.format import read_recording\n"
         "from analysis.spectra import estimate_spectra\n"
         "estimate_spectra(read_recording(sys.argv[1]))")


STARTUP_PAIRS = 15     # runs of the floor and of the command, taken in turns


def startup_rows(path: Path) -> list[Row]:
    """`linpar analyze REC --json` as a whole process against the floor (issue 28: at most 1.3 times it), in CPU
    time (user + sys of the child: what an idle machine's wall time would be) and in wall time. The two are run in
    turns, STARTUP_PAIRS times, and their medians compared: run as two blocks of 9, the ratio of three runs on an
    idle machine was 1.27-1.37, the machine's pace drifting between the blocks. Both with linpar's modules
    compiled once into the benchmark's folder (compiled_env), as an installed copy runs: under
    PYTHONDONTWRITEBYTECODE every module changed since its bytecode was written was compiled again at each
    start, the command's many more than the floor's."""
    env = compiled_env(dict(os.environ), path.parent)
    floor_cmd = [sys.executable, "-c", FLOOR, str(path)]
    command = [sys.executable, "-m", "app.cli", "analyze", str(path), "--json"]
    for cmd in (floor_cmd, command):
        child_time(cmd, env)            # compiles what has changed, once
    floor, whole = [], []
    for _ in range(STARTUP_PAIRS):
        floor.append(child_time(floor_cmd, env))
        whole.append(child_time(command, env))
    floor_cpu, floor_wall = (statistics.median(times) for times in zip(*floor))
    cpu, wall = (statistics.median(times) for times in zip(*whole))
    return [at_most("whole 'linpar analyze --json' / read+FFT floor, CPU time", cpu / floor_cpu, "x", 1.3),
            Row(f"  CPU {cpu:.3f} s against {floor_cpu:.3f} s; wall {wall:.3f} s against {floor_wall:.3f} s "
                f"(medians of {STARTUP_PAIRS})", wall / floor_wall, "x", "", None)]


def diagnosis_rows(clean_data) -> list[Row]:
    """The model lab's two cases (issue 30): a clean recording, the default model already explains it (one
    round, nothing missing), and a real-like woofer, several physics at once none in the catalogue's exact
    form (65,536-sample periods, a path of steps). Wall time on the pool, then the CPU time of the same
    diagnosis on one core (the median of as many runs): on a machine shared with others the wall time
    measures the others too."""
    import time

    from analysis.diagnosis import diagnose
    from analysis.effects import parse_effects
    from analysis.fit import FitData
    from analysis.model import Model
    from analysis.parallel import fit_executor
    from analysis.spectra import estimate_spectra
    from tests.real_like import real_like_recording

    default = Model(parse_effects("lr2,creep-log"))
    real_like = FitData.from_spectra(estimate_spectra(real_like_recording()))
    rows = []
    for name, data, limit, repeats in (("clean recording, default model", clean_data, 1.0, 5),
                                       ("real-like woofer recording, default model", real_like, 3.0, 3)):
        with fit_executor() as pool:
            wall = median_time(lambda: diagnose(data, default, executor=pool), repeats=repeats)
        cpu = median_time(lambda: diagnose(data, default), repeats=repeats, warmup=0, clock=time.process_time)
        steps = diagnose(data, default).steps_taken
        rows.append(at_most(f"diagnosis of a {name} ({steps} step(s)), and sites", wall, "s", limit))
        rows.append(Row(f"  its CPU time on one core (median of {repeats})", cpu, "s", "", None))
    return rows
