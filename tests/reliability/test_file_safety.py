"""Nothing read from a file runs code, and no name read from a file puts anything outside the archive.

1. A scan of the source of analysis/, instruments/, app/ and resources/:
   no pickle, marshal, shelve, dill, joblib or yaml.load; no eval, exec,
   compile or __import__ (method calls like QApplication.exec() are not
   builtins and do not count); numpy's load and read_array only with
   allow_pickle=False written at the call; no shell commands. The scan reads
   the syntax tree, not the text, so comments, strings and the docs that
   name these functions cannot hide a call nor raise a false alarm.
2. The one binary container the program reads that could hold a pickle
   (the runner's NAME.laser.npz) is refused when it does, and the pickle
   does not run.
3. Names the archive takes from files (the recording's driver name, the
   laser stream's file name, the "files" and "folder" of measurement.json)
   with '../', absolute paths, NUL, very long names and Windows device
   names: every path the archive makes stays inside it.
"""
from __future__ import annotations

import ast
import json
import os
from pathlib import Path

import numpy as np
import pytest

from analysis.archive import Archive, ArchiveError
from analysis.archive.archive import FOLDERS
from analysis.archive.names import folder_name, inside, safe_suffix, slug
from analysis.archive.record import RECORD_FILE
from analysis.pipeline import analyze_recording
from analysis.recording.format import make_recording, read_recording, write_recording
from tests.builders import REPO_ROOT, TYPICAL_NOISE, recording

pytestmark = pytest.mark.timeout(60)

PACKAGES = ("analysis", "instruments", "app", "resources")
FORBIDDEN_MODULES = {"pickle", "cPickle", "_pickle", "marshal", "shelve", "dill", "cloudpickle", "joblib",
                     "jsonpickle", "yaml", "ruamel", "pandas", "torch"}
FORBIDDEN_BUILTINS = {"eval", "exec", "compile", "__import__", "execfile"}
PICKLING_LOADERS = {"load", "read_array", "open_memmap"}      # numpy's, with allow_pickle
SHELL_CALLS = {("os", "system"), ("os", "popen"), ("os", "execl"), ("os", "execlp"), ("os", "spawnl")}
# import_module with a computed name, and why it is safe.
ALLOWED_DYNAMIC_IMPORTS = {
    "instruments/audio/__init__.py": "the module name comes from the package's own _EXPORTS table",
    "instruments/measurement/__init__.py": "the module name comes from the package's own _EXPORTS table",
    "instruments/audio/factory.py": "the module name comes from the factory's own BACKENDS table",
    "instruments/laser/factory.py": "the names are the subpackages pkgutil lists in instruments/laser's own folder",
    "analysis/export/registry.py": "the names are the modules pkgutil lists in analysis/export's own folder",
    "app/cli/boundary.py": "the module name comes from the command line's own COMMANDS table",
    "analysis/effects/catalogue.py": "the module name comes from the catalogue's own table of built-in effects "
                                     "(an id not in it is no effect: nothing is imported)",
}
# The families' lazy packages load a submodule named in their own table (analysis/lazy_exports.py).
ALLOWED_DYNAMIC_IMPORTS["analysis/lazy_exports.py"] = "the module name comes from the package's own table"
WINDOWS_DEVICES = ["CON", "PRN", "AUX", "NUL", "COM1", "LPT1", "con.txt", "Nul.json", "COM9.wav"]


def sources():
    for package in PACKAGES:
        for path in sorted((REPO_ROOT / package).rglob("*.py")):
            yield path.relative_to(REPO_ROOT).as_posix(), ast.parse(path.read_text(encoding="utf-8"), str(path))


def dotted(node) -> str:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return f"{dotted(node.value)}.{node.attr}"
    return "?"


