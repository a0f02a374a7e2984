"""The error of an effect of the user's own that cannot be used (a file, a package's entry point).

A module of its own so that the registry can raise and catch it without loading the effect files' reader
(analysis.effects.user: tomllib and the formula parser), which a command needs only when there are files.
"""
from __future__ import annotations

from analysis.errors import LinparError


class EffectFileError(LinparError, ValueError):
    """An effect file (or an effect from a package) that cannot be used. One line: the file, the key, what was expected.

    A LinparError (analysis.errors), so that the CLI's boundary says it as one line with exit 2; still a
    ValueError, as it was before that error model, for code that catches that.
    """
