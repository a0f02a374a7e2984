"""`make bench`: every benchmark, a small table, and bench/results/bench.json."""
from __future__ import annotations

import json
import platform
import sys
import tempfile
import time
from pathlib import Path

from app.blas_threads import one_blas_thread

one_blas_thread()       # first: one BLAS thread per process, as `linpar` and its window run

from bench import (analysis_bench, archive_bench, gui_bench, large_signal_bench,  # noqa: E402 - after that
                   production_bench, report_bench, rig_bench, validity_bench)
from bench.common import RESULTS_DIR  # noqa: E402

SUITES = {"analysis": analysis_bench.run, "validity": validity_bench.run, "rig": rig_bench.run, "archive": archive_bench.run,
          "production": production_bench.run, "report": report_bench.run, "gui": gui_bench.run, "large-signal": large_signal_bench.run}


def main(argv: list[str]) -> int:
    wanted = argv or list(SUITES)
    unknown = [w for w in wanted if w not in SUITES]
    if unknown:
        print(f"unknown benchmark(s): {', '.join(unknown)}; known: {', '.join(SUITES)}", file=sys.stderr)
        return 2
    results = {"date": time.strftime("%Y-%m-%d %H:%M:%S"), "machine": platform.platform(),
               "python": platform.python_version(), "suites": {}}
    failed = False
    with tempfile.TemporaryDirectory(prefix="linpar-bench-") as tmp:
        for name in wanted:
            rows = SUITES[name](Path(tmp))
            results["suites"][name] = [r.as_json() for r in rows]
            print(f"\n{name}")
            print(f"  {'benchmark':<58}{'value':>10} {'unit':<6}{'target':>10}  ok")
            for r in rows:
                ok = "" if r.ok is None else ("yes" if r.ok else "NO")
                print(f"  {r.name:<58}{r.value:>10.3f} {r.unit:<6}{r.target:>10}  {ok}")
                failed |= r.ok is False
    RESULTS_DIR.mkdir(exist_ok=True)
    out = RESULTS_DIR / "bench.json"
    tmp_out = out.with_suffix(".json.tmp")
    tmp_out.write_text(json.dumps(results, indent=1))
    tmp_out.replace(out)
    print(f"\nwritten: {out}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
