"""A simulator station for the three-station test: stores N units into an archive, as `linpar measure` would.

    python -m tests.production_station --archive URL --station QA-A --count 100 --recording REC --results DOC.json
                                       [--pause-at 30,60] [--seed S]

Each unit is the small measurement with its own fs and RE (drawn from the
seed), stored through the archive's store() as `linpar measure` stores one.
Prints one line per unit, "unit I ID PENDING" (PENDING: how many wait in the
station's local queue after it); at each --pause-at unit it prints
"paused I" and waits for a line on stdin (the test cuts or restores the
network meanwhile). Last line: "done" and the JSON list of ids.
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np


def main(argv=None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--archive", required=True)
    parser.add_argument("--station", required=True)
    parser.add_argument("--count", type=int, default=100)
    parser.add_argument("--recording", required=True)
    parser.add_argument("--results", required=True)
    parser.add_argument("--pause-at", default="")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    from analysis.archive.backends import open_archive
    from tests.production_helpers import unit
    doc = json.loads(open(args.results).read())
    pauses = {int(p) for p in args.pause_at.split(",") if p}
    rng = np.random.default_rng(args.seed)
    ids = []
    for i in range(1, args.count + 1):
        archive = open_archive(args.archive)           # a new one per unit, as each `linpar measure` process has
        values = unit(doc, fs=70.0 + 0.8 * rng.standard_normal(), RE=3.0 + 0.02 * rng.standard_normal())
        mid = archive.store(args.recording, values, {"station": args.station, "serial": f"{args.station}-{i:03d}",
                                                     "operator": "sim", "driver": "W6"})
        ids.append(mid)
        print(f"unit {i} {mid} {archive.pending}", flush=True)
        if i in pauses:
            print(f"paused {i}", flush=True)
            sys.stdin.readline()
    print("done " + json.dumps(ids), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
