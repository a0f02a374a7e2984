"""The measurement's base error, in a module of its own so that callers can name it without loading the runner."""
from __future__ import annotations


from analysis.errors import LinparError

class MeasurementError(LinparError, RuntimeError):
    """The measurement could not start (a device missing, a plan the devices cannot do); nothing was recorded."""

    def __init__(self, message: str):
        super().__init__(" ".join(str(message).splitlines()))
