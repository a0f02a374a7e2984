"""How make test shares the tests among its workers (tests/scheduling.py): files whole, the rig's files as one."""
from __future__ import annotations

from types import SimpleNamespace

import pytest

from tests.scheduling import RIG_UNIT, is_rig_file, rig_file_check, unit_of


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
