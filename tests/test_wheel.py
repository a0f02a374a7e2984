"""Issue 22: the wheel holds what the program needs, and the installed `linpar` runs away from the checkout.

The wheel is built from a copy of the packages (pip wheel: a build of its own,
nothing written into the checkout) and installed without its dependencies
into a fresh virtual environment outside the checkout; the dependencies are
borrowed from the environment running the tests, through a .pth line (the
same pinned versions, no download; the .pth files of that folder, the
checkout's editable install among them, are not run, so the checkout's
packages cannot be imported from there). Every command runs in another folder.
What this cannot show: that the pins resolve on Windows and macOS (pip's
wheels for them exist for every dependency; the README says how to install).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from analysis.drivers import load_driver
from analysis.recording.format import write_recording
from tests.builders import TYPICAL_NOISE, recording

ROOT = Path(__file__).resolve().parents[1]
PACKAGED = ("analysis", "app", "instruments", "resources", "pyproject.toml", "README.md")
DATA = ("resources/guide.md", "resources/linpar.desktop", "resources/icons/linpar.png", "resources/icons/linpar.svg",
        "resources/drivers/paper.json", "resources/limits/example.json", "resources/effects/rms-sqrt-f.toml")
SLOW_S = 240


def _run(command, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(command, capture_output=True, text=True, timeout=SLOW_S, **kwargs)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    work = tmp_path_factory.mktemp("wheel-build")
    source = work / "src"
    source.mkdir()
    junk = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info", "build")
    for name in PACKAGED:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, source / name, ignore=junk)
        else:
            shutil.copy2(ROOT / name, source / name)
    built = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(work / "dist"), str(source)])
    assert built.returncode == 0, built.stderr[-3000:]
    (found,) = (work / "dist").glob("linpar-*.whl")
    return found


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> dict:
    """The fresh environment's bin folder, an environment for its commands, and a folder away from everything."""
    work = tmp_path_factory.mktemp("wheel-install")
    venv = work / "venv"
    made = _run([sys.executable, "-m", "venv", "--without-pip", str(venv)])
    assert made.returncode == 0, made.stderr
    python = venv / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
    done = _run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "--no-index", "-q",
                 str(wheel)])
    assert done.returncode == 0, done.stderr[-3000:]
    site = _run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).stdout.strip()
    borrowed = {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]}
    Path(site, "borrowed-dependencies.pth").write_text("\n".join(sorted(borrowed)) + "\n", encoding="utf-8")
    elsewhere = work / "elsewhere"
    elsewhere.mkdir()
    env = {key: value for key, value in os.environ.items() if key not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(PATH=f"{python.parent}{os.pathsep}{env.get('PATH', '')}", HOME=str(work / "home"),
               XDG_CONFIG_HOME=str(work / "config"), XDG_DATA_HOME=str(work / "data"),
               LINPAR_CACHE=str(work / "cache"), QT_QPA_PLATFORM="offscreen")
    return {"bin": python.parent, "python": python, "env": env, "cwd": elsewhere}


def _linpar(installed, *args, **extra_env) -> subprocess.CompletedProcess:
    linpar = installed["bin"] / ("linpar.exe" if os.name == "nt" else "linpar")
    return _run([str(linpar), *args], cwd=installed["cwd"], env={**installed["env"], **extra_env})


def test_the_wheel_holds_the_packages_and_their_data(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    assert set(DATA) <= names, sorted(set(DATA) - names)
    tops = {name.split("/")[0] for name in names if not name.startswith("linpar-")}
    assert tops == {"analysis", "app", "instruments", "resources"}
    assert "app/window/main_window.py" in names and "instruments/measurement/runner.py" in names
    assert not any(name.startswith(("tests/", "bench/", "tools/")) for name in names)


def test_the_installed_packages_are_the_wheels_not_the_checkouts(installed):
    found = _run([str(installed["python"]), "-c", "import app, analysis, resources; print(app.__file__); "
                  "print(resources.__file__)"], cwd=installed["cwd"], env=installed["env"])
    assert found.returncode == 0, found.stderr
    for line in found.stdout.split():
        assert Path(line).is_relative_to(installed["python"].parent.parent), line
        assert not Path(line).is_relative_to(ROOT), line


def test_linpar_version_is_the_packages(installed):
    import tomllib
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["version"]
    done = _linpar(installed, "--version")
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"linpar {declared}"


def test_linpar_analyze_runs_from_another_folder(installed):
    path = installed["cwd"].parent / "recordings" / "paper"
    path.parent.mkdir()
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=4, seed=11))
    done = _linpar(installed, "analyze", str(path) + ".wav", "--json")
    assert done.returncode == 0, done.stderr[-3000:]
    doc = json.loads(done.stdout)
    assert doc["parameters"]["Bl"]["value"] == pytest.approx(load_driver("paper").parameters["Bl"], rel=1e-3)
    assert doc["model"]["effects"] == ["lr2", "creep-log"]


def test_linpar_gui_starts_offscreen_and_leaves_by_itself(installed):
    done = _linpar(installed, "gui", LINPAR_EXIT_AFTER_S="1")
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Traceback" not in done.stderr


def test_the_desktop_entry_starts_linpar_with_its_icon():
    import configparser
    entry = configparser.ConfigParser(interpolation=None)
    entry.optionxform = str
    entry.read(ROOT / "resources" / "linpar.desktop", encoding="utf-8")
    desktop = entry["Desktop Entry"]
    assert desktop["Type"] == "Application" and desktop["Exec"].split()[:2] == ["linpar", "gui"]
    assert (ROOT / "resources" / "icons" / f"{desktop['Icon']}.png").is_file()
    assert desktop["Categories"].endswith(";") and desktop["Terminal"] == "false"
