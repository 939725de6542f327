"""What a child process of dyncheck does first, so that it can neither outlive dyncheck nor
hold its caller hostage: it dies with its parent (Linux ``PR_SET_PDEATHSIG``: SIGKILL when the
parent exits for any reason, a SIGKILL of dyncheck included), it lets go of the caller's
stdout and stderr (an engine's C++ messages would otherwise keep ``dyncheck check … | tee
log`` or a CI step open after dyncheck is gone), and its address space is capped where a cap
is asked for (a model that makes a parser grow without bound fails there, in one line,
instead of taking the machine).
"""

from __future__ import annotations

import ctypes
import os
import resource
import signal
import sys

PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal this process receives when its parent thread exits."""


def die_with_parent(parent: int) -> None:
    """SIGKILL this process when ``parent`` exits (Linux); where the parent is already gone
    (it exited before this ran) exit now."""
    if sys.platform == "linux":
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):  # no prctl: the parent's own cleanup stops us
            pass
    if os.getppid() != parent:
        os._exit(0)


def release_output(errors: str | None = None) -> None:
    """Point this process's stdout at /dev/null and its stderr there too, or at the file
    ``errors`` (the parent reads a crash's last words from it): the caller's pipe is let
    go."""
    sys.stdout.flush()
    sys.stderr.flush()
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    if errors is None:
        os.dup2(null, 2)
    else:
        try:
            err = os.open(errors, os.O_WRONLY | os.O_APPEND)
        except FileNotFoundError:  # the parent let this process go before it started (its
            os._exit(0)  # folder removed on an interrupt): nothing to do, nothing to say
        os.dup2(err, 2)
        os.close(err)
    os.close(null)


def cap_memory(limit_bytes: int | None) -> None:
    """At most ``limit_bytes`` of address space for this process (None: no cap)."""
    if limit_bytes is None:
        return
    _soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = limit_bytes if hard == resource.RLIM_INFINITY else min(limit_bytes, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))


def confine(parent: int, *, memory_bytes: int | None = None, quiet: bool = False,
            errors: str | None = None) -> None:
    """All of the above for a child of ``parent`` (``errors``: where a quiet one's stderr
    goes)."""
    die_with_parent(parent)
    if quiet:
        release_output(errors)
    cap_memory(memory_bytes)


def address_space_mib() -> int | None:
    """This process's address-space limit in MiB (``ulimit -v``; None: unlimited)."""
    soft, _hard = resource.getrlimit(resource.RLIMIT_AS)
    return None if soft == resource.RLIM_INFINITY else soft // 2**20


FLOOR_MIB = {"check": 768, "engines": 4096}
"""The address space a command needs, measured on this machine under ``ulimit -v``: ``check``
of a URDF through MuJoCo, Pinocchio and Drake failed at 390 MiB and passed at 586 MiB;
``run simple_pendulum`` (every engine, JAX's included) aborted in C++ (``std::bad_alloc``,
exit 134) at 1953 MiB and finished at 3906 MiB. ``engines``: every command that loads JAX
or Warp (``run``, ``bench``, ``tutorials``, a ``check`` with a MuJoCo port)."""


def floor_mib(command: str, impls: tuple[str, ...] = ()) -> int | None:
    """The address space ``command`` needs (None: no engine loaded: no floor)."""
    if command == "check":
        from dyncheck.adapters import ENGINE_PORTS

        return FLOOR_MIB["engines"] if set(ENGINE_PORTS) & set(impls) else FLOOR_MIB["check"]
    if command in ("run", "bench", "tutorials"):
        return FLOOR_MIB["engines"]
    return None


STACK_MIB = 64
"""The stack this process asks for (``ulimit -s``): the model walks, pickling a deep tree
for an engine's process and the engines' own parsers recurse through C, body by body; a
200-link chain under a 1 MiB stack ended dyncheck in a segmentation fault (exit 139, no
message; measured). Linux grows the main thread's stack up to the limit in force when it
grows, so a soft limit raised here takes effect at once, and children inherit it."""


def stack_room() -> None:
    """Raise this process's soft stack limit to :data:`STACK_MIB` (at most its hard limit):
    what the caller's ``ulimit -s`` left is never less than the command needs, unless the
    hard limit itself is (then :func:`stack_mib` says so, refused up front)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_STACK)
    want = STACK_MIB << 20
    if soft == resource.RLIM_INFINITY or soft >= want:
        return
    raised = want if hard == resource.RLIM_INFINITY else min(want, hard)
    if raised > soft:
        resource.setrlimit(resource.RLIMIT_STACK, (raised, hard))


def stack_mib() -> int | None:
    """This process's stack limit in MiB (None: unlimited)."""
    soft, _hard = resource.getrlimit(resource.RLIMIT_STACK)
    return None if soft == resource.RLIM_INFINITY else soft >> 20
