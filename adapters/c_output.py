"""What an engine's C code prints, kept off the caller's output where dyncheck's own process
loads the engine (PyBullet's "build time" line when a client connects, its importer's
``b3Warning`` lines): file descriptors 1 and 2 at /dev/null for the duration."""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def c_output_dropped() -> Iterator[None]:
    """This process's stdout and stderr (file descriptors 1 and 2) at /dev/null for the
    duration: what an engine's C code prints in dyncheck's own process (PyBullet's "build
    time" line, on stderr, when a client connects) never reaches the caller's output;
    Python's own writes are flushed first, C's buffered ones before the output is given
    back. An exception raised inside still propagates (and is reported by the caller)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        _flush_c_stdio()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (null, *saved):
            os.close(fd)


def _flush_c_stdio() -> None:
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library to flush: nothing buffered there
        pass
