"""Where units of work run: this process, a pool of ``--jobs`` local processes, or a
``dask.distributed`` cluster (``--dask ADDRESS``, or ``--dask local`` for a ``LocalCluster``).

Every place that fans work out (a run's cases and catalogue entries) submits the same units
through :func:`executor` and collects them in submission order, so the results do not depend
on where they ran. Dask is the optional extra ``dask``; it is imported only when asked for.
"""

from __future__ import annotations

import atexit
import gc
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from functools import partial
from multiprocessing import parent_process as mp_parent_process
from pathlib import Path
from typing import Any

from dyncheck.errors import DyncheckError, EngineError, InvalidInput
from dyncheck.progress import Progress
from dyncheck.settings import Settings, current, in_force

LOCAL = "local"
"""``--dask local``: a ``LocalCluster`` of ``--jobs`` single-threaded worker processes."""

CONNECT_SECONDS = 20
"""How long to wait for a scheduler before giving up (an error, before any work)."""


JOB_MEMORY = 2 * 2**30
"""Memory one worker may take with every engine and port loaded (a run's worker holding MJX
and MuJoCo Warp: 1.8 GB resident, measured)."""


def default_jobs() -> int:
    """``--jobs``' default: the cores this process may use, at most one per
    :data:`JOB_MEMORY` of the machine's memory (never fewer than one)."""
    affinity = getattr(os, "sched_getaffinity", None)
    cores = len(affinity(0)) if affinity is not None else (os.cpu_count() or 1)
    try:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # no sysconf (Windows) or no such name
        return max(1, cores)
    return max(1, min(cores, memory // JOB_MEMORY))


THREADED_RUNTIMES = ("jax", "warp")
"""Modules that start threads of their own when imported: a process holding one is not
forked."""


def start_method() -> str:
    """How this process starts worker processes: ``fork`` on Linux while no
    :data:`THREADED_RUNTIMES` is imported here (a forked worker has the engines and libraries
    this process loaded: ~1 s of a cold ``run --jobs 2``), else ``spawn`` (JAX warns that a
    fork "will likely lead to a deadlock")."""
    threaded = any(name in sys.modules for name in THREADED_RUNTIMES)
    return "fork" if sys.platform == "linux" and not threaded else "spawn"


@contextmanager
def executor(jobs: int = 1, dask: str | None = None) -> Iterator[Executor | None]:
    """A ``concurrent.futures`` executor for the units of work, or None to run them here.

    ``dask``: a scheduler address (``tcp://host:8786``) or :data:`LOCAL`; a scheduler that
    cannot be reached, or dask not installed, is an :class:`InvalidInput` naming ``--dask``.
    """
    if dask is None:
        if jobs <= 1:
            yield None
            return
        import multiprocessing

        ctx = multiprocessing.get_context(start_method())
        pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_start,
                                   initargs=(os.getpid(),))
        try:
            yield pool
        except BaseException:  # Ctrl-C, SIGTERM, an error: queued work is not computed
            stop(pool)
            raise
        pool.shutdown(wait=True)
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        from dyncheck.errors import install_hint

        raise InvalidInput(
            "--dask", dask, "used with the extra 'dask' installed (" + install_hint("dask") + ")"
        ) from None
    with _quiet_distributed():
        yield from _dask_executor(jobs, dask, Client, LocalCluster)


@contextmanager
def _quiet_distributed() -> Iterator[None]:
    """distributed's own log records above CRITICAL while its client is ours: a cluster
    that loses a unit logs its tracebacks (``distributed.client - ERROR``) to stderr before
    :func:`_result` turns the loss into one line. Restored afterwards."""
    import logging

    names = ["distributed", *(n for n in logging.root.manager.loggerDict
                              if n.startswith("distributed."))]  # each has its own handler
    levels = {n: logging.getLogger(n).level for n in names}
    for name in names:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for name, level in levels.items():
            logging.getLogger(name).setLevel(level)


def _dask_executor(jobs: int, dask: str, Client: Any,
                   LocalCluster: Any) -> Iterator[Executor]:
    if dask == LOCAL:
        import dask as dask_config

        # non-daemonic workers may start processes of their own (a model check's engines)
        with dask_config.config.set({"distributed.worker.daemon": False}):
            cluster = LocalCluster(
                n_workers=max(jobs, 1),
                threads_per_worker=1,
                processes=True,
                # no dashboard; the scheduler's HTTP server (health routes) on a free port:
                # its default 8787 is taken by any other cluster on the machine (a warning)
                dashboard_address=":0",
                scheduler_kwargs={"dashboard": False},
            )
        with cluster, Client(cluster) as client:
            yield client.get_executor(pure=False)
        return
    try:
        client = Client(dask, timeout=CONNECT_SECONDS)
    except (OSError, TimeoutError, ValueError) as exc:
        why = type(exc).__name__
        raise InvalidInput(
            "--dask", dask, f"a reachable dask scheduler (tcp://HOST:PORT) or 'local' ({why})"
        ) from None
    with client:
        yield client.get_executor(pure=False)


def stop(pool: ProcessPoolExecutor) -> None:
    """End a local pool now: its queued units cancelled, its workers terminated (a unit
    running in one is abandoned, its result never written) and reaped within a second —
    ``shutdown(wait=True)``, the context manager's exit, computed every queued unit first
    (27–230 s after Ctrl-C with ``--jobs 2``)."""
    processes = list(getattr(pool, "_processes", {}).values())  # (the executor's own list)
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    for process in processes:
        process.join(1.0)
        if process.is_alive():
            process.kill()
            process.join(1.0)


_AT_END: list[Callable[[], None]] = []
"""What a process told to end does last (:func:`at_end`, :func:`end_now`)."""


def at_end(fn: Callable[[], None]) -> None:
    """Have :func:`end_now` call ``fn`` (an engine module's: kill its processes, remove
    their files), once however often it is asked."""
    if fn not in _AT_END:
        _AT_END.append(fn)


def end_now() -> None:
    """What this process must do before it ends on a signal: every :func:`at_end` call."""
    for fn in _AT_END:
        try:
            fn()
        except Exception:  # (ending anyway: the rest still runs)
            pass


@contextmanager
def scratch() -> Iterator[Path]:
    """A private temporary folder for this command's work (its ``TMPDIR`` and
    ``tempfile``'s, inherited by every process it starts), removed with whatever is left in
    it when the command ends — however it ends: a worker or an engine's process killed
    mid-way (SIGTERM, Ctrl-C) cannot leave its files behind. The previous settings
    restored."""
    import shutil
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="dyncheck-"))
    before, env = tempfile.tempdir, os.environ.get("TMPDIR")
    tempfile.tempdir = str(folder)
    os.environ["TMPDIR"] = str(folder)
    try:
        yield folder
    finally:
        tempfile.tempdir = before
        if env is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = env
        shutil.rmtree(folder, ignore_errors=True)


