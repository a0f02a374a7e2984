"""Suspension creep: a compliance that grows towards low frequencies.

Every law here is a factor c(s) on the compliance, Cms(s) = Cms * c(s) (so
LCES * c(s) in the model). They are alternatives (one category), so they may
share parameter names: 'lambda' means the same thing in all the logarithmic
laws (the change of compliance per decade, well below any upper transition).

A complex factor whose imaginary part is negative is a lossy suspension: the
stiffness 1/c(s) then has a positive imaginary part, a resistance falling as
1/w in the mechanical impedance. The real-valued law creep-log has no loss;
the causal laws cannot avoid one (Kramers-Kronig).
"""
from __future__ import annotations


import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.model.lumped import resonance_frequency

CATEGORY = "creep"
LAMBDA = ParamSpec("lambda", "1", "-", 1.0, -0.5, 2.0, 0.05,
                   "relative change of the compliance per decade away from fs", typical=(0.0, 1.0))
# The retardation-spectrum law starts its creep this far above fs (Speakerbench's choice).
RETARDATION_CORNER_OVER_FS = 1.5

_LOG_LAW_REFERENCE = ("M. H. Knudsen, J. G. Jensen, 'Low-frequency loudspeaker models that include suspension "
                      "creep', JAES 41(1/2), 1993")


def _ws(p) -> float:
    return 2.0 * np.pi * resonance_frequency(p)


class CreepLog(Effect):
    """CMS(jw) = CMS * [1 - lambda*log10(w/ws)], ws = 2*pi*fs (Knudsen and Jensen; real-valued)."""

    def response(self, s, p):
        return 1.0 - p["lambda"] * np.log10(np.abs(s) / _ws(p))


creep_log = CreepLog(
    id="creep-log",
    category=CATEGORY,
    title="Logarithmic creep (Knudsen and Jensen)",
    site=Site.COMPLIANCE,
    params=(LAMBDA,),
    physics=("The surround and spider are viscoelastic: under a sustained force they keep yielding. "
             "The suspension is softer at low frequencies than at the resonance, by lambda*100 % per decade."),
    signature=("Displacement residual below fs: the measured |Hx| rises above the model towards low "
               "frequencies instead of flattening; the impedance hardly changes."),
    typical="lambda 0.05 to 0.4 (paper: 0.376)",
    reference=_LOG_LAW_REFERENCE,
    notes=("Real-valued: the compliance changes with frequency without any loss, which is not causal. "
           "It is what the reference paper fits; creep-log-causal is the same law with its loss. "
           "The factor reaches zero at fs*10^(1/lambda) (32 kHz for the paper's 0.376, 1.5 kHz for "
           "lambda 0.76): above that the model has a spurious resonance, so a fit that drives lambda up "
           "until the zero enters the band is imitating some other high-frequency effect (e.g. breakup)."),
)


class CreepLogCausal(Effect):
    """CMS(s) = CMS * [1 - lambda*log10(s/ws)], s = jw, ws = 2*pi*fs.

    log10(jw/ws) = log10(w/ws) + j*pi/(2*ln 10): the same real part as
    creep-log, plus a constant imaginary part -j*0.682*lambda, the loss that
    a compliance changing as log(w) must have to be causal. At fs the factor
    is 1 - j*0.682*lambda: its real part is 1.
    """

    def response(self, s, p):
        return 1.0 - p["lambda"] * np.log10(s / _ws(p))


creep_log_causal = CreepLogCausal(
    id="creep-log-causal",
    category=CATEGORY,
    title="Logarithmic creep, causal form (with its loss)",
    site=Site.COMPLIANCE,
    params=(LAMBDA,),
    physics=("The same logarithmic softening as creep-log, but written so that it could happen in a real "
             "material: a suspension that yields slowly also dissipates energy, a little at every frequency. "
             "That loss adds to the mechanical damping, most at low frequencies."),
    signature=("After creep-log: a residual in the phase of Hx below fs and a small one in Re(Z) near fs "
               "(the fitted RES compensates the creep loss at fs but not its 1/f trend)."),
    typical="lambda 0.05 to 0.3; the loss factor is 0.68*lambda (e.g. 0.07 for lambda 0.1)",
    reference=_LOG_LAW_REFERENCE,
    notes=("RES then holds only the frequency-independent part of the mechanical losses: at fs the creep "
           "loss adds a conductance of about 0.682*lambda/(ws*LCES) to 1/RES, so RES comes out higher than with "
           "creep-log on the same data."),
)


