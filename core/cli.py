"""The ``dyncheck`` command line: ``list``, ``run`` and ``bench``.

Exit status: 0 when nothing failed unexplained, 1 when a check failed, 2 for bad usage or
bad input (a one-line message naming the argument and the value).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from dyncheck.errors import DyncheckError, InvalidInput


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="dyncheck", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="cases and implementations, with installed engine versions")
    r = sub.add_parser("run", help="compare implementations on cases and write the report")
    r.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    r.add_argument(
        "--impl",
        action="append",
        default=[],
        metavar="NAME",
        help="implementation to include (repeatable; default: all)",
    )
    r.add_argument("--out", type=Path, default=Path("reports"), help="report folder")
    r.add_argument(
        "--states",
        type=int,
        default=None,
        metavar="N",
        help="sampled states per case (default: each case's own, 16)",
    )
    b = sub.add_parser("bench", help="time the engines, adapters, reference and a sweep")
    b.add_argument("case", nargs="?", default="compound_pendulum", metavar="CASE")
    b.add_argument("--states", type=int, default=100_000, metavar="N")
    b.add_argument("--repeats", type=int, default=3, metavar="R")
    b.add_argument(
        "--memory",
        type=int,
        nargs="*",
        default=[100_000, 1_000_000],
        metavar="N",
        help="sweep sizes whose peak memory is measured in fresh processes",
    )
    b.add_argument("--out", type=Path, default=Path("reports"), help="report folder")
    return p


def _bench(args: argparse.Namespace) -> int:
    from dyncheck import bench
    from dyncheck.cases import get_case

    _check_out(args.out)
    get_case(args.case)
    for name in ("states", "repeats"):
        if getattr(args, name) < 1:
            raise InvalidInput(f"--{name}", getattr(args, name), "a positive integer")
    print(bench.main(args.case, args.states, args.repeats, args.memory, args.out))
    return 0


def _list() -> int:
    from dyncheck.adapters import ADAPTERS, ENGINE_PACKAGES, MISSING
    from dyncheck.cases import CASES
    from dyncheck.implementations import IMPLEMENTATIONS

    print("cases:")
    for name, cls in CASES.items():
        print(f"  {name:20s} {cls.title}")
    print("implementations:")
    for name in IMPLEMENTATIONS:
        if name in ADAPTERS:
            what = f"{ENGINE_PACKAGES[name]} {ADAPTERS[name].version()}"
        elif name in MISSING:
            what = f"not installed: pip install {ENGINE_PACKAGES[name]}"
        else:
            what = (
                "dyncheck.reference (book printed equations)"
                if name == "book"
                else "dyncheck.reference (general method, (2.2.23)-(2.2.26))"
            )
        print(f"  {name:20s} {what}")
    return 0


def _check_out(out: Path) -> None:
    """--out must be a directory, or creatable: its nearest existing ancestor a writable
    directory (checked before any work, so bad usage changes nothing)."""
    if out.exists() and not out.is_dir():
        raise InvalidInput("--out", str(out), "a directory")
    probe = out if out.exists() else next((p for p in out.parents if p.exists()), Path("."))
    if not probe.is_dir():
        raise InvalidInput("--out", str(out), f"a directory path ({probe} is a file)")
    if not os.access(probe, os.W_OK):
        raise InvalidInput("--out", str(out), "a writable directory")


def _run(args: argparse.Namespace) -> int:
    from dyncheck import report
    from dyncheck.run import resolve, run

    _check_out(args.out)
    cases, impls = resolve(args.cases, args.impl)
    if args.states is not None and args.states < 1:
        raise InvalidInput("--states", args.states, "a positive integer")
    result = run(cases, impls, states=args.states, progress=report.stderr_progress)
    report.write(result, args.out)
    counts = result.discrepancies["verdict"].value_counts()
    print(
        ", ".join(f"{counts.get(v, 0)} {v}" for v in ("passed", "explained", "failed", "skipped"))
        + f"; report in {args.out}/README.md"
    )
    return 1 if result.failed else 0


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "list":
            return _list()
        if args.command == "bench":
            return _bench(args)
        return _run(args)
    except DyncheckError as exc:
        print(f"dyncheck: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
