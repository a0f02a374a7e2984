"""`linpar diagnose`: rank the effects the model may lack, follow the greedy path, say what is missing and where.

The analysis is imported when the command runs: building the parser (`linpar --help`) stays light.
"""
from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from app.cli import curves, effects
from app.cli.options import add_json_option, add_sd_option, model_effects
from app.cli.output import print_json

if TYPE_CHECKING:
    from analysis.diagnosis.candidates import Candidate, Diagnosis, Step
    from analysis.fit.least_squares import FitData, FitResult


def register(sub) -> None:
    diagnose = sub.add_parser("diagnose", help="find which physical effect the model lacks")
    diagnose.add_argument("path", nargs="?", help="recording: NAME, NAME.wav or NAME.json (or --impedance/--uiv)")
    diagnose.add_argument("--from", dest="start", metavar="EFFECTS", default="none",
                          help="the starting model's effect ids (default: the textbook model)")
    add_sd_option(diagnose)
    add_json_option(diagnose)
    curves.add_curve_options(diagnose)
    effects.add_effects_file_option(diagnose)
    diagnose.set_defaults(run=run)


def _data(args: argparse.Namespace) -> tuple[FitData, float | None, str | None]:
    """The lines to diagnose (from a recording, or from imported curves), Sd, and the recording's drift finding."""
    from analysis.diagnosis.words import drift_from_validity
    from analysis.pipeline import judged_fit_data, resolve_sd
    from analysis.recording.format import read_recording
    if curves.wants_curves(args):
        from analysis.curves.fitting import curve_data
        z, hx, notes = curves.load_curves(args)
        data, _ = curve_data(z, hx, curves.fit_range(args, args.hx_fmax), notes)
        return data, args.sd, None
    recording = read_recording(args.path)
    data, validity = judged_fit_data(recording, "be diagnosed")
    return data, resolve_sd(recording, args.sd), drift_from_validity(validity)


def run_diagnosis(args: argparse.Namespace):
    from analysis.diagnosis.candidates import diagnose
    from analysis.model.composed import Model
    from analysis.parallel import fit_executor
    start = model_effects(args.start, "--from")     # a bad --from fails before the data are read
    data, sd, drift = _data(args)
    model = Model(start, with_displacement=data.displacement is not None)
    with fit_executor() as executor:
        result = diagnose(data, model, executor=executor)
    return result, sd, drift


def _fit_summary(fit: FitResult) -> dict:
    return {"effects": list(fit.model.effect_ids), "chi2_red": fit.chi2_red_by_channel(), "bic": fit.bic}


def _candidate_json(current: FitResult, c: Candidate) -> dict:
    from analysis.diagnosis import acceptance
    from analysis.diagnosis.candidates import explain
    return {
        "action": c.action,
        "effect": c.effect.id,
        "category": c.effect.category,
        "site": c.effect.site.key,
        "replaces": c.replaces.id if c.replaces else None,
        "chi2_red": c.fit.chi2_red_by_channel() if c.fit else None,
        "delta_bic": c.delta_bic if c.fit else None,
        "accepted": c.accepted,
        "assessment": c.assessment.as_json() if c.assessment else None,
        "flags": acceptance.flags_json(c.flags),
        "explanation": explain(current, c),
    }


def _step_json(step: Step) -> dict:
    from analysis.diagnosis import acceptance
    return {**_fit_summary(step.fit), "chosen": step.chosen.effect.id if step.chosen else None,
            "flags": acceptance.flags_json(step.flags)}


def diagnosis_json(result: Diagnosis, sd_m2: float | None, drift: str | None = None) -> dict:
    from analysis.diagnosis import acceptance
    from analysis.derived import parameter_table
    from analysis.diagnosis.words import residual_json, sites_json, verdict_text
    final = result.final
    return {
        "verdict": result.verdict,
        "verdict_text": verdict_text(result, drift),
        "step_cap_reached": result.step_cap_reached,
        "start": _fit_summary(result.start),
        "residual": result.steps[0].residual,
        "candidates": [_candidate_json(result.start, c) for c in result.first_candidates],
        "steps": [_step_json(step) for step in result.steps],
        "final": {**_fit_summary(final),
                  "parameters": {n: p.as_json() for n, p in parameter_table(final, sd_m2).items()},
                  "residual": residual_json(final),
                  "flags": acceptance.flags_json(result.final_flags)},
        "sites": sites_json(result.sites),
    }


def _flags_text(flags) -> str:
    return "; ".join(f"{f.code}: {f.message}" for f in flags)


def format_diagnosis(result: Diagnosis, drift: str | None = None) -> str:
    from analysis.diagnosis.candidates import explain
    from analysis.diagnosis.words import VERDICT_TITLES, chi2_words, tied_sites, verdict_text
    lines = [f"verdict: {VERDICT_TITLES[result.verdict]}", "  " + verdict_text(result, drift), "",
             f"start: {result.start.model.describe()}", f"  residual: {result.steps[0].residual}", "",
             f"{'rank':<5}{'move':<34}{'delta BIC':>12}  {'taken?':<12} reduced chi^2"]
    for rank, c in enumerate(result.first_candidates, 1):
        move = f"{c.action} {c.effect.id}" + (f" (for {c.replaces.id})" if c.replaces else "")
        chi = chi2_words(c.fit.chi2_red_by_channel()) if c.fit else c.error
        dbic = f"{c.delta_bic:+.1f}" if c.fit else "failed"
        taken = "yes" if c.accepted else (c.assessment.reason if c.assessment else "")
        lines.append(f"{rank:<5}{move:<34}{dbic:>12}  {taken:<12} {chi}")
    if result.first_candidates:
        lines += ["", "why: " + explain(result.start, result.first_candidates[0])]
    lines += ["", "path:"]
    previous = None
    for i, step in enumerate(result.steps):
        lines.append(f"  {i}: {step.fit.model.describe():<40} BIC {step.fit.bic:12.1f}   reduced chi^2 "
                     f"{chi2_words(step.fit.chi2_red_by_channel())}")
        if previous is not None and previous.chosen is not None:
            c = previous.chosen
            move = f"replaced {c.replaces.id} by {c.effect.id}" if c.replaces else f"added {c.effect.id}"
            lines.append(f"     {move}" + (f", taken with flags: {_flags_text(c.flags)}" if c.flags else ""))
        if step.flags:
            lines.append(f"     flags of this model: {_flags_text(step.flags)}")
        previous = step
    lines.append(f"final residual: {result.steps[-1].residual}")
    if result.sites:
        tied = {s.site for s in tied_sites(result.sites)}
        lines += ["", f"{'site':<14}{'delta BIC':>14}  reduced chi^2 with a smooth correction there"]
        for s in result.sites:
            mark = "  (the data cannot tell it from the first)" if s.site in tied else ""
            lines.append(f"{s.key:<14}{s.delta_bic:>14.1f}  {chi2_words(s.chi2_red)}{mark}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    result, sd, drift = run_diagnosis(args)
    if args.json:
        print_json(diagnosis_json(result, sd, drift))
    else:
        print(format_diagnosis(result, drift))
    return 0
