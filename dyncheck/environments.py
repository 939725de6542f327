"""The release environments of the version matrix: one virtual environment per engine
release, kept under the cache folder, whose library files are shared between them.

With uv (the extra ``versions``) each environment is made by ``uv venv`` and ``uv pip
install`` from one cache of unpacked wheels under the cache folder, its files hard-linked
from there: a library at the same version is stored on disk once however many environments
hold it. Without uv, pip makes each one (the standard library's :mod:`venv`), a full copy.
The page of a matrix says which, and the disk its environments hold (:func:`footprint`, each
file counted once however many links it has).
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import subprocess
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

from dyncheck.cache.store import cache_root
from dyncheck.errors import ROOT, DyncheckError

Log = Callable[[str], None]

VENVS = "venvs"
"""The cache's folder of release environments."""
UV_CACHE = "uv"
"""The cache's folder of uv's unpacked wheels, the files the environments link to (on the
same file system as the environments: a hard link cannot cross one)."""


class Installer(Enum):
    """What makes the environments."""

    UV = "uv"
    PIP = "pip"


def installer() -> Installer:
    """uv where its package is installed (the extra ``versions``), else pip."""
    return Installer.UV if _uv() else Installer.PIP


def _uv() -> str:
    try:
        import uv  # type: ignore[import-not-found,unused-ignore]
    except ImportError:
        return ""
    try:
        return str(uv.find_uv_bin())
    except FileNotFoundError:
        return ""


def folder(name: str, release: str) -> Path:
    return cache_root() / VENVS / f"{name}-{release}"


def make(name: str, release: str, *, requirements: Sequence[str], pins: str,
         log: Log) -> Path:
    """The Python of the release's environment (made once, then reused): ``requirements``
    installed under the constraints ``pins``, and dyncheck from this checkout."""
    home = folder(name, release)
    python = home / "bin" / "python"
    done = home / ".installed"
    if done.exists():
        _install_checkout(python, home, _recorded(done), name=name, release=release)
        return python
    how = installer()
    log(f"creating {home} ({release}, by {how.value})")
    started = time.perf_counter()
    shutil.rmtree(home, ignore_errors=True)
    if how is Installer.UV:
        subprocess.run([_uv(), "venv", "--quiet", "--python", sys.executable, str(home)],
                       check=True, capture_output=True)
    else:
        subprocess.run([sys.executable, "-m", "venv", "--clear", str(home)], check=True)
    constraints = home / "constraints.txt"
    constraints.write_text(pins)
    result = _install(how, python, ["-c", str(constraints), *requirements])
    if result.returncode != 0:
        raise ReleaseUnavailable(name, release, reason(result.stderr))
    _install_checkout(python, home, how, name=name, release=release)
    done.write_text(f"{release}\n{time.perf_counter() - started:.1f}\n{how.value}\n")
    return python


def _recorded(done: Path) -> Installer:
    lines = done.read_text().split()
    return Installer(lines[2]) if len(lines) > 2 else Installer.PIP


def _install(how: Installer, python: Path, args: Sequence[str]) -> subprocess.CompletedProcess:
    if how is Installer.UV:
        command = [_uv(), "pip", "install", "--python", str(python), "--link-mode", "hardlink",
                   "--cache-dir", str(cache_root() / UV_CACHE), "--no-progress", *args]
        return subprocess.run(command, capture_output=True, text=True, check=False,
                              env={**os.environ, "NO_COLOR": "1"})
    # not -q: pip's resolver explains a conflict only when not quiet (read by reason)
    return subprocess.run([str(python), "-m", "pip", "install", "--disable-pip-version-check",
                           *args], capture_output=True, text=True, check=False)


def _install_checkout(python: Path, home: Path, how: Installer, *, name: str,
                      release: str) -> None:
    """dyncheck from this checkout, editable and without its ranges — reinstalled when the
    environment was made from another checkout (a clone can run the matrix while this one is
    being edited)."""
    marker = home / ".checkout"
    if marker.exists() and marker.read_text().strip() == str(ROOT):
        return
    result = _install(how, python, ["--no-deps", "-e", str(ROOT)])
    if result.returncode != 0:
        raise ReleaseUnavailable(name, release, reason(result.stderr))
    marker.write_text(f"{ROOT}\n")


@dataclass(frozen=True, kw_only=True)
class Made:
    """One environment as it stands: how it was made and what it holds."""

    seconds: float | None
    """The seconds it took to make (None where not recorded)."""
    by: Installer
    apparent: int
    """The bytes of its files, as a copy would hold them."""
    own: int
    """The bytes of its files no other path links to: what it adds to the disk."""


def made(name: str, release: str) -> Made | None:
    """The release's environment, None where there is none."""
    home = folder(name, release)
    done = home / ".installed"
    if not done.exists():
        return None
    lines = done.read_text().split()
    apparent = own = 0
    for info in _files([home]):
        apparent += info.st_size
        own += info.st_size if info.st_nlink == 1 else 0
    return Made(seconds=float(lines[1]) if len(lines) > 1 else None, by=_recorded(done),
                apparent=apparent, own=own)


def _files(tops: Iterable[Path]) -> Iterable[os.stat_result]:
    for top in tops:
        for path in top.rglob("*") if top.is_dir() else ():
            info = path.lstat()
            if stat.S_ISREG(info.st_mode):
                yield info


def disk(tops: Iterable[Path]) -> int:
    """The bytes the regular files under ``tops`` hold on disk: each file once, however many
    hard links to it lie there."""
    seen: dict[tuple[int, int], int] = {}
    for info in _files(tops):
        seen[(info.st_dev, info.st_ino)] = info.st_size
    return sum(seen.values())


@dataclass(frozen=True, kw_only=True)
class Footprint:
    """What a page's environments cost: each as it stands, the disk they hold together (each
    file once however many of them link it) and what uv's cache holds beyond every
    environment (its files no environment links; shared by all of them)."""

    made: Mapping[tuple[str, str], Made]
    """(engine, release) → its environment, for those that exist."""
    disk: int
    cache: int


def footprint(names: Iterable[tuple[str, str]]) -> Footprint:
    """The :class:`Footprint` of the named (engine, release) environments."""
    found = {(n, r): made(n, r) for n, r in names}
    present = {k: m for k, m in found.items() if m is not None}
    cache = sum(info.st_size for info in _files([cache_root() / UV_CACHE])
                if info.st_nlink == 1)
    return Footprint(made=present, disk=disk(folder(n, r) for n, r in present), cache=cache)


class ReleaseUnavailable(DyncheckError):
    """A release that cannot be installed here (no wheel for this Python or platform)."""

    def __init__(self, engine: str, release: str, reason: str) -> None:
        super().__init__(f"{engine} {release} cannot be installed: {reason}")


def reason(text: str) -> str:
    """The installer's reason in one line: the dependency that conflicts with a pinned
    version, else its last line."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip() and "WARNING" not in ln]
    pinned = [ln for ln in lines if "The user requested (constraint)" in ln]  # pip
    if pinned:
        pin = pinned[0].split("(constraint)", 1)[1].strip()
        name = pin.split("=")[0].strip()
        cause = [ln for ln in lines if f"depends on {name}" in ln and "<" in ln]
        if cause:
            return f"{cause[0]}, but constraints.txt pins {pin}"
    causes = [ln for ln in lines if ln.startswith(("cause:", "╰─▶"))]  # uv
    if causes:
        text = causes[0].split(maxsplit=1)[1].split(", we can conclude", 1)[0]
        return re.sub(r"\{[^}]*\}", "", text).removeprefix("Because ")
    return lines[-1] if lines else "the installer failed"
