"""No module import circles anywhere in the project (CONTRIBUTING.md: "a circle is a missing module").

The graph is read from the source with ast, nothing is imported. Every import
counts, wherever it is written: at the top, inside a function (a late import
only hides a circle until that function runs) and under `if TYPE_CHECKING:`
(two modules that name each other's types still know each other). An import
of a.b.c is an edge to a.b.c; the packages a and a.b it runs first are not
edges of their own, else every __init__ that gathers its submodules would be
a circle.
"""
from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PACKAGES = ("analysis", "instruments", "app", "tools", "bench")


def project_modules() -> dict[str, Path]:
    found = {}
    for package in PACKAGES:
        for path in sorted((REPO / package).rglob("*.py")):
            parts = path.relative_to(REPO).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def imported_names(name: str, path: Path, modules=frozenset()) -> set[str]:
    """The modules `name` imports. `from X import Y` is X.Y when that is a module (one of `modules`), else X."""
    is_package = path.name == "__init__.py"
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:      # relative: from the module's package, one level up per extra dot
                base = name.split(".")[: None if is_package else -1]
                base = base[: len(base) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            for alias in node.names:
                submodule = f"{module}.{alias.name}"
                names.add(submodule if submodule in modules else module)
    return names


def import_graph() -> dict[str, set[str]]:
    modules = project_modules()
    return {name: {m for m in imported_names(name, path, modules) if m in modules and m != name}
            for name, path in modules.items()}


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_project_has_no_import_circle():
    graph = import_graph()
    assert len(graph) > 250 and "app.cli.boundary" in graph       # the whole project was read
    found = circles(graph)
    details = ["; ".join(f"{m} -> {', '.join(sorted(graph[m] & set(c)))}" for m in c) for c in found]
    assert found == [], "\n".join(details)


def test_the_circle_finder_finds_circles():
    """A test of the test: the kinds of circle the issue found, built by hand."""
    graph = {"a.cli": {"a.cli_import"}, "a.cli_import": {"a.cli"},           # a late import back
             "r.recording": {"r.sidecar"}, "r.sidecar": {"r.recording"},     # a TYPE_CHECKING import back
             "x": {"y"}, "y": {"z"}, "z": {"x"}, "leaf": set(), "top": {"x", "leaf"}}
    assert sorted(circles(graph)) == [["a.cli", "a.cli_import"], ["r.recording", "r.sidecar"], ["x", "y", "z"]]


def test_late_and_type_only_imports_are_edges(tmp_path):
    module = tmp_path / "m.py"
    module.write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from analysis.recording.format import Recording\n"
                      "def f():\n    from app.cli import main\n    import instruments.audio\n"
                      "from . import sibling\n", encoding="utf-8")
    names = imported_names("analysis.m", module, {"analysis.sibling"})
    assert names == {"typing", "analysis.recording.format", "app.cli", "instruments.audio", "analysis.sibling"}
