"""Checkpoint and restart: the file of a run's state, saved as it goes, and the check that a restart is of the same run.

A curve (:class:`~petsc_adhesion.tracing.tracer.Tracer`) is saved into one
file, at most every ``-cont_checkpoint_interval`` seconds, at the moments the
continuation offers (before a step attempt, the ``pause`` of
:meth:`~petsc_adhesion.core.continuation.Continuation.run`; after each event's
error bars).  ``-cont_restart FILE`` rebuilds that state and goes on, taking
exactly the steps the uninterrupted run takes: the continuation is deterministic
(one thread per rank, fixed rank count).  Each object says what its state is
and takes it up again (``state()`` and ``restore()`` of the tracer, the
continuation, the event finder, the Newton and bordered solvers and their
preconditioners' reuse, :class:`~petsc_adhesion.core.protocol.Point`); this
module holds only the file and the fingerprint:

* the state's arrays are the ranks' local parts of distributed vectors: they
  are gathered to rank 0, which alone writes, and a restart reads on rank 0 and
  scatters them in the same parts (a curve restarts on as many ranks);
* each save is atomic: a temporary beside the target
  (:func:`~petsc_adhesion.io.resultset.atomic_write`), flushed to disk, renamed
  over the previous save;
* the file is ``MAGIC``, a JSON header line (format, version, the run's
  fingerprint, the payload's length and SHA-256) and the payload, an ``.npz``
  archive of the arrays and the JSON of everything else; anything else is
  refused, in one line naming ``-cont_restart``, as is a checkpoint of other
  model, grid or solver options (:func:`fingerprint`).

The error bars' estimates made so far are saved with the tracer in the phase
"errors" (typed values, :mod:`petsc_adhesion.io.values`): a restart takes them up
and locates again only the events not yet estimated.  A study saves its finished
cases alike (:meth:`Checkpoint.save_cases`), each a
:class:`~petsc_adhesion.tracing.case.CaseResult` through the same serializer.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import re
import time
from contextlib import contextmanager

import numpy as np

from ..errors import InputError, collective, first_line, interrupted_in, printable
from ..io.inputs import check_input
from ..io.resultset import ResultSet, atomic_write, check_targets
from ..io.values import decode, encode
from ..version import __version__

__all__ = ["Checkpoint", "open_checkpoint", "default_path", "fingerprint", "write_file", "read_file", "is_checkpoint", "MAGIC", "FORMAT", "INTERVAL", "FREE"]

#: The first line of every checkpoint.
MAGIC = b"petsc-adhesion checkpoint\n"
#: The layout of the state; a file of another is refused.  3: a study's cases and a curve's error-bar
#: estimates as typed values (:mod:`petsc_adhesion.io.values`).
FORMAT = 3
#: Seconds between saves by default.  A save costs about 0.35 s per 10^7 numbers held (2000 points of
#: 2500 nodes, 80 MB), mostly writing them: under 4 per cent of this for such a curve, 0.1 per cent
#: for the usual few hundred points of 500 nodes (15 ms a save).
INTERVAL = 10.0
#: Options that change no number of the curve (where results go, what is printed, the checkpoint's own):
#: a restart may differ in these.
FREE = ("out", "summary", "plot", "csv", "csv_events", "profiles", "cont_monitor", "cont_checkpoint", "cont_checkpoint_interval",
        "cont_restart", "progress", "progress_interval", "options_file", "help")
#: PETSc options that only print (monitors, viewers, logs), free alike.
_PRINTING = re.compile(r"monitor|(^|_)view|converged_reason|^log|^info|^options_|^malloc|^memory")


def default_path(targets: dict) -> str | None:
    """The checkpoint of a run writing ``targets`` (option -> path): hidden beside the first of -out,
    -summary, -plot, -csv, -csv_events (``results/x.h5`` -> ``results/.x.h5.checkpoint``); None without them."""
    for option in ("out", "summary", "plot", "csv", "csv_events"):
        if targets.get(option):
            folder, base = os.path.split(targets[option])
            return os.path.join(folder, f".{base}.checkpoint")
    return None


def fingerprint(opts, comm, inputs: dict | None = None) -> dict:
    """What must not change between a run and its restart: the program's version, the ranks (a block
    preconditioner has one block a rank), every application option's value but FREE's (defaults
    included), PETSc's options as given but those that only print, and the contents of the heights and topography files."""
    fp = {"version": __version__, "mpi_ranks": comm.getSize()}
    values = opts.values()
    for name, value in values.items():
        if name not in FREE:
            fp[name] = value
    for name, value in sorted(opts.db.getAll().items()):       # getAll marks nothing used
        if name not in values and name not in FREE and not _PRINTING.search(name):
            fp[name] = "" if value is None else str(value)
    for path in [*(inputs or {}).get("adh_roughness_file", ()), *(inputs or {}).get("adh_topography", ())]:
        if path and os.path.isfile(path):
            with open(path, "rb") as f:
                fp[f"contents of {path}"] = hashlib.sha256(f.read()).hexdigest()
    return fp


