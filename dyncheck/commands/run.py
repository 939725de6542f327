"""``dyncheck run``: every case compared, the report written."""

from __future__ import annotations

import argparse

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import (
    MAX_STATES,
    OUT,
    check_out,
    ci_files,
    claim_out,
    path_arg,
    positive,
    warn_cost,
    write_ci,
)
from dyncheck.errors import InvalidInput
from dyncheck.roster import not_run
from dyncheck.vocabulary import Verdict


def run_command(args: argparse.Namespace) -> int:
    from dyncheck import baseline
    from dyncheck.explain import catalogue
    from dyncheck.provenance import versions
    from dyncheck.report import folder as report
    from dyncheck.report.figures import cached_figures as draw_figures
    from dyncheck.run import resolve, run

    check_out(args.out)
    ci_files(args)
    positive("--states", args.states)
    if args.states is not None and args.states > MAX_STATES:
        raise InvalidInput("--states", args.states, f"at most {MAX_STATES} (~50 µs per state)")
    positive("--jobs", args.jobs)
    reference = baseline.load(args.baseline) if args.baseline is not None else None
    cases, impls = resolve(args.cases, args.impl, accelerators=args.accelerators)
    claim_out(args.out)  # every option checked: the folder held for this command
    if args.states is not None:
        warn_cost(args.states * len(cases), args.jobs)
    # the conventions catalogue does not depend on the cases: it runs with the full report
    from dyncheck.progress import Progress

    with Progress("run", quiet=args.quiet) as progress:
        result = run(cases, impls, states=args.states, jobs=args.jobs, dask=args.dask,
                     conventions=None if args.cases else catalogue.units(impls),
                     progress=progress, render=draw_figures)
    report.write(result, args.out)
    from dyncheck.ci_outputs import RUN, WHOLE, split

    write_ci(args, split(result.discrepancies, RUN), RUN, versions(result.engines),
             seconds={case: {WHOLE: t} for case, t in result.seconds.items()})
    counts = result.discrepancies["verdict"].value_counts()
    left_out = None if args.impl else not_run(impls)  # (what --impl names is chosen)
    if left_out is not None:
        print(left_out)
    print(
        ", ".join(f"{counts.get(v, 0)} {v}" for v in Verdict)
        + f"; report in {args.out}/README.md"
    )
    regressed = False
    if reference is not None:
        changes = baseline.compare(result.discrepancies, reference,
                                   cases=[c.name for c in cases], impls=impls)
        regressed = len(changes) > 0
        print(
            f"{len(changes)} rows regressed against {args.baseline}"
            if regressed
            else f"no regression against {args.baseline}"
        )
        moved = baseline.version_changes(args.baseline, versions(result.engines))
        print(
            "versions changed since the baseline: " + ", ".join(moved)
            if moved
            else "same engine versions as the baseline (a regression is a change of code)"
        )
        if regressed:
            print(changes.to_string(index=False))
    return 1 if result.failed or regressed else 0


def _arguments(p: argparse.ArgumentParser) -> None:
    flags.selection(p)
    p.add_argument("--out", type=path_arg, default=OUT,
                   help=f"report folder (default: {OUT}; the committed report: --out reports)")
    p.add_argument("--device", choices=("cpu", "cuda"), default=None,
                   help="where MuJoCo's ports (MJX, MuJoCo Warp) compute (default: the CPU "
                   "for Warp, JAX's default device for MJX); named in the provenance")
    p.add_argument(
        "--states",
        type=int,
        default=None,
        metavar="N",
        help="sampled states per case (default: each case's own, 16)",
    )
    p.add_argument(
        "--baseline",
        type=path_arg,
        default=None,
        metavar="FILE",
        help="report every row that regressed against this baseline (exit 1)",
    )
    flags.ci(p)
    flags.quiet(p)


COMMAND = Command(
    name="run", help="compare implementations on cases and write the report",
    example="dyncheck run simple_pendulum --impl reference --impl mujoco --out /tmp/report",
    arguments=_arguments, handler=run_command)
