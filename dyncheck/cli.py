"""The ``dyncheck`` command line: ``list``, ``run``, ``check``, ``report``, ``explain``,
``baseline`` and ``bench``.

Exit status: 0 when nothing failed unexplained, 1 when a check failed (or regressed against a
baseline, or the committed report is stale), 2 for bad usage or bad input (a one-line message
naming the argument and the value).

Why one module of ~600 lines: each subcommand is its argparse definition plus one small
handler that validates its arguments and calls the module that does the work; kept together
so that every flag, its check (exit 2) and its example are read in one place.
"""

from __future__ import annotations

import argparse
import errno
import os
import re
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

from dyncheck.errors import DyncheckError, EngineNotInstalled, InvalidInput, UnknownName

if TYPE_CHECKING:
    import pandas as pd

    from dyncheck.check.engines import Limits
    from dyncheck.ci_outputs import Columns


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``dyncheck: error: …``, exit 2), no usage dump."""

    def error(self, message: str) -> NoReturn:
        where = self.prog.removeprefix("dyncheck").strip()
        print(f"dyncheck: error: {where + ': ' if where else ''}{message}", file=sys.stderr)
        raise SystemExit(2)


def _path(text: str) -> Path:
    """A path argument; an empty one is refused (it would silently mean this folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path is not a folder or file name")
    try:
        os.stat(text)
    except OSError as exc:  # a missing path is each command's to name; a loop is no path
        if exc.errno == errno.ELOOP:
            raise argparse.ArgumentTypeError(f"{text!r} is a symlink loop") from None
    return Path(text)


def _selection(p: argparse.ArgumentParser) -> None:
    p.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    p.add_argument(
        "--impl",
        action="append",
        default=[],
        metavar="NAME",
        help="implementation to include (repeatable; default: all); the catalogue's entries "
        "that need an optional engine left out (Drake, MJX) are skipped",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        metavar="N",
        help="cases in N parallel processes (same results)",
    )
    _dask(p)
    _no_cache(p)

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
    p.add_argument("--junit", type=_path, default=None, metavar="FILE",
                   help="also write the rows as JUnit XML (one test suite per case or model, "
                   "one test case per quantity and pair) for a CI system to show")
    p.add_argument("--json", type=_path, default=None, metavar="FILE",
                   help="also write a JSON summary: the counts, each case's or model's, every "
                   "row")


def _ci_files(args: argparse.Namespace) -> None:
    """The ``--junit`` and ``--json`` files writable, checked before any work."""
    for flag, path in (("--junit", args.junit), ("--json", args.json)):
        if path is not None:
            _check_out_file(flag, path)
            out = getattr(args, "out", None)
            if out is not None and path.resolve() == Path(out).resolve():
                raise InvalidInput(flag, str(path), "a file path other than the --out folder")
    if args.junit is not None and args.json is not None \
            and args.junit.resolve() == args.json.resolve():
        raise InvalidInput("--json", str(args.json), "a file other than --junit's (one would "
                           "overwrite the other)")


def _write_ci(args: argparse.Namespace, tables: dict[str, pd.DataFrame], columns: Columns,
              versions: dict[str, str], refused: dict[str, str] | None = None) -> None:
    from dyncheck import ci_outputs

    if args.junit is not None:
        ci_outputs.write_junit(args.junit, tables, columns)
    if args.json is not None:
        ci_outputs.write_json(args.json, tables, versions, refused)


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
    r.add_argument("--out", type=_path, default=Path("reports"), help="report folder")
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
        type=_path,
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
    k.add_argument("paths", nargs="*", type=_path, metavar="PATH",
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
    k.add_argument("--against", type=_path, default=None, metavar="PATH",
                   help="also compare what MuJoCo reads with this other file (a previous version)")
    k.add_argument("--out", type=_path, default=Path("reports/check"), help="output folder")
    k.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="models checked in N parallel processes (same results)")
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
    d.add_argument("run_a", type=_path, metavar="RUN_A",
                   help="output folder of `run` or `check` (or a baseline CSV): the old side")
    d.add_argument("run_b", type=_path, metavar="RUN_B", help="the new side, same kind")
    d.add_argument("--tolerance", type=float, default=None, metavar="FACTOR",
                   help="an error above its tolerance moved when it changed by more than this "
                        "factor (default 10)")
    d.add_argument("--markdown", type=_path, default=None, metavar="FILE",
                   help="also write the diff as a Markdown page")
    d.add_argument("--all", action="store_true", help="list unchanged rows too")
    v = sub.add_parser(
        "versions", help="the version matrix: each engine release in its own environment")
    v.add_argument("--engine", action="append", default=[], metavar="NAME",
                   help="mujoco, pinocchio, drake, newton, pybullet (repeatable; default: "
                   "all)")
    v.add_argument("--case", action="append", default=[], metavar="CASE",
                   help="cases to run (repeatable; default: all)")
    v.add_argument("--jobs", type=int, default=2, metavar="N")
    v.add_argument("--bisect", nargs=3, default=None, metavar=("ENGINE", "GOOD", "BAD"),
                   help="name the first release between GOOD and BAD whose results moved")
    v.add_argument("--reuse", action="store_true",
                   help="reuse each release's newest cached run, whatever code made it")
    v.add_argument("--out", type=_path, default=Path("reports/versions.md"), metavar="FILE")
    t = sub.add_parser("tutorials", help="execute the tutorials and render them to Markdown")
    t.add_argument("names", nargs="*", metavar="NAME", help="tutorials (default: all)")
    t.add_argument("--out", type=_path, default=Path("reports/tutorials"), help="output folder")
    c = sub.add_parser("report", help="check that the committed report matches the code")
    c.add_argument(
        "--check",
        action="store_true",
        required=True,
        help="recompute every case and compare with the report folder",
    )
    c.add_argument("--out", type=_path, default=Path("reports"), help="report folder")
    c.add_argument("--jobs", type=int, default=1, metavar="N")
    _dask(c)
    _no_cache(c)
    c.add_argument(
        "--from",
        dest="run_dir",
        type=_path,
        default=None,
        metavar="DIR",
        help="compare with the output folder of a finished `dyncheck run` instead of running",
    )
    e = sub.add_parser("explain", help="demonstrate a modelling convention (all if none)")
    e.add_argument("name", nargs="?", default=None, metavar="NAME")
    _no_cache(e)
    er = sub.add_parser("errata", help="check every formula of §2.2 and write the errata page")
    er.add_argument("--out", type=_path, default=Path("reports/errata.md"),
                    metavar="FILE")
    bl = sub.add_parser("baseline", help="run and write the regression baseline")
    _selection(bl)
    bl.add_argument("--out", type=_path, default=Path("reports/baseline.csv"), metavar="FILE")
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
    b.add_argument("--out", type=_path, default=Path("reports"), help="report folder")
    b.add_argument("--jobs", type=int, default=1, metavar="N",
                   help="also time the sweep in slices on N processes against this one "
                   "(the same rows, checked)")
    _dask(b)
    b.add_argument("--suite", action="store_true",
                   help="instead: time the commands a user runs (list, explain, one case, the "
                   "full run, report --check) in fresh processes -> benchmark-suite.md")
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


def _installed(package: str) -> str | None:
    """An installed distribution's version, read from its metadata (nothing imported)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return None


def _engine_line(name: str) -> str:
    """An engine imported: its version (and device, for a port) and its integrators."""
    from dyncheck.adapters import ENGINE_PACKAGES, get_adapter

    try:
        adapter = get_adapter(name)
    except EngineNotInstalled as exc:  # the hint names the package or the extra
        return f"not installed: {exc.hint}"
    steps = list(adapter.integrators)
    if adapter.adaptive:
        steps.append("dop853 (scipy, error-controlled)")
    if hasattr(adapter, "simulate_controlled"):
        steps.append("rk3-controlled (its own runge_kutta3, error-controlled)")
    return f"{ENGINE_PACKAGES[name]} {adapter.version()}; integrators: {', '.join(steps)}"


def _list(*, integrators: bool = False) -> int:
    """Cases, implementations and robots. Engines are named with their installed version from
    the package metadata — fast, nothing imported — or, with ``integrators``, imported."""
    from dyncheck.adapters import ENGINE_EXTRAS, ENGINE_PACKAGES
    from dyncheck.cases import CASES
    from dyncheck.roster import IMPLEMENTATIONS

    print("cases:")
    for name, cls in CASES.items():
        print(f"  {name:24s} {cls.title}")
    print("implementations:")
    for name in IMPLEMENTATIONS:
        if name == "book":
            what = "dyncheck.reference (book printed equations)"
        elif name not in ENGINE_PACKAGES:
            what = "dyncheck.reference (general method, (2.2.23)-(2.2.26))"
        elif integrators:
            what = _engine_line(name)
        elif (version := _installed(ENGINE_PACKAGES[name])) is not None:
            what = f"{ENGINE_PACKAGES[name]} {version}"
        elif name in ENGINE_EXTRAS:
            what = f"not installed: pip install 'dyncheck[{ENGINE_EXTRAS[name]}]'"
        else:
            what = f"not installed: pip install {ENGINE_PACKAGES[name]}"
        print(f"  {name:24s} {what}")
    from dyncheck.check.inputs import robots

    found = robots()
    if found:
        print(f"robots (example-robot-data, for `dyncheck check --robot NAME`): {len(found)}")
        for name, path in found.items():
            print(f"  {name:32s} {path.name}")
    else:
        print("robots: the 'robots' extra is not installed (pip install 'dyncheck[robots]')")
    return 0


def _check_out(out: Path, flag: str = "--out") -> None:
    """--out must be a directory, or creatable, and writable — tried for real (a probe file
    created and removed, any folder made for it removed again) before any work, so bad usage
    changes nothing. ``flag``: the option the folder comes from."""
    if out.exists() and not out.is_dir():
        raise InvalidInput(flag, str(out), "a directory")
    bad = next((p for p in out.parents if p.exists() and not p.is_dir()), None)
    if bad is not None:
        raise InvalidInput(flag, str(out), f"a folder path ({bad} is a file)")
    missing = [p for p in (out, *out.parents) if not p.exists()]
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out, prefix=".dyncheck-probe-"):
            pass
    except OSError as exc:
        raise InvalidInput(flag, str(out), f"a writable directory ({exc.strerror})") from None
    finally:
        for p in missing:  # innermost first: leave no trace of the probe
            if p.is_dir() and not any(p.iterdir()):
                p.rmdir()


def _check_out_file(flag: str, path: Path) -> None:
    """A file to write: not a folder, and its folder writable (:func:`_check_out`)."""
    if path.is_dir():
        raise InvalidInput(flag, str(path), "a file path, not a folder")
    _check_out(path.parent, flag)


MAX_STATES = 10**9
"""More sampled states than this would take over half a day at ~50 µs per state: refused."""
STATE_SECONDS = 50e-6
"""Measured cost of one sampled state through every implementation (reports/benchmark.md)."""


def _warn_cost(states: int, jobs: int) -> None:
    """Say up front what a large sweep will cost (more than a minute), before it starts."""
    seconds = states * STATE_SECONDS / jobs
    if seconds > 60:
        took = f"{seconds / 3600:.1f} h" if seconds >= 3600 else f"{seconds / 60:.0f} min"
        print(f"dyncheck: {states} sampled states: about {took} on this machine with --jobs "
              f"{jobs} (~50 µs per state); the states are drawn and compared in chunks, so "
              "memory stays flat", file=sys.stderr, flush=True)


MAX_JOBS = 256
"""More local processes than this: refused (each holds the engines, ~0.3 GB)."""
BENCH_MAX = {"--states": 10**7, "--repeats": 100, "--memory": 10**8}
"""``bench``'s bounds: its sweeps hold every state's arrays in memory (10⁷ states of a
six-dof case: ~4 GB)."""


def _positive(name: str, value: int | None, most: int | None = None) -> None:
    """A positive integer (at most ``most``; ``--jobs`` at most :data:`MAX_JOBS`)."""
    most = MAX_JOBS if most is None and name == "--jobs" else most
    if value is not None and (value < 1 or (most is not None and value > most)):
        expected = "a positive integer" + (f" at most {most}" if most is not None else "")
        raise InvalidInput(name, value, expected)


DEVICE = re.compile(r"cpu|cuda(:\d+)?")


def _device_env() -> None:
    """``DYNCHECK_DEVICE`` from the environment, checked before any work."""
    value = os.environ.get("DYNCHECK_DEVICE")
    if value is not None and not DEVICE.fullmatch(value):
        raise InvalidInput("DYNCHECK_DEVICE", value, "cpu, cuda or cuda:N (the environment)")


def _has_cuda() -> bool:
    """An NVIDIA driver on this machine (its library or its /proc entry)."""
    import ctypes.util

    return Path("/proc/driver/nvidia/version").exists() or \
        ctypes.util.find_library("cuda") is not None


def _use_device(device: str) -> None:
    """The ports' device, for this process and the workers it starts: Warp reads
    ``DYNCHECK_DEVICE``, JAX its platform (set before its first computation). ``cuda`` on a
    machine without an NVIDIA driver is refused here, before any work."""
    if device == "cuda" and not _has_cuda():
        raise InvalidInput("--device", device, "cpu on this machine (no NVIDIA driver found)")
    os.environ["DYNCHECK_DEVICE"] = device
    os.environ["JAX_PLATFORMS"] = device
    if "jax" in sys.modules:
        sys.modules["jax"].config.update("jax_platforms", device)


def _run(args: argparse.Namespace) -> int:
    from dyncheck import baseline, report
    from dyncheck.report.figures import cached_figures as draw_figures
    from dyncheck.run import resolve, run

    _check_out(args.out)
    _ci_files(args)
    _device_env()
    if args.device is not None:
        _use_device(args.device)
    _positive("--states", args.states)
    if args.states is not None and args.states > MAX_STATES:
        raise InvalidInput("--states", args.states, f"at most {MAX_STATES} (~50 µs per state)")
    _positive("--jobs", args.jobs)
    reference = baseline.load(args.baseline) if args.baseline is not None else None
    cases, impls = resolve(args.cases, args.impl)
    if args.states is not None:
        _warn_cost(args.states * len(cases), args.jobs)
    # the conventions catalogue does not depend on the cases: it runs with the full report
    from dyncheck.progress import Progress

    with Progress("run", quiet=args.quiet) as progress:
        result = run(cases, impls, states=args.states, jobs=args.jobs, dask=args.dask,
                     conventions=not args.cases, progress=progress, render=draw_figures)
    report.write(result, args.out)
    from dyncheck.ci_outputs import RUN, split

    _write_ci(args, split(result.discrepancies, RUN), RUN, report.versions(result.engines))
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
        moved = baseline.version_changes(args.baseline, report.versions(result.engines))
        print(
            "versions changed since the baseline: " + ", ".join(moved)
            if moved
            else "same engine versions as the baseline (a regression is a change of code)"
        )
        if regressed:
            print(changes.to_string(index=False))
    return 1 if result.failed or regressed else 0


SHOWN = 20
"""Moved results listed by `report --check` (the rest counted)."""


def _report(args: argparse.Namespace) -> int:
    from dyncheck import freshness, report
    from dyncheck.run import resolve, run

    _positive("--jobs", args.jobs)
    for flag, folder in (("--out", args.out), ("--from", args.run_dir)):
        if folder is not None and not folder.is_dir():
            raise InvalidInput(flag, str(folder), "an existing report folder")
        if folder is not None and not (folder / "discrepancies.csv").is_file():
            raise InvalidInput(flag, str(folder), "a report folder written by `dyncheck run` "
                               "(it has no discrepancies.csv)")
    committed = freshness.read_report(args.out)
    if args.run_dir is not None:
        moved = freshness.compare(committed, freshness.read_report(args.run_dir))
    else:
        cases, impls = resolve([], [])
        result = run(cases, impls, jobs=args.jobs, dask=args.dask, conventions=True)
        moved = report.check(result, args.out)
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


def _baseline(args: argparse.Namespace) -> int:
    """Write the baseline; show what changed against the previous one."""
    from dyncheck import baseline, report
    from dyncheck.run import resolve, run

    _check_out_file("--out", args.out)
    _positive("--jobs", args.jobs)
    cases, impls = resolve(args.cases, args.impl)
    previous = baseline.load(args.out, "--out") if args.out.exists() else None  # validated first
    result = run(cases, impls, jobs=args.jobs, dask=args.dask)
    if previous is not None:
        changes = baseline.compare(result.discrepancies, previous, cases=[c.name for c in cases])
        print(changes.to_string(index=False) if len(changes) else "no change")
    baseline.write(result.discrepancies, args.out, versions=report.versions(result.engines))
    print(f"baseline written to {args.out} ({len(result.discrepancies)} rows)")
    return 0


def _bench(args: argparse.Namespace) -> int:
    from dyncheck import bench
    from dyncheck.cases import get_case

    _check_out(args.out)
    if args.suite:
        from dyncheck import bench_suite

        print(bench_suite.main(args.out))
        return 0
    get_case(args.case)
    _positive("--states", args.states, BENCH_MAX["--states"])
    _positive("--repeats", args.repeats, BENCH_MAX["--repeats"])
    for n in args.memory:
        _positive("--memory", n, BENCH_MAX["--memory"])
    _positive("--jobs", args.jobs)
    print(bench.main(args.case, args.states, args.repeats, args.memory, args.out,
                     jobs=args.jobs, dask=args.dask))
    return 0


def _diff(args: argparse.Namespace) -> int:
    """Exit 1 when any row moved; 0 when every row is unchanged."""
    import dataclasses

    from dyncheck import baseline, diff
    from dyncheck.results import write_atomic

    factor = diff.FACTOR if args.tolerance is None else args.tolerance
    diff.check_factor(factor)
    if args.markdown is not None:
        _check_out_file("--markdown", args.markdown)
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


def _versions(args: argparse.Namespace) -> int:
    """Exit 0 (the matrix reports moves; it does not judge them)."""
    from dyncheck import matrix
    from dyncheck.cases import get_case
    from dyncheck.results import write_atomic

    _positive("--jobs", args.jobs)
    for name in args.case:
        get_case(name)
    if args.bisect is not None:
        name, good, bad = args.bisect
        first, moved = matrix.bisect(name, good, bad, cases=args.case, jobs=args.jobs,
                                     log=_log)
        print(f"first release that moved: {name} {first} ({len(moved)} rows)")
        print(moved.to_string(index=False))
        return 0
    names = args.engine or list(matrix.ENGINES)
    for name in names:
        matrix.engine(name)
    _check_out_file("--out", args.out)
    steps = matrix.matrix(names, cases=args.case, jobs=args.jobs, log=_log, reuse=args.reuse)
    write_atomic(args.out, matrix.page(steps, notes=matrix.EXPLANATIONS))
    print(f"version matrix written to {args.out}")
    return 0


def _log(message: str) -> None:
    print(f"dyncheck: {message}", file=sys.stderr, flush=True)


def _tutorials(args: argparse.Namespace) -> int:
    """Execute each tutorial (its own checks must hold) and render it; exit 1 if one fails."""
    from dyncheck import tutorials

    known = tutorials.available()
    names = args.names or list(known)
    for name in names:
        if name not in known:
            raise UnknownName("tutorial", name, known)
    _check_out(args.out)
    failed = 0
    for name in names:
        try:
            nb = tutorials.execute(name)
        except tutorials.TutorialFailed as exc:
            print(f"dyncheck: {exc}", file=sys.stderr)
            failed += 1
            continue
        written = tutorials.render(name, nb, args.out)
        print(f"{name}: executed -> {written[0]}")
    if not args.names:
        tutorials.index(args.out)
    return 1 if failed else 0


def _explain(args: argparse.Namespace) -> int:
    from dyncheck.catalogue import explain_cached, render

    if args.name is not None and args.name.startswith("erratum-"):
        from dyncheck.errata import page

        print(page.explain(args.name.removeprefix("erratum-")))
        return 0
    entries, read_back = explain_cached(args.name)
    print(render(entries))
    if read_back:
        print(f"({read_back} of {len(entries)} measured by an earlier `dyncheck explain` with "
              "the same dyncheck, engines and machine, read from the cache; --no-cache "
              "measures afresh)")
    return 1 if any(e.failed for e in entries) else 0


def _errata(args: argparse.Namespace) -> int:
    from dyncheck.errata import page
    from dyncheck.results import write_atomic

    _check_out_file("--out", args.out)
    write_atomic(args.out, page.page())
    print(f"errata page written to {args.out}")
    return 0


def _case_files(names: list[str], folder: Path) -> list[tuple[Path, str | None]]:
    """Each book case's MJCF (:func:`~dyncheck.adapters.mjcf.to_mjcf`, what ``run`` gives
    MuJoCo) written into ``folder``."""
    from dyncheck.adapters.mjcf import to_mjcf
    from dyncheck.cases import CASES, get_case

    chosen = list(CASES) if "all" in names else names
    out: list[tuple[Path, str | None]] = []
    for name in chosen:
        case = get_case(name)  # an unknown name: one line, exit 2, before any work
        path = folder / f"{name}.xml"
        path.write_text(to_mjcf(case.multibody()))
        out.append((path, None))
    return out


def _check_targets(args: argparse.Namespace, cases: Path) -> list[tuple[Path, str | None]]:
    """The files to check: PATHs (a folder: every model file under it), ``--robot``s, then
    ``--case``s (written into ``cases``)."""
    from dyncheck.check import index, inputs

    targets: list[tuple[Path, str | None]] = []
    for path in args.paths:
        if path.is_dir():
            found = index.in_folder(path)
            if not found:
                raise InvalidInput("PATH", str(path), "a folder holding MJCF or URDF files")
            targets += [(p, None) for p in found]
        else:
            targets.append((path, None))
    robots = list(inputs.robots()) if "all" in args.robot else args.robot
    targets += [(inputs.robot(name), name) for name in robots]
    targets += _case_files(args.case, cases)
    if not targets:
        raise InvalidInput("PATH", "", "at least one model file, folder, --robot or --case")
    return targets


MAX_ENGINE_MIB = 1 << 20
MAX_ENGINE_SECONDS = 86_400.0


def _limits(args: argparse.Namespace) -> Limits:
    """The engines' limits from ``--engine-memory`` and ``--engine-seconds`` (checked)."""
    from dyncheck.check.engines import MEMORY_MIB, Limits

    memory = MEMORY_MIB if args.engine_memory is None else args.engine_memory
    if not (memory == 0 or 256 <= memory <= MAX_ENGINE_MIB):
        raise InvalidInput("--engine-memory", memory,
                           f"0 (no cap) or a size in MiB in [256, {MAX_ENGINE_MIB}]")
    if args.engine_seconds is not None and not (
            1.0 <= args.engine_seconds <= MAX_ENGINE_SECONDS):
        raise InvalidInput("--engine-seconds", args.engine_seconds,
                           f"a number of seconds in [1, {MAX_ENGINE_SECONDS:g}]")
    return Limits(memory_mib=memory or None, seconds=args.engine_seconds)


