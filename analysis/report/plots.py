"""The report's plots, drawn with matplotlib's object API (no pyplot: no global state, no GUI backend).

Measured lines are markers, the fitted model a line evaluated on a dense
logarithmic grid over the measured band. Every axis is labelled with its
quantity and unit. Each `draw_*` function draws into axes it is given, so
the PDF (several plots per A4 page) and the HTML (one SVG per figure)
share the drawing.
"""
from __future__ import annotations

import io

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.collections import LineCollection
from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

from analysis.archive.results import StoredResult
from analysis.spl import predicted_spl

MEASURED = dict(linestyle="none", marker="o", markersize=2.8, color="#1f5fa8", label="measured")
MODEL = dict(linewidth=1.3, color="#d2542c", label="model")
# Imported curves: the exporting tool's own fitted curve (a Klippel export's "Fitted" column), beside linpar's.
REFERENCE = dict(linewidth=1.2, linestyle="--", color="#2e8b57", label="the export's fit")
DENSE_PER_DECADE = 200
SPL_VOLTAGE = 2.83
# pdf.fonttype 3: the glyphs drawn as the PDF's own procedures. TrueType embedding (42) had fontTools subset
# DejaVu's four faces on every export, decompiling their layout tables: a quarter of an export's CPU (3.5-3.9 ->
# 2.7-3.2 s); pdftotext reads the text (Ω, σ, ±) as before.
# axes.titley fixed: matplotlib otherwise measures every tick label of the axes (their tight box) to place each
# title, 15 % of an export; nothing sits above an axes' top edge here.
STYLE = {"font.size": 8, "axes.titlesize": 9, "axes.titley": 1.0, "axes.labelsize": 8, "legend.fontsize": 7,
         "xtick.labelsize": 7, "ytick.labelsize": 7, "svg.fonttype": "path", "pdf.fonttype": 3,
         "axes.grid": True, "grid.alpha": 0.35, "grid.linewidth": 0.5, "svg.hashsalt": "linpar"}


def _dense(freqs: np.ndarray) -> np.ndarray:
    lo, hi = float(np.nanmin(freqs)), float(np.nanmax(freqs))
    n = max(int(np.log10(hi / lo) * DENSE_PER_DECADE), 50)
    return np.geomspace(lo, hi, n)


# A log axis' minor grid at 2 and 5 of each decade, drawn as one collection of lines: matplotlib's minor ticks
# (8 a decade, each a tick with its marks, grid line and label) were ~260 objects an export, a quarter of its
# CPU. An axis spanning under NARROW decades keeps real minor ticks at 2 and 5, labelled: its one or two major
# ticks would leave it nearly unlabelled.
MINOR_SUBS = (2.0, 5.0)
NARROW = 1.5
GRID = dict(alpha=0.3, linewidth=0.4)
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _hz(x: float, pos=None) -> str:
    """10, 200, 1k, 20k: plain text, no mathtext to parse and lay out ("$10^{3}$" is the default)."""
    return f"{x / 1000:g}k" if x >= 1000 else f"{x:g}"


def _decade(x: float, pos=None) -> str:
    """10⁻³, 1, 10, 10²: a power of ten in Unicode superscripts (no mathtext)."""
    exponent = int(round(np.log10(x))) if x > 0 else 0
    if exponent in (0, 1):
        return f"{10 ** exponent:g}"
    return "10" + str(exponent).translate(_SUPERSCRIPT)


def _log_ticks(ax, which: str, label) -> None:
    axis = ax.xaxis if which == "x" else ax.yaxis
    axis.set_major_locator(LogLocator(base=10.0))
    axis.set_major_formatter(FuncFormatter(label))
    lo, hi = sorted(ax.get_xlim() if which == "x" else ax.get_ylim())
    if not (lo > 0 and np.isfinite(hi)) or np.log10(hi / lo) < NARROW:
        axis.set_minor_locator(LogLocator(base=10.0, subs=MINOR_SUBS))
        axis.set_minor_formatter(FuncFormatter(label))
        return
    axis.set_minor_locator(NullLocator())
    decades = 10.0 ** np.arange(np.floor(np.log10(lo)) - 1, np.ceil(np.log10(hi)) + 1)
    at = (decades[:, None] * np.array(MINOR_SUBS)).ravel()
    if which == "x":
        segments, transform = [((v, 0.0), (v, 1.0)) for v in at], ax.get_xaxis_transform()
    else:
        segments, transform = [((0.0, v), (1.0, v)) for v in at], ax.get_yaxis_transform()
    ax.add_collection(LineCollection(segments, transform=transform, colors=matplotlib.rcParams["grid.color"],
                                     zorder=0.5, **GRID), autolim=False)


