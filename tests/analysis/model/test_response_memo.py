"""analysis.model.response_memo: a model evaluated again with some parameters moved gives what a fresh
evaluation gives (compared to 1e-13, not bit for bit: numpy's vector loops may round the last bit by where
an array sits in memory); an effect is worked out again as soon as any parameter it reads moves, including
another effect's or the base model's (air-load reads Bl, creep reads fs through CMES and LCES)."""
from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
import pytest

from analysis.effects import parse_effects
from analysis.effects.base import Effect, ParamSpec, Site
from analysis.model import Model
from analysis.model import response_memo
from tests.builders import PAPER

S = 2j * np.pi * np.geomspace(5.0, 1e4, 150)


def _values(model: Model, **extra) -> dict[str, float]:
    values = {**PAPER.parameters, "f2x": 3000.0, "Q2x": 4.0, "a_rad": 0.06, **extra}
    return {spec.name: float(values.get(spec.name, spec.default)) for spec in model.param_specs}


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return np.allclose(a, b, rtol=1e-13, atol=0)


def _fresh(model: Model, values) -> tuple[np.ndarray, np.ndarray]:
    """The same model as a new object: the memo starts empty for it."""
    return Model(model.effects, model.with_displacement).responses(S, values)


def test_every_parameter_moved_in_turn_gives_what_a_fresh_evaluation_gives():
    model = Model(parse_effects("lr2,creep-log,air-load,damping-power,breakup-spot,delay-current"))
    values = _values(model)
    model.responses(S, values)
    # A Jacobian's walk: each parameter stepped alone, then all at once, then back.
    walk = [{**values, name: values[name] * 1.001 + 1e-9} for name in values]
    walk += [{name: v * 0.999 for name, v in values.items()}, values]
    for p in walk:
        Z, Hx = model.responses(S, p)
        Z0, Hx0 = _fresh(model, p)
        assert _same(Z, Z0) and _same(Hx, Hx0)
        assert _same(model.impedance(S, p), Z0)


def test_an_effect_that_reads_another_effects_parameter_is_worked_out_again_when_it_moves():
    model = Model(parse_effects("lr2,creep-log,air-load"))
    values = _values(model)
    before = model.responses(S, values)[0]
    moved = {**values, "Bl": values["Bl"] * 1.5}       # air-load's term is Zr / Bl^2
    after = model.responses(S, moved)[0]
    assert _same(after, _fresh(model, moved)[0])
    assert not _same(after, before)


@dataclass(frozen=True)
class _Branching(Effect):
    """Reads RE only when its own parameter is positive: what it depends on changes with its values."""

    def response(self, s, p):
        return 1.0 + (p["k_b"] * p["RE"] if p["k_b"] > 0 else p["k_b"]) * s / (s + 1e3)


BRANCHING = _Branching(id="branching", category="test-branching", title="test", site=Site.CURRENT,
                       params=(ParamSpec("k_b", "1", "-", 1.0, -1.0, 1.0, 0.1, "test"),),
                       physics="", signature="", typical="", reference="")


def test_what_an_effect_reads_is_seen_on_each_evaluation_not_assumed():
    model = Model((BRANCHING,))
    values = _values(model, k_b=-0.2)
    model.impedance(S, values)                          # reads k_b alone
    for p in ({**values, "k_b": 0.3}, {**values, "k_b": 0.3, "RE": values["RE"] * 2}):
        assert _same(model.impedance(S, p), Model((BRANCHING,)).impedance(S, p))


def test_a_remembered_response_cannot_be_changed_by_its_user():
    model = Model(parse_effects("lr2"))
    values = _values(model)
    model.responses(S, values)
    memo = response_memo.for_model(model, S)
    kept = memo.response(model.effects[0], S, values)
    with pytest.raises(ValueError):
        kept[0] = 0.0


def test_parameters_that_are_arrays_are_evaluated_and_not_remembered():
    model = Model(parse_effects("lr2,creep-log"))
    values = _values(model)
    values["L2"] = np.array(values["L2"])          # a 0-d array: a number the memo does not compare
    first = model.impedance(S, values)
    values["L2"] = np.array(float(values["L2"]) * 2)
    assert _same(model.impedance(S, values), Model(model.effects).impedance(S, values))
    assert not _same(first, model.impedance(S, values))


def test_other_lines_and_other_threads_start_afresh():
    model = Model(parse_effects("lr2,creep-log,air-load"))
    values = _values(model)
    model.responses(S, values)
    fewer = S[::3].copy()
    assert _same(model.responses(fewer, values)[0], _fresh(model, values)[0][::3])
    seen = {}
    thread = threading.Thread(target=lambda: seen.update(memo=response_memo.for_model(model, S)))
    thread.start()
    thread.join(timeout=60)
    assert seen["memo"] is not response_memo.for_model(model, S)
