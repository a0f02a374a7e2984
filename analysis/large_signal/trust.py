"""Whether a large-signal identification can be trusted at all: the serial laser's delay found or not.

    delay_not_found(ident, k) -> the reason (one line), or None
    delay_doubtful(ident, k) -> the reason for a smaller misfit (a flag to read), or None
    verdict(ident, flags) -> "red" | "yellow" | "green"

A serial laser's delay is searched over +-1 ms (fitting.py). Beyond it the
search either stops on the limit (delay_at_limit) or settles in a wrong
valley inside the range: at the in-process rig's link latencies of 2 and
4 ms, delays of +330 to +520 us and -880 to -1000 us, Bl(0) ~ 0 and RE up to
26 ohm. The misfit-weighted chi^2 does not show it (0.5: the weights count
the misfit as noise, weights.misfit_variance), but the electrical equation
then misses the voltage: the back-EMF Bl(x) v, with v out of phase, is left
unexplained. Against the lines' noise alone that misfit is ~1e9 times the
noise and ~100 % of the voltage, where a delay found leaves ~1 and 0.1-0.2 %
(14 JACK plans, the in-process rig at 0 and 0.5 ms; docs/large-signal.md).
Both are asked: significant (not the noise) and large (not a driver's
physics the polynomials miss by a few %). A smaller misfit, still far above
the noise, is a doubt (a flag, yellow): at 1 ms two delays stopped near
the limit (+995, +987 us, ~100 us short) left 1.9 % of the voltage at 2.5e5
times its noise; but a driver's own physics can leave that much too.
"""
from __future__ import annotations

from analysis.large_signal.columns import ELECTRICAL
from analysis.large_signal.fitting import DELAY_LIMIT_S
from analysis.large_signal.identify import Identification

VOLTAGE_MISFIT_UNTRUSTED_PERCENT = 10.0    # the electrical equation's rms misfit, % of the voltage's rms
NOISE_CHI2_UNTRUSTED = 100.0                # the same misfit's power over the lines' noise alone
VOLTAGE_MISFIT_DOUBTFUL_PERCENT = 1.0       # a delay found leaves 0.1-0.2 % (docs/large-signal.md)


def delay_not_found(ident: Identification, k: int) -> str | None:
    """Why recording k's laser delay was not found (None: found, or no delay searched)."""
    if not ident.data[k].laser_delay_possible:
        return None
    label, delay_us = ident.data[k].label, ident.delays[k] * 1e6
    remedy = ("Bl(x), Kms(x) and Le(x) are not to be trusted; check the laser's latency (its link) and measure "
              "again")
    if ident.delay_at_limit(k):
        centre_us = ident.delay_centres[k] * 1e6
        return (f"{label}: the laser's delay was not found: it reached the search's limit ({delay_us:+.0f} us, at "
                f"most {DELAY_LIMIT_S * 1e6:.0f} us either way of {centre_us:+.0f} us, where the small-signal "
                f"model placed it): {remedy}")
    misfit = ident.voltage_residual_percent[k]
    noise = ident.noise_chi2_red[k][ELECTRICAL]
    if misfit > VOLTAGE_MISFIT_UNTRUSTED_PERCENT and noise > NOISE_CHI2_UNTRUSTED:
        return (f"{label}: the laser's delay was not found: at the best delay ({delay_us:+.0f} us) the electrical "
                f"equation misses {misfit:.0f} % of the voltage, {noise:.2g} times its noise: {remedy}")
    return None


def delay_doubtful(ident: Identification, k: int) -> str | None:
    """Why recording k's laser delay may be off, when it was not found wrong outright (None: no doubt)."""
    if not ident.data[k].laser_delay_possible or delay_not_found(ident, k):
        return None
    misfit = ident.voltage_residual_percent[k]
    noise = ident.noise_chi2_red[k][ELECTRICAL]
    if misfit > VOLTAGE_MISFIT_DOUBTFUL_PERCENT and noise > NOISE_CHI2_UNTRUSTED:
        return (f"{ident.data[k].label}: the electrical equation misses {misfit:.1f} % of the voltage, {noise:.2g} "
                f"times its noise, at the laser's delay found ({ident.delays[k] * 1e6:+.0f} us): the delay may be "
                f"off (or the driver has physics the model lacks); check the laser's latency")
    return None


def delays_found(ident: Identification) -> list[bool | None]:
    """Per recording: whether its laser delay was found (None where none was searched)."""
    return [None if not d.laser_delay_possible else delay_not_found(ident, k) is None
            for k, d in enumerate(ident.data)]


def verdict(ident: Identification, flags) -> str:
    """red: a laser delay not found (the curves are not a measurement); yellow: flags to read; green: none."""
    if any(delay_not_found(ident, k) for k in range(len(ident.data))):
        return "red"
    return "yellow" if flags else "green"