def findings_in(relative: str, tree: ast.AST) -> list[str]:
    found = []
    numpy_names = {"np", "numpy"}
    for node in ast.walk(tree):
        where = f"{relative}:{getattr(node, 'lineno', '?')}"
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] in FORBIDDEN_MODULES:
                    found.append(f"{where}: import {alias.name}")
                if alias.name == "numpy":
                    numpy_names.add(alias.asname or "numpy")
        elif isinstance(node, ast.ImportFrom):
            module = (node.module or "").split(".")[0]
            if module in FORBIDDEN_MODULES:
                found.append(f"{where}: from {node.module} import ...")
            if module == "numpy" and any(a.name in PICKLING_LOADERS for a in node.names):
                found.append(f"{where}: from numpy import a loader (call it as np.load(..., allow_pickle=False))")
        elif isinstance(node, ast.Call):
            name = dotted(node.func)
            head, _, last = name.rpartition(".")
            if isinstance(node.func, ast.Name) and node.func.id in FORBIDDEN_BUILTINS:
                found.append(f"{where}: {node.func.id}()")
            if last in PICKLING_LOADERS and head.split(".")[0] in numpy_names:
                flag = next((k.value for k in node.keywords if k.arg == "allow_pickle"), None)
                if not (isinstance(flag, ast.Constant) and flag.value is False):
                    found.append(f"{where}: {name}() without allow_pickle=False")
            if tuple(name.split(".")[-2:]) in SHELL_CALLS:
                found.append(f"{where}: {name}()")
            if any(k.arg == "shell" and not (isinstance(k.value, ast.Constant) and k.value.value is False)
                   for k in node.keywords):
                found.append(f"{where}: {name}(shell=...)")
            if last in ("import_module", "__import__") and not (
                    node.args and isinstance(node.args[0], ast.Constant)) and relative not in ALLOWED_DYNAMIC_IMPORTS:
                found.append(f"{where}: {name}() of a computed name")
            if last == "loads" and head in ("pickle", "marshal"):
                found.append(f"{where}: {name}()")
    return found


def test_no_source_file_can_run_code_from_data():
    scanned, found = 0, []
    for relative, tree in sources():
        scanned += 1
        found += findings_in(relative, tree)
    assert scanned > 100, "the scan found too few sources: wrong root?"
    assert found == [], "\n".join(found)


@pytest.mark.parametrize("snippet, hits", [
    ("import pickle", 1), ("from marshal import loads", 1), ("import yaml", 1), ("eval('1')", 1),
    ("exec(code)", 1), ("import numpy as n\nn.load(p)", 1), ("np.load(p, allow_pickle=True)", 1),
    ("np.load(p, allow_pickle=flag)", 1), ("np.load(p, allow_pickle=False)", 0), ("app.exec()", 0),
    ("subprocess.run(cmd, shell=True)", 1), ("os.system(cmd)", 1), ("importlib.import_module(name)", 1),
    ("x = 'eval(1) and pickle.loads'  # import pickle", 0), ("from numpy import load", 1),
])
def test_the_scan_itself_finds_what_it_must(snippet, hits):
    assert len(findings_in("snippet.py", ast.parse(snippet))) == hits


