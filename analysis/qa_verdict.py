"""One QA verdict for a result against limits, as every output shows it (the QA page, reports, the CLI, the archive).

The measurement first (analysis.validity.fit.qa_blocker): a red one is
INVALID (measure again), one whose model misses a curve by more than the
limits file's fit-error tolerance is NOT JUDGED. Then the parameters, each by
its interval (analysis.limits.Limit.judge): FAIL when any lies wholly outside
its limits, UNCERTAIN (measure again) when any straddles one, else PASS. The
why names the parameters concerned with their margins, in the limits file's
units.
"""
from __future__ import annotations

import math

from dataclasses import dataclass
from typing import Mapping

from analysis.qa_interval import FAIL, INTERVAL_K, PASS, UNCERTAIN, verdict_of
from analysis.report.numbers import plain_number, pretty_unit
from analysis.validity.fit import VERDICT_HEADLINES, qa_blocker
from analysis.validity.findings import Severity
from analysis.validity.result import ResultValidity


@dataclass(frozen=True, kw_only=True)
class QAJudgement:
    verdict: str                        # pass | fail | uncertain | invalid | not judged
    why: str
    verdicts: tuple                     # analysis.limits.Verdict, one per limit, in the file's order
    judged: bool                        # False: invalid or not judged, no parameter judged against its limit
    fit_error_percent: Mapping[str, float]

    @property
    def headline(self) -> str:
        return VERDICT_HEADLINES[self.verdict]


def _unit(verdict) -> str:
    unit = verdict.limit.unit.strip()
    return "" if unit in ("", "-", "1") else pretty_unit(unit)


def margin_text(verdict) -> str:
    """"0.8 Hz above max", "inside by 0.3 Hz" (the value's distance to its nearest bound), or ""."""
    margin = verdict.margin()
    if margin is None:
        return ""
    distance, side = margin
    shown = f"{plain_number(abs(distance) / verdict.limit.to_si)} {_unit(verdict)}".rstrip()     # never "1.2e-05"
    return f"inside by {shown}" if distance >= 0 else f"{shown} {'below min' if side == 'min' else 'above max'}"


def outcome_word(verdict, judged: bool = True) -> str:
    """What a table's result column reads for one parameter."""
    if not judged:
        return "not judged"
    return {PASS: "pass", FAIL: "FAIL", UNCERTAIN: "uncertain"}.get(verdict.outcome, verdict.outcome)


def _straddle_text(verdict) -> str:
    lo, hi = verdict.interval
    scale, unit = verdict.limit.to_si, _unit(verdict)
    bounds = [b / scale for b in (verdict.limit.low, verdict.limit.high) if b is not None]
    digits = telling_digits(lo / scale, hi / scale, *bounds)
    return (f"{verdict.limit.name} {lo / scale:.{digits}g} .. {hi / scale:.{digits}g} {unit}".rstrip()
            + f" across {verdict.limit.text}")


def telling_digits(*values: float, least: int = 4, most: int = 12) -> int:
    """The fewest significant digits (from `least`) that write every two different `values` differently: an
    interval across a limit was "3.02 .. 3.02 Ω across ≤ 3.02 Ω", the three numbers that decide it the same."""
    distinct = {v for v in values if math.isfinite(v)}
    for digits in range(least, most + 1):
        if len({f"{v:.{digits}g}" for v in distinct}) == len(distinct):
            return digits
    return most


def judge(limits, parameters: Mapping, validity: ResultValidity | str) -> QAJudgement:
    """The verdict of `parameters` (name -> analysis.derived.ParameterValue) with their `validity` (or the
    overall light alone) against `limits` (analysis.limits.Limits, which imports this module: not imported
    here)."""
    validity = ResultValidity(overall=validity) if isinstance(validity, str) else validity
    verdicts = limits.judge(parameters)
    errors = dict(validity.fit_error_percent or {})
    blocker = qa_blocker(validity, limits.fit_error_percent)
    if blocker is not None:
        return QAJudgement(verdict=blocker[0], why=blocker[1], verdicts=verdicts, judged=False,
                           fit_error_percent=errors)
    verdict = verdict_of(verdicts)
    if verdict == FAIL:
        failed = [v for v in verdicts if v.outcome == FAIL]
        why = f"{len(failed)} of {len(verdicts)} parameters outside their limits: " + ", ".join(
            f"{v.limit.name} {margin_text(v)}" if v.value is not None else f"{v.limit.name} not measured"
            for v in failed)
    elif verdict == UNCERTAIN:
        straddling = [v for v in verdicts if v.outcome == UNCERTAIN]
        why = (f"{', '.join(_straddle_text(v) for v in straddling)}: the interval (value ± {INTERVAL_K:g} σ) "
               "straddles the limit; measure again (more periods narrow it)")
    else:
        why = f"all {len(verdicts)} parameters within their limits (value ± {INTERVAL_K:g} σ)"
        if validity.overall == Severity.YELLOW:
            why += "; the measurement is doubtful: read the yellow findings"
    return QAJudgement(verdict=verdict, why=why, verdicts=verdicts, judged=True, fit_error_percent=errors)
