"""The driver measured in a box: the enclosure's air as a mechanical load on the cone.

The box's air is a spring on the cone, Kb = rho*c^2*Sd^2/Vb; with Vas = rho*c^2*Sd^2*Cms (docs/physics.md
section 3) that is Kb = alpha_b*Kms, alpha_b = Vas/Vb, so neither Sd nor Bl is needed: in the model's
admittance Y = Zm/Bl^2 the spring Kb/s is alpha_b/(s*LCES). Kms and the creep law remain the
suspension's own (the box's air does not creep), Mms the driver's moving mass.

A vented box adds the port: seen from the cone (physics of Thiele's alignments), the box's compliance
1/Kb, the port's air mass Mp = Kb/wb^2 (wb = 2*pi*fb, the Helmholtz resonance of box and port) and the
box's leakage loss RL = QL*Kb/wb are in parallel (a mobility sum):

    Zbox = 1 / (s/Kb + 1/(s*Mp) + 1/RL) = Kb * s / (s^2 + s*wb/QL + wb^2)

Well above fb it is the closed box's spring Kb/s; at fb the port takes the cone's volume flow and the
box hardly loads the cone (the impedance dip between the two peaks of Z); well below fb the cone moves
the port's air, a mass Mp.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.effects.base import Effect, ParamSpec, Site
from analysis.fit.startvalues import impedance_peaks

CATEGORY = "enclosure"
ALPHA = ParamSpec("alpha_b", "1", "-", 1.0, 0.005, 100.0, 1.0,
                  "the box's air stiffness relative to the suspension's (Vas/Vb)", typical=(0.05, 20.0))
# A port's tuning relative to fs tried as starts: the fit converges from within about a factor 1.4.
FB_OVER_FS_STARTS = (0.4, 0.55, 0.75, 1.0, 1.35)

_REFERENCE = ("R. H. Small, 'Closed-box loudspeaker systems, part I: analysis', JAES 20(10), 1972; A. N. Thiele, "
              "'Loudspeakers in vented boxes, parts I and II', JAES 19(5), 19(6), 1971 (first in Proc. IRE "
              "Australia, 1961); R. H. Small, 'Vented-box loudspeaker systems, part I', JAES 21(5), 1973")


class ClosedBox(Effect):
    """Zm += Kb/s with Kb = alpha_b*Kms: in the model's admittance Y += alpha_b / (s*LCES); alpha_b = Vas/Vb."""

    def response(self, s, p):
        return p["alpha_b"] / (s * p["LCES"])

    def guess(self, ctx):
        return {"alpha_b": 0.05}


closed_box = ClosedBox(
    id="closed-box",
    category=CATEGORY,
    title="Closed box (the enclosure's air spring)",
    site=Site.MECHANICAL,
    params=(ALPHA,),
    physics=("Measured in a sealed box, the cone compresses the air behind it: a spring in parallel with the "
             "suspension, alpha_b times as stiff (alpha_b = Vas/Vb). Unlike the suspension it does not creep, so "
             "the creep law then describes the suspension alone."),
    signature=("After a creep law is fitted: a residual below fs shaped like the creep's own, because the fitted "
               "law had to share one stiffness between a spring that creeps and one that does not; fs and Qts "
               "are those of the box, Kms too high by the box's stiffness without this effect."),
    typical="alpha_b 0.5 to 10 (a box of Vas/2 gives 2)",
    reference=_REFERENCE,
    notes=("Only the creep tells the box's spring from the suspension's: the box does not creep. With a real-valued "
           "creep law (creep-log) the two trade against each other to first order; the data separate them through "
           "the creep's curvature, so alpha_b's standard error is large unless the creep is strong and the "
           "lowest lines well measured. Knowing Vb, compare alpha_b with Vas/Vb."),
)


