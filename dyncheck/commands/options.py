"""What the commands share: their path arguments, the checks of an output folder or file
(before any work), numeric bounds, the ports' device, the CI files."""

from __future__ import annotations

import argparse
import errno
import os
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from dyncheck.errors import InvalidInput
from dyncheck.settings import Settings, from_environment

if TYPE_CHECKING:
    import pandas as pd

    from dyncheck.ci_outputs import Columns, Moves


OUT = Path("dyncheck-report")
"""Where ``run``, ``check``, ``bench`` and ``tutorials`` write by default: a folder of the
current directory, never a checkout's committed ``reports/`` (a newcomer's first command
leaves ``git status`` clean; the maintainers regenerate the committed report with
``--out reports``)."""


def path_arg(text: str) -> Path:
    """A path argument; an empty one is refused (it would silently mean this folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path is not a folder or file name")
    try:
        os.stat(text)
    except OSError as exc:  # a missing path is each command's to name; a loop is no path
        if exc.errno == errno.ELOOP:
            raise argparse.ArgumentTypeError(f"{text!r} is a symlink loop") from None
    return Path(text)


def ci_files(args: argparse.Namespace, inputs: Sequence[Path] = ()) -> None:
    """The ``--junit`` and ``--json`` files writable and none of the command's ``inputs``,
    checked before any work (``--json -``: standard output)."""
    from dyncheck.ci_outputs import STDOUT

    for flag, path in (("--junit", args.junit), ("--json", args.json)):
        if path is not None and not (flag == "--json" and path == STDOUT):
            check_out_file(flag, path, inputs)
            out = getattr(args, "out", None)
            if out is not None and path.resolve() == Path(out).resolve():
                raise InvalidInput(flag, str(path), "a file path other than the --out folder")
    if args.junit is not None and args.json is not None \
            and args.junit.resolve() == args.json.resolve():
        raise InvalidInput("--json", str(args.json), "a file other than --junit's (one would "
                           "overwrite the other)")


def write_ci(args: argparse.Namespace, tables: dict[str, pd.DataFrame], columns: Columns,
             versions: dict[str, str], *, refused: dict[str, str] | None = None,
             seconds: dict[str, dict[str, float]] | None = None,
             moves: Moves | None = None) -> None:
    """The ``--junit`` and ``--json`` files of a command's tables (``seconds``: per table,
    what each engine took, where the command measured it; ``moves``: what moved against a
    baseline)."""
    from dyncheck import ci_outputs

    if args.junit is not None:
        ci_outputs.write_junit(args.junit, tables, columns, refused=refused, seconds=seconds,
                               moves=moves)
    if args.json is not None:
        ci_outputs.write_json(args.json, tables, versions, refused=refused,
                              command=args.command, seconds=seconds, moves=moves)


def check_out(out: Path, flag: str = "--out") -> None:
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


_CLAIMS: list[tuple[int, list[Path]]] = []
"""The output folders this command holds: a descriptor of each folder (locked), and the
folders made for it (removed again where the command leaves them empty)."""


def claim_out(out: Path, flag: str = "--out") -> None:
    """Hold ``out`` for this command — an exclusive ``flock`` on the folder itself, so that
    two dyncheck commands never write one folder at once and nothing is written to hold it
    (a command killed with SIGKILL leaves no lock behind: the lock goes with the process). A
    second command is refused at once, naming the process that holds the folder
    (``/proc/locks``)."""
    import fcntl

    made = [p for p in (out, *out.parents) if not p.exists()]
    try:
        out.mkdir(parents=True, exist_ok=True)
        fd = os.open(out, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError as exc:
        raise InvalidInput(flag, str(out), f"a folder that can be opened ({exc.strerror})") \
            from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        holder = _lock_holder(fd)
        os.close(fd)
        raise InvalidInput(flag, str(out), f"a folder no other dyncheck is writing (process "
                           f"{holder} is: wait for it to end, or choose another {flag})") \
            from None
    _CLAIMS.append((fd, made))
    from dyncheck.workers import at_end

    at_end(release_outs)


def _lock_holder(fd: int) -> str:
    """The process holding an flock on the file of ``fd`` (Linux ``/proc/locks``), or
    "another process" where it cannot be read."""
    st = os.fstat(fd)
    inode = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
    try:
        lines = Path("/proc/locks").read_text().splitlines()
    except OSError:
        return "another process"
    for line in lines:
        fields = line.split()
        if "FLOCK" in fields and inode in fields:
            pid = fields[fields.index(inode) - 1]
            return pid if pid.isdigit() else "another process"
    return "another process"


def release_outs() -> None:
    """Let go of every folder :func:`claim_out` took (a folder it made removed if empty)."""
    while _CLAIMS:
        fd, made = _CLAIMS.pop()
        os.close(fd)
        for folder in made:  # innermost first: a refused command leaves no trace
            try:
                if folder.is_dir() and not any(folder.iterdir()):
                    folder.rmdir()
            except OSError:
                pass


def check_out_file(flag: str, path: Path, inputs: Sequence[Path] = ()) -> None:
    """A file to write, checked before any work: not a folder, not a symlink or a special
    file (it is written beside and renamed over: a link or a device would be replaced, not
    written through), not one of the command's ``inputs`` (the model it reads), and its folder
    writable (:func:`check_out`)."""
    if path.is_symlink():
        raise InvalidInput(flag, str(path), "a regular file path, not a symlink (outputs are "
                           "written beside and renamed over: the link would be replaced)")
    if path.is_dir():
        raise InvalidInput(flag, str(path), "a file path, not a folder")
    if path.exists() and not path.is_file():
        raise InvalidInput(flag, str(path), "a regular file path, not a special file (a "
                           "device, a pipe or a socket)")
    for given in inputs:
        if _same_file(path, given):
            raise InvalidInput(flag, str(path), f"a file other than the input {str(given)!r} "
                               "(it would be overwritten)")
    check_out(path.parent, flag)


def _same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file (hard links and links followed), or would."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


MAX_STATES = 10**9
"""More sampled states than this would take over half a day at ~50 µs per state: refused."""


STATE_SECONDS = 50e-6
"""Measured cost of one sampled state through every implementation (reports/benchmark.md)."""


def warn_cost(states: int, jobs: int) -> None:
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


def positive(name: str, value: int | None, most: int | None = None) -> None:
    """A positive integer (at most ``most``; ``--jobs`` at most :data:`MAX_JOBS`)."""
    most = MAX_JOBS if most is None and name == "--jobs" else most
    if value is not None and (value < 1 or (most is not None and value > most)):
        expected = "a positive integer" + (f" at most {most}" if most is not None else "")
        raise InvalidInput(name, value, expected)


def settings_of(args: argparse.Namespace) -> Settings:
    """The command's :class:`~dyncheck.settings.Settings` (``--no-cache``, ``--device``,
    their environment defaults), checked before any work: ``cuda`` on a machine without an
    NVIDIA driver is refused here."""
    device = getattr(args, "device", None)
    if device == "cuda" and not has_cuda():
        raise InvalidInput("--device", device, "cpu on this machine (no NVIDIA driver found)")
    return from_environment(no_cache=getattr(args, "no_cache", False), device=device)


def has_cuda() -> bool:
    """An NVIDIA driver on this machine (its library or its /proc entry)."""
    import ctypes.util

    return Path("/proc/driver/nvidia/version").exists() or \
        ctypes.util.find_library("cuda") is not None


def log(message: str) -> None:
    print(f"dyncheck: {message}", file=sys.stderr, flush=True)


def one_line(text: str) -> str:
    """An error's one line, as the terminal may show it (:func:`dyncheck.escaping.shown`:
    no control character from a file name reaches the terminal)."""
    from dyncheck.escaping import shown

    return shown(" ".join(text.split()))
