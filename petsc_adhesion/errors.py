"""The program's exception for bad input, shared by every module that checks input."""

__all__ = ["InputError"]


class InputError(Exception):
    """Bad user input: reported as one line naming the option, exit status 2, nothing written."""
