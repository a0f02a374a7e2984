"""The first site the diagnosis names is one where the physics acts, on recordings the catalogue does not hold.

Issue 30's criterion: recordings of physics of another form than the catalogue's, one per site, and
several at once (tests/site_cases.py); the site the verdict points at first should be one where the
physics acts in at least 90 % of them. Main before issue 30 named a right site in 2 of the 12; with the
sites ranked on both channels at their own scale, 10; with a sense site's own channel counted no more than
the other channel's share, 11 (92 %; 11 of 12 on seed 32 too). The one left wrong is the real-like woofer
with the laser on the outer cone (on seed 32: with the laser on the coil), which names the force-factor
site: a factor g on Bl acts as the mechanical site's Zm / g^2 with the laser's factor 1 / g, so it follows
misfit at the mechanical site and in Hx together better than either site alone.
The count asserted is what this branch reaches less a margin of one, so that a regression shows; every
case is said in the failure message.
"""
import pytest

from analysis.diagnosis.candidates import diagnose
from analysis.diagnosis.words import first_site
from analysis.effects import parse_effects
from analysis.fit.least_squares import FitData
from analysis.model.composed import Model
from analysis.spectra import estimate_spectra
from tests.site_cases import SITE_CASES, case_recording

GOAL_SHARE = 0.9         # issue 30's criterion
REQUIRED_RIGHT = 10      # what this branch reaches (11 measured), less a margin


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