def _without(message: str, path: Path) -> str:
    """``message`` with the model's path as its file name: no machine path on a page."""
    for text in (str(path.resolve()), str(path)):
        message = message.replace(text, path.name)
    return message


def _check(args: argparse.Namespace) -> int:
    with tempfile.TemporaryDirectory(prefix="dyncheck-cases-") as cases:
        return _check_all(args, _check_targets(args, Path(cases)), Path(cases))


def _check_all(args: argparse.Namespace, targets: list[tuple[Path, str | None]],
               cases: Path) -> int:
    from functools import partial

    from dyncheck.check import index, inputs
    from dyncheck.check.model_check import check_model, implementations
    from dyncheck.check.page import summary_line, write
    from dyncheck.progress import Progress
    from dyncheck.workers import each_unit

    names = index.page_names([p for p, _ in targets])
    names = [robot.replace("/", "__") if robot else name
             for (_, robot), name in zip(targets, names, strict=True)]
    several = len(targets) > 1
    base = index.common_folder([p for p, _ in targets])
    files = {name: f"robot {robot}" if robot else f"book case {p.stem}" if p.parent == cases
             else str(p.resolve().relative_to(base))
             for (p, robot), name in zip(targets, names, strict=True)}
    entries: list[index.Entry] = []
    valid = []
    for (path, robot), name in zip(targets, names, strict=True):  # all before any engine runs
        try:
            inputs.model_path(str(path))
        except DyncheckError as exc:
            if not several:
                raise
            print(f"dyncheck: error: {exc}", file=sys.stderr)
            entries.append(index.refused(name, files[name], _without(str(exc), path)))
            continue
        valid.append((path, robot, name))
    if args.against is not None:
        inputs.model_path(str(args.against))
    inputs.states(args.states)
    if args.seed < 0:
        raise InvalidInput("--seed", args.seed, "a non-negative integer")
    _check_out(args.out)
    _ci_files(args)
    _device_env()
    _positive("--jobs", args.jobs)
    options = {"impls": tuple(args.impl) or None, "states": args.states, "seed": args.seed,
               "floating": args.floating, "against": args.against,
               "isolate": not args.in_process, "limits": _limits(args),
               "derivatives": args.derivatives}
    units = [(name, partial(check_model, **options, name=robot or (name if several else None)),
              (str(path),)) for path, robot, name in valid]
    engines = tuple(i for i in implementations(tuple(args.impl) or None) if i != "reference")
    failed, refusals = False, len(entries)
    tables: dict[str, pd.DataFrame] = {}
    refused: dict[str, str] = {}
    progress = Progress("check", len(units) if several else None, quiet=args.quiet or not several)
    for name, result in each_unit(units, jobs=args.jobs, dask=args.dask):
        progress.done(name)
        if isinstance(result, DyncheckError):
            if not several:
                raise result
            print(f"dyncheck: error: {name}: {result}", file=sys.stderr)
            path = next(p for p, _, n in valid if n == name)
            entries.append(index.refused(name, files[name], _without(str(result), path)))
            refused[name] = _without(str(result), path)
            refusals += 1
        else:
            written = write(result, args.out, name=name)
            print(f"{summary_line(result)} -> {written[1]}")
            entries.append(index.entry(result, name, files[name]))
            tables[name] = result.rows
            if not result.ok:
                failed = True
                print(result.failures())
        if several:
            index.write(entries, engines, args.out)
    progress.close()
    if several:
        print(f"{len(entries)} models: index -> {args.out / (index.INDEX + '.md')}")
    refused |= {e.model: e.refused for e in entries if e.refused}
    if args.junit is not None or args.json is not None:
        from dyncheck.check.page import engine_versions_of
        from dyncheck.ci_outputs import CHECK

        _write_ci(args, tables, CHECK, engine_versions_of(implementations(
            tuple(args.impl) or None)), refused)
    return 2 if refusals else 1 if failed else 0