class VentedBox(Effect):
    """Zm += Kb*s / (s^2 + s*wb/QL + wb^2), Kb = alpha_b*Kms, wb = 2*pi*fb: in the model's admittance
    Y += (alpha_b/LCES) * s / (s^2 + s*wb/QL + wb^2). See the module docstring for the network."""

    def response(self, s, p):
        wb = 2.0 * np.pi * p["fb"]
        return p["alpha_b"] / p["LCES"] * s / (s * s + s * wb / p["QL"] + wb * wb)

    def guess(self, ctx):
        """Thiele and Small's reading of the two impedance peaks: the driver's own fs and the box's start.

        With the peaks at fL < fH and the minimum of |Z| between them at fM (about fb):
        fs = fL*fH/fb, alpha_b = (fH^2 - fb^2)*(fb^2 - fL^2) / (fH^2*fL^2) (Small 1973, lossless box).
        The driver's compliance is moved to that fs (LCES = 1/(ws^2*CMES)): the fit from a model without
        the box put its one resonance on one of the peaks.
        """
        found = _two_peaks(ctx)
        if found is None:
            return {"alpha_b": 1.0, "fb": 0.75 * ctx.fs, "QL": 7.0}
        f_lo, f_mid, f_hi = found
        fs = f_lo * f_hi / f_mid
        alpha = (f_hi**2 - f_mid**2) * (f_mid**2 - f_lo**2) / (f_hi**2 * f_lo**2)
        cmes = ctx.CMES
        return {"alpha_b": float(np.clip(alpha, 0.05, 20.0)), "fb": f_mid, "QL": 7.0,
                "CMES": cmes, "LCES": 1.0 / ((2.0 * np.pi * fs) ** 2 * cmes)}

    def starts(self, ctx) -> list[dict[str, float]]:
        """The reading of the two peaks when Z has them; else fb stepped around fs."""
        if _two_peaks(ctx) is not None:
            return [self.guess(ctx)]
        return [{"alpha_b": 1.0, "fb": ratio * ctx.fs, "QL": 7.0} for ratio in FB_OVER_FS_STARTS]


@dataclass(frozen=True)
class VentedBoxLosses(VentedBox):
    """A vented box whose losses sit in the box's filling (QA) or in the port (QP) instead of in leaks: see the
    module docstring. In the model's admittance, with a = alpha_b/LCES,

        absorption  Y += a * s * (1 + s/(wb*QA)) / (s^2 + s*wb/QA + wb^2)
        port        Y += a * (s + wb/QP) / (s^2 + s*wb/QP + wb^2)
    """

    q_name: str = "QA"

    def response(self, s, p):
        wb = 2.0 * np.pi * p["fb"]
        q = p[self.q_name]
        a = p["alpha_b"] / p["LCES"]
        numerator = s * (1.0 + s / (wb * q)) if self.q_name == "QA" else s + wb / q
        return a * numerator / (s * s + s * wb / q + wb * wb)

    def guess(self, ctx):
        return _renamed(super().guess(ctx), self.q_name)

    def starts(self, ctx) -> list[dict[str, float]]:
        return [_renamed(start, self.q_name) for start in super().starts(ctx)]


def _renamed(start: dict, q_name: str) -> dict:
    """A leakage box's start with its QL as the family member's Q (the same peak's damping)."""
    out = {k: v for k, v in start.items() if k != "QL"}
    out[q_name] = start.get("QL", 7.0)
    return out


def _two_peaks(ctx) -> tuple[float, float, float] | None:
    """(fL, fM, fH): the two highest peaks of Re(Z) and the minimum of |Z| between them, when the second peak
    is at least a fifth of the first (a box's, not a wiggle's) and within a decade of it. A lower peak
    below the band (Re(Z) still rising at the lowest line) is taken at the lowest line: fs and alpha_b
    then start too low and too high, near enough for the fit."""
    z = ctx.impedance
    peaks = impedance_peaks(ctx)
    if peaks is not None:
        (f_lo, f_hi), heights = peaks
    else:
        one = impedance_peaks(ctx, 1)
        if z is None or one is None:
            return None
        ok = np.isfinite(z.value)
        excess = z.value[ok].real - ctx.RE
        if not excess[0] > excess[1]:            # no peak below the band either
            return None
        f_lo, f_hi = float(z.freqs[ok][0]), float(one[0][0])
        heights = np.array([excess[0], one[1][0]])
    if min(heights) < 0.2 * max(heights) or f_hi > 10.0 * f_lo:
        return None
    between = (z.freqs > f_lo) & (z.freqs < f_hi) & np.isfinite(z.value)
    if not between.any():
        return None
    f_mid = float(z.freqs[between][np.argmin(np.abs(z.value[between]))])
    return float(f_lo), f_mid, float(f_hi)


