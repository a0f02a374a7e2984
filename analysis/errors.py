"""The one error model: LinparError is the base of everything a user can cause.

A file that breaks its format, an option out of range, a device that does
not answer, an entry in the GUI that cannot be used: each module raises its
own subclass (RecordingError, LimitsError, ArchiveError, AudioError, ...)
with ONE line that says what was wrong and what to do. They are caught at
exactly two boundaries:

- `linpar`'s main (app.cli): "linpar: error: <message>", exit 2;
- the GUI's job runner (app.jobs.book.failure_text): the message on the page.

Anything else that escapes is a bug, not bad input: exit 70 and one line
"internal error: ... (details in FILE)", with a crash report written by
app.crash_report (click's ClickException / unexpected-exception split).

A subclass may also derive from the builtin it used to be (ValueError,
RuntimeError, OSError), so that code which catches that keeps working; the
boundaries catch LinparError, never a bare ValueError or KeyError.

Besides LinparError, two builtins count as the user's, not as bugs: an
OSError (a file or device the user named is missing, unreadable, full) and
a MemoryError (an input too large for this machine). `is_user_error` is the
one place that says so.

Analysis is the bottom layer, so this module lives here: instruments and
app import it.
"""
from __future__ import annotations


class LinparError(Exception):
    """An error the user can cause and fix; str(err) is the message shown to them."""


def is_user_error(exc: BaseException) -> bool:
    """True for what the boundaries report as the user's problem (exit 2); False for a bug (exit 70)."""
    return isinstance(exc, (LinparError, OSError, MemoryError))


def user_message(exc: BaseException) -> str:
    """The one line a user reads for a user error (see is_user_error)."""
    if isinstance(exc, MemoryError):
        text = ("not enough memory for this input: close other programs, or check that the file is a real "
                "measurement (--size-limit says how large a file may be)")
    elif isinstance(exc, OSError) and not isinstance(exc, LinparError) and exc.strerror:
        # "[Errno 2] No such file or directory: 'x'" -> "x: No such file or directory"
        names = [str(n) for n in (exc.filename, exc.filename2) if n is not None]
        text = f"{' -> '.join(names)}: {exc.strerror}" if names else exc.strerror
    else:
        text = str(exc)
    return one_line(text) or type(exc).__name__


def one_line(text: object) -> str:
    """Whitespace (line breaks too) collapsed to single spaces: a message is one line whatever it quotes."""
    return " ".join(str(text).split())
