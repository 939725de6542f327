"""``dyncheck bench``: speed against the engines."""

from __future__ import annotations

import argparse

from dyncheck.commands.options import (
    BENCH_MAX,
    check_out,
    claim_out,
    positive,
)


def bench_command(args: argparse.Namespace) -> int:
    from dyncheck import bench
    from dyncheck.cases import get_case

    check_out(args.out)
    if args.suite:
        claim_out(args.out)
        from dyncheck import bench_suite

        print(bench_suite.main(args.out))
        return 0
    get_case(args.case)
    positive("--states", args.states, BENCH_MAX["--states"])
    positive("--repeats", args.repeats, BENCH_MAX["--repeats"])
    for n in args.memory:
        positive("--memory", n, BENCH_MAX["--memory"])
    claim_out(args.out)
    positive("--jobs", args.jobs)
    print(bench.main(args.case, args.states, args.repeats, args.memory, args.out,
                     jobs=args.jobs, dask=args.dask, quiet=args.quiet))
    return 0
