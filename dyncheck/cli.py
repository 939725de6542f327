"""The ``dyncheck`` command line: ``list``, ``run``, ``check``, ``diff``, ``versions``,
``tutorials``, ``report``, ``explain``, ``errata``, ``baseline`` and ``bench``.

Exit status: 0 when nothing failed unexplained, 1 when a check failed (or regressed against a
baseline, or the committed report is stale), 2 for bad usage or bad input (a one-line message
naming the argument and the value).

Here: every subcommand's flags, help and example, read in one place; each command's handler
(which validates its arguments before any work and calls the module that does it) is in
:mod:`dyncheck.commands`, one module per command.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn, TextIO

from dyncheck.commands.baseline import baseline_command
from dyncheck.commands.bench import bench_command
from dyncheck.commands.check import check_command
from dyncheck.commands.diff import diff_command
from dyncheck.commands.explain import errata_command, explain_command
from dyncheck.commands.listing import list_command
from dyncheck.commands.options import one_line, path_arg
from dyncheck.commands.report import report_command
from dyncheck.commands.run import run_command
from dyncheck.commands.tutorials import tutorials_command
from dyncheck.commands.versions import versions_command
from dyncheck.errors import DyncheckError, InvalidInput, Terminated
from dyncheck.workers import JOB_MEMORY, default_jobs


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``dyncheck: error: …``, exit 2), no usage dump."""

    def error(self, message: str) -> NoReturn:
        where = self.prog.removeprefix("dyncheck").strip()
        print(f"dyncheck: error: {where + ': ' if where else ''}{message}", file=sys.stderr)
        raise SystemExit(2)


_JOBS = (f"{default_jobs()}: this machine's usable cores, at most one per "
         f"{JOB_MEMORY // 2**30} GiB of memory")


def _selection(p: argparse.ArgumentParser) -> None:
    p.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    p.add_argument(
        "--impl",
        action="append",
        default=[],
        metavar="NAME",
        help="implementation to include (repeatable; default: every one but the engines "
        "built for accelerators); the catalogue's entries that need an engine left out say "
        "so",
    )
    _accelerators(p)
    p.add_argument(
        "--jobs",
        type=int,
        default=default_jobs(),
        metavar="N",
        help=f"cases in N parallel processes (same results; default: {_JOBS})",
    )
    _dask(p)
    _no_cache(p)

def _accelerators(p: argparse.ArgumentParser) -> None:
    from dyncheck.adapters import ACCELERATORS

    p.add_argument("--accelerators", action="store_true",
                   help=f"also run the engines built for accelerators ({', '.join(ACCELERATORS)}"
                   "): minutes on a CPU, where they compile every case; on a GPU add "
                   "--device cuda")


def _no_cache(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--no-cache",
        action="store_true",
        help="derive every symbolic result (measure every demonstration, solve every "
        "reference, draw every figure) afresh, neither reading nor writing the cache (under "
        "$DYNCHECK_CACHE or ~/.cache/dyncheck)",
    )


def _quiet(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quiet", action="store_true",
                   help="no progress on stderr (by default: a live bar on a terminal, one line "
                   "per finished unit in a log)")


def _ci(p: argparse.ArgumentParser) -> None:
    p.add_argument("--junit", type=path_arg, default=None, metavar="FILE",
                   help="also write the rows as JUnit XML (one test suite per case or model, "
                   "one test case per quantity and pair) for a CI system to show")
    p.add_argument("--json", type=path_arg, default=None, metavar="FILE",
                   help="also write a JSON summary: the counts, each case's or model's, every "
                   "row")


def _dask(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--dask",
        default=None,
        metavar="ADDRESS",
        help="run the units of work on a dask.distributed cluster: a scheduler address "
        "(tcp://HOST:8786) or 'local' for a LocalCluster of --jobs workers (same results; "
        "the extra 'dask')",
    )


