"""The project cites only its own documents: a clone or the wheel has no file beside the repository.

Every *.py, *.md and *.toml file of the repository is read. A mention of a
Markdown document (`docs/physics.md`, or a link from one doc to another) must name a file
of the repository, found from the mentioning file's folder or from the
repository's root; nothing may point outside it (`../`, a `shared/` folder).

Exceptions:
- data, not a document: tests.builders.REAL_DATA, real drivers measured by
  others, kept beside the repository (tests that use it skip, saying why, when
  it is absent);
- the sources of the WinISD exporter (analysis/export/winisd.py,
  docs/driver-formats.md): files of the public repository github.com/Johnlon/openisd,
  cited with that repository's name (PUBLIC_SOURCES);
- a file name in quotes is a path being built (`REPO / "docs" / "bounds.md"`),
  checked by the code that opens it;
- this file, whose examples are wrong on purpose.
"""
from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SKIPPED_DIRS = {".git", ".venv", "build", "dist", "__pycache__", ".pytest_cache", ".hypothesis"}
# A Markdown document's name, with the folders before it; not a URL's tail (lmfit.github.io/.../x.md).
DOCUMENT = re.compile(r"(?<![\w./:\"-])((?:\.\.?/)*[\w-]+(?:/[\w.-]+)*\.md)\b")
# Files of github.com/Johnlon/openisd, the public sources of the WinISD driver format.
PUBLIC_SOURCES = {"docs/design/WINISD_SCHEMA.md", "WINISD_SCHEMA.md", "docs/research/UNIT_BOUNDARY_AUDIT.md",
                  "drivers/sample/README.md"}
OUTSIDE = re.compile(r"\.\./shared\b|(?<![\w./])shared/|\bSTYLE\.md\b")


def project_files() -> list[Path]:
    found = []
    for path in REPO.rglob("*"):
        if path.suffix in {".py", ".md", ".toml"} and path.is_file() \
                and not SKIPPED_DIRS.intersection(path.relative_to(REPO).parts) \
                and not any(part.endswith(".egg-info") for part in path.relative_to(REPO).parts) \
                and path != Path(__file__).resolve():
            found.append(path)
    return sorted(found)


def wrong_references(files: list[Path]) -> list[str]:
    wrong = []
    for path in files:
        where = path.relative_to(REPO) if path.is_relative_to(REPO) else path.name
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for match in OUTSIDE.finditer(line):
                wrong.append(f"{where}:{number}: {match.group(0)!r} points outside the repository: {line.strip()[:120]}")
            for match in DOCUMENT.finditer(line):
                name = match.group(1)
                if name in PUBLIC_SOURCES:
                    continue
                if not any((base / name).resolve().is_file() and (base / name).resolve().is_relative_to(REPO)
                           for base in (path.parent, REPO)):
                    wrong.append(f"{where}:{number}: {name} is no file of the repository: {line.strip()[:120]}")
    return wrong


def test_every_document_cited_is_the_projects_own():
    assert wrong_references(project_files()) == []


def test_a_reference_outside_is_found(tmp_path):
    """The check can fail: a file citing a document beside the repository, one citing a missing document,
    and one citing the project's own are told apart."""
    bad = tmp_path / "bad.py"
    bad.write_text('"""The format is ../shared/spec/recording-format.md; see STYLE.md and nowhere.md."""\n',
                   encoding="utf-8")
    good = tmp_path / "good.py"
    good.write_text('"""The formulas: docs/physics.md section 5."""\n', encoding="utf-8")
    found = wrong_references([bad, good])
    assert any("'../shared'" in f for f in found)
    assert any("'STYLE.md'" in f for f in found)
    assert any("nowhere.md is no file" in f for f in found)
    assert not any(f.startswith("good.py") for f in found)
