"""Cone breakup: a second mechanical mode coupled to the voice coil.

Derivation (mechanical side, velocities v of the coil, v2 of the mass m2).
A part m2 of the moving mass is coupled to the rest through a spring k2 and a
damper r2 acting side by side, so the force through the coupling is
F = (r2 + k2/s)*(v - v2) and it drives m2: F = s*m2*v2. The impedance the
coil sees through the coupling is

    Z2 = F/v = 1 / (1/(r2 + k2/s) + 1/(s*m2)).

At low frequencies the coupling is stiff and Z2 -> s*m2: m2 moves with the
cone, and it is part of Mms. So the cone's own mass is Mms - m2, and the
effect adds Z2 - s*m2 to Zm: nothing at low frequencies, the loss of m2
above the mode. With w2^2 = k2/m2 and Q2 = w2*m2/r2 this is

    Z2 - s*m2 = -m2 * s^3 / (s^2 + s*w2/Q2 + w2^2).

In the model's admittance units (Y = Zm/Bl^2, where s*Mms/Bl^2 = s*CMES),
m2/Bl^2 = mu2*CMES with mu2 = m2/Mms, so the response is

    Y2(s) = -mu2*CMES * s^3 / (s^2 + s*w2/Q2 + w2^2),      w2 = 2*pi*f2.

As an electrical analogue: a branch of a capacitance M2E = mu2*CMES (= m2/Bl^2)
in series with L2E = 1/(w2^2*M2E) (= Bl^2/k2) parallel to R2E = Q2/(w2*M2E)
(= Bl^2/r2), across the motional branch CMES || LCES || RES, with M2E taken
out of CMES so that the total low-frequency mass stays CMES.

What the data show: Zm -> infinity at f2 (m2 on k2 resonates and holds the
coil still: a dip of Z towards Ze and a notch in Hx) and Zm -> 0 at
f2/sqrt(1 - mu2) (cone and m2 move against each other: a peak in Z and Hx).
"""
from __future__ import annotations


import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site

CATEGORY = "breakup"
# The spot's local mode is not an alternative to a mode the coil feels: a cone mode can show in both (the
# diagnosis then takes the two as a pair, analysis.diagnosis.pairs), so it is a category of its own.
SPOT_CATEGORY = "cone-spot"
# With only the basic start context, the mode is looked for a decade above fs
# (where paper and plastic cones of woofers usually break up first), and
# never above half the top line.
DEFAULT_F2_OVER_FS = 10.0
# A fit converges when it starts within about a factor 1.5 of f2 (a narrow
# feature: farther away the model's wiggle and the data's do not overlap and
# the fit removes the mode instead of moving it). A search over the band
# therefore steps f2 by this ratio, from 2*fs to just below the top line.
START_GRID_RATIO = 1.4
START_Q2 = 3.0      # broad enough to overlap a mode some way off, sharpened by the fit
START_MU2 = 0.1


def upper_band_grid(ctx, ratio: float) -> list[float] | None:
    """Frequencies from 2*fs to just below the top line, `ratio` apart, where a mode's search starts;
    None when the band holds no such span."""
    lo, hi = 2.0 * ctx.fs, ctx.f_max / 1.2
    if hi <= lo:
        return None
    n = int(np.ceil(np.log(hi / lo) / np.log(ratio))) + 1
    return [float(f) for f in np.geomspace(lo, hi, n)]


class Breakup(Effect):
    """Y2(s) = -mu2*CMES * s^3 / (s^2 + s*w2/Q2 + w2^2), w2 = 2*pi*f2, added to Y = Zm/Bl^2.

    mu2 = m2/Mms (the part of the moving mass that decouples), f2 = the
    resonance of m2 on its coupling spring k2, Q2 = w2*m2/r2. Zm is infinite
    at f2 and zero at f2/sqrt(1 - mu2). See the module docstring for the
    derivation from Z2 = 1 / (1/(r2 + k2/s) + 1/(s*m2)).
    """

    def response(self, s, p):
        w2 = 2.0 * np.pi * p["f2"]
        return -p["mu2"] * p["CMES"] * s**3 / (s * s + s * w2 / p["Q2"] + w2 * w2)

    def guess(self, ctx):
        return {"f2": min(DEFAULT_F2_OVER_FS * ctx.fs, 0.5 * ctx.f_max), "Q2": START_Q2, "mu2": START_MU2}

    def starts(self, ctx) -> list[dict[str, float]]:
        """Start values stepping f2 across the band, for a search that keeps the lowest chi^2."""
        grid = upper_band_grid(ctx, START_GRID_RATIO)
        if grid is None:
            return [self.guess(ctx)]
        return [{"f2": f2, "Q2": START_Q2, "mu2": START_MU2} for f2 in grid]