class CreepThreeParameter(Effect):
    """CMS(s) = CMS * [1 + kappa / (1 + s*tau_r)]: the standard linear solid (three-parameter model).

    A spring of compliance CMS in series with one Kelvin-Voigt element (a
    spring of compliance kappa*CMS in parallel with a damper r): the extra
    compliance kappa*CMS yields with the retardation time tau_r = r*kappa*CMS.
    Three parameters for the suspension: CMS (here LCES), kappa, tau_r.
    Above 1/tau_r the factor tends to 1 (LCES is the high-frequency
    compliance), below it to 1 + kappa (the static compliance); the loss
    factor of the stiffness, kappa*w*tau_r / (1 + kappa + (w*tau_r)^2),
    peaks at w = sqrt(1 + kappa)/tau_r.
    """

    def response(self, s, p):
        return 1.0 + p["kappa"] / (1.0 + s * p["tau_r"])

    def guess(self, ctx):
        # The creep a measurement can see lies between its lowest line and fs:
        # start the retardation in the middle (log scale) of that band.
        f_mid = np.sqrt(max(ctx.f_min, 1e-3) * ctx.fs)
        return {"kappa": 0.2, "tau_r": 1.0 / (2.0 * np.pi * f_mid)}


creep_3p = CreepThreeParameter(
    id="creep-3p",
    category=CATEGORY,
    title="Three-parameter creep (standard linear solid)",
    site=Site.COMPLIANCE,
    params=(ParamSpec("kappa", "1", "%", 100.0, 0.0, 10.0, 0.2,
                      "extra compliance at DC, relative to the high-frequency compliance", typical=(0.01, 3.0)),
            ParamSpec("tau_r", "s", "ms", 1e3, 1e-5, 10.0, 5e-3, "retardation time of the creep",
                      typical=(1e-4, 1.0))),
    physics=("The suspension is modelled as a spring in series with a second, damped spring: under a slow "
             "force the damped spring yields too, so below a transition frequency 1/(2*pi*tau_r) the "
             "compliance is (1 + kappa) times larger. Unlike the logarithmic laws it stays finite at DC."),
    signature=("Displacement residual below fs that levels off at the lowest frequencies (a step in |Hx| "
               "rather than a steady log rise), with a phase bump in Hx around 1/(2*pi*tau_r)."),
    typical="kappa 0.1 to 1, tau_r 1 to 50 ms (transition between 3 and 150 Hz)",
    reference=(_LOG_LAW_REFERENCE + "; T. Ritter, F. T. Agerkvist, 'Modelling viscoelasticity of loudspeaker "
               "suspensions using retardation spectra', AES 129th Convention, paper 8217, 2010"),
    notes=("LCES is the compliance above the creep transition, so the fs computed from CMES and LCES is the "
           "resonance of that compliance: it is slightly above the measured one when 1/tau_r is near fs. "
           "A single retardation time describes a step; real suspensions spread it over decades "
           "(see creep-rs)."),
)


class CreepFractional(Effect):
    """CMS(s) = CMS * (s/ws)^(-beta), s = jw, ws = 2*pi*fs: a fractional-derivative (springpot) stiffness.

    The stiffness K(s) = KMS*(s/ws)^beta is the fractional derivative of order
    beta of the displacement. The factor is (w/ws)^(-beta) * exp(-j*beta*pi/2):
    |c| = 1 at fs, a compliance rising by a factor 10^beta per decade down,
    and a constant loss factor tan(beta*pi/2). For small beta it equals the
    causal log law with lambda = beta*ln(10).
    """

    def response(self, s, p):
        return (s / _ws(p)) ** (-p["beta"])


