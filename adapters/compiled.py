"""Where an engine keeps the machine code it compiles for this work (JAX's persistent
compilation cache, Warp's kernel cache): the folder the command line checked
(:mod:`dyncheck.cache.compiled`, handed to the work as :attr:`dyncheck.settings.Settings.
compiled`), or none — Warp then compiles into a private temporary folder of the process,
removed at exit, never into its own default under the home folder."""

from __future__ import annotations

import atexit
import os
import shutil
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from dyncheck.settings import Settings

_TEMPORARY: dict[str, Path] = {}
"""Warp's temporary kernel folder of this process, where it has no checked one."""

_AIMED: dict[str, Callable[[], None]] = {}
"""How to point each engine that was aimed at a checked folder away from it again, by
engine."""


def aimed(engine: str, away: Callable[[], None]) -> None:
    """Record that ``engine`` now writes into a checked folder, and how to stop it."""
    _AIMED[engine] = away


def released() -> None:
    """Point every engine of this process away from the checked folders, when the command
    that checked them ends: their settings are process-wide, so an engine used afterwards in
    the same process (a library call, the next command of a test session) would otherwise
    write entries that no manifest vouches for, and the next command would delete them."""
    while _AIMED:
        _AIMED.popitem()[1]()


def private_folder(folder: Path) -> None:
    """``mkdir -p`` with every created level 0700 (umask aside)."""
    missing = []
    at = folder
    while not at.exists() and at != at.parent:
        missing.append(at)
        at = at.parent
    for level in reversed(missing):
        try:
            level.mkdir(mode=0o700)
        except FileExistsError:
            pass
        os.chmod(level, 0o700)


def private(folder: Path) -> bool:
    """A real folder (created 0700 where missing) of this user's that nobody else can
    write."""
    try:
        private_folder(folder)
        info = folder.lstat()
    except OSError:
        return False
    return stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() \
        and not info.st_mode & 0o022


def folder(settings: Settings, engine: str) -> Path | None:
    """The checked folder of ``engine``'s compiled cache for this work, or None."""
    if not settings.cache or settings.compiled is None:
        return None
    path = Path(settings.compiled) / engine
    return path if private(path) else None


def warp_folder(settings: Settings) -> Path:
    """Warp's kernel cache for this work: the checked folder, else a private temporary one
    of this process (removed at exit) — never Warp's own default under the home folder."""
    checked = folder(settings, "warp")
    if checked is not None:
        return checked
    if "warp" not in _TEMPORARY:
        _TEMPORARY["warp"] = Path(tempfile.mkdtemp(prefix="dyncheck-warp-"))
        atexit.register(shutil.rmtree, _TEMPORARY["warp"], True)
    return _TEMPORARY["warp"]


def start_warp(wp: Any) -> None:
    """Warp's settings for this work, made before it starts (``wp.init``): its log at errors
    only (no banner, no line per kernel module) and its kernel cache in
    :func:`warp_folder`."""
    from dyncheck.settings import current

    wp.config.log_level = wp.LOG_ERROR
    wp.config.kernel_cache_dir = str(warp_folder(current()))
    if folder(current(), "warp") is not None:
        aimed("warp", lambda: setattr(wp.config, "kernel_cache_dir",
                                      str(warp_folder(Settings(cache=False)))))
