"""What importing one module loads, seen from a fresh interpreter (this process has imported everything already)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tests.pace import paced

REPO = Path(__file__).resolve().parent.parent


def loaded_by_import(module: str, prefix: str) -> list[str]:
    """The modules whose names start with `prefix` that `import module` leaves in sys.modules, sorted."""
    code = (f"import sys, {module}\n"
            f"print(','.join(sorted(m for m in sys.modules if m.startswith({prefix!r}))))")
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True,
                         timeout=paced(300))
    assert out.returncode == 0, out.stderr
    return [m for m in out.stdout.strip().split(",") if m]
