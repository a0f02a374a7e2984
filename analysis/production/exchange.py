"""The selected population as CSV (long: one row per measurement and parameter) and as JSON.

Values in SI with their unit, as the archive keeps them; a parameter a
measurement could not give is a row with an empty value (CSV) or null (JSON),
so that its absence is seen, not guessed. The measurements a statistic leaves
out (red, not judgeable) are exported too, with their validity and verdict.
The CSV starts with '#' comment lines (what it is, the exporting software);
each row carries its own measurement's traceability (date, station, driver,
serial, operator).
"""
from __future__ import annotations

import csv
import io

from analysis.session import comment_lines
from analysis.text_boundary import spreadsheet_cell

CSV_COLUMNS = ("id", "measured_at", "station", "driver", "serial", "operator", "validity", "verdict",
               "limits_version", "parameter", "value", "std", "unit")
FORMAT = "linpar-population/1"


def _units(names) -> dict[str, str]:
    from analysis.limits import parameter_units
    table = parameter_units()
    return {n: table.get(n, ("",))[0] for n in names}


def population_csv(population) -> str:
    out = io.StringIO()
    title = "linpar population: one row per measurement and parameter, value and std in the unit of the row"
    out.writelines(line + "\n" for line in comment_lines(title, {}))
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    units = _units(population.values)
    for u, mid in enumerate(population.ids):
        # Names people typed: never a formula when the QA engineer opens the file in a spreadsheet.
        head = (mid, population.measured_at[u], *(spreadsheet_cell(t) for t in (
                population.stations[u], population.drivers[u], population.serials[u], population.operators[u])),
                population.validity[u],
                population.verdicts[u] or "", "" if population.limits_versions[u] is None
                else population.limits_versions[u])
        for name in population.values:
            value, std = population.value(name, u), population.std(name, u)
            writer.writerow((*head, name, "" if value is None else repr(value), "" if std is None else repr(std),
                             units[name]))
    return out.getvalue()


def population_json(population, selection: str, location: str, limits=None) -> dict:
    units = _units(population.values)
    return {"format": FORMAT, "archive": location, "selection": selection,
            "limits": None if limits is None else {"version": limits.version, "name": limits.name,
                                                   "document": limits.document},
            "measurements": [
                {"id": mid, "measured_at": population.measured_at[u], "station": population.stations[u],
                 "driver": population.drivers[u], "serial": population.serials[u],
                 "operator": population.operators[u], "validity": population.validity[u],
                 "verdict": population.verdicts[u], "limits_version": population.limits_versions[u],
                 "parameters": {name: {"value": population.value(name, u), "std": population.std(name, u),
                                       "unit": units[name]} for name in population.values}}
                for u, mid in enumerate(population.ids)]}
