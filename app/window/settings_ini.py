"""The settings file read as Qt 6 reads an INI file (qsettings.cpp), to find what Qt would unpickle.

app.window.settings calls sanitized_ini before Qt reads the file: see its docstring
for why (PySide6 decodes "@Variant(...)" values through pickle).
"""
from __future__ import annotations

import codecs
from pathlib import Path

from analysis.files import write_atomic

# What Qt's QSettingsPrivate::stringToVariant may make of a value starting with "@"
# without a QDataStream: bytes, a string, geometry, nothing. "@@" is an escaped "@".
_SAFE_TAGS = ("@@", "@ByteArray(", "@String(", "@Rect(", "@Size(", "@Point(", "@Invalid()")
# Decoded through QDataStream >> QVariant, which reaches any registered type (pickle included).
_STREAMED_TAGS = ("@Variant(", "@DateTime(")


def replace_bytes(path: Path, data: bytes) -> None:
    write_atomic(path, data)        # a crash leaves the old file or the new, with the old one's mode


# -- reading an INI file the way Qt 6 does (qsettings.cpp), to look before Qt does --------------

def sanitized_ini(data: bytes) -> tuple[bytes, list[str]]:
    """`data` without the entries Qt would decode through QDataStream, and those entries' keys."""
    found = _unsafe_entries(data)
    if not found:
        return data, []
    kept, last = [], 0
    for _key, start, end in found:
        kept.append(data[last:start])
        last = end
    kept.append(data[last:])
    cleaned = b"".join(kept)
    if _unsafe_entries(cleaned):        # removing a whole logical line cannot expose another
        raise RuntimeError("settings: the settings file could not be cleaned")
    return cleaned, [key for key, _start, _end in found]


def _unsafe_entries(data: bytes) -> list[tuple[str, int, int]]:
    """(key, start, end) of every entry whose value Qt would not read as plain data."""
    offset = 3 if data.startswith(b"\xef\xbb\xbf") else 0
    section, found = "", []
    for start, end, equals in _ini_lines(data, offset):
        line = data[start:end]
        if line.startswith(b"["):
            close = line.find(b"]")
            name = line[1:close if close >= 0 else len(line)].strip()
            if name.lower() == b"general":
                section = ""
            elif name.lower() == b"%general":
                section = name[1:].decode("latin-1") + "/"
            else:
                section = _ini_key(name) + "/"
            continue
        if equals < 0:
            continue
        strings = _ini_strings(data[equals + 1:end])
        if any(_unsafe(s) for s in strings):
            found.append((section + _ini_key(data[start:equals].strip()), start, end))
    return found


def _unsafe(text: str) -> bool:
    # Conservative on purpose: a streamed tag anywhere, or an "@" tag other than the plain ones; leading
    # blanks and replacement characters are skipped, so that a slip in this port of Qt's decoding drops more.
    head = text.lstrip(" \t\r\n\f\v\ufffd")
    if any(tag in text for tag in _STREAMED_TAGS):
        return True
    return head.startswith("@") and not head.startswith(_SAFE_TAGS)


_SPACE = b" \t\r\n"


def _ini_lines(data: bytes, pos: int):
    """(start, end, index of the first unquoted '=' or -1) of each logical line: QConfFileSettingsPrivate::readIniLine."""
    n = len(data)
    while True:
        start = pos
        while start < n and data[start] in _SPACE:
            start += 1
        i, equals, quoted = start, -1, False
        while i < n:
            ch = data[i]
            i += 1
            if ch == 0x3D:                                  # =
                if not quoted and equals == -1:
                    equals = i - 1
            elif ch in (0x0A, 0x0D):
                if i == start + 1:
                    start += 1
                elif not quoted:
                    i -= 1
                    break
            elif ch == 0x5C:                                # backslash: the next byte is taken as is
                if i < n:
                    escaped = data[i]
                    i += 1
                    if i < n and {escaped, data[i]} == {0x0A, 0x0D}:
                        i += 1
            elif ch == 0x22:                                # "
                quoted = not quoted
            elif ch == 0x3B:                                # ; a comment at the start, else the line's end
                if i == start + 1:
                    while i < n and data[i] not in (0x0A, 0x0D):
                        i += 1
                    while i < n and data[i] in _SPACE:
                        i += 1
                    start = i
                elif not quoted:
                    i -= 1
                    break
        pos = i
        if i <= start:
            return
        yield start, i, equals


_ESCAPES = {ord(k): v for k, v in
            {"a": "\a", "b": "\b", "f": "\f", "n": "\n", "r": "\r", "t": "\t", "v": "\v",
             '"': '"', "?": "?", "'": "'", "\\": "\\"}.items()}
_HEX = b"0123456789abcdefABCDEF"
_OCT = b"01234567"


def _ini_strings(raw: bytes) -> list[str]:
    """The string, or each string of a list, in a raw INI value: QSettingsPrivate::iniUnescapedStringList."""
    decoder = codecs.getincrementaldecoder("utf-8")("replace")    # one per value, as Qt's QStringDecoder
    strings: list[str] = []
    current: list[str] = []
    in_quotes = False
    n, i = len(raw), 0

    def skip_blanks(i: int) -> int:
        while i < n and raw[i] in b" \t":
            i += 1
        return i

    i = skip_blanks(0)
    while i < n:
        ch = raw[i]
        if ch == 0x5C:                                      # backslash
            i += 1
            if i >= n:
                break
            code = raw[i]
            i += 1
            if code in _ESCAPES:
                current.append(_ESCAPES[code])
            elif code == ord("x"):
                if i < n and raw[i] in _HEX:
                    value = 0
                    while i < n and raw[i] in _HEX:        # Qt accumulates into a char16_t
                        value = (value * 16 + int(chr(raw[i]), 16)) & 0xFFFF
                        i += 1
                    current.append(chr(value))
            elif code in _OCT:
                value = code - 0x30
                while i < n and raw[i] in _OCT:
                    value = (value * 8 + raw[i] - 0x30) & 0xFFFF
                    i += 1
                current.append(chr(value))
            elif code in (0x0A, 0x0D) and i < n and raw[i] in (0x0A, 0x0D) and raw[i] != code:
                i += 1                                      # a continued line
        elif ch == 0x22:                                    # "
            i += 1
            in_quotes = not in_quotes
            if not in_quotes:
                i = skip_blanks(i)
        elif ch == 0x2C and not in_quotes:                  # , between the strings of a list
            strings.append("".join(current).rstrip(" \t"))
            current = []
            i = skip_blanks(i + 1)
        else:
            j = i + 1
            while j < n and raw[j] not in (0x5C, 0x22, 0x2C):
                j += 1
            current.append(decoder.decode(raw[i:j]))
            i = j
    strings.append("".join(current).rstrip(" \t"))
    return strings


def _ini_key(raw: bytes) -> str:
    r"""A key or section name as Qt reads it (QSettingsPrivate::iniUnescapedKey): '\' is '/', %XX and %UXXXX escapes."""
    text, out, i = raw.decode("utf-8", "replace"), [], 0
    while i < len(text):
        ch = text[i]
        if ch == "\\":
            out.append("/")
            i += 1
            continue
        digits = 4 if text[i + 1:i + 2] == "U" else 2
        first = i + (2 if digits == 4 else 1)
        code = text[first:first + digits]
        if ch == "%" and len(code) == digits and all(c in "0123456789abcdefABCDEF" for c in code):
            out.append(chr(int(code, 16)))
            i = first + digits
        else:
            out.append(ch)
            i += 1
    return "".join(out)
