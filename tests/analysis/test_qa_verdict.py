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


def test_an_interval_across_a_limit_is_written_with_the_digits_that_tell_them_apart(tmp_path):
    """RE 3.0200020 ± 1e-6 against max 3.02: the words were "RE 3.02 .. 3.02 Ω across ≤ 3.02 Ω"."""
    import json
    from analysis.derived import ParameterValue
    from analysis.limits import format_verdicts, load_limits
    from analysis.qa_verdict import judge
    path = tmp_path / "limits.json"
    path.write_text(json.dumps({"format": "linpar-limits/1", "name": "edge",
                                "parameters": {"RE": {"max": 3.02, "unit": "ohm"}}}))
    limits = load_limits(path)
    re_ = ParameterValue(name="RE", value=3.0200020, std=1e-6, unit="ohm", display_unit="ohm", display_scale=1.0)
    judgement = judge(limits, {"RE": re_}, "green")
    assert judgement.verdict == "uncertain"
    assert "RE 3.02 .. 3.020004 Ω across ≤ 3.02 Ω" in judgement.why         # its lower end is the limit
    assert "(3.02 .. 3.020004)" in format_verdicts(limits, {"RE": re_}, "green")
