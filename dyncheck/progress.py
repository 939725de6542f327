"""Progress of long work, where it runs: on a terminal a live bar (units done / to do,
elapsed, expected; ``tqdm``), in a log (stderr not a terminal: CI, ``| tee``, a notebook) one
line per finished unit with its time and the time still expected, with ``--quiet`` nothing.
Always on stderr: stdout keeps the results."""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO


def seconds_text(s: float) -> str:
    """A duration as a reader takes it in: seconds, minutes or hours."""
    if s < 120:
        return f"{s:.1f} s"
    return f"{s / 60:.1f} min" if s < 7200 else f"{s / 3600:.1f} h"


class Progress:
    """Progress over ``total`` units of ``what`` (set later with :meth:`begin` where the
    caller learns it then)."""

    def __init__(self, what: str, total: int | None = None, *, quiet: bool = False,
                 stream: TextIO | None = None) -> None:
        self.what, self.quiet = what, quiet
        self.stream = stream if stream is not None else sys.stderr
        self.total = 0
        self.count = 0
        self.start = self.last = time.perf_counter()
        self.bar: Any = None
        if total is not None:
            self.begin(total)

    def begin(self, total: int) -> None:
        self.total, self.count = total, 0
        self.start = self.last = time.perf_counter()
        if self.quiet or total < 1 or not self.stream.isatty():
            return
        from tqdm import tqdm

        self.bar = tqdm(total=total, desc=f"dyncheck {self.what}", unit=" unit",
                        file=self.stream, leave=False, dynamic_ncols=True, mininterval=0,
                        miniters=1)  # units are coarse (a case, a model): draw each

    def done(self, unit: str, *, seconds: float | None = None) -> None:
        """One unit finished (``unit``: what it was; ``seconds``: the time it took where it
        ran — units on several workers overlap —, else the time since the last one)."""
        now = time.perf_counter()
        took, self.last = (now - self.last) if seconds is None else seconds, now
        self.count += 1
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.set_postfix_str(unit[:40], refresh=False)
            self.bar.update(1)
            return
        elapsed = now - self.start
        left = ""
        if self.total and self.count < self.total:
            left = f", about {seconds_text(elapsed / self.count * (self.total - self.count))} to go"
        of = f"/{self.total}" if self.total else ""
        print(f"dyncheck {self.what}: [{self.count}{of}] {unit} done in {seconds_text(took)} "
              f"(elapsed {seconds_text(elapsed)}{left})", file=self.stream, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
