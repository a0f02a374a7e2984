"""How `make test` shares the tests among its worker processes (pytest-xdist, `--dist loadfile`).

A test file goes to one worker whole, so that its module fixtures (synthetic
recordings, identifications, process pools) are built once. Every file that
uses the JACK virtual rig goes, with the others of its kind, to one worker,
and their tests run one after another as in a serial run: two real-time rigs
on the same two cores would each miss their deadlines, and one rig fixture
per worker would start two JACK servers.

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
    """xdist's loadfile, with every rig file in one unit."""
    from xdist.scheduler import LoadFileScheduling

    class FilesAndTheRig(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return unit_of(nodeid, Path(config.rootpath))

    return FilesAndTheRig(config, log)
