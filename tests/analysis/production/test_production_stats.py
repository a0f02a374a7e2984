"""Statistics over units: capability against an exact reference, the control chart's rules, a drift found
within 10 units, stations compared, and who is left out and why."""
import math
from decimal import Decimal, getcontext
from fractions import Fraction

import numpy as np
import pytest

from analysis.archive.population import Population
from analysis.production import capability, compare_stations, control_chart, production_stats
from analysis.production.control_chart import D4_PAIRS
from tests.pace import paced

# pi to 60 digits, for a reference that owes nothing to floating point
PI = Decimal("3.141592653589793238462643383279502884197169399375105820974944")


def reference(values, low, high):
    """Cp, Cpk, Pp, Ppk in exact rational arithmetic (Fraction of each float), square roots in 60-digit Decimal."""
    getcontext().prec = 60
    x = [Fraction(v) for v in values]
    n = len(x)
    mean = sum(x) / n
    mr_bar = sum(abs(b - a) for a, b in zip(x, x[1:])) / (n - 1)
    var = sum((v - mean) ** 2 for v in x) / (n - 1)

    def dec(f: Fraction) -> Decimal:
        return Decimal(f.numerator) / Decimal(f.denominator)
    d2 = 2 / PI.sqrt()
    s_within = dec(mr_bar) / d2
    s_overall = dec(var).sqrt()
    lo, hi, m = dec(Fraction(low)), dec(Fraction(high)), dec(mean)
    return (float((hi - lo) / (6 * s_within)), float(min(hi - m, m - lo) / (3 * s_within)),
            float((hi - lo) / (6 * s_overall)), float(min(hi - m, m - lo) / (3 * s_overall)))


@pytest.mark.parametrize("seed", range(5))
def test_cp_cpk_pp_ppk_agree_with_an_exact_reference_to_1e_9(seed):
    rng = np.random.default_rng(seed)
    x = 70.0 + 1.3 * rng.standard_normal(250) + np.linspace(0, 4.0, 250)        # a drift: Pp < Cp
    low, high = 64.0, 77.5
    c = capability(x, low, high)
    for got, want in zip((c.cp, c.cpk, c.pp, c.ppk), reference(x.tolist(), low, high)):
        assert got == pytest.approx(want, rel=1e-9, abs=0)
    assert c.pp < c.cp                       # the drift is in the overall sigma, not in the within one
    assert (c.n, c.within + c.below + c.above) == (250, 250)


def test_one_sided_limits_and_yield():
    x = np.array([1.0, 2.0, 3.0, 4.0, 5.0, None, np.nan], dtype=object)
    c = capability(x, None, 4.0)
    assert (c.n, c.cp, c.pp) == (5, None, None)
    assert c.cpk == pytest.approx((4.0 - 3.0) / (3 * 1.0 / (2 / math.sqrt(math.pi))))
    assert (c.within, c.above, c.yield_fraction) == (4, 1, 0.8)
    assert capability([], 1, 2).yield_fraction is None
    assert capability([3.0, 3.0], 1, 5).cpk is None                 # no spread: no index, not infinity


def baseline(n=20, a=1.0):
    """Alternating +-a around 0, ending at -a: centre 0, MR = 2a, sigma = 2a/d2 = a*sqrt(pi), no rule fires."""
    return [-a if i % 2 else a for i in range(n)]


SIGMA = math.sqrt(math.pi)


@pytest.mark.parametrize("tail, rule, side", [
    ([3.2], "WE1", "below"), ([2.5, 0.0, 2.5], "WE2", "above"), ([1.5, 1.5, 0.0, 1.5, 1.5], "WE3", "above"),
    ([0.3] * 8, "WE4", "above"), ([0.3] + [-0.3] * 8, "WE4", "below")])
def test_each_western_electric_rule_fires_on_its_pattern(tail, rule, side):
    sign = -1 if rule == "WE1" else 1
    x = baseline() + [sign * v * SIGMA for v in tail]
    chart = control_chart(x, baseline=20)
    assert chart.centre == pytest.approx(0.0) and chart.sigma == pytest.approx(SIGMA)
    fired = [a for a in chart.alarms if a.rule == rule]
    assert len(fired) == 1 and fired[0].side == side and fired[0].triggers == (len(x) - 1,)
    assert fired[0].points[0] >= 20


