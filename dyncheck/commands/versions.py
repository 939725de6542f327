"""``dyncheck versions``: the version matrix and its bisection."""

from __future__ import annotations

import argparse
from pathlib import Path

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import OUT, check_out_file, log, path_arg, positive
from dyncheck.errors import InvalidInput
from dyncheck.progress import Progress
from dyncheck.workers import default_jobs


def versions_command(args: argparse.Namespace) -> int:
    """Exit 0 (the matrix reports moves; it does not judge them)."""
    import time

    from dyncheck import environments, versions
    from dyncheck.cases import get_case
    from dyncheck.errors import NeedsCheckout
    from dyncheck.explain.releases import EXPLANATIONS
    from dyncheck.results import write_atomic

    if args.remove_environments:
        return _remove()
    NeedsCheckout.unless_checkout("dyncheck versions (each release is installed beside the "
                                  "checkout's code, pinned by its constraints.txt)")
    positive("--jobs", args.jobs)
    if args.paths:
        return _on_models(args)
    if args.release or args.floating or args.states is not None:
        flag = "--release" if args.release else "--floating" if args.floating else "--states"
        raise InvalidInput(flag, True, "given with model files (PATH ...)")
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
    out = args.out or Path("reports/versions.md")
    check_out_file("--out", out)
    releases = sum(len(versions.engine(name).releases) for name in names)
    t0 = time.perf_counter()
    with Progress("versions", releases, quiet=args.quiet) as progress:
        steps = versions.matrix(names, cases=args.case, jobs=args.jobs, log=log,
                              reuse=args.reuse, progress=progress)
    write_atomic(out, versions.page(steps, notes=EXPLANATIONS, seconds=time.perf_counter() - t0,
                                    footprint=environments.footprint(
                                        (n, r) for n in names
                                        for r in versions.engine(n).releases)))
    print(f"version matrix written to {out}")
    return 0


def _remove() -> int:
    from dyncheck.cache.store import cache_root
    from dyncheck.model_versions import remove_environments

    count, size = remove_environments()
    print(f"removed {count} release environments and cached runs under {cache_root()} "
          f"({size / 2**30:.2f} GiB)")
    return 0


def _on_models(args: argparse.Namespace) -> int:
    """``versions MODEL... --engine E``: the user's models under each release of E."""
    import time

    from dyncheck import environments, model_versions, versions
    from dyncheck.check import inputs
    from dyncheck.results import write_atomic

    if len(args.engine) != 1:
        raise InvalidInput("--engine", ",".join(args.engine), "one engine with model files")
    if args.case:
        raise InvalidInput("--case", args.case[0], "absent with model files")
    eng = versions.engine(args.engine[0])
    for path in args.paths:
        inputs.model_path(str(path))
    if args.states is not None:
        inputs.states(args.states)
    options = (*(("--floating",) if args.floating else ()),
               *(("--states", str(args.states)) if args.states is not None else ()))
    models = model_versions.Models(paths=tuple(p.resolve() for p in args.paths),
                                   options=options)
    if args.bisect is not None:
        name, good, bad = args.bisect
        if name != eng.name:
            raise InvalidInput("--bisect", name, f"the engine of --engine ({eng.name})")
        first, moved = model_versions.bisect(eng, good, bad, models, log=log)
        print(f"first release that moved: {eng.name} {first} ({len(moved)} rows)")
        print(moved.to_string(index=False))
        return 0
    out = args.out or OUT / "versions.md"
    check_out_file("--out", out, list(args.paths))
    releases = tuple(args.release) or eng.releases
    t0 = time.perf_counter()
    with Progress("versions", len(releases), quiet=args.quiet) as progress:
        steps, outcomes = model_versions.matrix(eng, releases, models, log=log,
                                                done=progress.done)
    write_atomic(out, model_versions.page(
        steps, outcomes, models, seconds=time.perf_counter() - t0,
        footprint=environments.footprint((eng.name, r) for r in releases)))
    moved = sum(len(s.moved) for s in steps if s.moved is not None)
    print(f"{moved} rows moved over {len(releases)} releases of {eng.name}: {out}")
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("paths", nargs="*", type=path_arg, metavar="PATH",
                   help="your MJCF or URDF files: checked under each release of --engine "
                   "(one engine) instead of the book's cases")
    p.add_argument("--release", action="append", default=[], metavar="R",
                   help="with PATHs: the releases to compare, in order (repeatable; default: "
                   "those the project proves)")
    p.add_argument("--floating", action="store_true",
                   help="with PATHs: a URDF's root link is a free body")
    p.add_argument("--states", type=int, default=None, metavar="N",
                   help="with PATHs: sampled states per model (default: check's)")
    p.add_argument("--remove-environments", action="store_true",
                   help="delete every release environment and cached release run (about "
                   "1.3 GB each), and do nothing else")
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
    p.add_argument("--out", type=path_arg, default=None, metavar="FILE",
                   help=f"the page (default: reports/versions.md; with PATHs: "
                   f"{OUT / 'versions.md'})")
    flags.quiet(p)


COMMAND = Command(
    name="versions", help="the version matrix: each engine release in its own environment",
    example="dyncheck versions --engine mujoco   |   dyncheck versions --bisect mujoco 3.3.7 "
    "4.0.0   |   dyncheck versions my_robot.xml --engine mujoco --release 3.3.7 --release "
    "4.0.0",
    arguments=_arguments, handler=versions_command)
