"""Numeric options of `linpar`, checked where they enter against their bounds (analysis.bounds).

`number(bound)` is an argparse type: the text becomes a finite number in
the bound's range, or argparse's one-line error ("argument --sd: found
1e+160, expected an effective radiating area Sd: a number from 0.0001 to 1
m^2"). The bound says what the number is; no command repeats a range.
"""
from __future__ import annotations

import argparse
from typing import Callable

from analysis.bounds import Bound, BoundsError, parse_size_limit


def number(bound: Bound) -> Callable[[str], float | int]:
    def parse(text: str):
        try:
            return bound.parse(text, "")
        except BoundsError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    parse.__name__ = bound.what          # argparse names the type in a few of its own messages
    return parse


def size_limit(text: str) -> tuple[str, int]:
    try:
        return parse_size_limit(text)
    except BoundsError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--size-limit: ")) from None