_ENDING = threading.Event()
"""Set when a signal asked this process to end: what is left is unwinding, at once."""


def ending() -> bool:
    """Whether a signal asked this process to end (an engine's process is then killed, not
    asked to finish: :meth:`dyncheck.check.engines.Isolated.close`)."""
    return _ENDING.is_set()


@contextmanager
def on_sigterm() -> Iterator[None]:
    """While the block runs (the main thread only: Python's rule), SIGTERM raises
    :class:`~dyncheck.errors.Terminated` and Ctrl-C KeyboardInterrupt, each marking this
    process as ending (:func:`ending`); the previous handlers restored after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if not _FORK_HOOK:
        os.register_at_fork(after_in_child=_forked_quiet)
        _FORK_HOOK.append(True)
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    interrupt = signal.getsignal(signal.SIGINT)
    if interrupt is signal.default_int_handler:
        signal.signal(signal.SIGINT, _raise_interrupt)
    hook = sys.unraisablehook
    sys.unraisablehook = partial(_deliver_again, otherwise=hook)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, interrupt)
        sys.unraisablehook = hook
        _ENDING.clear()


def _deliver_again(unraisable: Any, *,
                   otherwise: Callable[[Any], object] = sys.__unraisablehook__) -> None:
    """A signal's exception raised where Python cannot propagate it — a handler that ran
    inside an at-fork hook, a finalizer or a weak reference's callback ("Exception ignored
    in: <function _acquireLock>", then the process went on as if never signalled) — is not
    printed: a pool's worker ends at once (its engines closed), the command's own process
    has the signal sent again a moment later, from a thread started without waiting (a
    second signal during the wait raised inside this hook too), so that its handler runs
    once this hook has returned. Once a signal has asked the process to end, what the
    interrupted machinery leaves unraisable (a finalizer caught half-built: "Exception
    ignored in: <Finalize object, dead>") is its consequence, not news: not printed. Any
    other goes to ``otherwise`` (the hook before, Python's own)."""
    import _thread

    from dyncheck.errors import Terminated

    signum = signal.SIGTERM if isinstance(unraisable.exc_value, Terminated) else \
        signal.SIGINT if isinstance(unraisable.exc_value, KeyboardInterrupt) else None
    if signum is None:
        if not ending():
            otherwise(unraisable)
        return
    if mp_parent_process() is not None:
        exit_worker()
    _thread.start_new_thread(_send_later, (signum,))


def exit_worker() -> None:
    """A pool's worker told to end: its engines closed (:func:`end_now`) with further
    signals held off — a second SIGTERM raised inside that cleanup, where nothing could
    catch it —, then gone at once (nothing of it is waited for)."""
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM, signal.SIGINT})
    end_now()
    os._exit(143)