def _parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="dyncheck",
        description="A textbook's tensor dynamics (its general method and printed equations) "
        "against MuJoCo, Pinocchio and Drake: every discrepancy measured and explained.",
        epilog="exit status: 0 nothing failed unexplained; 1 a check failed, regressed or "
        "moved; 2 bad usage or input (one line naming the argument and value). "
        "`dyncheck COMMAND --help` shows an example of each command.",
    )
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    ls = sub.add_parser("list", help="cases and implementations, with installed engine versions")
    ls.add_argument(
        "--integrators",
        action="store_true",
        help="import each engine: its integrators and, for the ports, the device (slower: "
        "JAX and Warp take seconds to import)",
    )
    r = sub.add_parser("run", help="compare implementations on cases and write the report")
    _selection(r)
    r.add_argument("--out", type=path_arg, default=Path("reports"), help="report folder")
    r.add_argument("--device", choices=("cpu", "cuda"), default=None,
                   help="where MuJoCo's ports (MJX, MuJoCo Warp) compute (default: the CPU "
                   "for Warp, JAX's default device for MJX); named in the provenance")
    r.add_argument(
        "--states",
        type=int,
        default=None,
        metavar="N",
        help="sampled states per case (default: each case's own, 16)",
    )
    r.add_argument(
        "--baseline",
        type=path_arg,
        default=None,
        metavar="FILE",
        help="report every row that regressed against this baseline (exit 1)",
    )
    _ci(r)
    _quiet(r)
    k = sub.add_parser(
        "check",
        help="do the engines read YOUR model alike and compute the same dynamics (and "
        "derivatives)?",
    )
    k.add_argument("paths", nargs="*", type=path_arg, metavar="PATH",
                   help="MJCF (.xml) or URDF files, or folders (every model file under "
                   "them; files another one includes left out); several: an index page too")
    k.add_argument("--robot", action="append", default=[], metavar="NAME",
                   help="a robot of example-robot-data (extra 'robots'; see `dyncheck list`; "
                   "'all': every one)")
    k.add_argument("--case", action="append", default=[], metavar="CASE",
                   help="a book case's MJCF, the file `run` gives MuJoCo (repeatable; 'all': "
                   "every case)")
    k.add_argument("--impl", action="append", default=[], metavar="NAME",
                   help="reference, mujoco, pinocchio, drake, MuJoCo's ports mjx, mjx-f64, "
                   "mujoco-warp, and newton, pybullet (repeatable; default: the first four; the "
                   "others only when named)")
    k.add_argument("--states", type=int, default=100, metavar="N", help="sampled states")
    k.add_argument("--seed", type=int, default=0, metavar="S")
    k.add_argument("--floating", action="store_true",
                   help="a URDF's root link is a free body (a free joint in every engine)")
    k.add_argument("--derivatives", action="store_true",
                   help="also compare the derivatives of the dynamics (d(forward)/d(q, v, tau), "
                   "d(inverse)/d(q, v)) of every engine that offers them with the referee's")
    k.add_argument("--against", type=path_arg, default=None, metavar="PATH",
                   help="also compare what MuJoCo reads with this other file (a previous version)")
    k.add_argument("--out", type=path_arg, default=Path("reports/check"), help="output folder")
    k.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"models checked in N parallel processes (same results; default: "
                   f"{_JOBS})")
    _dask(k)
    _ci(k)
    _quiet(k)
    _no_cache(k)
    k.add_argument("--engine-memory", type=int, default=None, metavar="MIB",
                   help="address space each engine process may use (default 8192 MiB; 0: no "
                   "cap; MuJoCo's ports are never capped)")
    k.add_argument("--engine-seconds", type=float, default=None, metavar="S",
                   help="base time limit of an engine's load and of each batch of states "
                   "(default 120 s), scaled up with the file's size and states x dofs^2")
    k.add_argument("--in-process", action="store_true",
                   help="load the engines in this process (faster start; an engine that "
                   "crashes on the file then ends the check)")
    d = sub.add_parser("diff", help="what moved between two runs (engine upgrade, code change)")
    d.add_argument("run_a", type=path_arg, metavar="RUN_A",
                   help="output folder of `run` or `check` (or a baseline CSV): the old side")
    d.add_argument("run_b", type=path_arg, metavar="RUN_B", help="the new side, same kind")
    d.add_argument("--tolerance", type=float, default=None, metavar="FACTOR",
                   help="an error above its tolerance moved when it changed by more than this "
                        "factor (default 10)")
    d.add_argument("--markdown", type=path_arg, default=None, metavar="FILE",
                   help="also write the diff as a Markdown page")
    d.add_argument("--all", action="store_true", help="list unchanged rows too")
    v = sub.add_parser(
        "versions", help="the version matrix: each engine release in its own environment")
    v.add_argument("--engine", action="append", default=[], metavar="NAME",
                   help="mujoco, pinocchio, drake, newton, pybullet (repeatable; default: "
                   "all)")
    v.add_argument("--case", action="append", default=[], metavar="CASE",
                   help="cases to run (repeatable; default: all)")
    v.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"each release's run in N parallel processes (default: {_JOBS})")
    v.add_argument("--bisect", nargs=3, default=None, metavar=("ENGINE", "GOOD", "BAD"),
                   help="name the first release between GOOD and BAD whose results moved")
    v.add_argument("--reuse", action="store_true",
                   help="reuse each release's newest cached run, whatever code made it")
    v.add_argument("--out", type=path_arg, default=Path("reports/versions.md"), metavar="FILE")
    _quiet(v)
    t = sub.add_parser("tutorials", help="execute the tutorials and render them to Markdown")
    t.add_argument("names", nargs="*", metavar="NAME", help="tutorials (default: all)")
    t.add_argument("--out", type=path_arg, default=Path("reports/tutorials"), help="output folder")
    _quiet(t)
    c = sub.add_parser("report", help="check that the committed report matches the code")
    c.add_argument(
        "--check",
        action="store_true",
        required=True,
        help="recompute every case and compare with the report folder",
    )
    c.add_argument("--out", type=path_arg, default=Path("reports"), help="report folder")
    c.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"cases in N parallel processes (same results; default: {_JOBS})")
    _dask(c)
    _no_cache(c)
    _accelerators(c)
    c.add_argument(
        "--from",
        dest="run_dir",
        type=path_arg,
        default=None,
        metavar="DIR",
        help="compare with the output folder of a finished `dyncheck run` instead of running",
    )
    e = sub.add_parser("explain", help="demonstrate a modelling convention (all if none)")
    e.add_argument("name", nargs="?", default=None, metavar="NAME")
    e.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                   help=f"entries measured in N parallel processes (default: {_JOBS})")
    e.add_argument("--reproducer", type=path_arg, default=None, metavar="FILE",
                   help="write NAME's standalone script for the engine's issue tracker "
                   "instead (its engine, numpy and an inline model; exits 1 while the defect "
                   "stands)")
    _accelerators(e)
    _no_cache(e)
    er = sub.add_parser("errata", help="check every formula of §2.2 and write the errata page")
    er.add_argument("--out", type=path_arg, default=Path("reports/errata.md"),
                    metavar="FILE")
    bl = sub.add_parser("baseline", help="run and write the regression baseline")
    _selection(bl)
    bl.add_argument("--out", type=path_arg, default=Path("reports/baseline.csv"), metavar="FILE")
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
    b.add_argument("--out", type=path_arg, default=Path("reports"), help="report folder")
    b.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="also time the sweep in slices on N processes against this one "
                   "(the same rows, checked)")
    _dask(b)
    b.add_argument("--suite", action="store_true",
                   help="instead: time the commands a user runs (list, explain, one case, the "
                   "full run, the README's main command with its install, report --check, "
                   "the test commands) in fresh processes -> benchmark-suite.md")
    _quiet(b)
    for name, example in EXAMPLES.items():
        sub.choices[name].epilog = f"example: {example}"
    return p