def test_the_rules_do_not_fire_short_of_their_pattern():
    for tail in ([2.9], [2.5, 0.0, 1.9], [1.5, 1.5, 0.0, 1.5, 0.9], [0.3] * 7):
        chart = control_chart(baseline() + [v * SIGMA for v in tail], baseline=20)
        assert [a.rule for a in chart.alarms if a.rule != "MR"] == [], tail


def test_a_jump_between_two_units_is_a_moving_range_alarm():
    x = baseline() + [-2.0 * SIGMA, 2.0 * SIGMA]        # neither beyond 3 sigma, but 4 sigma apart
    chart = control_chart(x, baseline=20)
    (jump,) = [a for a in chart.alarms if a.rule == "MR"]
    assert jump.points == (20, 21) and chart.mr_ucl == pytest.approx(D4_PAIRS * 2.0)
    assert not [a for a in chart.alarms if a.rule == "WE1"]


def drifted(seed, kind, n=300, start=150, sigma=0.8, centre=70.0):
    rng = np.random.default_rng(seed)
    x = centre + sigma * rng.standard_normal(n)
    steps = np.arange(n) - start
    if kind == "step":                      # units 150, 151, ... read 2 sigma high
        x[start:] += 2.0 * sigma
    else:                                   # a ramp: unit 150 reads 0.25 sigma high, 151 0.5 sigma, ...
        x[start:] += 0.25 * sigma * (steps[start:] + 1)
    return x


def test_a_baseline_of_fewer_than_10_units_draws_the_points_and_raises_no_alarm():
    """8 units: centre and sigma from 8 points are too unsure to judge by (the CLI raised 6 alarms, each one
    said to come about once in 92 units of a stable process)."""
    x = [70.0, 70.1, 69.9, 70.0, 73.0, 70.05, 69.95, 70.0]
    chart = control_chart(x)
    assert chart is not None and chart.baseline == 8 and not chart.judges and len(chart.alarms) == 0
    assert control_chart(x + [70.0, 70.02], baseline=10).judges       # from 10 units it judges


@pytest.mark.parametrize("kind", ["step", "ramp"])
def test_a_drift_injected_at_unit_150_is_flagged_within_10_units(kind):
    for seed in range(20):
        chart = control_chart(drifted(seed, kind), baseline=50)
        triggers = sorted(t for a in chart.alarms for t in a.triggers if t >= 150)
        assert triggers and triggers[0] < 160, (seed, [(a.rule, a.triggers[:3]) for a in chart.alarms])


def test_without_a_drift_false_alarms_are_as_rare_as_the_rules_promise():
    # Four rules together: an alarm starts about once in 92 points of a stable process (ARL0 ~ 92).
    fired = points = 0
    for seed in range(40):
        x = 70.0 + 0.8 * np.random.default_rng(100 + seed).standard_normal(300)
        chart = control_chart(x, baseline=300)         # the limits of the whole run: phase I
        fired += len({t for a in chart.alarms if a.rule != "MR" for t in a.triggers[:1]})
        points += x.size
    assert points / 200 < points / max(fired, 1) < points / 20       # an alarm per 60 to 600 points


def test_stations_are_compared_pair_by_pair_and_the_one_that_reads_high_is_named():
    from scipy.stats import ttest_ind
    rng = np.random.default_rng(7)
    a, b, c = (70 + rng.standard_normal(120) for _ in range(3))
    b = b + 0.8                                       # station B reads high
    comparison = compare_stations(np.concatenate([a, b, c]), ["A"] * 120 + ["B"] * 120 + ["C"] * 120)
    reads = {s.station: s.reads for s in comparison.stations}
    assert reads == {"A": "", "B": "high", "C": ""}
    pairs = {(p.a, p.b): p for p in comparison.pairs}
    assert pairs["A", "B"].significant and pairs["B", "C"].significant and not pairs["A", "C"].significant
    assert pairs["A", "B"].offset == pytest.approx(a.mean() - b.mean())
    assert pairs["A", "B"].p == pytest.approx(ttest_ind(a, b, equal_var=False).pvalue, rel=1e-9)
    assert compare_stations([1.0, 2.0, 3.0], ["A", "A", "B"]).pairs == ()      # one station of two units


