"""Issue 22: no path of one system hard-coded outside the virtual rig (/tmp, /dev, ~/.local, /proc, the root).

Read from the source's string literals (docstrings aside: they may name a
path as an example). The folders come from analysis.config_folder
(platformdirs), the serial port's example name from instruments.serial_ports.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("app", "analysis", "instruments", "tools", "bench")
LINUX_PATH = re.compile(r"(^|[^\w.])(/tmp\b|/dev/|/proc/|/var/|/run/)|~/\.local|\.local/share|^\.local$|\.cache/linpar")
PATH_CALLS = {"Path", "PurePath", "PurePosixPath", "open", "join", "listdir", "stat", "chdir", "mkdir", "scandir"}
# Where a system's own path is the point, and why.
ALLOWED = {
    "instruments/rig/": "the virtual rig: JACK and pseudo-terminals, Linux only by design",
    "instruments/laser/ild1420/emulator.py": "the laser's emulator on a pseudo-terminal (Linux, macOS)",
    "instruments/serial_ports.py": "each system's name for a USB serial port, shown as an example",
    "instruments/audio/portaudio.py": "JACK2's socket folder, asked on Linux only",
    "tools/soak.py": "soaks the virtual rig (Linux): memory, files and threads from /proc/self",
    "bench/rig_bench.py": "times the virtual rig's process (Linux): its CPU time from /proc/<pid>/stat",
}


def _allowed(relative: str) -> bool:
    return any(relative == path or (path.endswith("/") and relative.startswith(path)) for path in ALLOWED)


def _docstrings(tree: ast.AST) -> set[int]:
    found = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and body
                and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)):
            found.add(id(body[0].value))
    return found


def _called(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")


def hard_coded_paths(source: str) -> list[tuple[int, str]]:
    """(line, text) of each string literal that names a system path, one per line."""
    tree = ast.parse(source)
    docstrings = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            if LINUX_PATH.search(node.value):
                found.append((node.lineno, node.value))
        elif isinstance(node, ast.Call) and _called(node) in PATH_CALLS and node.args:
            first = node.args[0]
            text = first.value if isinstance(first, ast.Constant) else None
            if isinstance(first, ast.JoinedStr) and first.values and isinstance(first.values[0], ast.Constant):
                text = first.values[0].value
            if isinstance(text, str) and text.startswith("/"):
                found.append((node.lineno, text))
    return sorted(dict(found).items())


def test_the_scanner_finds_what_it_looks_for():
    source = ('"""Module doc: /tmp/x is fine here."""\n'
              'a = Path.home() / ".local" / "share"\n'
              'b = "~/.local/share/linpar"\n'
              'c = Path("/")\n'
              'd = open(f"/proc/{pid}/stat")\n'
              'e = os.path.join("/tmp", name)\n'
              'f = "a/b"\n')
    lines = sorted(line for line, _ in hard_coded_paths(source))
    assert lines == [2, 3, 4, 5, 6]


def test_nothing_outside_the_rig_hard_codes_a_system_path():
    offenders = []
    for package in SCANNED:
        for path in sorted((ROOT / package).rglob("*.py")):
            relative = path.relative_to(ROOT).as_posix()
            if _allowed(relative):
                continue
            offenders += [f"{relative}:{line}: {text[:80]!r}"
                          for line, text in hard_coded_paths(path.read_text(encoding="utf-8"))]
    assert offenders == [], "\n".join(offenders)


def test_every_allowed_file_exists_or_is_expected_from_the_device_packages():
    # An allowance for a file that is gone would hide nothing but mislead; the ild1420 package comes with issue 17.
    for relative in ALLOWED:
        assert (ROOT / relative).exists() or relative.startswith("instruments/laser/ild1420/"), relative
