"""The QA limits part of a report: the overall verdict and, per parameter, value, limit and margin.

Numbers are shown in the unit the limits file uses for that parameter, so
the operator reads them against the file as written. The verdict is the QA
page's (analysis.validity.fit.qa_blocker): a red measurement FAILS with the
reason that the measurement is broken (measure again; the unit itself was
not judged), one the model does not describe is NOT JUDGED (find the model).
Either way no parameter is judged against its limit.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from analysis.derived import ParameterValue
from analysis.report.numbers import format_number, pretty_unit
from analysis.validity.fit import INVALID, NOT_JUDGED, VERDICT_HEADLINES, qa_blocker

# (background, text) of the verdict banner, also the QA page's: an invalid measurement is a FAIL, in red.
VERDICT_COLOURS = {"pass": ("#d8f0d8", "#1b5e20"), "fail": ("#f8d4d4", "#8e1b1b"), INVALID: ("#f8d4d4", "#8e1b1b"),
                   NOT_JUDGED: ("#fff1c9", "#7a5300")}


@dataclass(frozen=True)
class LimitRow:
    name: str
    value: str           # in the limits file's unit
    limit: str           # as the file gives it ("70 ± 5 Hz", "11 .. 13 g", "≥ 5 T·m")
    margin: str          # "inside by 0.3 Hz" | "0.8 Hz above max" | "0.2 g below min" | ""
    used: str            # share of a two-sided tolerance used ("58 %"), or ""
    outcome: str         # "pass" | "FAIL" | "not judged"
    note: str            # why there is no value (the parameter table has the whole reason)


@dataclass(frozen=True)
class QASection:
    file: str            # the limits file's name (no folders: a report travels)
    name: str            # the name the file gives itself
    verdict: str         # "pass" | "fail" | "invalid" | "not judged"
    why: str
    rows: tuple[LimitRow, ...]

    @property
    def headline(self) -> str:
        return VERDICT_HEADLINES[self.verdict]


def _unit(limit) -> str:
    return "" if limit.unit.strip() in ("", "-", "1") else pretty_unit(limit.unit)


def _row(verdict, parameter: ParameterValue | None, judged: bool) -> LimitRow:
    limit = verdict.limit
    unit = _unit(limit)
    outcome = "not judged" if not judged else ("pass" if verdict.passed else "FAIL")
    if verdict.value is None:
        # "not measured: not identifiable without displacement: Bl only appears in Hx; ..." -> up to the 2nd colon
        note = ":".join(verdict.note.split(":")[:2])
        return LimitRow(limit.name, "n/a", limit.text, "", "", outcome, note)
    std = parameter.std / limit.to_si if parameter is not None and parameter.std is not None else None
    value = f"{format_number(verdict.value / limit.to_si, std)} {unit}".rstrip()
    distance, side = verdict.margin()
    shown = f"{abs(distance) / limit.to_si:.3g} {unit}".rstrip()
    margin = f"inside by {shown}" if distance >= 0 else f"{shown} {'below min' if side == 'min' else 'above max'}"
    used = verdict.tolerance_used()
    return LimitRow(limit.name, value, limit.text, margin, "" if used is None else f"{100 * used:.0f} %",
                    outcome, "")


def qa_section(limits, parameters: Mapping[str, ParameterValue], validity: Mapping | str) -> QASection:
    """limits: analysis.limits.Limits; parameters in SI as the result has them; validity: the result's (as
    JSON), or its overall light alone."""
    validity = {"overall": validity} if isinstance(validity, str) else validity
    validity_overall = str(validity.get("overall", "unknown"))
    verdicts = limits.judge(parameters)
    blocker = qa_blocker(validity)
    judged = blocker is None
    rows = tuple(_row(v, parameters.get(v.limit.name), judged) for v in verdicts)
    failed = [v.limit.name for v in verdicts if not v.passed]
    if blocker is not None:
        verdict, why = blocker
    elif failed:
        verdict, why = "fail", (f"{len(failed)} of {len(verdicts)} parameters outside their limits: "
                                + ", ".join(failed))
    else:
        verdict, why = "pass", f"all {len(verdicts)} parameters within their limits"
        if validity_overall == "yellow":
            why += " (the measurement is doubtful: read the yellow findings)"
    return QASection(limits.path.name, limits.name, verdict, why, rows)