def population(values, validity=None, verdicts=None, stations=None):
    n = len(values)
    return Population(tuple(f"20240501-{i:06d}-abcdef" for i in range(n)),
                      tuple(f"2024-05-01T{i // 3600:02d}:{i // 60 % 60:02d}:{i % 60:02d}Z" for i in range(n)),
                      tuple(stations or ["QA1"] * n), ("W6",) * n, tuple(f"SN{i}" for i in range(n)), ("ana",) * n,
                      tuple(validity or ["green"] * n), tuple(verdicts or [None] * n), (None,) * n,
                      {"fs": tuple(values)}, {"fs": (0.1,) * n})


def test_production_stats_leave_out_what_judges_nothing_and_say_why():
    x = list(drifted(3, "step"))
    validity = ["green"] * 300
    verdicts = [None] * 300
    validity[10] = "red"
    verdicts[11] = "not judged"
    stats = production_stats(population(x, validity, verdicts))
    fs = stats.parameters["fs"]
    assert fs.capability.n == 298 and "SN10" not in fs.ids and fs.ids[0] == "20240501-000000-abcdef"
    assert sum(stats.excluded.values()) == 2 and any("red" in r for r in stats.excluded)
    first = min(t for a in fs.chart.alarms for t in a.triggers if t >= 148)
    alarm = next(a for a in fs.chart.alarms if first in a.triggers)
    doc = fs.as_json()["control_chart"]["alarms"]
    named = next(d for d in doc if d["first"] == alarm.triggers[0] and d["rule"] == alarm.rule)
    assert named["title"] and named["measurements"] == [fs.ids[i] for i in alarm.points]
    assert fs.display_unit == "Hz" and fs.histogram[1].sum() == 298


def test_the_statistics_import_no_scipy():
    """`qa stats` over 100,000 units must take about a second, and importing scipy.special alone took 0.1-0.3 s
    of it: the statistics (stations' t tests included) and the units of the limits need no scipy."""
    import subprocess
    import sys
    code = """if True:
        import sys
        import numpy as np
        from analysis.archive.pg import PostgresArchive
        from analysis.archive.population import Population
        from analysis.limits import parameter_units
        from analysis.production import production_stats
        n = 60
        x = tuple(70.0 + np.sin(np.arange(n)) + (np.arange(n) % 3 == 1) * 0.5)
        population = Population(tuple(f"20240501-{i:06d}-abcdef" for i in range(n)), ("2024-05-01T00:00:00Z",) * n,
                                tuple("QA%d" % (i % 3) for i in range(n)), ("W6",) * n, ("SN",) * n, ("ana",) * n,
                                ("green",) * n, (None,) * n, (None,) * n, {"fs": x}, {})
        stats = production_stats(population)
        assert stats.parameters["fs"].stations.pairs[0].p is not None
        assert parameter_units()["fs"][0] == "Hz"
        print(sorted(m for m in sys.modules if m.split(".")[0] == "scipy"))
    """
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=paced(120))
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "[]"


def test_qa_stats_with_stored_limits_imports_no_scipy(tmp_path):
    """The whole command, limits stored: reading them (their units, written as the reports write them) once
    pulled in the report package, the fit and scipy.stats: +0.7 s on every `linpar qa stats`."""
    import subprocess
    import sys
    from pathlib import Path
    root = tmp_path / "archive"
    example = Path(__file__).resolve().parents[3] / "resources" / "limits" / "example.json"
    store = subprocess.run([sys.executable, "-m", "app.cli", "qa", "limits", "--store", str(example), "--root",
                            str(root)], capture_output=True, text=True, timeout=paced(120))
    assert store.returncode == 0, store.stderr
    code = f"""if True:
        import sys
        from app.cli import main
        assert main(["qa", "stats", "--root", {str(root)!r}]) == 0
        print(sorted(m for m in sys.modules if m.split(".")[0] == "scipy"))
    """
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=paced(120))
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "[]"
