"""What `linpar qa` prints for people: the statistics table, the alarms with their measurements, the stations,
the limits versions, a proposal. Customary units (Hz, ohm, mH, g), values to four digits; --json has it all in SI.
"""
from __future__ import annotations

ALARMS_SHOWN = 10
IDS_SHOWN = 3


def _v(value, scale: float = 1.0) -> str:
    return "-" if value is None else f"{value * scale:.4g}"


def _extreme(value, capability, scale: float) -> str:
    """The smallest or largest unit's value with as many digits as tell it from the limits (max 3.02 against
    "≤ 3.02 Ω" with 11 % of the units outside read as if every unit sat on the limit)."""
    if value is None:
        return "-"
    from analysis.qa_verdict import telling_digits
    bounds = [b * scale for b in (capability.low, capability.high) if b is not None]
    digits = telling_digits(value * scale, *bounds, most=7)      # 11 characters at most: the column keeps
    return f"{value * scale:.{digits}g}"


INDEX_WIDTH = 7       # a capability index in at most 7 characters, each column one wider: never glued


def _index(value) -> str:
    """Cp, Cpk, ... to two decimals, or in scientific notation when that does not fit (a 6-digit Cp of a
    nearly constant parameter): the columns keep their width and each number its sign."""
    if value is None:
        return "-"
    for text in (f"{value:.2f}", f"{value:.1e}", f"{value:.0e}"):
        if len(text) <= INDEX_WIDTH:
            return text
    return text


def _index_name(key: str) -> str:
    """'cpk' -> 'Cpk'."""
    return key[0].upper() + key[1:]


def _unit(unit: str) -> str:
    return "" if unit in ("-", "1") else unit


def _ids(ids: list[str]) -> str:
    shown = ", ".join(ids[:IDS_SHOWN])
    return shown + (f" and {len(ids) - IDS_SHOWN} more" if len(ids) > IDS_SHOWN else "")


def stats_text(stats, location: str) -> str:
    lines = [f"{location}: {stats.selection}: {stats.n_measurements} measurement(s)"]
    if stats.excluded:
        lines[0] += "; left out of the statistics: " + ", ".join(f"{n} {why}" for why, n in stats.excluded.items())
    if stats.limits is not None:
        lines.append(f"Limits: version {stats.limits.version}, {stats.limits.name} (stored {stats.limits.created_at}"
                     f" by {stats.limits.created_by})")
    else:
        lines.append("Limits: none stored: Cp, Cpk, Pp, Ppk and yield need limits ('linpar qa limits --store FILE')")
    if stats.verdicts:
        counts = ", ".join(f"{n} {v}" for v, n in sorted(stats.verdicts.items()))
        fpy = stats.first_pass_yield
        by = "; ".join(f"v{k}: {sum(v.values())}" for k, v in stats.verdicts_by_version.items())
        lines.append(f"Verdicts as the stations recorded them: {counts}" +
                     (f"; first-pass yield {100 * fpy:.1f} %" if fpy is not None else "") +
                     (f" (judged by limits {by})" if by else ""))
    if not stats.parameters:
        lines.append("No measurement in this selection.")
        return "\n".join(lines)
    # The limit as its file says it, whole (cut to 21 characters, "0.000421234 .. 0.000438765 m/N" lost its upper
    # bound and its unit).
    limit_width = max([22, *(len(p.limit_text or "-") + 1 for p in stats.parameters.values())])
    head = (f"{'parameter':<13}{'unit':<6}{'n':>7}{'mean':>11}{'sigma':>10}{'min':>11}{'max':>11}  "
            f"{'limit':<{limit_width}}{'Cp':>8}{'Cpk':>8}{'Pp':>8}{'Ppk':>8}{'yield':>8}{'alarms':>7}")
    lines += ["", head]
    for p in stats.parameters.values():
        c, s = p.capability, p.display_scale
        yield_text = "-" if c.yield_fraction is None else f"{100 * c.yield_fraction:.1f}%"
        alarms = "-" if p.chart is None else str(len(p.chart.alarms))
        lines.append(f"{p.name:<13}{_unit(p.display_unit):<6}{c.n:>7}{_v(c.mean, s):>11}{_v(c.sigma_overall, s):>10}"
                     f"{_extreme(c.minimum, c, s):>11}{_extreme(c.maximum, c, s):>11}  "
                     f"{(p.limit_text or '-'):<{limit_width}}"
                     f"{_index(c.cp):>8}{_index(c.cpk):>8}{_index(c.pp):>8}{_index(c.ppk):>8}{yield_text:>8}"
                     f"{alarms:>7}")
    lines += _estimate_lines(stats) + _alarm_lines(stats) + _station_lines(stats)
    return "\n".join(lines)


