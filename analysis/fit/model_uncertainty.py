"""The model part of each parameter's uncertainty: how far it moves between models the data cannot tell apart.

A fit's statistical uncertainty (the noise's, Birge-scaled) says how well the data fix the parameters of
*this* model. When the model misses physics the driver has (a semi-inductance of another form, a creep
with losses, a cone mode at the laser's spot...) the parameters bend to imitate it, by far more than the
noise: on the tests' realistic recordings (tests/realistic_drivers.py) the default fit lands 2-7 of its
standard deviations from the truth. No model of the catalogue describes such a driver down to the noise,
but several describe it about as well as each other; where they disagree, the data do not decide.

So the recording is fitted again with the blocked impedance and the creep law each exchanged for the
other forms the catalogue has (ALTERNATIVES: lr2, lr3, leach, wright; creep-log, creep-log-causal), all
else as the user's model. The members are the fits whose chi^2 is within INDISTINCT_FACTOR of the best
one's: their rms misfit within sqrt(4) = 2 times the best's (a fit error of 1.5 % against 3 %, both what a
good fit of a real driver shows). The reported value stays the user's model's. A recording's model part
is the standard deviation of the parameter over the reported value and the members' (each counted once);
imported curves (magnitude only, no phase to show what the model misses) keep the largest shift:

    recording:   std_model = sqrt(std over {value, value_member...}^2 + rms over added |value_added - value|^2)
    curves:      std_model = max over members |value_member - value|
    std = sqrt(std_noise^2 + std_model^2)

The forms cover physics the model holds in another shape; `added` covers physics it has no term for: the user's
model with one effect more each (air load, cone breakup, Bl's fall, rising damping, the laser spot's mode), those
the data ask for (analysis.fit.added_physics).

Why not the largest shift for recordings (issue 29): the user's model is usually not itself among the
members (on the realistic drivers its chi^2 is 5-30 times the best one's), so it sits at one end and the
members cluster at the other: the creep-log against creep-log-causal moves Mms by 6-8 %, the truth between.
Taken as one sigma, that distance made the interval value +- 2 sigma twice as wide as the models' disagreement
(the model part 3-5 times the actual error; every unit UNCERTAIN at the truth +- 15 %). On a recording an
alternative whose blocked impedance takes RE's place (its resistance at the lowest line DC_EXCESS above RE:
lr3 with the lossless creep, 13-18 %; a coil has < 0.1 % there) is not a reading of RE and is left out
(`degenerate`), as for magnitude-only curves. Measured on the realistic woofer, midrange and subwoofer (two
seeds each, fitted over their piston band, analysis.fit.bands): the truth of RE, Bl, Mms and Kms within 1.4
total std, each interval inside the truth +- 15 % (tests/analysis/test_realistic_qa.py).

When the model describes the recording (every channel's reduced chi^2 below MISFIT_FROM: the misfit
within twice the noise) nothing is refitted and nothing changes: no model part is reported. The refits take
a few seconds: a separate step after the statistical result (the GUI shows that at once and runs this in the background;
`linpar analyze`, `measure`, `archive store` and `report` run it before they print or store).

Every place that shows, stores or judges a result passes it through `model_uncertainty` (once: a result
that carries its ModelPart is returned as it is), so the same recording reads the same everywhere. What was
done is kept on the result (`model_part`) and in its validity's "model_part" ({"state", "seconds"}), which
the archive record, the reports and the JSON carry.
"""
from __future__ import annotations

import dataclasses
import math
import threading
import time
from typing import TYPE_CHECKING, Mapping

import numpy as np

from analysis.derived import ParameterValue, derived_from_values
from analysis.effects import get_effect
from analysis.fit.added_physics import asked_for, extended_models
from analysis.fit.least_squares import FitData, FitError, FitResult
from analysis.fit.methods import fit_with
from analysis.model.composed import Model, ModelError

if TYPE_CHECKING:       # a caller's pool, named for the reader: concurrent.futures (with logging) costs the
    from concurrent.futures import Executor     # command line's start 2-3 ms, and `linpar analyze` fits serially

