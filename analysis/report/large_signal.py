"""The large-signal report: one self-contained HTML page (inline SVG) or one A4 PDF page.

What it says, for a technician: the driver and the recordings, the curves at
rest, where to move the coil, the stiffness asymmetry and the excursion
limits, the fit and the distortion explained per recording, what to read
with care; the plots of Bl(x), Kms(x), Le(x) (2-sigma bands, measured range
shaded, limits marked) and of the distortion predicted against measured at
the highest level; the polynomials' coefficients (SI, ascending powers of x).
"""
from __future__ import annotations

import io
import math
import textwrap
from html import escape

import matplotlib
import numpy as np
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from analysis.large_signal.result import LargeSignalResult
from analysis.report.plots import STYLE, svg_of

A4 = (8.27, 11.69)
BAND, MODEL, RANGE, LIMIT = "#f2b8bf", "#d2542c", "#e3ebf7", "#e08a00"
CURVES = (("Bl", "Bl (T·m)", 1.0), ("Kms", "Kms (N/mm)", 1e-3), ("Le", "Le (mH)", 1e3))


def summary_rows(result: LargeSignalResult) -> list[tuple[str, str]]:
    model, derived = result.model, result.derived
    lo, hi = model.x_range
    rows = [("Driver", str(result.driver.get("name") or "not named")),
            ("Recordings", ", ".join(f"{f.label} ({f.drive_rms_v:.3g} V)" for f in result.fits)),
            ("Measured range", f"{lo * 1e3:+.2f} to {hi * 1e3:+.2f} mm (positive outwards)")]
    for name, label, scale in CURVES:
        curve = model.curves[name]
        sigma = float(curve.sigma(np.array([0.0]))[0]) * abs(scale)
        rows.append((f"{name}(0)", f"{curve.coefficients[0] * scale:.5g} ± {sigma:.2g} {label.split('(')[1][:-1]}"))
    rows += [("Coil", derived.coil_advice()),
             ("Stiffness asymmetry", f"{derived.asymmetry_percent:+.1f} % at ±{derived.asymmetry_at_m * 1e3:.2f} mm")]
    for limit in derived.limits.values():
        if limit.value is not None:
            rows.append((f"{limit.name} ({limit.criterion})",
                         f"more than {limit.value * 1e3:.2f} mm (beyond the measured range)" if limit.beyond_range
                         else f"{limit.value * 1e3:.2f} mm ({limit.side} side)"))
    chi2 = result.identification.solution.chi2_by_equation
    rows.append(("Fit (reduced chi²)", ", ".join(f"{eq} {c / max(n, 1):.2f}" for eq, (c, n) in chi2.items())))
    for fit in result.fits:
        if fit.failed:
            rows.append((fit.label, fit.failed))
            continue
        current = fit.channels["current"]
        explained = (f"{current.explained_percent:.0f} % of the current's distortion explained"
                     if math.isfinite(current.explained_percent) else "current's distortion at the noise")
        rows.append((fit.label, f"{fit.drive_rms_v:.3g} V: {explained}"))
    return rows


def coefficient_rows(result: LargeSignalResult) -> list[tuple[str, str, str, str]]:
    """(curve, power, coefficient, 1-sigma) in SI: the polynomials in ascending powers of x (m)."""
    out = []
    for name, curve in result.model.curves.items():
        for k, (c, s) in enumerate(zip(curve.coefficients, curve.std)):
            out.append((f"{name} [{curve.unit}·m^-{k}]" if k else f"{name} [{curve.unit}]", str(k), f"{c:.6g}",
                        f"{s:.2g}"))
    return out


def figure(result: LargeSignalResult, width_in: float = 7.2, height_in: float = 5.6) -> Figure:
    with matplotlib.rc_context(STYLE):
        fig = Figure(figsize=(width_in, height_in), layout="constrained")
        axes = fig.subplots(2, 2)
        draw_curves(result, [axes[0, 0], axes[0, 1], axes[1, 0]])
        draw_distortion(result, axes[1, 1])
    return fig


def draw_curves(result: LargeSignalResult, axes) -> None:
    model, derived, th = result.model, result.derived, result.thresholds
    lo, hi = model.x_range
    x = np.linspace(lo - 0.15 * (hi - lo), hi + 0.15 * (hi - lo), 301)
    thresholds = {"Bl": model.Bl.coefficients[0] * th.bl_ratio,
                  "Kms": model.Kms.coefficients[0] / th.compliance_ratio * 1e-3,
                  "Le": model.Le.coefficients[0] * (1 + th.le_change) * 1e3}
    limit_of = {"Bl": "X_Bl", "Kms": "X_C", "Le": "X_L"}
    for ax, (name, label, scale) in zip(axes, CURVES):
        curve = model.curves[name]
        y, s = curve(x) * scale, curve.sigma(x) * abs(scale)
        ax.axvspan(lo * 1e3, hi * 1e3, color=RANGE, zorder=0)
        ax.fill_between(x * 1e3, y - 2 * s, y + 2 * s, color=BAND, linewidth=0, zorder=1)
        inside = (x >= lo) & (x <= hi)
        ax.plot(x[inside] * 1e3, y[inside], color=MODEL, linewidth=1.3, zorder=2)
        ax.plot(x[x <= lo] * 1e3, y[x <= lo], color=MODEL, linewidth=0.8, linestyle="--", zorder=2)
        ax.plot(x[x >= hi] * 1e3, y[x >= hi], color=MODEL, linewidth=0.8, linestyle="--", zorder=2)
        ax.axhline(thresholds[name], color="#888888", linewidth=0.7, linestyle=":")
        limit = derived.limits[limit_of[name]]
        if limit.value is not None:
            for sign in (-1, 1):
                ax.axvline(sign * limit.value * 1e3, color=LIMIT, linewidth=0.8, linestyle="--")
            ax.set_title(f"{name}(x): {limit.name} {'> ' if limit.beyond_range else ''}{limit.value * 1e3:.2f} mm")
        if name == "Bl":
            ax.axvline(derived.offset_m * 1e3, color=MODEL, linewidth=0.8, linestyle="-.")
        ax.set_xlabel("x (mm), positive outwards")
        ax.set_ylabel(label)


