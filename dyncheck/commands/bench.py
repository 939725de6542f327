"""``dyncheck bench``: speed against the engines."""

from __future__ import annotations

import argparse

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import (
    BENCH_MAX,
    OUT,
    check_out,
    claim_out,
    path_arg,
    positive,
)

MEMORY_DEFAULT_MOST = 1_000_000
"""The largest memory sweep ``bench`` measures unless asked (the committed benchmark's)."""


def bench_command(args: argparse.Namespace) -> int:
    from dyncheck.bench import engines as bench
    from dyncheck.cases import get_case

    check_out(args.out)
    if args.suite:
        from dyncheck.errors import NeedsCheckout

        NeedsCheckout.unless_checkout("dyncheck bench --suite (it times the README's commands "
                                      "in the checkout)")
        claim_out(args.out)
        from dyncheck.bench import suite as bench_suite

        print(bench_suite.main(args.out))
        return 0
    get_case(args.case)
    positive("--states", args.states, BENCH_MAX["--states"])
    positive("--repeats", args.repeats, BENCH_MAX["--repeats"])
    if args.memory is None:  # the default follows --states: the sweep's size and ten times it
        args.memory = sorted({min(n, MEMORY_DEFAULT_MOST) for n in (args.states, 10 * args.states)})
    for n in args.memory:
        positive("--memory", n, BENCH_MAX["--memory"])
    claim_out(args.out)
    positive("--jobs", args.jobs)
    print(bench.main(args.case, args.states, args.repeats, args.memory, args.out,
                     jobs=args.jobs, dask=args.dask, quiet=args.quiet))
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("case", nargs="?", default="compound_pendulum", metavar="CASE")
    p.add_argument("--states", type=int, default=100_000, metavar="N")
    p.add_argument("--repeats", type=int, default=3, metavar="R")
    p.add_argument(
        "--memory",
        type=int,
        nargs="*",
        default=None,
        metavar="N",
        help="sweep sizes whose peak memory is measured in fresh processes (default: --states "
        f"and ten times it, each at most {MEMORY_DEFAULT_MOST}; none given: none measured)",
    )
    p.add_argument("--out", type=path_arg, default=OUT,
                   help=f"report folder (default: {OUT}; the committed benchmark: --out "
                   "reports)")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="also time the sweep in slices on N processes against this one "
                   "(the same rows, checked)")
    flags.dask(p)
    p.add_argument("--suite", action="store_true",
                   help="instead: time the commands a user runs (list, explain, one case, the "
                   "full run, the README's main command with its install, report --check, "
                   "the test commands) in fresh processes -> benchmark-suite.md")
    flags.quiet(p)


COMMAND = Command(
    name="bench", help="time the engines, adapters, reference and a sweep",
    example="dyncheck bench compound_pendulum --states 100000",
    arguments=_arguments, handler=bench_command)