vented_box = VentedBox(
    id="vented-box",
    category=CATEGORY,
    title="Vented box (box and port: a Helmholtz resonator)",
    site=Site.MECHANICAL,
    params=(ALPHA,
            ParamSpec("fb", "Hz", "Hz", 1.0, 2.0, 1000.0, 40.0, "tuning of the port (box and port's Helmholtz "
                      "resonance)", typical=(10.0, 300.0)),
            ParamSpec("QL", "1", "-", 1.0, 0.3, 200.0, 7.0, "the box's leakage quality factor at fb",
                      typical=(2.0, 50.0))),
    physics=("Measured in a vented box, the air in the port resonates on the box's air spring at fb: there the "
             "port moves the air and the cone hardly needs to, above fb the box is a spring, below it the cone "
             "drives the port's air mass. The impedance has two peaks with a dip near fb between them."),
    signature=("Two impedance peaks where the model has one, with a minimum of |Z| near fb between them, and "
               "|Hx| with a notch near fb (the cone stands nearly still there); no creep law or breakup mode can "
               "make the second peak."),
    typical="fb 0.5 to 1.3 fs, alpha_b 0.5 to 5, QL 5 to 20 (leakage and absorption)",
    reference=_REFERENCE,
    notes=("Kms, Mms and the creep law stay the driver's own; the box's alignment (fb, Vb = Vas/alpha_b, QL) comes "
           "out with them. The port's own losses are counted in QL; fb is started at several values near fs "
           "(the fit converges from within about a factor 1.4)."),
    # Without the box the one resonance of the model sits on one of the two peaks and every parameter bends:
    # far from the data the box is also fitted from the data's own start (Thiele and Small's reading of Z).
    cold_start=True,
)


def _lossy_box(q_name: str, where: str, physics: str, signature: str) -> VentedBoxLosses:
    return VentedBoxLosses(
        id=f"vented-box-{where}",
        category=CATEGORY,
        title=f"Vented box, losses in the {'box filling' if where == 'absorption' else 'port'}",
        site=Site.MECHANICAL,
        params=(ALPHA, vented_box.params[1],
                ParamSpec(q_name, "1", "-", 1.0, 0.3, 200.0, 7.0, f"the box's {where} quality factor at fb",
                          typical=(2.0, 100.0))),
        physics=physics,
        signature=signature,
        typical=f"fb 0.5 to 1.3 fs, alpha_b 0.5 to 5, {q_name} 5 to 100",
        reference=_REFERENCE,
        notes=("One of the vented box's loss family (Small 1973: QL leakage, QA absorption, QP port); the "
               "diagnosis tries each in turn and keeps the one the data take."),
        cold_start=True,
        q_name=q_name,
    )


vented_box_absorption = _lossy_box(
    "QA", "absorption",
    "A vented box whose filling (wool, foam) absorbs: a resistance in series with the box's air spring. Near fb it "
    "damps the dip like a leak; well above fb, where the box is a spring, it adds a small resistance to the cone.",
    "Two impedance peaks with a dip near fb, as a leaky box, but the upper peak a little lower than a leak would "
    "leave it.")
vented_box_port = _lossy_box(
    "QP", "port",
    "A vented box whose losses sit in the port (friction and turbulence of the air in a long or narrow port): a "
    "resistance in series with the port's air mass. Near fb it damps the dip; well below fb the cone drives the "
    "port's air through that resistance.",
    "Two impedance peaks with a dip near fb, as a leaky box, but below fb extra damping of the lower peak that a "
    "leak cannot give.")
