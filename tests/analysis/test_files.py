"""analysis.files: what is read is a regular file within its size limit; large WAVs are memory-mapped.

The issue's finding 5: a 3 GB WAV with a valid header was read whole (3.2 GB of memory, a MemoryError
traceback under a memory limit). Now it is refused before a byte of it is read, unless the limit is raised.
"""
from __future__ import annotations

import os
import re
import struct

import numpy as np
import pytest

import analysis.files as files
from analysis.bounds import GiB, size_limits_set
from analysis.recording.format import RecordingError, read_recording, write_recording
from tests.builders import TYPICAL_NOISE, multitone, recording


@pytest.fixture(scope="module")
def rec(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "rec"
    write_recording(path, recording(noise=TYPICAL_NOISE, n_periods=3, seed=9,
                                    mt=multitone(period_samples=4096, f_min=20.0)))
    return path


def test_a_3_gb_wav_is_refused_before_it_is_read(rec, tmp_path, monkeypatch):
    big = tmp_path / "big"
    (tmp_path / "big.json").write_bytes(rec.with_name("rec.json").read_bytes())
    header = bytearray(rec.with_name("rec.wav").read_bytes()[:64])
    size = 3 * GiB
    with open(tmp_path / "big.wav", "wb") as f:        # sparse: no disk is used for the zeros
        f.write(header)
        f.truncate(size)
    reads = []
    monkeypatch.setattr(files, "mapped", lambda *a, **k: reads.append(a) or pytest.fail("the WAV was read"))
    with pytest.raises(RecordingError) as err:
        read_recording(big)
    message = str(err.value)
    assert "big.wav: 3 GB, above the limit of 2 GB for wav files" in message
    assert "linpar --size-limit wav=SIZE" in message and reads == []


def test_the_size_limit_is_raised_for_a_command(rec, tmp_path):
    with size_limits_set(wav=100):
        with pytest.raises(RecordingError, match="above the limit of 100 bytes"):
            read_recording(rec)
    assert read_recording(rec).n_periods == 3


def test_a_large_wav_is_memory_mapped_and_decodes_as_when_read(rec, monkeypatch):
    read = read_recording(rec)
    monkeypatch.setattr(files, "MAP_FROM_BYTES", 0)       # map even this small file
    mapped = read_recording(rec)
    assert np.array_equal(read.data, mapped.data) and not mapped.data.flags.writeable


@pytest.mark.parametrize("bits", [16, 24, 32])
def test_integer_pcm_decodes_channel_by_channel(tmp_path, bits):
    from analysis.recording.wav import decode_wav
    ints = np.array([[0, 1, -1, 2**(bits - 1) - 1, -2**(bits - 1)], [5, -5, 7, -7, 0], [1, 2, 3, 4, 5]])
    width = bits // 8
    frames = b"".join(int(v).to_bytes(width, "little", signed=True) for v in ints.T.reshape(-1))
    fmt = struct.pack("<HHIIHH", 1, 3, 8000, 8000 * 3 * width, 3 * width, bits)
    body = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"data" + struct.pack("<I", len(frames)) + frames
    wav = decode_wav(b"RIFF" + struct.pack("<I", len(body)) + body)
    assert np.array_equal(wav.samples, ints / 2.0 ** (bits - 1))


@pytest.mark.parametrize("kind, words", [("fifo", "a FIFO (named pipe)"), ("folder", "a folder"),
                                         ("device", "a device"), ("missing", "missing")])
def test_what_is_not_a_regular_file_is_named(tmp_path, kind, words):
    path = tmp_path / "x.json"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        path.mkdir()
    elif kind == "device":
        path.symlink_to("/dev/zero")
    with pytest.raises(RecordingError, match=re.escape(words)):
        files.read_bytes(path, "sidecar", "a sidecar", RecordingError)


def test_reading_a_small_file_asks_for_no_more_memory_than_its_size(tmp_path):
    """Issue 31, class 6: read(limit + 1) made the OS reserve the kind's whole limit (2 GiB for a recording's
    sidecar) for every small file; traced, the bench's analysis peaked at 80x its samples."""
    import tracemalloc
    path = tmp_path / "small.json"
    path.write_bytes(b"{}" * 500)
    tracemalloc.start()
    data = files.read_bytes(path, "sidecar", "a sidecar", RecordingError)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert data == b"{}" * 500
    assert peak < 64 * 1024, peak
