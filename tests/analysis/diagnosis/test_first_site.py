"""The first site the diagnosis names is one where the physics acts, on recordings the catalogue does not hold.

Issue 30's criterion: recordings of physics of another form than the catalogue's, one per site, and
several at once (tests/site_cases.py); the site the verdict points at first should be one where the
physics acts in at least 90 % of them. Not yet: main before issue 30 named a right site in 2 of the 12,
this branch in 10 (83 %: the mixture damping bump + DC block names the displacement site, the
real-like woofer with the spot the force-factor site). The count asserted is the floor reached less
a margin of two, so that a regression shows; every case is said in the failure message.
"""
import pytest

from analysis.diagnosis.candidates import diagnose
from analysis.diagnosis.words import first_site
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.site_cases import SITE_CASES, case_recording

GOAL_SHARE = 0.9         # issue 30's criterion, not reached yet
REQUIRED_RIGHT = 8       # what this branch reaches (10 measured), less a margin


@pytest.mark.slow
@pytest.mark.timeout(1800)      # twelve diagnoses in one test: a count over the table needs them all
def test_the_first_site_named_is_where_the_physics_acts_in_most_cases(pool):
    table = []
    for case in SITE_CASES:
        data = FitData.from_spectra(estimate_spectra(case_recording(case)))
        result = diagnose(data, Model(parse_effects("lr2,creep-log")), executor=pool)
        named = first_site(result)
        table.append((case.name, named.key if named else None, sorted(s.key for s in case.sites), named in case.sites))
    right = sum(ok for *_, ok in table)
    report = "\n".join(f"{'right' if ok else 'WRONG'}  {name}: named {named}, acts at {', '.join(sites)}"
                       for name, named, sites, ok in table)
    assert right >= REQUIRED_RIGHT, report
