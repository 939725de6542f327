"""``dyncheck versions``: the version matrix and its bisection."""

from __future__ import annotations

import argparse
from pathlib import Path

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import check_out_file, log, path_arg, positive
from dyncheck.progress import Progress
from dyncheck.workers import default_jobs


def versions_command(args: argparse.Namespace) -> int:
    """Exit 0 (the matrix reports moves; it does not judge them)."""
    from dyncheck import versions
    from dyncheck.cases import get_case
    from dyncheck.errors import NeedsCheckout
    from dyncheck.explain.releases import EXPLANATIONS
    from dyncheck.results import write_atomic

    NeedsCheckout.unless_checkout("dyncheck versions (each release is installed beside the "
                                  "checkout's code, pinned by its constraints.txt)")
    positive("--jobs", args.jobs)
    for name in args.case:
        get_case(name)
    if args.bisect is not None:
        name, good, bad = args.bisect
        first, moved = versions.bisect(name, good, bad, cases=args.case, jobs=args.jobs,
                                     log=log)
        print(f"first release that moved: {name} {first} ({len(moved)} rows)")
        print(moved.to_string(index=False))
        return 0
    names = args.engine or list(versions.ENGINES)
    for name in names:
        versions.engine(name)
    check_out_file("--out", args.out)
    releases = sum(len(versions.engine(name).releases) for name in names)
    with Progress("versions", releases, quiet=args.quiet) as progress:
        steps = versions.matrix(names, cases=args.case, jobs=args.jobs, log=log,
                              reuse=args.reuse, progress=progress)
    write_atomic(args.out, versions.page(steps, notes=EXPLANATIONS))
    print(f"version matrix written to {args.out}")
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--engine", action="append", default=[], metavar="NAME",
                   help="mujoco, pinocchio, drake, newton, pybullet (repeatable; default: "
                   "all)")
    p.add_argument("--case", action="append", default=[], metavar="CASE",
                   help="cases to run (repeatable; default: all)")
    p.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"each release's run in N parallel processes (default: {flags.JOBS})")
    p.add_argument("--bisect", nargs=3, default=None, metavar=("ENGINE", "GOOD", "BAD"),
                   help="name the first release between GOOD and BAD whose results moved")
    p.add_argument("--reuse", action="store_true",
                   help="reuse each release's newest cached run, whatever code made it")
    p.add_argument("--out", type=path_arg, default=Path("reports/versions.md"), metavar="FILE")
    flags.quiet(p)


COMMAND = Command(
    name="versions", help="the version matrix: each engine release in its own environment",
    example="dyncheck versions --engine mujoco   |   dyncheck versions --bisect mujoco 3.3.7 "
    "4.0.0",
    arguments=_arguments, handler=versions_command)
