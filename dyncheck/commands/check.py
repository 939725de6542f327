"""``dyncheck check``: the user's models, one page each."""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import (
    OUT,
    check_out,
    check_out_file,
    ci_files,
    claim_out,
    path_arg,
    positive,
    write_ci,
)
from dyncheck.errors import DyncheckError, InvalidInput

if TYPE_CHECKING:
    import pandas as pd

    from dyncheck.check import index
    from dyncheck.check.acceptance import Acceptance
    from dyncheck.check.engines import Limits
    from dyncheck.ci_outputs import Moves


def say(message: str) -> None:
    """A long step's estimate, on stderr (a function of this module: the workers' pickle
    finds it)."""
    print(f"dyncheck check: {message}", file=sys.stderr, flush=True)


def _case_files(names: list[str], folder: Path) -> list[tuple[Path, str | None]]:
    """Each book case's MJCF (:func:`~dyncheck.adapters.formats.mjcf.to_mjcf`, what ``run`` gives
    MuJoCo) written into ``folder``."""
    from dyncheck.adapters.formats.mjcf import to_mjcf
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
    if args.skip_included:
        kept = set(index.without_fragments([p for p, _ in targets]))
        targets = [(p, r) for p, r in targets if p in kept]
        if not targets and not args.robot and not args.case:
            return []
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


def check_command(args: argparse.Namespace) -> int:
    with tempfile.TemporaryDirectory(prefix="dyncheck-cases-") as cases:
        targets = _check_targets(args, Path(cases))
        if not targets:  # --skip-included, and every file given is a fragment
            print("no model to check: every file given is included by another model file")
            return 0
        return _check_all(args, targets, Path(cases))


def _options(args: argparse.Namespace) -> dict[str, Any]:
    """``check_model``'s keyword arguments from the command's flags."""
    return {"impls": tuple(args.impl) or None, "states": args.states, "seed": args.seed,
            "floating": args.floating, "against": args.against, "isolate": not args.in_process,
            "limits": _limits(args), "derivatives": args.derivatives,
            "actuators": not args.no_actuators, "say": None if args.quiet else say,
            "given_states": args.states_file}


def _named(targets: list[tuple[Path, str | None]], cases: Path
           ) -> tuple[list[str], dict[str, str]]:
    """Each target's page name (:func:`~dyncheck.check.index.page_names`) and what the index
    calls its file: a robot's name, a book case's, or the path below the files' common
    folder."""
    from dyncheck.check import index
    from dyncheck.escaping import shown

    names = index.page_names([p for p, _ in targets], [robot for _, robot in targets])
    base = index.common_folder([p for p, _ in targets])
    files = {name: f"robot {robot}" if robot else f"book case {p.stem}" if p.parent == cases
             else shown(str(p.resolve().relative_to(base)))
             for (p, robot), name in zip(targets, names, strict=True)}
    return names, files


def _validated(args: argparse.Namespace, targets: list[tuple[Path, str | None]],
               names: list[str], files: dict[str, str]
               ) -> tuple[list[index.Entry], list[tuple[Path, str | None, str]], Gates]:
    """Every input checked before any engine runs: the model files (one refused among
    several is an index entry), the options, the output files; then the folder claimed."""
    from dyncheck.check import index, inputs

    several = len(targets) > 1
    entries: list[index.Entry] = []
    valid = []
    for (path, robot), name in zip(targets, names, strict=True):
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
    if args.states_file is not None:  # what the file alone can say, before any engine
        from dyncheck.check.given_states import given

        given(args.states_file, most=inputs.MAX_STATES)
    if args.seed < 0:
        raise InvalidInput("--seed", args.seed, "a non-negative integer")
    check_out(args.out)
    read = [p for p, _ in targets] + [f for f in (args.against, args.states_file, args.accept)
                                       if f is not None]
    ci_files(args, read)
    gates = _gates(args, read)
    positive("--jobs", args.jobs)
    claim_out(args.out)  # every option checked: the folder held for this command
    return entries, valid, gates