def _send_later(signum: int) -> None:
    time.sleep(AGAIN_S)
    os.kill(os.getpid(), signum)


AGAIN_S = 0.05
"""How long after a lost signal it is sent again (:func:`_deliver_again`)."""


def _raise_terminated(signum: int, frame: object) -> None:
    from dyncheck.errors import Terminated

    _ENDING.set()
    raise Terminated


def _raise_interrupt(signum: int, frame: object) -> None:
    _ENDING.set()
    raise KeyboardInterrupt


def _worker_start(parent: int) -> None:
    """A local worker dies with the process that started it (SIGTERM or SIGKILL of
    ``dyncheck run --jobs 2`` left its workers computing) and skips the final collection;
    Ctrl-C is its parent's to answer (:func:`stop` ends it), and SIGTERM unwinds its unit
    (an engine's process closed, its temporary files removed) before it exits."""
    from dyncheck.confinement import die_with_parent

    die_with_parent(parent)
    exit_without_collecting()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _worker_terminated)
    sys.unraisablehook = _deliver_again


_IN_UNIT = threading.Event()
"""Set while this process computes a unit of work (:func:`_under`)."""


def _worker_terminated(signum: int, frame: object) -> None:
    """A pool worker's SIGTERM: inside a unit, :class:`~dyncheck.errors.Terminated` unwinds
    it (:func:`_under`); idle, waiting for the next unit, the worker exits at once — the
    exception there ended in the pool's loop, whose process printed its traceback ("Process
    ForkProcess-1: Traceback …", on every Ctrl-C that found a worker idle)."""
    if _ENDING.is_set():
        return  # (already unwinding: a second SIGTERM would break into its cleanup)
    _ENDING.set()
    if not _IN_UNIT.is_set():
        os._exit(143)
    _raise_terminated(signum, frame)


def _forked_quiet() -> None:
    """In a process forked while a command answers signals (a pool's worker before its
    initializer has run, an engine's process): SIGTERM ends it at once unless it computes a
    unit, Ctrl-C is its parent's to answer. It inherited the command's handlers, which raised
    in multiprocessing's start-up code, and printed ("Process ForkProcess-2: Traceback …
    Terminated", SIGINT as a pool started)."""
    _IN_UNIT.clear()
    if signal.getsignal(signal.SIGTERM) is _raise_terminated:
        signal.signal(signal.SIGTERM, _worker_terminated)
    if signal.getsignal(signal.SIGINT) is _raise_interrupt:
        signal.signal(signal.SIGINT, signal.SIG_IGN)


_FORK_HOOK: list[bool] = []
"""Whether :func:`_forked_quiet` is registered (once a process: Python cannot unregister it;
it acts only where a command's handlers are in force)."""

def exit_without_collecting() -> None:
    """At this process's exit, skip the interpreter's final cyclic garbage collection over
    every object still alive (``gc.freeze`` from an ``atexit`` hook): ~0.5 s a process
    that loaded the core engines, sympy and matplotlib, ~2.7 s one that loaded JAX and Warp
    too. Nothing is lost — the memory goes back to the system with the process, results are
    written and closed before exit (files whole, then renamed), and objects freed by
    reference counting still are."""
    atexit.register(gc.freeze)


Unit = tuple[str, Callable[..., Any], tuple[Any, ...]]
"""A unit of work: what it is (for progress), a picklable function, its arguments."""


@contextmanager
def settled(settings: Settings) -> Iterator[None]:
    """``settings`` in force for the work inside (:func:`dyncheck.settings.current`), and the
    reference handed its store: the disk cache (:class:`dyncheck.cache.store.DiskStore`), or none
    under ``--no-cache``."""
    from dyncheck.cache.store import DiskStore
    from dyncheck.reference.derivations import STORE

    token = STORE.set(DiskStore() if settings.cache else None)
    try:
        with in_force(settings):
            yield
    finally:
        STORE.reset(token)


