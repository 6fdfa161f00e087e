"""The program's exceptions for bad input and for signals, and its one-line messages."""
import sys

__all__ = ["InputError", "Interrupted", "say"]


def say(text: str, stream=None) -> None:
    """``petsc-adhesion: TEXT`` as one line on ``stream`` (stderr), text and newline in one write.

    ``print`` writes them apart, and a SIGTERM between the two (its handler raises
    :class:`Interrupted` from inside the write) left a progress line without its
    newline, so the run's last line, which names the checkpoint, was joined to it.
    """
    stream = stream or sys.stderr
    stream.write(f"petsc-adhesion: {text}\n")
    stream.flush()


class InputError(Exception):
    """Bad user input: reported as one line naming the option, exit status 2, nothing written."""


class Interrupted(BaseException):
    """SIGINT or SIGTERM: end cleanly, with the signal's exit status (not an Exception: nothing may catch it
    on the way but the command line)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum
        self.restart = None          # the checkpoint to go on from (-cont_restart), once one is saved
        self.done = None             # the run's exit status when the signal came after its results were written