breakup = Breakup(
    id="breakup",
    category=CATEGORY,
    title="Cone breakup (a second mechanical mode)",
    site=Site.MECHANICAL,
    params=(ParamSpec("f2", "Hz", "Hz", 1.0, 10.0, 1e5, 700.0, "resonance of the decoupling mass on its coupling",
                      typical=(150.0, 2e4)),
            ParamSpec("Q2", "1", "-", 1.0, 0.1, 200.0, START_Q2, "quality factor of the breakup mode", typical=(1.0, 50.0)),
            ParamSpec("mu2", "1", "%", 100.0, 1e-4, 0.95, START_MU2, "decoupling mass as a fraction of Mms",
                      typical=(0.01, 0.6))),
    physics=("Above some frequency the cone no longer moves as one piece: its outer part (a mass m2) swings "
             "on the cone's own bending stiffness. At that resonance it holds the coil nearly still, just "
             "above it cone and outer part move against each other, and above both the coil drives a "
             "lighter cone."),
    signature=("A narrow dip-then-peak wiggle in |Z| and in the phase of Z well above fs (at f2 and "
               "f2/sqrt(1 - mu2)), and a notch followed by a peak in |Hx| at the same frequencies; above "
               "them |Hx| is higher than the model (a lighter cone)."),
    typical="f2 0.5 to 5 kHz for woofers (higher for small and stiff cones), Q2 2 to 20, mu2 0.05 to 0.5",
    reference=("W. Klippel, 'Loudspeaker cone vibration and radiation' (Klippel GmbH); J. P. Den Hartog, "
               "'Mechanical Vibrations' (the two-mass system, the dynamic vibration absorber)"),
    notes=("Identifiable from Z alone when both frequencies are inside the band and the wiggle stands above "
           "the noise; CMES stays the whole low-frequency moving mass, so fs and Mms keep their meaning. "
           "The start f2 = min(10*fs, f_max/2) is only a default: a fit started more than about a factor "
           "1.5 from the mode does not find it, so a search should try the starts of Breakup.starts(ctx) "
           "(f2 stepped by 1.4 across the band) and keep the lowest chi^2. From Z alone, modes below about "
           "7*fs carrying much of the mass (mu2 > 0.2) are hard to reach even then. The laser sees the coil's motion (the cone's centre); a laser spot "
           "on the outer cone would see m2 instead."),
)


class SpotMode(Effect):
    """Hx_measured(s) = Hx(s) * (s*w2/Q2 + w2^2) / (s^2 + s*w2/Q2 + w2^2),  w2 = 2*pi*f2x.

    The laser spot sits on a part of the cone that rides on the coil through
    the cone's own bending stiffness: a base-excited oscillator whose
    transmissibility is 1 far below f2x, peaks at f2x and falls above. Its
    mass is small against Mms, so the impedance does not see it.
    """

    def response(self, s, p):
        w2 = 2.0 * np.pi * p["f2x"]
        damping = s * w2 / p["Q2x"]
        return (damping + w2 * w2) / (s * s + damping + w2 * w2)

    def guess(self, ctx):
        return {"f2x": min(DEFAULT_F2_OVER_FS * ctx.fs, 0.5 * ctx.f_max), "Q2x": START_Q2}

    def starts(self, ctx) -> list[dict[str, float]]:
        """f2x stepped across the band like Breakup.starts: a narrow mode is found only from nearby."""
        return [{"f2x": start["f2"], "Q2x": START_Q2} for start in breakup.starts(ctx)]


breakup_spot = SpotMode(
    id="breakup-spot",
    category=SPOT_CATEGORY,
    title="Cone breakup seen at the laser spot only",
    site=Site.DISPLACEMENT,
    params=(ParamSpec("f2x", "Hz", "Hz", 1.0, 10.0, 1e5, 2000.0, "resonance of the cone area under the laser spot",
                      typical=(300.0, 2e4)),
            ParamSpec("Q2x", "1", "-", 1.0, 0.1, 200.0, START_Q2, "quality factor of that local mode", typical=(1.0, 50.0))),
    physics=("The laser measures one spot of the cone, not the coil. When the cone bends, that spot moves "
             "more than the coil near its local resonance and less above it, while the coil, and so the "
             "impedance, hardly notices: the mode's mass is small."),
    signature=("A peak followed by a fall in |Hx| (and a phase swing) at one frequency well above fs, with no "
               "matching wiggle in Z."),
    typical="f2x 1 to 8 kHz for woofer cones, Q2x 2 to 20",
    reference="W. Klippel, 'Loudspeaker cone vibration and radiation' (Klippel GmbH): scanning vibrometry",
    notes=("Alone when Z shows no trace of the mode; with `breakup` when Z shows it too (the spot on the outer "
           "cone sees more of the mode than the coil). Aim the laser at the dust cap or close to the coil to "
           "avoid it."),
)


# The coil's share of the moving mass and its decoupling frequency tried as starts: a voice coil, its
# former and the dust cap are a fifth to a third of Mms; the joint resonates in the upper band. Its mode
# is broad in Hx (the coil's motion rises for good above it), so starts an octave apart find it.
COIL_SHARE_START = 0.25
COIL_GRID_RATIO = 2.0


