"""Which candidates the diagnosis pairs (analysis.diagnosis.pairs): one that trades a channel's misfit for the
other's, with the candidates that act on the channel it worsens."""
from dataclasses import dataclass

from analysis.diagnosis import acceptance
from analysis.diagnosis.pairs import PairedEffect, pair_moves, trades_channels
from analysis.effects import get_effect


@dataclass(frozen=True)
class FakeCandidate:
    effect: object
    flags: tuple = ()
    delta_bic: float = -1e6
    fit: object = "fitted"
    action: str = "add"
    replaces: object = None


def _worse(channel):
    return acceptance.Flag(acceptance.CHANNEL_WORSE, f"{channel} worse", channel=channel)


def test_a_mode_that_worsens_hx_is_paired_with_the_displacement_sites_effects_only():
    breakup = FakeCandidate(get_effect("breakup"), (_worse("displacement"),))
    spot = FakeCandidate(get_effect("breakup-spot"))
    delay_x = FakeCandidate(get_effect("delay-x"), (_worse("impedance"),))
    delay_i = FakeCandidate(get_effect("delay-current"))
    moves = pair_moves(None, [breakup, spot, delay_x, delay_i])
    assert [(a.effect.id, b.effect.id) for a, b in moves] == [("breakup", "breakup-spot"), ("breakup", "delay-x")]


def test_only_a_candidate_whose_one_blocking_flag_is_the_channel_and_that_gains_is_paired():
    flagged_more = FakeCandidate(get_effect("breakup"), (_worse("displacement"),
                                                         acceptance.Flag(acceptance.AT_BOUND, "Q2 on its bound", "Q2")))
    no_gain = FakeCandidate(get_effect("breakup"), (_worse("displacement"),), delta_bic=-1.0)
    failed = FakeCandidate(get_effect("breakup"), (_worse("displacement"),), fit=None)
    assert [trades_channels(c) for c in (flagged_more, no_gain, failed)] == [None, None, None]
    assert trades_channels(FakeCandidate(get_effect("breakup"), (_worse("displacement"),))) == "displacement"


def test_a_pair_is_judged_on_both_effects_parameters_at_the_first_ones_site():
    pair = PairedEffect(get_effect("breakup"), get_effect("breakup-spot"))
    assert pair.site is get_effect("breakup").site
    assert pair.param_names == ("f2", "Q2", "mu2", "f2x", "Q2x")
