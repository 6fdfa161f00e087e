"""The program's exceptions for bad input and for signals, and its one-line messages.

Every module may import this one; it imports nothing of the package.  :func:`collective` makes a
check's refusal every rank's, so that no rank is left waiting in a collective call.
"""
import os
import sys

__all__ = ["InputError", "Interrupted", "interrupted_in", "say", "first_line", "printable", "collective", "tell"]


def say(text: str, stream=None) -> None:
    """``petsc-adhesion: TEXT`` as one line on ``stream`` (stderr), text and newline in one write.

    ``print`` writes them apart, and a SIGTERM between the two (its handler raises
    :class:`Interrupted` from inside the write) left a progress line without its
    newline, so the run's last line, which names the checkpoint, was joined to it.
    """
    stream = stream or sys.stderr
    stream.write(f"petsc-adhesion: {text}\n")
    stream.flush()


def first_line(e: BaseException) -> str:
    """The first line of an exception's message, or its type's name when it has none."""
    text = str(e).strip()
    return text.splitlines()[0] if text else type(e).__name__


def tell(text: str, stream=None) -> None:
    """``text`` and a newline on ``stream`` (stdout), flushed at once.

    A reader that went away (``petsc-adhesion ... | head -1``: a broken pipe) loses the rest,
    which is no error: later output goes to the null device, and the run ends with its own
    status.  Any other failure (a full device) raises OSError naming standard output: the report
    was the output asked for.
    """
    stream = stream or sys.stdout
    try:
        stream.write(text + "\n")
        stream.flush()
    except BrokenPipeError:
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())
        except (OSError, ValueError):
            pass
    except OSError as e:
        raise OSError(e.errno, e.strerror, "standard output") from None


class InputError(Exception):
    """Bad user input: reported as one line naming the option, exit status 2, nothing written."""


class Interrupted(BaseException):
    """SIGINT or SIGTERM: end cleanly, with the signal's exit status (not an Exception: nothing may catch it
    on the way but the command line)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum
        self.restart: str | None = None   # the checkpoint to go on from (-cont_restart), once one is saved
        self.done: int | None = None      # the run's exit status when the signal came after its results were written

    def resumable(self, path: str) -> None:
        """Name the checkpoint saved before the signal, the one to go on from (-cont_restart)."""
        self.restart = path


def interrupted_in(exc: BaseException) -> Interrupted | None:
    """The :class:`Interrupted` that ``exc`` is, or that it was raised from or while handling; None if none.

    A signal's exception can reach a handler inside another: Python 3.11 raises RuntimeError("Error calling
    __set_name__ ...") from any exception raised while a class is made, and a signal that comes during an
    import is one (a SIGTERM while matplotlib was imported for a result's figure ended a run with that line
    and status 1, not 143: found by tests/test_kill.py)."""
    seen: set[int] = set()
    at: BaseException | None = exc
    while at is not None and id(at) not in seen:
        if isinstance(at, Interrupted):
            return at
        seen.add(id(at))
        at = at.__cause__ or at.__context__
    return None


def printable(text) -> str:
    """``text`` (str or bytes) with control characters and undecodable bytes escaped, for one line."""
    if isinstance(text, bytes):
        text = text.decode("utf-8", errors="backslashreplace")
    text = text.encode("utf-8", errors="surrogateescape").decode("utf-8", errors="backslashreplace")
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def collective(comm, check, *args):
    """Run ``check(*args)`` on every rank; an InputError on any rank is raised on all (rank order).

    Keeps a check that fails on one rank only (a file part, a path) from
    leaving the others waiting in a collective call.
    """
    try:
        out, why = check(*args), None
    except InputError as e:
        out, why = None, str(e)
    whys = comm.tompi4py().allgather(why)
    first = next((w for w in whys if w), None)
    if first:
        raise InputError(first)
    return out
