"""analysis.qa_verdict's QAJudgement: built by keyword only (its five fields are easy to swap by position)."""
from __future__ import annotations

import dataclasses

import pytest

from analysis.qa_verdict import QAJudgement


def test_a_judgement_is_built_by_keyword_only():
    assert all(f.kw_only for f in dataclasses.fields(QAJudgement))
    with pytest.raises(TypeError):
        QAJudgement("pass", "why", (), True, {})      # the positional form is refused
    judged = QAJudgement(verdict="pass", why="all within", verdicts=(), judged=True, fit_error_percent={})
    assert judged.headline