class CoilDecoupling(Effect):
    """The coil rides on the cone through the former's joint; the force and the laser are on the coil.

    Network (velocities v of the coil, v_k of the cone). The coil and former, a mass m_c = mu_c*Mms,
    carry the force Bl*i and the back-EMF; the cone, the rest Mms - m_c with the suspension on it,
    hangs on the former's joint, a spring k_j and a damper r_j side by side. The coil then sees

        Zm = s*m_c + 1 / (1/(r_j + k_j/s) + 1/(s*(Mms - m_c) + Rms + Kms/s))

    and the laser on the coil or the dust cap (which sits on the former) sees the coil's motion: Hx
    follows the same network as Z. With w_c^2 = k_j/m_c (the coil on the joint, the cone held) and
    Q_c = w_c*m_c/r_j, in the model's admittance Y = Zm/Bl^2 the effect adds
    Zm/Bl^2 - (s*CMES + 1/RES + 1/(s*LCES)), where m_c/Bl^2 = mu_c*CMES, (r_j + k_j/s)/Bl^2 =
    mu_c*CMES*(w_c/Q_c + w_c^2/s). Zm is infinite where the cone resonates on the joint with the coil
    held, f_c*sqrt(mu_c/(1 - mu_c)) (Z dips to Ze, Hx has a notch), and zero at f_c/sqrt(1 - mu_c)
    where coil and cone move against each other (a peak); above both the coil moves as a mass m_c
    alone, |Hx| 1/mu_c times the rigid cone's. The suspension's creep is taken on the coil's side (it
    acts where the joint is stiff, far below f_c).
    """

    def response(self, s, p):
        w_c = 2.0 * np.pi * p["f_c"]
        coil = p["mu_c"] * p["CMES"]
        rigid = s * p["CMES"] + 1.0 / p["RES"] + 1.0 / (s * p["LCES"])
        joint = coil * (w_c / p["Q_c"] + w_c * w_c / s)
        cone = s * (p["CMES"] - coil) + 1.0 / p["RES"] + 1.0 / (s * p["LCES"])
        return s * coil + 1.0 / (1.0 / joint + 1.0 / cone) - rigid

    def guess(self, ctx):
        return {"f_c": min(20.0 * ctx.fs, 0.5 * ctx.f_max), "Q_c": START_Q2, "mu_c": COIL_SHARE_START}

    def starts(self, ctx) -> list[dict[str, float]]:
        """f_c stepped an octave at a time from 2*fs to just below the top line."""
        grid = upper_band_grid(ctx, COIL_GRID_RATIO)
        if grid is None:
            return [self.guess(ctx)]
        return [{"f_c": f, "Q_c": START_Q2, "mu_c": COIL_SHARE_START} for f in grid]


breakup_coil = CoilDecoupling(
    id="breakup-coil",
    category=CATEGORY,
    title="Coil decoupling from the cone (laser on the coil or dust cap)",
    site=Site.MECHANICAL,
    params=(ParamSpec("f_c", "Hz", "Hz", 1.0, 20.0, 1e5, 3000.0,
                      "resonance of the coil on the former's joint, the cone held", typical=(300.0, 3e4)),
            ParamSpec("Q_c", "1", "-", 1.0, 0.1, 200.0, START_Q2, "quality factor of the joint", typical=(1.0, 50.0)),
            ParamSpec("mu_c", "1", "%", 100.0, 0.01, 0.9, COIL_SHARE_START,
                      "the coil, former and dust cap's share of Mms", typical=(0.03, 0.6))),
    physics=("At high frequencies the joint between the coil former and the cone is no longer rigid: the coil, "
             "which the force drives, starts to move on its own and the heavy cone lags behind. The laser on the "
             "dust cap or the coil sees the coil, so the displacement shows the same mode as the impedance: a "
             "notch, a peak, then a motion much larger than a rigid cone's."),
    signature=("In the upper band a dip then a peak in |Z| and, at the same frequencies, a notch then a peak in "
               "|Hx| after which |Hx| stays well above the model (the coil alone is light); `breakup`, whose "
               "decoupling part is the outer cone, can match Z there but not this rise of Hx."),
    typical="mu_c 0.1 to 0.4, f_c 1 to 10 kHz, Q_c 2 to 20",
    reference=("W. Klippel, J. Schlechter, 'Distributed mechanical parameters of loudspeakers, part 1: measurements', "
               "JAES 57(7/8), 2009 (modal vibration of cone and coil, measured by laser); J. P. Den Hartog, "
               "'Mechanical Vibrations' (the two-mass system)"),
    notes=("Mms stays the whole low-frequency moving mass and Kms the suspension's. breakup (the outer cone "
           "decoupling, the laser on the coil) is the same two-mass network with the roles of the masses "
           "exchanged, approximately: it reaches this mode only with mu2 = 1 - mu_c (above its typical range), "
           "which is why the two are separate effects with their own starts."),
    # Without it the model bends Mms, Bl and the creep to follow Hx's rise: far from the data the diagnosis
    # also fits it from the data's own start (with the best of its screened starts for the mode).
    cold_start=True,
)
