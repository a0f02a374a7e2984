"""The report as one self-contained HTML file: inline CSS and inline SVG plots, no external resource.

Every text that came from a user or a file is escaped; nothing is loaded
from anywhere when the page is opened.
"""
from __future__ import annotations

from html import escape

from analysis.report.content import CHANNEL_TITLES, ReportContent
from analysis.report.numbers import NOT_DETERMINED_NOTE
from analysis.report.plots import figures, svg_of
from analysis.limits import INTERVAL_K
from analysis.report.qa import VERDICT_COLOURS, QASection

LIGHT_COLOURS = {"green": "#2e9d44", "yellow": "#e0b000", "red": "#d23a2c", "absent": "#b8b8b8",
                 "unknown": "#b8b8b8"}

CSS = """
body { font-family: 'DejaVu Sans', Arial, sans-serif; font-size: 13px; color: #222; max-width: 60em;
       margin: 1.5em auto; padding: 0 1em; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { font-size: 1.15em; border-bottom: 1px solid #ccc;
     padding-bottom: 0.15em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.4em 0; }
td, th { padding: 0.15em 0.7em; text-align: left; vertical-align: top; }
table.params td.num, table.params th.num { text-align: right; font-variant-numeric: tabular-nums; }
table.params tr:nth-child(even) td { background: #f4f6f8; }
th { border-bottom: 1px solid #999; }
.light { display: inline-block; width: 0.95em; height: 0.95em; border-radius: 50%; vertical-align: -0.15em;
         margin-right: 0.35em; border: 1px solid #555; }
.finding { margin: 0.2em 0 0.5em 1.6em; } .remedy { color: #444; } .note { color: #555; font-style: italic; }
figure { margin: 1em 0; } figure svg { width: 100%; height: auto; } figcaption { font-weight: bold; }
.verdict { border: 2px solid; border-radius: 6px; padding: 0.4em 0.8em; margin: 0.6em 0; }
.verdict .headline { font-size: 1.6em; font-weight: bold; margin-right: 0.6em; }
table.params td.fail { color: #8e1b1b; font-weight: bold; } table.params td.pass { color: #1b5e20; }
table.params td.uncertain { color: #8a4300; font-weight: bold; }
"""


def _light(status: str) -> str:
    colour = LIGHT_COLOURS.get(status, LIGHT_COLOURS["unknown"])
    return f'<span class="light" style="background:{colour}" title="{escape(status)}"></span>'


def _pairs(rows) -> str:
    body = "".join(f"<tr><th scope='row'>{escape(k)}</th><td>{escape(v)}</td></tr>" for k, v in rows)
    return f"<table>{body}</table>"


def _verdict_banner(qa: QASection) -> str:
    background, colour = VERDICT_COLOURS[qa.verdict]
    return (f"<div class='verdict' id='qa-verdict' style='background:{background};color:{colour};"
            f"border-color:{colour}'><span class='headline'>QA: {escape(qa.headline)}</span> {escape(qa.why)}"
            f"<br><small>limits: {escape(qa.name)} ({escape(qa.file)})</small></div>")


def _qa_table(qa: QASection) -> str:
    parts = [f"<h2>QA limits</h2><p>Limits file <b>{escape(qa.file)}</b> ({escape(qa.name)}): "
             f"<b>{escape(qa.headline)}</b>. Values in the file's units; “tolerance used” is the distance "
             "from the middle of a two-sided limit as a share of its half-width. Each parameter is judged by "
             f"its value ± {INTERVAL_K:g} σ: pass inside the limit, FAIL wholly outside, uncertain across it.</p>"
             + (f"<p>Fit error (rms misfit of each curve): {escape(qa.fit_error)}.</p>" if qa.fit_error else ""),
             "<table class='params'><tr><th>parameter</th><th>result</th><th class='num'>measured</th>"
             "<th class='num'>tolerance used</th><th>limit</th><th>margin</th></tr>"]
    for r in qa.rows:
        css = {"pass": "pass", "FAIL": "fail", "uncertain": "uncertain"}.get(r.outcome, "")
        parts.append(f"<tr><td>{escape(r.name)}</td><td class='{css}'>{escape(r.outcome)}</td>"
                     f"<td class='num'>{escape(r.value)}</td><td class='num'>{escape(r.used)}</td>"
                     f"<td>{escape(r.limit)}</td><td>{escape(r.margin or r.note)}</td></tr>")
    parts.append("</table>")
    return "".join(parts)


