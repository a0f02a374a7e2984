"""The QA limits part of a report: the overall verdict and, per parameter, value, limit and margin.

Numbers are shown in the unit the limits file uses for that parameter, so
the operator reads them against the file as written, rounded as the QA and
Results pages show them (at most 4 significant digits, fewer when the sigma
supports fewer; the parameter table beside it has every digit the sigma
allows), under the names the pages use (Re, not RE). The verdict is the QA
page's and the CLI's (analysis.qa_verdict): a red measurement is INVALID
(measure again; the unit itself was not judged), one whose model misses a
curve by more than the fit-error tolerance is NOT JUDGED (find the model);
either way no parameter is judged against its limit. Otherwise each
parameter is judged by its interval: pass, FAIL, or uncertain (measure again).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from analysis.derived import ParameterValue
from analysis.parameter_names import display_name
from analysis.report.numbers import pretty_unit, readable_number, short_number
from analysis.validity.fit import FAIL, INVALID, NOT_JUDGED, PASS, UNCERTAIN, VERDICT_HEADLINES
from analysis.validity.result import ResultValidity

# (background, text) of the verdict banner, also the QA page's. INVALID has its own colour (violet), not FAIL's
# red: a broken measurement says nothing of the unit, and an operator reads the colour first.
VERDICT_COLOURS = {PASS: ("#d8f0d8", "#1b5e20"), FAIL: ("#f8d4d4", "#8e1b1b"), INVALID: ("#e6dcf5", "#4a2a7a"),
                   UNCERTAIN: ("#fde3cc", "#8a4300"), NOT_JUDGED: ("#fff1c9", "#7a5300")}


@dataclass(frozen=True)
class LimitRow:
    name: str
    value: str           # in the limits file's unit
    limit: str           # as the file gives it ("70 ± 5 Hz", "11 .. 13 g", "≥ 5 T·m")
    margin: str          # "inside by 0.3 Hz" | "0.8 Hz above max" | "0.2 g below min" | ""
    used: str            # share of a two-sided tolerance used ("58 %"), or ""
    outcome: str         # "pass" | "FAIL" | "uncertain" | "not judged"
    note: str            # why there is no value (the parameter table has the whole reason)


@dataclass(frozen=True)
class QASection:
    file: str            # the limits file's name (no folders: a report travels)
    name: str            # the name the file gives itself
    verdict: str         # "pass" | "fail" | "uncertain" | "invalid" | "not judged"
    why: str
    rows: tuple[LimitRow, ...]
    fit_error: str = ""  # "impedance 2.1 % (tolerance 5 %), displacement ..." or ""

    @property
    def headline(self) -> str:
        return VERDICT_HEADLINES[self.verdict]


def _unit(limit) -> str:
    return "" if limit.unit.strip() in ("", "-", "1") else pretty_unit(limit.unit)


def _row(verdict, parameter: ParameterValue | None, judged: bool) -> LimitRow:
    from analysis.qa_verdict import margin_text, outcome_word
    limit = verdict.limit
    unit = _unit(limit)
    outcome = outcome_word(verdict, judged)
    if verdict.value is None:
        # "not measured: not identifiable without displacement: Bl only appears in Hx; ..." -> up to the 2nd colon
        note = ":".join(verdict.note.split(":")[:2])
        return LimitRow(display_name(limit.name), "n/a", limit.text, "", "", outcome, note)
    std = parameter.std / limit.to_si if parameter is not None and parameter.std is not None else None
    value = f"{short_number(verdict.value / limit.to_si, std)} {unit}".rstrip()
    used = verdict.tolerance_used()
    return LimitRow(display_name(limit.name), value, limit.text, margin_text(verdict), "" if used is None else f"{100 * used:.0f} %",
                    outcome, "")


def qa_section(limits, parameters: Mapping[str, ParameterValue], validity: ResultValidity | str) -> QASection:
    """limits: analysis.limits.Limits; parameters in SI as the result has them; validity: the result's, or its
    overall light alone."""
    from analysis.qa_verdict import judge
    judgement = judge(limits, parameters, validity)
    rows = tuple(_row(v, parameters.get(v.limit.name), judgement.judged) for v in judgement.verdicts)
    from analysis.fit.error import band_text
    shown = None if isinstance(validity, str) else validity
    fit_error = ", ".join(f"{name} {readable_number(err)} %{band_text(shown, name)} (tolerance "
                          f"{limits.fit_error_percent.get(name, float('nan')):g} %)"
                          for name, err in judgement.fit_error_percent.items())
    return QASection(limits.path.name, limits.name, judgement.verdict, judgement.why, rows, fit_error)
