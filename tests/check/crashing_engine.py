"""Engines that fail as a C extension can: a segfault while loading, a segfault while
computing, a computation that never returns. Used to show that an engine run in its own
process costs only its own rows (:mod:`dyncheck.check.engines`)."""

from __future__ import annotations

import ctypes
import time

from dyncheck.adapters.mujoco.model import MujocoModel


def _segfault() -> None:
    ctypes.string_at(0)  # reads address 0: SIGSEGV, as a crashing parser would


class CrashOnLoad(MujocoModel):
    def __init__(self, source):  # type: ignore[no-untyped-def]
        _segfault()


class AbortOnLoad(MujocoModel):
    """A parser that states why on stderr, then ends its process (Drake's MJCF parser on an
    ``<inertial mass="0">``: "Failure at …unit_inertia.h:104 …: condition 'mass > 0'
    failed.", exit status 1)."""

    def __init__(self, source):  # type: ignore[no-untyped-def]
        import os

        os.write(2, b"a first line the page need not show\n")
        os.write(2, b"Failure at parser.cc:104 in Read(): condition 'mass > 0' failed.\n")
        os._exit(1)


class CrashOnDynamics(MujocoModel):
    def dynamics(self, q, v, a):  # type: ignore[no-untyped-def]
        _segfault()


class HangOnDynamics(MujocoModel):
    def dynamics(self, q, v, a):  # type: ignore[no-untyped-def]
        time.sleep(3600)


class GrowOnLoad(MujocoModel):
    """A parser that grows without bound (Drake's on an MJCF that includes itself did)."""

    def __init__(self, source):  # type: ignore[no-untyped-def]
        held = []
        while True:
            held.append(bytearray(64 * 2**20))


class NoisyHangOnDynamics(MujocoModel):
    """Writes to the caller's stdout and stderr at the C level, records its pid, then never
    answers: it must neither reach the caller's output nor outlive the check's process."""

    def __init__(self, source):  # type: ignore[no-untyped-def]
        import os

        os.write(1, b"ENGINE-NOISE-STDOUT\n")
        os.write(2, b"ENGINE-NOISE-STDERR\n")
        pid_file = os.environ.get("DYNCHECK_TEST_PID_FILE")
        if pid_file:
            with open(pid_file, "w") as handle:
                handle.write(str(os.getpid()))
        super().__init__(source)

    def dynamics(self, q, v, a):  # type: ignore[no-untyped-def]
        time.sleep(3600)