def _freq_axis(ax, bottom: bool = True) -> None:
    """A log frequency axis (and the y axis' ticks when it is log too); call it once the axes' data are drawn."""
    ax.set_xscale("log")
    _log_ticks(ax, "x", _hz)
    if ax.get_yscale() == "log":
        _log_ticks(ax, "y", _decade)
    if bottom:
        ax.set_xlabel("frequency [Hz]")
    ax.grid(True, which="both", **GRID)


def _phase_deg(values: np.ndarray) -> np.ndarray:
    return np.degrees(np.angle(values))


def _unwrapped_phases(result: StoredResult, name: str, f_dense: np.ndarray):
    """Phases in degrees of the model (dense grid) and of the measured lines, unwrapped together.

    The model is unwrapped on the union of both grids (dense enough never to
    skip a turn); each measured line's phase is the model's there plus the
    small angle between measurement and model, so both share one branch.
    """
    c = result.curves[name]
    grid = np.concatenate([f_dense, c.freqs])
    order = np.argsort(grid, kind="stable")
    model_all = result.model_curve(name, grid[order])
    unwrapped = np.empty(len(grid))
    unwrapped[order] = np.unwrap(np.angle(model_all))
    model_dense, model_lines = unwrapped[:len(f_dense)], unwrapped[len(f_dense):]
    with np.errstate(invalid="ignore", divide="ignore"):
        measured = model_lines + np.angle(c.measured / result.model_curve(name, c.freqs))
    return np.degrees(model_dense), np.degrees(measured)


def _reference(result: StoredResult, name: str, plot, scale: float) -> None:
    """The exporting tool's fitted curve over the band linpar fitted (beyond it the comparison says nothing)."""
    if name not in result.reference_curves:
        return
    freqs, magnitude = result.reference_curves[name]
    band = result.curves[name].freqs
    inside = (freqs >= band.min()) & (freqs <= band.max())
    plot(freqs[inside], magnitude[inside] * scale, **REFERENCE)


def draw_impedance(result: StoredResult, ax_mag, ax_phase) -> None:
    c = result.curves["impedance"]
    f = _dense(c.freqs)
    model = result.model_curve("impedance", f)
    ax_mag.plot(c.freqs, np.abs(c.measured), **MEASURED)
    ax_mag.plot(f, np.abs(model), **MODEL)
    _reference(result, "impedance", ax_mag.plot, 1.0)
    ax_mag.set_ylabel("|Z| [Ω]")
    ax_mag.set_title("Impedance Z = U / I")
    ax_mag.legend(loc="upper left")
    _freq_axis(ax_mag, bottom=False)
    if c.has_phase:
        ax_phase.plot(c.freqs, _phase_deg(c.measured), **MEASURED)
    ax_phase.plot(f, _phase_deg(model), **MODEL)
    ax_phase.set_ylabel("phase of Z [°]")
    ax_phase.set_ylim(-90, 90)
    ax_phase.set_yticks([-90, -45, 0, 45, 90])
    _freq_axis(ax_phase)


def draw_hx(result: StoredResult, ax_mag, ax_phase) -> None:
    c = result.curves["displacement"]
    f = _dense(c.freqs)
    model = result.model_curve("displacement", f)
    ax_mag.loglog(c.freqs, np.abs(c.measured) * 1e3, **MEASURED)
    ax_mag.loglog(f, np.abs(model) * 1e3, **MODEL)
    _reference(result, "displacement", ax_mag.loglog, 1e3)
    ax_mag.set_ylabel("|Hx| [mm/V]")
    ax_mag.set_title("Displacement per volt Hx = X / U")
    ax_mag.legend(loc="lower left")
    _freq_axis(ax_mag, bottom=False)
    model_phase, measured_phase = _unwrapped_phases(result, "displacement", f)
    if c.has_phase:
        ax_phase.plot(c.freqs, measured_phase, **MEASURED)
    ax_phase.plot(f, model_phase, **MODEL)
    ax_phase.set_ylabel("phase of Hx [°] (unwrapped)")
    both = np.concatenate([model_phase, measured_phase if c.has_phase else model_phase])
    both = both[np.isfinite(both)]
    if both.size == 0:          # nothing finite to draw (a damaged stored result): a plain axis
        both = np.array([-180.0, 0.0])
    lo = 90 * np.floor(both.min() / 90 - 0.1)
    hi = 90 * np.ceil(both.max() / 90 + 0.1)
    ax_phase.set_ylim(lo, hi)
    ax_phase.set_yticks(np.arange(lo, hi + 1, 90 if hi - lo <= 540 else 180))
    _freq_axis(ax_phase)


