"""The cases a coverage study's command line names: ``-mu MU ...``, ``-sigma S ...`` (of the study's own cases,
tuples whose first two entries are mu and sigma) and ``-jobs N``, the processes at once."""
from __future__ import annotations

__all__ = ["selected"]


def selected(argv: list[str], cases: list) -> tuple:
    """(the cases whose mu ``-mu MU ...`` and sigma ``-sigma S ...`` name, all of them without; the processes
    at once, ``-jobs N``, 2 without it), or (None, why) for arguments that are not that."""
    jobs, chosen, rest = 2, {}, list(argv)
    known = {name: sorted({c[k] for c in cases}) for k, name in enumerate(("mu", "sigma"))}
    try:
        while rest:
            flag = rest.pop(0)
            if flag == "-jobs":
                jobs = int(rest.pop(0))
                if jobs < 1:
                    raise ValueError
            elif flag in ("-mu", "-sigma"):
                name = flag[1:]
                chosen[name] = []
                while rest and not rest[0].startswith("-j") and not rest[0].startswith("-s") \
                        and not rest[0].startswith("-m"):
                    chosen[name].append(float(rest.pop(0)))
                if not chosen[name] or any(v not in known[name] for v in chosen[name]):
                    raise ValueError
            else:
                raise ValueError
    except (ValueError, IndexError):
        return None, ("the study takes -mu MU ... (of " + ", ".join(f"{m:g}" for m in known["mu"]) + "), -sigma S ... "
                      "(of " + ", ".join(f"{m:g}" for m in known["sigma"]) + ") and -jobs N (a positive integer)")
    return [c for c in cases if all(c[k] in chosen[name] for k, name in enumerate(("mu", "sigma")) if name in chosen)], \
        jobs
