"""The benchmarks' command lines refuse bad input as the program does: one line, exit 2.

argparse prints its usage and then the message, over several lines; the benchmarks that build the tables
(benchmarks/family.py, benchmarks/pull_off.py) are run by scripts and by tests that read their one line.
"""
from __future__ import annotations

import argparse
import functools
import sys

from ..errors import say

__all__ = ["OneLineParser"]


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose refusal is ``petsc-adhesion: LABEL: message``, one line, and exit status 2; its
    subcommands' parsers are of this class with the same ``label`` (argparse makes them of the parent's class, but
    without the label)."""

    def __init__(self, *args, label: str, **kwargs):
        super().__init__(*args, **kwargs)
        self.label = label

    def add_subparsers(self, **kwargs):
        kwargs.setdefault("parser_class", functools.partial(OneLineParser, label=self.label))
        return super().add_subparsers(**kwargs)

    def error(self, message: str):
        say(f"{self.label}: {message}")
        sys.exit(2)