creep_fractional = CreepFractional(
    id="creep-fractional",
    category=CATEGORY,
    title="Fractional-derivative creep (power law)",
    site=Site.COMPLIANCE,
    params=(ParamSpec("beta", "1", "-", 1.0, -0.2, 0.5, 0.02, "order of the fractional stiffness",
                      typical=(0.0, 0.3)),),
    physics=("The suspension's stiffness behaves between a spring (order 0) and a damper (order 1): it grows "
             "as a small power beta of frequency. The compliance then rises by a constant factor per decade "
             "towards low frequencies, with a loss that is the same at every frequency."),
    signature=("Displacement residual below fs growing as a power law (straight on log-log axes, where the "
               "log laws curve), with a constant phase offset of beta*90 degrees in the stiffness."),
    typical="beta 0.02 to 0.15 (lambda = 2.3*beta for the log laws: beta 0.16 matches lambda 0.376)",
    reference=("R. L. Bagley, P. J. Torvik, 'On the fractional calculus model of viscoelastic behavior', "
               "J. Rheology 30(1), 1986; applied to loudspeaker suspensions e.g. in Acta Acustica (Chinese) "
               "41(2), 2016 ('Modeling of creep effect in electro-dynamic loudspeaker suspensions')"),
    notes=("Causal by construction. Like the log laws it has no DC limit (the compliance keeps growing); "
           "creep-3p and creep-rs do."),
)


class CreepRetardationSpectrum(Effect):
    """CMS(s) = CMS * [1 + lambda*log10(1 + w0/s)], w0 = 1.5*ws: creep from a flat retardation spectrum.

    Kelvin-Voigt elements with retardation times spread evenly on a log scale
    from 1/w0 to infinity, each adding lambda/ln(10) of compliance per unit of
    ln(tau): integral of dtau/tau / (1 + s*tau) from 1/w0 to inf = ln(1 + w0/s).
    Well below w0 it is the causal log law (the same lambda); well above, the
    factor tends to 1, so LCES is the compliance above the creep band. w0 is
    tied to fs, as Speakerbench does, so the law adds one parameter only.
    """

    def response(self, s, p):
        w0 = RETARDATION_CORNER_OVER_FS * _ws(p)
        return 1.0 + p["lambda"] * np.log10(1.0 + w0 / s)


creep_rs = CreepRetardationSpectrum(
    id="creep-rs",
    category=CATEGORY,
    title="Logarithmic creep from a retardation spectrum (Ritter and Agerkvist)",
    site=Site.COMPLIANCE,
    params=(LAMBDA,),
    physics=("A real suspension creeps on many time scales at once: the compliance keeps growing the longer "
             "the force lasts. Spreading the creep evenly over every time scale longer than about one "
             "resonance period gives the logarithmic law below fs, a compliance that is constant above it, "
             "and the loss that goes with it."),
    signature=("Like creep-log-causal below fs; differs above fs, where the compliance stops changing: a "
               "better fit of the phase of Hx and of Re(Z) just above fs."),
    typical="lambda 0.05 to 0.3",
    reference=("T. Ritter, F. T. Agerkvist, 'Modelling viscoelasticity of loudspeaker suspensions using "
               "retardation spectra', AES 129th Convention, paper 8217, 2010; Speakerbench advanced model "
               "(J. Candy, C. Futtrup), w0 = 1.5*ws"),
    notes=("The upper end of the spectrum is fixed at w0 = 1.5*ws rather than fitted: a free w0 is "
           "identifiable only when it falls inside the measured band, and elsewhere trades against LCES."),
)


_FRACTIONAL_REFERENCE = ("W. King, F. T. Agerkvist, 'Fractional derivative loudspeaker models for nonlinear "
                         "suspensions and voice coils', JAES 66(7/8), 525-536, 2018; R. L. Bagley, P. J. Torvik, 'On the "
                         "fractional calculus model of viscoelastic behavior', J. Rheology 30(1), 1986")


class CreepKelvinVoigtFractional(Effect):
    """CMS(s) = CMS * (1 + kappa) / (1 + kappa*(s/ws)^beta), s = jw, ws = 2*pi*fs.

    A spring in parallel with a springpot (King and Agerkvist): the stiffness is
    K(jw) = KMS * (1 + kappa*(jw/ws)^beta) / (1 + kappa), whose inverse is this factor on the
    compliance. At DC the compliance is finite, (1 + kappa)*CMS (the spring alone); above ws it keeps
    falling as w^-beta (the springpot stiffens), with a loss angle that peaks between the two.
    """

    def response(self, s, p):
        return (1.0 + p["kappa"]) / (1.0 + p["kappa"] * (s / _ws(p)) ** p["beta"])

    def guess(self, ctx):
        return {"kappa": 0.5, "beta": 0.3}


