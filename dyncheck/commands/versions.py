"""``dyncheck versions``: the version matrix and its bisection."""

from __future__ import annotations

import argparse

from dyncheck.commands.options import check_out_file, log, positive
from dyncheck.progress import Progress


def versions_command(args: argparse.Namespace) -> int:
    """Exit 0 (the matrix reports moves; it does not judge them)."""
    from dyncheck import matrix
    from dyncheck.cases import get_case
    from dyncheck.results import write_atomic

    positive("--jobs", args.jobs)
    for name in args.case:
        get_case(name)
    if args.bisect is not None:
        name, good, bad = args.bisect
        first, moved = matrix.bisect(name, good, bad, cases=args.case, jobs=args.jobs,
                                     log=log)
        print(f"first release that moved: {name} {first} ({len(moved)} rows)")
        print(moved.to_string(index=False))
        return 0
    names = args.engine or list(matrix.ENGINES)
    for name in names:
        matrix.engine(name)
    check_out_file("--out", args.out)
    releases = sum(len(matrix.engine(name).releases) for name in names)
    with Progress("versions", releases, quiet=args.quiet) as progress:
        steps = matrix.matrix(names, cases=args.case, jobs=args.jobs, log=log,
                              reuse=args.reuse, progress=progress)
    write_atomic(args.out, matrix.page(steps, notes=matrix.EXPLANATIONS))
    print(f"version matrix written to {args.out}")
    return 0
