"""QA limits files of any content: Limits that judge and print, or one LimitsError line naming the file.

Structure-aware: documents built from the real parameter names and units
with random entries (nominal/tolerance/min/max of every JSON type, percent
strings, unknown keys), raw bytes, and the inputs that once escaped as other
errors (an integer beyond the float range, nesting beyond the recursion
limit, a 100,000-digit percentage that took quadratic time, a FIFO).
"""
from __future__ import annotations

import json
import os

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from analysis.derived import ParameterValue
from analysis.limits import LimitsError, format_verdicts, judge_result, load_limits, parameter_units
from tests.reliability.fuzzing import FUZZ_MANY, one_line

pytestmark = pytest.mark.timeout(60)

UNITS = parameter_units()
NAMES = sorted(UNITS)
UNIT_WORDS = sorted({u for si, customary, _ in UNITS.values() for u in (si, customary)}
                    | {"", "-", "Ω", "ohms", "µF", "L", "furlong", "%"})
numbers = st.one_of(st.integers(-(10**6), 10**6), st.floats(allow_nan=False, allow_infinity=False),
                    st.sampled_from([0, -0.0, 10**400, 1e308, 5e-324]))
tolerances = st.one_of(numbers, st.sampled_from(["5%", " 0.5 % ", "%", "1e999%", "-5%", "5", "five %", "5%%"]),
                       st.text(alphabet="0123456789.eE%+- ", max_size=12))
anything = st.one_of(st.none(), st.booleans(), numbers, st.text(max_size=6), st.lists(st.integers(), max_size=2),
                     st.dictionaries(st.text(max_size=3), st.integers(), max_size=2))
entries = st.fixed_dictionaries({}, optional={
    "nominal": numbers | anything, "tolerance": tolerances | anything, "min": numbers | anything,
    "max": numbers | anything, "unit": st.sampled_from(UNIT_WORDS) | anything, "note": anything,
    "extra": anything})


@st.composite
def sound_entries(draw, name: str) -> dict:
    """An entry a person would write for `name`: its own units, nominal and tolerance or min and/or max."""
    si, customary, _ = UNITS[name]
    plain = st.floats(1e-3, 1e3)
    entry = {"unit": draw(st.sampled_from([si, customary]))}
    if draw(st.booleans()):
        entry.update(nominal=draw(plain | numbers), tolerance=draw(st.sampled_from(["5%", 0.5, " 10 %", 2])
                                                                   | tolerances))
    else:
        low, high = sorted(draw(st.lists(plain, min_size=2, max_size=2)))
        entry.update(draw(st.sampled_from([{"min": low}, {"max": high}, {"min": low, "max": high},
                                           {"min": draw(numbers), "max": draw(numbers)}])))
    if draw(st.booleans()):
        entry["note"] = draw(st.text(max_size=8))
    return entry


sound_tables = st.lists(st.sampled_from(NAMES), min_size=1, max_size=3, unique=True).flatmap(
    lambda names: st.fixed_dictionaries({n: sound_entries(n) for n in names}))
parameter_tables = st.one_of(
    sound_tables, sound_tables, sound_tables,
    st.dictionaries(st.sampled_from(NAMES) | st.text(max_size=5), entries, max_size=4),
    anything)
documents = st.fixed_dictionaries(
    {"format": st.sampled_from(["linpar-limits/1"] * 4 + ["linpar-limits/2", None]), "parameters": parameter_tables},
    optional={"name": anything})
PARAMETERS = {name: ParameterValue(name=name, value=1.0, std=0.01, unit=si, display_unit=customary,
                                   display_scale=scale) for name, (si, customary, scale)
              in UNITS.items()}


