"""Fixtures the analysis tests share: the fit pool of the diagnosis tests and the paper's multitone."""
import pytest

from analysis.parallel import fit_executor
from tests.builders import multitone


@pytest.fixture(scope="module")
def pool():
    """A process pool for the diagnosis's candidate fits, one per test module (starting one costs seconds)."""
    with fit_executor() as executor:
        yield executor


@pytest.fixture(scope="module")
def mt():
    return multitone()
