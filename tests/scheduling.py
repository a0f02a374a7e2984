"""How `make test` shares the tests among its worker processes (pytest-xdist, `--dist loadfile`).

A test file goes to one worker whole, so that its module fixtures (synthetic
recordings, identifications, process pools) are built once. Every file that
uses the JACK virtual rig goes, with the others of its kind, to one worker,
and their tests run one after another as in a serial run: two real-time rigs
on the same two cores would each miss their deadlines, and one rig fixture
per worker would start two JACK servers.

The longest units go out first (longest-processing-time first): xdist hands the
units out in order of their number of tests, which sent the rig's unit out
fifth but a one-test file of 71 s last of 170, so that two workers sat idle
at the end while the third ran it. UNIT_SECONDS names the long units with
their seconds in an idle run of `make test` (its --durations list); a file
not named costs 0 and keeps xdist's order after them. A name that no longer
exists is caught by tests/test_scheduling.py.

xdist's own way to keep tests together (`xdist_group` with `--dist
loadgroup`) does nothing with pytest 9.2: it renames the tests' ids, which
pytest no longer reads (pytest-xdist issue 1386). The controller, which
collects nothing, sees only those ids; so a rig file is known by its text,
and each worker checks at collection that every test using the rig is in
such a file (rig_file_check), so that a rig test is never missed silently.
"""
from __future__ import annotations

import functools
import re
from pathlib import Path

RIG_UNIT = "the JACK rig's tests"
# The rig fixture as a test's argument, or the rig mark; find_virtual_rig and the like are other names.
_USES_RIG = re.compile(r"(?<![\w.])virtual_rig\b|\bmark\.rig\b")


# Seconds of the longest units; the order matters, not the precision. The rig's: run alone before one BLAS thread
# per process (tests/conftest.py; 7 min 9 s after, at load ~14); test_large_signal.py: its CPU with one BLAS
# thread (162 s before); the others: an idle `make test` on main 0769005 (--durations=40, each file's tests summed).
UNIT_SECONDS = {
    RIG_UNIT: 596.0,
    "tests/analysis/large_signal/test_large_signal.py": 45.0,
    "tests/reliability/test_fuzz_numbers.py": 127.0,
    "tests/analysis/diagnosis/test_first_site.py": 71.0,
    "tests/reliability/test_fuzz_archive.py": 60.0,
    "tests/app/cli/test_large_signal.py": 41.0,
    "tests/reliability/test_three_stations.py": 33.0,
    "tests/app/wizard/test_wizard.py": 26.0,
    "tests/app/test_feedback.py": 22.0,
    "tests/instruments/measurement/test_laser_gaps.py": 19.0,
    "tests/app/large_signal/test_page.py": 19.0,
    "tests/app/cli/test_lpm_import.py": 19.0,
    "tests/analysis/report/test_report.py": 19.0,
    "tests/analysis/test_api.py": 14.0,
    "tests/app/test_real_window.py": 10.0,
    "tests/test_wheel.py": 10.0,
}


def longest_first(queue) -> None:
    """Moves the unit of the most UNIT_SECONDS to the front of xdist's queue (an ordered dict, unit -> tests);
    among units of equal seconds (those not named) the first stays first."""
    unit = max(queue, key=lambda name: UNIT_SECONDS.get(name, 0.0))
    queue.move_to_end(unit, last=False)


@functools.cache
def is_rig_file(path: str) -> bool:
    try:
        return _USES_RIG.search(Path(path).read_text(encoding="utf-8")) is not None
    except OSError:
        return False


def uses_rig(item) -> bool:
    return item.get_closest_marker("rig") is not None or "virtual_rig" in getattr(item, "fixturenames", ())


def rig_file_check(items) -> None:
    """Every test that uses the rig lives in a file is_rig_file finds (else the scheduler would run it beside
    another rig test)."""
    missed = sorted({str(item.path) for item in items if uses_rig(item) and not is_rig_file(str(item.path))})
    if missed:
        raise RuntimeError(f"tests/scheduling.py does not see that {', '.join(missed)} uses the rig: "
                           f"name its fixture virtual_rig or mark its tests with pytest.mark.rig")


def unit_of(nodeid: str, rootpath: Path) -> str:
    """The unit of work a test belongs to: its file, or RIG_UNIT."""
    path = nodeid.split("::", 1)[0]
    return RIG_UNIT if is_rig_file(str(rootpath / path)) else path


def make_scheduler(config, log):
    """xdist's loadfile, with every rig file in one unit and the longest units handed out first."""
    from xdist.scheduler import LoadFileScheduling

    class FilesAndTheRig(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return unit_of(nodeid, Path(config.rootpath))

        def _assign_work_unit(self, node) -> None:
            # xdist (3.8) hands out the first unit of self.workqueue; put the longest one there.
            if self.workqueue:
                longest_first(self.workqueue)
            super()._assign_work_unit(node)

    return FilesAndTheRig(config, log)