def _difference(saved: dict, now: dict) -> str | None:
    """The first difference of two fingerprints, in words, or None."""
    if ("mpi_ranks" in saved) != ("mpi_ranks" in now):    # only a curve's fingerprint has the ranks
        return "is a curve's, this run is a study" if "mpi_ranks" in saved else \
            "is a study's, this run traces one curve"
    for key in list(saved) + [k for k in now if k not in saved]:
        a, b = saved.get(key), now.get(key)
        if a == b:
            continue
        if key == "version":
            return f"was written by petsc-adhesion {a}, this is {b}"
        if key == "mpi_ranks":
            return f"was written on {a} MPI rank{'s' * (a != 1)}, this run has {b}"
        if key.startswith("contents of "):
            return f"was written with other {key} (the file changed)"
        was = f"without -{key}" if a is None else f"with -{key} {a}"
        return f"was written {was}; this run has " + (f"no -{key}" if b is None else f"-{key} {b}")
    return None


# -- the file -----------------------------------------------------------------------------------

def _encode(tree, arrays: list):
    """``tree`` for JSON, each numpy array replaced by its number in ``arrays``."""
    if isinstance(tree, np.ndarray):
        arrays.append(tree)
        return {"__array__": len(arrays) - 1}
    if isinstance(tree, dict):
        return {k: _encode(v, arrays) for k, v in tree.items()}
    if isinstance(tree, (list, tuple)):
        return [_encode(v, arrays) for v in tree]
    if isinstance(tree, np.generic):
        return tree.item()
    return tree


def _decode(tree, arrays):
    """Inverse of :func:`_encode`; with ``arrays`` None, each array becomes None (ranks but 0)."""
    if isinstance(tree, dict):
        if set(tree) == {"__array__"}:
            return None if arrays is None else arrays[f"arr_{tree['__array__']}"]
        return {k: _decode(v, arrays) for k, v in tree.items()}
    if isinstance(tree, list):
        return [_decode(v, arrays) for v in tree]
    return tree


