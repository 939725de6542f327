"""``dyncheck baseline``: the rows a later run is held to."""

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


def baseline_command(args: argparse.Namespace) -> int:
    """Write the baseline; show what changed against the previous one."""
    from dyncheck import baseline
    from dyncheck.provenance import versions
    from dyncheck.run import resolve, run

    check_out_file("--out", args.out)
    positive("--jobs", args.jobs)
    cases, impls = resolve(args.cases, args.impl, accelerators=args.accelerators)
    previous = baseline.load(args.out, "--out") if args.out.exists() else None  # validated first
    result = run(cases, impls, jobs=args.jobs, dask=args.dask)
    if previous is not None:
        changes = baseline.compare(result.discrepancies, previous, cases=[c.name for c in cases])
        print(changes.to_string(index=False) if len(changes) else "no change")
    baseline.write(result.discrepancies, args.out, versions=versions(result.engines))
    print(f"baseline written to {args.out} ({len(result.discrepancies)} rows)")
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    flags.selection(p)
    p.add_argument("--out", type=path_arg, default=Path("reports/baseline.csv"), metavar="FILE")


COMMAND = Command(
    name="baseline", help="run and write the regression baseline",
    example="dyncheck baseline --out reports/baseline.csv",
    arguments=_arguments, handler=baseline_command)
