"""The work-precision benchmark's worker and re-rendering commands.

    python -m petsc_adhesion.benchmarks.workprecision scale N PMAT STEPS   # one process of the scaling study
    python -m petsc_adhesion.benchmarks.workprecision docs DUMP             # the documents again from a dump of run()
    python -m petsc_adhesion.benchmarks.workprecision profile DUMP          # profile() measured again into a dump
"""
import json
import sys

from petsc4py import PETSc

from . import __doc__ as DOC
from .render import write_docs
from .speed import profile, scale_worker

if len(sys.argv) >= 5 and sys.argv[1] == "scale":
    res = scale_worker(int(sys.argv[2]), sys.argv[3], int(sys.argv[4]))
    if PETSc.COMM_WORLD.getRank() == 0:
        print(json.dumps(res), flush=True)
elif len(sys.argv) >= 3 and sys.argv[1] == "docs":      # re-render the documents from a dump of run()
    with open(sys.argv[2]) as f:
        write_docs(json.load(f))
elif len(sys.argv) >= 3 and sys.argv[1] == "profile":   # profile() measured again into a dump, re-rendered
    with open(sys.argv[2]) as f:
        kept = json.load(f)
    kept["profile"] = profile()
    with open(sys.argv[2], "w") as f:
        json.dump(kept, f)
    write_docs(kept)
else:
    print(DOC)