def draw_distortion(result: LargeSignalResult, ax) -> None:
    fits = [f for f in result.fits if not f.failed]
    if not fits:
        ax.set_axis_off()
        return
    fit = max(fits, key=lambda f: f.drive_rms_v)
    for name, colour in (("current", "#1f5fa8"), ("displacement", "#e08a00")):
        c = fit.channels[name]
        hz = np.array(c.bands_hz)
        for values, style in ((c.bands_measured_db, dict(linestyle="none", marker="o", markersize=3)),
                              (c.bands_predicted_db, dict(linewidth=1.2))):
            y = np.array(values, dtype=float)
            ok = np.isfinite(y)
            ax.plot(hz[ok], y[ok], color=colour, label=f"{name}, {'measured' if 'marker' in style else 'predicted'}",
                    **style)
    ax.set_xscale("log")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("distortion re signal (dB)")
    ax.set_title(f"distortion at {fit.drive_rms_v:.3g} V")
    ax.legend(loc="lower left")


def render_large_signal_html(result: LargeSignalResult) -> str:
    title = f"Large-signal parameters: {result.driver.get('name') or 'driver'}"
    rows = "".join(f"<tr><td><b>{escape(a)}</b></td><td>{escape(b)}</td></tr>" for a, b in summary_rows(result))
    coeffs = "".join(f"<tr><td>{escape(a)}</td><td class='num'>{escape(b)}</td><td class='num'>{escape(c)}</td>"
                     f"<td class='num'>{escape(d)}</td></tr>" for a, b, c, d in coefficient_rows(result))
    flags = "".join(f"<li>{escape(f)}</li>" for f in result.flags)
    return (f"<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>{escape(title)}</title>"
            f"<style>body{{font-family:'DejaVu Sans',Arial,sans-serif;font-size:13px;max-width:60em;margin:1.5em "
            f"auto}} td{{padding:0.15em 0.7em;vertical-align:top}} td.num{{text-align:right}} "
            f"figure svg{{width:100%;height:auto}}</style></head><body><h1>{escape(title)}</h1>"
            f"<table>{rows}</table>"
            + (f"<h2>To read with care</h2><ul>{flags}</ul>" if flags else "")
            + f"<h2>Curves</h2><figure>{svg_of(figure(result))}</figure>"
            f"<h2>Polynomials (SI, ascending powers of x in m)</h2><table><tr><th>coefficient</th><th>power</th>"
            f"<th>value</th><th>± 1σ</th></tr>{coeffs}</table>"
            f"<p><i>Bands: two standard deviations, from the noise of the periods; the measured range is shaded, "
            f"the curves are dashed beyond it.</i></p></body></html>\n")


def render_large_signal_pdf(result: LargeSignalResult) -> bytes:
    """One A4 page: the summary, then the plots (flags wrapped under the summary)."""
    title = f"Large-signal parameters: {result.driver.get('name') or 'driver'}"
    buf = io.BytesIO()
    with matplotlib.rc_context(STYLE):
        fig = Figure(figsize=A4)
        fig.text(0.08, 0.96, title, fontsize=14, weight="bold")
        y = 0.935
        for key, value in summary_rows(result):
            lines = textwrap.wrap(value, 80) or [""]
            fig.text(0.08, y, key, fontsize=8, weight="bold")
            for line in lines:
                fig.text(0.36, y, line, fontsize=8)
                y -= 0.0145
        if result.flags:
            fig.text(0.08, y - 0.005, "To read with care", fontsize=9, weight="bold")
            y -= 0.02
            for flag in result.flags:
                for line in textwrap.wrap("- " + flag, 110):
                    fig.text(0.08, y, line, fontsize=7.5)
                    y -= 0.013
        bottom = 0.05
        grid = fig.add_gridspec(2, 2, left=0.1, right=0.95, bottom=bottom, top=max(y - 0.03, 0.3), hspace=0.45,
                                wspace=0.3)
        axes = [fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 0])]
        draw_curves(result, axes)
        draw_distortion(result, fig.add_subplot(grid[1, 1]))
        with PdfPages(buf, metadata={"Title": title, "Creator": "linpar", "CreationDate": None}) as pdf:
            pdf.savefig(fig)
    return buf.getvalue()