def _parameter_table(title: str, rows) -> str:
    parts = [f"<h2>{escape(title)}</h2><table class='params'><tr><th>parameter</th><th class='num'>value</th>"
             "<th class='num'>± 1σ</th><th>unit</th><th class='num'>rel.</th><th>note</th></tr>"]
    for p in rows:
        parts.append(f"<tr><td>{escape(p.name)}</td><td class='num'>{escape(p.value)}</td>"
                     f"<td class='num'>{escape(p.std)}</td><td>{escape(p.unit)}</td>"
                     f"<td class='num'>{escape(p.relative)}</td><td>{escape(p.note)}</td></tr>")
    parts.append("</table>")
    if not all(p.determined for p in rows):
        parts.append(f"<p class='note'>{escape(NOT_DETERMINED_NOTE)}</p>")
    return "".join(parts)


def _validity(c: ReportContent) -> str:
    parts = [f"<h2>Validity</h2><p>{_light(c.overall)}<b>Overall: {escape(c.overall)}</b> "
             f"&nbsp; peak excursion {escape(c.peak_displacement)}</p><ul style='list-style:none;padding:0'>"]
    for light in c.lights:
        parts.append(f"<li>{_light(light.status)}{escape(CHANNEL_TITLES.get(light.channel, light.channel))}: "
                     f"{escape(light.status)}")
        for f in light.findings:
            parts.append(f"<div class='finding'>{_light(f.severity)}<b>{escape(f.code)}</b>: {escape(f.message)}"
                         f"<br><span class='remedy'>Remedy: {escape(f.remedy)}</span></div>")
        parts.append("</li>")
    parts.append("</ul>")
    return "".join(parts)


def render_html(content: ReportContent) -> str:
    """The customer's part (parameters, model, validity, plots, calibration), then the appendix."""
    c = content
    parts = [f"<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>{escape(c.title)}</title>"
             f"<style>{CSS}</style></head><body>", f"<h1>{escape(c.title)}</h1>"]
    if c.qa is not None:
        parts.append(_verdict_banner(c.qa))
    parts.append(_pairs(c.header))
    if c.qa is not None:
        parts.append(_qa_table(c.qa))
    parts.append(_parameter_table("Parameters", c.parameters))
    parts.append("<h2>Model</h2>" + _pairs(c.model))
    for note in c.notes:
        parts.append(f"<p class='note'>{escape(note)}</p>")
    parts.append(_validity(c))
    shown = figures(c.result)
    residuals = [(t, f) for t, f in shown if "residual" in t.lower()]      # engineering detail: the appendix
    parts.append("<h2>Plots</h2>")
    for title, fig in shown:
        if "residual" not in title.lower():
            parts.append(f"<figure><figcaption>{escape(title)}</figcaption>{svg_of(fig)}</figure>")
    parts.append("<h2>Calibration</h2>" + _pairs(c.calibration))

    parts.append("<h1 class='appendix'>Appendix: engineering detail</h1>")
    if c.fit:
        parts.append("<h2>Fit</h2>" + _pairs(c.fit))
    if c.internal:
        parts.append(_parameter_table("Model's internal quantities", c.internal))
    for title, fig in residuals:
        parts.append(f"<figure><figcaption>{escape(title)}</figcaption>{svg_of(fig)}</figure>")
    parts.append("<h2>Measurement settings</h2>" + _pairs(c.settings))
    if c.calibration_detail:           # nothing recorded: the first page says so already, in its own words
        parts.append("<h2>Calibration as recorded</h2>" + _pairs(c.calibration_detail))
    parts.append("<p class='note'>Values in SI are in the results JSON; uncertainties are one standard "
                 "deviation from the fit, scaled by the Birge ratio when the model does not fit within the "
                 "noise.</p></body></html>\n")
    return "\n".join(parts)
