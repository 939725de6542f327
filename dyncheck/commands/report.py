"""``dyncheck report --check``: the committed report against the code."""

from __future__ import annotations

import argparse
from pathlib import Path

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import (
    path_arg,
    positive,
)
from dyncheck.errors import InvalidInput

SHOWN = 20
"""Moved results listed by `report --check` (the rest counted)."""


def report_command(args: argparse.Namespace) -> int:
    from dyncheck import report_check
    from dyncheck.explain import catalogue
    from dyncheck.report import folder as report
    from dyncheck.run import resolve, run

    positive("--jobs", args.jobs)
    for flag, folder in (("--out", args.out), ("--from", args.run_dir)):
        if folder is not None and not folder.is_dir():
            raise InvalidInput(flag, str(folder), "an existing report folder")
        if folder is not None and not (folder / "discrepancies.csv").is_file():
            raise InvalidInput(flag, str(folder), "a report folder written by `dyncheck run` "
                               "(it has no discrepancies.csv)")
    committed = report_check.read_report(args.out)
    if args.run_dir is not None:
        fresh = report_check.read_report(args.run_dir)
        ran = report_check.ran_in(args.run_dir)
    else:
        cases, impls = resolve([], [], accelerators=args.accelerators)
        result = run(cases, impls, jobs=args.jobs, dask=args.dask,
                     conventions=catalogue.units(impls))
        fresh, ran = report.rendered_text(result, args.out), list(result.ran)
    old, new, left_out = (committed, fresh, []) if ran is None else report_check.narrowed(
        committed, fresh, ran)
    if left_out:
        print(f"not run here: {', '.join(left_out)}: their rows of {args.out} and the pages "
              "(each sums up every implementation) not compared")
    moved = report_check.compare(old, new)
    for m in moved[:SHOWN]:
        print(f"moved: {m}")
    if len(moved) > SHOWN:
        print(f"moved: ... and {len(moved) - SHOWN} more")
    print(
        "report up to date (results equal beyond round-off)"
        if not moved
        else f"{len(moved)} results moved: run `dyncheck run --out {args.out}` and commit"
    )
    return 1 if moved else 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--check",
        action="store_true",
        required=True,
        help="recompute every case and compare with the report folder",
    )
    p.add_argument("--out", type=path_arg, default=Path("reports"), help="report folder")
    flags.jobs(p, "cases")
    flags.dask(p)
    flags.no_cache(p)
    flags.accelerators(p)
    p.add_argument(
        "--from",
        dest="run_dir",
        type=path_arg,
        default=None,
        metavar="DIR",
        help="compare with the output folder of a finished `dyncheck run` instead of running",
    )


COMMAND = Command(
    name="report", help="check that the committed report matches the code",
    example="dyncheck report --check --from /tmp/report",
    arguments=_arguments, handler=report_command)
