"""Physics no catalogue would hold, one per site: recordings the diagnosis must not pretend to explain.

Each shape is odd on purpose (a bump in log f with a twisted phase, a dip
that comes back): no textbook effect has it, and no reasonable catalogue
or effect file would add it. Each acts at one site of docs/physics.md section 8,
the way an effect there acts, so the site localisation has a right answer.
The sizes make the default model miss by 10^2 to 10^5 in reduced chi^2 with
the tests' typical noise.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from analysis.effects import parse_effects
from analysis.effects.base import Effect, Site
from analysis.model.composed import Model
from analysis.synthesis import synthesize_recording
from tests.builders import PAPER, TYPICAL_NOISE, multitone

__all__ = ["ODD", "OddEffect", "odd_recording"]


def bump(f: np.ndarray, f0: float, width: float) -> np.ndarray:
    """A Gaussian bump in ln f: 1 at f0, 1/e at f0 * exp(+-width)."""
    return np.exp(-(np.log(f / f0) / width) ** 2)


@dataclass(frozen=True)
class OddEffect(Effect):
    """A fixed response (no parameters) of frequency, at its site."""

    shape: Callable[[np.ndarray, dict], np.ndarray] | None = None

    def response(self, s, p):
        return self.shape(np.abs(s) / (2.0 * np.pi), p)


def _odd(site: Site, name: str, what: str, shape) -> OddEffect:
    return OddEffect(id=f"odd-{name}", category=f"odd-{name}", title=what, site=site, params=(),
                     physics=what, signature="", typical="", reference="none: made up for the tests", shape=shape)


ODD: dict[str, OddEffect] = {
    "electrical": _odd(Site.BLOCKED, "ze", "25 milliohm of resistance in a bump at 400 Hz, with a reactance "
                                           "that steps from -15 to +15 milliohm across it",
                       lambda f, p: 0.025 * bump(f, 400.0, 0.8) + 0.015j * np.tanh(np.log(f / 400.0))),
    "force-factor": _odd(Site.FORCE_FACTOR, "bl", "Bl dips by 0.6 % around 150 Hz with a 23 degree phase twist",
                         lambda f, p: 1.0 - 0.006 * bump(f, 150.0, 0.7) * np.exp(0.4j)),
    # A broad hump of damping is no longer odd: damping-power (damping rising with frequency) takes most of
    # it. A narrower one, as odd as before, no reasonable law follows.
    # A hump of damping alone is no longer odd: damping-power (damping rising with frequency above fs) takes
    # most of it. With a dip of damping on its way up (150 Hz), no reasonable law follows it.
    "mechanical": _odd(Site.MECHANICAL, "zm", "a hump of 0.15 kg/s of damping at 250 Hz with a dip of 0.06 kg/s "
                                              "at 150 Hz, and 0.08 kg/s of reactance at 350 Hz added to Zm",
                       lambda f, p: (0.15 * bump(f, 250.0, 0.9) - 0.06 * bump(f, 150.0, 0.7)
                                     + 0.08j * bump(f, 350.0, 0.8)) / p["Bl"] ** 2),
    "compliance": _odd(Site.COMPLIANCE, "cms", "the compliance dips by 3 % around 25 Hz, with a phase, and "
                                               "comes back below",
                       lambda f, p: 1.0 - 0.03 * bump(f, 25.0, 0.6) * np.exp(-0.3j)),
    "current": _odd(Site.CURRENT, "i", "the current sense reads 0.3 % high around 2 kHz with a phase twist",
                    lambda f, p: 1.0 / (1.0 + 0.003 * bump(f, 2000.0, 0.6) * np.exp(0.5j))),
    "displacement": _odd(Site.DISPLACEMENT, "x", "the laser reads 0.8 % high around 500 Hz, its phase turning "
                                                 "through the bump",
                         lambda f, p: 1.0 + 0.008 * bump(f, 500.0, 0.5) * np.exp(1j * np.tanh(np.log(f / 500.0)))),
}


def odd_recording(site: str | None, seed: int = 21, base: str = "lr2,creep-log", extra: tuple[Effect, ...] = (),
                  values: dict | None = None, mt=None):
    """The paper's driver (the default model) plus the odd physics at `site` (None: nothing odd)."""
    effects = parse_effects(base) + ((ODD[site],) if site else ()) + tuple(extra)
    truth = {**PAPER.parameters, **(values or {})}
    model = Model(effects)
    mt = mt or multitone()
    return synthesize_recording(model, truth, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1, TYPICAL_NOISE,
                                seed=seed, driver={"name": "synthetic, odd physics", "sd_m2": 0.0133})
