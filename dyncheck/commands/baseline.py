"""``dyncheck baseline``: the rows a later run is held to."""

from __future__ import annotations

import argparse

from dyncheck.commands.options import (
    check_out_file,
    positive,
)


def baseline_command(args: argparse.Namespace) -> int:
    """Write the baseline; show what changed against the previous one."""
    from dyncheck import baseline, report
    from dyncheck.run import resolve, run

    check_out_file("--out", args.out)
    positive("--jobs", args.jobs)
    cases, impls = resolve(args.cases, args.impl, accelerators=args.accelerators)
    previous = baseline.load(args.out, "--out") if args.out.exists() else None  # validated first
    result = run(cases, impls, jobs=args.jobs, dask=args.dask)
    if previous is not None:
        changes = baseline.compare(result.discrepancies, previous, cases=[c.name for c in cases])
        print(changes.to_string(index=False) if len(changes) else "no change")
    baseline.write(result.discrepancies, args.out, versions=report.versions(result.engines))
    print(f"baseline written to {args.out} ({len(result.discrepancies)} rows)")
    return 0
