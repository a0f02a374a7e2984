"""`linpar diagnose`: rank the effects the model may lack and follow the greedy path."""
from __future__ import annotations

import argparse
import json

from analysis.derived import parameter_table
from analysis.diagnosis import Candidate, Diagnosis, diagnose, explain
from analysis.effects import parse_effects
from analysis.fit import FitData, FitResult
from analysis.model import Model, ModelError
from analysis.parallel import fit_executor
from analysis.pipeline import resolve_sd
from analysis.recording import read_recording
from analysis.spectra import estimate_spectra


def _data(args: argparse.Namespace) -> tuple[FitData, float | None]:
    """The lines to diagnose: from a recording, or from imported curves."""
    from app import cli_import
    if cli_import.wants_curves(args):
        from analysis.curve_fit import curve_data
        z, hx, notes = cli_import.load_curves(args)
        data, _ = curve_data(z, hx, cli_import.fit_range(args, args.hx_fmax), notes)
        return data, args.sd
    recording = read_recording(args.path)
    return FitData.from_spectra(estimate_spectra(recording)), resolve_sd(recording, args.sd)


def run_diagnosis(args: argparse.Namespace):
    data, sd = _data(args)
    start = args.start
    try:
        effects = parse_effects(start)
    except KeyError as exc:
        raise ModelError(f"--from: {exc.args[0]}") from None
    model = Model(effects, with_displacement=data.displacement is not None)
    with fit_executor() as executor:
        result = diagnose(data, model, executor=executor)
    return result, sd


def _fit_summary(fit: FitResult) -> dict:
    return {"effects": list(fit.model.effect_ids), "chi2_red": fit.chi2_red_by_channel(), "bic": fit.bic}


def _candidate_json(current: FitResult, c: Candidate) -> dict:
    return {
        "action": c.action,
        "effect": c.effect.id,
        "category": c.effect.category,
        "replaces": c.replaces.id if c.replaces else None,
        "chi2_red": c.fit.chi2_red_by_channel() if c.fit else None,
        "delta_bic": c.delta_bic if c.fit else None,
        "explanation": explain(current, c),
    }


def diagnosis_json(result: Diagnosis, sd_m2: float | None) -> dict:
    final = result.final
    return {
        "start": _fit_summary(result.start),
        "residual": result.steps[0].residual,
        "candidates": [_candidate_json(result.start, c) for c in result.first_candidates],
        "steps": [_fit_summary(step.fit) for step in result.steps],
        "final": {**_fit_summary(final),
                  "parameters": {n: p.as_json() for n, p in parameter_table(final, sd_m2).items()}},
    }


def format_diagnosis(result: Diagnosis) -> str:
    lines = [f"start: {result.start.model.describe()}", f"  residual: {result.steps[0].residual}", "",
             f"{'rank':<5}{'move':<34}{'delta BIC':>12}  reduced chi^2"]
    for rank, c in enumerate(result.first_candidates, 1):
        move = f"{c.action} {c.effect.id}" + (f" (for {c.replaces.id})" if c.replaces else "")
        chi = ", ".join(f"{k} {v:.3g}" for k, v in c.fit.chi2_red_by_channel().items()) if c.fit else c.error
        dbic = f"{c.delta_bic:+.1f}" if c.fit else "failed"
        lines.append(f"{rank:<5}{move:<34}{dbic:>12}  {chi}")
    if result.first_candidates:
        lines += ["", "why: " + explain(result.start, result.first_candidates[0])]
    lines += ["", "path:"]
    for i, step in enumerate(result.steps):
        chi = ", ".join(f"{k} {v:.3g}" for k, v in step.fit.chi2_red_by_channel().items())
        lines.append(f"  {i}: {step.fit.model.describe():<40} BIC {step.fit.bic:12.1f}   reduced chi^2 {chi}")
    lines.append(f"final residual: {result.steps[-1].residual}")
    return "\n".join(lines)


def cmd_diagnose(args: argparse.Namespace) -> int:
    result, sd = run_diagnosis(args)
    if args.json:
        print(json.dumps(diagnosis_json(result, sd), allow_nan=False, default=lambda _: None))
    else:
        print(format_diagnosis(result))
    return 0
