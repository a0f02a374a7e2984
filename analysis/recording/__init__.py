"""Recordings: the raw signals of one multitone measurement, and their files (NAME.wav + NAME.json).

The public names of analysis.recording.format (Recording, read_recording, write_recording,
make_recording, ...) are importable from the package itself; each is loaded on first use.
"""
from __future__ import annotations

from analysis.lazy_exports import lazy_exports

# Where each public name lives; a name is imported on first use only, so that
# importing one submodule of the package does not load the rest.
_HOME = {
    "FORMAT": "format",
    "IN_MEMORY": "format",
    "MIN_PERIODS": "format",
    "REQUIRED_SIGNALS": "format",
    "UNITS": "format",
    "Channel": "format",
    "Recording": "format",
    "RecordingError": "format",
    "make_recording": "format",
    "read_recording": "format",
    "recording_paths": "format",
    "write_recording": "format",
}

__all__ = sorted(_HOME)

__getattr__, __dir__ = lazy_exports(__name__, _HOME)
