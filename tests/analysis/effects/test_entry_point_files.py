"""The look at the packages' metadata before importlib.metadata (analysis/effects/entry_point_files.py): it may
answer "maybe" when there is nothing, never "no" when importlib.metadata would find an entry point."""
from __future__ import annotations

import importlib.metadata
import sys
import zipfile

import pytest

from analysis.effects.entry_point_files import may_declare

GROUP = "linpar.effects"


def dist_info(folder, name="my_effects-1.0.dist-info", entry_points="[linpar.effects]\ncable = m:EFFECT\n"):
    dist = folder / name
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: my-effects\nVersion: 1.0\n", encoding="utf-8")
    if entry_points is not None:
        (dist / "entry_points.txt").write_text(entry_points, encoding="utf-8")
    return dist


@pytest.fixture
def only(monkeypatch):
    """sys.path set to the given folders alone."""
    return lambda *folders: monkeypatch.setattr(sys, "path", [str(f) for f in folders])


def test_a_package_naming_the_group_is_found(tmp_path, only):
    dist_info(tmp_path / "site")
    only(tmp_path / "site", tmp_path / "not-there")
    assert may_declare(GROUP)
    assert [ep.name for ep in importlib.metadata.entry_points(group=GROUP)] == ["cable"]


def test_packages_of_other_groups_or_none_are_not(tmp_path, only):
    dist_info(tmp_path / "site", entry_points="[console_scripts]\ntool = m:main\n")
    dist_info(tmp_path / "site", "old-2.0.egg-info", entry_points=None)
    (tmp_path / "site" / "legacy-1.0.egg-info").write_text("Metadata-Version: 1.0\n", encoding="utf-8")   # a file
    only(tmp_path / "site", tmp_path / "not-there")
    assert not may_declare(GROUP)
    assert list(importlib.metadata.entry_points(group=GROUP)) == []


def test_an_egg_folders_metadata_is_read(tmp_path, only):
    egg = tmp_path / "my_effects-1.0-py3.11.egg"
    dist_info(egg, "EGG-INFO")
    only(egg)
    assert may_declare(GROUP)


def test_a_zip_archive_on_the_path_is_left_to_importlib_metadata(tmp_path, only):
    with zipfile.ZipFile(tmp_path / "packages.zip", "w") as archive:
        archive.writestr("x.py", "")
    only(tmp_path / "packages.zip")
    assert may_declare(GROUP)


def test_another_finder_that_lists_distributions_is_left_to_importlib_metadata(tmp_path, only, monkeypatch):
    class Finder:
        def find_spec(self, *args):
            return None

        def find_distributions(self, context=None):
            return iter(())

    only(tmp_path)
    assert not may_declare(GROUP)
    monkeypatch.setattr(sys, "meta_path", [*sys.meta_path, Finder()])
    assert may_declare(GROUP)


def test_on_this_interpreters_path_every_group_importlib_metadata_finds_is_found():
    groups = {ep.group for dist in importlib.metadata.distributions() for ep in dist.entry_points}
    assert groups, "no installed package declares any entry point: nothing was compared"
    assert all(may_declare(group) for group in groups)
    assert may_declare(GROUP) or list(importlib.metadata.entry_points(group=GROUP)) == []