def draw_spl(result: StoredResult, ax) -> None:
    c = result.curves["displacement"]
    f = _dense(c.freqs)
    sd = result.sd_m2
    measured = predicted_spl(c.freqs, c.measured, sd, SPL_VOLTAGE)
    model = predicted_spl(f, result.model_curve("displacement", f), sd, SPL_VOLTAGE)
    ax.plot(c.freqs, measured, **MEASURED)
    ax.plot(f, model, **MODEL)
    finite = np.concatenate([model, measured])
    finite = finite[np.isfinite(finite)]
    top = float(finite.max())
    # 60 dB below the loudest point shows every useful detail; the model sets the bottom when it is lower.
    bottom = max(float(finite.min()), top - 60.0)
    ax.set_ylim(10 * np.floor(bottom / 10 - 0.5), 10 * np.ceil(top / 10 + 0.2))
    ax.set_ylabel("SPL [dB re 20 µPa]")
    ax.set_title(f"Predicted SPL at {SPL_VOLTAGE:g} V, 1 m, half space (Sd = {sd * 1e4:.4g} cm²)")
    ax.legend(loc="lower right")
    _freq_axis(ax)


def draw_residuals(result: StoredResult, axes) -> None:
    """One axes per channel: real and imaginary parts of (model - measured) / std per line."""
    titles = {"impedance": "Z", "displacement": "Hx"}
    for ax, (name, c) in zip(axes, result.curves.items()):
        r = c.normalized_residual
        if c.has_phase:
            ax.plot(c.freqs, r.real, linestyle="none", marker="o", markersize=2.5, color="#1f5fa8", label="real part")
            ax.plot(c.freqs, r.imag, linestyle="none", marker="s", markersize=2.5, color="#3a9d4a", label="imaginary part")
        else:
            ax.plot(c.freqs, r, linestyle="none", marker="o", markersize=2.5, color="#1f5fa8", label="magnitude")
        for level in (-2, 2):
            ax.axhline(level, color="#888888", linewidth=0.8, linestyle="--")
        ax.axhline(0, color="#444444", linewidth=0.6)
        peak = float(np.nanmax(np.abs(np.concatenate([np.ravel(r.real), np.ravel(np.imag(r))]))))
        lim = max(4.0, 1.15 * peak) if np.isfinite(peak) else 4.0
        ax.set_ylim(-lim, lim)
        ax.set_ylabel(f"residual of {titles.get(name, name)} [σ]")
        ax.set_title(f"Normalised residual of {titles.get(name, name)}: (model − measured) / std "
                     f"(dashed: ±2σ)")
        ax.legend(loc="upper left", ncols=2)
        _freq_axis(ax)


def figures(result: StoredResult, width_in: float = 7.2) -> list[tuple[str, Figure]]:
    """(title, figure) for every plot the result allows, one figure each (for the HTML report)."""
    with matplotlib.rc_context(STYLE):     # font sizes are taken when the artists are made
        return _figures(result, width_in)


def _figures(result: StoredResult, width_in: float) -> list[tuple[str, Figure]]:
    out = []
    if "impedance" not in result.curves:        # nothing was fitted (a broken measurement): no plots
        return out
    fig = Figure(figsize=(width_in, 4.6), layout="constrained")
    draw_impedance(result, *fig.subplots(2, 1, sharex=True, height_ratios=[3, 2]))
    out.append(("Impedance", fig))
    if "displacement" in result.curves:
        fig = Figure(figsize=(width_in, 4.6), layout="constrained")
        draw_hx(result, *fig.subplots(2, 1, sharex=True, height_ratios=[3, 2]))
        out.append(("Displacement per volt (Hx)", fig))
        if result.sd_m2:
            fig = Figure(figsize=(width_in, 3.0), layout="constrained")
            draw_spl(result, fig.subplots())
            out.append(("Predicted SPL", fig))
    n = len(result.curves)
    fig = Figure(figsize=(width_in, 2.4 * n), layout="constrained")
    axes = fig.subplots(n, 1, squeeze=False)[:, 0]
    draw_residuals(result, axes)
    out.append(("Normalised residuals", fig))
    return out


def svg_of(fig: Figure) -> str:
    """The figure as an inline <svg> element (no XML prolog, no creation date)."""
    buf = io.StringIO()
    with matplotlib.rc_context(STYLE):
        fig.savefig(buf, format="svg", metadata={"Date": None})
    text = buf.getvalue()
    return text[text.index("<svg"):]
