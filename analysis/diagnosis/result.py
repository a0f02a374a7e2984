"""A recording's diagnosis and its two forms: the text `linpar diagnose` prints, the object `--json` prints.

DiagnosisResult is the diagnosis (analysis.diagnosis.candidates) with what the recording adds to it: the
radiating area for the final model's derived parameters, and the drift finding its verdict mentions.
`report()` and `as_json()` say it; the CLI only prints them. The words (verdict, residual, sites) come from
analysis.diagnosis.words, which the model lab shares.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from analysis.derived import parameter_table
from analysis.diagnosis import acceptance, noise_floor
from analysis.diagnosis.candidates import Diagnosis, explain
from analysis.diagnosis.words import (VERDICT_TITLES, chi2_words, residual_json, sites_json, stop_reason,
                                      tied_sites, verdict_text)

if TYPE_CHECKING:
    from analysis.diagnosis.candidates import Candidate, Step
    from analysis.fit.least_squares import FitResult


@dataclass(frozen=True, kw_only=True)
class DiagnosisResult:
    diagnosis: Diagnosis
    sd_m2: float | None = None          # for the final model's derived parameters (Vas, SPL)
    drift: str | None = None            # the recording's drift finding, in words (analysis.diagnosis.words)

    @property
    def verdict(self) -> str:
        return self.diagnosis.verdict

    @property
    def final(self) -> FitResult:
        """The model the diagnosis ends at, fitted."""
        return self.diagnosis.final

    def report(self) -> str:
        return format_diagnosis(self.diagnosis, self.drift)

    def as_json(self) -> dict:
        return diagnosis_json(self.diagnosis, self.sd_m2, self.drift)


def _fit_summary(fit: FitResult) -> dict:
    return {"effects": list(fit.model.effect_ids), "chi2_red": fit.chi2_red_by_channel(), "bic": fit.bic}


def _candidate_json(current: FitResult, c: Candidate) -> dict:
    return {
        "action": c.action,
        "effect": c.effect.id,
        "with": c.partner.id if c.partner else None,
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
    """A step of the path: its model, the move taken from it (`chosen`, `chosen_with` for a pair's second
    effect) and every candidate ranked there."""
    chosen = step.chosen
    return {**_fit_summary(step.fit), "chosen": chosen.effect.id if chosen else None,
            "chosen_with": chosen.partner.id if chosen and chosen.partner else None,
            "chosen_action": chosen.action if chosen else None,
            "flags": acceptance.flags_json(step.flags), "at_noise_floor": step.at_noise_floor,
            "candidates": [_candidate_json(step.fit, c) for c in step.candidates]}


def diagnosis_json(result: Diagnosis, sd_m2: float | None = None, drift: str | None = None) -> dict:
    """The diagnosis as JSON-ready values: verdict, candidates, path, the final model's parameters (with Sd)
    and residual, and the sites."""
    final = result.final
    return {
        "verdict": result.verdict,
        "verdict_text": verdict_text(result, drift),
        "step_cap_reached": result.step_cap_reached,
        "start": _fit_summary(result.start),
        "residual": result.steps[0].residual,
        "candidates": [_candidate_json(result.start, c) for c in result.first_candidates],
        "steps": [_step_json(step) for step in result.steps],
        "stopped": dict(zip(("reason", "text"), stop_reason(result))),
        "final": {**_fit_summary(final),
                  "parameters": {n: p.as_json() for n, p in parameter_table(final, sd_m2).items()},
                  "residual": residual_json(final),
                  "flags": acceptance.flags_json(result.final_flags)},
        "sites": sites_json(result.sites),
    }


def _move(c: Candidate) -> str:
    """'add lr3', 'replace lr2 (for lr3)', 'add breakup + breakup-spot'."""
    return f"{c.action} {c.label}" + (f" (for {c.replaces.id})" if c.replaces else "")


def _judgement(c: Candidate, chosen: Candidate | None) -> str:
    """What the acceptance rule made of a candidate: taken (the one the path took), acceptable, or why not."""
    if c is chosen:
        return "taken"
    if c.accepted:
        return "acceptable"
    return c.assessment.reason if c.assessment else ""


def _flags_text(flags) -> str:
    return "; ".join(f"{f.code}: {f.message}" for f in flags)


def format_diagnosis(result: Diagnosis, drift: str | None = None) -> str:
    """The verdict in words, the first candidates ranked, the path taken and the sites."""
    lines = [f"verdict: {VERDICT_TITLES[result.verdict]}", "  " + verdict_text(result, drift), "",
             f"start: {result.start.model.describe()}", f"  residual: {result.steps[0].residual}", ""]
    first = result.steps[0]
    rows = [(_move(c), f"{c.delta_bic:+.1f}" if c.fit else "failed", _judgement(c, first.chosen),
             chi2_words(c.fit.chi2_red_by_channel()) if c.fit else c.error) for c in result.first_candidates]
    # The columns as wide as their longest entry: a pair's or a user effect's move can be long.
    move_w = max([34] + [len(r[0]) + 2 for r in rows])
    bic_w = max([12] + [len(r[1]) + 1 for r in rows])
    lines.append(f"{'rank':<5}{'move':<{move_w}}{'delta BIC':>{bic_w}}  {'judgement':<12} reduced chi^2")
    for rank, (move, dbic, judgement, chi) in enumerate(rows, 1):
        lines.append(f"{rank:<5}{move:<{move_w}}{dbic:>{bic_w}}  {judgement:<12} {chi}")
    if rows:
        lines.append("  (taken: the move the path took; acceptable: passes the acceptance rule but ranks below it)")
    if result.first_candidates:
        lines += ["", "why: " + explain(result.start, result.first_candidates[0])]
    elif result.steps[0].at_noise_floor:
        lines += ["", "none: " + noise_floor.SKIPPED_WORDS]
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
        if step.candidates:
            acceptable = sum(1 for c in step.candidates if c.accepted)
            lines.append(f"     ranked {len(step.candidates)} candidates, {acceptable} acceptable")
        previous = step
    lines.append(f"stopped: {stop_reason(result)[1]}")
    lines.append(f"final residual: {result.steps[-1].residual}")
    if result.sites:
        tied = {s.site for s in tied_sites(result.sites)}
        lines += ["", f"{'site':<14}{'delta BIC':>14}  reduced chi^2 with a smooth correction there"]
        for s in result.sites:
            mark = "  (the data cannot tell it from the first)" if s.site in tied else ""
            lines.append(f"{s.key:<14}{s.delta_bic:>14.1f}  {chi2_words(s.chi2_red)}{mark}")
    return "\n".join(lines)
