"""The ``dyncheck`` command line: ``list``, ``run``, ``report``, ``explain``, ``baseline`` and
``bench``.

Exit status: 0 when nothing failed unexplained, 1 when a check failed (or regressed against a
baseline, or the committed report is stale), 2 for bad usage or bad input (a one-line message
naming the argument and the value).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from dyncheck.errors import DyncheckError, InvalidInput


def _selection(p: argparse.ArgumentParser) -> None:
    p.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    p.add_argument(
        "--impl",
        action="append",
        default=[],
        metavar="NAME",
        help="implementation to include (repeatable; default: all)",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        metavar="N",
        help="cases in N parallel processes (same results)",
    )


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="dyncheck", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="cases and implementations, with installed engine versions")
    r = sub.add_parser("run", help="compare implementations on cases and write the report")
    _selection(r)
    r.add_argument("--out", type=Path, default=Path("reports"), help="report folder")
    r.add_argument(
        "--states",
        type=int,
        default=None,
        metavar="N",
        help="sampled states per case (default: each case's own, 16)",
    )
    r.add_argument(
        "--baseline",
        type=Path,
        default=None,
        metavar="FILE",
        help="report every row that regressed against this baseline (exit 1)",
    )
    c = sub.add_parser("report", help="check that the committed report matches the code")
    c.add_argument(
        "--check",
        action="store_true",
        required=True,
        help="recompute every case and compare with the report folder",
    )
    c.add_argument("--out", type=Path, default=Path("reports"), help="report folder")
    c.add_argument("--jobs", type=int, default=1, metavar="N")
    e = sub.add_parser("explain", help="demonstrate a modelling convention (all if none)")
    e.add_argument("name", nargs="?", default=None, metavar="NAME")
    bl = sub.add_parser("baseline", help="run and write the regression baseline")
    _selection(bl)
    bl.add_argument("--out", type=Path, default=Path("reports/baseline.csv"), metavar="FILE")
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


def _list() -> int:
    from dyncheck.adapters import ADAPTERS, ENGINE_PACKAGES, MISSING
    from dyncheck.cases import CASES
    from dyncheck.implementations import IMPLEMENTATIONS

    print("cases:")
    for name, cls in CASES.items():
        print(f"  {name:24s} {cls.title}")
    print("implementations:")
    for name in IMPLEMENTATIONS:
        if name in ADAPTERS:
            adapter = ADAPTERS[name]
            steps = list(adapter.integrators)
            if adapter.adaptive:
                steps.append("dop853 (scipy, error-controlled)")
            if hasattr(adapter, "simulate_controlled"):
                steps.append("rk3-controlled (its own runge_kutta3, error-controlled)")
            what = f"{ENGINE_PACKAGES[name]} {adapter.version()}; integrators: {', '.join(steps)}"
        elif name in MISSING:
            what = f"not installed: pip install {ENGINE_PACKAGES[name]}"
        elif name == "book":
            what = "dyncheck.reference (book printed equations)"
        else:
            what = "dyncheck.reference (general method, (2.2.23)-(2.2.26))"
        print(f"  {name:24s} {what}")
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


def _positive(name: str, value: int | None) -> None:
    if value is not None and value < 1:
        raise InvalidInput(name, value, "a positive integer")


def _run(args: argparse.Namespace) -> int:
    from dyncheck import baseline, report
    from dyncheck.run import resolve, run

    _check_out(args.out)
    _positive("--states", args.states)
    _positive("--jobs", args.jobs)
    reference = baseline.load(args.baseline) if args.baseline is not None else None
    cases, impls = resolve(args.cases, args.impl)
    result = run(cases, impls, states=args.states, jobs=args.jobs, progress=report.stderr_progress)
    report.write(result, args.out)
    counts = result.discrepancies["verdict"].value_counts()
    print(
        ", ".join(f"{counts.get(v, 0)} {v}" for v in ("passed", "explained", "failed", "skipped"))
        + f"; report in {args.out}/README.md"
    )
    regressed = False
    if reference is not None:
        changes = baseline.compare(result.discrepancies, reference, cases=[c.name for c in cases])
        regressed = len(changes) > 0
        print(
            f"{len(changes)} rows regressed against {args.baseline}"
            if regressed
            else f"no regression against {args.baseline}"
        )
        if regressed:
            print(changes.to_string(index=False))
    return 1 if result.failed or regressed else 0


def _report(args: argparse.Namespace) -> int:
    from dyncheck import report
    from dyncheck.run import resolve, run

    _positive("--jobs", args.jobs)
    cases, impls = resolve([], [])
    stale = report.check(run(cases, impls, jobs=args.jobs), args.out)
    for line in stale:
        print(f"stale: {line}")
    print(
        "report up to date"
        if not stale
        else f"{len(stale)} stale files: run `dyncheck run --out {args.out}` and commit"
    )
    return 1 if stale else 0


def _baseline(args: argparse.Namespace) -> int:
    """Write the baseline; show what changed against the previous one."""
    from dyncheck import baseline
    from dyncheck.run import resolve, run

    _check_out(args.out.parent)
    _positive("--jobs", args.jobs)
    cases, impls = resolve(args.cases, args.impl)
    result = run(cases, impls, jobs=args.jobs)
    if args.out.exists():
        changes = baseline.compare(
            result.discrepancies, baseline.load(args.out), cases=[c.name for c in cases]
        )
        print(changes.to_string(index=False) if len(changes) else "no change")
    baseline.write(result.discrepancies, args.out)
    print(f"baseline written to {args.out} ({len(result.discrepancies)} rows)")
    return 0


def _bench(args: argparse.Namespace) -> int:
    from dyncheck import bench
    from dyncheck.cases import get_case

    _check_out(args.out)
    get_case(args.case)
    _positive("--states", args.states)
    _positive("--repeats", args.repeats)
    print(bench.main(args.case, args.states, args.repeats, args.memory, args.out))
    return 0


def _explain(args: argparse.Namespace) -> int:
    from dyncheck.catalogue import explain, render

    print(render(explain(args.name)))
    return 0


COMMANDS = {
    "run": _run,
    "report": _report,
    "baseline": _baseline,
    "bench": _bench,
    "explain": _explain,
}


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "list":
            return _list()
        return COMMANDS[args.command](args)
    except DyncheckError as exc:
        print(f"dyncheck: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
