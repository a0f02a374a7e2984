"""analysis.model.composed: Model.responses (both channels from one pass) gives what impedance() and
displacement() give apart."""
from __future__ import annotations

import numpy as np

from analysis.effects import parse_effects
from analysis.model import Model
from tests.builders import PAPER
from tests.odd_physics import ODD


def test_one_pass_gives_the_channels_of_two_with_an_effect_at_every_site():
    effects = parse_effects("lr2,creep-log,breakup,delay-current,lowpass-x") + (ODD["force-factor"],)
    model = Model(effects)
    values = {**PAPER.parameters, "f2": 900.0, "Q2": 4.0, "mu2": 0.1, "tau_i": 2e-5, "fc_x": 3000.0}
    values = {spec.name: values.get(spec.name, spec.default) for spec in model.param_specs}
    s = 2j * np.pi * np.geomspace(5.0, 1e4, 200)
    Z, Hx = model.responses(s, values)
    assert np.allclose(Z, model.impedance(s, values), rtol=1e-13, atol=0)
    assert np.allclose(Hx, model.displacement(s, values), rtol=1e-13, atol=0)
    # The sites really act: without the current-channel delay Z differs.
    assert not np.allclose(Z, Model(effects[:3] + effects[4:]).impedance(s, values), rtol=1e-6)