EXAMPLES = {
    "errata": "dyncheck errata && dyncheck explain erratum-action-integral.d5",
    "list": "dyncheck list --integrators",
    "run": "dyncheck run simple_pendulum --impl reference --impl mujoco --out /tmp/report",
    "check": "dyncheck check my_robot.urdf --floating --states 1000",
    "diff": "dyncheck diff reports /tmp/report_after_upgrade --markdown /tmp/diff.md",
    "versions": "dyncheck versions --engine mujoco   |   dyncheck versions --bisect mujoco 3.3.7 "
    "4.0.0",
    "tutorials": "dyncheck tutorials 01_quaternion_order --out /tmp/tutorials",
    "report": "dyncheck report --check --from /tmp/report",
    "explain": "dyncheck explain quaternion-storage-order",
    "baseline": "dyncheck baseline --out reports/baseline.csv",
    "bench": "dyncheck bench compound_pendulum --states 100000",
}
"""One example per subcommand, printed under its --help."""


COMMANDS = {
    "run": run_command,
    "check": check_command,
    "report": report_command,
    "diff": diff_command,
    "versions": versions_command,
    "tutorials": tutorials_command,
    "baseline": baseline_command,
    "bench": bench_command,
    "explain": explain_command,
    "errata": errata_command,
}


