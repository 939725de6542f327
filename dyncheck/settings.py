"""What a command's options set for all of its work: the disk cache on or off
(``--no-cache``) and the ports' device (``--device``).

One frozen value, :class:`Settings`, in force for the work of this process
(:func:`current`); :func:`dyncheck.workers.settled` puts it in force, and hands it to every
unit of work a command fans out — local processes, a dask cluster, an engine's own process —
as an argument, never through environment variables (which a cluster's workers do not see).
The environment is read once, at the command line, for the options' defaults
(:func:`from_environment`). Imports nothing of dyncheck: the adapters read it.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

from dyncheck.errors import InvalidInput

NO_CACHE = "DYNCHECK_NO_CACHE"
"""Environment variable: set (to anything but empty or 0), ``--no-cache`` is the default."""
DEVICE = "DYNCHECK_DEVICE"
"""Environment variable: the default of ``--device`` (``cpu``, ``cuda`` or ``cuda:N``)."""
DEVICE_NAME = re.compile(r"cpu|cuda(:\d+)?")


@dataclass(frozen=True, kw_only=True)
class Settings:
    """``cache``: read and write the disk cache; ``device``: where MuJoCo's ports compute
    (``cpu``, ``cuda``, ``cuda:N``; None: each port's default — the CPU for Warp, JAX's
    default device for MJX); ``compiled``: the folder of the compiled-code caches the
    command line checked (:mod:`dyncheck.cache.compiled`; None: none used)."""

    cache: bool = True
    device: str | None = None
    compiled: str | None = None


_CURRENT: ContextVar[Settings | None] = ContextVar("dyncheck_settings", default=None)


def current() -> Settings:
    """The settings in force for the work of this process (none put in force: the
    defaults)."""
    return _CURRENT.get() or Settings()


@contextmanager
def in_force(settings: Settings) -> Iterator[Settings]:
    """``settings`` in force inside the block (the comparison layer's
    :func:`dyncheck.workers.settled` also hands the reference its store)."""
    token = _CURRENT.set(settings)
    try:
        yield settings
    finally:
        _CURRENT.reset(token)


def from_environment(*, no_cache: bool = False, device: str | None = None) -> Settings:
    """The command line's settings: its options, else :data:`NO_CACHE` and :data:`DEVICE`
    from the environment (checked here, before any work)."""
    env_device = os.environ.get(DEVICE)
    if env_device is not None and not DEVICE_NAME.fullmatch(env_device):
        raise InvalidInput(DEVICE, env_device, "cpu, cuda or cuda:N (the environment)")
    return Settings(cache=not (no_cache or os.environ.get(NO_CACHE, "") not in ("", "0")),
                    device=device or env_device)
