"""The seed paper's two-step identification: Z for the electrical parameters, then Hx for Bl and the creep.

docs/physics.md section 1: everything in Hx but Bl is known once Z is fitted. The paper fits Z alone for
RE, LE, the eddy-current branch and the motional branch's CMES, LCES, RES; then, those held, it fits Hx
for Bl and the creep law (creep barely shows in Z, clearly in Hx below fs). Neither channel's misfit can
then bend what the other determines: a blocked impedance the model cannot follow moves the Z-step's
parameters only, a cone mode at the laser's spot moves Bl and the creep only. The creep does show a
little in Z: the first step fits it too (else its start value would bend CMES), the second refits it on
Hx, where it shows, and that is the value reported. (A joint fit lets
Z's low-frequency misfit pull the creep, which trades with CMES: on magnitude-only curves of a real 6.5"
woofer the joint fit lands Mms +27 % from Klippel LPM's value, the two steps within 4 %.)

Uncertainties are those of the two-step estimator. With J1 the Z step's Jacobian (its parameters theta1),
J2 the Hx step's (theta2 = Bl and the creep) and J21 Hx's on theta1, each step's covariance scaled by its
own channel's Birge ratio (b_z, b_x, never below 1):

    cov1 = (J1'J1)^-1 b_z          G = -(J2'J2)^-1 J2'J21  (how theta2 follows theta1)
    cov2 = (J2'J2)^-1 b_x + G cov1 G'          cov(theta2, theta1) = G cov1

so Bl carries the uncertainty of the Z step's parameters it was fitted with.
"""
from __future__ import annotations

import threading
from typing import Mapping

import numpy as np

from analysis.effects.base import Site
from analysis.fit.covariance import jacobian, normal_inverse
from analysis.fit.least_squares import (EVALUATIONS_PER_PARAMETER, FitData, FitResult, _check_effects, _minimize,
                                        _residual_vector, _start, channel_sigmas, fit_model, result_of, start_values)
from analysis.fit.startvalues import linear_gain
from analysis.model.composed import Model


def hx_step_parameters(model: Model) -> set[str]:
    """What the second step fits on Hx: Bl, the creep law's parameters, the displacement channel's own."""
    sites = (Site.COMPLIANCE, Site.DISPLACEMENT)
    return {"Bl"} | {s.name for e in model.effects if e.site in sites for s in e.params}


def two_step_start(data: FitData, model: Model, start: Mapping[str, float] | None
                   ) -> tuple[dict[str, float], dict[str, float], set[str], set[str]]:
    """What both two-step methods start from: (channel sigmas, start values with the user's, Z step's
    parameters, Hx step's parameters)."""
    sigmas = channel_sigmas(data, True)
    values = start_values(model, data)
    values.update({k: v for k, v in (start or {}).items() if k in values})
    _check_effects(model, data, values)
    second = hx_step_parameters(model)
    return sigmas, values, set(values) - second, second


def bl_from_hx(model: Model, values: Mapping[str, float], data: FitData, sigmas: Mapping[str, float]) -> float:
    """Bl from Hx with the rest held: Bl is a pure gain on Hx, so it is solved linearly (a start for the Hx step)."""
    x = data.displacement
    g = model.displacement(2j * np.pi * x.freqs, {**values, "Bl": 1.0})
    inv_bl = linear_gain(g if x.has_phase else np.abs(g), x.value, sigmas["displacement"])
    return abs(1.0 / inv_bl) if inv_bl != 0 else 1.0


def free_off_bounds(model: Model, values: Mapping[str, float], names: set[str]) -> list[str]:
    """`names` not on a bound, sorted: the parameters a step's covariance is taken over."""
    specs = {s.name: s for s in model.param_specs}
    return [n for n in sorted(names) if not specs[n].on_bound(values[n])]


def fit_paper(data: FitData, model: Model, start: Mapping[str, float] | None = None,
              cancel: threading.Event | None = None, per_parameter: int = EVALUATIONS_PER_PARAMETER) -> FitResult:
    """Fit `model` in the paper's two steps (module doc); without Hx there is only the first: the joint fit."""
    if not model.with_displacement:
        return fit_model(data, model, start, cancel, per_parameter)
    sigmas, values, first, second = two_step_start(data, model, start)
    creep = {s.name for e in model.effects if e.site is Site.COMPLIANCE for s in e.params}
    # Step 1, Z alone: the creep held at its start first (it barely shows in Z), then free with the rest.
    r0 = _minimize(model, _start(model, values, second), data, False, sigmas, cancel, per_parameter)
    r1 = _minimize(model, _start(model, r0.values, second - creep), data, False, sigmas, cancel,
                   per_parameter) if creep else r0
    values = dict(r1.values)
    if "Bl" not in (start or {}):
        values["Bl"] = bl_from_hx(model, values, data, sigmas)
    # Step 2, Hx alone: Bl and the creep, what Z gave held.
    r2 = _minimize(model, _start(model, values, first), data, True, sigmas, cancel, per_parameter, use_z=False)
    values = dict(r2.values)
    nfev = r0.nfev + (r1.nfev if creep else 0) + r2.nfev
    free1, free2 = free_off_bounds(model, values, first), free_off_bounds(model, values, second)
    z_values = {**values, **{n: r1.values[n] for n in creep}}
    covar = _two_step_covariance(model, values, z_values, data, sigmas, free1, free2, creep)
    return result_of(model, values, tuple(free1 + free2), covar, data, True, sigmas,
                     bool(r1.success and r2.success), f"Z step: {r1.message}; Hx step: {r2.message}", int(nfev),
                     birge_scaled=True, method="paper")


def _two_step_covariance(model, values, z_values, data, sigmas, free1, free2, creep) -> np.ndarray | None:
    """The covariance of (free1, free2) (module doc); the Z step's creep (at z_values) is a nuisance there."""
    specs = {s.name: s for s in model.param_specs}

    def z_residual(p):
        return _residual_vector(model, p, data, False, sigmas)

    def x_residual(p):
        return _residual_vector(model, p, data, True, sigmas, use_z=False)

    z_step = free1 + sorted(n for n in creep if not specs[n].on_bound(z_values[n]))
    rz, rx = z_residual(z_values), x_residual(values)
    b_z = max(1.0, float(rz @ rz) / max(len(rz) - len(z_step), 1))
    b_x = max(1.0, float(rx @ rx) / max(len(rx) - len(free2), 1))
    A1 = normal_inverse(jacobian(z_residual, z_values, z_step, specs))
    A2 = normal_inverse(jacobian(x_residual, values, free2, specs))
    if A1 is None or A2 is None:
        return None
    n1 = len(free1)
    cov1 = A1[:n1, :n1] * b_z
    G = -A2 @ jacobian(x_residual, values, free2, specs).T @ jacobian(x_residual, values, free1, specs)
    cov2 = A2 * b_x + G @ cov1 @ G.T
    cross = G @ cov1
    return np.block([[cov1, cross.T], [cross, cov2]])
