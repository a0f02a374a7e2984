"""How make test shares the tests among its workers (tests/scheduling.py): files whole, the rig's files as one."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from tests.scheduling import RIG_UNIT, UNIT_SECONDS, is_rig_file, make_scheduler, rig_file_check, unit_of

ROOT = Path(__file__).resolve().parents[1]


def test_the_rigs_files_are_one_unit_and_any_other_file_is_its_own(tmp_path):
    (tmp_path / "test_marked.py").write_text("import pytest\n\npytestmark = pytest.mark.rig\n")
    (tmp_path / "test_fixture.py").write_text("def test_b(virtual_rig, tmp_path):\n    pass\n")
    (tmp_path / "test_plain.py").write_text("def test_c():\n    pass\n")
    assert unit_of("test_marked.py::test_a[1]", tmp_path) == unit_of("test_fixture.py::test_b", tmp_path) == RIG_UNIT
    assert unit_of("test_plain.py::test_c", tmp_path) == "test_plain.py"


def test_a_file_that_only_names_a_function_like_the_fixture_is_not_a_rig_file(tmp_path):
    other = tmp_path / "test_other.py"
    other.write_text("from app.wizard.hardware import find_virtual_rig\n\ndef test_x():\n    find_virtual_rig()\n")
    rig = tmp_path / "test_rig.py"
    rig.write_text("def test_y(virtual_rig):\n    pass\n")
    assert not is_rig_file(str(other)) and is_rig_file(str(rig))


def test_a_rig_test_in_a_file_the_scheduler_does_not_see_stops_the_collection(tmp_path):
    hidden = tmp_path / "test_hidden.py"
    hidden.write_text("def test_z(rig_by_another_name):\n    pass\n")
    marked = SimpleNamespace(path=hidden, fixturenames=("rig_by_another_name",),
                             get_closest_marker=lambda name: object() if name == "rig" else None)
    with pytest.raises(RuntimeError, match="does not see that .*test_hidden.py uses the rig"):
        rig_file_check([marked])


def test_every_long_unit_named_is_a_test_file_of_its_own_or_the_rig():
    """A renamed or moved file would lose its place at the front silently: each name must still be a unit."""
    for name in UNIT_SECONDS:
        if name != RIG_UNIT:
            assert (ROOT / name).is_file(), f"{name} is gone: update tests/scheduling.py UNIT_SECONDS"
            assert unit_of(f"{name}::test", ROOT) == name, f"{name} is a rig file: the rig's unit stands for it"


class FakeWorker:
    """What xdist's scheduler asks of a worker; the tests it is sent go to a log shared by the workers."""

    def __init__(self, name, log):
        self.gateway = SimpleNamespace(id=name)
        self.shutting_down = False
        self.log = log

    def send_runtest_some(self, indices):
        self.log.append((self, list(indices)))

    def shutdown(self):
        self.shutting_down = True


def test_the_longest_units_go_out_first_and_the_rest_in_xdists_order():
    """xdist's own scheduler with ours on it, three workers: the rig's unit and the two longest files start at
    once, one on each worker, although xdist would first send the file of the most tests; the named units follow
    by their seconds, then the others in xdist's order (the most tests first)."""
    named = sorted((seconds, name) for name, seconds in UNIT_SECONDS.items() if name != RIG_UNIT)[::-1]
    longest, second, shortest = named[0][1], named[1][1], named[-1][1]
    rig_file = "tests/instruments/rig/test_rig_cli.py"
    assert is_rig_file(str(ROOT / rig_file))
    collection = ([f"tests/test_few.py::test_{k}" for k in range(3)] + [f"{shortest}::test_a", f"{longest}::test_a"]
                  + [f"tests/test_many.py::test_{k}" for k in range(40)]
                  + [f"{second}::test_a", f"{second}::test_b"] + [f"{rig_file}::test_{k}" for k in range(2)])
    config = SimpleNamespace(rootpath=ROOT, getvalue=lambda name: ["3*popen"] if name == "tx" else "loadfile",
                             option=SimpleNamespace(loadscopereorder=True))
    scheduler = make_scheduler(config, None)
    sent: list = []
    workers = [FakeWorker(f"gw{k}", sent) for k in range(3)]
    for worker in workers:
        scheduler.add_node(worker)
    for worker in workers:
        scheduler.add_node_collection(worker, collection)
    scheduler.schedule()
    assert [(worker, unit_of(collection[indices[0]], ROOT)) for worker, indices in sent[:3]] == [
        (workers[0], RIG_UNIT), (workers[1], longest), (workers[2], second)]
    done = 0
    while done < len(sent):                  # each worker runs what it was sent; xdist sends more as it runs dry
        worker, indices = sent[done]
        for index in indices:
            scheduler.mark_test_complete(worker, index)
        done += 1
    assert [unit_of(collection[indices[0]], ROOT) for _, indices in sent] == [
        RIG_UNIT, longest, second, shortest, "tests/test_many.py", "tests/test_few.py"]
