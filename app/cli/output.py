"""What `linpar` writes to stdout and stderr besides its tables: JSON documents and progress lines."""
from __future__ import annotations

import sys
from typing import Any

from analysis.json_finite import dumps


def print_json(doc: Any, **kwargs) -> None:
    """One JSON document on stdout: valid JSON whatever numbers it holds (analysis.json_finite)."""
    print(dumps(doc, **kwargs))


def say(command: str, text: str) -> None:
    """A progress or note line on stderr (stdout is the result): "linpar COMMAND: TEXT"."""
    print(f"linpar {command}: {text}", file=sys.stderr, flush=True)
