"""`linpar measure` on the JACK rig, measured again when the host did not keep up and nothing was injected.

On a loaded 2-core machine the rig's JACK server now and then reports an xrun by itself (a client was
late). With the serial laser an xrun ends the measurement (a large-signal plan's step too), which
tests/instruments/measurement/test_measure_rig.py tests on its own. A large-signal plan also stops when a
step's displacement did not repeat from period to period (analysis/large_signal/stepping.py, tested on its
own in tests/analysis/large_signal/test_displacement_repeat.py) twice in a row: on the rig that happened
once, on a fresh CI machine with nothing injected, and the product says "a busy machine?" and "measure
again". A test that injects neither measures again, as the product says, instead of failing on the host's
scheduling; it fails when every attempt ends so.
"""
from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Callable

from app.cli import main

UNINJECTED_XRUN = "the audio driver reported an xrun"
BUSY_MACHINE = "was not placed right in time (a busy machine?)"
ATTEMPTS = 3


def host_did_not_keep_up(err: str) -> bool:
    """Whether what ended the run (its "linpar: error:" line, not a step measured again before) was an xrun or
    a laser stream misplaced in time: the host's scheduling."""
    errors = [line for line in err.splitlines() if line.startswith("linpar: error:")]
    return any(UNINJECTED_XRUN in line or BUSY_MACHINE in line for line in errors)


def measure_until_no_xrun(argv_into: Callable[[Path], list[str]], folder: Path) -> tuple[int, str, str, Path]:
    """Runs `linpar` with argv_into(output folder), each attempt into a folder of its own under `folder`,
    until it ends without the host falling behind (at most ATTEMPTS times): its exit code, stdout, stderr and
    that folder."""
    for attempt in range(ATTEMPTS):
        out_folder = folder / f"attempt{attempt}"
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv_into(out_folder))
        if code == 0 or not host_did_not_keep_up(err.getvalue()):
            break
    return code, out.getvalue(), err.getvalue(), out_folder
