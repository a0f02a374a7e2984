"""Files a user names, read safely: regular files only, within a size limit, each refusal one clear line.

A FIFO or a character device (/dev/zero) would block a read forever or feed
it without end; a folder cannot be read; a file far larger than any real
measurement would exhaust the memory. So every file linpar reads whole goes
through `regular_file` first, which says what the path is when it is not a
regular file, and refuses one above its kind's size limit
(analysis.bounds.SizeLimits, raised with `linpar --size-limit KIND=SIZE`).

`read_bytes` reads a small file; `mapped` memory-maps a large one (the WAV
samples), so that the file's bytes are not copied before they are decoded.
"""
from __future__ import annotations

import contextlib
import mmap
import os
import stat
import tempfile
from pathlib import Path
from typing import Iterator

from analysis.bounds import describe_size, size_limit
from analysis.errors import LinparError

# Below this a file is read into memory; above it, memory-mapped.
MAP_FROM_BYTES = 16 * 1024 * 1024
# What a file that grew while being read is read on in.
GROWTH_CHUNK = 1024 * 1024


def _what_it_is(mode: int) -> str | None:
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def regular_file(path: str | Path, kind: str, what: str, error: type[LinparError]) -> int:
    """The size of `path` when it is a regular file within the `kind`'s size limit; else `error` (one line).

    `what` says what was expected ("the sidecar of the recording"), `kind` is one of analysis.bounds.SIZE_KINDS.
    """
    path = Path(path)
    try:
        status = path.stat()
    except FileNotFoundError:
        raise error(f"{path}: missing, expected {what}") from None
    except OSError as exc:
        raise error(f"{path}: cannot be read ({exc.strerror or exc}), expected {what}") from None
    other = _what_it_is(status.st_mode)
    if other is not None:
        raise error(f"{path}: {other}, not a regular file: expected {what}")
    limit = size_limit(kind)
    if status.st_size > limit:
        raise error(f"{path}: {describe_size(status.st_size)}, above the limit of {describe_size(limit)} for "
                    f"{kind} files: expected {what}; if it is one, raise the limit with "
                    f"'linpar --size-limit {kind}=SIZE ...'")
    return status.st_size


def read_bytes(path: str | Path, kind: str, what: str, error: type[LinparError]) -> bytes:
    """The bytes of a regular file within its size limit (see regular_file)."""
    size = regular_file(path, kind, what, error)
    limit = size_limit(kind)
    try:
        with open(path, "rb") as f:
            # Ask for the file's size and one byte, not the limit: read(limit + 1) makes the OS reserve the
            # whole limit (2 GiB for a recording) for every small file, which Windows commits. A file that
            # grew since the check is read on in chunks, and refused past the limit.
            data = f.read(size + 1)
            while len(data) > size and len(data) <= limit:
                more = f.read(min(GROWTH_CHUNK, limit + 1 - len(data)))
                if not more:
                    break
                data += more
    except OSError as exc:
        raise error(f"{path}: cannot be read ({exc.strerror or exc}), expected {what}") from None
    if len(data) > limit:
        raise error(f"{path}: grew beyond the limit of {describe_size(size_limit(kind))} while being read")
    return data


def read_text(path: str | Path, kind: str, what: str, error: type[LinparError]) -> str:
    """A regular UTF-8 text file within its size limit (a BOM is allowed); `error` for anything else."""
    data = read_bytes(path, kind, what, error)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not UTF-8 text (byte {exc.start}), expected {what}") from None


@contextlib.contextmanager
def mapped(path: str | Path, kind: str, what: str, error: type[LinparError]) -> Iterator[bytes | mmap.mmap]:
    """The file's bytes for the duration of the block: memory-mapped when large, read when small.

    Whatever the block makes of them must be copied out before it ends (numpy views of the map are not).
    """
    size = regular_file(path, kind, what, error)
    if size < MAP_FROM_BYTES:
        yield read_bytes(path, kind, what, error)
        return
    try:
        with open(path, "rb") as f:
            view = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)      # the map outlives the descriptor
    except (OSError, ValueError) as exc:       # ValueError: the file shrank to nothing meanwhile
        raise error(f"{path}: cannot be read ({getattr(exc, 'strerror', None) or exc}), expected {what}") from None
    try:
        yield view
    finally:
        try:
            view.close()
        except BufferError:     # a view of it still lives (an exception's frame): unmapped when that goes
            pass


class OutputError(LinparError, OSError):
    """An output that would replace something that is not a regular file (a FIFO, a device, a folder)."""


def check_output(path: str | Path) -> None:
    """OutputError unless writing `path` (by renaming a new file onto it) replaces at most a regular file.

    An atomic write renames its temporary file over the target: onto /dev/null or a FIFO that would put a
    regular file in place of the device or the pipe. A symlink to a regular file is replaced by the file.
    """
    path = Path(path)
    if not os.path.lexists(path):
        return
    try:
        mode = os.stat(path).st_mode
    except OSError as exc:         # a dangling or looping link
        raise OutputError(f"{path}: cannot be written ({exc.strerror or exc}): choose another name") from None
    other = _what_it_is(mode)
    if other is not None:
        raise OutputError(f"{path}: {other}, not a regular file: an output replaces only a regular file; "
                          f"choose another name")


def check_outputs_spare_inputs(outputs, inputs) -> None:
    """OutputError when an output (option, path) is one of the command's inputs or an earlier output: the same
    path after links (realpath, not resolve(): a symlink loop is a bad input, not a RuntimeError) or the same
    file by another name (a hard link)."""
    seen: list[Path] = []
    for option, path in outputs:
        path = Path(path)
        for other in [*inputs, *seen]:
            if os.path.realpath(path) == os.path.realpath(other) or _same_file(path, other):
                raise OutputError(f"{option} {path}: that file is an input of this command (or another output): "
                                  f"choose another name, nothing was written")
        seen.append(path)


def _same_file(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:         # one of them does not exist (yet), or cannot be reached
        return False


def is_regular(path: str | Path) -> bool:
    """True for an existing regular file (after symlinks), without reading it."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except OSError:
        return False


# Read once (os.umask can only be read by setting it): new files get the
# mode an ordinary open() would give them, not mkstemp's private 0600.
_UMASK = os.umask(0o022)
os.umask(_UMASK)
FILE_MODE = 0o666 & ~_UMASK
DIR_MODE = 0o777 & ~_UMASK


def write_atomic(path: str | Path, payload: bytes | str) -> Path:
    """Write to a temporary file in the same folder, flush it to disk, then rename it over `path`: a reader sees
    the old file or the new one, never half of one. The only atomic write (recordings, the archive, reports,
    exports, the rig's state, the laser stream, the settings); never over a FIFO, a device or a folder."""
    path = Path(path)
    check_output(path)          # a FIFO or a device is never replaced by a file
    data = payload.encode("utf-8") if isinstance(payload, str) else payload
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        try:
            os.chmod(tmp, path.stat().st_mode & 0o7777 if path.exists() else FILE_MODE)
        except OSError:
            pass
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
