"""Limits proposed from golden units, and the population exported: CSV (long), JSON, Q-DAS AQDEF (.dfq) read back."""
import csv
import io
import math

import numpy as np
import pytest

from analysis.archive.limits_store import checked_document
from analysis.archive.names import ArchiveError
from analysis.archive.population import Population
from analysis.production import production_stats, propose_limits
from analysis.production.aqdef import INVALID, PLACEHOLDER, VALID, encode, read_dfq, write_dfq
from analysis.production.exchange import CSV_COLUMNS, population_csv, population_json


def population(fs, re=None, fs_std=0.05, stations=None, validity=None, serials=None, drivers=None):
    n = len(fs)
    re = re if re is not None else [3.0 + 0.01 * i for i in range(n)]
    return Population(tuple(f"20240501-1200{i:02d}-abcdef" for i in range(n)),
                      tuple(f"2024-05-01T12:00:{i:02d}Z" for i in range(n)), tuple(stations or ["QA1"] * n),
                      tuple(drivers or ["W6"] * n), tuple(serials or [f"SN{i}" for i in range(n)]), ("ana",) * n,
                      tuple(validity or ["green"] * n), (None,) * n, (None,) * n,
                      {"fs": tuple(fs), "RE": tuple(re)}, {"fs": (fs_std,) * n, "RE": (0.001,) * n})


def test_limits_from_golden_units_are_mean_plus_minus_k_sigma_in_customary_units():
    rng = np.random.default_rng(1)
    fs = 70.0 + 1.2 * rng.standard_normal(12)
    document, proposed, notes = propose_limits(population(fs), k=3.0)
    checked_document(document)                               # a limits file analysis.limits takes
    entry = document["parameters"]["fs"]
    sigma = np.std(fs, ddof=1)
    assert entry["unit"] == "Hz" and "12 golden units" in entry["note"]
    assert entry["min"] == pytest.approx(fs.mean() - 3 * sigma, abs=1e-4)
    assert entry["max"] == pytest.approx(fs.mean() + 3 * sigma, abs=1e-4)
    assert entry["min"] <= fs.mean() - 3 * sigma and entry["max"] >= fs.mean() + 3 * sigma   # rounded outwards
    assert notes == [] and document["source"]["k"] == 3.0


def test_golden_units_tighter_than_the_measurement_get_the_measurement_s_uncertainty_as_floor():
    fs = [70.0, 70.001, 69.999, 70.0]                        # spread 0.001 Hz, each measured to +-0.05 Hz
    document, proposed, notes = propose_limits(population(fs, fs_std=0.05), k=2.0)
    p = next(p for p in proposed if p.name == "fs")
    assert p.floored and p.half_width == pytest.approx(2 * 0.05)
    assert document["parameters"]["fs"]["max"] == pytest.approx(70.0 + 0.1, abs=1e-4)
    assert "uncertainty" in document["parameters"]["fs"]["note"] and "only 4 golden units" in notes[0]


def test_golden_units_that_cannot_be_used_are_refused_with_one_line():
    with pytest.raises(ArchiveError, match="at least 2"):
        propose_limits(population([70.0]), k=3)
    with pytest.raises(ArchiveError, match="must be a valid measurement"):
        propose_limits(population([70.0, 71.0], validity=["green", "red"]), k=3)


def test_csv_is_long_and_json_has_every_measurement():
    pop = population([70.0, None, 71.0])
    text = population_csv(pop)
    assert text.startswith("# linpar population") and "# exported by linpar" in text
    rows = list(csv.reader(line for line in io.StringIO(text) if not line.startswith("#")))
    assert tuple(rows[0]) == CSV_COLUMNS and len(rows) == 1 + 3 * 2
    fs_rows = [r for r in rows[1:] if r[9] == "fs"]
    assert [r[10] for r in fs_rows] == ["70.0", "", "71.0"] and fs_rows[0][12] == "Hz"
    doc = population_json(pop, "every measurement", "/archive")
    assert [m["parameters"]["fs"]["value"] for m in doc["measurements"]] == [70.0, None, 71.0]
    assert doc["measurements"][0]["parameters"]["RE"]["unit"] == "ohm"


def test_aqdef_round_trip_of_every_field_written():
    from analysis.archive.limits_store import LimitsVersion
    limits = LimitsVersion(1, "w6", {"format": "linpar-limits/1", "name": "w6", "parameters": {
        "fs": {"min": 64.0, "max": 76.0, "unit": "Hz"}, "RE": {"max": 3.5, "unit": "ohm"}}}, "", "", "")
    pop = population([70.0, None, 71.5, 69.0], stations=["QA1", "QA2", "QA1", "QA2"],
                     validity=["green", "green", "red", "green"], serials=["SN-1", "SN-2", "SЖ-3", "SN\n4"],
                     drivers=["W6", "W6", "W8", "W6"])
    stats = production_stats(pop, limits)
    data = encode(write_dfq(pop, stats.parameters, excluded_ids={pop.ids[2]}))
    assert b"\r\n" in data and b"\n4" not in data.replace(b"\r\n", b"")
    dfq = read_dfq(data)
    names = list(stats.parameters)                   # fs, RE
    assert dfq.characteristics_count == 2 * len(names)          # two drivers: two parts
    assert dfq.parts[1]["K1001"] == "W6" and dfq.parts[2]["K1001"] == "W8"
    fs = dfq.characteristics[names.index("fs") + 1]
    assert (fs["K2001"], fs["K2142"], float(fs["K2110"]), float(fs["K2111"]), float(fs["K2101"])) == \
           ("fs", "Hz", 64.0, 76.0, 70.0)
    re_ = dfq.characteristics[names.index("RE") + 1]
    assert re_["K2142"] == "Ohm" and "K2110" not in re_ and float(re_["K2111"]) == 3.5
    assert [set(r) for r in dfq.values] == [{1, 2}, {1, 2}, {1, 2}, {3, 4}]      # three W6 units, one W8
    w6 = [r for r in dfq.values if 1 in r]
    i = names.index("fs") + 1
    assert [float(r[i]["K0001"]) for r in w6] == [70.0, 0.0, 69.0]
    assert [int(r[i]["K0002"]) for r in w6] == [VALID, PLACEHOLDER, VALID]
    assert [r[i]["K0014"] for r in w6] == ["SN-1", "SN-2", "SN 4"]
    assert w6[0][i]["K0004"] == "01.05.2024/12:00:00" and "station QA1" in w6[0][i]["K0009"]
    w8 = dfq.values[3][i + 2]
    assert (int(w8["K0002"]), w8["K0014"], float(w8["K0001"])) == (INVALID, "S?-3", 71.5)   # red: shown, not counted
    assert pop.ids[2] in w8["K0009"]
    assert all(math.isfinite(float(r[k]["K0001"])) for r in dfq.values for k in r)