# Each family: forms of one physics at one site, any of which a real driver may follow about as well. A model's
# member is exchanged within the first family that holds it (creep-log-causal-fs, the causal creep with its loss
# at fs in RES, is set against the lossless creep-log, whose RES means the same).
ALTERNATIVES = (("lr2", "lr3", "leach", "wright"), ("creep-log", "creep-log-causal"),
                ("creep-log-causal-fs", "creep-log"))
INDISTINCT_FACTOR = 4.0
MISFIT_FROM = 4.0
DC_EXCESS = 0.1

# What was done about the model part (ModelPart.state; the validity's "model_part" in the JSON).
ESTIMATED = "estimated"             # refitted: std_model on every parameter the members give
NOT_NEEDED = "not needed"           # the model describes the data: std is the noise's alone
NOT_ESTIMATED = "not estimated"     # misfit, but no alternative the data cannot reject (or none to exchange)
ESTIMATING = "estimating"           # not a state of a result: what a page says while the refits run


@dataclasses.dataclass(frozen=True, kw_only=True)
class Member:
    """One of the fits the data cannot tell apart: its model's effects, its chi^2 and values."""

    effects: tuple[str, ...]
    chi2: float
    values: dict[str, float]


@dataclasses.dataclass(frozen=True, kw_only=True)
class ModelPart:
    """What the model part of a result's uncertainties came to (module doc): kept with the result, so that a
    change of Sd (derived parameters only) recomputes the parts from the same members without refitting."""
    state: str                          # ESTIMATED | NOT_NEEDED | NOT_ESTIMATED
    members: tuple[Member, ...] = ()    # ESTIMATED: the fits the data cannot tell apart, the user's first
    seconds: float = 0.0                # how long the refits took
    why: str = ""                       # NOT_ESTIMATED for another reason than the module doc's (cancelled)
    # True: the spread is the std over the reported value and the members' (a recording's, module doc); False:
    # the largest distance of a member from the reported value (imported curves).
    ensemble: bool = False
    # A recording's: the user's model with one effect more each, that the data ask for (analysis.fit.added_physics).
    added: tuple[Member, ...] = ()

    def as_json(self) -> dict:
        return {"state": self.state, "seconds": round(self.seconds, 2),
                "models": [list(m.effects) for m in self.members],
                **({"added": [m.effects[-1] for m in self.added]} if self.added else {}),
                **({"why": self.why} if self.why else {})}

    def spread(self, values: Mapping[str, float], sd_m2: float | None) -> dict[str, float]:
        """Each parameter's model part around `values` (the reported fit's), derived ones at `sd_m2`."""
        if self.state != ESTIMATED:
            return {}
        reported = _with_derived(values, sd_m2)
        theirs = [_with_derived(member.values, sd_m2) for member in self.members]
        spread = {}
        for name, value in reported.items():
            others = [t[name] for t in theirs if name in t and math.isfinite(t[name])]
            if self.ensemble:           # the members begin with the reported fit (estimate_model_part)
                spread[name] = float(np.std(others)) if others else 0.0
            else:
                spread[name] = max((abs(v - value) for v in others), default=0.0)
        for name, shift in _rms_shift(reported, [_with_derived(m.values, sd_m2) for m in self.added]).items():
            spread[name] = math.hypot(spread.get(name, 0.0), shift)
        return spread


def pending(result) -> bool:
    """True when `result` still lacks a model part it needs: a fit that misses its data (or magnitude-only curves,
    which want it always: analysis.curves.fitting), not yet refitted."""
    fit = getattr(result, "fit", None)
    return (fit is not None and getattr(result, "model_part", None) is None
            and (getattr(result, "model_part_always", False) or not describes_the_data(fit)))


def describes_the_data(fit: FitResult) -> bool:
    """True when every channel's misfit is within MISFIT_FROM in reduced chi^2 (the model part is then 0)."""
    return all(math.isfinite(c) and c < MISFIT_FROM for c in fit.chi2_red_by_channel().values())


