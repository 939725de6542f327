"""Whether an engine's defect still stands under a release: its reproducer
(:mod:`dyncheck.explain.reproducers`) run by that release's interpreter. ``dyncheck versions``
runs them in each release's environment and names the release that fixed a defect (its
reproducer fails under one release and passes under the next) or brought one back."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Collection, Mapping
from enum import StrEnum
from pathlib import Path

from dyncheck.explain.reproducers import REPRODUCERS
from dyncheck.results import write_atomic

FILE = "reproducers.json"
"""In a release's run folder: reproducer name → :class:`Outcome` under that release."""
TIMEOUT_S = 600.0
"""A reproducer that runs longer is reported ``does not run`` (none takes a minute)."""


class Outcome(StrEnum):
    """What a reproducer's run says (each script prints the expected and the observed value,
    then exits 1 while its defect stands, 0 once fixed)."""

    STANDS = "stands"
    FIXED = "fixed"
    DOES_NOT_RUN = "does not run"
    """The script failed by itself (an API it calls is gone, an import fails: a traceback, no
    observed value), exited otherwise, or ran past :data:`TIMEOUT_S`."""


def reproduce(python: Path | str, impls: Collection[str], folder: Path) -> dict[str, Outcome]:
    """Every reproducer of the implementations ``impls`` run in isolation (``-I``) by the
    interpreter ``python``; the outcomes written to ``folder``/:data:`FILE` too."""
    out: dict[str, Outcome] = {}
    for name, found in REPRODUCERS.items():
        if found.engine not in impls:
            continue
        script = folder / f"reproducer-{name}.py"
        write_atomic(script, found.script)
        try:
            done = subprocess.run([str(python), "-I", str(script)], capture_output=True,
                                  text=True, cwd=folder, timeout=TIMEOUT_S, check=False)
        except subprocess.TimeoutExpired:
            out[name] = Outcome.DOES_NOT_RUN
            continue
        out[name] = _outcome(done)
    write_atomic(folder / FILE, json.dumps(out, indent=1, sort_keys=True) + "\n")
    return out


def _outcome(done: subprocess.CompletedProcess[str]) -> Outcome:
    """A script that printed its observed value and exited 0 or 1 by itself; an uncaught
    exception (an import or an API gone) exits 1 too, with a traceback: that one did not run."""
    ran = "observed" in done.stdout and "Traceback (most recent call last)" not in done.stderr
    if not ran or done.returncode not in (0, 1):
        return Outcome.DOES_NOT_RUN
    return Outcome.STANDS if done.returncode == 1 else Outcome.FIXED


def load(folder: Path | None) -> dict[str, Outcome]:
    """The outcomes recorded in a run folder (none where it has no :data:`FILE`: a run made
    before reproducers were run, or ``--reuse`` of one)."""
    path = None if folder is None else folder / FILE
    if path is None or not path.is_file():
        return {}
    return {str(k): Outcome(v) for k, v in json.loads(path.read_text(encoding="utf-8")).items()}


def changed(old: Mapping[str, Outcome], new: Mapping[str, Outcome], *,
            to: Outcome) -> tuple[str, ...]:
    """The reproducers whose defect went between two consecutive releases: ``to=FIXED``,
    standing under ``old`` and fixed under ``new``; ``to=STANDS``, the reverse."""
    before = Outcome.STANDS if to is Outcome.FIXED else Outcome.FIXED
    return tuple(sorted(n for n in new if new[n] is to and old.get(n) is before))
