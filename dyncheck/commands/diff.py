"""``dyncheck diff``: what moved between two runs."""

from __future__ import annotations

import argparse

from dyncheck.commands.flags import Command
from dyncheck.commands.options import (
    check_out_file,
    path_arg,
)


def diff_command(args: argparse.Namespace) -> int:
    """Exit 1 when any row moved; 0 when every row is unchanged."""
    import dataclasses

    from dyncheck import baseline, diff
    from dyncheck.results import write_atomic

    factor = diff.FACTOR if args.tolerance is None else args.tolerance
    diff.check_factor(factor)
    if args.markdown is not None:
        read = [p for side in (args.run_a, args.run_b) for p in (
            (side,) if not side.is_dir() else tuple(side.glob("*.csv")) + tuple(
                side.glob("*.json")))]
        check_out_file("--markdown", args.markdown, read)
    sides = []
    for flag, path in (("RUN_A", args.run_a), ("RUN_B", args.run_b)):
        side = diff.load(path, flag)
        if path.is_file() and not side.versions:
            side = dataclasses.replace(side, versions=baseline.versions_of(path))
        sides.append(side)
    a, b = sides
    table = diff.diff(a, b, factor=factor)
    counts = diff.summary(table)
    print(diff.text(a, b, table, factor=factor, every=args.all).rstrip())
    if args.markdown is not None:
        write_atomic(args.markdown, diff.markdown(a, b, table, factor=factor, every=args.all))
    return 0 if counts[diff.Move.UNCHANGED] == len(table) else 1


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run_a", type=path_arg, metavar="RUN_A",
                   help="output folder of `run` or `check` (or a baseline CSV): the old side")
    p.add_argument("run_b", type=path_arg, metavar="RUN_B", help="the new side, same kind")
    p.add_argument("--tolerance", type=float, default=None, metavar="FACTOR",
                   help="an error above its tolerance moved when it changed by more than this "
                        "factor (default 10)")
    p.add_argument("--markdown", type=path_arg, default=None, metavar="FILE",
                   help="also write the diff as a Markdown page")
    p.add_argument("--all", action="store_true", help="list unchanged rows too")


COMMAND = Command(
    name="diff", help="what moved between two runs (engine upgrade, code change)",
    example="dyncheck diff reports /tmp/report_after_upgrade --markdown /tmp/diff.md",
    arguments=_arguments, handler=diff_command)