COMMANDS = {
    "run": _run,
    "check": _check,
    "report": _report,
    "diff": _diff,
    "versions": _versions,
    "tutorials": _tutorials,
    "baseline": _baseline,
    "bench": _bench,
    "explain": _explain,
    "errata": _errata,
}


def main(argv: Sequence[str] | None = None) -> int:
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:  # --help (0) or a one-line usage error (2), already printed
        return int(exc.code or 0)
    from dyncheck.reference.derivations import NO_CACHE

    before = os.environ.get(NO_CACHE)
    if getattr(args, "no_cache", False):  # read by this process and the workers it starts
        os.environ[NO_CACHE] = "1"
    try:
        if args.command == "list":
            return _list(integrators=args.integrators)
        return COMMANDS[args.command](args)
    except DyncheckError as exc:
        print(f"dyncheck: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except OSError as exc:  # a write that failed mid-way (disk full, file-size limit)
        where = exc.filename or "output"
        print(f"dyncheck: error: cannot write {where}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("dyncheck: interrupted (nothing half-written)", file=sys.stderr)
        return 130
    finally:
        if before is None:
            os.environ.pop(NO_CACHE, None)
        else:
            os.environ[NO_CACHE] = before


def console() -> int:
    """The ``dyncheck`` command: :func:`main` in a process that exits without a last garbage
    collection (:func:`dyncheck.workers.exit_without_collecting`)."""
    from dyncheck.workers import exit_without_collecting

    exit_without_collecting()
    return main()


def _one_line(text: str) -> str:
    return " ".join(text.split())


if __name__ == "__main__":
    raise SystemExit(console())
