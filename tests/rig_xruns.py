"""`linpar measure` on the JACK rig, measured again after an xrun nobody injected.

On a loaded 2-core machine the rig's JACK server now and then reports an xrun by itself (a client was
late). With the serial laser an xrun ends the measurement (a large-signal plan's step too), which
tests/instruments/measurement/test_measure_rig.py tests on its own; a test that injects no xrun measures
again instead of failing on the host's scheduling.
"""
from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Callable

from app.cli import main

UNINJECTED_XRUN = "the audio driver reported an xrun"
ATTEMPTS = 3


def measure_until_no_xrun(argv_into: Callable[[Path], list[str]], folder: Path) -> tuple[int, str, str, Path]:
    """Runs `linpar` with argv_into(output folder), each attempt into a folder of its own under `folder`,
    until it ends without an xrun (at most ATTEMPTS times): its exit code, stdout, stderr and that folder."""
    for attempt in range(ATTEMPTS):
        out_folder = folder / f"attempt{attempt}"
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv_into(out_folder))
        if code == 0 or UNINJECTED_XRUN not in err.getvalue():
            break
    return code, out.getvalue(), err.getvalue(), out_folder
