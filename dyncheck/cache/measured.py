"""Measured results cached on disk, keyed by everything that can change them.

A demonstration of the conventions catalogue is a deterministic function of dyncheck's source
and data, the installed engines and numerical libraries, the Python and the machine (the same
inputs give the same numbers). :func:`measured` stores its result under the user's cache
folder (:func:`~dyncheck.cache.store.cache_root`) keyed by a hash of all of them, so
that a second ``dyncheck explain`` prints without running the engines, while an upgrade of any
engine, an edit of any file of dyncheck or another machine measures afresh. A case's figures
are kept the same way (:func:`~dyncheck.report.figures.cached_figures`, the plotted data part
of their name), and so are the studies' reference trajectories
(:class:`~dyncheck.studies.references.References`, keyed by case, model variant and step).
``--no-cache`` (:class:`dyncheck.settings.Settings`) neither reads nor writes. Files are
written whole (a temporary file, then a rename); one that cannot be read back is measured
again and replaced.
"""

from __future__ import annotations

import hashlib
import importlib.util
import platform
import shutil
import sys
from collections.abc import Callable, Sequence
from functools import cache
from importlib import metadata
from pathlib import Path
from typing import TypeVar

from dyncheck.adapters import ENGINE_PACKAGES
from dyncheck.cache.store import cache_root, cached
from dyncheck.settings import current

T = TypeVar("T")

LIBRARIES = ("numpy", "scipy", "sympy", "jax", "jaxlib", "warp-lang", "pandas", "matplotlib",
             "pillow")
"""Libraries the cached results depend on, beside the engines' own packages: numerical ones
(an engine's numbers), and those that format tables and draw and encode figures."""

SOURCE_SUFFIXES = (".py", ".xml", ".urdf", ".json", ".md")
"""Files of dyncheck whose content is part of the key (code, models, data, the book's text)."""


def _installed(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def _source_roots() -> list[Path]:
    """The folders of dyncheck's packages (``reference``, ``adapters`` and ``cases`` live
    beside ``dyncheck`` in a source checkout, inside it when installed): found by the import
    system, not imported (the case registry reads installed packages' entry points)."""
    specs = [importlib.util.find_spec(name) for name in
             ("dyncheck", "dyncheck.reference", "dyncheck.adapters", "dyncheck.cases")]
    return sorted({Path(spec.origin).resolve().parent for spec in specs
                   if spec is not None and spec.origin})


def _cpu() -> str:
    """The processor's model and instruction-set flags (Linux): compiled float32 code (XLA,
    Warp) rounds differently on CPUs with other vector units, so another CPU measures afresh
    even where a cache folder is shared between machines."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return platform.processor()
    wanted = ("model name", "flags")
    return "\n".join(next((x for x in lines if x.startswith(w)), "") for w in wanted)


@cache
def fingerprint() -> str:
    """A hash of dyncheck's files, the versions of every engine and library it may use, the
    Python, the platform and the CPU: two processes with the same fingerprint compute the same
    numbers."""
    h = hashlib.sha256()
    h.update(f"{sys.version}\n{platform.platform()}\n{platform.machine()}\n{_cpu()}\n".encode())
    for package in sorted({*ENGINE_PACKAGES.values(), *LIBRARIES}):
        h.update(f"{package}={_installed(package)}\n".encode())
    for root in _source_roots():
        for path in sorted(root.rglob("*")):
            if path.suffix in SOURCE_SUFFIXES and "__pycache__" not in path.parts:
                h.update(str(path.relative_to(root.parent)).encode())
                h.update(path.read_bytes())
    return h.hexdigest()[:24]


def path_for(kind: str, name: str) -> Path:
    return cache_root() / kind / fingerprint() / f"{name}.pickle"


def measured(
    kind: str, name: str, measure: Callable[[], T], keep: Callable[[T], bool], *,
    latest_only: bool = False, expect: type | tuple[type, ...] = object,
) -> tuple[T, bool]:
    """``measure()``, or the result an earlier call with the same ``kind``, ``name`` and
    :func:`fingerprint` stored; with whether it was read back. A result for which ``keep``
    is false (a demonstration that failed) is returned but never stored. ``latest_only``:
    storing a result removes what other fingerprints stored under ``kind`` (for large results
    — a case's figures — that would otherwise pile up with every edit of dyncheck). What is
    read back must be an ``expect`` (:func:`~dyncheck.cache.store.cached`)."""
    if not current().cache:  # before the fingerprint: it reads every file of dyncheck
        return measure(), False
    path = path_for(kind, name)
    result, found = cached(path, measure, keep, expect=expect)
    if latest_only and not found:
        try:
            others = [p for p in path.parent.parent.iterdir() if p != path.parent]
        except OSError:  # nothing stored (a read-only or unusable cache folder)
            others = []
        for other in others:
            shutil.rmtree(other, ignore_errors=True)  # another process's may be gone
    return result, found


def reused(kind: str, label: str, inputs: Sequence[bytes], compute: Callable[[], T], *,
           expect: type | tuple[type, ...] = object) -> T:
    """``compute()``, or what an earlier call stored for the same ``kind``, ``label``, inputs
    and :func:`fingerprint` — for a deterministic computation that cannot fail (always
    stored) and whose results are large enough that only the latest fingerprint's are kept
    (a case's figures, the studies' reference trajectories). Its name: ``label`` and a hash
    of ``inputs`` (everything the result depends on beside the fingerprint)."""
    h = hashlib.sha256()
    for part in inputs:
        h.update(part)
    name = f"{label}-{h.hexdigest()[:32]}"
    return measured(kind, name, compute, keep=lambda _result: True, latest_only=True,
                    expect=expect)[0]