def _check_all(args: argparse.Namespace, targets: list[tuple[Path, str | None]],
               cases: Path) -> int:
    import datetime as dt
    from functools import partial

    from dyncheck.check import acceptance, index
    from dyncheck.check.model_check import check_model, implementations
    from dyncheck.check.page import engine_versions_of, summary_line, write
    from dyncheck.progress import Progress
    from dyncheck.workers import each_unit

    names, files = _named(targets, cases)
    several = len(targets) > 1
    entries, valid, gates = _validated(args, targets, names, files)
    options = _options(args)
    units = [(name, partial(check_model, **options, name=robot or (name if several else None)),
              (str(path),)) for path, robot, name in valid]
    engines = tuple(i for i in implementations(tuple(args.impl) or None) if i != "reference")
    failed, refusals, today = False, len(entries), dt.date.today()
    tables: dict[str, pd.DataFrame] = {}
    seconds: dict[str, dict[str, float]] = {}
    refused: dict[str, str] = {}
    checked, used = [], set()
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
            result, accepted = acceptance.apply(result, gates.accepted, today)
            used |= accepted
            checked.append(result)
            written = write(result, args.out, name=name, indexed=several)
            print(f"{summary_line(result)} -> {written[1]}")
            entries.append(index.entry(result, name, files[name]))
            tables[name], seconds[name] = result.rows, dict(result.seconds)
            if not result.ok:
                failed = True
                print(result.failures())
        if several:
            index.write(entries, engines, args.out)
    progress.close()
    if several:
        print(f"{len(entries)} models: index -> {args.out / (index.INDEX + '.md')}")
    for line in acceptance.unused(gates.accepted, checked, used, today):
        print(f"dyncheck check: {line}")
    versions = engine_versions_of(implementations(tuple(args.impl) or None))
    moves = _held(args, gates, tables, versions)
    refused |= {e.model: e.refused for e in entries if e.refused}
    if args.junit is not None or args.json is not None:
        from dyncheck.ci_outputs import CHECK

        write_ci(args, tables, CHECK, versions, refused=refused, seconds=seconds, moves=moves)
    if refusals:
        return 2
    if moves is not None:  # held to the baseline: a failed row it holds is a known one
        return 1 if len(moves.rows) else 0
    return 1 if failed else 0


@dataclass(frozen=True, kw_only=True)
class Gates:
    """What a check is held to besides its verdicts, read before any work: the known findings
    it accepts (``--accept``) and the stored baseline (``--baseline``; None without one, or
    none yet where ``--update-baseline`` writes the first)."""

    accepted: tuple[Acceptance, ...] = ()
    stored: pd.DataFrame | None = None


def _gates(args: argparse.Namespace, read: list[Path]) -> Gates:
    from dyncheck.check import acceptance
    from dyncheck.check import baseline as check_baseline

    accepted = acceptance.load(args.accept) if args.accept is not None else ()
    if args.update_baseline and args.baseline is None:
        raise InvalidInput("--update-baseline", True, "given with --baseline FILE (the file "
                           "to write)")
    stored = None
    if args.baseline is not None:
        if args.update_baseline:
            check_out_file("--baseline", args.baseline, read)
            if args.baseline.exists():  # what it will replace: a baseline, not another file
                stored = check_baseline.load(args.baseline)
        else:
            stored = check_baseline.load(args.baseline)
    return Gates(accepted=accepted, stored=stored)