def write_file(path: str, header: dict, tree: dict) -> None:
    """Write ``tree`` (nested dicts and lists of JSON values and numpy arrays) atomically, with ``header``."""
    arrays: list[np.ndarray] = []
    meta = json.dumps(_encode(tree, arrays)).encode()
    buf = io.BytesIO()
    np.savez(buf, *arrays, meta=np.frombuffer(meta, dtype=np.uint8))
    payload = buf.getvalue()
    head = {**header, "format": FORMAT, "bytes": len(payload), "sha256": hashlib.sha256(payload).hexdigest()}
    with atomic_write(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(MAGIC + json.dumps(head).encode() + b"\n")
            f.write(payload)
            f.flush()
            os.fsync(f.fileno())
    folder = os.open(os.path.dirname(os.path.abspath(path)), os.O_RDONLY)
    try:
        os.fsync(folder)                      # the rename itself on disk
    finally:
        os.close(folder)


def _study_cases(tree) -> list | None:
    """A study's saved state read back: its finished cases (each a
    :class:`~petsc_adhesion.tracing.case.CaseResult`), or None when ``tree`` is not one."""
    from ..tracing.case import CaseResult

    if not isinstance(tree, dict) or tree.get("phase") != "study" or not isinstance(tree.get("cases"), list):
        return None
    try:
        cases = [decode(r) for r in tree["cases"]]
    except (ValueError, TypeError, KeyError):
        return None
    return cases if all(isinstance(c, CaseResult) for c in cases) else None


def is_checkpoint(path: str) -> bool:
    """Whether ``path`` is a file of ours (it starts with MAGIC): only such a file is ever replaced by a save."""
    try:
        with open(path, "rb") as f:
            return f.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


def read_file(path: str, option: str = "cont_restart") -> tuple[dict, dict, bytes]:
    """(header, tree, JSON of the tree) of a checkpoint; InputError naming ``option`` for a missing,
    foreign or damaged file."""
    name = printable(path)
    check_input(option, path)
    try:
        with open(path, "rb") as f:
            magic = f.read(len(MAGIC))
            if magic != MAGIC:
                raise InputError(f"-{option}: '{name}' is not a petsc-adhesion checkpoint")
            header = json.loads(f.readline())
            payload = f.read()
    except (OSError, ValueError, UnicodeDecodeError) as e:
        why = e.strerror if isinstance(e, OSError) else "unreadable header"
        raise InputError(f"-{option}: cannot read the checkpoint '{name}' ({why})") from None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise InputError(f"-{option}: '{name}' is a checkpoint of another format than {FORMAT}")
    if header.get("bytes") != len(payload) or header.get("sha256") != hashlib.sha256(payload).hexdigest():
        raise InputError(f"-{option}: the checkpoint '{name}' is damaged (truncated or altered)")
    try:
        with np.load(io.BytesIO(payload), allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        meta = arrays.pop("meta").tobytes()
        tree = _decode(json.loads(meta), arrays)
    except (OSError, ValueError, KeyError) as e:
        raise InputError(f"-{option}: the checkpoint '{name}' is damaged ({e})") from None
    return header, tree, meta


# -- gathering and scattering the rank-local parts ------------------------------------------------

def _gather(mpi, tree):
    """``tree`` with each numpy array (a rank's local part of a distributed vector) joined along its last axis on
    rank 0, as {"__local__": whole, "counts": the ranks' lengths} (the whole None elsewhere); collective."""
    if isinstance(tree, np.ndarray):
        parts = mpi.gather(tree, root=0)
        counts = mpi.bcast([p.shape[-1] for p in parts] if parts is not None else None, root=0)
        return {"__local__": np.concatenate(parts, axis=-1) if parts is not None else None, "counts": counts}
    if isinstance(tree, dict):
        return {k: _gather(mpi, v) for k, v in tree.items()}
    if isinstance(tree, (list, tuple)):
        return [_gather(mpi, v) for v in tree]
    return tree


def _scatter(mpi, tree):
    """Inverse of :func:`_gather`: each rank's part of every joined array (held by rank 0); collective."""
    if isinstance(tree, dict):
        if set(tree) == {"__local__", "counts"}:
            ends = np.cumsum([0] + list(tree["counts"]))
            whole = tree["__local__"]
            parts = [whole[..., a:b] for a, b in zip(ends[:-1], ends[1:])] if mpi.Get_rank() == 0 else None
            return mpi.scatter(parts, root=0)
        return {k: _scatter(mpi, v) for k, v in tree.items()}
    if isinstance(tree, list):
        return [_scatter(mpi, v) for v in tree]
    return tree


class Checkpoint:
    """The checkpoint of one curve: where it is saved, how often, and the state read back for a restart.

    Parameters
    ----------
    path : str or None
        The file saved into (None: the run saves nothing).
    comm : PETSc.Comm
        The run's communicator; rank 0 reads and writes.
    fingerprint : dict
        The run's :func:`fingerprint`, kept in the file.
    interval : float
        Least time in seconds from the end of one save to the next (0: at every pause).
    restart : str or None
        A checkpoint to go on from (its state is read by :func:`open_checkpoint`).
    saved : dict or None
        That checkpoint's state as read (its arrays on rank 0 only).
    """

    def __init__(self, path, comm, fingerprint: dict, interval: float = INTERVAL, restart=None, saved=None):
        self.path, self.comm, self.fp, self.interval, self.restart = path, comm, fingerprint, interval, restart
        self.mpi = comm.tompi4py()
        self.rank0 = self.mpi.Get_rank() == 0
        self.saved = saved          # the state read for the restart (its arrays on rank 0 only)
        self.last = time.perf_counter()
        self.rows: dict[int, dict] = {}     # segment number -> {"x", "xdot": gathered rows (rank 0)}, "n": points sent
        if path and self.rank0:
            ResultSet({"checkpoint": path})    # removes the temporaries of saves killed on this host

    # -- saving -------------------------------------------------------------------------------------
    @property
    def name(self) -> str:
        """The checkpoint restarted from, for one line."""
        return printable(self.restart or "")

    def due(self) -> bool:
        """Whether a save is due (collective: rank 0's clock decides)."""
        return bool(self.path) and self.mpi.bcast(time.perf_counter() - self.last >= self.interval
                                                  if self.rank0 else None, root=0)

    def pause(self, tracer, phase: str, wall: dict, estimates: tuple = ()) -> None:
        """Save the state of ``tracer`` if due (collective); ``phase``: "trace" or "errors"; ``wall``: the
        seconds spent so far on each; ``estimates``: the error bars' estimates made so far, in the order of
        the events estimated (:class:`~petsc_adhesion.tracing.error_bars.Estimate` or Missing)."""
        if self.due():
            self.save(tracer, phase, wall, estimates)

    def save(self, tracer, phase: str, wall: dict, estimates: tuple = ()) -> None:
        """Save the state of ``tracer`` now (:meth:`~petsc_adhesion.tracing.tracer.Tracer.state`; after the
        trace its solvers serve no step again) and the ``estimates`` made; collective, rank 0 writes."""
        tree = {"phase": phase, "wall": wall, "tracer": _gather(self.mpi, tracer.state(solvers=phase == "trace")),
                "estimates": encode(tuple(estimates))}
        if self.rank0:
            last = tracer.segments[-1].cont.points[-1]
            write_file(self.path, {"program": "petsc-adhesion", "version": __version__, "fingerprint": self.fp,
                                   "phase": phase, "lambda": last.p}, tree)
        self.mpi.barrier()           # the file is whole before any rank goes on (or is killed)
        self.last = time.perf_counter()

    # -- restoring ------------------------------------------------------------------------------------
    def restore(self, tracer) -> tuple[str, dict, tuple] | None:
        """Rebuild the saved state into ``tracer`` (collective); returns (phase, wall, the error bars'
        estimates already made, in the order of the events estimated), or None when there is nothing to
        restore."""
        if self.saved is None:
            return None
        tree = self.saved
        if not isinstance(tree, dict) or tree.get("phase") not in ("trace", "errors") or not isinstance(tree.get("wall"), dict) or \
                not isinstance(tree.get("tracer"), dict) or not tree["tracer"].get("segments"):
            raise InputError(f"-cont_restart: the checkpoint '{self.name}' holds no curve's state this version can "
                             f"take up (no segments, or no phase it knows)")
        try:
            tracer.restore(_scatter(self.mpi, tree["tracer"]))
        except ValueError as e:
            raise InputError(f"-cont_restart: the checkpoint '{self.name}' holds {e}") from None
        except (KeyError, TypeError, IndexError, AttributeError) as e:
            raise InputError(f"-cont_restart: the checkpoint '{self.name}' holds a state this version cannot take up "
                             f"({type(e).__name__}: {first_line(e)})") from None
        estimates = self._estimates(tree.get("estimates"))
        return tree["phase"], tree["wall"], estimates

    def _estimates(self, saved) -> tuple:
        """The error bars' estimates of the checkpoint, read on rank 0 and given to every rank (collective)."""
        from ..tracing.error_bars import Estimate
        from ..tracing.measured import Missing

        got: tuple | str | None = None
        if self.rank0:
            try:
                got = decode(saved)
            except (ValueError, TypeError, KeyError) as e:
                got = f"({first_line(e)})"
            if not isinstance(got, str) and (not isinstance(got, tuple) or
                                             not all(isinstance(v, (Estimate, Missing)) for v in got)):
                got = "(no tuple of estimates)"
        got = self.mpi.bcast(got, root=0)
        if isinstance(got, str):
            raise InputError(f"-cont_restart: the checkpoint '{self.name}' holds error bars this version cannot "
                             f"take up {got}")
        return got

    # -- a study: its finished cases ---------------------------------------------------------------------
    def cases(self) -> tuple[set, list]:
        """A study's restart: (the numbers of the cases done, on every rank; their
        :class:`~petsc_adhesion.tracing.case.CaseResult` on rank 0, [] elsewhere); collective."""
        if self.saved is None:
            return set(), []
        # read back on rank 0 when the checkpoint was opened (a curve's was refused by its fingerprint)
        done = self.mpi.bcast({r.case for r in self.saved["cases"]} if self.rank0 else None, root=0)
        return done, list(self.saved["cases"]) if self.rank0 else []

    def save_cases(self, results: list) -> None:
        """Rank 0: save a study's finished cases (``results``, each a
        :class:`~petsc_adhesion.tracing.case.CaseResult`) if the interval has passed (not collective: the
        cases reach rank 0 at their own times)."""
        if not self.path or not self.rank0 or time.perf_counter() - self.last < self.interval:
            return
        write_file(self.path, {"program": "petsc-adhesion", "version": __version__, "fingerprint": self.fp,
                               "phase": "study", "cases": len(results)},
                   {"phase": "study", "cases": [encode(r) for r in results]})
        self.last = time.perf_counter()

    # -- the end ----------------------------------------------------------------------------------------
    @contextmanager
    def on_interrupt(self):
        """Name this checkpoint, once saved, in the :class:`~petsc_adhesion.errors.Interrupted` that ends
        the block: the command line's last word says how to go on."""
        try:
            yield
        except BaseException as e:
            signal_ = interrupted_in(e)     # a signal during an import inside the block comes wrapped
            if signal_ is not None and self.exists():
                signal_.resumable(self.path)
            raise

    def exists(self) -> bool:
        """Whether there is a saved state to restart from (rank 0 knows; False elsewhere)."""
        return bool(self.path) and self.rank0 and os.path.isfile(self.path)

    def paths(self) -> list[str]:
        """What the run's results replace (rank 0; none elsewhere): its checkpoint and the one it restarted
        from, removed as they are put in place (:class:`~petsc_adhesion.io.resultset.ResultSet`)."""
        return sorted({self.path, self.restart} - {None, ""}) if self.rank0 else []


def open_checkpoint(opts, targets: dict, inputs: dict, comm, study: bool = False) -> Checkpoint:
    """The checkpoint a curve's (a ``study``'s) options ask for, and the state of ``-cont_restart`` read
    and checked (collective; an InputError on every rank, before any work, for a bad one).

    The file saved into: ``-cont_checkpoint``; else the one restarted from; else
    :func:`default_path` of the outputs; ``-cont_checkpoint none`` saves nothing.  A study's cases
    are each traced on ``-study_ranks`` ranks, whatever the run's number: it may restart on another.
    """
    fp = fingerprint(opts, comm, inputs)
    if study:
        del fp["mpi_ranks"]
    restart = opts.string("cont_restart")
    path = opts.string("cont_checkpoint")
    path = None if path == "none" else path or restart or default_path(targets)
    if path is None and opts.db.hasName("cont_checkpoint_interval") and opts.string("cont_checkpoint") != "none":
        raise InputError("-cont_checkpoint_interval: times the saves of a checkpoint, and this run saves none (no "
                         "-out, -summary or -plot to keep it beside, nor -cont_checkpoint); remove it")
    interval = opts.real("cont_checkpoint_interval")

    def check():
        if comm.getRank() != 0:
            return None
        if restart is not None:
            check_input("cont_restart", restart)
        if path:
            check_targets({**targets, "cont_checkpoint": path}, inputs)
            if path != restart and os.path.lexists(path) and not is_checkpoint(path):
                raise InputError(f"-cont_checkpoint: '{printable(path)}' exists and is not a petsc-adhesion "
                                 f"checkpoint: it is not overwritten; give another name, or none")
        if restart is None:
            return None
        header, tree, meta = read_file(restart)
        why = _difference(header.get("fingerprint", {}) if isinstance(header.get("fingerprint"), dict) else {}, fp)
        if why:
            raise InputError(f"-cont_restart: the checkpoint '{printable(restart)}' {why}")
        if study:
            cases = _study_cases(tree)
            if cases is None:
                raise InputError(f"-cont_restart: the checkpoint '{printable(restart)}' holds no study's cases this "
                                 f"version can take up")
            return {"phase": "study", "cases": cases}, None
        return tree, meta

    got, saved = collective(comm, check), None
    if restart is not None:
        mpi = comm.tompi4py()
        if study:          # the cases on rank 0 (Checkpoint.cases gives every rank their numbers)
            saved = got[0] if mpi.Get_rank() == 0 else {"phase": "study", "cases": []}
        else:
            meta = mpi.bcast(got[1] if mpi.Get_rank() == 0 else None, root=0)
            saved = got[0] if mpi.Get_rank() == 0 else _decode(json.loads(meta), None)
    return Checkpoint(path, comm, fp, interval, restart, saved)
