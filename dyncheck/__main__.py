"""The ``dyncheck`` command line: ``list``, ``run``, ``check``, ``diff``, ``versions``,
``tutorials``, ``report``, ``explain``, ``errata``, ``baseline`` and ``bench`` — one module for
``python -m dyncheck`` and the ``dyncheck`` script (the script's entry point is
:func:`console`).

Exit status: 0 when nothing failed unexplained, 1 when a check failed (or regressed against a
baseline, or the committed report is stale), 2 for bad usage or bad input (a one-line message
naming the argument and the value).

Here: the parser, built from the commands' records, and the handling of errors and signals
every command shares. Each command — its flags, help, example and handler (which validates
its arguments before any work and calls the module that does it) — is one module of
:mod:`dyncheck.commands`, named as the command (``list``: ``listing``).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, NoReturn, TextIO

from dyncheck.errors import DyncheckError, InvalidInput, Terminated

if TYPE_CHECKING:
    from dyncheck.commands.flags import Command


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``dyncheck: error: …``, exit 2), no usage dump."""

    def error(self, message: str) -> NoReturn:
        where = self.prog.removeprefix("dyncheck").strip()
        print(f"dyncheck: error: {where + ': ' if where else ''}{message}", file=sys.stderr)
        raise SystemExit(2)


def commands() -> dict[str, Command]:
    """Every subcommand, in the order ``--help`` lists them: each is its module's
    :class:`~dyncheck.commands.flags.Command` (flags, help, example and handler together).
    Imported here, not with this module: loading them takes a quarter of a second (numpy,
    pandas, the engines' records), during which :func:`console` answers signals itself."""
    from dyncheck.commands import (
        baseline,
        bench,
        check,
        diff,
        errata,
        explain,
        listing,
        report,
        run,
        tutorials,
        versions,
    )

    return {c.name: c for c in (
        listing.COMMAND, run.COMMAND, check.COMMAND, diff.COMMAND, versions.COMMAND,
        tutorials.COMMAND, report.COMMAND, explain.COMMAND, errata.COMMAND, baseline.COMMAND,
        bench.COMMAND)}


def __getattr__(name: str) -> Any:
    """``COMMANDS``: :func:`commands`, as the module's attribute."""
    if name == "COMMANDS":
        return commands()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="dyncheck",
        description="A textbook's tensor dynamics (its general method and printed equations) "
        "against MuJoCo (with MJX and MuJoCo Warp), Pinocchio, Drake, Newton, PyBullet and "
        "sympy.physics.mechanics: every discrepancy measured and explained.",
        epilog="exit status: 0 nothing failed unexplained; 1 a check failed, regressed or "
        "moved; 2 bad usage or input (one line naming the argument and value). "
        "`dyncheck COMMAND --help` shows an example of each command.",
    )
    from dyncheck.provenance import dyncheck_version

    p.add_argument("--version", action="version", version=f"dyncheck {dyncheck_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for command in commands().values():
        one = sub.add_parser(command.name, help=command.help,
                             epilog=f"example: {command.example}")
        command.arguments(one)
    return p


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
        try:  # (a signal while the parser's modules load is answered as any other)
            args = _parser().parse_args(argv)
        except SystemExit as exc:  # --help (0) or a one-line usage error (2), already printed
            return int(exc.code or 0)
        from dyncheck.cache.compiled import held
        from dyncheck.ci_outputs import json_on_stdout
        from dyncheck.commands.options import settings_of
        from dyncheck.workers import settled

        _address_space(args)
        # handed to every unit of work (dyncheck.settings), with the compiled-code folder
        # checked before any engine runs and signed when the command ends
        with held(settings_of(args)) as settings, settled(settings), \
                json_on_stdout(vars(args).get("json")):
            return commands()[args.command].handler(args)
    except DyncheckError as exc:
        from dyncheck.commands.options import one_line

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


ENDED = {signal.SIGINT: ("interrupted", 130), signal.SIGTERM: ("terminated", 143)}
"""What each signal ends a command with: the word its one line says, the exit status."""


def _while_loading(signum: int, frame: object) -> None:
    raise SystemExit(signum)


def _said(signum: int) -> int:
    word, code = ENDED[signal.Signals(signum)]
    print(f"dyncheck: {word} (nothing half-written)", file=sys.stderr)
    return code


def console() -> int:
    """The ``dyncheck`` command: :func:`main` in a process that exits without a last garbage
    collection (:func:`dyncheck.workers.exit_without_collecting`), its output to a reader
    that may leave (:class:`_LeavingReader`). Ctrl-C or SIGTERM while the commands' modules
    load ended it with Python's traceback from inside an import: they are answered here —
    one line, 130 or 143, nothing was written yet — until :func:`main`'s handlers take over.
    A signalled command ends without the interpreter's shutdown (:func:`_end_now`)."""
    from dyncheck.confinement import stack_room

    stack_room()
    for signum in ENDED:
        signal.signal(signum, _while_loading)
    try:
        commands()
        from dyncheck.workers import exit_without_collecting
    except SystemExit as exc:
        return _end_now(_said(int(exc.code or signal.SIGINT)))
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        exit_without_collecting()
        _open_standard_streams()
        sys.stdout = _LeavingReader(sys.stdout)
        sys.stderr = _LeavingReader(sys.stderr)
        code = main()
    except KeyboardInterrupt:  # (in the instant before main's own handlers)
        code = _said(signal.SIGINT)
    return _end_now(code) if code in {c for _, c in ENDED.values()} else code


def _end_now(code: int) -> NoReturn:
    """End a signalled command without the interpreter's shutdown: its line is said, its
    files whole, its workers and engines stopped — what is left are multiprocessing's
    finalizers, which the signal may have caught half-built and which then print a
    traceback at exit ("Exception ignored in: <Finalize object, dead>")."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)


def _open_standard_streams() -> None:
    """A standard stream the command was started without (``dyncheck check m.xml >&-``, as
    some CI runners and daemons start commands) is opened on /dev/null: Python gave it as
    None, every engine process died flushing it (a good model reported as one no engine
    could load), and the next file dyncheck opened would have taken its descriptor (a page
    written where output goes)."""
    for fd, name, mode in ((0, "stdin", os.O_RDONLY), (1, "stdout", os.O_WRONLY),
                           (2, "stderr", os.O_WRONLY)):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, mode)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
            setattr(sys, name, open(fd, "r" if fd == 0 else "w", closefd=False,
                                    encoding="utf-8", errors="replace"))


class _LeavingReader:
    """``sys.stdout`` (and ``sys.stderr``) for a reader that may go away — ``dyncheck check
    FOLDER | head``: a write to the closed pipe raised ``BrokenPipeError``, which ended the
    check after the first model ('cannot write output: Broken pipe', exit 2, the other pages
    never written); a full one (``> /dev/full``) raised ``OSError`` (no space) the same way.
    Now the rest of that stream's output goes to /dev/null and the command finishes with its
    own exit status: what it writes into ``--out`` does not depend on who reads its lines."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except OSError:  # a closed pipe, a full device, an I/O error: the reader is gone
            self._drop()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except OSError:
            self._drop()

    def _drop(self) -> None:
        """The stream's file descriptor pointed at /dev/null: what is buffered, and the
        interpreter's last flush, go nowhere without an error."""
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, self._stream.fileno())
        os.close(devnull)
        try:  # what the stream still buffers goes to /dev/null now
            self._stream.flush()
        except OSError:
            pass

    def __getattr__(self, name: str) -> object:
        return getattr(self._stream, name)


if __name__ == "__main__":
    raise SystemExit(console())
