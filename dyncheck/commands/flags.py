"""A command's record (:class:`Command`: its name, help, example, flags and handler, each in
the command's own module) and the flags several commands share."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass

from dyncheck.commands.options import path_arg
from dyncheck.workers import JOB_MEMORY, default_jobs


@dataclass(frozen=True, kw_only=True)
class Command:
    """One subcommand of ``dyncheck``: the command line (:mod:`dyncheck.__main__`) adds a parser
    per record, with ``arguments`` adding its flags and ``example`` under its ``--help``."""

    name: str
    help: str
    example: str
    arguments: Callable[[argparse.ArgumentParser], None]
    handler: Callable[[argparse.Namespace], int]


JOBS = (f"{default_jobs()}: this machine's usable cores, at most one per "
        f"{JOB_MEMORY // 2**30} GiB of memory")
"""The default of ``--jobs``, said in its help."""


def jobs(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"{what} in N parallel processes (same results; default: {JOBS})")


def selection(p: argparse.ArgumentParser) -> None:
    """The cases and implementations of ``run`` and ``baseline``."""
    p.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    p.add_argument(
        "--impl",
        action="append",
        default=[],
        metavar="NAME",
        help=f"implementation to include: {', '.join(_run_names())} (repeatable; default: "
        "every one but the engines built for accelerators); the catalogue's entries that need "
        "an engine left out say so",
    )
    accelerators(p)
    jobs(p, "cases")
    dask(p)
    no_cache(p)


def _run_names() -> tuple[str, ...]:
    """What ``run --impl`` takes: the book's solutions, the referee, each registered engine."""
    from dyncheck.roster import IMPLEMENTATIONS

    return IMPLEMENTATIONS


def impl_help() -> str:
    """``check --impl``'s help, from the registry: the engines that load a user's file, and
    which of them are checked only when named (:attr:`Registration.on_request`)."""
    from dyncheck.adapters import MODELS
    from dyncheck.vocabulary import REFEREE

    named = [n for n, r in MODELS.items() if r.on_request]
    default = [REFEREE, *(n for n in MODELS if n not in named)]
    return (f"{', '.join([REFEREE, *MODELS])} (repeatable; default: {', '.join(default)}; "
            f"{', '.join(named)} only when named)")


def accelerators(p: argparse.ArgumentParser) -> None:
    from dyncheck.adapters import ACCELERATORS

    p.add_argument("--accelerators", action="store_true",
                   help=f"also run the engines built for accelerators ({', '.join(ACCELERATORS)}"
                   "): minutes on a CPU, where they compile every case; on a GPU add "
                   "--device cuda")


def no_cache(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--no-cache",
        action="store_true",
        help="derive every symbolic result (measure every demonstration, solve every "
        "reference, draw every figure) afresh, neither reading nor writing the cache (under "
        "$DYNCHECK_CACHE or ~/.cache/dyncheck)",
    )


def quiet(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quiet", action="store_true",
                   help="no progress on stderr (by default: a live bar on a terminal, one line "
                   "per finished unit in a log)")


def ci(p: argparse.ArgumentParser) -> None:
    p.add_argument("--junit", type=path_arg, default=None, metavar="FILE",
                   help="also write the rows as JUnit XML (one test suite per case or model, "
                   "one test case per quantity and pair) for a CI system to show")
    p.add_argument("--json", type=path_arg, default=None, metavar="FILE",
                   help="also write a JSON summary: the counts, each case's or model's, every "
                   "row, in the format of the JSON Schema dyncheck ships (results.schema.json, "
                   "its schema_version in the file); '-': to standard output, the command's "
                   "other lines to standard error")


def dask(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--dask",
        default=None,
        metavar="ADDRESS",
        help="run the units of work on a dask.distributed cluster: a scheduler address "
        "(tcp://HOST:8786) or 'local' for a LocalCluster of --jobs workers (same results; "
        "the extra 'dask')",
    )
