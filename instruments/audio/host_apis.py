"""Which of PortAudio's host APIs suits a measurement, and why; a sound card listed under several is one card.

A measurement needs the samples exactly as the converters took them and as
they were sent: no resampling, no mixing with other programs' sound, no
"enhancements", and one clock for input and output. How close a host API
comes to that is a property of the API (and, for ALSA, of the device: a
``hw:`` device is the card itself, ``default``, ``pulse`` and ``pipewire``
are a sound server that resamples). Names are PortAudio's
(``sounddevice.query_hostapis()``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from instruments.audio.interface import AudioDeviceInfo

BEST, GOOD, POOR, UNUSABLE = 0, 1, 2, 3
# host API -> (rank, why), lower is better.
HOST_APIS = {
    "ASIO": (BEST, "the card maker's own driver: bit-exact, no Windows mixer, no resampling, low latency"),
    "Windows WASAPI": (GOOD, "bit-exact in exclusive mode only; in shared mode the Windows mixer resamples to its "
                             "own rate. Windows lists input and output as two devices, which linpar cannot pair "
                             "yet: use ASIO"),
    "Windows WDM-KS": (GOOD, "kernel streaming past the Windows mixer, but input and output are separate devices "
                             "on most cards: use ASIO"),
    "Windows DirectSound": (POOR, "goes through the Windows mixer, which resamples and may add effects"),
    "MME": (POOR, "the oldest Windows API: through the mixer, resampled, high latency"),
    "Core Audio": (BEST, "macOS's own: no resampling when the card runs at the measurement's rate (set it in Audio "
                         "MIDI Setup)"),
    "JACK Audio Connection Kit": (BEST, "one clock for every port at the server's rate, no resampling"),
    "ALSA": (BEST, "a hw: device is the card itself: no resampling, no mixing"),
    "OSS": (POOR, "an old Linux interface that may convert rates behind the program's back"),
}
ALSA_SERVER_DEVICE = (POOR, "an ALSA device of a sound server or plug-in (default, pulse, pipewire, dmix, "
                            "plughw): it resamples and mixes; choose the card's hw: device")
NOT_DUPLEX = (UNUSABLE, "linpar plays and records on one device, with one clock (under WASAPI, MME and "
                        "DirectSound Windows lists a card's inputs and outputs apart: take its ASIO driver)")
UNKNOWN = (POOR, "a host API linpar knows nothing about: check that it neither resamples nor mixes")
_ALSA_HW = re.compile(r"\((hw:\d+,\d+)\)\s*$")
MME_NAME_LIMIT = 31     # MME cuts device names to 31 characters


@dataclass(frozen=True, slots=True)
class Suitability:
    rank: int       # BEST, GOOD, POOR or UNUSABLE
    text: str       # in words, for the device list


def judge(device: AudioDeviceInfo) -> tuple[int, str]:
    """How well this device suits a measurement: (rank, why). NOT_DUPLEX for one that only plays or records."""
    if not device.full_duplex:
        return NOT_DUPLEX[0], f"{'inputs' if device.max_input_channels else 'outputs'} only: " + NOT_DUPLEX[1]
    if device.hostapi == "ALSA" and not _ALSA_HW.search(device.name):
        return ALSA_SERVER_DEVICE
    return HOST_APIS.get(device.hostapi, UNKNOWN)


def card_key(name: str) -> str:
    """What stays of a card's name under every host API (ALSA's "(hw:1,0)" and MME's cut-off removed)."""
    return _ALSA_HW.sub("", name).strip()[:MME_NAME_LIMIT].casefold()


def suitability(devices: list[AudioDeviceInfo]) -> list[Suitability]:
    """One Suitability per device, in the same order: where a card is listed under several host APIs, which of
    them to choose, and why."""
    by_card: dict[str, list[int]] = {}
    for i, device in enumerate(devices):
        by_card.setdefault(card_key(device.name), []).append(i)
    found = []
    for i, device in enumerate(devices):
        rank, why = judge(device)
        twins = [j for j in by_card[card_key(device.name)] if j != i]
        if not twins or rank == UNUSABLE:
            found.append(Suitability(rank, _word(rank) + why))
            continue
        best = min([i, *twins], key=lambda j: (judge(devices[j])[0], j))
        if best == i:
            apis = sorted({devices[j].hostapi for j in twins} - {device.hostapi})
            also = f" (also listed under {', '.join(apis)})" if apis else ""
            found.append(Suitability(rank, f"{_word(rank)}the best of this card's host APIs{also}: {why}"))
            continue
        best_rank, best_why = judge(devices[best])
        other = devices[best].hostapi
        if best_rank < rank:
            found.append(Suitability(rank, f"{_word(rank)}{why}. Better: this card under {other} ({best_why})"))
        else:
            found.append(Suitability(rank, f"{_word(rank)}{why} (as good: this card under {other})"))
    return found


def _word(rank: int) -> str:
    return {BEST: "suits measurement: ", GOOD: "usable: ", POOR: "avoid: ", UNUSABLE: "cannot be used: "}[rank]