def alternative_models(model: Model) -> list[Model]:
    """`model` with each family's member exchanged for the family's other forms (every combination)."""
    variants = [tuple(model.effect_ids)]
    exchanged: set[str] = set()
    for family in ALTERNATIVES:
        here = [i for i in model.effect_ids if i in family and i not in exchanged]
        if not here:
            continue
        exchanged.update(family)
        grown = []
        for ids in variants:
            here = [i for i in ids if i in family]
            if not here:
                grown.append(ids)
                continue
            grown += [tuple(other if i == here[0] else i for i in ids) for other in family]
        variants = grown
    models = []
    for ids in dict.fromkeys(variants):
        if ids == tuple(model.effect_ids):
            continue
        try:
            effects = tuple(e for e in model.effects if e.id in ids) + tuple(
                get_effect(i) for i in ids if i not in model.effect_ids)
            models.append(Model(effects, with_displacement=model.with_displacement))
        except ModelError:
            continue        # a combination the model cannot hold (a parameter name twice)
    return models


def members(fit: FitResult, data: FitData, cancel: threading.Event | None = None,
            drop_degenerate: bool = False, executor: Executor | None = None) -> list[Member]:
    """The user's fit and the alternatives' fits that describe the data about as well (module doc).

    drop_degenerate: leave out a fit whose RE, CMES, LCES, RES or Bl ended on a bound, or whose blocked impedance
    is resistive at the lowest line (on magnitude-only curves leach's K*w^n, n small, can take RE's place:
    no driver is like that). `executor`: a pool the alternatives are fitted on (the same fits, so the same numbers)."""
    fits = [Member(effects=fit.model.effect_ids, chi2=fit.chi2, values=dict(fit.values))]
    models = alternative_models(fit.model)
    for model, other in zip(models, _refits(fit.method, [(data, model, None) for model in models], cancel, executor)):
        if other is None:
            continue        # an alternative that does not converge is not one the data cannot reject
        if drop_degenerate and degenerate(other, data):
            continue
        if math.isfinite(other.chi2):
            fits.append(Member(effects=model.effect_ids, chi2=other.chi2, values=dict(other.values)))
    best = min(m.chi2 for m in fits)
    return [m for m in fits if m.chi2 <= INDISTINCT_FACTOR * best]


def estimate_model_part(fit: FitResult, data: FitData, cancel: threading.Event | None = None, always: bool = False,
                        other_bands: tuple[FitData, ...] = (), drop_degenerate: bool | None = None,
                        ensemble: bool = False, executor: Executor | None = None) -> ModelPart:
    """The refits' outcome (module doc): NOT_NEEDED when the model describes the data (nothing is refitted),
    unless `always`; `other_bands` as model_spread's; degenerate alternatives dropped (members) when
    `drop_degenerate` (None: when `always`). `ensemble` (a recording's): the spread is the std over the reported
    fit and the members, the reported fit first even when the data reject it (one alternative the data prefer
    is then enough). `executor`: a pool the refits run on (members)."""
    if describes_the_data(fit) and not always:
        return ModelPart(state=NOT_NEEDED)
    started = time.perf_counter()
    drop = always if drop_degenerate is None else drop_degenerate
    indistinct = (members(fit, data, cancel, drop_degenerate=drop, executor=executor)
                  + _band_members(fit, other_bands, cancel, executor))
    added = tuple(_added_physics(fit, data, cancel, executor)) if ensemble else ()
    seconds = time.perf_counter() - started
    if ensemble:
        reported = Member(effects=fit.model.effect_ids, chi2=fit.chi2, values=dict(fit.values))
        others = [m for m in indistinct if m.effects != reported.effects]
        if not others and not added:
            return ModelPart(state=NOT_ESTIMATED, seconds=seconds)
        return ModelPart(state=ESTIMATED, members=(reported, *others), seconds=seconds, ensemble=True, added=added)
    if len(indistinct) < 2:
        # No alternative the data cannot reject (or none of either family to exchange, `--model none`):
        # the model part is not estimated, which is not the same as zero.
        return ModelPart(state=NOT_ESTIMATED, seconds=seconds)
    return ModelPart(state=ESTIMATED, members=tuple(indistinct), seconds=seconds)