def _held(args: argparse.Namespace, gates: Gates, tables: dict[str, pd.DataFrame],
          versions: dict[str, str]) -> Moves | None:
    """The check against its baseline: what moved, on ``baseline.md`` and the terminal
    (None without ``--baseline``, and after ``--update-baseline`` wrote it)."""
    from dyncheck import baseline as stored_versions
    from dyncheck.check import baseline as check_baseline
    from dyncheck.ci_outputs import Moves
    from dyncheck.provenance import dyncheck_version
    from dyncheck.results import write_atomic

    if args.baseline is None:
        return None
    versions = {"dyncheck": dyncheck_version(), **versions}
    current = check_baseline.table(tables)
    moved = (check_baseline.compare(current, gates.stored) if gates.stored is not None
             else None)
    if args.update_baseline:
        check_baseline.write(tables, args.baseline, versions)
        before = f"; {len(moved)} rows moved since the previous one" if moved is not None \
            else ""
        print(f"baseline written to {args.baseline} ({len(current)} rows{before})")
        return None
    assert moved is not None  # loaded by _gates
    changed = tuple(stored_versions.version_changes(args.baseline, versions))
    page = check_baseline.page(moved, args.baseline, list(changed), len(current))
    write_atomic(args.out / f"{check_baseline.PAGE}.md", page)
    if changed:
        print("versions changed since the baseline: " + ", ".join(changed))
    print(f"{len(moved)} rows moved against {args.baseline}" if len(moved)
          else f"nothing moved against {args.baseline}")
    for row in moved.itertuples(index=False):
        print(f"  {row.model}: {row.row}: {row.move}: {row.note}")
    return Moves(file=str(args.baseline), versions_changed=changed, rows=moved)


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("paths", nargs="*", type=path_arg, metavar="PATH",
                   help="MJCF (.xml) or URDF files, or folders (every model file under "
                   "them; files another one includes left out); several: an index page too")
    p.add_argument("--robot", action="append", default=[], metavar="NAME",
                   help="a robot of example-robot-data (extra 'robots'; see `dyncheck list`; "
                   "'all': every one)")
    p.add_argument("--case", action="append", default=[], metavar="CASE",
                   help="a book case's MJCF, the file `run` gives MuJoCo (repeatable; 'all': "
                   "every case)")
    p.add_argument("--impl", action="append", default=[], metavar="NAME",
                   help=flags.impl_help())
    p.add_argument("--states", type=int, default=100, metavar="N", help="sampled states")
    p.add_argument("--skip-included", action="store_true",
                   help="leave out a file given that another model file beside it includes "
                   "(an MJCF fragment: what a pre-commit hook is handed when it changes)")
    p.add_argument("--states-file", type=path_arg, default=None, metavar="FILE",
                   help="check at these states instead of sampled ones: a .npz with arrays q "
                   "(n, nq) and v (n, nv), or a .npy of q then v per row, in the canonical "
                   "layout the page names (MuJoCo's qpos and qvel order for a file MuJoCo "
                   "loads); accelerations drawn with --seed")
    p.add_argument("--seed", type=int, default=0, metavar="S")
    p.add_argument("--floating", action="store_true",
                   help="a URDF's root link is a free body (a free joint in every engine)")
    p.add_argument("--derivatives", action="store_true",
                   help="also compare the derivatives of the dynamics (d(forward)/d(q, v, tau), "
                   "d(inverse)/d(q, v)) of every engine that offers them with the referee's")
    p.add_argument("--no-actuators", action="store_true",
                   help="leave the actuators out (by default, where the model has actuators, "
                   "each engine's reading of them, their force at sampled controls and MuJoCo's "
                   "step Jacobian in the controls are compared)")
    p.add_argument("--against", type=path_arg, default=None, metavar="PATH",
                   help="also compare the model's reading with this other file's (a previous "
                   "version), both read by the first engine (MuJoCo by default), the other "
                   "compiled in a process of its own")
    p.add_argument("--baseline", type=path_arg, default=None, metavar="FILE",
                   help="hold every row to this stored baseline of the same models: exit 1 "
                   "when a row moved (its verdict, its error by more than its tolerance, a "
                   "reading), appeared or vanished, each named on baseline.md (a failed row "
                   "the baseline holds is a known one)")
    p.add_argument("--update-baseline", action="store_true",
                   help="write --baseline FILE from this check instead (accepting what moved)")
    p.add_argument("--accept", type=path_arg, default=None, metavar="FILE",
                   help="a TOML file of known findings ([[accept]]: model, engine, label, "
                   "reason, optional expires): a failed row one matches stays on the page "
                   "marked accepted and no longer fails the command; an entry that accepts "
                   "nothing is named")
    p.add_argument("--out", type=path_arg, default=OUT / "check",
                   help=f"output folder (default: {OUT / 'check'})")
    flags.jobs(p, "models checked")
    flags.dask(p)
    flags.ci(p)
    flags.quiet(p)
    flags.no_cache(p)
    p.add_argument("--engine-memory", type=int, default=None, metavar="MIB",
                   help="address space each engine process may use (default 8192 MiB; 0: no "
                   "cap; MuJoCo's ports are never capped)")
    p.add_argument("--engine-seconds", type=float, default=None, metavar="S",
                   help="base time limit of an engine's load and of each batch of states "
                   "(default 120 s), scaled up with the file's size and states x dofs^2")
    p.add_argument("--in-process", action="store_true",
                   help="load the engines in this process (faster start; an engine that "
                   "crashes on the file then ends the check)")


COMMAND = Command(
    name="check",
    help="do the engines read YOUR model alike and compute the same dynamics (and "
    "derivatives)?",
    example="dyncheck check my_robot.urdf --floating --states 1000",
    arguments=_arguments, handler=check_command)
