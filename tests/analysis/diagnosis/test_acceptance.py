"""The acceptance rule's margin (rule 2) and the swap that simplifies, which needs only to lower BIC."""
import math
from types import SimpleNamespace

from analysis.diagnosis import acceptance
from analysis.effects import get_effect, parse_effects
from analysis.model.composed import Model

N_DATA = 1000


def _fit(chi2: float, k: int, model=None, stderr=None):
    """What rules 1 and 2 read of a fit."""
    values = {s.name: s.default for s in model.param_specs} if model else {}
    return SimpleNamespace(chi2=chi2, n_varying=k, chi2_red=chi2 / (N_DATA - k), n_data=N_DATA, model=model,
                           values=values, stderr=stderr if stderr is not None else {n: 0.01 * abs(v) + 1e-12
                                                                                 for n, v in values.items()})


def test_a_swap_that_saves_a_parameter_for_nothing_is_taken_without_the_margin():
    # One parameter fewer, chi^2 up by 1: delta BIC = 1 - ln 1000 = -5.9, short of the margin of 10.
    current, simpler = _fit(900.0, 11), _fit(901.0, 10)     # at the noise floor
    lr2 = get_effect("lr2")
    assert not acceptance.assess(current, simpler, lr2, ()).accepted
    taken = acceptance.assess(current, simpler, lr2, (), simplifying=True)
    assert taken.accepted and math.isclose(taken.scaled_delta_bic, 1.0 - math.log(N_DATA))
    # It must still lower BIC.
    assert not acceptance.assess(current, _fit(908.0, 10), lr2, (), simplifying=True).accepted


def test_only_a_swap_to_fewer_parameters_for_an_effect_with_an_idle_parameter_simplifies():
    model = Model(parse_effects("lr3,creep-log"))
    lr3 = get_effect("lr3")
    idle = _fit(1000.0, 11, model)
    idle.stderr["L3"] = None
    assert acceptance.simplifies(idle, _fit(1001.0, 10), lr3)
    assert not acceptance.simplifies(_fit(1000.0, 11, model), _fit(1001.0, 10), lr3)   # every parameter fixed
    assert not acceptance.simplifies(idle, _fit(1001.0, 11), lr3)                      # no fewer parameters
    assert not acceptance.simplifies(idle, _fit(1001.0, 10), None)                     # an effect added
    assert not acceptance.simplifies(idle, _fit(1001.0, 10), get_effect("creep-log"))  # another effect's
