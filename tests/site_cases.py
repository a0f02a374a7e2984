"""Recordings with physics the catalogue does not hold in that form, each acting at known sites.

The first-site criterion of issue 30: for each recording the diagnosis's first named
site must be one where the physics acts. One physics per site, each a textbook law
of another form than the catalogue's, and several at once:

- the laser's spot on the outer cone (a base-excited mode with structural damping): displacement;
- a bump of damping at 400 Hz (a loss peak of the surround, no dip): mechanical;
- a vented box whose losses sit in the port (Small 1973's QP, Vb 20 l, fb 45 Hz, Qp 8): mechanical;
- eddy currents by diffusion in the force factor (tanh sqrt, not the catalogue's first-order fall): force-factor;
- a sound card's DC block on the current sense (a first-order high-pass at 0.5 Hz): current;
- a mode of the laser's mount (the stand rocking at 120 Hz, Q 8): displacement;

and the real-like woofer of tests/real_like.py, alone and with some of the above.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.effects import parse_effects
from analysis.effects.base import Site
from analysis.model.composed import Model
from analysis.synthesis import synthesize_recording
from tests.builders import PAPER, TYPICAL_NOISE, multitone
from tests.odd_physics import OddEffect, bump
from tests.real_like import REAL_LIKE

__all__ = ["SITE_CASES", "SiteCase", "PHYSICS", "case_recording", "port_loss_box"]


def _effect(site: Site, name: str, what: str, shape) -> OddEffect:
    return OddEffect(id=f"case-{name}", category=f"case-{name}", title=what, site=site, params=(),
                     physics=what, signature="", typical="", reference="none: written for the tests", shape=shape)


def _damping_bump(f, p, share=0.6, f0=400.0, width=0.5):
    """Rms rises by `share` of itself in a bump around f0 (kg/s added to Zm, as Y = Zm / Bl^2)."""
    rms = p["Bl"] ** 2 / p["RES"]
    return share * rms * bump(f, f0, width) / p["Bl"] ** 2


def port_loss_box(alpha_b=1.5, fb=45.0, qp=8.0):
    """Small's vented box with its losses in the port: Zm += 1 / (s/Kb + 1/(s Mp + Rp)), Kb = alpha_b Kms,
    Mp = Kb / wb^2, Rp = Kb / (wb QP) (QP = 1/(wb CAB RAP)); as Y = Zm / Bl^2."""
    def shape(f, p):
        s = 2j * np.pi * f
        wb = 2 * np.pi * fb
        a = alpha_b / p["LCES"]
        return 1.0 / (s / a + 1.0 / (s * a / wb**2 + a / (wb * qp)))
    return shape


def _bl_diffusion(f, p, depth=0.04, tau=1.0 / (2 * np.pi * 300.0)):
    """Bl falls by `depth` as the pole's eddy currents shield the gap's flux: a diffusion law, tanh(q)/q."""
    q = np.sqrt(2j * np.pi * f * tau)
    return 1.0 - depth * (1.0 - np.tanh(q) / q)


def _dc_block(f, p, corner=0.5):
    """The current sense behind a first-order high-pass: I_measured = I s/(s + wc), so Z = U/I grows by (s + wc)/s."""
    s = 2j * np.pi * f
    return (s + 2 * np.pi * corner) / s


def _laser_mount(f, p, share=0.01, fm=120.0, qm=8.0):
    """The laser head rocks on its stand, driven by the baffle: a second-order high-pass bump on the displacement."""
    s = 2j * np.pi * f
    wm = 2 * np.pi * fm
    return 1.0 + share * s * s / (s * s + s * wm / qm + wm * wm)


PHYSICS = {
    "cone-spot": REAL_LIKE["cone-spot"],
    "damping-bump": _effect(Site.MECHANICAL, "damping", "a bump of damping at 400 Hz, 60 % of Rms", _damping_bump),
    "port-losses": _effect(Site.MECHANICAL, "port", "a vented box with its losses in the port (QP 8, fb 45 Hz)",
                           port_loss_box()),
    "bl-diffusion": _effect(Site.FORCE_FACTOR, "bl", "Bl falling 4 % by eddy-current diffusion (tanh sqrt)",
                            _bl_diffusion),
    "dc-block": _effect(Site.CURRENT, "dcblock", "a 0.5 Hz high-pass on the current sense", _dc_block),
    "laser-mount": _effect(Site.DISPLACEMENT, "mount", "the laser's mount rocking at 120 Hz, Q 8", _laser_mount),
}
REAL_LIKE_ALL = tuple(REAL_LIKE)
REAL_LIKE_NO_SPOT = tuple(n for n in REAL_LIKE if n != "cone-spot")


@dataclass(frozen=True)
class SiteCase:
    name: str
    physics: tuple[str, ...]          # keys of PHYSICS, then of REAL_LIKE (real-like physics on its own base)
    real_like: tuple[str, ...] = ()   # the real-like physics: the recording's base instead of lr2, creep-log

    @property
    def sites(self) -> frozenset[Site]:
        """Where the physics acts (the base's lr2 and creep-log are in the fitted model): a right first site is one of these."""
        return frozenset(e.site for e in [PHYSICS[n] for n in self.physics] + [REAL_LIKE[n] for n in self.real_like])


SITE_CASES = (
    SiteCase("cone mode at the spot", ("cone-spot",)),
    SiteCase("damping bump", ("damping-bump",)),
    SiteCase("box with port losses", ("port-losses",)),
    SiteCase("eddy-current Bl(f), diffusion", ("bl-diffusion",)),
    SiteCase("DC block on the current sense", ("dc-block",)),
    SiteCase("mode of the laser's mount", ("laser-mount",)),
    SiteCase("real-like woofer", (), REAL_LIKE_ALL),
    SiteCase("real-like woofer, laser on the coil", (), REAL_LIKE_NO_SPOT),
    SiteCase("cone mode in Z and at the spot", (), ("cone-mode", "cone-spot")),
    SiteCase("damping bump and DC block", ("damping-bump", "dc-block")),
    SiteCase("diffusion Bl(f) and laser mount", ("bl-diffusion", "laser-mount")),
    SiteCase("port losses and the spot", ("port-losses", "cone-spot")),
)


def case_recording(case: SiteCase, seed: int = 31, period_samples: int = 16384):
    """The paper driver with the case's physics: on lr2, creep-log, or on the real-like physics when it has some."""
    base = tuple(REAL_LIKE[n] for n in case.real_like) if case.real_like else parse_effects("lr2,creep-log")
    model = Model(tuple(base) + tuple(PHYSICS[n] for n in case.physics))
    mt = multitone(period_samples=period_samples)
    return synthesize_recording(model, dict(PAPER.parameters), mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1,
                                TYPICAL_NOISE, seed=seed, driver={"name": f"synthetic: {case.name}", "sd_m2": 0.0133})