def load_or_refuse(path):
    try:
        limits = load_limits(path)
    except LimitsError as exc:
        one_line(exc, str(path))
        return None
    for limit in limits.limits:
        assert limit.name in UNITS and (limit.low is not None or limit.high is not None)
        assert limit.low is None or limit.high is None or not limit.low > limit.high
    # Whatever was accepted can be judged, written as JSON and printed.
    for validity in ("green", "red"):
        json.dumps(judge_result(limits, PARAMETERS, validity), allow_nan=False)
        format_verdicts(limits, PARAMETERS, validity).encode("utf-8")
    return limits


@FUZZ_MANY
@given(doc=documents)
@example(doc={"format": "linpar-limits/1", "parameters": {"RE": {"nominal": 10**400, "tolerance": 1, "unit": "ohm"}}})
@example(doc={"format": "linpar-limits/1", "parameters": {"RE": {"nominal": 3, "tolerance": 10**400, "unit": "ohm"}}})
@example(doc={"format": "linpar-limits/1", "parameters": {"fs": {"min": 10**400, "unit": "Hz"}}})
def test_limits_documents_load_or_are_refused_in_one_line(tmp_path_factory, doc):
    path = tmp_path_factory.mktemp("limits") / "limits.json"
    path.write_text(json.dumps(doc, indent=1))
    load_or_refuse(path)


@FUZZ_MANY
@given(raw=st.binary(max_size=200) | st.text(max_size=200).map(lambda t: t.encode("utf-8", "surrogatepass")))
def test_limits_files_of_random_bytes(tmp_path_factory, raw):
    path = tmp_path_factory.mktemp("limits") / "limits.json"
    path.write_bytes(raw)
    load_or_refuse(path)


@pytest.mark.parametrize("text, words", [
    ("[" * 100_000 + "]" * 100_000, ["nested too deeply"]),                                  # was RecursionError
    ('{"format": "linpar-limits/1", "parameters": {"RE": {"nominal": 1' + "0" * 400 +
     ', "tolerance": 1, "unit": "ohm"}}}', ["parameters.RE.nominal"]),                       # was OverflowError
    ('{"format": "linpar-limits/1", "name": "\\ud800", "parameters": {"RE": {"max": 4, "unit": "ohm"}}}',
     ["surrogate"]),                                                                           # unprintable name
    ('{"format": "linpar-limits/1", "parameters": {"RE": {"nominal": 3, "unit": "ohm", "tolerance": "'
     + "1" * 100_000 + 'x%"}}}', ["parameters.RE.tolerance"]),                                # was quadratic
    ('{"format": "linpar-limits/1", "parameters": {"RE": {"nominal": NaN, "tolerance": 1, "unit": "ohm"}}}',
     ["NaN"]),
])
def test_limits_files_that_once_escaped_as_other_errors(tmp_path, text, words):
    path = tmp_path / "limits.json"
    path.write_text(text)
    with pytest.raises(LimitsError) as info:
        load_limits(path)
    one_line(info.value, str(path), *words)


def test_a_fifo_or_a_folder_is_refused_without_blocking(tmp_path):
    os.mkfifo(tmp_path / "limits.json")
    (tmp_path / "folder.json").mkdir()
    for path in (tmp_path / "limits.json", tmp_path / "folder.json", tmp_path / "missing.json"):
        with pytest.raises(LimitsError) as info:
            load_limits(path)
        one_line(info.value, str(path))


@pytest.mark.parametrize("entry", [{"nominal": 3.0, "tolerance": "1e999%"}, {"nominal": 1e308, "tolerance": 1e308},
                                   {"nominal": -1e308, "tolerance": "100%"}])
def test_bounds_that_overflow_are_refused_not_judged(tmp_path, entry):
    """`linpar analyze --json --limits` writes strict JSON: an infinite bound would end it with a traceback."""
    path = tmp_path / "limits.json"
    path.write_text(json.dumps({"format": "linpar-limits/1", "parameters": {"RE": {**entry, "unit": "ohm"}}}))
    with pytest.raises(LimitsError) as info:
        load_limits(path)
    one_line(info.value, "parameters.RE", "overflow")
