"""tests/ mirrors the source tree, so that a module's tests are where one looks for them.

The rule, for a test file tests/D/test_NAME.py:

1. D mirrors a source package: tests/analysis/fit/ holds the tests of analysis/fit/,
   tests/app/cli/ those of app/cli/, tests/instruments/laser/ those of instruments/laser/.
2. A test named after a module or package of its layer sits beside that module's mirror:
   NAME, or its longest prefix cut at an underscore, names a module M or package Q of the
   layer (analysis, app, instruments); D must then be the package holding M, or Q itself.
   tests/analysis/fit/test_report.py tests analysis/fit/report.py;
   tests/app/wizard/test_wizard_rig.py tests app/wizard/ on the rig.
3. A test named after a topic (no module of its layer has that name: test_honesty.py,
   test_real_data.py) tests several modules together and sits in the package it is about.

Allowed exceptions, where no single package is the subject:
- tests/ itself: checks of the whole project (layers, import graph, the wheel, portability,
  the docs' file paths, this file);
- tests/reliability/: end-to-end runs across the layers (faults, fuzzing, crash safety,
  three stations on one archive).
"""
from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
LAYERS = ("analysis", "app", "instruments")
WHOLE_PROJECT_DIRS = {REPO / "tests", REPO / "tests" / "reliability"}


def layer_names(layer: str) -> dict[str, set[Path]]:
    """Each module or package name of a layer -> the source packages a test named after it may sit in."""
    homes: dict[str, set[Path]] = {}
    for path in (REPO / layer).rglob("*.py"):
        if path.name == "__init__.py":
            homes.setdefault(path.parent.name, set()).add(path.parent.relative_to(REPO))
        else:
            homes.setdefault(path.stem, set()).add(path.parent.relative_to(REPO))
    return homes


def misplaced(tests: list[Path] | None = None) -> list[str]:
    """What is wrong with the location of each test file (every one in tests/, unless `tests` names some)."""
    names = {layer: layer_names(layer) for layer in LAYERS}
    wrong = []
    for test in tests if tests is not None else sorted((REPO / "tests").rglob("test_*.py")):
        folder = test.parent
        if folder in WHOLE_PROJECT_DIRS:
            continue
        mirrored = folder.relative_to(REPO / "tests")
        where = test.relative_to(REPO)
        if mirrored.parts[0] not in LAYERS or not (REPO / mirrored / "__init__.py").is_file():
            wrong.append(f"{where}: tests/{mirrored}/ mirrors no source package")
            continue
        words = test.stem[len("test_"):].split("_")
        homes = names[mirrored.parts[0]]
        for k in range(len(words), 0, -1):
            subject = "_".join(words[:k])
            if subject in homes:
                if mirrored not in homes[subject]:
                    wanted = " or ".join(f"tests/{home}/" for home in sorted(map(str, homes[subject])))
                    wrong.append(f"{where}: tests {subject}, whose tests belong in {wanted}")
                break
    return wrong


def test_every_test_file_sits_where_its_module_is():
    assert misplaced() == []


def test_the_rule_finds_a_misplaced_test():
    """The check can fail: a test of analysis/fit/report.py at the top of tests/analysis/, one in a folder
    that mirrors nothing, and the same test where it belongs."""
    top = REPO / "tests" / "analysis" / "test_fit_report.py"
    nowhere = REPO / "tests" / "analysis" / "fitting" / "test_report.py"
    home = REPO / "tests" / "analysis" / "fit" / "test_report.py"
    found = misplaced([top, nowhere, home])
    assert len(found) == 2
    assert found[0].startswith("tests/analysis/test_fit_report.py: tests fit, ") and "tests/analysis/fit/" in found[0]
    assert found[1] == "tests/analysis/fitting/test_report.py: tests/analysis/fitting/ mirrors no source package"
