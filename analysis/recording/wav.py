"""RIFF/WAVE bytes <-> sample arrays, for the recording format (NAME.wav).

Accepted, as the spec says: 32-bit IEEE float and 16-, 24- and 32-bit integer
PCM, plain or WAVE_FORMAT_EXTENSIBLE. Integer samples come out as fractions of
full scale (int16 / 2**15, int24 / 2**23, int32 / 2**31), floats as they are.

Why not scipy.io.wavfile: a truncated file has to be refused, and scipy only
warns and returns fewer samples; so the chunks are walked and their sizes
checked here anyway. Once the chunks are found, decoding is one numpy view per
format, and one parser cannot disagree with a second one about the same bytes.

Errors are WavFormatError without a file name: the caller knows the file.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from analysis.errors import LinparError

FORMAT_PCM = 0x0001
FORMAT_IEEE_FLOAT = 0x0003
FORMAT_EXTENSIBLE = 0xFFFE
# The 12 bytes that follow the format code in a KSDATAFORMAT_SUBTYPE_* GUID.
_SUBTYPE_GUID_TAIL = bytes.fromhex("000010008000 00aa00389b71".replace(" ", ""))
# Only for messages: what a refused file holds.
_FORMAT_NAMES = {
    FORMAT_PCM: "integer PCM", 0x0002: "Microsoft ADPCM", FORMAT_IEEE_FLOAT: "IEEE float",
    0x0006: "A-law", 0x0007: "mu-law", 0x0011: "IMA ADPCM", 0x0055: "MPEG layer 3",
}
ACCEPTED_FORMATS = "32-bit IEEE float or 16-, 24- or 32-bit integer PCM"
# (format, bits) -> (numpy dtype of one sample after widening, full scale)
_DECODERS = {
    (FORMAT_PCM, 16): ("<i2", 2.0**15),
    (FORMAT_PCM, 24): ("<i4", 2.0**31),   # widened to int32 with the 24 bits on top
    (FORMAT_PCM, 32): ("<i4", 2.0**31),
    (FORMAT_IEEE_FLOAT, 32): ("<f4", 1.0),
}
_U32_MAX = 2**32 - 1


class WavFormatError(LinparError, ValueError):
    """Bytes that are not a WAV file the recording format accepts."""


@dataclass(frozen=True, slots=True)
class WavSamples:
    """What a WAV file holds, before any sidecar scale is applied."""

    sample_rate: int
    samples: np.ndarray     # (n_channels, n_frames) float64, fractions of full scale for PCM
    encoding: str           # e.g. "24-bit integer PCM", for messages and reports


def decode_wav(blob: bytes) -> WavSamples:
    """Decode a whole WAV file held in memory; refuse anything truncated or unsupported."""
    chunks = _find_chunks(blob)
    for required in (b"fmt ", b"data"):
        if required not in chunks:
            raise WavFormatError(f"no {required.decode().strip()!r} chunk, expected a 'fmt ' and a 'data' chunk")
    fmt_start, fmt_end = chunks[b"fmt "]
    fmt_code, n_channels, sample_rate, bits = _read_fmt(blob[fmt_start:fmt_end])
    dtype, full_scale = _DECODERS[(fmt_code, bits)]
    frame_bytes = n_channels * bits // 8

    data_start, data_end = chunks[b"data"]
    size = data_end - data_start
    if size % frame_bytes:
        raise WavFormatError(f"data chunk: {size} bytes is not a whole number of {frame_bytes}-byte frames "
                             f"({n_channels} channels x {bits} bits), expected whole frames")
    frames = np.frombuffer(blob, dtype=np.uint8, count=size, offset=data_start).reshape(-1, frame_bytes)
    # Channel by channel straight into the result: a long file (memory-mapped by the reader) is never held
    # twice, and no view of `blob` outlives this function.
    samples = np.empty((n_channels, frames.shape[0]), dtype=np.float64)
    width = bits // 8
    for c in range(n_channels):
        column = frames[:, c * width:(c + 1) * width]
        if bits == 24:
            # Put the 3 bytes on top of an int32 so that the sign comes for free.
            wide = np.zeros((column.shape[0], 4), dtype=np.uint8)
            wide[:, 1:] = column
            values = wide.view(dtype)[:, 0]
        else:
            values = np.ascontiguousarray(column).view(dtype)[:, 0]
        np.divide(values, full_scale, out=samples[c])
    del frames
    return WavSamples(sample_rate, samples, describe_format(fmt_code, bits))


def encode_float32_wav(sample_rate: int, samples: np.ndarray) -> bytes:
    """A 32-bit IEEE float WAV file of `samples`, shape (n_channels, n_frames)."""
    n_channels, n_frames = samples.shape
    frame_bytes = 4 * n_channels
    frames = np.ascontiguousarray(samples.T, dtype="<f4").tobytes()
    if not (0 < n_channels < 2**16 and 0 < sample_rate and sample_rate * frame_bytes <= _U32_MAX
            and len(frames) + 64 <= _U32_MAX):
        raise WavFormatError(f"{n_channels} channels, {n_frames} frames at {sample_rate} Hz do not fit a WAV file, "
                             f"expected 1..65535 channels and less than 4 GiB of samples")
    fmt = struct.pack("<HHIIHHH", FORMAT_IEEE_FLOAT, n_channels, sample_rate,
                      sample_rate * frame_bytes, frame_bytes, 32, 0)
    # A non-PCM format must carry a 'fact' chunk with the number of frames.
    body = (b"WAVE" + _chunk(b"fmt ", fmt) + _chunk(b"fact", struct.pack("<I", n_frames))
            + _chunk(b"data", frames))
    return b"RIFF" + struct.pack("<I", len(body)) + body


def describe_format(fmt_code: int, bits: int) -> str:
    return f"{bits}-bit {_FORMAT_NAMES.get(fmt_code, f'format 0x{fmt_code:04x}')}"


def _chunk(chunk_id: bytes, payload: bytes) -> bytes:
    pad = b"\0" if len(payload) % 2 else b""
    return chunk_id + struct.pack("<I", len(payload)) + payload + pad


def _find_chunks(blob: bytes) -> dict[bytes, tuple[int, int]]:
    """Start and end offset of the payload of each top-level chunk, sizes checked."""
    if len(blob) < 12 or blob[:4] != b"RIFF" or blob[8:12] != b"WAVE":
        raise WavFormatError(f"starts with {bytes(blob[:12])!r}, expected a RIFF/WAVE header ('RIFF', size, 'WAVE')")
    riff_end = 8 + struct.unpack_from("<I", blob, 4)[0]
    limit = min(riff_end, len(blob))
    chunks: dict[bytes, tuple[int, int]] = {}
    offset = 12
    while offset + 8 <= limit:
        chunk_id, size = struct.unpack_from("<4sI", blob, offset)
        start, end = offset + 8, offset + 8 + size
        name = repr(chunk_id.decode("latin-1"))
        if end > len(blob):
            raise WavFormatError(f"{name} chunk: header says {size} bytes but the file ends after "
                                 f"{len(blob) - start}, expected the whole chunk (the file is truncated)")
        if end > riff_end:
            raise WavFormatError(f"{name} chunk: {size} bytes run past the end of the RIFF chunk "
                                 f"({riff_end} bytes), expected chunks inside the RIFF size")
        if chunk_id in (b"fmt ", b"data") and chunk_id in chunks:
            raise WavFormatError(f"{name} chunk: found a second one, expected exactly one")
        chunks[chunk_id] = (start, end)
        offset = end + (size & 1)   # chunks are word aligned
    if riff_end > len(blob):
        raise WavFormatError(f"RIFF header: says {riff_end} bytes but the file has {len(blob)}, "
                             f"expected the whole file (the file is truncated)")
    return chunks


def _read_fmt(fmt: bytes) -> tuple[int, int, int, int]:
    """(format code, channels, sample rate, bits per sample) of an accepted 'fmt ' chunk."""
    if len(fmt) < 16:
        raise WavFormatError(f"'fmt ' chunk: {len(fmt)} bytes, expected at least 16")
    fmt_code, n_channels, sample_rate, _, block_align, bits = struct.unpack_from("<HHIIHH", fmt)
    if fmt_code == FORMAT_EXTENSIBLE:
        if len(fmt) < 40:
            raise WavFormatError(f"'fmt ' chunk: WAVE_FORMAT_EXTENSIBLE in {len(fmt)} bytes, expected 40")
        sub_format = fmt[24:40]
        if sub_format[4:] != _SUBTYPE_GUID_TAIL:
            raise WavFormatError(f"'fmt ' chunk: extensible sub-format GUID {sub_format.hex()}, "
                                 f"expected PCM or IEEE float")
        fmt_code = struct.unpack_from("<I", sub_format)[0]
    if (fmt_code, bits) not in _DECODERS:
        raise WavFormatError(f"'fmt ' chunk: sample format {describe_format(fmt_code, bits)}, "
                             f"expected {ACCEPTED_FORMATS}")
    if n_channels == 0:
        raise WavFormatError("'fmt ' chunk: 0 channels, expected at least 1")
    if sample_rate == 0:
        raise WavFormatError("'fmt ' chunk: sample rate 0 Hz, expected a positive sample rate")
    if block_align != n_channels * bits // 8:
        raise WavFormatError(f"'fmt ' chunk: block align {block_align} bytes, expected "
                             f"{n_channels * bits // 8} ({n_channels} channels x {bits} bits)")
    return fmt_code, n_channels, sample_rate, bits
