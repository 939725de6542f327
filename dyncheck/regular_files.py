"""Opening a file that untrusted input names (an included model file, a baseline, a cache
entry, a key) only where it is a regular file, and without blocking: a FIFO, a device or a
socket there would hang the command or never end. Its kind is read from the open file
(``fstat``), so nothing can swap it between the check and the read; a link is followed only
where the caller allows it."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from enum import StrEnum
from pathlib import Path
from typing import BinaryIO


class Refusal(StrEnum):
    """Why a path was not opened."""

    UNOPENABLE = "cannot be opened"
    NOT_REGULAR = "is not a regular file"
    TOO_LARGE = "is too large"


class NotRegular(Exception):
    """A path :func:`open_regular` did not open: why (:class:`Refusal`), the system's words
    where it could not be opened, its size where too large."""

    def __init__(self, refusal: Refusal, *, reason: str = "", size: int = 0) -> None:
        super().__init__(f"{refusal}" + (f" ({reason})" if reason else ""))
        self.refusal, self.reason, self.size = refusal, reason, size


@contextmanager
def open_regular(path: Path | str, *, follow: bool,
                 most: int | None = None) -> Iterator[BinaryIO]:
    """``path`` open for binary reading where it is a regular file (of at most ``most``
    bytes), through a link only where ``follow``; :class:`NotRegular` otherwise.
    FileNotFoundError passes as it is (a missing file is not a refused one)."""
    flags = os.O_RDONLY | os.O_NONBLOCK | (0 if follow else os.O_NOFOLLOW)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise
    except OSError as exc:
        raise NotRegular(Refusal.UNOPENABLE, reason=exc.strerror or str(exc)) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise NotRegular(Refusal.NOT_REGULAR)
        if most is not None and info.st_size > most:
            raise NotRegular(Refusal.TOO_LARGE, size=info.st_size)
        os.set_blocking(fd, True)
        handle = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with handle:
        yield handle