def main(argv: Sequence[str] | None = None) -> int:
    from dyncheck.workers import on_sigterm, scratch

    deep_walks()
    with on_sigterm(), scratch():
        return _main(argv)


def deep_walks() -> None:
    """Python's recursion limit raised for the model walks, which recurse body by body, so
    that a tree :data:`~dyncheck.check.inputs.MAX_NESTING` deep is walked (3.11's
    Python-to-Python calls take no C stack); deeper ones are refused up front."""
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))


def _address_space(args: argparse.Namespace) -> None:
    """A limit on this process's address space (``ulimit -v``) below what the command needs
    (:data:`dyncheck.confinement.FLOOR_MIB`, measured) is refused before any work: the engines
    would otherwise abort in C++ (``std::bad_alloc``, exit 134) or fail their rows as if the
    model were at fault."""
    from dyncheck.confinement import address_space_mib, floor_mib

    have = address_space_mib()
    need = floor_mib(args.command, tuple(getattr(args, "impl", ()) or ()))
    if have is not None and need is not None and have < need:
        raise InvalidInput("ulimit -v", f"{have} MiB", f"at least {need} MiB for "
                           f"`dyncheck {args.command}` (measured: its engines need that much "
                           "address space to load); raise it, e.g. ulimit -v unlimited")


def _main(argv: Sequence[str] | None) -> int:
    from dyncheck.workers import end_now

    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:  # --help (0) or a one-line usage error (2), already printed
        return int(exc.code or 0)
    from dyncheck.commands.options import settings_of
    from dyncheck.compiled_caches import held
    from dyncheck.workers import settled

    try:
        _address_space(args)
        # handed to every unit of work (dyncheck.settings), with the compiled-code folder
        # checked before any engine runs and signed when the command ends
        with held(settings_of(args)) as settings, settled(settings):
            if args.command == "list":
                return list_command(integrators=args.integrators)
            return COMMANDS[args.command](args)
    except DyncheckError as exc:
        print(f"dyncheck: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except OSError as exc:  # a write that failed mid-way (disk full, file-size limit)
        where = exc.filename or "output"
        print(f"dyncheck: error: cannot write {where}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except Terminated:
        end_now()
        print("dyncheck: terminated (nothing half-written)", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        end_now()
        print("dyncheck: interrupted (nothing half-written)", file=sys.stderr)
        return 130
    finally:
        from dyncheck.commands.options import release_outs

        release_outs()  # the output folders this command held (claim_out)


def console() -> int:
    """The ``dyncheck`` command: :func:`main` in a process that exits without a last garbage
    collection (:func:`dyncheck.workers.exit_without_collecting`), its output to a reader
    that may leave (:class:`_LeavingReader`)."""
    from dyncheck.workers import exit_without_collecting

    exit_without_collecting()
    sys.stdout = _LeavingReader(sys.stdout)
    return main()


class _LeavingReader:
    """``sys.stdout`` for a reader that may go away — ``dyncheck check FOLDER | head``: a
    write to the closed pipe raised ``BrokenPipeError``, which ended the check after the
    first model ('cannot write output: Broken pipe', exit 2, the other pages never
    written). Now the rest of the output goes to /dev/null and the command finishes with
    its own exit status."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._drop()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._drop()

    def _drop(self) -> None:
        """The stream's file descriptor pointed at /dev/null: what is buffered, and the
        interpreter's last flush, go nowhere without an error."""
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, self._stream.fileno())
        os.close(devnull)

    def __getattr__(self, name: str) -> object:
        return getattr(self._stream, name)


if __name__ == "__main__":
    raise SystemExit(console())