def model_spread(fit: FitResult, data: FitData, sd_m2: float | None,
                 cancel: threading.Event | None = None, always: bool = False,
                 other_bands: tuple[FitData, ...] = ()) -> dict[str, float]:
    """Each parameter's model part (module doc); none when the model describes the data (the table is then
    left as it is: its std is the noise's alone, as before), unless `always` (magnitude-only curves, whose
    misfit cannot show what the phase would). `other_bands`: the same curves over the other fit bands the
    data cannot choose between; their fits are members too."""
    return estimate_model_part(fit, data, cancel, always, other_bands).spread(fit.values, sd_m2)


def degenerate(other: FitResult, data: FitData) -> bool:
    """A base parameter on a bound, or a blocked impedance whose resistance at the lowest line exceeds RE by more
    than DC_EXCESS (it took RE's place: a coil's eddy currents and semi-inductance barely act at a few hertz)."""
    specs = {s.name: s for s in other.model.param_specs}
    if any(n in other.values and specs[n].on_bound(other.values[n]) for n in ("RE", "CMES", "LCES", "RES", "Bl")):
        return True
    lowest = 2j * np.pi * np.array([data.impedance.freqs[0]])
    excess = float(other.model.blocked_impedance(lowest, other.values).real[0]) - other.values["RE"]
    return excess > DC_EXCESS * other.values["RE"]


def _added_physics(fit: FitResult, data: FitData, cancel: threading.Event | None,
                   executor: Executor | None = None) -> list[Member]:
    """The user's model with each effect of analysis.fit.added_physics.EXTENSIONS it lacks, fitted from the
    reported values; those the data ask for (asked_for) and whose base parameters are not degenerate."""
    models = extended_models(fit.model)
    fits = _refits(fit.method, [(data, model, dict(fit.values)) for model in models], cancel, executor)
    return [Member(effects=model.effect_ids, chi2=other.chi2, values=dict(other.values))
            for model, other in zip(models, fits)
            if other is not None and asked_for(other, fit) and not degenerate(other, data)]


def _rms_shift(reported: Mapping[str, float], theirs: list[Mapping[str, float]]) -> dict[str, float]:
    """Each parameter's rms distance from `reported` over `theirs` (where it is finite)."""
    shifts = {}
    for name, value in reported.items():
        moved = [t[name] - value for t in theirs if name in t and math.isfinite(t[name])]
        if moved:
            shifts[name] = math.sqrt(sum(d * d for d in moved) / len(moved))
    return shifts


def _band_members(fit: FitResult, bands: tuple[FitData, ...], cancel: threading.Event | None,
                  executor: Executor | None = None) -> list[Member]:
    """The user's model fitted over each other band (no chi^2 to compare: the bands hold different lines)."""
    others = _refits(fit.method, [(data, fit.model, fit.values) for data in bands], cancel, executor)
    return [Member(effects=fit.model.effect_ids, chi2=fit.chi2, values=dict(other.values))
            for other in others if other is not None]


def _refits(method: str, calls: list[tuple], cancel: threading.Event | None,
            executor: Executor | None) -> list[FitResult | None]:
    """fit_with(method, data, model, start) for each (data, model, start), None for a fit that did not converge.

    On `executor` every call is handed over at once and its result waited for in order; a worker process cannot
    see `cancel`, so the executor's own wait must end on it (app.jobs.background_pool)."""
    if executor is None:
        return [_converged(lambda c=call: fit_with(method, *c, cancel=cancel), cancel) for call in calls]
    futures = [executor.submit(fit_with, method, *call) for call in calls]
    return [_converged(future.result, cancel) for future in futures]


def _converged(fitting, cancel: threading.Event | None) -> FitResult | None:
    try:
        return fitting()
    except FitError:
        if cancel is not None and cancel.is_set():
            raise
        return None


