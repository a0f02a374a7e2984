"""The diagnosis on a pool: rule 3's site fits handed over as soon as a candidate passes rules 1 and 2, each
site fitted once per model, and the same judgements as without a pool."""
from concurrent.futures import Future

import pytest

from analysis.diagnosis import acceptance
from analysis.diagnosis.candidates import diagnose
from analysis.diagnosis.sites import fit_site
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.odd_physics import odd_recording


class _Noted(Future):
    """A future that notes in its pool's log when its result is asked for."""

    def __init__(self, log: list, what: str):
        super().__init__()
        self.log, self.what = log, what

    def result(self, timeout=None):
        self.log.append(("collected", self.what))
        return super().result(timeout)


class _InProcessPool:
    """Runs each call when it is handed over; notes the site fits (which model, which site) in that order,
    and in one log when each call was handed over and when its result was asked for."""

    def __init__(self):
        self.sites: list[tuple[int, object]] = []
        self.log: list[tuple[str, str]] = []

    def submit(self, fn, *args):
        what = "site" if fn is fit_site else fn.__name__
        if fn is fit_site:
            self.sites.append((id(args[1]), args[2]))
        self.log.append(("handed over", what))
        future = _Noted(self.log, what)
        future.set_result(fn(*args))
        return future


@pytest.fixture(scope="module")
def odd_electrical():
    """Odd physics at the electrical site: rule 3 judges candidates at two sites, then all six are located."""
    return FitData.from_spectra(estimate_spectra(odd_recording("electrical")))


def test_on_a_pool_each_site_is_fitted_once_and_the_judgements_are_those_without(odd_electrical):
    model = Model(parse_effects("lr2,creep-log"))
    alone = diagnose(odd_electrical, model)
    pool = _InProcessPool()
    pooled = diagnose(odd_electrical, model, executor=pool)

    assert len(pool.sites) == len(set(pool.sites)) == 6
    step = pooled.steps[0]
    rule_3 = {c.effect.site for c in step.candidates
              if c.assessment.reason in (acceptance.ACCEPTED, acceptance.MISFIT_LEFT)}
    assert rule_3 and len(rule_3) < 6
    # rule 3's sites were the first handed over, before the last refit was collected
    assert {site for _, site in pool.sites[: len(rule_3)]} == rule_3
    first_site = pool.log.index(("handed over", "site"))
    last_refit = max(i for i, entry in enumerate(pool.log) if entry == ("collected", "_refit"))
    assert first_site < last_refit
    assert pooled.verdict == alone.verdict
    assert [s.chosen for s in pooled.steps] == [s.chosen for s in alone.steps] == [None]
    assert [c.label for c in pooled.first_candidates] == [c.label for c in alone.first_candidates]
    assert [(c.assessment.reason, c.flags) for c in pooled.first_candidates] == \
        [(c.assessment.reason, c.flags) for c in alone.first_candidates]
    assert [s.site for s in pooled.sites] == [s.site for s in alone.sites]
    assert [s.rank_key for s in pooled.sites] == pytest.approx([s.rank_key for s in alone.sites], rel=1e-6)
