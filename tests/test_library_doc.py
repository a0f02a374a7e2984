"""docs/library.md runs: its python blocks, in order, in one namespace (as a notebook runs its cells), print
what its text blocks show, and the example reproduces the parameters the simulator was given."""
from __future__ import annotations

import re

import pytest

from tests.builders import REPO_ROOT

DOC = REPO_ROOT / "docs" / "library.md"


def blocks(kind: str) -> list[str]:
    return re.findall(rf"^```{kind}\n(.*?)^```$", DOC.read_text(encoding="utf-8"), flags=re.M | re.S)


@pytest.fixture(scope="module")
def notebook():
    namespace: dict = {"__name__": "library_doc"}
    printed: list[str] = []
    namespace["print"] = lambda *args, **kwargs: printed.append(" ".join(map(str, args)))
    for code in blocks("python"):
        exec(compile(code, str(DOC), "exec"), namespace)
    return namespace, "\n".join(printed).splitlines()


def test_the_doc_has_its_cells():
    assert len(blocks("python")) == 4 and len(blocks("text")) == 3


def test_every_line_shown_is_printed(notebook):
    _, printed = notebook
    for shown in blocks("text"):
        for line in shown.splitlines():
            start = line.removesuffix("...").rstrip()
            assert any(out.rstrip().startswith(start) for out in printed), f"not printed: {line!r}"


def test_the_example_reproduces_the_drivers_parameters(notebook):
    ns, _ = notebook
    assert ns["first"].validity.overall == "yellow"        # the default model misses the second stage
    assert "lr3" in ns["effects"]
    result, given = ns["result"], ns["given"]
    for name in ("RE", "Bl", "Mms", "Kms", "fs", "Qts", "Vas"):
        p = result.parameters[name]
        assert abs(p.value - given[name]) <= 3 * p.std, name
        assert p.value == pytest.approx(given[name], rel=1e-3), name
    assert ns["document"]["model"]["effects"] == list(ns["effects"])
    again = ns["again"]          # through a file: the same numbers
    assert again.parameters["Bl"].value == pytest.approx(result.parameters["Bl"].value, rel=1e-6)
