"""The layers of CONTRIBUTING.md, enforced: the import-linter contracts in pyproject.toml, run as `make test` runs.

analysis imports neither instruments nor app and no Qt; instruments imports no app and no Qt.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from tests.pace import paced

REPO = Path(__file__).resolve().parent.parent
LINT_IMPORTS = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
pytestmark = pytest.mark.skipif(LINT_IMPORTS is None,
                                reason="lint-imports is missing: `make setup` installs the test extra (import-linter)")


def lint_imports(cwd: Path, pythonpath: Path | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, **({"PYTHONPATH": str(pythonpath)} if pythonpath else {})}
    return subprocess.run([LINT_IMPORTS, "--no-cache"], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=paced(120))


def test_the_layers_contracts_are_kept():
    run = lint_imports(REPO)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "Contracts: 3 kept, 0 broken." in run.stdout


def test_the_contracts_break_on_an_import_against_the_layers(tmp_path):
    """The same contracts on a small tree that breaks each: analysis -> app, analysis -> instruments,
    instruments -> PySide6, and so analysis -> PySide6 through instruments (an indirect import counts);
    the recording format -> the fit."""
    config = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]
    lines = ['[tool.importlinter]', 'root_packages = ["analysis", "instruments", "app"]',
             "include_external_packages = true"]
    for contract in config["contracts"]:
        lines += ["", "[[tool.importlinter.contracts]]"]
        lines += [f"{key} = {value!r}".replace("'", '"') for key, value in contract.items()]
    (tmp_path / "pyproject.toml").write_text("\n".join(lines) + "\n", encoding="utf-8")
    files = {"analysis/__init__.py": "", "analysis/helper.py": "from app import window\n",
             "analysis/devices.py": "import instruments.laser\n",
             "instruments/__init__.py": "", "instruments/laser.py": "import PySide6\n",
             "analysis/recording.py": "import analysis.fit\n", "analysis/fit.py": "", "analysis/model.py": "",
             "analysis/validity.py": "", "analysis/diagnosis.py": "", "analysis/effects.py": "",
             "app/__init__.py": "", "app/window.py": ""}
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(text, encoding="utf-8")
    run = lint_imports(tmp_path, pythonpath=tmp_path)
    assert run.returncode == 1, run.stdout + run.stderr
    assert "Contracts: 0 kept, 3 broken." in run.stdout
    assert "analysis.recording is not allowed to import analysis.fit" in run.stdout
    assert "analysis is not allowed to import app" in run.stdout and "analysis.helper -> app.window" in run.stdout
    assert "analysis is not allowed to import instruments" in run.stdout
    assert "analysis is not allowed to import PySide6" in run.stdout      # through instruments.laser
    assert "instruments is not allowed to import PySide6" in run.stdout
    assert "instruments.laser -> PySide6" in run.stdout
