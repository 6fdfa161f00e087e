"""All or nothing: the result files of one run appear together, or the earlier set stays.

Each output is written to a temporary beside its target, ``.NAME.partial-HOST-PID``,
created with the umask's mode.  When every output of the run is complete, a
journal ``.NAME.commit`` (next to the first output) lists the renames; then, with
SIGINT, SIGTERM and SIGHUP held, each earlier file is moved aside to
``.NAME.previous-HOST-PID`` and each temporary renamed into place.  If any of
these renames fails (a file that may not be replaced, such as an immutable one),
the ones done are undone, the earlier set is back, the journal goes and the
run fails with one line: never a mixed set.  Once all are in place the earlier
files, the journal and what the set replaces (the run's checkpoint) are removed.
A run that fails or is killed before the journal leaves the earlier set
untouched; one killed (kill -9) within the microseconds of the renames leaves
its journal, and the next run that writes any of those names completes them
first (roll forward).  Temporaries of dead runs on this host are removed then
too, so they do not accumulate.

Targets are checked before any work (:func:`check_targets`): regular files or
new names only (no device, FIFO, directory or symbolic link), in a writable
directory, distinct from each other and from the run's input files.
"""
from __future__ import annotations

import glob
import json
import os
import signal
import socket
import stat
from contextlib import contextmanager

from ..errors import InputError, Interrupted, interrupted_in, printable, say

__all__ = ["check_targets", "ResultSet", "written", "mark_done", "said_after", "atomic_write", "PLOT_FORMATS", "plot_format",
           "JOURNAL"]

#: Figure formats by file extension.
PLOT_FORMATS = {".png": "png", ".pdf": "pdf", ".svg": "svg"}


def plot_format(path: str) -> str | None:
    """The figure format a file name ends in (``-plot .png`` too: a hidden file named by its format), or None.

    >>> plot_format("a/b.PDF"), plot_format(".png"), plot_format("fig.jpg")
    ('pdf', 'png', None)
    """
    return next((fmt for ext, fmt in PLOT_FORMATS.items() if path.lower().endswith(ext)), None)
#: What a journal of ours says it is (a file of that name that does not is left alone).
JOURNAL = "petsc-adhesion journal"


def _kind(mode: int) -> str:
    return {stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device", stat.S_IFIFO: "a FIFO",
            stat.S_IFSOCK: "a socket", stat.S_IFDIR: "a directory"}.get(stat.S_IFMT(mode), "not a regular file")


def _same(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def check_targets(targets: dict, inputs: dict | None = None) -> None:
    """Refuse, in one line naming the option, output paths that must not be written.

    ``targets``: option -> path of each output of the run; ``inputs``: option ->
    list of paths the run reads (options files, guesses).  Tries creating a
    temporary beside each target.
    """
    seen: dict[str, str] = {}
    for option, path in targets.items():
        name = printable(path)
        try:
            path.encode("utf-8")
        except UnicodeEncodeError:
            raise InputError(f"-{option}: the file name '{name}' is not valid UTF-8") from None
        if path.endswith(os.sep):
            raise InputError(f"-{option}: '{name}' names a directory; give a file name")
        base = os.path.basename(path)
        if base.startswith(".") and (base.endswith(".commit") or ".partial-" in base):
            raise InputError(f"-{option}: '{name}' is the name of a temporary or journal of result files")
        if os.path.islink(path):
            raise InputError(f"-{option}: '{name}' is a symbolic link; give the file itself")
        if os.path.exists(path):
            mode = os.stat(path).st_mode
            if not stat.S_ISREG(mode):
                raise InputError(f"-{option}: '{name}' is {_kind(mode)}; give a regular file name")
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):
            raise InputError(f"-{option}: cannot write '{name}' (no directory '{printable(folder)}')")
        for other, where in seen.items():
            if _same(path, where):
                raise InputError(f"-{option}: '{name}' is also the file of -{other}")
        for source, paths in (inputs or {}).items():
            if any(p and os.path.exists(p) and _same(path, p) for p in paths):
                raise InputError(f"-{option}: '{name}' is an input of this run (-{source})")
        try:
            with atomic_write(path, keep=False):
                pass
        except OSError as e:
            raise InputError(f"-{option}: cannot write '{name}' ({e.strerror})") from None
        seen[option] = path


def _temp_name(path: str) -> str:
    folder, base = os.path.split(os.path.abspath(path))
    return os.path.join(folder, f".{base}.partial-{socket.gethostname()}-{os.getpid()}")


def _create(path: str) -> None:
    """An empty file at path, with the umask's mode (0666 & ~umask), not replacing one."""
    os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))


@contextmanager
def atomic_write(path: str, keep: bool = True):
    """Yield a temporary path beside ``path``; rename it into place on success (``keep``)."""
    tmp = _temp_name(path)
    _create(tmp)
    try:
        yield tmp
        if keep:
            os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _journal(path: str) -> str:
    folder, base = os.path.split(os.path.abspath(path))
    return os.path.join(folder, f".{base}.commit")


def _previous_name(path: str) -> str:
    folder, base = os.path.split(os.path.abspath(path))
    return os.path.join(folder, f".{base}.previous-{socket.gethostname()}-{os.getpid()}")


def _read_journal(path: str) -> list | None:
    """The renames a journal of ours lists, or None for any other file (left alone)."""
    try:
        with open(path) as f:
            data = json.load(f)
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if isinstance(data, dict) and data.get("program") == JOURNAL and isinstance(data.get("renames"), list) \
            and all(isinstance(x, list) and len(x) == 2 and all(isinstance(y, str) for y in x)
                    for x in data["renames"]):
        return data["renames"]
    return None