def _estimate_lines(stats) -> list[str]:
    """The indices as what they are, estimates: each one's 95 % interval, and, below the minimum count, that they
    are no verdict (a Cpk of 9,983 from 4 units printed alone read as a capable process)."""
    from analysis.production.capability_interval import MIN_UNITS, too_few
    lines, counts = [], []
    for p in stats.parameters.values():
        shown = [(name, interval) for name, interval in p.capability.intervals().items() if interval is not None]
        if shown:
            counts.append(p.capability.n)
            lines.append(f"{p.name:<13}95 % intervals: " + ", ".join(
                f"{_index_name(name)} {_index(lo)} .. {_index(hi)}" for name, (lo, hi) in shown))
    if not lines:
        return []
    n = min(counts)
    head = ["", "Cp, Cpk, Pp and Ppk are estimates from the units measured:"]
    if n < MIN_UNITS:
        head[1] += f" {too_few(n)}."
    return head + lines


def _alarm_lines(stats) -> list[str]:
    charts = [(p, p.chart) for p in stats.parameters.values() if p.chart is not None and p.chart.alarms]
    if not charts:
        short = [p.chart.baseline for p in stats.parameters.values() if p.chart is not None and not p.chart.judges]
        if not short:
            return []
        from analysis.production.control_chart import MIN_BASELINE
        return ["", f"Control chart: no alarms judged: its centre and sigma would come from {max(short)} units; at "
                    f"least {MIN_BASELINE} set them"]
    baseline = charts[0][1].baseline
    lines = ["", f"Control-chart alarms (individuals; centre and sigma from the first {baseline} units; an alarm is a "
                 "reason to look, about one in 92 units of a stable process raises one):"]
    for p, chart in charts:
        for alarm in chart.alarms[:ALARMS_SHOWN]:
            side = f", {alarm.side} the centre line" if alarm.side else ""
            units = [i + 1 for i in alarm.points]
            span = f"unit {units[0]}" if len(units) == 1 else f"units {units[0]}-{units[-1]}"
            lines.append(f"  {p.name}: {alarm.rule} {alarm.title}{side}: {span}: "
                         f"{_ids([p.ids[i] for i in alarm.points])}")
        if len(chart.alarms) > ALARMS_SHOWN:
            lines.append(f"  {p.name}: ... and {len(chart.alarms) - ALARMS_SHOWN} more alarms (--json lists every one)")
    return lines


def _station_lines(stats) -> list[str]:
    lines = []
    for p in stats.parameters.values():
        for st in p.stations.stations:
            if not st.reads:
                continue
            others = [(q.b if q.a == st.station else q.a, q.p) for q in p.stations.pairs
                      if st.station in (q.a, q.b)]
            sigmas = "" if st.offset_sigmas is None else f", {st.offset_sigmas:+.2f} sigma"
            lines.append(f"  {p.name}: station {st.station} reads {st.reads}: {st.offset * p.display_scale:+.3g} "
                         f"{_unit(p.display_unit)} from the stations' mean{sigmas}; differs from "
                         + ", ".join(f"{o} (p {pv:.1g})" for o, pv in others))
    if any(p.stations.pairs for p in stats.parameters.values()):
        head = "Stations (Welch's t per pair, significant below 1 % over the number of pairs):"
        lines = ["", head] + (lines or ["  no station reads differently from every other one"])
    return lines


def versions_text(versions, location: str) -> str:
    if not versions:
        return f"no limits versions in {location}: 'linpar qa limits --store FILE' stores the first"
    lines = [f"{len(versions)} limits version(s) in {location} (the newest judges new measurements):"]
    for v in versions:
        names = ", ".join(v.document.get("parameters", {}))
        lines.append(f"  v{v.version}  {v.created_at}  {v.created_by:<12} {v.name}  ({names})"
                     + (f"  - {v.note}" if v.note else ""))
    return "\n".join(lines)


def proposal_text(proposed, notes, k: float, out: str | None, document_text: str) -> str:
    lines = [f"Limits proposed from golden units, mean +- {k:g} sigma (review them, then 'linpar qa limits --store "
             f"{out or 'FILE'}'):"]
    for p in proposed:
        entry = p.entry(k)
        lines.append(f"  {p.name:<13}{entry['min']:>12.6g} .. {entry['max']:<12.6g} {_unit(p.unit):<6} "
                     f"{entry['note']}")
    lines += [f"note: {n}" for n in notes]
    if out:
        lines.append(f"written: {out}")
    else:
        lines += ["", document_text.rstrip()]
    return "\n".join(lines)
