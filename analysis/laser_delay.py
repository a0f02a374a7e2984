"""A serial laser's delay found from the measurement itself, over -5 ... +25 ms and beyond.

A laser on a clock and a link of its own (a USB serial adapter hands its
samples over in packets, 1 - 16 ms late with ms of jitter) is placed on the
audio's time line by host arrival times, which leave its link latency in.
What is left is a pure delay of the displacement, Hx_measured = Hx *
exp(-s tau). Once Z is fitted, everything in Hx but Bl and the creep is
known (Hx = ZR / (ZR + Ze) / (Bl s)), so

    r(f) = Hx_measured / Hx_model(Bl = 1, tau = 0) ~ exp(-j w tau) / Bl,

a phasor whose phase is -w tau, and whose sign is known (Bl > 0). The delay
is the tau that turns every line's r back to the positive real axis:

    score(tau) = Re sum_k w_k r_k/|r_k| exp(j w_k tau) / sum_k w_k,     w_k = |Hx_k / std_k|^2

which is 1 at the true delay and well below it elsewhere. Searched first on
a grid over SEARCH_S (finer than the main lobe, 1 / (4 f_top)), then refined
by a bounded scalar search inside the best grid point's lobe. A slope fitted
to the unwrapped phase (the previous way) aliases once the delay turns the
phase by more than half a turn between two lines (~2 ms at the top of a
1.76 kHz band); the grid has no such limit below 1 / line spacing (170 ms
at 5.9 Hz lines).

The data place the delay when the best peak stands clear of every other
against the noise: a line of power signal-to-noise w_k whose phase is off by
phi adds 2 w_k (1 - cos phi) to chi^2, so the next best peak's chi^2 lies
above the best's by 2 W (score - runner-up), W = sum w_k; placed when that
is at least PLACED_CHI2 and the lines agree (score >= PLACED_SCORE: a model
that misses the phase by a radian on average cannot place anything), and the
delay is not on the search's edge. Otherwise ``placed`` is False and the
caller must say so. The delay's uncertainty comes from the fit that starts here
(delay-x's tau_x, with the creep and Bl fitted together); this search only
has to land in the right lobe.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

SEARCH_S = (-10e-3, 40e-3)      # covers the host's placement error plus a USB link's worst (16 ms timer + jitter)
PLACED_CHI2 = 25.0              # the next best peak's chi^2 above the best's by this (5 sigma): placed
PLACED_SCORE = 0.5              # and the lines agree on it at least this much


@dataclass(frozen=True, slots=True)
class DelaySearch:
    """What the search found: the delay (s, positive: the displacement lags), and whether the data place it."""

    delay_s: float
    score: float            # at the delay: 1 when every line agrees
    runner_up: float        # the best score of any other peak
    chi2_margin: float      # how much more chi^2 that peak leaves than the delay's
    placed: bool

    def as_json(self) -> dict:
        return {"delay_s": self.delay_s, "score": self.score, "runner_up": self.runner_up,
                "chi2_margin": self.chi2_margin, "placed": self.placed}


def find_delay(freqs: np.ndarray, ratio: np.ndarray, weight: np.ndarray,
               search_s: tuple[float, float] = SEARCH_S) -> DelaySearch:
    """The delay that turns ``ratio`` (measured / model, a positive real times exp(-j w tau)) real (module doc).

    ``weight``: each line's weight (its power signal-to-noise ratio); lines with a non-finite ratio or weight
    are left out."""
    ok = np.isfinite(ratio) & np.isfinite(weight) & (weight > 0) & (np.abs(ratio) > 0)
    if ok.sum() < 3:
        return DelaySearch(0.0, 0.0, 0.0, 0.0, False)
    total = float(weight[ok].sum())
    w, phasor, weight = 2 * np.pi * freqs[ok], ratio[ok] / np.abs(ratio[ok]), weight[ok] / total

    def score(tau):
        return (np.exp(1j * np.multiply.outer(np.atleast_1d(tau), w)) @ (weight * phasor)).real

    lobe = 1.0 / (w.max() / (2 * np.pi))              # a main lobe is about this wide (1 / f_top)
    grid = np.arange(search_s[0], search_s[1] + lobe / 8, lobe / 8)
    scores = np.concatenate([score(chunk) for chunk in np.array_split(grid, max(1, grid.size // 512))])
    best = int(np.argmax(scores))
    refined = minimize_scalar(lambda t: -score(t)[0], bounds=(grid[best] - lobe / 8, grid[best] + lobe / 8),
                              method="bounded", options={"xatol": 1e-8})
    tau = float(refined.x)
    at = float(score(tau)[0])
    peaks = np.flatnonzero((scores[1:-1] > scores[:-2]) & (scores[1:-1] >= scores[2:])) + 1
    others = peaks[peaks != best]
    runner_up = float(scores[others].max()) if others.size else -1.0
    margin = 2.0 * total * (at - runner_up)
    on_edge = not (search_s[0] + lobe / 4 < tau < search_s[1] - lobe / 4)
    placed = at >= PLACED_SCORE and margin >= PLACED_CHI2 and not on_edge
    return DelaySearch(tau, at, runner_up, margin, placed)
