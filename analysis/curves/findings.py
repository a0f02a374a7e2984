"""Findings on imported curves' results, added to their validity where a recording's checks would be.

A curve's channel gets findings but no light of its own (nothing else of the curves was checked), and the
overall light is the worst of what it was and what was found: "unknown" until something is found.
"""
from __future__ import annotations

from typing import Sequence

from analysis.validity.assessment import ChannelValidity
from analysis.validity.findings import Finding, Severity, worst
from analysis.validity.result import ResultValidity


def with_curve_findings(validity: ResultValidity, found: Sequence[Finding]) -> ResultValidity:
    """`validity` with `found` added to their channels' findings and the overall light raised to the worst."""
    if not found:
        return validity
    channels = dict(validity.channels)
    for finding in found:
        before = channels.get(finding.channel)
        channels[finding.channel] = ChannelValidity(finding.channel, None,
                                                    (*(before.findings if before else ()), finding))
    lights = [f.severity for f in found]
    if validity.overall in set(Severity):
        lights.append(Severity(validity.overall))
    return validity.replace(overall=worst(lights), channels=channels)