creep_kv = CreepKelvinVoigtFractional(
    id="creep-kv",
    category=CATEGORY,
    title="Fractional Kelvin-Voigt creep (spring parallel to a springpot)",
    site=Site.COMPLIANCE,
    params=(ParamSpec("kappa", "1", "%", 100.0, 1e-3, 50.0, 0.5,
                      "the springpot's stiffness at fs relative to the parallel spring's", typical=(0.02, 10.0)),
            ParamSpec("beta", "1", "-", 1.0, 0.01, 1.0, 0.3, "order of the springpot (0 a spring, 1 a damper)",
                      typical=(0.05, 0.8))),
    physics=("The suspension is a spring in parallel with a fractional element between a spring and a damper (a "
             "springpot): under a slow force the springpot gives way and only the spring holds, so the "
             "compliance levels off at (1 + kappa) times its value at fs instead of growing without end as in "
             "the log laws; towards high frequencies the springpot stiffens the suspension."),
    signature=("Displacement residual below fs that levels off towards the lowest lines (a finite static "
               "compliance), with a loss (phase of Hx) spread over decades; above fs a stiffness still rising, "
               "which the log laws and the three-parameter law cannot both follow."),
    typical="kappa 0.1 to 3, beta 0.1 to 0.6",
    reference=_FRACTIONAL_REFERENCE,
    notes=("Written as the issue's K(jw) = K*(1 + kappa*(jw/ws)^beta)/(1 + kappa): KMS = 1/CMS is K, the stiffness "
           "the law is normalised to at fs (exactly so for beta near 0); the static stiffness is KMS/(1 + kappa), and "
           "at fs the stiffness is KMS*|1 + kappa*j^beta|/(1 + kappa). Causal by construction."),
)


class CreepZenerFractional(Effect):
    """CMS(s) = CMS * [1 + kappa / (1 + (s*tau_r)^beta)]: the fractional standard linear solid (Zener).

    A spring of compliance CMS in series with a fractional Kelvin-Voigt element (a spring of compliance
    kappa*CMS parallel to a springpot): the extra compliance kappa*CMS yields around 1/tau_r, spread over
    more decades the smaller beta is. beta = 1 is creep-3p; the static compliance is (1 + kappa)*CMS and
    the high-frequency one CMS (LCES).
    """

    def response(self, s, p):
        return 1.0 + p["kappa"] / (1.0 + (s * p["tau_r"]) ** p["beta"])

    def guess(self, ctx):
        f_mid = np.sqrt(max(ctx.f_min, 1e-3) * ctx.fs)
        return {"kappa": 0.3, "tau_r": 1.0 / (2.0 * np.pi * f_mid), "beta": 0.6}


creep_zener = CreepZenerFractional(
    id="creep-zener",
    category=CATEGORY,
    title="Fractional standard-linear-solid creep (Zener)",
    site=Site.COMPLIANCE,
    params=(ParamSpec("kappa", "1", "%", 100.0, 0.0, 20.0, 0.3,
                      "extra compliance at DC, relative to the high-frequency compliance", typical=(0.01, 5.0)),
            ParamSpec("tau_r", "s", "ms", 1e3, 1e-5, 10.0, 5e-3, "retardation time of the creep",
                      typical=(1e-4, 1.0)),
            ParamSpec("beta", "1", "-", 1.0, 0.05, 1.0, 0.6, "order of the springpot (1: creep-3p)",
                      typical=(0.1, 1.0))),
    physics=("A spring in series with a spring and springpot in parallel: the suspension has a finite static "
             "compliance, (1 + kappa) times its high-frequency one, and the change between them is spread over "
             "decades around 1/(2*pi*tau_r) (a single retardation time when beta = 1)."),
    signature=("Displacement residual below fs that levels off at the lowest lines like creep-3p's, but spread "
               "over a wider band with a flatter phase bump in Hx than one retardation time gives."),
    typical="kappa 0.1 to 2, tau_r 1 to 100 ms, beta 0.3 to 0.8",
    reference=(_FRACTIONAL_REFERENCE + "; C. Zener, 'Elasticity and anelasticity of metals', 1948 (the standard "
               "linear solid)"),
    notes=("LCES is the compliance above the creep band. beta = 1 is creep-3p: prefer that when BIC says the extra "
           "parameter does not pay."),
)
