"""The program's exception for bad input, shared by every module that checks input."""

__all__ = ["InputError", "Interrupted"]


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