class _Trap:
    """Pickles into a call that leaves a file behind: the proof that a pickle ran."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (Path.touch, (self.marker,))


def test_a_raw_laser_capture_holding_a_pickle_is_refused_and_the_pickle_never_runs(tmp_path):
    raw_stream = pytest.importorskip("instruments.measurement.raw_stream",
                                     reason="the runner's raw laser file (instruments/measurement) is not there")
    marker = tmp_path / "the-pickle-ran"
    path = tmp_path / "m.laser.npz"
    with open(path, "wb") as f:
        np.savez(f, format=np.array(raw_stream.FORMAT), info=np.array("{}"),
                 counter=np.array([_Trap(marker)], dtype=object))
    with pytest.raises(ValueError, match="pickle"):
        raw_stream.read_raw_capture(path)
    assert not marker.exists()


# --- names from files, in the archive ----------------------------------------------------------------------

EVIL = ["../../outside", "/etc/passwd", "..", ".", "a\x00b", "x" * 5000, "C:\\Windows\\system32",
        "\\\\server\\share\\x", "~root", "$(touch pwned)", "-rf", "\n", *WINDOWS_DEVICES]


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    rec = recording(noise=TYPICAL_NOISE, n_periods=3, seed=9)
    from analysis.archive.results import results_document
    return rec, results_document(analyze_recording(rec), rec)


def everything_under(path: Path) -> set[Path]:
    return {p for p in path.rglob("*")}


@pytest.mark.parametrize("evil", EVIL)
def test_a_recordings_driver_name_and_a_laser_files_name_make_no_path(tmp_path, results, evil):
    rec, doc = results
    src = tmp_path / "src"
    src.mkdir()
    named = make_recording(rec.sample_rate, {c.signal: rec.data[i] for i, c in enumerate(rec.channels)},
                           rec.period_samples, driver={"name": evil, "sd_m2": 0.0133})
    write_recording(src / "rec", named)                         # the name travels inside the sidecar
    laser_name = evil.replace("/", "_").replace("\x00", "_").replace("\n", "_")[:200] or "x"
    laser = src / f"laser.{laser_name}"
    laser.write_bytes(b"\x01\x02")
    before = everything_under(tmp_path)
    root = tmp_path / "archive"
    archive = Archive(root)
    mid = archive.store(src / "rec", doc, laser_stream=laser)
    m = archive.get(mid)
    assert m.folder.parent == root / FOLDERS and len(m.folder.name) <= 22 + 1 + 40
    assert all(c.isalnum() or c == "-" for c in m.folder.name)
    assert m.folder.name.split(".")[0].upper() not in WINDOWS_DEVICES    # 'ID-con' is a name, 'CON' a device
    stream = m.path("laser_stream")
    assert stream.parent == m.folder and len(stream.name) <= len("laser.") + 8 and stream.read_bytes() == b"\x01\x02"
    assert stream.stem == "laser"                             # never a bare device name like 'CON'
    assert {p for p in everything_under(tmp_path) - before if root not in p.parents} == {root}
    assert read_recording(m.recording_path()).driver["name"] == evil   # kept as data, byte for byte


@pytest.mark.parametrize("evil", EVIL + ["recording.wav/../../../../outside/secret.json", "measurement.json/x"])
def test_file_names_in_measurement_json_never_lead_outside_the_folder(tmp_path, results, evil):
    rec, doc = results
    root = tmp_path / "archive"
    (tmp_path / "outside").mkdir()
    (tmp_path / "outside" / "secret.json").write_text('{"secret": 1}')
    archive = Archive(root)
    mid = archive.store(rec, doc)
    folder = archive.get(mid).folder
    record = json.loads((folder / RECORD_FILE).read_text())
    record["files"] = {role: evil for role in ("recording", "sidecar", "results", "settings", "calibration",
                                                "laser_stream")}
    (folder / RECORD_FILE).write_text(json.dumps(record))
    try:
        m = Archive(root).get(mid)
    except ArchiveError as exc:     # a name with a control character: the record is refused as it is read
        assert "\n" not in str(exc) and "control character" in str(exc)
        return
    for role in record["files"]:
        try:
            path = m.path(role)
        except ArchiveError as exc:
            assert "\n" not in str(exc)
            continue
        assert folder.resolve() in path.parents            # strictly inside the measurement's folder
    for load in (lambda: m.load_json("settings"), m.result):
        try:
            value = load()
        except ArchiveError:
            continue
        assert value != {"secret": 1}
    exported = archive.export(mid, tmp_path / "exported")
    assert exported.parent == tmp_path / "exported"
    assert (tmp_path / "outside" / "secret.json").read_text() == '{"secret": 1}'
    assert sorted(p.name for p in (tmp_path / "outside").iterdir()) == ["secret.json"]


@pytest.mark.parametrize("evil", EVIL)
def test_a_folder_field_that_is_not_the_folders_own_name_is_refused(tmp_path, results, evil):
    rec, doc = results
    archive = Archive(tmp_path / "archive")
    mid = archive.store(rec, doc)
    folder = archive.get(mid).folder
    record = json.loads((folder / RECORD_FILE).read_text())
    record["folder"] = evil
    (folder / RECORD_FILE).write_text(json.dumps(record))
    report = archive.rebuild()
    assert report.indexed == 0 and len(report.skipped) == 1 and "folder" in report.skipped[0]


@pytest.mark.parametrize("evil", EVIL)
def test_the_name_helpers_hold_for_every_evil_name(tmp_path, evil):
    name = folder_name("20240101-000000-abcdef", evil, evil)
    assert inside(tmp_path, name).parent == tmp_path.resolve()
    assert set(slug(evil)) <= set("abcdefghijklmnopqrstuvwxyz0123456789-") and len(slug(evil)) <= 40
    suffix = safe_suffix(evil)
    assert suffix.startswith(".") and len(suffix) <= 9 and "/" not in suffix and "\\" not in suffix
    if evil.startswith(("..", "/")) or "\x00" in evil:     # on POSIX a backslash is part of a name
        with pytest.raises(ArchiveError):
            inside(tmp_path / "sub", evil if evil != ".." else "../x")


def test_a_symlink_planted_in_a_measurement_folder_is_neither_followed_nor_exported(tmp_path, results):
    rec, doc = results
    (tmp_path / "outside").mkdir()
    secret = tmp_path / "outside" / "secret.json"
    secret.write_text('{"secret": 1}')
    archive = Archive(tmp_path / "archive")
    mid = archive.store(rec, doc)
    folder = archive.get(mid).folder
    (folder / "settings.json").unlink()
    os.symlink(secret, folder / "settings.json")
    with pytest.raises(ArchiveError, match="outside"):
        archive.get(mid).load_json("settings")
    exported = archive.export(mid, tmp_path / "exported")
    assert not (exported / "settings.json").exists()
