"""Parameters as CSV and JSON: SI values with their standard uncertainty, and the customary unit beside.

CSV: comment lines starting with '#' (what the file is, the traceability
header of analysis.session one item a line: driver, serial, date, operator,
station, template, software; and the exporting software), then one row per
parameter, columns

    parameter, value, std, unit, display_value, display_std, display_unit, note, std_noise, std_model

(value and std in SI; display_* = SI x display_scale; an empty value with a
note says why it is missing; std is the total standard uncertainty, std_noise and
std_model its two parts in SI, empty where the analysis did not estimate them:
analysis.fit.model_uncertainty). Decimal point '.', comma-separated, UTF-8,
RFC 4180 quoting; in the comment lines a part after a comma that would start a spreadsheet formula is quoted
(analysis.text_boundary.spreadsheet_comment). A reader skips the '#' lines (pandas: comment="#").

JSON ("linpar-parameters/1"): the driver header, the parameters keyed by
name ({value, std, unit, display_unit, display_scale, reason; std_noise and std_model where estimated}), the model
(effects, reduced chi^2 per channel, AIC, BIC) and the overall validity.
"""
from __future__ import annotations

import csv
import io
import json
from typing import TYPE_CHECKING, Mapping

from analysis.export.registry import Exporter
from analysis.session import comment_lines
from analysis.text_boundary import spreadsheet_cell

if TYPE_CHECKING:      # a type only: listing the formats (the CLI's parser) loads no archive
    from analysis.archive.results import StoredResult

JSON_FORMAT = "linpar-parameters/1"
CSV_COLUMNS = ("parameter", "value", "std", "unit", "display_value", "display_std", "display_unit", "note",
               "std_noise", "std_model")


def _num(x) -> str:
    return "" if x is None else repr(float(x))


def parameters_csv(result: StoredResult, header: Mapping | None = None) -> str:
    buf = io.StringIO()
    title = "linpar parameters: value and std in SI, display_value and display_std in display_unit"
    buf.writelines(line + "\n" for line in comment_lines(title, header or {}))
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for p in result.parameters.values():
        ok = p.value is not None
        writer.writerow([p.name, _num(p.value), _num(p.std), p.unit,
                         _num(p.value * p.display_scale) if ok else "",
                         _num(p.std * abs(p.display_scale)) if ok and p.std is not None else "",
                         p.display_unit, spreadsheet_cell(p.reason or ""), _num(p.std_noise), _num(p.std_model)])
    return buf.getvalue()


def parameters_json(result: StoredResult, header: Mapping | None = None) -> str:
    info = result.model_info
    doc = {
        "format": JSON_FORMAT,
        "driver": {k: v for k, v in dict(header or {}).items() if v},
        "sd_m2": result.sd_m2,
        "parameters": {p.name: {"value": p.value, "std": p.std, "unit": p.unit, "display_unit": p.display_unit,
                                "display_scale": p.display_scale, **({"reason": p.reason} if p.reason else {}),
                                **{k: v for k, v in (("std_noise", p.std_noise), ("std_model", p.std_model))
                                   if v is not None}}
                       for p in result.parameters.values()},
        "model": {k: info.get(k) for k in ("effects", "chi2_red", "aic", "bic", "n_data", "n_parameters", "converged")},
        "validity": result.overall,
    }
    return json.dumps(doc, indent=1, ensure_ascii=False, allow_nan=False) + "\n"


# A result with nothing fitted (a broken measurement) still exports its parameters, each "not measured" and why.
EXPORTERS = (
    Exporter("csv", "Parameters, CSV", ".csv", lambda result, header: parameters_csv(result, header).encode("utf-8"),
             needs_fit=False, rank=10),
    Exporter("json", "Parameters, JSON", ".json",
             lambda result, header: parameters_json(result, header).encode("utf-8"), needs_fit=False, rank=11),
)
