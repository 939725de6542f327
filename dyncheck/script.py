"""The ``dyncheck`` script's entry point, kept light. Loading the command's modules takes a
quarter of a second (numpy, pandas, the engines' records): Ctrl-C or SIGTERM then ended it
with Python's traceback from inside an import. Here the signals are answered from the first
line — one line and 130 or 143, nothing was written yet — until
:func:`dyncheck.__main__.console` takes them over."""

from __future__ import annotations

import os
import signal
import sys

ENDED = {signal.SIGINT: ("interrupted", 130), signal.SIGTERM: ("terminated", 143)}
"""What each signal ends a command with: the word its one line says, the exit status."""


def _while_loading(signum: int, frame: object) -> None:
    raise SystemExit(signum)


def _said(signum: int) -> int:
    word, code = ENDED[signal.Signals(signum)]
    print(f"dyncheck: {word} (nothing half-written)", file=sys.stderr)
    return code


def console() -> int:
    """The ``dyncheck`` command (:func:`dyncheck.__main__.console`), its signals answered
    while its modules load."""
    for signum in ENDED:
        signal.signal(signum, _while_loading)
    try:
        from dyncheck.__main__ import console as command
    except SystemExit as exc:
        return _said(int(exc.code or signal.SIGINT))
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        code = command()
    except KeyboardInterrupt:  # (in the instant before the command's own handlers)
        code = _said(signal.SIGINT)
    if code in {c for _, c in ENDED.values()}:
        _end_now(code)
    return code


def _end_now(code: int) -> None:
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