@contextmanager
def _signals_held():
    held = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class ResultSet:
    """The output files of one run, written as temporaries and committed together.

    >>> rs = ResultSet({"out": "r.h5", "summary": "r.json"})   # doctest: +SKIP
    >>> write_h5(rs.temp("out"), ...); write_json(rs.temp("summary"), ...)  # doctest: +SKIP
    >>> rs.commit()                                             # doctest: +SKIP
    """

    def __init__(self, targets: dict, drop=()):
        self.targets = {k: v for k, v in targets.items() if v}
        self.drop = [p for p in drop if p]         # what the set replaces: gone once it is in place
        self.temps: dict[str, str] = {}
        self.committed = False
        self.recover()

    def recover(self) -> None:
        """Finish the renames of a run killed while committing any of these names; remove dead runs' temporaries.

        A journal lies beside each folder's first output of its set and lists all
        of them, so it is found from any name of the set.
        """
        for folder in {os.path.dirname(os.path.abspath(p)) for p in self.targets.values()}:
            mine = {os.path.abspath(p) for p in self.targets.values()}
            for journal in glob.glob(os.path.join(glob.escape(folder), ".*.commit")):
                renames = _read_journal(journal)
                if renames is None or not mine & {final for _, final in renames}:
                    continue
                for tmp, final in renames:
                    if os.path.exists(tmp):
                        os.replace(tmp, final)
                for _, final in renames:             # the earlier files the dead run moved aside
                    folder_, base = os.path.split(final)
                    for old in glob.glob(os.path.join(glob.escape(folder_), f".{glob.escape(base)}.previous-*")):
                        os.remove(old)
                for other in {_journal(final) for _, final in renames}:
                    if os.path.exists(other) and _read_journal(other) is not None:
                        os.remove(other)
        host = socket.gethostname()
        # the outputs' temporaries, and those of a journal killed while it was being written
        for path in [p for t in self.targets.values() for p in (t, _journal(os.path.abspath(t)))]:
            folder, base = os.path.split(os.path.abspath(path))
            for tmp in glob.glob(os.path.join(glob.escape(folder), f".{glob.escape(base)}.partial-*")):
                owner = tmp.rsplit(".partial-", 1)[1]
                where, _, pid = owner.rpartition("-")
                if where == host and pid.isdigit() and not _alive(int(pid)):
                    os.remove(tmp)

    def temp(self, option: str) -> str:
        """The temporary file to write the output of ``option`` into."""
        if option not in self.temps:
            self.temps[option] = _temp_name(self.targets[option])
            _create(self.temps[option])
        return self.temps[option]

    def commit(self) -> None:
        """Rename every written temporary into place, together (see the module's docstring)."""
        renames = [(self.temps[k], os.path.abspath(self.targets[k])) for k in self.targets if k in self.temps]
        journals: dict[str, str] = {}                              # one beside the first output of each folder
        for _, final in renames:
            journals.setdefault(os.path.dirname(final), _journal(final))
        for journal in journals.values():
            with atomic_write(journal) as tmp:
                with open(tmp, "w") as f:
                    json.dump({"program": JOURNAL, "renames": renames}, f)
                    f.flush()
                    os.fsync(f.fileno())
        with _signals_held():
            aside, placed = [], []
            try:
                for _, final in renames:              # the earlier set moved aside: each may refuse
                    if os.path.lexists(final):
                        os.rename(final, _previous_name(final))
                        aside.append(final)
                for tmp, final in renames:
                    os.rename(tmp, final)
                    placed.append((tmp, final))
            except OSError as e:                      # undone: the earlier set back, no journal, one line
                refused = final
                for tmp, done in reversed(placed):
                    os.rename(done, tmp)
                for done in reversed(aside):
                    os.rename(_previous_name(done), done)
                for journal in journals.values():
                    os.remove(journal)
                raise OSError(e.errno, f"{e.strerror}; the earlier files are kept", refused) from None
            self.committed = True
            for final in aside:
                os.remove(_previous_name(final))
            for journal in journals.values():
                os.remove(journal)
            for path in self.drop:
                if os.path.isfile(path):
                    os.remove(path)
        self.temps = {}

    def discard(self) -> None:
        """Remove the temporaries written so far; the earlier files stay."""
        for tmp in self.temps.values():
            if os.path.exists(tmp):
                os.remove(tmp)
        self.temps = {}


def mark_done(e: Interrupted, files: ResultSet | None, status: int | None) -> None:
    """A signal that came once ``files`` were in place ends the run as done with ``status``
    (:attr:`~petsc_adhesion.errors.Interrupted.done`; the command line says so)."""
    if files is not None and files.committed:
        e.done = status


def said_after(signum: int) -> None:
    """One line: a signal came once the run's results were in place (the run ends as done)."""
    say(f"{signal.Signals(signum).name} came after the results were written")


@contextmanager
def written(targets: dict, drop=()):
    """A :class:`ResultSet` for the block (``drop``: the files it replaces), discarded after it.  A
    signal held during the renames that comes once the set is complete is said in one line, and the run
    ends as done; one that comes after the block is the caller's (:attr:`Interrupted.done`)."""
    files = ResultSet(targets, drop)
    try:
        yield files
    except BaseException as e:
        signal_ = interrupted_in(e)     # a signal during an import inside the block comes wrapped
        if signal_ is None or not files.committed:
            raise
        said_after(signal_.signum)
    finally:
        files.discard()
