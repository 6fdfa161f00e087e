"""Checkpoint and restart of a traced curve: the run's state saved as it goes, and resumed exactly.

A curve (:class:`~petsc_adhesion.adaptive.Tracer`) saves its whole state into
one file, at most every ``-cont_checkpoint_interval`` seconds, at the moments
the continuation offers (before a step attempt, :meth:`Continuation.run
<petsc_adhesion.continuation.Continuation.run>`'s ``pause``; after the jumps of
the folds; after each event's error bars).  ``-cont_restart FILE`` rebuilds
that state and goes on, taking exactly the steps the uninterrupted run takes:
the continuation is deterministic (one thread per rank, fixed rank count), and
the state holds all it depends on:

* every segment: its kind and the grid it was made for (centre, band), its
  settings and step budget, every point (x, tangent, observables, step
  statistics), the next step ``ds``, its counters, and the events found on it
  (each with its located point, its landing and, once computed, its error bars);
* for each solver of a segment (natural corrector, bordered arclength system),
  the point its preconditioning matrix was last filled at and whether the next
  linearization refills it (:class:`~petsc_adhesion.solver.PCReuse`): a
  restart fills the same matrix there, so that the same preconditioner yields
  the same Newton and Krylov iterates (a fresh one would change them by the
  solver tolerances, and the step control's choices with them);
* the phase (tracing, or the error bars after it) and the wall time spent.

Distributed vectors are gathered to rank 0, which alone writes; a restart reads
on rank 0 and scatters.  Each save is atomic: a temporary beside the target
(:func:`~petsc_adhesion.files.atomic_write`), flushed to disk, renamed over the
previous save.  The file is ``MAGIC``, a JSON header line (format, version, the
run's fingerprint, the payload's length and SHA-256) and the payload, an
``.npz`` archive of the arrays and the JSON of everything else; anything else
is refused, in one line naming ``-cont_restart``, as is a checkpoint of other
model, grid or solver options (:func:`fingerprint`).
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import re
import time
from contextlib import contextmanager
from dataclasses import asdict, fields

import numpy as np

from . import __version__
from .continuation import Point, Settings
from .errors import InputError, Interrupted
from .events import Found
from .files import ResultSet, atomic_write, printable

__all__ = ["Checkpoint", "open_checkpoint", "default_path", "fingerprint", "write_file", "read_file", "MAGIC",
           "FORMAT", "INTERVAL", "FREE"]

#: The first line of every checkpoint.
MAGIC = b"petsc-adhesion checkpoint\n"
#: The layout of the state; a file of another is refused.
FORMAT = 1
#: Seconds between saves by default.  A save costs about 0.35 s per 10^7 numbers held (2000 points of
#: 2500 nodes, 80 MB), mostly writing them: under 4 per cent of this for such a curve, 0.1 per cent
#: for the usual few hundred points of 500 nodes (15 ms a save).
INTERVAL = 10.0
#: Rows of points kept in this many arrays at most (gathered save by save, joined beyond).
CHUNKS = 32
#: Options that change no number of the curve (where results go, what is printed, the checkpoint's own):
#: a restart may differ in these.
FREE = ("out", "summary", "plot", "profiles", "cont_monitor", "cont_checkpoint", "cont_checkpoint_interval",
        "cont_restart", "progress", "progress_interval", "options_file", "help")
#: PETSc options that only print (monitors, viewers, logs), free alike.
_PRINTING = re.compile(r"monitor|(^|_)view|converged_reason|^log|^info|^options_|^malloc|^memory")
_POINT = [f.name for f in fields(Point) if f.name not in ("x", "xdot")]


def default_path(targets: dict) -> str | None:
    """The checkpoint of a run writing ``targets`` (option -> path): hidden beside the first of -out,
    -summary, -plot (``results/x.h5`` -> ``results/.x.h5.checkpoint``); None without them."""
    for option in ("out", "summary", "plot"):
        if targets.get(option):
            folder, base = os.path.split(targets[option])
            return os.path.join(folder, f".{base}.checkpoint")
    return None


def fingerprint(opts, comm, inputs: dict | None = None) -> dict:
    """What must not change between a run and its restart: the program's version, the ranks (a block
    preconditioner has one block a rank), every application option's value but FREE's (defaults
    included), PETSc's options as given but those that only print, and the contents of the heights file."""
    from .options import TABLE

    fp = {"version": __version__, "mpi_ranks": comm.getSize()}
    for name, o in TABLE.items():
        if name not in FREE:
            fp[name] = repr(getattr(opts, o.kind)(name))
    for name, value in sorted(opts.db.getAll().items()):       # getAll marks nothing used
        if name not in TABLE and name not in FREE and not _PRINTING.search(name):
            fp[name] = "" if value is None else str(value)
    for path in (inputs or {}).get("adh_roughness_file", ()):
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
    arrays = []
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