def _with_derived(values: Mapping[str, float], sd_m2: float | None) -> dict[str, float]:
    try:
        return {**values, **derived_from_values(values, sd_m2)}
    except (ValueError, ZeroDivisionError, OverflowError):
        return dict(values)


def with_model_part(parameters: Mapping[str, ParameterValue], spread: Mapping[str, float]
                    ) -> dict[str, ParameterValue]:
    """The table with std_noise (the statistical std), std_model, and std their quadrature sum."""
    out = {}
    for name, p in parameters.items():
        model = spread.get(name)
        if p.value is None or model is None:
            out[name] = p
            continue
        noise = p.std
        total = model if noise is None else math.hypot(noise, model)
        out[name] = dataclasses.replace(p, std=total, std_noise=noise, std_model=model)
    return out


def model_uncertainty(result, cancel: threading.Event | None = None, executor: Executor | None = None):
    """`result` (an analysis.pipeline.AnalysisResult, or an analysis.curves.fitting.CurveAnalysis) with each parameter's
    model part (module doc), the alternatives fitted by the result's own method.

    The same result when nothing was fitted or when it already carries its model part (every output calls
    this: the refits run once); the refits honour `cancel` (FitCancelled), on `executor` when there is one
    (a process pool: the GUI's, so that its thread only waits)."""
    if result.fit is None or getattr(result, "model_part", None) is not None:
        return result
    data = getattr(result, "data", None) or FitData.from_spectra(result.spectra)
    # Imported magnitude-only curves (analysis.curves.fitting) say whether they want it always, and their other bands.
    always = getattr(result, "model_part_always", False)
    recorded = hasattr(result, "spectra")           # a recording's result (module doc), not imported curves
    part = estimate_model_part(result.fit, data, cancel, always, getattr(result, "other_bands", ()),
                               drop_degenerate=always or recorded, ensemble=recorded, executor=executor)
    return with_estimated(result, part)


def with_estimated(result, part: ModelPart):
    """`result` with `part`'s spread in its parameters' std, and `part` kept on it and in its validity."""
    changes = {"parameters": with_model_part(result.parameters, part.spread(result.fit.values, result.sd_m2)),
               "validity": result.validity.replace(model_part=part.as_json())}
    if "model_part" in {f.name for f in dataclasses.fields(result)}:
        changes["model_part"] = part
    return dataclasses.replace(result, **changes)


def with_sd(result, parameters: Mapping[str, ParameterValue], sd_m2: float | None):
    """`result`'s statistical table recomputed at another Sd (`parameters`), its model part applied again from the
    same members (no refit): what the Results page shows when the user edits Sd."""
    part = getattr(result, "model_part", None)
    spread = part.spread(result.fit.values, sd_m2) if part is not None else {}
    return dataclasses.replace(result, sd_m2=sd_m2, parameters=with_model_part(parameters, spread))


def model_part_words(validity) -> str:
    """What a result's model part came to, in one sentence (its analysis.validity.result.ResultValidity's
    model_part, ModelPart.as_json()); "" before it is estimated."""
    entry = (validity.model_part if validity is not None else None) or {}
    state = entry.get("state")
    if state == ESTIMATED:
        n = len(entry.get("models") or ())
        added = entry.get("added") or ()
        asked = (f" and from the shift of {len(added)} effect{'s' if len(added) > 1 else ''} the data ask for "
                 f"({', '.join(added)})" if added else "")
        return (f"model part: estimated from {n} models the data cannot tell apart{asked} (their refits took "
                f"{float(entry.get('seconds') or 0):.1f} s); each 1-sigma is its total with the noise's")
    if state == NOT_NEEDED:
        return "model part: none (the model describes the measurement within its noise)"
    if state == NOT_ESTIMATED:
        why = entry.get("why") or "the model misses the measurement, but no other form fits about as well"
        return f"model part: not estimated ({why}); each 1-sigma is the noise's alone"
    return ""