def _under(settings: Settings, fn: Callable[..., Any], *args: Any) -> Any:
    """``fn(*args)`` with the submitting command's settings in force (in whatever process or
    machine runs it: they travel as this argument). A local worker told to end (SIGTERM from
    :func:`stop`) unwinds the unit — its engines killed, their files removed — and exits."""
    from dyncheck.errors import Terminated

    _IN_UNIT.set()
    try:
        with settled(settings):
            return fn(*args)
    except Terminated:
        if mp_parent_process() is not None and ending():
            exit_worker()
        raise
    finally:
        _IN_UNIT.clear()


def _timed(settings: Settings, fn: Callable[..., Any], *args: Any) -> tuple[float, Any]:
    """:func:`_under`, and the seconds the unit took where it ran (its own time, not the
    wait for a worker)."""
    start = time.perf_counter()
    result = _under(settings, fn, *args)
    return time.perf_counter() - start, result


def run_units(
    units: Sequence[Unit],
    *,
    jobs: int = 1,
    dask: str | None = None,
    progress: Progress | None = None,
    took: list[float] | None = None,
) -> list[Any]:
    """The units' results in submission order, run here, on ``jobs`` processes or on a dask
    cluster (see :func:`executor`); ``progress`` hears of each unit as it finishes, with the
    time it took; ``took``, where given, receives each unit's seconds in submission order
    (its own time where it ran, not the wait for a worker)."""
    if progress is not None:
        progress.begin(len(units))
    seconds_of: dict[int, float] = {}
    with executor(max(1, min(jobs, len(units))), dask) as pool:
        results: dict[int, Any] = {}
        if pool is None:
            for i, (what, fn, args) in enumerate(units):
                start = time.perf_counter()
                results[i] = fn(*args)
                seconds_of[i] = time.perf_counter() - start
                if progress is not None:
                    progress.done(what)
        else:
            settings = current()
            futures = {pool.submit(_timed, settings, fn, *args): i
                       for i, (_what, fn, args) in enumerate(units)}
            for future in as_completed(futures):  # progress as units finish, not in order
                i = futures[future]
                seconds_of[i], results[i] = _result(future, units[i][0], dask)
                if progress is not None:
                    progress.done(units[i][0], seconds=seconds_of[i])
    if took is not None:
        took[:] = [seconds_of[i] for i in range(len(units))]
    return [results[i] for i in range(len(units))]


def _result(future: Any, what: str, dask: str | None) -> Any:
    """A unit's result, or — where the pool lost it — an error naming the unit and why,
    never an exception of the pool's own (a dask scheduler that died mid-run raised
    ``CancelledError``, which ended the command with exit 1 as if a check had failed; a
    lost connection, an ``OSError``, read as a failed write)."""
    from concurrent.futures import CancelledError
    from concurrent.futures.process import BrokenProcessPool

    try:
        return future.result()
    except BrokenProcessPool:
        raise EngineError(f"{what}: its worker process died (a crash in an engine outside "
                          "its own process, or out of memory); nothing was written") from None
    except (CancelledError, TimeoutError, OSError) as exc:
        if dask is None:
            raise
        raise InvalidInput("--dask", dask, f"a cluster that keeps its scheduler and workers "
                           f"for the whole run: it lost {what!r} ({type(exc).__name__}); "
                           "nothing was written") from None


def each_unit(
    units: Sequence[Unit], *, jobs: int = 1, dask: str | None = None,
) -> Iterator[tuple[str, Any]]:
    """``(what, result)`` for each unit in submission order, as soon as it and the units
    before it are done — so a caller writes each result before the next is waited for. A
    unit's :class:`~dyncheck.errors.DyncheckError` is its result (the units after it still
    run); a worker that died is one, naming the unit."""
    from concurrent.futures.process import BrokenProcessPool

    with executor(max(1, min(jobs, len(units))), dask) as pool:
        if pool is None:
            for what, fn, args in units:
                try:
                    yield what, fn(*args)
                except DyncheckError as exc:
                    yield what, exc
            return
        settings = current()
        futures = [pool.submit(_under, settings, fn, *args) for _what, fn, args in units]
        for (what, _fn, _args), future in zip(units, futures, strict=True):
            try:
                yield what, future.result()
            except DyncheckError as exc:
                yield what, exc
            except BrokenProcessPool:
                yield what, EngineError(f"{what}: its worker process died (a crash in an "
                                        "engine outside its own process, or out of memory)")
