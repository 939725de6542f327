"""``dyncheck explain``: the conventions catalogue, and an engine defect's reproducer."""

from __future__ import annotations

import argparse
from pathlib import Path

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import (
    check_out_file,
    path_arg,
    positive,
)
from dyncheck.errors import InvalidInput
from dyncheck.workers import default_jobs


def explain_command(args: argparse.Namespace) -> int:
    from dyncheck.explain.catalogue import explain_cached, render

    if args.name is not None and args.name.startswith("erratum-"):
        from dyncheck.errata import page

        print(page.explain(args.name.removeprefix("erratum-")))
        return 0
    positive("--jobs", args.jobs)
    if args.reproducer is not None:
        return _reproducer(args.name, args.reproducer)
    entries, read_back = explain_cached(args.name, accelerators=args.accelerators,
                                        jobs=args.jobs)
    print(render(entries))
    if read_back:
        print(f"({read_back} of {len(entries)} measured by an earlier `dyncheck explain` with "
              "the same dyncheck, engines and machine, read from the cache; --no-cache "
              "measures afresh)")
    return 1 if any(e.failed for e in entries) else 0


def _reproducer(name: str | None, out: Path) -> int:
    """``explain NAME --reproducer FILE``: the entry's standalone script, written whole."""
    from dyncheck.escaping import shown  # (pandas: not on `dyncheck list`'s path)
    from dyncheck.explain.reproducers import REPRODUCERS
    from dyncheck.results import write_atomic

    if name is None or name not in REPRODUCERS:
        raise InvalidInput("--reproducer", str(name), "given with a convention that is an "
                           f"engine's defect: one of {', '.join(REPRODUCERS)}")
    check_out_file("--reproducer", out)
    found = REPRODUCERS[name]
    write_atomic(out, found.script)
    print(f"wrote {shown(str(out))}: `python {shown(str(out))}` needs only {found.engine} and "
          "numpy; it prints the expected and the observed value and exits 1 while the defect "
          "stands")
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", nargs="?", default=None, metavar="NAME")
    p.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"entries measured in N parallel processes (default: {flags.JOBS})")
    p.add_argument("--reproducer", type=path_arg, default=None, metavar="FILE",
                   help="write NAME's standalone script for the engine's issue tracker "
                   "instead (its engine, numpy and an inline model; exits 1 while the defect "
                   "stands)")
    flags.accelerators(p)
    flags.no_cache(p)


COMMAND = Command(
    name="explain", help="demonstrate a modelling convention (all if none)",
    example="dyncheck explain quaternion-storage-order",
    arguments=_arguments, handler=explain_command)
