"""Shared settings and checks of the reliability tests (fuzzing and fault injection).

FUZZ is the hypothesis profile of every fuzz test here: derandomized (the
same examples on every run, so CI cannot turn red by chance), no example
database, no deadline (a slow CI machine is not a bug), a moderate number
of examples so that the whole folder stays well under a minute on two
cores, and no shrinking: a failing example is reported as found, at once,
instead of after minutes of shrinking under the per-test time limit (to
shrink one locally, add Phase.shrink). A failure found once is kept as an
explicit @example in its test.
"""
from __future__ import annotations

from hypothesis import HealthCheck, Phase, settings

FUZZ = settings(max_examples=60, deadline=None, derandomize=True, database=None,
                phases=[Phase.explicit, Phase.generate],
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])
FUZZ_FEW = settings(FUZZ, max_examples=25)
FUZZ_MANY = settings(FUZZ, max_examples=150)


def one_line(exc: BaseException, *fragments: str) -> str:
    """The message of a refused input: one line, not empty, holding every fragment."""
    message = str(exc)
    assert message.strip(), f"{type(exc).__name__} without a message"
    assert "\n" not in message and "\r" not in message, f"message over several lines: {message!r}"
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    return message