def read_file(path: str, option: str = "cont_restart") -> tuple[dict, dict, bytes]:
    """(header, tree, JSON of the tree) of a checkpoint; InputError naming ``option`` for a missing,
    foreign or damaged file."""
    name = printable(path)
    if not os.path.exists(path):
        raise InputError(f"-{option}: no file '{name}'")
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

def _gather(mpi, rows: np.ndarray):
    """Rows of local parts (k, n_local) as rows of whole vectors (k, N) on rank 0 (None elsewhere)."""
    parts = mpi.gather(rows, root=0)
    return np.concatenate(parts, axis=1) if parts is not None else None


def _scatter(mpi, rows, lo: int, hi: int) -> np.ndarray:
    """Each rank's columns [lo, hi) of ``rows`` (k, N) held by rank 0."""
    ranges = mpi.allgather((lo, hi))
    return mpi.scatter([rows[..., a:b] for a, b in ranges] if mpi.Get_rank() == 0 else None, root=0)


def _owned(problem) -> tuple[int, int]:
    """The rows [lo, hi) of the problem's state vectors on this rank."""
    v = problem.create_vec()
    try:
        return v.getOwnershipRange()
    finally:
        v.destroy()


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
    """

    def __init__(self, path, comm, fingerprint: dict, interval: float = INTERVAL, restart=None):
        self.path, self.comm, self.fp, self.interval, self.restart = path, comm, fingerprint, interval, restart
        self.mpi = comm.tompi4py()
        self.rank0 = self.mpi.Get_rank() == 0
        self.saved = None           # the state read for the restart (its arrays on rank 0 only)
        self.last = time.perf_counter()
        self.rows = {}              # segment number -> {"x", "xdot": gathered rows (rank 0)}, "n": points sent
        if path and self.rank0:
            ResultSet({"checkpoint": path})    # removes the temporaries of saves killed on this host

    # -- saving -------------------------------------------------------------------------------------
    def due(self) -> bool:
        """Whether a save is due (collective: rank 0's clock decides)."""
        return bool(self.path) and self.mpi.bcast(time.perf_counter() - self.last >= self.interval
                                                  if self.rank0 else None, root=0)

    def pause(self, tracer, phase: str, wall: dict) -> None:
        """Save the state of ``tracer`` if due (collective); ``phase``: "trace" or "errors"; ``wall``: the
        seconds spent so far on each."""
        if self.due():
            self.save(tracer, phase, wall)

    def save(self, tracer, phase: str, wall: dict) -> None:
        """Save the state of ``tracer`` now (collective; rank 0 writes)."""
        tree = {"phase": phase, "wall": wall,
                "segments": [self._segment(k, seg, tracer, phase) for k, seg in enumerate(tracer.segments)]}
        if self.rank0:
            last = tracer.segments[-1].cont.points[-1]
            write_file(self.path, {"program": "petsc-adhesion", "version": __version__, "fingerprint": self.fp,
                                   "phase": phase, "lambda": last.p}, tree)
        self.mpi.barrier()           # the file is whole before any rank goes on (or is killed)
        self.last = time.perf_counter()

    def _point(self, pt) -> dict | None:
        if pt is None:
            return None
        x, xdot = (_gather(self.mpi, v[None, :]) for v in (pt.x, pt.xdot))
        return {"x": None if x is None else x[0], "xdot": None if xdot is None else xdot[0],
                **{k: getattr(pt, k) for k in _POINT}}

    def _points(self, k: int, points: list) -> dict:
        """All points of segment k, the new ones gathered (only rank 0 keeps them)."""
        rows = self.rows.setdefault(k, {"x": [], "xdot": [], "n": 0})
        new = points[rows["n"]:]
        if new:
            for key in ("x", "xdot"):
                whole = _gather(self.mpi, np.array([getattr(p, key) for p in new]))
                if whole is not None:
                    rows[key].append(whole)
                    if len(rows[key]) > CHUNKS:
                        rows[key] = [np.concatenate(rows[key])]
            rows["n"] = len(points)
        out = {name: [getattr(p, name) for p in points] for name in _POINT}
        return out | {key: rows[key] if self.rank0 else [] for key in ("x", "xdot")}

    def _solvers(self, cont) -> dict:
        """What each solver keeps of its preconditioner: the fill point and whether it is due a refill."""
        out = {}
        for name, reuse, ksp in (("newton", cont.newton.reuse, cont.newton.snes.getKSP()),
                                 ("bordered", cont.bordered.reuse, cont.bordered.snes.getKSP())):
            at = None
            if reuse.at is not None:
                at = [_gather(self.mpi, v[None, :]) if isinstance(v, np.ndarray) else v for v in reuse.at]
                at = [v[0] if isinstance(v, np.ndarray) else v for v in at]
            out[name] = {"pending": bool(reuse.pending(ksp)), "at": at}
        return out

    def _segment(self, k: int, seg, tracer, phase: str) -> dict:
        cont, pb = seg.cont, seg.problem
        owner = {id(s.finder): j for j, s in enumerate(tracer.segments)}
        found = [{"event": tracer.events.index(f.event), "label": f.label, "segment": f.segment, "before": f.before,
                  "point": self._point(f.point), "landing": self._point(f.landing),
                  "landing_by": owner.get(id(f.landing_by)), "landing_step": f.landing_step,
                  "estimate": f.estimate} for f in seg.finder.found]
        out = {"kind": seg.kind, "at": seg.grid.edge if seg.grid is not None else None,
               "band": seg.grid.band if seg.kind == "scaled" else None, "N": pb.layout.N,
               "settings": asdict(cont.set), "index0": cont.index0, "ds": cont.ds, "rejected": cont.rejected,
               "folds": cont.folds, "stop": cont.stop, "guarded": pb.guarded, "points": self._points(k, cont.points),
               "found": found}
        if phase == "trace":          # after the trace the solvers serve no step again
            out["solvers"] = self._solvers(cont)
        return out

    # -- restoring ------------------------------------------------------------------------------------
    def restore(self, tracer) -> tuple[str, dict] | None:
        """Rebuild the saved segments into ``tracer`` (collective); returns (phase, wall), or None when
        there is nothing to restore."""
        if self.saved is None:
            return None
        tree = self.saved
        segments = []
        for k, st in enumerate(tree["segments"]):
            settings = Settings(**{**st["settings"], "monitor": tracer.set.monitor})
            seg = tracer.segment(st["kind"], st["at"], settings=settings, band=st["band"])
            if seg.problem.layout.N != st["N"]:
                raise InputError(f"-cont_restart: segment {k + 1} of the checkpoint has {st['N']} nodes, "
                                 f"this version makes {seg.problem.layout.N}")
            tracer.segments.append(seg)
            segments.append((seg, st))
            lo, hi = _owned(seg.problem)
            cont = seg.cont
            cont.index0, cont.ds, cont.rejected, cont.folds = st["index0"], st["ds"], st["rejected"], st["folds"]
            cont.stop = tuple(st["stop"]) if st["stop"] is not None else None
            seg.problem.guarded = st["guarded"]
            pts = st["points"]
            whole = {key: [np.concatenate(pts[key])] if self.rank0 else [] for key in ("x", "xdot")}
            x, xdot = (_scatter(self.mpi, whole[key][0] if self.rank0 else None, lo, hi) for key in ("x", "xdot"))
            cont.points = [Point(x=x[i].copy(), xdot=xdot[i].copy(), **{name: pts[name][i] for name in _POINT})
                           for i in range(len(pts["p"]))]
            self.rows[k] = {**whole, "n": len(cont.points)}
        for seg, st in segments:
            seg.finder.found = [self._found(f, seg, tracer) for f in st["found"]]
            if tree["phase"] == "trace":
                self._refill(seg, st["solvers"])
        return tree["phase"], tree["wall"]

    def _unpoint(self, d, seg):
        if d is None:
            return None
        lo, hi = _owned(seg.problem)
        x, xdot = (_scatter(self.mpi, d[key], lo, hi) for key in ("x", "xdot"))
        return Point(x=x.copy(), xdot=xdot.copy(), **{k: d[k] for k in _POINT})

    def _found(self, d: dict, seg, tracer) -> Found:
        by = tracer.segments[d["landing_by"]] if d["landing_by"] is not None else None
        return Found(tracer.events[d["event"]], d["label"], self._unpoint(d["point"], seg), d["segment"], d["before"],
                     landing=self._unpoint(d["landing"], by) if by is not None else None,
                     landing_by=by.finder if by is not None else None, landing_step=d["landing_step"],
                     estimate=d["estimate"])

    def _refill(self, seg, solvers: dict) -> None:
        """Each solver's preconditioning matrix filled where the saved run last filled it."""
        cont, pb = seg.cont, seg.problem
        lo, hi = _owned(pb)
        newton, bordered = solvers["newton"], solvers["bordered"]
        if newton["at"] is not None:
            x, p = newton["at"]
            v = pb.create_vec()
            v.setArray(_scatter(self.mpi, x, lo, hi))
            cont.newton.p = p
            cont.newton.linearize(v, True)
            v.destroy()
        cont.newton.reuse.stale = newton["pending"]
        if bordered["at"] is not None:
            x, p, xdot, pdot = bordered["at"]
            b = cont.bordered
            b.x.setArray(_scatter(self.mpi, x, lo, hi))
            b.p = p
            b.set_border(_scatter(self.mpi, xdot, lo, hi), pdot)
            b.linearize(True)
        cont.bordered.reuse.stale = bordered["pending"]

    # -- a study: its finished cases ---------------------------------------------------------------------
    def cases(self) -> tuple[set, list]:
        """A study's restart: (the numbers of the cases done, their records on rank 0, [] elsewhere)."""
        if self.saved is None:
            return set(), []
        records = self.saved["cases"]          # a curve's checkpoint was refused by its fingerprint
        return {r["case"] for r in records}, records if self.rank0 else []

    def save_cases(self, records: list[dict]) -> None:
        """Rank 0: save a study's finished cases (``records``) if the interval has passed (not collective:
        the cases reach rank 0 at their own times)."""
        if not self.path or not self.rank0 or time.perf_counter() - self.last < self.interval:
            return
        write_file(self.path, {"program": "petsc-adhesion", "version": __version__, "fingerprint": self.fp,
                               "phase": "study", "cases": len(records)}, {"phase": "study", "cases": records})
        self.last = time.perf_counter()

    # -- the end ----------------------------------------------------------------------------------------
    @contextmanager
    def on_interrupt(self):
        """Name this checkpoint, once saved, in the :class:`~petsc_adhesion.errors.Interrupted` that ends
        the block: the command line's last word says how to go on."""
        try:
            yield
        except Interrupted as e:
            if self.exists():
                e.restart = self.path
            raise

    def exists(self) -> bool:
        """Whether there is a saved state to restart from (rank 0 knows; False elsewhere)."""
        return bool(self.path) and self.rank0 and os.path.isfile(self.path)

    def paths(self) -> list[str]:
        """What the run's results replace (rank 0; none elsewhere): its checkpoint and the one it restarted
        from, removed as they are put in place (:class:`~petsc_adhesion.files.ResultSet`)."""
        return sorted({self.path, self.restart} - {None, ""}) if self.rank0 else []


def open_checkpoint(opts, targets: dict, inputs: dict, comm, study: bool = False) -> Checkpoint:
    """The checkpoint a curve's (a ``study``'s) options ask for, and the state of ``-cont_restart`` read
    and checked (collective; an InputError on every rank, before any work, for a bad one).

    The file saved into: ``-cont_checkpoint``; else the one restarted from; else
    :func:`default_path` of the outputs; ``-cont_checkpoint none`` saves nothing.  A study's cases
    are each traced on ``-study_ranks`` ranks, whatever the run's number: it may restart on another.
    """
    from .files import check_targets
    from .options import collective

    fp = fingerprint(opts, comm, inputs)
    if study:
        del fp["mpi_ranks"]
    restart = opts.string("cont_restart")
    path = opts.string("cont_checkpoint")
    path = None if path == "none" else path or restart or default_path(targets)
    ck = Checkpoint(path, comm, fp, opts.real("cont_checkpoint_interval"), restart)

    def check():
        if comm.getRank() != 0:
            return None
        if path:
            check_targets({**targets, "cont_checkpoint": path}, inputs)
        if restart is None:
            return None
        header, tree, meta = read_file(restart)
        why = _difference(header.get("fingerprint", {}), fp)
        if why:
            raise InputError(f"-cont_restart: the checkpoint '{printable(restart)}' {why}")
        return tree, meta

    got = collective(comm, check)
    if restart is not None:
        mpi = comm.tompi4py()
        meta = mpi.bcast(got[1] if mpi.Get_rank() == 0 else None, root=0)
        ck.saved = got[0] if mpi.Get_rank() == 0 else _decode(json.loads(meta), None)
    return ck
