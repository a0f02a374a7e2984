"""How a parameter's interval is judged against a limit: the outcomes, the coverage factor, the unit's verdict.

A module of its own, with no imports, so that reading a limits file
(analysis.limits), the verdict every output shows (analysis.qa_verdict)
and the validity's QA codes (analysis.validity.fit) share these words
without importing one another.
"""
from __future__ import annotations

# The interval a parameter is judged by: value +- INTERVAL_K x std. With a std that covers what the model misses,
# two of them hold the truth about 95 times in 100 (a normal error); the realistic recordings' acceptance is
# "truth within 2 reported std" (issue 29), and a PASS then says the unit is inside its limits with that
# confidence, while a unit whose value only just clears a bound is not passed on the luck of its noise.
INTERVAL_K = 2.0
PASS, FAIL, UNCERTAIN = "pass", "fail", "uncertain"


def verdict_of(verdicts) -> str:
    """FAIL when any parameter fails, else UNCERTAIN when any interval straddles a limit, else PASS."""
    outcomes = {v.outcome for v in verdicts}
    return FAIL if FAIL in outcomes else UNCERTAIN if UNCERTAIN in outcomes else PASS
