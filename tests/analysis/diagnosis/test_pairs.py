"""Which candidates the diagnosis pairs (analysis.diagnosis.pairs): one that trades a channel's misfit for the
other's, with the candidates that act on the channel it worsens."""
from dataclasses import dataclass

from analysis.diagnosis import acceptance
from analysis.diagnosis.pairs import PairedEffect, credible_partner, leaves_channel, pair_moves, trades_channels
from analysis.effects import get_effect


@dataclass(frozen=True)
class FakeCandidate:
    effect: object
    flags: tuple = ()
    delta_bic: float = -1e6
    fit: object = "fitted"
    action: str = "add"
    replaces: object = None
    assessment: object = None


@dataclass(frozen=True)
class FakeChannel:
    chi2: float


@dataclass(frozen=True)
class FakeFit:
    channels: dict


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


def _refused(reason, z, x):
    return FakeCandidate(get_effect("breakup"), fit=FakeFit({"impedance": FakeChannel(z), "displacement": FakeChannel(x)}),
                         assessment=acceptance.Assessment(False, reason, -1e3))


def test_a_candidate_rule_3_refused_is_paired_on_the_channel_it_improved_least():
    current = FakeFit({"impedance": FakeChannel(6e4), "displacement": FakeChannel(2e5)})
    # Z down to 7 % of its chi^2, Hx to 65 %: the displacement is what is left to mend.
    assert leaves_channel(current, _refused(acceptance.MISFIT_LEFT, 4e3, 1.3e5)) == "displacement"
    assert leaves_channel(current, _refused(acceptance.MISFIT_LEFT, 5e4, 1e4)) == "impedance"
    assert leaves_channel(current, _refused(acceptance.FLAGGED, 4e3, 1.3e5)) is None
    spot = FakeCandidate(get_effect("breakup-spot"), fit=FakeFit({"displacement": FakeChannel(1.5e5)}),
                         assessment=acceptance.Assessment(False, acceptance.MISFIT_LEFT, -1e3))
    delay_x = FakeCandidate(get_effect("delay-x"), fit=FakeFit({"displacement": FakeChannel(1.9e5)}),
                            assessment=acceptance.Assessment(False, acceptance.NO_GAIN, -1.0))
    lowpass_x = FakeCandidate(get_effect("lowpass-x"), fit=FakeFit({"displacement": FakeChannel(2.1e5)}),
                              assessment=acceptance.Assessment(True, acceptance.ACCEPTED, -1e3))
    moves = pair_moves(current, [_refused(acceptance.MISFIT_LEFT, 4e3, 1.3e5), spot, delay_x, lowpass_x],
                       lambda c: leaves_channel(current, c), lambda p, ch: credible_partner(current, p, ch))
    # delay-x did not pay alone, lowpass-x made Hx worse: only breakup-spot is a credible partner.
    assert [(a.effect.id, b.effect.id) for a, b in moves] == [("breakup", "breakup-spot")]
