"""Engines that fail as a C extension can: a segfault while loading, a segfault while
computing, a computation that never returns. Used to show that an engine run in its own
process costs only its own rows (:mod:`dyncheck.check.engines`)."""

from __future__ import annotations

import ctypes
import time

from dyncheck.adapters.mujoco_model import MujocoModel


def _segfault() -> None:
    ctypes.string_at(0)  # reads address 0: SIGSEGV, as a crashing parser would


class CrashOnLoad(MujocoModel):
    def __init__(self, source):  # type: ignore[no-untyped-def]
        _segfault()


class CrashOnDynamics(MujocoModel):
    def dynamics(self, q, v, a):  # type: ignore[no-untyped-def]
        _segfault()


class HangOnDynamics(MujocoModel):
    def dynamics(self, q, v, a):  # type: ignore[no-untyped-def]
        time.sleep(3600)
